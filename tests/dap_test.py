#!/usr/bin/env python3
"""simbot dap: a small Debug Adapter Protocol client drives real sessions.

Usage: dap_test.py SIMBOT ICEMAN FIG92

Session 1 (ICEMAN vs fig92, seed 3; the edge handler INT1 is entered first
at tick 83150170): a breakpoint on INT1's first line (191); the stop, its
stack (INT1 at 191 over platform at 220), scopes and variables (the global
buf, a char[9], with its 9 elements), evaluate in two frames, next, then
stepBack to the same line and values, a data breakpoint on buf that stops
where it is written with a new value, reverseContinue back before that
write and then to the breakpoint (each stop with its hitBreakpointIds),
evaluate "goto 9s" in the debug console, disconnect.

Session 2 (the same match, 20 s, stopOnEntry): the entry stop; breakpoints
refused with a message (no such line, a bad condition, no such function);
a hit count (the second entry into INT1); stepping robot B's thread (the
hold moves to B); a data breakpoint on A's buf set while B is held stops A;
a condition that is never true runs the match to its end; continuing past
the end ends the session (terminated).

Session 2b (tests/debug/inspect.dc alone): a data breakpoint on an auto is
removed by the adapter when its call returns: a `breakpoint` event, reason
removed, and a stop there with no hit.

Session 3 (what a broken or hostile client sends, after the robustness
audit of issue 38): a request whose arguments nest 150,000 arrays (300 KB),
one with 350,000 empty objects (1 MB), {"type": 5}, {"seq": "abc"}, arguments that are not an object, a missing
command, Content-Length "abc", negative, huge or too large for its body,
a header block without one, an unknown header, a body that is not JSON, a
line that is not a header; then arguments of the wrong type or range at a
stop. Each is answered (an error response where the request's seq or
command can be read, else an `output` event on stderr) and the next good
request is answered. Session 4: a body the input ends inside.

Session 5 (a continue in a 600-s match that steps every instruction for
a data breakpoint that never fires: a minute or more): pause stops it at
once (the answer, then a `stopped` event with reason "pause"); terminate
stops it at once; disconnect during it ends the adapter within 2 s (the
time is printed).

Every response's success and contents are checked.
"""
import json
import os
import queue
import re
import subprocess
import sys
import threading
import time

SIMBOT, ICEMAN, FIG92 = sys.argv[1:4]
ICEMAN = os.path.abspath(ICEMAN)
FIG92 = os.path.abspath(FIG92)
TIMEOUT = 120  # seconds for any one answer (a sanitizer build is slow)
TRACE = bool(os.environ.get("DAP_TEST_TRACE"))  # print every message
failures = []


def check(condition, what):
    if not condition:
        failures.append(what)
        print("FAIL:", what)
    return condition


class Client:
    """Content-Length framed JSON over the adapter's stdin and stdout."""

    def __init__(self):
        self.proc = subprocess.Popen([SIMBOT, "dap"], stdin=subprocess.PIPE,
                                     stdout=subprocess.PIPE, stderr=subprocess.PIPE)
        self.seq = 1
        self.messages = queue.Queue()
        self.events = []  # every event seen, in order
        self.responses = []  # responses seen while waiting for another
        self.stderr = b""
        threading.Thread(target=self._read, daemon=True).start()
        threading.Thread(target=self._drain, daemon=True).start()

    def _drain(self):
        self.stderr = self.proc.stderr.read()

    def _read(self):
        out = self.proc.stdout
        while True:
            length = None
            while True:
                line = out.readline()
                if not line:
                    self.messages.put(None)
                    return
                line = line.strip()
                if not line:
                    if length is not None:
                        break
                    continue
                name, _, value = line.decode().partition(":")
                if name.strip().lower() == "content-length":
                    length = int(value)
            body = out.read(length)
            self.messages.put(json.loads(body))

    def _next(self):
        try:
            m = self.messages.get(timeout=TIMEOUT)
        except queue.Empty:
            raise SystemExit("FAIL: no message from simbot dap in %d s" % TIMEOUT)
        if m is None:
            raise SystemExit("FAIL: simbot dap closed its output; stderr:\n" +
                             self.stderr.decode(errors="replace"))
        if TRACE:
            print("<-", json.dumps(m))
        return m

    def send(self, command, arguments=None):
        message = {"seq": self.seq, "type": "request", "command": command}
        if arguments is not None:
            message["arguments"] = arguments
        self.seq += 1
        body = json.dumps(message).encode()
        if TRACE:
            print("->", body.decode())
        self.proc.stdin.write(b"Content-Length: %d\r\n\r\n" % len(body) + body)
        self.proc.stdin.flush()
        return message["seq"]

    def raw(self, data):
        """Bytes as they are, framing and all."""
        if TRACE:
            print("->", data[:200])
        self.proc.stdin.write(data)
        self.proc.stdin.flush()

    def next_seq(self):
        self.seq += 1
        return self.seq - 1

    def response(self, request_seq, command=None):
        """The response to request_seq (events and other responses on the way
        are kept)."""
        def wanted(m):
            return m.get("request_seq") == request_seq and (command is None or m.get("command") == command)
        for k, m in enumerate(self.responses):
            if wanted(m):
                return self.responses.pop(k)
        while True:
            m = self._next()
            if m.get("type") == "event":
                self.events.append(m)
            elif m.get("type") == "response":
                if wanted(m):
                    return m
                self.responses.append(m)

    def refused(self, request_seq, command, words):
        """An error response to request_seq that names `words`."""
        m = self.response(request_seq, command)
        check(m.get("success") is False and words in m.get("message", ""),
              f"{command} #{request_seq}: wanted an error naming {words!r}, got {m}")
        return m

    def output(self, words):
        """The next `output` event on stderr, which must name `words`."""
        e = self.event("output")["body"]
        check(e.get("category") == "stderr" and words in e.get("output", ""),
              f"output: wanted {words!r} on stderr, got {e}")
        check(e.get("output", "").count("\n") == 1, f"output: one line: {e}")
        return e

    def request(self, command, arguments=None, success=True):
        """The response to one request (events on the way are kept)."""
        seq = self.send(command, arguments)
        while True:
            m = self._next()
            if m.get("type") == "event":
                self.events.append(m)
                continue
            if m.get("type") == "response" and m.get("request_seq") != seq:
                self.responses.append(m)
            if m.get("type") == "response" and m.get("request_seq") == seq:
                check(m.get("command") == command, f"{command}: response names {m.get('command')}")
                check(m.get("success") is success,
                      f"{command} {arguments}: success {m.get('success')}, wanted {success} "
                      f"({m.get('message')})")
                if not success:
                    check(bool(m.get("message")), f"{command}: a failure without a message")
                return m

    def event(self, name):
        """The next event of that name (earlier ones already seen first)."""
        for k, e in enumerate(self.events):
            if e["event"] == name:
                return self.events.pop(k)
        while True:
            m = self._next()
            if m.get("type") == "event":
                if m["event"] == name:
                    return m
                self.events.append(m)

    def stopped(self, reason, thread=1):
        e = self.event("stopped")["body"]
        check(e.get("reason") == reason, f"stopped: reason {e.get('reason')!r}, wanted {reason!r} ({e})")
        check(e.get("threadId") == thread, f"stopped: thread {e.get('threadId')}, wanted {thread}")
        check(e.get("allThreadsStopped") is True, "stopped: allThreadsStopped")
        return e

    def frames(self, thread=1):
        r = self.request("stackTrace", {"threadId": thread})
        frames = r["body"]["stackFrames"]
        check(r["body"]["totalFrames"] == len(frames), "stackTrace: totalFrames")
        return frames

    def evaluate(self, expression, frame, success=True):
        r = self.request("evaluate", {"expression": expression, "frameId": frame, "context": "watch"},
                         success=success)
        return r["body"] if success else r

    def finish(self):
        self.request("disconnect", {"terminateDebuggee": True})
        try:
            status = self.proc.wait(timeout=TIMEOUT)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            raise SystemExit("FAIL: simbot dap did not exit after disconnect")
        check(status == 0, f"simbot dap exit status {status}")


def tick_of(stop):
    m = re.search(r"at tick (\d+)", stop.get("description", ""))
    check(m is not None, f"stopped: no tick in the description {stop.get('description')!r}")
    return int(m.group(1)) if m else -1


def start(client, arguments):
    r = client.request("initialize", {"clientID": "dap_test", "adapterID": "simbot",
                                      "linesStartAt1": True, "columnsStartAt1": True,
                                      "pathFormat": "path"})
    caps = r["body"]
    for cap in ["supportsConfigurationDoneRequest", "supportsConditionalBreakpoints",
                "supportsHitConditionalBreakpoints", "supportsStepBack",
                "supportsDataBreakpoints", "supportsEvaluateForHovers",
                "supportsFunctionBreakpoints"]:
        check(caps.get(cap) is True, f"initialize: {cap}")
    client.request("launch", arguments)
    client.event("initialized")


# ---- session 1 -----------------------------------------------------------------

c = Client()
# A launch that cannot build its run answers with the reason.
c.request("initialize", {"adapterID": "simbot"})
r = c.request("launch", {"program": "/no/such/robot.dc"}, success=False)
check("robot.dc" in r.get("message", ""), f"launch of a missing file: {r.get('message')!r}")
r = c.request("launch", {"seconds": 5}, success=False)
check("program" in r.get("message", ""), f"launch without a program: {r.get('message')!r}")
start(c, {"program": ICEMAN, "opponent": FIG92, "seed": 3, "stopOnEntry": False})

r = c.request("setBreakpoints", {"source": {"path": ICEMAN, "name": "iceman.dc"},
                                 "breakpoints": [{"line": 191}]})
bps = r["body"]["breakpoints"]
check(len(bps) == 1 and bps[0]["verified"] and bps[0]["line"] == 191,
      f"setBreakpoints 191: {bps}")
bp_id = bps[0].get("id")
c.request("setExceptionBreakpoints", {"filters": []})
c.request("configurationDone")
stop = c.stopped("breakpoint")
check(stop.get("hitBreakpointIds") == [bp_id], f"stopped: hitBreakpointIds {stop.get('hitBreakpointIds')}")
check(tick_of(stop) == 83150170, f"the first entry into INT1 at tick 83150170: {stop}")

threads = c.request("threads")["body"]["threads"]
check([t["id"] for t in threads] == [1, 2], f"threads: {threads}")
check(threads[0]["name"].startswith("A") and "iceman.dc" in threads[0]["name"], f"thread 1: {threads[0]}")
check(threads[1]["name"].startswith("B") and "fig92.dc" in threads[1]["name"], f"thread 2: {threads[1]}")

frames = c.frames()
check(len(frames) >= 3, f"stackTrace: {frames}")
top, caller = frames[0], frames[1]
check(top["name"].startswith("INT1(") and top["line"] == 191, f"frame 0: {top}")
check(caller["name"].startswith("platform(") and caller["line"] == 220, f"frame 1: {caller}")
check(top["source"]["path"] == ICEMAN, f"frame 0's source: {top['source']}")
check(frames[-1]["name"].startswith("<startup>"), f"outermost frame: {frames[-1]}")
partial = c.request("stackTrace", {"threadId": 1, "startFrame": 1, "levels": 1})["body"]
check([f["id"] for f in partial["stackFrames"]] == [caller["id"]], f"stackTrace startFrame/levels: {partial}")

scopes = c.request("scopes", {"frameId": top["id"]})["body"]["scopes"]
check([s["name"] for s in scopes] == ["Locals", "Globals"], f"scopes: {scopes}")
locals_ = {v["name"]: v for v in
           c.request("variables", {"variablesReference": scopes[0]["variablesReference"]})["body"]["variables"]}
check(set(locals_) == {"data", "counter"}, f"INT1's locals: {sorted(locals_)}")
check(locals_.get("counter", {}).get("type") == "unsigned long", f"counter: {locals_.get('counter')}")
globals_ref = scopes[1]["variablesReference"]
globals_ = {v["name"]: v for v in
            c.request("variables", {"variablesReference": globals_ref})["body"]["variables"]}
for name in ["buf", "cc", "x", "y", "count"]:
    check(name in globals_, f"globals: no {name} in {sorted(globals_)}")
buf = globals_.get("buf", {})
check(buf.get("type") == "char[9]", f"buf's type: {buf}")
check(buf.get("value", "").startswith('"4fgr4rgr"'), f"buf's value: {buf}")
check(buf.get("variablesReference", 0) > 0, "buf has children")
check(globals_.get("count", {}).get("value") == "1000", f"count: {globals_.get('count')}")
elements = c.request("variables", {"variablesReference": buf["variablesReference"]})["body"]["variables"]
check([e["name"] for e in elements] == [f"[{k}]" for k in range(9)], f"buf's elements: {elements}")
check(len(elements) == 9 and elements[0]["evaluateName"] == "buf[0]" and elements[0]["type"] == "char"
      and "52" in elements[0]["value"], f"buf[0]: {elements[:1]}")
check(len(elements) == 9 and elements[8]["value"].startswith("0"), f"buf[8]: {elements[8:]}")
page = c.request("variables", {"variablesReference": buf["variablesReference"], "start": 2, "count": 3})
check([e["name"] for e in page["body"]["variables"]] == ["[2]", "[3]", "[4]"], f"variables paged: {page['body']}")

z = c.evaluate("platform::z", top["id"])
check(z["result"] == "120" and z["type"] == "int" and z["variablesReference"] == 0, f"platform::z: {z}")
check(c.evaluate("z", caller["id"])["result"] == "120", "z in platform's frame")
check(c.evaluate("count", top["id"])["result"] == "1000", "count")
check(c.evaluate("buf[1]", top["id"])["type"] == "char", "buf[1]'s type")
bad = c.evaluate("no_such_name", top["id"], success=False)
check("no_such_name" in bad.get("message", ""), f"evaluate of an unknown name: {bad.get('message')!r}")
c.request("pause", {"threadId": 1}, success=False)

# next, then stepBack to the same place and values.
before = {"line": top["line"], "z": "120", "count": "1000", "data": locals_["data"]["value"],
          "frames": [(f["name"], f["line"]) for f in frames]}
c.request("next", {"threadId": 1})
stop = c.stopped("step")
after_next = tick_of(stop)
check(after_next > 83150170, f"next moves the clock: {stop}")
frames = c.frames()
check(frames[0]["name"].startswith("INT1(") and frames[0]["line"] == 192, f"after next: {frames[0]}")
c.request("stepBack", {"threadId": 1})
stop = c.stopped("step")
check(tick_of(stop) == 83150170, f"stepBack returns to tick 83150170: {stop}")
frames = c.frames()
top = frames[0]
check([(f["name"], f["line"]) for f in frames] == before["frames"], f"after stepBack: {frames}")
check(c.evaluate("platform::z", top["id"])["result"] == before["z"], "platform::z after stepBack")
check(c.evaluate("count", top["id"])["result"] == before["count"], "count after stepBack")
check(c.evaluate("data", top["id"])["result"] == before["data"], "data after stepBack")

# A data breakpoint on buf: stops where it is next written, with a new value.
scopes = c.request("scopes", {"frameId": top["id"]})["body"]["scopes"]
info = c.request("dataBreakpointInfo", {"variablesReference": scopes[1]["variablesReference"],
                                        "name": "buf"})["body"]
check(info.get("dataId") == "A:buf", f"dataBreakpointInfo buf: {info}")
check("write" in info.get("accessTypes", []), f"dataBreakpointInfo access: {info}")
nothing = c.request("dataBreakpointInfo", {"name": "1 + 2", "frameId": top["id"]})["body"]
check(nothing.get("dataId") is None and nothing.get("description"), f"dataBreakpointInfo of a number: {nothing}")
r = c.request("setDataBreakpoints", {"breakpoints": [{"dataId": info["dataId"], "accessType": "write"}]})
dbs = r["body"]["breakpoints"]
check(len(dbs) == 1 and dbs[0]["verified"], f"setDataBreakpoints: {dbs}")
# The client sends the whole list again on any change: the same dataId
# keeps its data breakpoint (same id), a new one is added beside it.
again = c.request("setDataBreakpoints", {"breakpoints": [
    {"dataId": info["dataId"], "accessType": "write"}, {"dataId": "cnt", "accessType": "write"}]})
kept = again["body"]["breakpoints"]
check(len(kept) == 2 and kept[0].get("id") == dbs[0].get("id") and kept[1]["verified"]
      and kept[1].get("id") != dbs[0].get("id"), f"setDataBreakpoints again: {kept}")
r = c.request("setDataBreakpoints", {"breakpoints": [{"dataId": info["dataId"], "accessType": "write"}]})
check(r["body"]["breakpoints"][0].get("id") == dbs[0].get("id"), f"setDataBreakpoints dropping cnt: {r}")
old = c.evaluate("buf", top["id"])["result"]
c.request("continue", {"threadId": 1})
stop = c.stopped("data breakpoint")
check(stop.get("hitBreakpointIds") == [dbs[0].get("id")], f"data breakpoint ids: {stop}")
check("old value" in stop.get("text", "") and "new value" in stop.get("text", ""), f"old and new: {stop}")
frames = c.frames()
new = c.evaluate("buf", frames[0]["id"])["result"]
check(new != old and new.startswith('"crgrcrgr"'), f"buf written: {old} -> {new}")
check(frames[0]["line"] == 195 and "written by line 195" in stop.get("description", ""),
      f"the write at line 195: {frames[0]}, {stop}")
watch_tick = tick_of(stop)

# reverseContinue: back over the write first (the data breakpoint stops
# before it, as gdb's reverse-continue does: buf as it was, the values in
# the order they are met going back), then to the breakpoint.
c.request("reverseContinue", {"threadId": 1})
stop = c.stopped("data breakpoint")
check(stop.get("hitBreakpointIds") == [dbs[0].get("id")] and tick_of(stop) < watch_tick,
      f"reverseContinue to the write: {stop}")
frames = c.frames()
check(frames[0]["line"] == 195 and c.evaluate("buf", frames[0]["id"])["result"] == old,
      f"before the write: {frames[0]}")
c.request("reverseContinue", {"threadId": 1})
stop = c.stopped("breakpoint")
check(tick_of(stop) == 83150170 and tick_of(stop) < watch_tick, f"reverseContinue: {stop}")
check(stop.get("hitBreakpointIds") == [bp_id], f"reverseContinue's breakpoint id: {stop}")
frames = c.frames()
check(frames[0]["name"].startswith("INT1(") and frames[0]["line"] == 191, f"after reverseContinue: {frames[0]}")
check(c.evaluate("buf", frames[0]["id"])["result"] == old, "buf as it was before the write")

# Going to a time from the debug console: evaluate "goto 9s" (repl).
r = c.request("evaluate", {"expression": "goto 9s", "context": "repl"})
check(r["success"] and "going to tick 82944000" in r["body"]["result"], f"goto 9s: {r}")
stop = c.stopped("goto")
check(82944000 <= tick_of(stop) < 82944000 + 1000, f"goto 9s: {stop}")
c.finish()

# ---- session 2 -----------------------------------------------------------------

c = Client()
start(c, {"program": ICEMAN, "opponent": FIG92, "seed": 3, "seconds": 20, "stopOnEntry": True})
c.request("configurationDone")
stop = c.stopped("entry")
check(tick_of(stop) == 0, f"entry at tick 0: {stop}")
frames = c.frames()
check(frames and frames[0]["line"] == 21, f"entry frame: {frames}")

r = c.request("setBreakpoints", {"source": {"path": ICEMAN},
                                 "breakpoints": [{"line": 191, "hitCondition": "2"},
                                                 {"line": 99999},
                                                 {"line": 195, "condition": "data =="},
                                                 {"line": 198, "hitCondition": "often"}]})
bps = r["body"]["breakpoints"]
check(len(bps) == 4, f"setBreakpoints: one answer each: {bps}")
check(bps[0]["verified"] and bps[0]["line"] == 191, f"hit-count breakpoint: {bps[0]}")
for k in (1, 2, 3):
    check(not bps[k]["verified"] and bps[k].get("message"), f"refused breakpoint {k}: {bps[k]}")
r = c.request("setBreakpoints", {"source": {"path": "/elsewhere/other.dc"}, "breakpoints": [{"line": 3}]})
check(not r["body"]["breakpoints"][0]["verified"], f"a file of no robot: {r['body']}")
r = c.request("setFunctionBreakpoints", {"breakpoints": [{"name": "no_such_function"}]})
check(not r["body"]["breakpoints"][0]["verified"], f"function breakpoint refused: {r['body']}")
r = c.request("setFunctionBreakpoints", {"breakpoints": [{"name": "B:main"}]})
fb = r["body"]["breakpoints"][0]
check(fb["verified"] and fb["source"]["path"] == FIG92, f"B:main: {fb}")

# B's main is entered at once: the hold moves to B (thread 2).
c.request("continue", {"threadId": 1})
stop = c.stopped("function breakpoint", thread=2)
check(stop.get("hitBreakpointIds") == [fb["id"]], f"B:main's id: {stop}")
frames = c.frames(thread=2)
check(frames[0]["name"].startswith("main(") and frames[0]["source"]["path"] == FIG92, f"B's frame: {frames[0]}")
scopes = c.request("scopes", {"frameId": frames[0]["id"]})["body"]["scopes"]
b_globals = {v["name"] for v in
             c.request("variables", {"variablesReference": scopes[1]["variablesReference"]})["body"]["variables"]}
check({"ammo", "left", "right", "sum"} <= b_globals, f"B's globals: {sorted(b_globals)}")
info = c.request("dataBreakpointInfo", {"name": "ammo", "frameId": frames[0]["id"]})["body"]
check(info.get("dataId") == "B:ammo", f"B's ammo: {info}")
a_frames = c.frames(thread=1)
info = c.request("dataBreakpointInfo", {"name": "buf", "frameId": a_frames[0]["id"]})["body"]
check(info.get("dataId") == "A:buf", f"A's variable while B is held: {info}")
c.request("setFunctionBreakpoints", {"breakpoints": []})
# A data breakpoint on A's buf while B is held: A's first strcpy into buf
# stops A (thread 1).
r = c.request("setDataBreakpoints", {"breakpoints": [{"dataId": "A:buf", "accessType": "write"}]})
a_buf = r["body"]["breakpoints"][0]
check(a_buf.get("verified"), f"A:buf set while B is held: {a_buf}")
c.request("continue", {"threadId": 2})
stop = c.stopped("data breakpoint", thread=1)
check(stop.get("hitBreakpointIds") == [a_buf.get("id")] and "written by line" in
      stop.get("description", ""), f"A's buf written with B held: {stop}")
c.request("setDataBreakpoints", {"breakpoints": []})

# Stepping A's thread moves the hold back to A.
c.request("next", {"threadId": 1})
stop = c.stopped("step", thread=1)

c.request("continue", {"threadId": 1})
stop = c.stopped("breakpoint")
check(tick_of(stop) > 83150170, f"hitCondition 2: the second entry into INT1: {stop}")
check(c.frames()[0]["line"] == 191, "at INT1's first line")

r = c.request("setBreakpoints", {"source": {"path": ICEMAN},
                                 "breakpoints": [{"line": 193, "condition": "data == 1000"}]})
check(r["body"]["breakpoints"][0]["verified"], f"conditional breakpoint: {r['body']}")
c.request("continue", {"threadId": 1})
stop = c.stopped("step")
check("match is over" in stop.get("description", ""), f"the end of the match: {stop}")
check(tick_of(stop) >= 20 * 9216000, f"the end at 20 s: {stop}")
c.frames()  # still inspectable
c.request("continue", {"threadId": 1})
c.event("terminated")
c.finish()

# ---- session 2b: a data breakpoint on an auto, removed by the adapter -----------------

# tests/debug/inspect.dc (#class auto): at depth()'s first entry, a data
# breakpoint on its auto `twice` stops where line 29 writes it (n = 3:
# twice = 6); the deeper calls write their own `twice`; when this call
# returns the adapter removes the breakpoint, says so with a `breakpoint`
# event (reason removed) and stops there, with no hit.
c = Client()
start(c, {"program": os.path.join(os.path.dirname(os.path.abspath(__file__)), "debug/inspect.dc"),
          "seconds": 1, "stopOnEntry": True})
c.request("configurationDone")
c.stopped("entry")
fb = c.request("setFunctionBreakpoints", {"breakpoints": [{"name": "depth"}]})["body"]["breakpoints"][0]
c.request("continue", {"threadId": 1})
c.stopped("function breakpoint")
top = c.frames()[0]
c.request("setFunctionBreakpoints", {"breakpoints": []})
info = c.request("dataBreakpointInfo", {"name": "twice", "frameId": top["id"]})["body"]
check(info.get("dataId") == "A:twice", f"dataBreakpointInfo of depth's twice: {info}")
r = c.request("setDataBreakpoints", {"breakpoints": [{"dataId": "A:twice", "accessType": "write"}]})
auto_id = r["body"]["breakpoints"][0].get("id")
c.request("continue", {"threadId": 1})
stop = c.stopped("data breakpoint")
check(stop.get("hitBreakpointIds") == [auto_id] and
      c.evaluate("twice", c.frames()[0]["id"])["result"] == "6", f"depth's twice written: {stop}")
c.request("continue", {"threadId": 1})
removed = c.event("breakpoint")["body"]
check(removed.get("reason") == "removed" and removed["breakpoint"].get("id") == auto_id,
      f"the auto's data breakpoint removed: {removed}")
stop = c.stopped("data breakpoint")
check("hitBreakpointIds" not in stop and "deleted" in stop.get("description", ""),
      f"the stop where depth() returned: {stop}")
c.request("continue", {"threadId": 1})
c.stopped("step")  # the end of the run
c.finish()

# ---- session 3: a broken or hostile client ------------------------------------------


def framed(body, header=None):
    body = body if isinstance(body, bytes) else json.dumps(body).encode()
    return (header if header is not None else b"Content-Length: %d\r\n\r\n" % len(body)) + body


def answered(client, what):
    """A good request after a bad one is answered."""
    r = client.request("initialize", {"adapterID": "simbot"})
    check(r["body"].get("supportsStepBack") is True, f"initialize after {what}: {r}")


c = Client()
# 150,000 nested arrays in a 300-KB request (once a SIGSEGV in a recursive
# copy): refused as the JSON is parsed, without recursion.
n = c.next_seq()
deep = b'{"seq":%d,"type":"request","command":"evaluate","arguments":' % n + \
    b"[" * 150000 + b"]" * 150000 + b"}"
check(len(deep) > 300000, f"the nested request is {len(deep)} bytes")
c.raw(framed(deep))
c.refused(n, "evaluate", "nested more than 64 deep")
answered(c, "150,000 nested arrays")
# The same depth under a key of the arguments object.
n = c.next_seq()
c.raw(framed(b'{"seq":%d,"type":"request","command":"launch","arguments":{"program":' % n +
             b"[" * 150000 + b"]" * 150000 + b"}}"))
c.refused(n, "launch", "nested more than 64 deep")
# Wide rather than deep: 350,000 empty objects in 1 MB are built in one
# pass (nlohmann's parser callback would scan the array at each one's end:
# hours).
n = c.next_seq()
c.raw(framed(b'{"seq":%d,"type":"request","command":"threads","arguments":{"x":[' % n +
             b"{}," * 350000 + b'{}]}}'))
check(c.response(n, "threads").get("success") is True, "threads with 350,000 objects in its arguments")
# Fields of the wrong type (once "internal error", exit 2).
n = c.next_seq()
c.raw(framed({"type": 5, "seq": n, "command": "threads"}))
c.refused(n, "threads", "'type' must be")
c.raw(framed({"seq": "abc", "type": "request", "command": "threads"}))
c.refused(0, "threads", "'seq' must be an integer")
n = c.next_seq()
c.raw(framed({"seq": n, "type": "request", "command": "threads", "arguments": [1, 2]}))
c.refused(n, "threads", "'arguments' must be an object")
n = c.next_seq()
c.raw(framed({"seq": n, "type": "request", "command": 7}))
c.refused(n, "", "'command' must be")
n = c.next_seq()
c.raw(framed({"seq": n, "type": "request", "command": "launch", "arguments": {"program": 5}}))
c.refused(n, "launch", "'program' must be a string")
n = c.next_seq()
c.raw(framed({"seq": n, "type": "request", "command": "launch",
              "arguments": {"program": ICEMAN, "stopOnEntry": "yes"}}))
c.refused(n, "launch", "'stopOnEntry' must be true or false")
answered(c, "fields of the wrong type")
# Framing: after a Content-Length that is no count (once the end of all
# answers), the body is read up to its closing brace and answered.
for bad in [b"abc", b"-5", b"99999999999999999999999"]:
    n = c.next_seq()
    c.raw(framed({"seq": n, "type": "request", "command": "threads"},
                 b"Content-Length: " + bad + b"\r\n\r\n"))
    c.refused(n, "threads", "Content-Length")
    answered(c, b"Content-Length: " + bad)
    answered(c, b"Content-Length: " + bad + b" (twice)")
# A count over the 4-MB limit, honest or not: refused, not read.
n = c.next_seq()
c.raw(framed({"seq": n, "type": "request", "command": "threads"}, b"Content-Length: 5000000\r\n\r\n"))
c.refused(n, "threads", "over the limit of 4194304 bytes")
answered(c, "a Content-Length over the limit")
# No Content-Length at all, and an unknown header beside a good one.
n = c.next_seq()
c.raw(framed({"seq": n, "type": "request", "command": "threads"}, b"X-Thing: 1\r\n\r\n"))
c.output("header 'X-Thing' ignored")
c.refused(n, "threads", "without Content-Length")
n = c.next_seq()
body = json.dumps({"seq": n, "type": "request", "command": "threads"}).encode()
c.raw(b"Content-Type: application/json\r\nContent-Length: %d\r\n\r\n" % len(body) + body)
c.output("header 'Content-Type' ignored")
check(c.response(n, "threads").get("success") is True, "threads beside an unknown header")
# A Content-Length larger than its body: the next message is found inside.
n = c.next_seq()
body = json.dumps({"seq": n, "type": "request", "command": "threads"}).encode()
c.raw(b"Content-Length: %d\r\n\r\n" % (len(body) + 30) + body)
answered(c, "a Content-Length larger than its body")
c.refused(n, "threads", "a Content-Length of")
# A body that is not JSON, a line that is not a header, a message that is
# not an object: a line on stderr each (nothing names a request).
c.raw(framed(b"hello"))
c.output("not JSON")
answered(c, "a body that is not JSON")
c.raw(b"this is not a header\r\n")
c.output("is not a header line")
answered(c, "a line that is not a header")
c.raw(framed(b"[1, 2, 3]"))
c.output("must be a JSON object")
c.raw(framed(b"{}"))
c.output("'type' must be")
answered(c, "messages that are not requests")

# Arguments of the wrong type or range at a stop.
c.request("launch", {"program": ICEMAN, "seconds": 5, "stopOnEntry": True})
c.event("initialized")
c.request("configurationDone")
c.stopped("entry")
frames = c.frames()
for arguments, words in [
        ({"threadId": "1"}, "'threadId' must be an integer from 1 to 1"),
        ({"threadId": 2}, "'threadId' must be an integer from 1 to 1"),
        ({"threadId": 1, "levels": -1}, "'levels' must be an integer"),
        ({"threadId": 1, "startFrame": 1.5}, "'startFrame' must be an integer")]:
    r = c.request("stackTrace", arguments, success=False)
    check(words in r.get("message", ""), f"stackTrace {arguments}: {r.get('message')!r}")
big = 2**63 - 1
r = c.request("stackTrace", {"threadId": 1, "startFrame": 1, "levels": big})
check(len(r["body"]["stackFrames"]) == len(frames) - 1, f"stackTrace levels 2^63-1: {r['body']}")
r = c.request("stackTrace", {"threadId": 1, "startFrame": big})
check(r["body"]["stackFrames"] == [], f"stackTrace startFrame 2^63-1: {r['body']}")
for arguments, words in [({"frameId": 1e300}, "'frameId' must be an integer"),
                         ({"frameId": 2**62}, "no frame"),
                         ({"frameId": -1}, "'frameId' must be an integer"),
                         ({"frameId": 2**64}, "'frameId' must be an integer")]:
    r = c.request("scopes", arguments, success=False)
    check(words in r.get("message", ""), f"scopes {arguments}: {r.get('message')!r}")
scopes = c.request("scopes", {"frameId": frames[0]["id"]})["body"]["scopes"]
globals_ref = scopes[1]["variablesReference"]
everything = c.request("variables", {"variablesReference": globals_ref})["body"]["variables"]
r = c.request("variables", {"variablesReference": globals_ref, "start": 1, "count": big})
check(r["body"]["variables"] == everything[1:], "variables start 1, count 2^63-1")
for arguments, words in [({"variablesReference": -1}, "'variablesReference' must be"),
                         ({"variablesReference": "1"}, "'variablesReference' must be"),
                         ({"variablesReference": globals_ref, "count": -3}, "'count' must be")]:
    r = c.request("variables", arguments, success=False)
    check(words in r.get("message", ""), f"variables {arguments}: {r.get('message')!r}")
for arguments, words in [({"source": {"path": ICEMAN}, "breakpoints": [{"line": "abc"}]}, "'line' must be"),
                         ({"source": {"path": ICEMAN}, "breakpoints": [{"line": 1e300}]}, "'line' must be"),
                         ({"source": {"path": ICEMAN}, "breakpoints": [{"line": 0}]}, "'line' must be"),
                         ({"source": {"path": ICEMAN}, "breakpoints": [7]}, "array of objects"),
                         ({"source": {"path": ICEMAN}, "breakpoints": {"line": 3}}, "must be an array"),
                         ({"source": "iceman.dc", "breakpoints": []}, "'source' must be an object"),
                         ({"source": {"path": ICEMAN}, "breakpoints": [{"line": 191, "condition": 1}]},
                          "'condition' must be a string"),
                         ({"source": {"path": ICEMAN}, "breakpoints": [{"line": 191}] * 1001},
                          "at most 1000")]:
    r = c.request("setBreakpoints", arguments, success=False)
    check(words in r.get("message", ""), f"setBreakpoints {str(arguments)[:80]}: {r.get('message')!r}")
r = c.request("setFunctionBreakpoints", {"breakpoints": [{"name": 3}]}, success=False)
check("'name' must be a string" in r.get("message", ""), f"setFunctionBreakpoints: {r}")
r = c.request("next", {"threadId": 2**32 + 1}, success=False)
check("'threadId'" in r.get("message", ""), f"next threadId 2^32+1: {r}")
r = c.request("evaluate", {"expression": 5}, success=False)
check("'expression' must be a string" in r.get("message", ""), f"evaluate 5: {r}")
r = c.request("evaluate", {"expression": "(" * 400 + "1" + ")" * 400}, success=False)
check("nested too deeply" in r.get("message", ""), f"evaluate of 400 parentheses: {r.get('message', '')[:80]}")
# Still at the entry, still answering.
check(c.evaluate("count", frames[0]["id"])["result"] is not None, "evaluate after the refusals")
c.finish()
check(b"internal error" not in c.stderr, f"stderr: {c.stderr[-300:]!r}")

# ---- session 4: the input ends inside a message -----------------------------------

c = Client()
answered(c, "nothing")
c.raw(b'Content-Length: 100\r\n\r\n{"seq": 9')
c.proc.stdin.close()
c.output("the input ended 9 bytes into a message of 100")
check(c.proc.wait(timeout=TIMEOUT) == 0, "exit status after a truncated message")

# ---- session 5: pause, terminate and disconnect while a long match runs ------------

LONG = {"program": ICEMAN, "opponent": FIG92, "seed": 3, "seconds": 600, "stopOnEntry": True}


def run_long():
    """A continue that runs for a minute or more in any build: a data
    breakpoint on ICEMAN's global s, which it declares and never writes,
    makes the session step every instruction (the 600-s match alone runs
    in about a second here: too short to stop for sure in its middle).
    Not i: fire() writes it, and seed 3 reaches fire() at 21.03 s, which
    a fast host stepped to before the pause came."""
    client = Client()
    start(client, LONG)
    client.request("configurationDone")
    client.stopped("entry")
    r = client.request("setDataBreakpoints", {"breakpoints": [{"dataId": "s", "accessType": "write"}]})
    check(r["body"]["breakpoints"][0].get("verified") is True, f"a data breakpoint on s: {r['body']}")
    client.request("continue", {"threadId": 1})
    time.sleep(0.5)
    check(not any(e["event"] == "stopped" for e in client.events), "the long match runs")
    return client


c = run_long()
c.request("pause", {"threadId": 1})
stop = c.stopped("pause")
paused_at = tick_of(stop)
check(0 < paused_at < 600 * 9216000, f"paused inside the match: {stop}")
check(c.frames()[0]["line"] > 0, "frames at the pause")
c.request("pause", {"threadId": 1}, success=False)  # stopped already
c.finish()

c = run_long()
began = time.monotonic()
c.request("terminate")
c.event("terminated")
terminate_s = time.monotonic() - began
check(terminate_s < 2, f"terminate during a continue took {terminate_s:.3f} s")
c.finish()

c = run_long()
began = time.monotonic()
n = c.send("disconnect", {"terminateDebuggee": True})
r = c.response(n, "disconnect")
check(r.get("success") is True, f"disconnect: {r}")
try:
    status = c.proc.wait(timeout=TIMEOUT)
except subprocess.TimeoutExpired:
    c.proc.kill()
    raise SystemExit("FAIL: simbot dap did not exit after disconnect")
disconnect_s = time.monotonic() - began
check(status == 0, f"exit status {status} after disconnect")
check(disconnect_s < 2, f"disconnect during a continue took {disconnect_s:.3f} s to exit")
check(not any(e["event"] == "stopped" for e in c.events), "no stopped event before the disconnect's answer")
print(f"disconnect during a continue: exit {disconnect_s:.3f} s after it was sent; "
      f"terminate answered in {terminate_s:.3f} s")

if failures:
    print(f"{len(failures)} check(s) failed")
    sys.exit(1)
print("simbot dap: all checks passed")
