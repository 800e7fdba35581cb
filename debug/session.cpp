// debug/session.cpp -- the debugger's positions, snapshots and searches
// (session.h explains the model).
#include "debug/session.h"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cstdlib>

#include "timebase/written.h"

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
      anchor_ = now();
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
  if (snapshots_.count(key)) return;
  snapshots_.emplace(key, run_->snapshot());
  // Where the session is: this snapshot's place when running on, the
  // last stop's while a search replays an earlier window.
  thinSnapshots(scan_ ? lastStop_ / kSnapshotInterval : key);
}

// The snapshots kept, so that memory stays bounded however long a session
// runs: every one within kDenseSnapshots intervals of `present` (where
// stepping and searching back happen), then one in 2, 4, 8, ... as the
// distance doubles (a goto far away replays at most half the distance),
// and the first. About 16 + 8 log2(n / 16) of n intervals: 88 for an hour.
void Session::thinSnapshots(int64_t present) {
  for (auto it = snapshots_.begin(); it != snapshots_.end();) {
    const int64_t key = it->first, distance = std::abs(key - present);
    int64_t spacing = 1;
    while (kDenseSnapshots * spacing < distance) spacing *= 2;
    if (key == 0 || key % spacing == 0)
      ++it;
    else
      it = snapshots_.erase(it);
  }
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
  mode_.startPending = v.effectPending();
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

Tick Session::othersTo(Tick clock) const {
  return !scan_ && mode_.kind == Resume::Kind::Goto && mode_.anchored ? std::min(clock, mode_.tick)
                                                                      : clock;
}

bool Session::settles() const {
  if (scan_) return scan_->stepping;
  if (mode_.kind == Resume::Kind::Goto) return mode_.settled;
  return stepping();
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
    if (v.now() >= scan_->end) {
      // The window's last instruction may have changed a watched value:
      // going backwards, that change stops before it.
      Stop why;
      if (scan_->hits && !scan_->boundaries.empty() && watchpointHit(held_, why))
        reverseWatchHit(why);
      throw ScanDone{};
    }
    Boundary b{v.now(), v.line(),           v.callDepth(),    v.interruptDepth(),
               false,   !v.effectPending(), v.inLibraryCall()};
    if (scan_->hits) {
      Stop why;
      if (eventStop_) {
        why = *eventStop_;
        b.hit = true;
      } else if (breakpointHit(held_, why, false)) {
        b.hit = true;
      } else if (!scan_->boundaries.empty() && watchpointHit(held_, why)) {
        reverseWatchHit(why);
        why = Stop{};
      }
      // A time breakpoint stops at the first boundary at or after its tick.
      const Tick before =
          scan_->boundaries.empty() ? scan_->start - 1 : scan_->boundaries.back().tick;
      for (const Breakpoint& t : breakpoints_)
        if (!b.hit && t.kind == Breakpoint::Kind::Time && t.enabled && t.tick > before &&
            t.tick <= b.tick) {
          b.hit = true;
          why.kind = Stop::Kind::Breakpoint;
          why.breakpoint = t.id;
        }
      eventStop_.reset();
      if (b.hit) scan_->stops.emplace(b.tick, why);
    }
    scan_->boundaries.push_back(b);
    noteBoundary(held_, v);
    return;
  }
  Stop why;
  if (shouldStop(why)) park(why);
  noteBoundary(held_, vm(held_));
}

bool Session::event(int robot, Tick t, DebugEvent e) {
  if (scan_) {
    if (!scan_->hits) return false;
    for (const Breakpoint& b : breakpoints_)
      if (b.enabled && b.kind == Breakpoint::Kind::Event && b.event == e) {
        eventStop_ = eventStopOf(b, robot, t);
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
    eventStop_ = eventStopOf(b, robot, t);
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
  r.atOtherBreakpoint = true;
  throw r;
}

bool Session::watching(int robot) const {
  if (robot == held_ || scan_ || mode_.kind == Resume::Kind::Goto) return false;
  return std::any_of(watchpoints_.begin(), watchpoints_.end(),
                     [&](const Watchpoint& w) { return w.robot == robot && w.enabled; });
}

// A boundary of a robot not held that has watchpoints: a change there holds
// that robot from here, as its breakpoint does.
void Session::otherBoundary(const scheduler::MatchView& view, int robot) {
  view_ = &view;
  Stop why;
  const bool hit = watchpointHit(robot, why);
  noteBoundary(robot, view.vm(robot));
  if (!hit) return;
  Rewind r;
  r.how.kind = Resume::Kind::Hold;
  r.how.robot = robot;
  r.how.tick = view.vm(robot).now();
  r.from = r.how.tick;
  r.arrival = why;
  r.atOtherBreakpoint = true;
  throw r;
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
  if (watchpointHit(held_, why)) return true;
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
      return t > mode_.startTick || (mode_.startPending && !v.effectPending());
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
  anchor_ =
      mode_.kind == Resume::Kind::Goto && mode_.anchored ? std::min(mode_.tick, now()) : now();
  eventStop_.reset();
  for (Breakpoint& b : breakpoints_)
    if (b.kind == Breakpoint::Kind::Time) b.passed = b.tick <= lastStop_;
  refreshWatchpoints();
  // The robots not held compare their watched values from here on.
  for (int r = 0; r < robotCount(); ++r)
    if (r != held_) noteBoundary(r, vm(r));
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
  bool anchored = false;
  bool settled = false;
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
      anchored = !rewind.atOtherBreakpoint;
      target = anchored ? anchor_ : rewind.how.tick;
      arrival = rewind.arrival.kind == Stop::Kind::Entry ? arrival : rewind.arrival;
      break;
    default:
      if (const auto found = searchBack(rewind)) {
        target = found->tick;
        settled = found->settled;
        if (found->why) {
          // What stopped the robot going backwards, as a forward stop says it.
          arrival = *found->why;
          countHit(arrival);
        }
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
  mode_.anchored = anchored;
  mode_.settled = settled;
  lastStop_ = -1;
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

int Session::robotOfExpression(std::string& expression) const {
  for (int r = 0; r < robotCount(); ++r) {
    const std::string prefix = robotName(r) + ":";
    if (expression.rfind(prefix, 0) == 0 && expression.compare(prefix.size(), 1, ":") != 0) {
      expression.erase(0, prefix.size());
      expression.erase(0, expression.find_first_not_of(" \t"));
      return r;
    }
  }
  return held_;
}

std::vector<std::string> Session::takeNotices() { return std::exchange(notices_, {}); }

// ---- breakpoints ------------------------------------------------------------------

// ---- times ------------------------------------------------------------------

bool looksLikeTime(const std::string& word) {
  // A line is digits alone; a time ends in its unit (s, ms, us, t).
  return !word.empty() && (std::isdigit(static_cast<unsigned char>(word[0])) || word[0] == '.') &&
         (word.back() == 's' || word.back() == 't');
}

std::string secondsText(Tick t) { return fmt::format("{:.6f} s", timebase::secondsFromTicks(t)); }

std::string fileName(const std::string& path) {
  const auto slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

Tick parseTime(const std::string& text) {
  try {
    return timebase::parseTime(text, timebase::BareNumber::Ticks);
  } catch (const timebase::TimeError& e) {
    throw Error(e.what());
  }
}

}  // namespace simbot::debug
