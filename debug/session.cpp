// debug/session.cpp -- the debugger's positions, snapshots and searches
// (session.h explains the model).
#include "debug/session.h"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <charconv>

namespace simbot::debug {

using scheduler::DebugEvent;

namespace {

// The session ends: thrown out of the match from a stop.
struct Quit {};

bool reverse(Resume::Kind k) {
  switch (k) {
    case Resume::Kind::ReverseStep:
    case Resume::Kind::ReverseNext:
    case Resume::Kind::ReverseStepInstruction:
    case Resume::Kind::ReverseContinue:
    case Resume::Kind::ReverseFinish:
    case Resume::Kind::Goto:
    case Resume::Kind::Restart:
    case Resume::Kind::Hold:
      return true;
    default:
      return false;
  }
}

}  // namespace

// Thrown out of the match from a stop: the command goes back in time (or
// moves the hold), which the session does from its snapshots.
struct Session::Rewind {
  Resume how;
  Tick from = 0;  // where the command was given: the held robot's clock
  int line = 0, calls = 0, ints = 0;
  Stop arrival;
};

Session::Session(scheduler::MatchConfig config, std::vector<std::string> programs, int held)
    : config_(std::move(config)), programs_(std::move(programs)), held_(held) {
  if (held_ < 0 || held_ >= static_cast<int>(config_.robots.size()))
    throw Error("there is no such robot to hold");
}

Session::~Session() = default;

// ---- running ------------------------------------------------------------------

void Session::run(Controller& controller, std::atomic<bool>* interrupt) {
  controller_ = &controller;
  interrupt_ = interrupt;
  config_.stop = interrupt;
  config_.snapshots = true;
  config_.debugger = this;
  config_.debugRobot = held_;
  run_ = std::make_unique<scheduler::MatchRun>(config_);
  takeSnapshot();
  applyBreakpoints();
  mode_ = Mode{};
  mode_.kind = Resume::Kind::Goto;
  mode_.tick = 0;
  mode_.arrival.kind = Stop::Kind::Entry;
  std::optional<Rewind> pending;
  for (;;) {
    try {
      if (pending) {
        const Rewind r = *pending;
        pending.reset();
        perform(r);
      }
      forward();
      over_ = true;
      view_ = &run_->view();
      frame_ = 0;
      for (;;) {
        Stop end;
        end.kind = Stop::Kind::End;
        const Resume how = controller_->stopped(*this, end);
        if (how.kind == Resume::Kind::Quit) return;
        if (reverse(how.kind)) {
          if (interrupt_) interrupt_->store(false);
          controller_->resuming();
          Rewind r{how, now(), 0, 0, 0, {}};
          const vm::Vm& v = vm(held_);
          r.line = v.line();
          r.calls = v.callDepth();
          r.ints = v.interruptDepth();
          over_ = false;
          pending = r;
          break;
        }
      }
    } catch (const Rewind& r) {
      pending = r;
    } catch (const scheduler::Stopped&) {
      // Ctrl-C (also during a search back): the round that was to start
      // did not; hold the robot where it is (replayed from a snapshot, as
      // any place is reached).
      interrupt->store(false);
      if (controller_->quitOnInterrupt()) return;
      scan_.reset();
      Rewind r;
      r.how.kind = Resume::Kind::Goto;
      r.how.tick = now();
      r.from = r.how.tick;
      r.arrival.kind = Stop::Kind::Goto;
      r.arrival.note = "Interrupted.";
      pending = r;
    } catch (const Quit&) {
      return;
    }
  }
}

// Runs on from wherever the match is, snapshotting as it first passes each
// interval; stops happen inside (DebugHook::boundary).
void Session::forward() {
  over_ = false;
  for (;;) {
    view_ = nullptr;
    const Tick next = (run_->now() / kSnapshotInterval + 1) * kSnapshotInterval;
    if (!run_->runUntil(next)) return;
    takeSnapshot();
  }
}

void Session::takeSnapshot() {
  const int64_t key = run_->now() / kSnapshotInterval;
  if (!snapshots_.count(key)) snapshots_.emplace(key, run_->snapshot());
}

// The latest snapshot whose held robot has not passed `target` (has not
// reached it, unless inclusive), restored.
void Session::restoreBefore(Tick target, bool inclusive) {
  for (auto it = snapshots_.rbegin(); it != snapshots_.rend(); ++it) {
    const Tick clock = it->second.robotClock(held_);
    // After its fault the held robot's clock stands still: a place past
    // it is reached from before the fault, and is the fault.
    if (it->second.robotFaulted(held_)) continue;
    if (clock < target || (inclusive && clock == target)) {
      run_->restore(it->second);
      applyBreakpoints();
      return;
    }
  }
  run_->restore(snapshots_.begin()->second);
  applyBreakpoints();
}

void Session::applyBreakpoints() {
  if (!run_) return;
  for (int r = 0; r < robotCount(); ++r) {
    std::vector<uint32_t> addresses;
    for (const Breakpoint& b : breakpoints_)
      if (b.enabled && b.robot == r &&
          (b.kind == Breakpoint::Kind::Line || b.kind == Breakpoint::Kind::Function))
        addresses.push_back(b.address);
    std::sort(addresses.begin(), addresses.end());
    addresses.erase(std::unique(addresses.begin(), addresses.end()), addresses.end());
    run_->setDebugBreakpoints(r, addresses);
  }
}

void Session::startMode(const Resume& how, const Stop& arrival) {
  const vm::Vm& v = vm(held_);
  mode_ = Mode{};
  mode_.kind = how.kind;
  mode_.tick = how.tick;
  mode_.line = how.line;
  mode_.startTick = v.now();
  mode_.startLine = v.line();
  mode_.startCalls = v.callDepth();
  mode_.startInts = v.interruptDepth();
  // finish from an outer frame: as if from that frame.
  if (how.kind == Resume::Kind::Finish) mode_.startCalls -= frame_;
  mode_.arrival = arrival;
  leftLine_ = v.line() != how.line;
}

// ---- the hook -----------------------------------------------------------------

bool Session::stepping() const {
  if (scan_) return scan_->stepping;
  switch (mode_.kind) {
    case Resume::Kind::Continue:
    case Resume::Kind::AdvanceTime:
      return !watchpoints_.empty();
    case Resume::Kind::Goto:
      return false;
    default:
      return true;
  }
}

Tick Session::until() const {
  if (scan_) {
    Tick u = scan_->end;
    // A search for breakpoint hits stops where time breakpoints fall.
    if (scan_->hits) {
      // Past the last boundary recorded: the first boundary at or after
      // the tick is looked at, and recorded as a hit, before it moves on.
      const Tick seen =
          scan_->boundaries.empty() ? scan_->start - 1 : scan_->boundaries.back().tick;
      for (const Breakpoint& b : breakpoints_)
        if (b.kind == Breakpoint::Kind::Time && b.enabled && b.tick > seen) u = std::min(u, b.tick);
    }
    return u;
  }
  if (mode_.kind == Resume::Kind::Goto) return mode_.tick;
  Tick u = INT64_MAX;
  if (mode_.kind == Resume::Kind::AdvanceTime) u = mode_.tick;
  for (const Breakpoint& b : breakpoints_)
    if (b.kind == Breakpoint::Kind::Time && b.enabled && !b.passed) u = std::min(u, b.tick);
  return u;
}

void Session::boundary(const scheduler::MatchView& view) {
  view_ = &view;
  const vm::Vm& v = view.vm(held_);
  if (scan_) {
    if (v.now() >= scan_->end) throw ScanDone{};
    Boundary b{v.now(), v.line(), v.callDepth(), v.interruptDepth(), false};
    if (scan_->hits) {
      Stop why;
      b.hit = eventStop_.has_value() || breakpointHit(held_, why, false) || watchpointHit(why);
      // A time breakpoint stops at the first boundary at or after its tick.
      const Tick before =
          scan_->boundaries.empty() ? scan_->start - 1 : scan_->boundaries.back().tick;
      for (const Breakpoint& t : breakpoints_)
        b.hit |=
            t.kind == Breakpoint::Kind::Time && t.enabled && t.tick > before && t.tick <= b.tick;
      eventStop_.reset();
    }
    scan_->boundaries.push_back(b);
    lastPc_ = v.pc();
    return;
  }
  Stop why;
  if (shouldStop(why)) park(why);
  lastPc_ = vm(held_).pc();
}

bool Session::event(int robot, Tick t, DebugEvent e) {
  if (scan_) {
    if (!scan_->hits) return false;
    for (const Breakpoint& b : breakpoints_)
      if (b.enabled && b.kind == Breakpoint::Kind::Event && b.event == e) {
        eventStop_ = Stop{};
        return true;
      }
    return false;
  }
  if (e == DebugEvent::Fault && robot != held_ && mode_.kind != Resume::Kind::Goto) {
    const vm::Fault* f = run_->view().vm(robot).fault();
    notices_.push_back(fmt::format("robot {} faulted at tick {} ({:.6f} s), line {}: {}",
                                   robotName(robot), t, timebase::secondsFromTicks(t),
                                   f ? f->line : 0, f ? f->message : std::string()));
  }
  if (mode_.kind == Resume::Kind::Goto) return false;
  for (Breakpoint& b : breakpoints_) {
    if (!b.enabled || b.kind != Breakpoint::Kind::Event || b.event != e) continue;
    ++b.hits;
    if (b.ignore > 0) {
      --b.ignore;
      continue;
    }
    Stop why;
    why.kind = Stop::Kind::Event;
    why.breakpoint = b.id;
    why.event = e;
    why.eventRobot = robot;
    why.note = fmt::format("at tick {}", t);
    eventStop_ = why;
    return true;
  }
  return false;
}

void Session::otherBreakpoint(const scheduler::MatchView& view, int robot) {
  if (scan_ || mode_.kind == Resume::Kind::Goto || robot == held_) return;
  view_ = &view;
  Stop why;
  if (!breakpointHit(robot, why, true)) return;
  // Hold that robot from here: the match goes back to a snapshot and runs
  // to this tick with it held (every robot at the same tick again).
  Rewind r;
  r.how.kind = Resume::Kind::Hold;
  r.how.robot = robot;
  r.how.tick = view.vm(robot).now();
  r.from = r.how.tick;
  r.arrival = why;
  throw r;
}

bool Session::breakpointHit(int robot, Stop& why, bool counting) {
  const vm::Vm& v = vm(robot);
  if (v.fault() || v.inLibraryCall()) return false;
  const uint32_t pc = v.pc();
  for (Breakpoint& b : breakpoints_) {
    if (!b.enabled || b.robot != robot || b.address != pc ||
        (b.kind != Breakpoint::Kind::Line && b.kind != Breakpoint::Kind::Function))
      continue;
    if (b.condition) {
      try {
        const inspect::Scope s = scope(robot, 0);
        if (!inspect::truth(s, b.condition->evaluate(s))) continue;
      } catch (const inspect::Error& e) {
        why.note = fmt::format("error in the condition of breakpoint {}: {}", b.id, e.what());
      }
    }
    if (!counting) return true;
    ++b.hits;
    if (b.ignore > 0) {
      --b.ignore;
      continue;
    }
    why.kind = Stop::Kind::Breakpoint;
    why.breakpoint = b.id;
    return true;
  }
  return false;
}

bool Session::watchpointHit(Stop& why) {
  if (watchpoints_.empty()) return false;
  const vm::Vm& v = vm(held_);
  // A library routine writes over several steps: judged once it is done.
  if (v.inLibraryCall()) return false;
  for (size_t k = 0; k < watchpoints_.size(); ++k) {
    Watchpoint& w = watchpoints_[k];
    if (w.robot != held_) continue;  // watched while its robot is held
    if (w.depth >= 0 && v.callDepth() + v.interruptDepth() < w.depth) {
      if (scan_) continue;
      why.kind = Stop::Kind::Watchpoint;
      why.breakpoint = w.id;
      why.note =
          fmt::format("watchpoint {} deleted: the call its variable lived in returned", w.id);
      watchpoints_.erase(watchpoints_.begin() + static_cast<std::ptrdiff_t>(k));
      return true;
    }
    const inspect::Scope s(v);
    std::vector<uint8_t> now = inspect::bytes(s, w.object);
    if (w.valid && now == w.value) continue;
    const bool first = !w.valid;
    w.value = std::move(now);
    w.valid = true;
    const std::string before = w.text;
    try {
      w.text = inspect::format(s, w.object);
    } catch (const inspect::Error& e) {
      w.text = fmt::format("<{}>", e.what());
    }
    if (first) continue;
    if (!scan_) ++w.hits;
    why.kind = Stop::Kind::Watchpoint;
    why.breakpoint = w.id;
    why.oldValue = before;
    why.newValue = w.text;
    why.writtenAt = v.image().lineAt(lastPc_);
    return true;
  }
  return false;
}

void Session::refreshWatchpoints() {
  for (Watchpoint& w : watchpoints_) {
    const inspect::Scope s(vm(w.robot));
    w.value = inspect::bytes(s, w.object);
    try {
      w.text = inspect::format(s, w.object);
    } catch (const inspect::Error& e) {
      w.text = fmt::format("<{}>", e.what());
    }
    w.valid = true;
  }
}

bool Session::shouldStop(Stop& why) {
  const vm::Vm& v = vm(held_);
  const Tick t = v.now();
  if (v.fault()) {
    why.kind = Stop::Kind::Fault;
    return true;
  }
  if (mode_.kind == Resume::Kind::Goto) {
    if (t < mode_.tick) return false;
    why = mode_.arrival;
    return true;
  }
  if (eventStop_) {
    why = *eventStop_;
    eventStop_.reset();
    return true;
  }
  if (t != lastStop_ && breakpointHit(held_, why, true)) return true;
  if (watchpointHit(why)) return true;
  for (Breakpoint& b : breakpoints_) {
    if (b.kind != Breakpoint::Kind::Time || !b.enabled || b.passed || t < b.tick) continue;
    b.passed = true;
    ++b.hits;
    why.kind = Stop::Kind::Breakpoint;
    why.breakpoint = b.id;
    return true;
  }
  const int line = v.line(), calls = v.callDepth(), ints = v.interruptDepth();
  const int depth = calls + ints, startDepth = mode_.startCalls + mode_.startInts;
  why.kind = Stop::Kind::Step;
  switch (mode_.kind) {
    case Resume::Kind::StepInstruction:
      return t > mode_.startTick;
    case Resume::Kind::Step: {
      if (line <= 0 ||
          (line == mode_.startLine && calls == mode_.startCalls && ints == mode_.startInts))
        return false;
      // Into a call: past its prologue (the ENTER and the parameters'
      // stores, on the line of the function's name), as a breakpoint on
      // the function stops.
      const vm::Symbol* fn = calls > mode_.startCalls ? v.image().functionAt(v.pc()) : nullptr;
      return !(fn && fn->kind == vm::Symbol::Kind::Function && line == fn->line);
    }
    case Resume::Kind::Next:
      return depth < startDepth || (depth == startDepth && line > 0 && line != mode_.startLine);
    case Resume::Kind::Until:
      return depth < startDepth || (depth == startDepth && line > mode_.startLine);
    case Resume::Kind::AdvanceLine:
      if (line != mode_.line) leftLine_ = true;
      return depth < startDepth || (line == mode_.line && leftLine_);
    case Resume::Kind::Finish:
      return depth < startDepth;
    case Resume::Kind::AdvanceTime:
      why.kind = Stop::Kind::Time;
      return t >= mode_.tick;
    default:
      return false;
  }
}

void Session::park(const Stop& why) {
  frame_ = 0;
  lastStop_ = now();
  eventStop_.reset();
  for (Breakpoint& b : breakpoints_)
    if (b.kind == Breakpoint::Kind::Time) b.passed = b.tick <= lastStop_;
  refreshWatchpoints();
  // A temporary breakpoint goes once it has stopped the robot.
  if (why.kind == Stop::Kind::Breakpoint || why.kind == Stop::Kind::Event)
    if (const Breakpoint* b = findBreakpoint(why.breakpoint); b && b->temporary) {
      const int id = b->id;
      breakpoints_.erase(std::remove_if(breakpoints_.begin(), breakpoints_.end(),
                                        [&](const Breakpoint& x) { return x.id == id; }),
                         breakpoints_.end());
      applyBreakpoints();
    }
  handle(controller_->stopped(*this, why));
}

void Session::handle(const Resume& how) {
  if (how.kind == Resume::Kind::Quit) throw Quit{};
  // A Ctrl-C at the prompt is not meant for the command that follows.
  if (interrupt_) interrupt_->store(false);
  controller_->resuming();
  if (!reverse(how.kind)) {
    startMode(how);
    return;
  }
  const vm::Vm& v = vm(held_);
  Rewind r{how, v.now(), v.line(), v.callDepth(), v.interruptDepth(), {}};
  throw r;
}

void Session::perform(const Rewind& rewind) {
  eventStop_.reset();
  Stop arrival;
  arrival.kind = Stop::Kind::Goto;
  Tick target = rewind.from;
  switch (rewind.how.kind) {
    case Resume::Kind::Restart:
      restoreBefore(0, true);
      mode_ = Mode{};
      mode_.kind = Resume::Kind::Continue;
      lastStop_ = -1;
      for (Breakpoint& b : breakpoints_) b.passed = false;
      for (Watchpoint& w : watchpoints_) w.valid = false;
      return;
    case Resume::Kind::Goto:
      target = std::max<Tick>(rewind.how.tick, 0);
      arrival.note = rewind.arrival.note;
      break;
    case Resume::Kind::Hold:
      held_ = rewind.how.robot;
      config_.debugRobot = held_;
      target = rewind.how.tick;
      arrival = rewind.arrival.kind == Stop::Kind::Entry ? arrival : rewind.arrival;
      break;
    default:
      if (const auto found = searchBack(rewind)) {
        target = *found;
      } else {
        arrival.note = "no earlier place to go back to: the robot stays where it was";
      }
      break;
  }
  restoreBefore(target, true);
  mode_ = Mode{};
  mode_.kind = Resume::Kind::Goto;
  mode_.tick = target;
  mode_.arrival = arrival;
  lastStop_ = -1;
}

// Every boundary of the held robot from the latest snapshot whose held clock
// is at or before `from` up to (not including) `end`, as a forward run
// meets them: each one when stepping, else at breakpoints and events only.
std::vector<Session::Boundary> Session::scanWindow(Tick from, Tick end, bool stepping, bool hits) {
  restoreBefore(from, true);
  scan_ = Scan{end, stepping, hits, {}, run_->view().vm(held_).now()};
  for (Watchpoint& w : watchpoints_) w.valid = false;
  try {
    forward();
  } catch (const ScanDone&) {
  } catch (...) {
    scan_.reset();
    throw;
  }
  std::vector<Boundary> found = std::move(scan_->boundaries);
  scan_.reset();
  return found;
}

std::optional<Tick> Session::searchBack(const Rewind& rw) {
  const Resume::Kind kind = rw.how.kind;
  const Tick c = rw.from;
  const int depthNow = rw.calls + rw.ints;
  if (kind == Resume::Kind::ReverseContinue && watchpoints_.empty()) {
    // Breakpoints cost nothing to find: one pass from the start.
    const std::vector<Boundary> all = scanWindow(0, c, false, true);
    for (auto it = all.rbegin(); it != all.rend(); ++it)
      if (it->hit && it->tick < c) return it->tick;
    return std::nullopt;
  }
  const bool stepping = true;
  const bool hits = kind == Resume::Kind::ReverseContinue;
  std::vector<Boundary> history;  // every boundary before c found so far, in order
  Tick windowEnd = c;
  for (;;) {
    // The window before windowEnd: from the latest snapshot before it.
    Tick start = -1;
    for (auto it = snapshots_.rbegin(); it != snapshots_.rend(); ++it)
      if (it->second.robotClock(held_) < windowEnd) {
        start = it->second.robotClock(held_);
        break;
      }
    if (start < 0)
      return history.empty() ? std::nullopt : std::optional<Tick>(history.front().tick);
    std::vector<Boundary> window = scanWindow(start, windowEnd, stepping, hits);
    history.insert(history.begin(), window.begin(), window.end());
    windowEnd = start;
    const bool complete = snapshots_.begin()->second.robotClock(held_) >= start;
    if (history.empty()) {
      if (complete) return std::nullopt;
      continue;
    }
    switch (kind) {
      case Resume::Kind::ReverseStepInstruction:
        return history.back().tick;
      case Resume::Kind::ReverseContinue:
        for (auto it = history.rbegin(); it != history.rend(); ++it)
          if (it->hit) return it->tick;
        break;
      case Resume::Kind::ReverseFinish:
        for (auto it = history.rbegin(); it != history.rend(); ++it)
          if (it->calls + it->ints < depthNow) return it->tick;
        break;
      default: {
        // reverse-step, reverse-next: back over the rest of this line, then
        // to the start of the line before it (reverse-next passes over
        // deeper calls and handlers). Out of a handler, back to the
        // instruction it interrupted.
        const bool over = kind == Resume::Kind::ReverseNext;
        std::vector<size_t> seen;
        for (size_t k = 0; k < history.size(); ++k)
          if (!over || history[k].calls + history[k].ints <= depthNow) seen.push_back(k);
        auto same = [&](size_t a, int line, int calls, int ints) {
          const Boundary& b = history[a];
          return b.line == line && b.calls == calls && b.ints == ints;
        };
        ptrdiff_t i = static_cast<ptrdiff_t>(seen.size()) - 1;
        while (i >= 0 && same(seen[static_cast<size_t>(i)], rw.line, rw.calls, rw.ints)) --i;
        if (i < 0) break;
        const Boundary& prev = history[seen[static_cast<size_t>(i)]];
        if (prev.ints != rw.ints) return prev.tick;
        while (i > 0 && same(seen[static_cast<size_t>(i - 1)], prev.line, prev.calls, prev.ints))
          --i;
        if (i > 0 || complete) return history[seen[static_cast<size_t>(i)]].tick;
        break;
      }
    }
    if (complete) {
      const bool toStart = (kind == Resume::Kind::ReverseStep || kind == Resume::Kind::ReverseNext);
      return toStart ? std::optional<Tick>(history.front().tick) : std::nullopt;
    }
  }
}

// ---- at a stop ------------------------------------------------------------------

std::string Session::robotName(int robot) const {
  return config_.robots.at(static_cast<size_t>(robot)).name;
}

const std::string& Session::program(int robot) const {
  return programs_.at(static_cast<size_t>(robot));
}

const scheduler::MatchView& Session::view() const { return view_ ? *view_ : run_->view(); }

const vm::Vm& Session::vm(int robot) const { return view().vm(robot); }

Tick Session::now() const { return vm(held_).now(); }
Tick Session::matchTick() const { return run_->now(); }

void Session::selectFrame(int frame) {
  const auto count = static_cast<int>(vm(held_).activations().size());
  if (frame < 0 || frame >= count)
    throw Error(fmt::format("no frame {} (frames 0 to {})", frame, count - 1));
  frame_ = frame;
}

inspect::Scope Session::scope() const { return inspect::Scope(vm(held_), frame_); }
inspect::Scope Session::scope(int robot, int frame) const {
  return inspect::Scope(vm(robot), frame);
}

std::vector<FrameInfo> Session::backtrace(int robot) const {
  const vm::Vm& v = vm(robot);
  const vm::Image& img = v.image();
  const std::vector<vm::Vm::Activation> acts = v.activations();
  std::vector<FrameInfo> out;
  for (size_t k = 0; k < acts.size(); ++k) {
    FrameInfo f;
    const vm::Symbol* fn = img.functionAt(acts[k].pc);
    f.function = fn ? fn->name : "";
    f.line = img.lineAt(acts[k].pc);
    f.pc = acts[k].pc;
    f.handler = acts[k].handler;
    f.interrupted = k > 0 && acts[k - 1].handler;
    if (fn) {
      // Parameters in frame order (their offsets), read in that frame.
      std::vector<const vm::Symbol*> params;
      for (const vm::Symbol& s : img.symbols)
        if (s.parameter && s.name.rfind(fn->name + ".", 0) == 0) params.push_back(&s);
      std::sort(params.begin(), params.end(),
                [](const vm::Symbol* a, const vm::Symbol* b) { return a->address < b->address; });
      const inspect::Scope s(v, static_cast<int>(k));
      for (const vm::Symbol* p : params) {
        const std::string name = p->name.substr(fn->name.size() + 1);
        std::string value = "?";
        try {
          value = inspect::format(s, inspect::Expression(name).evaluate(s));
        } catch (const inspect::Error&) {
        }
        f.arguments += fmt::format("{}{}={}", f.arguments.empty() ? "" : ", ", name, value);
      }
    }
    out.push_back(std::move(f));
  }
  return out;
}

std::string Session::source(int robot, int line) const {
  const auto& lines = config_.robots.at(static_cast<size_t>(robot)).image.sourceLines;
  return line >= 1 && line <= static_cast<int>(lines.size()) ? lines[static_cast<size_t>(line - 1)]
                                                             : std::string();
}

int Session::lineCount(int robot) const {
  return static_cast<int>(config_.robots.at(static_cast<size_t>(robot)).image.sourceLines.size());
}

int Session::robotOf(std::string& where) const {
  const auto colon = where.rfind(':');
  if (colon == std::string::npos) return 0;
  const std::string prefix = where.substr(0, colon);
  for (int r = 0; r < robotCount(); ++r) {
    std::string upper = prefix;
    for (char& ch : upper) ch = static_cast<char>(std::toupper(static_cast<unsigned char>(ch)));
    if (upper == robotName(r) || prefix == program(r) || prefix == fileName(program(r))) {
      where = where.substr(colon + 1);
      return r;
    }
  }
  throw Error(fmt::format("no robot or program '{}' in this run", prefix));
}

std::vector<std::string> Session::takeNotices() { return std::exchange(notices_, {}); }

// ---- breakpoints ------------------------------------------------------------------

Breakpoint& Session::addBreakpoint(Breakpoint b) {
  b.id = nextId_++;
  breakpoints_.push_back(std::move(b));
  applyBreakpoints();
  return breakpoints_.back();
}

Breakpoint* Session::findBreakpoint(int id) {
  for (Breakpoint& b : breakpoints_)
    if (b.id == id) return &b;
  return nullptr;
}

const Breakpoint& Session::breakAtLine(int robot, int line, bool temporary) {
  if (robot < 0 || robot >= robotCount()) throw Error("there is no such robot");
  const vm::Image& img = config_.robots[static_cast<size_t>(robot)].image;
  if (line < 1 || line > static_cast<int>(img.sourceLines.size()))
    throw Error(
        fmt::format("{} has no line {} (it has {})", program(robot), line, img.sourceLines.size()));
  // The first instruction of the line, or of the next line that has code.
  std::optional<uint32_t> at;
  int found = 0;
  for (int l = line; l <= static_cast<int>(img.sourceLines.size()) && !at; ++l) {
    const auto it = std::find(img.lines.begin(), img.lines.end(), l);
    if (it != img.lines.end()) {
      at = static_cast<uint32_t>(it - img.lines.begin());
      found = l;
    }
  }
  if (!at) throw Error(fmt::format("no code at or after line {} of {}", line, program(robot)));
  Breakpoint b;
  b.kind = Breakpoint::Kind::Line;
  b.robot = robot;
  b.line = found;
  b.address = *at;
  const vm::Symbol* fn = img.functionAt(*at);
  b.function = fn ? fn->name : "";
  b.temporary = temporary;
  return addBreakpoint(std::move(b));
}

const Breakpoint& Session::breakAtFunction(int robot, const std::string& name, bool temporary) {
  if (robot < 0 || robot >= robotCount()) throw Error("there is no such robot");
  const vm::Image& img = config_.robots[static_cast<size_t>(robot)].image;
  for (const vm::Symbol& s : img.symbols) {
    if ((s.kind != vm::Symbol::Kind::Function && s.kind != vm::Symbol::Kind::Handler) ||
        s.name != name)
      continue;
    // Past the prologue (its ENTER and the parameters' stores, on the
    // line of the function's name): at the first instruction of the body,
    // where the parameters can be read. A handler whose first instruction
    // is already its body's stops at its entry.
    uint32_t at = s.address;
    while (at < s.address + s.size && at < img.lines.size() && img.lines[at] == s.line) ++at;
    if (at >= s.address + s.size || at >= img.lines.size()) at = s.address;
    Breakpoint b;
    b.kind = Breakpoint::Kind::Function;
    b.robot = robot;
    b.function = name;
    b.address = at;
    b.line = img.lineAt(at);
    b.temporary = temporary;
    return addBreakpoint(std::move(b));
  }
  throw Error(fmt::format("no function '{}' in {}", name, program(robot)));
}

const Breakpoint& Session::breakAtTick(Tick tick, bool temporary) {
  Breakpoint b;
  b.kind = Breakpoint::Kind::Time;
  b.tick = tick;
  b.temporary = temporary;
  b.passed = run_ && tick <= now();
  return addBreakpoint(std::move(b));
}

const Breakpoint& Session::breakAtEvent(DebugEvent event, bool temporary) {
  Breakpoint b;
  b.kind = Breakpoint::Kind::Event;
  b.event = event;
  b.temporary = temporary;
  return addBreakpoint(std::move(b));
}

const Breakpoint& Session::breakAt(const std::string& location, bool temporary) {
  std::string where = location;
  const bool named = where.find(':') != std::string::npos;
  const int robot = robotOf(where);
  if (!named && where.rfind("tick ", 0) == 0) {
    const std::string count = where.substr(5);
    Tick tick = 0;
    const auto [end, error] = std::from_chars(count.data(), count.data() + count.size(), tick);
    if (count.empty() || error != std::errc() || end != count.data() + count.size() || tick < 0)
      throw Error(fmt::format("'{}' is not a tick count", count));
    return breakAtTick(tick, temporary);
  }
  if (!named && looksLikeTime(where)) return breakAtTick(parseTime(where), temporary);
  int line = 0;
  const auto [end, error] = std::from_chars(where.data(), where.data() + where.size(), line);
  if (!where.empty() && error == std::errc() && end == where.data() + where.size())
    return breakAtLine(robot, line, temporary);
  if (!named)
    for (DebugEvent e : {DebugEvent::FrameLatched, DebugEvent::EdgeAccepted, DebugEvent::Contact,
                         DebugEvent::Shot, DebugEvent::Fault}) {
      if (where != scheduler::debugEventName(e)) continue;
      for (const vm::Symbol& sym : config_.robots[static_cast<size_t>(robot)].image.symbols)
        if (sym.name == where &&
            (sym.kind == vm::Symbol::Kind::Function || sym.kind == vm::Symbol::Kind::Handler))
          return breakAtFunction(robot, where, temporary);
      return breakAtEvent(e, temporary);
    }
  return breakAtFunction(robot, where, temporary);
}

void Session::setCondition(int id, const std::string& expression) {
  Breakpoint* b = findBreakpoint(id);
  if (!b) throw Error(fmt::format("no breakpoint {}", id));
  if (expression.empty()) {
    b->condition.reset();
    return;
  }
  try {
    b->condition = std::make_shared<inspect::Expression>(expression);
  } catch (const inspect::Error& e) {
    throw Error(e.what());
  }
}

void Session::setIgnore(int id, int count) {
  Breakpoint* b = findBreakpoint(id);
  if (!b) throw Error(fmt::format("no breakpoint {}", id));
  b->ignore = std::max(count, 0);
}

void Session::setEnabled(int id, bool enabled) {
  Breakpoint* b = findBreakpoint(id);
  if (!b) throw Error(fmt::format("no breakpoint {}", id));
  b->enabled = enabled;
  applyBreakpoints();
}

void Session::remove(int id) {
  const auto before = breakpoints_.size() + watchpoints_.size();
  breakpoints_.erase(std::remove_if(breakpoints_.begin(), breakpoints_.end(),
                                    [&](const Breakpoint& b) { return b.id == id; }),
                     breakpoints_.end());
  watchpoints_.erase(std::remove_if(watchpoints_.begin(), watchpoints_.end(),
                                    [&](const Watchpoint& w) { return w.id == id; }),
                     watchpoints_.end());
  if (before == breakpoints_.size() + watchpoints_.size())
    throw Error(fmt::format("no breakpoint or watchpoint {}", id));
  applyBreakpoints();
}

void Session::removeAll() {
  breakpoints_.clear();
  watchpoints_.clear();
  applyBreakpoints();
}

const Watchpoint& Session::watch(const std::string& expression) {
  Watchpoint w;
  try {
    w.expression = std::make_shared<inspect::Expression>(expression);
    const inspect::Scope s = scope();
    w.object = w.expression->evaluate(s);
    if (!w.object.inMemory)
      throw Error(fmt::format("'{}' is not an object in memory: nothing to watch", expression));
    // An auto: watched while the activation holding it lasts (its index
    // from the outermost, where calls and handlers both count).
    if (w.object.frame >= 0) w.depth = static_cast<int>(s.activations.size()) - 1 - w.object.frame;
    w.value = inspect::bytes(s, w.object);
    w.text = inspect::format(s, w.object);
    w.valid = true;
  } catch (const inspect::Error& e) {
    throw Error(e.what());
  }
  w.id = nextId_++;
  w.robot = held_;
  watchpoints_.push_back(std::move(w));
  return watchpoints_.back();
}

// ---- times ------------------------------------------------------------------

bool looksLikeTime(const std::string& word) {
  return !word.empty() && std::isdigit(static_cast<unsigned char>(word[0])) && word.back() == 's';
}

std::string secondsText(Tick t) { return fmt::format("{:.6f} s", timebase::secondsFromTicks(t)); }

std::string fileName(const std::string& path) {
  const auto slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

Tick parseTime(const std::string& text) {
  std::string digits = text;
  std::string exponent;
  auto ends = [&](const char* unit) {
    const std::string u = unit;
    return digits.size() > u.size() && digits.compare(digits.size() - u.size(), u.size(), u) == 0;
  };
  bool seconds = true;
  if (ends("ms")) {
    digits.resize(digits.size() - 2);
    exponent = "e-3";
  } else if (ends("us")) {
    digits.resize(digits.size() - 2);
    exponent = "e-6";
  } else if (ends("s")) {
    digits.resize(digits.size() - 1);
  } else {
    seconds = false;
  }
  if (!seconds) {
    Tick ticks = 0;
    const auto [end, error] = std::from_chars(digits.data(), digits.data() + digits.size(), ticks);
    if (error != std::errc() || end != digits.data() + digits.size() || ticks < 0 || digits.empty())
      throw Error(
          fmt::format("'{}' is not a time (write 12.5s, 20ms, 300us or a tick count)", text));
    return ticks;
  }
  // A decimal with an exponent already (1e-3s) takes no unit exponent.
  if (!exponent.empty() && digits.find_first_of("eE") != std::string::npos)
    throw Error(fmt::format("'{}' is not a time", text));
  const auto ticks = timebase::ticksFromDecimal(digits + exponent, timebase::kTicksPerSecond);
  if (!ticks || digits.empty() || digits[0] == '-')
    throw Error(fmt::format("'{}' is not a time (write 12.5s, 20ms, 300us or a tick count)", text));
  return ticks->ticks;
}

}  // namespace simbot::debug
