#!/usr/bin/env python3
"""simbot dap: a small Debug Adapter Protocol client drives real sessions.

Usage: dap_test.py SIMBOT ICEMAN FIG92

Session 1 (ICEMAN vs fig92, seed 3; the edge handler INT1 is entered first
at tick 83150170): a breakpoint on INT1's first line (191); the stop, its
stack (INT1 at 191 over platform at 220), scopes and variables (the global
buf, a char[9], with its 9 elements), evaluate in two frames, next, then
stepBack to the same line and values, a data breakpoint on buf that stops
where it is written with a new value, reverseContinue back to the
breakpoint, disconnect.

Session 2 (the same match, 20 s, stopOnEntry): the entry stop; breakpoints
refused with a message (no such line, a bad condition, no such function);
a hit count (the second entry into INT1); stepping robot B's thread (the
hold moves to B); a condition that is never true runs the match to its
end; continuing past the end ends the session (terminated).

Every response's success and contents are checked.
"""
import json
import os
import queue
import re
import subprocess
import sys
import threading

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

    def request(self, command, arguments=None, success=True):
        """The response to one request (events on the way are kept)."""
        seq = self.send(command, arguments)
        while True:
            m = self._next()
            if m.get("type") == "event":
                self.events.append(m)
                continue
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
check(info.get("dataId") == "buf", f"dataBreakpointInfo buf: {info}")
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

# reverseContinue: back to the breakpoint before the write.
c.request("reverseContinue", {"threadId": 1})
stop = c.stopped("breakpoint")
check(tick_of(stop) == 83150170 and tick_of(stop) < watch_tick, f"reverseContinue: {stop}")
frames = c.frames()
check(frames[0]["name"].startswith("INT1(") and frames[0]["line"] == 191, f"after reverseContinue: {frames[0]}")
check(c.evaluate("buf", frames[0]["id"])["result"] == old, "buf as it was before the write")
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
check(info.get("dataId") == "ammo", f"B's ammo: {info}")
a_frames = c.frames(thread=1)
info = c.request("dataBreakpointInfo", {"name": "buf", "frameId": a_frames[0]["id"]})["body"]
check(info.get("dataId") is None, f"A's variable while B is held: {info}")
c.request("setFunctionBreakpoints", {"breakpoints": []})

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

if failures:
    print(f"{len(failures)} check(s) failed")
    sys.exit(1)
print("simbot dap: all checks passed")
