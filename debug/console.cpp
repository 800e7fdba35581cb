// debug/console.cpp -- simbot debug's commands (console.h). Each command
// is one function of a line's words; the session does the work.
#include "debug/console.h"

#include <fmt/format.h>
#include <readline/history.h>
#include <readline/readline.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <climits>
#include <cstdint>
#include <cstdlib>
#include <istream>
#include <ostream>
#include <sstream>

#include "debug/trim.h"

namespace simbot::debug {

using scheduler::DebugEvent;

namespace {

constexpr const char* kPrompt = "(simbot) ";
constexpr int kListLines = 10;  // `list` shows this many lines

class TerminalLines final : public LineSource {
 public:
  bool next(std::string& line) override {
    char* text = readline(kPrompt);
    if (!text) return false;
    line = text;
    if (!line.empty()) add_history(text);
    std::free(text);
    return true;
  }
  bool echo() const override { return false; }
};

class StreamLines final : public LineSource {
 public:
  StreamLines(std::istream& in, bool echo) : in_(in), echo_(echo) {}
  bool next(std::string& line) override { return static_cast<bool>(std::getline(in_, line)); }
  bool echo() const override { return echo_; }

 private:
  std::istream& in_;
  bool echo_;
};

// The first word and the rest.
// "EXPR if COND" (break and watch): the two, trimmed; COND "" when absent.
std::pair<std::string, std::string> splitCondition(const std::string& s) {
  const auto at = (" " + s + " ").find(" if ");
  if (at == std::string::npos) return {trim(s, " \t\r"), ""};
  return {trim(s.substr(0, at), " \t\r"), trim(s.substr(std::min(s.size(), at + 3)), " \t\r")};
}

std::pair<std::string, std::string> split(const std::string& s) {
  const std::string t = trim(s, " \t\r");
  const auto space = t.find_first_of(" \t");
  if (space == std::string::npos) return {t, ""};
  return {t.substr(0, space), trim(t.substr(space), " \t\r")};
}

bool integer(const std::string& s, long& value) {
  if (s.empty()) return false;
  const auto [end, error] = std::from_chars(s.data(), s.data() + s.size(), value);
  return error == std::errc() && end == s.data() + s.size();
}

// A whole number the user wrote for `what`, in [lo, hi]; one line if not.
int number(const std::string& s, const std::string& what, int lo, int hi = INT_MAX) {
  long long v = 0;
  const auto [end, error] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (s.empty() || end != s.data() + s.size() ||
      (error != std::errc() && error != std::errc::result_out_of_range))
    throw Error(fmt::format("'{}' is not {}", s, what));
  if (error == std::errc::result_out_of_range || v < lo || v > hi)
    throw Error(fmt::format("{} is {} to {}: '{}' is out of range", what, lo, hi, s));
  return static_cast<int>(v);
}

// A repeat count (step 3, up 2): 1 if none.
int count(const std::string& args) { return args.empty() ? 1 : number(args, "a count", 1); }

const char* const kHelp = R"(Commands (gdb's where they fit; an empty line repeats the last one):
  break LOCATION [if COND]   stop at a line (12, B:12, FILE:12), a function or handler (INT1,
                             B:fire), a time (12.5s, 20ms, tick 115200000) or an event (frame,
                             edge, contact, shot, fault)
  tbreak LOCATION            the same, once
  watch [B:]EXPR [if COND]   stop when the value of an lvalue (of robot B) changes
  delete [N...], disable N, enable N, condition N [COND], ignore N COUNT
  run                        from the start, on to the first breakpoint
  continue [N], step [N], next [N], finish, until [LINE], advance LINE|TIME, stepi [N]
  reverse-step, reverse-next, reverse-stepi, reverse-continue, reverse-finish
  goto TIME|TICK             to the first boundary at or after it (forwards or backwards)
  print[/F] EXPR, display[/F] EXPR, undisplay N, ptype EXPR|TYPE, whatis EXPR|TYPE
  x/NFU ADDRESS              N units (U: b, h, w) of memory in format F from ADDRESS
  backtrace, frame N, up [N], down [N], list [LOCATION]
  info breakpoints|watchpoints|display|registers|arena|pose|locals|args|frame|line
  robot A|B                  hold the other robot at this tick
  quit
Expressions: C's, computed as the robot's code would (int 16 bits that wrap, char unsigned):
globals, statics, autos of the selected frame (FUNCTION::NAME for another function's), s.m,
p->m, a[i], *p, &x, casts, sizeof, ?:, a[i]@n (n elements). Formats F: x d u o t c a z
(a number's bits at its own width), and for x also s.
)";

}  // namespace

std::unique_ptr<LineSource> terminalLines() { return std::make_unique<TerminalLines>(); }
std::unique_ptr<LineSource> streamLines(std::istream& in, bool echo) {
  return std::make_unique<StreamLines>(in, echo);
}

// ---- stops ------------------------------------------------------------------

Resume Console::stopped(Session& s, const Stop& why) {
  for (const std::string& notice : s.takeNotices()) out_ << notice << "\n";
  // `step 3` and the like go on without asking while nothing else stopped.
  if (repeat_ > 0 && why.kind == Stop::Kind::Step) {
    --repeat_;
    lastPc_ = s.vm(s.robot()).pc();
    lastTick_ = s.now();
    return last_;
  }
  repeat_ = 0;
  report(s, why);
  for (;;) {
    std::string line;
    if (!lines_.next(line)) {
      Resume quit;
      quit.kind = Resume::Kind::Quit;
      return quit;
    }
    // A transcript shows the commands, not a script's comments.
    if (lines_.echo() && (trim(line, " \t\r").empty() || trim(line, " \t\r")[0] != '#'))
      out_ << kPrompt << line << "\n";
    if (trim(line, " \t\r").empty()) {
      line = lastCommand_;
    } else if (trim(line, " \t\r")[0] != '#') {
      lastCommand_ = line;
    }
    if (trim(line, " \t\r").empty() || trim(line, " \t\r")[0] == '#') continue;
    Resume how;
    try {
      if (execute(s, line, how)) {
        if (s.over() &&
            !(how.kind >= Resume::Kind::ReverseStep || how.kind == Resume::Kind::Quit)) {
          out_ << "The match is over: only going back (reverse-*, goto, run) is possible.\n";
          continue;
        }
        last_ = how;
        lastPc_ = s.vm(s.robot()).pc();
        lastTick_ = s.now();
        return how;
      }
    } catch (const Error& e) {
      ++errors_;
      out_ << "error: " << e.what() << "\n";
    } catch (const inspect::Error& e) {
      ++errors_;
      out_ << "error: " << e.what() << "\n";
    }
    out_.flush();
  }
}

void Console::report(Session& s, const Stop& why) {
  const std::string robot = s.robotName(s.robot());
  switch (why.kind) {
    case Stop::Kind::Entry:
      out_ << fmt::format("{} ({}) holds at its first instruction.\n", robot, s.program(s.robot()));
      break;
    case Stop::Kind::Breakpoint: {
      const Breakpoint* b = nullptr;
      for (const Breakpoint& x : s.breakpoints())
        if (x.id == why.breakpoint) b = &x;
      out_ << fmt::format(
          "{} {}{}.\n", temporaries_.count(why.breakpoint) ? "Temporary breakpoint" : "Breakpoint",
          why.breakpoint,
          b && b->kind == Breakpoint::Kind::Time ? fmt::format(" (tick {})", b->tick) : "");
      break;
    }
    case Stop::Kind::Watchpoint:
      if (why.oldValue.empty() && why.newValue.empty()) break;
      // Going backwards the robot stands before the write, and the old
      // value is the later one (gdb's order in the direction of travel).
      out_ << fmt::format("Watchpoint {}: written by {}{}\nOld value = {}\nNew value = {}\n",
                          why.breakpoint, why.writer,
                          why.reverse ? " (going backwards: stopped before that write)" : "",
                          why.oldValue, why.newValue);
      break;
    case Stop::Kind::Event:
      out_ << fmt::format("Breakpoint {} ({}: robot {} {}).\n", why.breakpoint,
                          scheduler::debugEventName(why.event), s.robotName(why.eventRobot),
                          why.note);
      break;
    case Stop::Kind::Fault: {
      const vm::Fault* f = s.vm(s.robot()).fault();
      out_ << fmt::format("Robot {} faulted at tick {} ({}), line {}: {}\n", robot,
                          f ? f->tick : s.now(), secondsText(f ? f->tick : s.now()),
                          f ? f->line : 0, f ? f->message : "");
      backtrace(s);
      return;
    }
    case Stop::Kind::End:
      out_ << fmt::format("The match is over at tick {} ({}).\n", s.matchTick(),
                          secondsText(s.matchTick()));
      return;
    case Stop::Kind::Step:
    case Stop::Kind::Time:
    case Stop::Kind::Goto:
      break;
  }
  if (!why.note.empty() && why.kind != Stop::Kind::Event) out_ << why.note << "\n";
  if (why.kind == Stop::Kind::Step && last_.kind == Resume::Kind::StepInstruction) {
    const vm::Image& img = s.vm(s.robot()).image();
    const vm::CostTable& costs = s.vm(s.robot()).costs();
    out_ << fmt::format("ran     {}\n", vm::disassembleAt(img, lastPc_, costs));
    out_ << fmt::format("clock   {} ({}), +{} T-states\n", s.now(), secondsText(s.now()),
                        s.now() - lastTick_);
    out_ << fmt::format("next    {}\n", vm::disassembleAt(img, s.vm(s.robot()).pc(), costs));
  }
  showLocation(s, s.robot());
  showDisplays(s);
  out_.flush();
}

void Console::showLocation(Session& s, int robot) {
  const std::vector<FrameInfo> frames = s.backtrace(robot);
  if (frames.empty()) return;
  const FrameInfo& f = frames[static_cast<size_t>(robot == s.robot() ? s.frame() : 0)];
  // A library call whose effect is due at this tick (a time gone to: the
  // events of the tick come first); a step makes it happen.
  const bool due = robot == s.robot() && s.frame() == 0 && s.vm(robot).effectPending();
  out_ << fmt::format("{} at tick {} ({}): {}({}) at {}:{}{}{}\n", s.robotName(robot),
                      s.vm(robot).now(), secondsText(s.vm(robot).now()),
                      f.function.empty() ? "<startup>" : f.function, f.arguments,
                      fileName(s.program(robot)), f.line, f.handler ? " [interrupt handler]" : "",
                      due ? " [the library call's effect is due at this tick]" : "");
  out_ << fmt::format("{}\t{}\n", f.line, s.source(robot, f.line));
  listRobot_ = robot;
  listLine_ = f.line;
}

void Console::showDisplays(Session& s) {
  for (const auto& [id, expression] : displays_) {
    try {
      printExpression(s, expression, fmt::format("{}: ", id));
    } catch (const inspect::Error& e) {
      out_ << fmt::format("{}: {} <{}>\n", id, expression, e.what());
    }
  }
}

// "EXPR" or "/F EXPR" (print/x, display/x). A display (labelled) shows
// its format, as gdb's does; print shows the expression alone.
void Console::printExpression(Session& s, const std::string& expression, const std::string& label) {
  inspect::Format how;
  std::string text = expression;
  if (!text.empty() && text[0] == '/') {
    const auto [letters, rest] = split(text);
    how = inspect::parseFormat(letters, false);
    text = rest;
    if (text.empty()) throw Error("print needs an expression");
  }
  const inspect::Scope scope = s.scope();
  const inspect::Value v = inspect::Expression(text).evaluate(scope);
  out_ << fmt::format("{}{} ({}) = {}\n", label, label.empty() ? text : expression,
                      inspect::typeName(scope, v), inspect::format(scope, v, how));
}

void Console::backtrace(Session& s) {
  const std::vector<FrameInfo> frames = s.backtrace(s.robot());
  for (size_t k = 0; k < frames.size(); ++k) {
    const FrameInfo& f = frames[k];
    out_ << fmt::format(
        "{}#{:<2} {}({}) at {}:{}{}{}\n", static_cast<int>(k) == s.frame() ? "*" : " ", k,
        f.function.empty() ? "<startup>" : f.function, f.arguments, fileName(s.program(s.robot())),
        f.line, f.handler ? " [interrupt handler]" : "",
        f.interrupted ? " [interrupted here]" : "");
  }
}

// ---- commands -----------------------------------------------------------------

bool Console::execute(Session& s, const std::string& line, Resume& how) {
  // (Named, not bound: clang 14 cannot capture a structured binding.)
  const std::pair<std::string, std::string> words = split(line);
  const std::string& command = words.first;
  const std::string& args = words.second;
  using K = Resume::Kind;
  auto resume = [&](K kind) {
    how = Resume{};
    how.kind = kind;
    return true;
  };
  auto repeated = [&](K kind) {
    repeat_ = count(args) - 1;
    return resume(kind);
  };
  if (command == "help" || command == "h") {
    out_ << kHelp;
    return false;
  }
  if (command == "quit" || command == "q") return resume(K::Quit);
  if (command == "continue" || command == "c") {
    const int n = count(args);
    if (n > 1) {
      // continue N: pass over the breakpoint that stopped us N - 1 more times.
      for (const Breakpoint& b : s.breakpoints())
        if ((b.kind == Breakpoint::Kind::Line || b.kind == Breakpoint::Kind::Function) &&
            b.address == s.vm(s.robot()).pc() && b.robot == s.robot())
          s.setIgnore(b.id, n - 1);
    }
    return resume(K::Continue);
  }
  if (command == "step" || command == "s") return repeated(K::Step);
  if (command == "next" || command == "n") return repeated(K::Next);
  if (command == "stepi" || command == "si") return repeated(K::StepInstruction);
  if (command == "finish" || command == "fin") {
    if (s.vm(s.robot()).callDepth() + s.vm(s.robot()).interruptDepth() == 0)
      throw Error("\"finish\" not meaningful in the outermost frame");
    return resume(K::Finish);
  }
  if (command == "until" || command == "u" || command == "advance") {
    if (args.empty()) {
      if (command == "advance") throw Error("advance needs a line or a time");
      return resume(K::Until);
    }
    if (looksLikeTime(args)) {
      resume(K::AdvanceTime);
      how.tick = s.now() + parseTime(args);
      return true;
    }
    std::string where = args;
    // A bare line is the held robot's.
    const int robot = where.find(':') == std::string::npos ? s.robot() : s.robotOf(where);
    long lineNumber = 0;
    if (robot != s.robot() || !integer(where, lineNumber))
      throw Error(fmt::format("{} takes a line of the held robot's program or a time", command));
    resume(K::AdvanceLine);
    how.line = number(where, "a line", 1, s.lineCount(robot));
    return true;
  }
  if (command == "reverse-step" || command == "rs") return resume(K::ReverseStep);
  if (command == "reverse-next" || command == "rn") return resume(K::ReverseNext);
  if (command == "reverse-stepi" || command == "rsi") return resume(K::ReverseStepInstruction);
  if (command == "reverse-continue" || command == "rc") return resume(K::ReverseContinue);
  if (command == "reverse-finish") return resume(K::ReverseFinish);
  if (command == "goto") {
    if (args.empty()) throw Error("goto needs a time (12.5s) or a tick");
    resume(K::Goto);
    how.tick = parseTime(args);
    return true;
  }
  if (command == "run" || command == "r") {
    out_ << "Starting from the beginning.\n";
    return resume(K::Restart);
  }
  if (command == "robot") {
    for (int r = 0; r < s.robotCount(); ++r) {
      std::string upper = args;
      for (char& ch : upper) ch = static_cast<char>(std::toupper(static_cast<unsigned char>(ch)));
      if (upper == s.robotName(r)) {
        if (r == s.robot()) throw Error(fmt::format("robot {} is held already", upper));
        // The robots stay where they are: nothing runs (Session::anchor).
        resume(K::Hold);
        how.robot = r;
        return true;
      }
    }
    throw Error(fmt::format("no robot '{}' (robots: A{})", args, s.robotCount() > 1 ? ", B" : ""));
  }
  if (command == "break" || command == "b" || command == "tbreak") {
    breakCommand(s, args, command == "tbreak");
    return false;
  }
  if (command == "watch") {
    auto [expression, condition] = splitCondition(args);
    // "B:EXPR": the other robot's variable, read in its innermost frame.
    const int robot = s.robotOfExpression(expression);
    if (expression.empty()) throw Error("watch needs an expression");
    const Watchpoint& w = s.watch(expression, condition, robot);
    out_ << fmt::format("Watchpoint {}: {} (now {}){}\n", w.id, expression, w.text,
                        condition.empty() ? "" : " if " + condition);
    return false;
  }
  if (command == "rwatch" || command == "awatch")
    throw Error(command +
                ": not supported by simbot (a watchpoint stops where its value changes: watch)");
  if (command == "delete" || command == "d") {
    if (args.empty()) {
      s.removeAll();
      return false;
    }
    std::istringstream ids(args);
    for (std::string id; ids >> id;) {
      s.remove(number(id, "a breakpoint number", 1));
    }
    return false;
  }
  if (command == "disable" || command == "enable") {
    if (args.empty()) throw Error(command + " needs a breakpoint number");
    s.setEnabled(number(args, "a breakpoint number", 1), command == "enable");
    return false;
  }
  if (command == "condition") {
    auto [id, expression] = split(args);
    if (id.empty()) throw Error("condition needs a breakpoint number");
    s.setCondition(number(id, "a breakpoint number", 1), expression);
    return false;
  }
  if (command == "ignore") {
    auto [id, times] = split(args);
    if (id.empty() || times.empty()) throw Error("ignore needs a breakpoint and a count");
    const int n = number(id, "a breakpoint number", 1), k = number(times, "an ignore count", 0);
    s.setIgnore(n, k);
    out_ << fmt::format("Will ignore the next {} crossings of breakpoint {}.\n", k, n);
    return false;
  }
  // gdb's format letters follow a slash: print/x EXPR, display/x EXPR, x/4xb ADDRESS.
  const std::string verb = command.substr(0, command.find('/'));
  const std::string letters = command.substr(verb.size());
  const std::string formatted = letters.empty() ? args : trim(letters + " " + args, " \t\r");
  if (verb == "print" || verb == "p" || verb == "output") {
    if (formatted.empty()) throw Error("print needs an expression");
    printExpression(s, formatted, "");
    return false;
  }
  if (verb == "x") {
    std::string spec = letters, address = args;
    if (spec.empty() && !args.empty() && args[0] == '/') {
      const auto parts = split(args);
      spec = parts.first;
      address = parts.second;
    }
    const inspect::Format shown = inspect::parseFormat(spec, true);
    if (address.empty()) throw Error("x needs an address");
    const inspect::Scope scope = s.scope();
    out_ << inspect::examine(scope, inspect::Expression(address).evaluate(scope), shown);
    return false;
  }
  if (command == "ptype" || command == "whatis") {
    if (args.empty()) throw Error(command + " needs an expression or a type");
    out_ << fmt::format("type = {}\n", inspect::describeType(s.scope(), args, command == "ptype"));
    return false;
  }
  if (verb == "display") {
    if (formatted.empty()) {
      showDisplays(s);
      return false;
    }
    // A bad expression or format is refused now.
    if (formatted[0] == '/') {
      const auto [spec, rest] = split(formatted);
      inspect::parseFormat(spec, false);
      inspect::Expression check(rest);
    } else {
      inspect::Expression check(formatted);
    }
    displays_.push_back({nextDisplay_++, formatted});
    printExpression(s, formatted, fmt::format("{}: ", displays_.back().first));
    return false;
  }
  if (command == "undisplay") {
    if (args.empty()) throw Error("undisplay needs a display number");
    const int n = number(args, "a display number", 1);
    const auto before = displays_.size();
    displays_.erase(std::remove_if(displays_.begin(), displays_.end(),
                                   [&](const auto& d) { return d.first == n; }),
                    displays_.end());
    if (displays_.size() == before) throw Error(fmt::format("no display {}", n));
    return false;
  }
  if (command == "backtrace" || command == "bt" || command == "where") {
    backtrace(s);
    return false;
  }
  if (command == "frame" || command == "f" || command == "up" || command == "down") {
    // Counted in 64 bits: up 2147483647 from frame 1 is no frame, not frame 0.
    const int64_t frames = static_cast<int64_t>(s.vm(s.robot()).activations().size());
    int64_t target = s.frame();
    if (command == "up") target += count(args);
    if (command == "down") target -= count(args);
    if ((command == "frame" || command == "f") && !args.empty())
      target = number(args, "a frame number", 0);
    if (target < 0 || target >= frames)
      throw Error(fmt::format("no frame {} (frames 0 to {})", target, frames - 1));
    s.selectFrame(static_cast<int>(target));
    showLocation(s, s.robot());
    return false;
  }
  if (command == "info" || command == "i") {
    info(s, args);
    return false;
  }
  if (command == "list" || command == "l") {
    list(s, args);
    return false;
  }
  throw Error(fmt::format("unknown command '{}' (try help)", command));
}

void Console::breakCommand(Session& s, std::string args, bool temporary) {
  std::string condition;
  std::tie(args, condition) = splitCondition(args);
  if (args.empty()) {
    // Here: the held robot's current line.
    args = fmt::format("{}:{}", s.robotName(s.robot()), s.vm(s.robot()).line());
  }
  const int id = s.breakAt(args, temporary).id;
  if (temporary) temporaries_.insert(id);
  if (!condition.empty()) s.setCondition(id, condition);
  for (const Breakpoint& x : s.breakpoints()) {
    if (x.id != id) continue;
    const std::string kind = temporary ? "Temporary breakpoint" : "Breakpoint";
    switch (x.kind) {
      case Breakpoint::Kind::Line:
      case Breakpoint::Kind::Function:
        out_ << fmt::format("{} {} at {}:{} ({}{}, robot {}){}\n", kind, x.id,
                            fileName(s.program(x.robot)), x.line,
                            x.kind == Breakpoint::Kind::Function ? "entry of " : "in ",
                            x.function.empty() ? "??" : x.function + "()", s.robotName(x.robot),
                            condition.empty() ? "" : " if " + condition);
        break;
      case Breakpoint::Kind::Time:
        out_ << fmt::format("{} {} at tick {} ({})\n", kind, x.id, x.tick, secondsText(x.tick));
        break;
      case Breakpoint::Kind::Event:
        out_ << fmt::format("{} {} on every {} event\n", kind, x.id,
                            scheduler::debugEventName(x.event));
        break;
    }
  }
}

void Console::info(Session& s, const std::string& what) {
  const vm::Vm& v = s.vm(s.robot());
  if (what == "breakpoints" || what == "b" || what == "break" || what == "watchpoints") {
    if (s.breakpoints().empty() && s.watchpoints().empty()) {
      out_ << "No breakpoints or watchpoints.\n";
      return;
    }
    out_ << "Num  Type        Enb  What\n";
    for (const Breakpoint& b : s.breakpoints()) {
      std::string place;
      switch (b.kind) {
        case Breakpoint::Kind::Line:
        case Breakpoint::Kind::Function:
          place = fmt::format("{}:{} in {}() (robot {})", fileName(s.program(b.robot)), b.line,
                              b.function, s.robotName(b.robot));
          break;
        case Breakpoint::Kind::Time:
          place = fmt::format("tick {} ({})", b.tick, secondsText(b.tick));
          break;
        case Breakpoint::Kind::Event:
          place = fmt::format("every {} event", scheduler::debugEventName(b.event));
          break;
      }
      out_ << fmt::format(
          "{:<4} {:<11} {:<4} {}{}{}{}\n", b.id, b.temporary ? "tbreakpoint" : "breakpoint",
          b.enabled ? "y" : "n", place, b.condition ? " if " + b.condition->text() : "",
          b.hits ? fmt::format(", hit {} time{}", b.hits, b.hits == 1 ? "" : "s") : "",
          b.ignore ? fmt::format(", ignore next {}", b.ignore) : "");
    }
    for (const Watchpoint& w : s.watchpoints())
      out_ << fmt::format(
          "{:<4} {:<11} {:<4} {}{} (now {}){}{}{}\n", w.id, "watchpoint", w.enabled ? "y" : "n",
          s.robotCount() > 1 ? fmt::format("{}: ", s.robotName(w.robot)) : "", w.expression->text(),
          w.text, w.condition ? " if " + w.condition->text() : "",
          w.hits ? fmt::format(", hit {} time{}", w.hits, w.hits == 1 ? "" : "s") : "",
          w.ignore ? fmt::format(", ignore next {}", w.ignore) : "");
    for (const Watchpoint& w : s.watchpoints())
      if (!w.writer.empty())
        out_ << fmt::format("     watchpoint {} last written by {}\n", w.id, w.writer);
    return;
  }
  if (what == "display") {
    for (const auto& [id, expression] : displays_) out_ << fmt::format("{}: {}\n", id, expression);
    return;
  }
  if (what == "registers" || what == "r") {
    const std::vector<vm::Vm::Activation> acts = v.activations();
    out_ << fmt::format("pc      0x{:04X}  {}\n", v.pc(),
                        vm::disassembleAt(v.image(), v.pc(), v.costs()));
    out_ << fmt::format("clock   {} ({})\n", v.now(), secondsText(v.now()));
    out_ << fmt::format("IFF1    {}  (interrupts {})\n", v.interruptsEnabled() ? 1 : 0,
                        v.interruptsEnabled() ? "enabled" : "disabled");
    if (!acts.empty() && acts[0].framed)
      out_ << fmt::format("IX      0x{:04X}\n", acts[0].fp);
    else
      out_ << "IX      (no auto frame in this function)\n";
    out_ << fmt::format("calls   {}   handlers in service {}{}{}\n", v.callDepth(),
                        v.interruptDepth(), v.halted() ? "   main returned" : "",
                        v.inLibraryCall() ? "   inside a library call" : "");
    std::string slots;
    for (int k = 0; k < std::min(v.evalDepth(), 8); ++k)
      slots += fmt::format(" 0x{:X}", v.evalSlot(k));
    out_ << fmt::format("stack   {} slot{}{}{}\n", v.evalDepth(), v.evalDepth() == 1 ? "" : "s",
                        v.evalDepth() ? ", top first:" : "", slots);
    for (int irq = 0; irq < vm::kIrqCount; ++irq)
      if (v.pending(static_cast<vm::Irq>(irq)))
        out_ << fmt::format("pending {}\n", vm::irqName(static_cast<vm::Irq>(irq)));
    return;
  }
  if (what == "arena") {
    out_ << s.view().describe(s.now());
    return;
  }
  if (what == "pose") {
    for (int r = 0; r < s.robotCount(); ++r) {
      const plant::Pose p = s.view().pose(r, s.now());
      out_ << fmt::format("{}: x {:.3f} ft  y {:.3f} ft  heading {:.2f} deg\n", s.robotName(r),
                          p.x_ft, p.y_ft, p.heading_deg);
    }
    return;
  }
  if (what == "locals" || what == "args") {
    const inspect::Scope scope = s.scope();
    const vm::Symbol* fn = scope.function();
    int shown = 0;
    for (const inspect::Variable& var : inspect::locals(scope)) {
      bool isParam = false;
      for (const vm::Symbol& sym : scope.image().symbols)
        isParam |= fn && sym.name == fn->name + "." + var.name && sym.parameter;
      if (isParam != (what == "args")) continue;
      out_ << fmt::format("{} ({}) = {}\n", var.name, inspect::typeName(scope, var.value),
                          inspect::format(scope, var.value));
      ++shown;
    }
    if (!shown) out_ << (what == "args" ? "No arguments.\n" : "No locals.\n");
    return;
  }
  if (what == "frame" || what == "line") {
    showLocation(s, s.robot());
    return;
  }
  throw Error(fmt::format(
      "info {}: try info breakpoints, display, registers, arena, pose, locals, args, frame", what));
}

void Console::list(Session& s, std::string args) {
  int robot = listRobot_;
  int center = listLine_;
  if (!args.empty()) {
    robot = s.robotOf(args);
    long n = 0;
    if (integer(args, n)) {
      center = number(args, "a line number", 1, std::max(1, s.lineCount(robot)));
    } else {
      bool found = false;
      for (const vm::Symbol& sym : s.vm(robot).image().symbols)
        if ((sym.kind == vm::Symbol::Kind::Function || sym.kind == vm::Symbol::Kind::Handler) &&
            sym.name == args) {
          center = sym.line;
          found = true;
        }
      if (!found) throw Error(fmt::format("no function '{}' in {}", args, s.program(robot)));
    }
  }
  const int first = std::max(1, center - kListLines / 2);
  const int last = std::min(s.lineCount(robot), first + kListLines - 1);
  for (int l = first; l <= last; ++l) out_ << fmt::format("{}\t{}\n", l, s.source(robot, l));
  listRobot_ = robot;
  listLine_ = last + kListLines / 2 + 1;
}

}  // namespace simbot::debug
