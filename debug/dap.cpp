// debug/dap.cpp -- simbot dap (dap.h): the Debug Adapter Protocol's
// requests answered from a session's accessors, its resuming requests
// turned into Resume commands.
#include "debug/dap.h"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <filesystem>
#include <istream>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <ostream>
#include <set>

#include "debug/dap_wire.h"
#include "debug/trim.h"

namespace simbot::debug {

namespace {

using nlohmann::json;

// The largest line number, frame id and variables reference a request
// may name (a program has far fewer lines; ids are this adapter's).
constexpr int64_t kMaxLine = std::numeric_limits<int32_t>::max();
constexpr int64_t kMaxId = std::numeric_limits<int64_t>::max();
// Breakpoints one request may set (a client sends one file's, or all its
// function or data breakpoints), and the longest source path it may name
// (Linux's PATH_MAX): each answer echoes its source.
constexpr size_t kMaxBreakpoints = 1000;
constexpr size_t kMaxPathBytes = 4096;

std::string absolutePath(const std::string& path) {
  std::error_code ec;
  const auto a = std::filesystem::absolute(path, ec);
  return ec ? path : a.lexically_normal().string();
}

bool samePath(const std::string& a, const std::string& b) {
  std::error_code ea, eb;
  const auto ca = std::filesystem::weakly_canonical(a, ea);
  const auto cb = std::filesystem::weakly_canonical(b, eb);
  return !ea && !eb && ca == cb;
}

// A hit condition: "N", ">=N" or "==N" stop from the N-th hit on, ">N"
// after the N-th. The hits to pass over first.
int hitsToIgnore(const std::string& text) {
  std::string t = trim(text, " \t\r\n");
  int extra = 0;
  if (t.rfind(">=", 0) == 0 || t.rfind("==", 0) == 0) {
    t = trim(t.substr(2), " \t\r\n");
  } else if (t.rfind('>', 0) == 0) {
    t = trim(t.substr(1), " \t\r\n");
    extra = 1;
  }
  int n = 0;
  const auto [end, error] = std::from_chars(t.data(), t.data() + t.size(), n);
  if (t.empty() || error != std::errc() || end != t.data() + t.size() || n < 1 - extra)
    throw Error(
        fmt::format("hit condition '{}': write a count N (stop from the N-th hit on)", text));
  return n - 1 + extra;
}

// An expression a member or element is appended to: a bare name or postfix
// chain as it is, anything else in parentheses.
std::string operand(const std::string& e) {
  const bool simple = !e.empty() && e.find_first_of("*&@ +-/%!<>=|") == std::string::npos;
  return simple ? e : "(" + e + ")";
}

// A child's expression from its parent's and its suffix ("[3]", ".x", "*").
std::string childExpression(const std::string& parent, const std::string& suffix) {
  if (suffix == "*") return "*" + operand(parent);
  return operand(parent) + suffix;
}

// The name the client shows for a child ("[3]", "x", "*p").
std::string childLabel(const std::string& parent, const std::string& suffix) {
  if (suffix == "*") return "*" + operand(parent);
  if (!suffix.empty() && suffix[0] == '.') return suffix.substr(1);
  return suffix;
}

bool isForward(Resume::Kind k) {
  return k == Resume::Kind::Continue || k == Resume::Kind::Step || k == Resume::Kind::Next ||
         k == Resume::Kind::Finish || k == Resume::Kind::StepInstruction;
}

// A string argument, "" when absent (Error if it is not a string).
std::string text(const json& args, const char* key) {
  return stringArgument(args, key).value_or("");
}

// A request's array of breakpoints (Error if it is not one, or too
// long; empty when absent).
const json& list(const json& args, const char* key) {
  static const json none = json::array();
  const json* a = arrayArgument(args, key);
  if (a && a->size() > kMaxBreakpoints)
    throw Error(fmt::format("'{}': at most {} in one request", key, kMaxBreakpoints));
  return a ? *a : none;
}

}  // namespace

struct DapServer::Impl {
  // A variables reference: a frame's locals or globals, or an aggregate's
  // members (with the expression that names it, for its children's).
  struct Handle {
    enum class Kind : uint8_t { Locals, Globals, Children };
    Kind kind = Kind::Locals;
    int robot = 0, frame = 0;
    inspect::Value value;
    std::string expression;
  };

  std::istream& input;
  std::ostream& output;
  Launcher launcher;
  std::unique_ptr<DapInbox> inbox;  // while serve() runs
  int64_t seq = 1;
  LaunchRequest launchRequest;
  bool configured = false;  // configurationDone came
  bool disconnected = false;
  bool terminatedSent = false;
  // Breakpoints the client set, by the request that set them: the
  // session's ids. One DAP breakpoint on a file both robots run is a
  // breakpoint in each; the client knows it by the first one's id.
  std::map<std::string, std::vector<int>> lineBreakpoints;  // by source path
  std::vector<int> functionBreakpoints, dataBreakpoints;
  std::map<int, std::string> dataIds;  // a data breakpoint's session id -> the client's dataId
  std::map<int, int> dapId;            // session id -> the id the client knows
  std::set<int> functionIds;
  std::map<int64_t, Handle> handles;
  int64_t nextHandle = 1;
  std::optional<Resume> pending;  // a step for another robot, after the hold moves
  Resume::Kind last = Resume::Kind::Continue;
  std::optional<Stop> pauseStop;  // a stop a pause made, reported as it is answered
  bool quitByInterrupt = false;   // a disconnect or terminate ended the session as it ran

  Impl(std::istream& i, std::ostream& o, Launcher l)
      : input(i), output(o), launcher(std::move(l)) {}

  // ---- the wire ---------------------------------------------------------------

  void send(json message) {
    message["seq"] = seq++;
    const std::string body = message.dump(-1, ' ', false, json::error_handler_t::replace);
    output << "Content-Length: " << body.size() << "\r\n\r\n" << body;
    output.flush();
  }

  void respond(const DapIncoming& request, const json& body = json::object()) {
    json r = {{"type", "response"},
              {"request_seq", request.seq},
              {"success", true},
              {"command", request.command}};
    if (!body.is_null()) r["body"] = body;
    send(std::move(r));
  }

  void fail(const DapIncoming& request, const std::string& message) {
    send({{"type", "response"},
          {"request_seq", std::max<int64_t>(request.seq, 0)},
          {"success", false},
          {"command", request.command},
          {"message", message}});
  }

  void event(const std::string& name, const json& body = nullptr) {
    json e = {{"type", "event"}, {"event", name}};
    if (!body.is_null()) e["body"] = body;
    send(std::move(e));
  }

  void log(const std::string& line, const char* category = "console") {
    event("output", {{"category", category}, {"output", line}});
  }

  // A message that cannot be used: an error response when it names a
  // request, else a line on the client's stderr.
  void answerProblem(const DapIncoming& m) {
    if (m.seq >= 0 || !m.command.empty())
      fail(m, m.problem);
    else
      log("simbot dap: " + m.problem + "\n", "stderr");
  }

  void terminated() {
    if (terminatedSent) return;
    terminatedSent = true;
    event("terminated");
  }

  // ---- before the session ------------------------------------------------------

  json capabilities() const {
    return {{"supportsConfigurationDoneRequest", true},
            {"supportsConditionalBreakpoints", true},
            {"supportsHitConditionalBreakpoints", true},
            {"supportsFunctionBreakpoints", true},
            {"supportsStepBack", true},
            {"supportsDataBreakpoints", true},
            {"supportsEvaluateForHovers", true},
            {"supportsSteppingGranularity", true},
            {"supportsTerminateRequest", true},
            {"exceptionBreakpointFilters", json::array()}};
  }

  LaunchRequest launchArguments(const json& args) const {
    LaunchRequest r;
    r.program = text(args, "program");
    if (r.program.empty()) throw Error("launch needs 'program': robot A's file");
    r.opponent = text(args, "opponent");
    r.scenario = text(args, "scenario");
    if (const std::string p = text(args, "profile"); !p.empty()) r.profile = p;
    if (const std::string robot = text(args, "robot"); !robot.empty()) r.robot = robot;
    r.cwd = text(args, "cwd");
    r.length = runLengthArgument(args, "seconds");
    r.seed = unsignedArgument(args, "seed");
    r.stopOnEntry = boolArgument(args, "stopOnEntry").value_or(false);
    return r;
  }

  int serve(DapServer& self) {
    inbox = std::make_unique<DapInbox>(input);
    while (!disconnected) {
      const DapIncoming m = inbox->take();
      if (m.kind == DapIncoming::Kind::End) break;
      if (m.kind == DapIncoming::Kind::Problem) {
        answerProblem(m);
        continue;
      }
      try {
        serveOne(self, m);
      } catch (const Error& e) {
        fail(m, e.what());
      } catch (const std::exception& e) {
        fail(m, fmt::format("bad request: {}", e.what()));
      }
    }
    inbox.reset();
    return 0;
  }

  // One request before (or after) the session.
  void serveOne(DapServer& self, const DapIncoming& m) {
    const std::string& command = m.command;
    if (command == "initialize") {
      respond(m, capabilities());
    } else if (command == "launch") {
      if (terminatedSent) return fail(m, "this adapter has run its session; start another");
      std::optional<Launched> run;
      int held = -1;
      try {
        launchRequest = launchArguments(m.arguments);
        run = launcher(launchRequest);
        for (size_t i = 0; i < run->config.robots.size(); ++i)
          if (run->config.robots[i].name == launchRequest.robot) held = static_cast<int>(i);
        if (held < 0)
          throw Error(fmt::format("'robot': this run has no robot '{}'", launchRequest.robot));
      } catch (const std::exception& e) {
        return fail(m, trim(e.what(), " \t\r\n"));
      }
      respond(m);
      event("initialized");
      // A pause or disconnect that came before the launch is not meant to
      // stop the run at its first round (one waiting is read at the
      // first stop).
      inbox->interrupt()->store(false);
      try {
        Session session(run->config, run->programs, held);
        session.run(self, inbox->interrupt());
      } catch (const std::exception& e) {
        log(trim(e.what(), " \t\r\n") + "\n");
      }
      handles.clear();
      // The terminate that stopped the session sends the event as it is
      // answered, next.
      if (!disconnected && !quitByInterrupt) terminated();
    } else if (command == "disconnect") {
      respond(m);
      disconnected = true;
    } else if (command == "terminate") {
      respond(m);
      terminated();
    } else if (command == "attach") {
      fail(m, "simbot dap launches its run (request \"launch\"); it does not attach");
    } else if (command == "threads") {
      respond(m, {{"threads", json::array()}});
    } else if (command == "setExceptionBreakpoints") {
      respond(m, {{"breakpoints", json::array()}});
    } else {
      fail(m, terminatedSent ? "the session is over" : "launch first");
    }
  }

  // ---- at a stop --------------------------------------------------------------

  Resume stopped(Session& s, const Stop& why) {
    handles.clear();
    for (const std::string& notice : s.takeNotices()) log(notice + "\n");
    if (pending) {
      const Resume how = *pending;
      pending.reset();
      if (why.kind == Stop::Kind::Goto) {
        last = how.kind;
        return how;
      }
    }
    // A stop the client's disconnect or terminate made is not reported;
    // one its pause made (the session holds the robot with a goto) is
    // reported as the pause is answered.
    pauseStop.reset();
    if (!inbox->quitWaiting() && (configured || why.kind != Stop::Kind::Entry)) {
      configured = true;
      if (why.kind == Stop::Kind::Goto && inbox->pauseNext())
        pauseStop = why;
      else
        report(s, why);
    }
    for (;;) {
      const DapIncoming m = inbox->take();
      if (m.kind == DapIncoming::Kind::End) return quit();
      if (m.kind == DapIncoming::Kind::Problem) {
        answerProblem(m);
        continue;
      }
      const bool wasConfigured = configured;
      Resume how;
      bool resumes = false;
      try {
        resumes = dispatch(s, m, how);
      } catch (const Error& e) {
        fail(m, e.what());
      } catch (const inspect::Error& e) {
        fail(m, e.what());
      } catch (const std::exception& e) {
        fail(m, fmt::format("bad request: {}", e.what()));
      }
      if (resumes) {
        last = how.kind;
        return how;
      }
      if (!wasConfigured && configured) {
        if (!launchRequest.stopOnEntry) {
          last = Resume::Kind::Continue;
          return Resume{};
        }
        report(s, why);
      }
    }
  }

  static Resume quit() {
    Resume how;
    how.kind = Resume::Kind::Quit;
    return how;
  }

  int dapIdOf(int sessionId) const {
    const auto it = dapId.find(sessionId);
    return it == dapId.end() ? sessionId : it->second;
  }

  void report(Session& s, const Stop& why, bool paused = false) {
    const int robot = s.robot();
    const std::string where =
        fmt::format("robot {} at tick {} ({})", s.robotName(robot), s.now(), secondsText(s.now()));
    json body = {{"threadId", robot + 1}, {"allThreadsStopped", true}};
    std::string reason, description, detail;
    switch (why.kind) {
      case Stop::Kind::Entry:
        reason = "entry";
        description = fmt::format("{} holds at its first instruction", where);
        break;
      case Stop::Kind::Breakpoint:
      case Stop::Kind::Event:
        reason = functionIds.count(why.breakpoint) ? "function breakpoint" : "breakpoint";
        description = fmt::format("breakpoint {}: {}", dapIdOf(why.breakpoint), where);
        if (why.kind == Stop::Kind::Event)
          description += fmt::format(" ({}: robot {} {})", scheduler::debugEventName(why.event),
                                     s.robotName(why.eventRobot), why.note);
        body["hitBreakpointIds"] = json::array({dapIdOf(why.breakpoint)});
        break;
      case Stop::Kind::Watchpoint:
        reason = "data breakpoint";
        if (why.oldValue.empty() && why.newValue.empty()) {
          description = fmt::format("data breakpoint {}: {}", why.breakpoint, where);
        } else {
          // Going backwards the robot stands before the write, the later
          // value first (as simbot debug says it).
          const std::string back =
              why.reverse ? " (going backwards: stopped before that write)" : "";
          description = fmt::format("data breakpoint {}: written by {}{}, {}", why.breakpoint,
                                    why.writer, back, where);
          detail = fmt::format("old value = {}\nnew value = {}", why.oldValue, why.newValue);
          log(fmt::format("Data breakpoint {}: written by {}{}\nOld value = {}\nNew value = {}\n",
                          why.breakpoint, why.writer, back, why.oldValue, why.newValue));
        }
        if (why.removed) {
          // The adapter removed it (its variable's call returned): the
          // client is told, as for any breakpoint it did not remove itself.
          std::erase(dataBreakpoints, why.removed);
          dataIds.erase(why.removed);
          event("breakpoint", {{"reason", "removed"},
                               {"breakpoint", {{"id", why.removed}, {"verified", false}}}});
        } else {
          body["hitBreakpointIds"] = json::array({why.breakpoint});
        }
        break;
      case Stop::Kind::Fault: {
        reason = "exception";
        const vm::Fault* f = s.vm(robot).fault();
        description =
            fmt::format("robot {} faulted at tick {} ({}), line {}", s.robotName(robot),
                        f ? f->tick : s.now(), secondsText(f ? f->tick : s.now()), f ? f->line : 0);
        detail = f ? f->message : "";
        log(fmt::format("{}: {}\n", description, detail));
        break;
      }
      case Stop::Kind::End:
        reason = "step";
        description = fmt::format("the match is over at tick {} ({}): only going back is possible",
                                  s.now(), secondsText(s.now()));
        log(description + "\n");
        break;
      case Stop::Kind::Step:
      case Stop::Kind::Time:
        reason = "step";
        description = where;
        break;
      case Stop::Kind::Goto:
        switch (last) {
          case Resume::Kind::ReverseStep:
          case Resume::Kind::ReverseNext:
          case Resume::Kind::ReverseStepInstruction:
          case Resume::Kind::ReverseFinish:
            reason = "step";
            break;
          case Resume::Kind::ReverseContinue:
            // A hit reports as a breakpoint (above); this is the start.
            reason = "goto";
            break;
          default:
            reason = "goto";
            break;
        }
        description = where;
        break;
    }
    if (!why.note.empty() && why.kind != Stop::Kind::Event) {
      description += ": " + why.note;
      log(why.note + "\n");
    }
    body["reason"] = paused ? "pause" : reason;
    body["description"] = description;
    if (!detail.empty()) body["text"] = detail;
    event("stopped", body);
  }

  // One request at a stop; true with `how` set when it resumes the robot.
  bool dispatch(Session& s, const DapIncoming& m, Resume& how) {
    const std::string& command = m.command;
    const json& args = m.arguments;
    using K = Resume::Kind;
    if (command == "configurationDone") {
      configured = true;
      respond(m);
      return false;
    }
    if (command == "threads") {
      json threads = json::array();
      for (int r = 0; r < s.robotCount(); ++r)
        threads.push_back(
            {{"id", r + 1},
             {"name", fmt::format("{} ({})", s.robotName(r), fileName(s.program(r)))}});
      respond(m, {{"threads", threads}});
      return false;
    }
    if (command == "setBreakpoints") return setBreakpoints(s, m, args), false;
    if (command == "setFunctionBreakpoints") return setFunctionBreakpoints(s, m, args), false;
    if (command == "setExceptionBreakpoints") {
      respond(m, {{"breakpoints", json::array()}});
      return false;
    }
    if (command == "dataBreakpointInfo") return dataBreakpointInfo(s, m, args), false;
    if (command == "setDataBreakpoints") return setDataBreakpoints(s, m, args), false;
    if (command == "stackTrace") return stackTrace(s, m, args), false;
    if (command == "scopes") return scopes(s, m, args), false;
    if (command == "variables") return variables(s, m, args), false;
    if (command == "evaluate") return evaluate(s, m, args, how);
    if (command == "source") {
      fail(m, "the sources are the programs' files: open them by their paths");
      return false;
    }
    if (command == "pause") {
      // The reader thread stopped the running command as the pause came:
      // the stop it made is reported now, after the answer.
      if (pauseStop) {
        respond(m);
        report(s, *pauseStop, true);
        pauseStop.reset();
      } else {
        fail(m, fmt::format("the match is stopped already (robot {} at tick {})",
                            s.robotName(s.robot()), s.now()));
      }
      return false;
    }
    if (command == "disconnect") {
      respond(m);
      disconnected = true;
      how = quit();
      return true;
    }
    if (command == "terminate") {
      respond(m);
      terminated();
      how = quit();
      return true;
    }
    if (command == "initialize" || command == "launch" || command == "attach") {
      fail(m, fmt::format("'{}': the session is running already", command));
      return false;
    }
    const bool instruction = text(args, "granularity") == "instruction";
    how = Resume{};
    if (command == "continue") {
      how.kind = K::Continue;
    } else if (command == "next") {
      how.kind = instruction ? K::StepInstruction : K::Next;
    } else if (command == "stepIn") {
      how.kind = instruction ? K::StepInstruction : K::Step;
    } else if (command == "stepOut") {
      how.kind = K::Finish;
    } else if (command == "stepBack") {
      how.kind = instruction ? K::ReverseStepInstruction : K::ReverseNext;
    } else if (command == "reverseContinue") {
      how.kind = K::ReverseContinue;
    } else {
      fail(m, fmt::format("'{}' is not supported", excerpt(command)));
      return false;
    }
    // A step of the other robot's thread: hold that robot at this tick,
    // then step it.
    int robot = s.robot();
    if (const std::optional<int64_t> thread = threadArgument(s, args);
        thread && command != "continue" && command != "reverseContinue")
      robot = static_cast<int>(*thread - 1);
    if (s.over() && isForward(how.kind)) {
      // The match has no more to run: the client's session ends here (it
      // may still step back until it disconnects).
      respond(m, command == "continue" ? json{{"allThreadsContinued", true}} : json::object());
      terminated();
      return false;
    }
    const vm::Vm& v = s.vm(robot);
    if (how.kind == K::Finish && v.callDepth() + v.interruptDepth() == 0)
      throw Error("step out: the robot is in its outermost frame");
    respond(m, command == "continue" ? json{{"allThreadsContinued", true}} : json::object());
    if (robot != s.robot()) {
      pending = how;
      // The robots stay where they are (Session::anchor), then it steps.
      how = Resume{};
      how.kind = K::Hold;
      how.robot = robot;
    }
    return true;
  }

  // A request's threadId: 1 to the number of robots (Error otherwise).
  static std::optional<int64_t> threadArgument(const Session& s, const json& args) {
    return integerArgument(args, "threadId", 1, s.robotCount());
  }

  // ---- breakpoints --------------------------------------------------------------

  void removeAll(Session& s, std::vector<int>& ids) {
    for (int id : ids) {
      try {
        s.remove(id);
      } catch (const Error&) {
        // A temporary one gone, a watchpoint whose call returned.
      }
      dapId.erase(id);
      dataIds.erase(id);
      functionIds.erase(id);
    }
    ids.clear();
  }

  // The robots whose program is at `path`: the same file, else the same
  // base name (Session::robotOf's rule).
  std::vector<int> robotsOf(const Session& s, const std::string& path) const {
    std::vector<int> found;
    for (int r = 0; r < s.robotCount(); ++r)
      if (samePath(path, s.program(r))) found.push_back(r);
    if (found.empty())
      for (int r = 0; r < s.robotCount(); ++r)
        if (fileName(path) == fileName(s.program(r))) found.push_back(r);
    return found;
  }

  json sourceOf(const Session& s, int robot) const {
    return {{"name", fileName(s.program(robot))}, {"path", absolutePath(s.program(robot))}};
  }

  // Condition and hit count of breakpoint `id` (Error: the caller removes it).
  void qualify(Session& s, int id, const json& b) {
    if (const std::string c = text(b, "condition"); !trim(c, " \t\r\n").empty())
      s.setCondition(id, trim(c, " \t\r\n"));
    if (const std::string h = text(b, "hitCondition"); !trim(h, " \t\r\n").empty())
      s.setIgnore(id, hitsToIgnore(h));
  }

  void setBreakpoints(Session& s, const DapIncoming& m, const json& args) {
    const json* given = objectArgument(args, "source");
    const json source = given ? *given : json::object();
    std::string path = text(source, "path");
    if (path.empty()) path = text(source, "name");
    if (path.size() > kMaxPathBytes)
      throw Error(fmt::format("'source': a path of at most {} bytes", kMaxPathBytes));
    // Each breakpoint's fields are read before any is set: a request
    // refused as a whole changes nothing.
    json wanted = json::array();
    if (arrayArgument(args, "breakpoints")) {
      wanted = list(args, "breakpoints");
    } else {
      for (const json& line : list(args, "lines")) wanted.push_back({{"line", line}});
    }
    std::vector<int> lines;
    for (const json& b : wanted) {
      if (!b.is_object()) throw Error("'breakpoints' must be an array of objects");
      const std::optional<int64_t> line = integerArgument(b, "line", 1, kMaxLine);
      if (!line) throw Error("a breakpoint needs its 'line'");
      lines.push_back(static_cast<int>(*line));
      text(b, "condition");
      text(b, "hitCondition");
    }
    std::vector<int>& ids = lineBreakpoints[path];
    removeAll(s, ids);
    const std::vector<int> robots = robotsOf(s, path);
    json answers = json::array();
    for (size_t k = 0; k < wanted.size(); ++k) {
      const json& b = wanted[k];
      const int line = lines[k];
      json answer = {{"verified", false}, {"line", line}, {"source", {{"path", path}}}};
      if (robots.empty()) {
        answer["message"] = fmt::format("{} is not a program of this run", fileName(path));
        answers.push_back(answer);
        continue;
      }
      std::vector<int> made;
      try {
        int first = 0, at = line;
        for (int r : robots) {
          const Breakpoint& bp = s.breakAtLine(r, line);
          const int id = bp.id;
          at = bp.line;
          made.push_back(id);
          if (!first) first = id;
          dapId[id] = first;
          qualify(s, id, b);
        }
        answer = {
            {"id", first}, {"verified", true}, {"line", at}, {"source", sourceOf(s, robots[0])}};
        ids.insert(ids.end(), made.begin(), made.end());
      } catch (const Error& e) {
        removeAll(s, made);
        answer["message"] = e.what();
      }
      answers.push_back(answer);
    }
    respond(m, {{"breakpoints", answers}});
  }

  // A function breakpoint's name: any location the terminal's `break`
  // takes (Session::breakAt): FUNCTION or ROBOT:FUNCTION (a handler too), a
  // time (12.5s, 20ms, tick N), an event (frame, edge, contact, shot,
  // fault), or a line.
  int functionBreakpoint(Session& s, const std::string& name) {
    return s.breakAt(trim(name, " \t\r\n")).id;
  }

  void setFunctionBreakpoints(Session& s, const DapIncoming& m, const json& args) {
    const json& wanted = list(args, "breakpoints");
    for (const json& b : wanted) {
      if (!b.is_object()) throw Error("'breakpoints' must be an array of objects");
      text(b, "name");
      text(b, "condition");
      text(b, "hitCondition");
    }
    removeAll(s, functionBreakpoints);
    json answers = json::array();
    for (const json& b : wanted) {
      const std::string name = text(b, "name");
      json answer = {{"verified", false}};
      std::vector<int> made;
      try {
        const int id = functionBreakpoint(s, name);
        made.push_back(id);
        qualify(s, id, b);
        answer = {{"id", id}, {"verified", true}};
        for (const Breakpoint& bp : s.breakpoints())
          if (bp.id == id && (bp.kind == Breakpoint::Kind::Function)) {
            answer["line"] = bp.line;
            answer["source"] = sourceOf(s, bp.robot);
          }
        functionBreakpoints.push_back(id);
        functionIds.insert(id);
      } catch (const Error& e) {
        removeAll(s, made);
        answer["message"] = e.what();
      }
      answers.push_back(answer);
    }
    respond(m, {{"breakpoints", answers}});
  }

  // The robot and frame a frame id names (Error if none at this stop).
  std::pair<int, int> frameOf(const Session& s, int64_t id) const {
    const int64_t robot = id / kDapFrameStride, frame = id % kDapFrameStride;
    if (id < 0 || robot >= s.robotCount() ||
        frame >= static_cast<int64_t>(s.backtrace(static_cast<int>(robot)).size()))
      throw Error(fmt::format("no frame {} at this stop", id));
    return {static_cast<int>(robot), static_cast<int>(frame)};
  }

  // The robot and frame of a request's frameId, or the held robot's
  // selected frame.
  std::pair<int, int> frameArgument(const Session& s, const json& args) const {
    if (const std::optional<int64_t> id = integerArgument(args, "frameId", 0, kMaxId))
      return frameOf(s, *id);
    return {s.robot(), s.frame()};
  }

  const Handle& handle(const json& args) const {
    const int64_t ref = integerArgument(args, "variablesReference", 0, kMaxId).value_or(0);
    const auto it = handles.find(ref);
    if (it == handles.end())
      throw Error(fmt::format("no variables reference {} at this stop", ref));
    return it->second;
  }

  void dataBreakpointInfo(Session& s, const DapIncoming& m, const json& args) {
    const std::string name = text(args, "name");
    int robot = s.robot(), frame = s.frame();
    std::string expression = name;
    if (integerArgument(args, "variablesReference", 0, kMaxId).value_or(0) != 0) {
      const Handle& h = handle(args);
      robot = h.robot;
      frame = h.frame;
      if (h.kind == Handle::Kind::Children) {
        const std::string suffix = name.empty() || name[0] == '[' ? name
                                   : name[0] == '*'               ? "*"
                                                                  : "." + name;
        expression = childExpression(h.expression, suffix);
      } else if (h.kind == Handle::Kind::Locals && frame > 0) {
        const inspect::Scope scope = s.scope(robot, frame);
        if (const vm::Symbol* fn = scope.function()) expression = fn->name + "::" + name;
      }
    } else {
      std::tie(robot, frame) = frameArgument(s, args);
    }
    json body = {{"dataId", nullptr}, {"description", ""}};
    try {
      const inspect::Scope scope = s.scope(robot, frame);
      const inspect::Value v = inspect::Expression(expression).evaluate(scope);
      if (!v.inMemory) {
        body["description"] = fmt::format("'{}' is not an object in memory", expression);
      } else {
        // The robot goes with it: a data breakpoint on either robot.
        body = {{"dataId", s.robotName(robot) + ":" + expression},
                {"description", fmt::format("{} ({})", expression, inspect::typeName(scope, v))},
                {"accessTypes", json::array({"write"})},
                {"canPersist", false}};
      }
    } catch (const inspect::Error& e) {
      body["description"] = e.what();
    }
    respond(m, body);
  }

  // The client sends the whole list each time: a data breakpoint it sent
  // before (same dataId) is kept as it is, with the object it was set on
  // and its hit count, not evaluated again in this stop's scope.
  void setDataBreakpoints(Session& s, const DapIncoming& m, const json& args) {
    const json& wantedList = list(args, "breakpoints");
    for (const json& b : wantedList) {
      if (!b.is_object()) throw Error("'breakpoints' must be an array of objects");
      text(b, "dataId");
      text(b, "accessType");
    }
    std::map<std::string, int> kept;
    for (int id : dataBreakpoints) kept[dataIds[id]] = id;
    std::vector<int> dropped;
    for (int id : dataBreakpoints) {
      bool wanted = false;
      for (const json& b : wantedList)
        wanted |= kept.count(text(b, "dataId")) && kept[text(b, "dataId")] == id;
      if (!wanted) dropped.push_back(id);
    }
    removeAll(s, dropped);
    dataBreakpoints.clear();
    json answers = json::array();
    for (const json& b : wantedList) {
      json answer = {{"verified", false}};
      try {
        const std::string access = text(b, "accessType");
        if (!access.empty() && access != "write")
          throw Error(fmt::format("only writes are watched (not {} access)", access));
        const std::string dataId = text(b, "dataId");
        const Watchpoint* existing = nullptr;
        if (const auto it = kept.find(dataId); it != kept.end())
          for (const Watchpoint& w : s.watchpoints())
            if (w.id == it->second) existing = &w;
        std::string expression = dataId;
        const int robot = s.robotOfExpression(expression);
        const Watchpoint& w = existing ? *existing : s.watch(expression, "", robot);
        dataBreakpoints.push_back(w.id);
        dataIds[w.id] = dataId;
        answer = {{"id", w.id},
                  {"verified", true},
                  {"message", fmt::format("{} (now {})", w.expression->text(), w.text)}};
      } catch (const Error& e) {
        answer["message"] = e.what();
      }
      answers.push_back(answer);
    }
    respond(m, {{"breakpoints", answers}});
  }

  // ---- frames and variables -------------------------------------------------------

  void stackTrace(Session& s, const DapIncoming& m, const json& args) {
    const int robot = static_cast<int>(threadArgument(s, args).value_or(s.robot() + 1) - 1);
    const std::vector<FrameInfo> frames = s.backtrace(robot);
    const auto total = static_cast<int64_t>(frames.size());
    const int64_t start =
        std::min(total, integerArgument(args, "startFrame", 0, kMaxId).value_or(0));
    const int64_t levels = integerArgument(args, "levels", 0, kMaxId).value_or(0);
    const int64_t end = levels > 0 && levels < total - start ? start + levels : total;
    json out = json::array();
    for (int64_t k = start; k < end; ++k) {
      const FrameInfo& f = frames[static_cast<size_t>(k)];
      std::string name =
          fmt::format("{}({})", f.function.empty() ? "<startup>" : f.function, f.arguments);
      if (f.handler) name += " [interrupt handler]";
      if (f.interrupted) name += " [interrupted here]";
      out.push_back({{"id", robot * kDapFrameStride + k},
                     {"name", name},
                     {"source", sourceOf(s, robot)},
                     {"line", f.line},
                     {"column", 1},
                     {"instructionPointerReference", fmt::format("0x{:04X}", f.pc)}});
    }
    respond(m, {{"stackFrames", out}, {"totalFrames", total}});
  }

  int64_t newHandle(Handle h) {
    const int64_t ref = nextHandle++;
    handles.emplace(ref, std::move(h));
    return ref;
  }

  void scopes(Session& s, const DapIncoming& m, const json& args) {
    const auto [robot, frame] = frameArgument(s, args);
    Handle locals;
    locals.kind = Handle::Kind::Locals;
    locals.robot = robot;
    locals.frame = frame;
    Handle globals = locals;
    globals.kind = Handle::Kind::Globals;
    json list = json::array();
    list.push_back({{"name", "Locals"},
                    {"presentationHint", "locals"},
                    {"variablesReference", newHandle(locals)},
                    {"expensive", false}});
    list.push_back(
        {{"name", "Globals"}, {"variablesReference", newHandle(globals)}, {"expensive", false}});
    respond(m, {{"scopes", list}});
  }

  json variable(const inspect::Scope& scope, int robot, int frame, const std::string& name,
                const std::string& expression, const inspect::Value& value) {
    json v = {{"name", name}, {"evaluateName", expression}, {"variablesReference", 0}};
    try {
      v["value"] = inspect::format(scope, value);
      v["type"] = inspect::typeName(scope, value);
      if (inspect::hasChildren(scope, value)) {
        Handle h;
        h.kind = Handle::Kind::Children;
        h.robot = robot;
        h.frame = frame;
        h.value = value;
        h.expression = expression;
        v["variablesReference"] = newHandle(std::move(h));
      }
    } catch (const inspect::Error& e) {
      v["value"] = fmt::format("<{}>", e.what());
    }
    return v;
  }

  void variables(Session& s, const DapIncoming& m, const json& args) {
    const Handle h = handle(args);
    const inspect::Scope scope = s.scope(h.robot, h.frame);
    json out = json::array();
    switch (h.kind) {
      case Handle::Kind::Locals: {
        const vm::Symbol* fn = scope.function();
        for (const inspect::Variable& var : inspect::locals(scope)) {
          // Named by its function outside the innermost frame, so that the
          // expression means it from any frame (a data breakpoint's).
          const std::string expression = h.frame > 0 && fn ? fn->name + "::" + var.name : var.name;
          out.push_back(variable(scope, h.robot, h.frame, var.name, expression, var.value));
        }
        break;
      }
      case Handle::Kind::Globals:
        for (const inspect::Variable& var : inspect::globals(scope))
          out.push_back(variable(scope, h.robot, h.frame, var.name, var.name, var.value));
        break;
      case Handle::Kind::Children:
        for (const inspect::Child& c : inspect::children(scope, h.value))
          out.push_back(variable(scope, h.robot, h.frame, childLabel(h.expression, c.name),
                                 childExpression(h.expression, c.name), c.value));
        break;
    }
    const auto total = static_cast<int64_t>(out.size());
    const int64_t start = std::min(total, integerArgument(args, "start", 0, kMaxId).value_or(0));
    const int64_t count = integerArgument(args, "count", 0, kMaxId).value_or(0);
    if (start > 0 || count > 0) {
      const int64_t end = count > 0 && count < total - start ? start + count : total;
      out = json(std::vector<json>(out.begin() + start, out.begin() + end));
    }
    respond(m, {{"variables", out}});
  }

  // An expression's value; in the debug console (context "repl") also
  // `goto TIME` or `goto TICK` (a time as simbot debug's goto takes it),
  // which goes there, either way, and stops: true with `how` set.
  bool evaluate(Session& s, const DapIncoming& m, const json& args, Resume& how) {
    const std::string expression = trim(text(args, "expression"), " \t\r\n");
    if (expression.empty()) throw Error("evaluate needs an expression");
    if (text(args, "context") == "repl" && expression.rfind("goto ", 0) == 0) {
      how = Resume{};
      how.kind = Resume::Kind::Goto;
      how.tick = parseTime(trim(expression.substr(5), " \t\r\n"));
      respond(m, {{"result", fmt::format("going to tick {} ({})", how.tick, secondsText(how.tick))},
                  {"variablesReference", 0}});
      last = how.kind;
      return true;
    }
    const auto [robot, frame] = frameArgument(s, args);
    const inspect::Scope scope = s.scope(robot, frame);
    const inspect::Value v = inspect::Expression(expression).evaluate(scope);
    const std::string result = inspect::format(scope, v);  // inspect::Error: the answer
    const json var = variable(scope, robot, frame, expression, expression, v);
    respond(m, {{"result", result},
                {"type", inspect::typeName(scope, v)},
                {"variablesReference", var["variablesReference"]}});
    return false;
  }
};

DapServer::DapServer(std::istream& in, std::ostream& out, Launcher launcher)
    : impl_(std::make_unique<Impl>(in, out, std::move(launcher))) {}

DapServer::~DapServer() = default;

int DapServer::serve() { return impl_->serve(*this); }

Resume DapServer::stopped(Session& session, const Stop& why) {
  return impl_->stopped(session, why);
}

void DapServer::resuming() { impl_->inbox->resuming(); }

// A disconnect or terminate stopped the command: the session ends without
// holding the robot (a replay from a snapshot) first.
bool DapServer::quitOnInterrupt() {
  impl_->quitByInterrupt = impl_->inbox->quitWaiting();
  return impl_->quitByInterrupt;
}

}  // namespace simbot::debug
