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
#include <map>
#include <nlohmann/json.hpp>
#include <ostream>
#include <set>

namespace simbot::debug {

namespace {

using nlohmann::json;

constexpr size_t kMaxMessageBytes = 16u << 20;

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

std::string trim(const std::string& s) {
  const auto a = s.find_first_not_of(" \t\r\n");
  if (a == std::string::npos) return "";
  const auto b = s.find_last_not_of(" \t\r\n");
  return s.substr(a, b - a + 1);
}

// A hit condition: "N", ">=N" or "==N" stop from the N-th hit on, ">N"
// after the N-th. The hits to pass over first.
int hitsToIgnore(const std::string& text) {
  std::string t = trim(text);
  int extra = 0;
  if (t.rfind(">=", 0) == 0 || t.rfind("==", 0) == 0) {
    t = trim(t.substr(2));
  } else if (t.rfind('>', 0) == 0) {
    t = trim(t.substr(1));
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

std::string text(const json& args, const char* key) {
  if (!args.is_object() || !args.contains(key) || args[key].is_null()) return "";
  if (!args[key].is_string()) throw Error(fmt::format("'{}' must be a string", key));
  return args[key].get<std::string>();
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
  std::map<int, int> dapId;  // session id -> the id the client knows
  std::set<int> functionIds;
  std::map<int64_t, Handle> handles;
  int64_t nextHandle = 1;
  std::optional<Resume> pending;  // a step for another robot, after the hold moves
  Resume::Kind last = Resume::Kind::Continue;

  Impl(std::istream& i, std::ostream& o, Launcher l)
      : input(i), output(o), launcher(std::move(l)) {}

  // ---- the wire ---------------------------------------------------------------

  // The next message; false at the end of the stream.
  bool read(json& message) {
    for (;;) {
      size_t length = 0;
      bool haveLength = false;
      std::string line;
      for (;;) {
        if (!std::getline(input, line)) return false;
        if (!line.empty() && line.back() == '\r') line.pop_back();
        if (line.empty()) {
          if (haveLength) break;
          continue;
        }
        const auto colon = line.find(':');
        if (colon == std::string::npos) continue;
        std::string name = line.substr(0, colon);
        for (char& c : name) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
        if (name != "content-length") continue;
        const std::string value = trim(line.substr(colon + 1));
        const auto [end, error] =
            std::from_chars(value.data(), value.data() + value.size(), length);
        haveLength = error == std::errc() && end == value.data() + value.size();
      }
      if (length > kMaxMessageBytes) {
        input.ignore(static_cast<std::streamsize>(length));
        log(fmt::format("simbot dap: a message of {} bytes ignored (the limit is {})\n", length,
                        kMaxMessageBytes));
        continue;
      }
      std::string body(length, '\0');
      if (!input.read(body.data(), static_cast<std::streamsize>(length))) return false;
      message = json::parse(body, nullptr, false);
      if (message.is_discarded() || !message.is_object()) {
        log("simbot dap: a message that is not a JSON object ignored\n");
        continue;
      }
      return true;
    }
  }

  void send(json message) {
    message["seq"] = seq++;
    const std::string body = message.dump(-1, ' ', false, json::error_handler_t::replace);
    output << "Content-Length: " << body.size() << "\r\n\r\n" << body;
    output.flush();
  }

  void respond(const json& request, const json& body = json::object()) {
    json r = {{"type", "response"},
              {"request_seq", request.value("seq", 0)},
              {"success", true},
              {"command", request.value("command", "")}};
    if (!body.is_null()) r["body"] = body;
    send(std::move(r));
  }

  void fail(const json& request, const std::string& message) {
    send({{"type", "response"},
          {"request_seq", request.value("seq", 0)},
          {"success", false},
          {"command", request.value("command", "")},
          {"message", message}});
  }

  void event(const std::string& name, const json& body = nullptr) {
    json e = {{"type", "event"}, {"event", name}};
    if (!body.is_null()) e["body"] = body;
    send(std::move(e));
  }

  void log(const std::string& line) {
    event("output", {{"category", "console"}, {"output", line}});
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
    if (args.contains("seconds") && !args["seconds"].is_null()) {
      if (!args["seconds"].is_number() || args["seconds"].get<double>() <= 0)
        throw Error("'seconds' must be a positive number");
      r.seconds = args["seconds"].get<double>();
    }
    if (args.contains("seed") && !args["seed"].is_null()) {
      if (!args["seed"].is_number_unsigned())
        throw Error("'seed' must be a whole number, 0 or more");
      r.seed = args["seed"].get<uint64_t>();
    }
    if (args.contains("stopOnEntry")) {
      if (!args["stopOnEntry"].is_boolean()) throw Error("'stopOnEntry' must be true or false");
      r.stopOnEntry = args["stopOnEntry"].get<bool>();
    }
    return r;
  }

  int serve(DapServer& self) {
    json m;
    while (!disconnected && read(m)) {
      if (m.value("type", "") != "request") continue;
      const std::string command = m.value("command", "");
      const json args = m.contains("arguments") ? m["arguments"] : json::object();
      if (command == "initialize") {
        respond(m, capabilities());
      } else if (command == "launch") {
        if (terminatedSent) {
          fail(m, "this adapter has run its session; start another");
          continue;
        }
        std::optional<Launched> run;
        int held = -1;
        try {
          launchRequest = launchArguments(args);
          if (!launchRequest.cwd.empty()) {
            std::error_code ec;
            std::filesystem::current_path(launchRequest.cwd, ec);
            if (ec) throw Error(fmt::format("cwd '{}': {}", launchRequest.cwd, ec.message()));
          }
          run = launcher(launchRequest);
          for (size_t i = 0; i < run->config.robots.size(); ++i)
            if (run->config.robots[i].name == launchRequest.robot) held = static_cast<int>(i);
          if (held < 0)
            throw Error(fmt::format("'robot': this run has no robot '{}'", launchRequest.robot));
        } catch (const std::exception& e) {
          fail(m, trim(e.what()));
          continue;
        }
        respond(m);
        event("initialized");
        try {
          Session session(run->config, run->programs, held);
          session.run(self);
        } catch (const std::exception& e) {
          log(trim(e.what()) + "\n");
        }
        handles.clear();
        if (disconnected) return 0;
        terminated();
      } else if (command == "disconnect") {
        respond(m);
        return 0;
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
    return 0;
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
    if (configured || why.kind != Stop::Kind::Entry) {
      configured = true;
      report(s, why);
    }
    json m;
    for (;;) {
      if (!read(m)) return quit();
      if (m.value("type", "") != "request") continue;
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

  void report(Session& s, const Stop& why) {
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
          description = fmt::format("data breakpoint {}: written by line {}, {}", why.breakpoint,
                                    why.writtenAt, where);
          detail = fmt::format("old value = {}\nnew value = {}", why.oldValue, why.newValue);
          log(fmt::format(
              "Data breakpoint {}: written by line {}\nOld value = {}\nNew value = {}\n",
              why.breakpoint, why.writtenAt, why.oldValue, why.newValue));
        }
        body["hitBreakpointIds"] = json::array({why.breakpoint});
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
            reason = why.note.empty() ? "breakpoint" : "goto";
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
    body["reason"] = reason;
    body["description"] = description;
    if (!detail.empty()) body["text"] = detail;
    event("stopped", body);
  }

  // One request at a stop; true with `how` set when it resumes the robot.
  bool dispatch(Session& s, const json& m, Resume& how) {
    const std::string command = m.value("command", "");
    const json args =
        m.contains("arguments") && m["arguments"].is_object() ? m["arguments"] : json::object();
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
    if (command == "evaluate") return evaluate(s, m, args), false;
    if (command == "source") {
      fail(m, "the sources are the programs' files: open them by their paths");
      return false;
    }
    if (command == "pause") {
      fail(m,
           "pause is not supported: set a breakpoint (a line, a function, or a time such as "
           "12.5s as a function breakpoint)");
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
    const bool instruction = args.value("granularity", "") == "instruction";
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
      fail(m, fmt::format("'{}' is not supported", command));
      return false;
    }
    if (s.over() && isForward(how.kind)) {
      // The match has no more to run: the client's session ends here (it
      // may still step back until it disconnects).
      respond(m, command == "continue" ? json{{"allThreadsContinued", true}} : json::object());
      terminated();
      return false;
    }
    // A step of the other robot's thread: hold that robot at this tick,
    // then step it.
    int robot = s.robot();
    if (command != "continue" && command != "reverseContinue" && args.contains("threadId")) {
      robot = args["threadId"].get<int>() - 1;
      if (robot < 0 || robot >= s.robotCount())
        throw Error(fmt::format("no thread {}", args["threadId"].dump()));
    }
    const vm::Vm& v = s.vm(robot);
    if (how.kind == K::Finish && v.callDepth() + v.interruptDepth() == 0)
      throw Error("step out: the robot is in its outermost frame");
    respond(m, command == "continue" ? json{{"allThreadsContinued", true}} : json::object());
    if (robot != s.robot()) {
      pending = how;
      how = Resume{};
      how.kind = K::Hold;
      how.robot = robot;
      how.tick = s.now();
    }
    return true;
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
    if (const std::string c = text(b, "condition"); !trim(c).empty()) s.setCondition(id, trim(c));
    if (const std::string h = text(b, "hitCondition"); !trim(h).empty())
      s.setIgnore(id, hitsToIgnore(h));
  }

  void setBreakpoints(Session& s, const json& m, const json& args) {
    const json source = args.value("source", json::object());
    std::string path = text(source, "path");
    if (path.empty()) path = text(source, "name");
    std::vector<int>& ids = lineBreakpoints[path];
    removeAll(s, ids);
    const std::vector<int> robots = robotsOf(s, path);
    json wanted = json::array();
    if (args.contains("breakpoints")) {
      wanted = args["breakpoints"];
    } else if (args.contains("lines")) {
      for (const json& line : args["lines"]) wanted.push_back({{"line", line}});
    }
    json answers = json::array();
    for (const json& b : wanted) {
      const int line = b.value("line", 0);
      json answer = {{"verified", false}, {"line", line}, {"source", source}};
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
  int functionBreakpoint(Session& s, const std::string& name) { return s.breakAt(trim(name)).id; }

  void setFunctionBreakpoints(Session& s, const json& m, const json& args) {
    removeAll(s, functionBreakpoints);
    json answers = json::array();
    for (const json& b : args.value("breakpoints", json::array())) {
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
    const auto robot = static_cast<int>(id / kDapFrameStride);
    const auto frame = static_cast<int>(id % kDapFrameStride);
    if (id < 0 || robot >= s.robotCount() || frame >= static_cast<int>(s.backtrace(robot).size()))
      throw Error(fmt::format("no frame {} at this stop", id));
    return {robot, frame};
  }

  // The robot and frame of a request's frameId, or the held robot's
  // selected frame.
  std::pair<int, int> frameArgument(const Session& s, const json& args) const {
    if (args.contains("frameId") && !args["frameId"].is_null())
      return frameOf(s, args["frameId"].get<int64_t>());
    return {s.robot(), s.frame()};
  }

  const Handle& handle(const json& args) const {
    const int64_t ref = args.value("variablesReference", int64_t{0});
    const auto it = handles.find(ref);
    if (it == handles.end())
      throw Error(fmt::format("no variables reference {} at this stop", ref));
    return it->second;
  }

  void dataBreakpointInfo(Session& s, const json& m, const json& args) {
    const std::string name = text(args, "name");
    int robot = s.robot(), frame = s.frame();
    std::string expression = name;
    if (args.contains("variablesReference") && !args["variablesReference"].is_null() &&
        args["variablesReference"].get<int64_t>() != 0) {
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
    if (robot != s.robot()) {
      body["description"] = fmt::format(
          "only the held robot's variables can be watched (robot {}, thread {}); step robot {}'s "
          "thread first",
          s.robotName(s.robot()), s.robot() + 1, s.robotName(robot));
      respond(m, body);
      return;
    }
    try {
      const inspect::Scope scope = s.scope(robot, frame);
      const inspect::Value v = inspect::Expression(expression).evaluate(scope);
      if (!v.inMemory) {
        body["description"] = fmt::format("'{}' is not an object in memory", expression);
      } else {
        body = {{"dataId", expression},
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
  void setDataBreakpoints(Session& s, const json& m, const json& args) {
    std::map<std::string, int> kept;
    for (const Watchpoint& w : s.watchpoints())
      for (int id : dataBreakpoints)
        if (w.id == id) kept[w.expression->text()] = id;
    std::vector<int> dropped;
    for (int id : dataBreakpoints) {
      bool wanted = false;
      for (const json& b : args.value("breakpoints", json::array()))
        wanted |= kept.count(text(b, "dataId")) && kept[text(b, "dataId")] == id;
      if (!wanted) dropped.push_back(id);
    }
    removeAll(s, dropped);
    dataBreakpoints.clear();
    json answers = json::array();
    for (const json& b : args.value("breakpoints", json::array())) {
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
        const Watchpoint& w = existing ? *existing : s.watch(dataId);
        dataBreakpoints.push_back(w.id);
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

  void stackTrace(Session& s, const json& m, const json& args) {
    const int robot = args.value("threadId", s.robot() + 1) - 1;
    if (robot < 0 || robot >= s.robotCount()) throw Error(fmt::format("no thread {}", robot + 1));
    const std::vector<FrameInfo> frames = s.backtrace(robot);
    const auto total = static_cast<int>(frames.size());
    const int start = std::clamp(args.value("startFrame", 0), 0, total);
    const int levels = args.value("levels", 0);
    const int end = levels > 0 ? std::min(total, start + levels) : total;
    json out = json::array();
    for (int k = start; k < end; ++k) {
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

  void scopes(Session& s, const json& m, const json& args) {
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

  void variables(Session& s, const json& m, const json& args) {
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
    const int64_t start = std::clamp<int64_t>(args.value("start", int64_t{0}), 0, total);
    const int64_t count = args.value("count", int64_t{0});
    if (start > 0 || count > 0) {
      const int64_t end = count > 0 ? std::min(total, start + count) : total;
      out = json(std::vector<json>(out.begin() + start, out.begin() + end));
    }
    respond(m, {{"variables", out}});
  }

  void evaluate(Session& s, const json& m, const json& args) {
    const std::string expression = trim(text(args, "expression"));
    if (expression.empty()) throw Error("evaluate needs an expression");
    const auto [robot, frame] = frameArgument(s, args);
    const inspect::Scope scope = s.scope(robot, frame);
    const inspect::Value v = inspect::Expression(expression).evaluate(scope);
    const std::string result = inspect::format(scope, v);  // inspect::Error: the answer
    const json var = variable(scope, robot, frame, expression, expression, v);
    respond(m, {{"result", result},
                {"type", inspect::typeName(scope, v)},
                {"variablesReference", var["variablesReference"]}});
  }
};

DapServer::DapServer(std::istream& in, std::ostream& out, Launcher launcher)
    : impl_(std::make_unique<Impl>(in, out, std::move(launcher))) {}

DapServer::~DapServer() = default;

int DapServer::serve() { return impl_->serve(*this); }

Resume DapServer::stopped(Session& session, const Stop& why) {
  return impl_->stopped(session, why);
}

}  // namespace simbot::debug
