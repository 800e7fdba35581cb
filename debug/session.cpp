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

// A watched object's bytes (no allocation once `bytes` has its size).
void readInto(const vm::Vm& v, const Watchpoint& w, std::vector<uint8_t>& bytes) {
  bytes.resize(w.size);
  for (uint32_t k = 0; k < w.size; ++k) bytes[k] = v.read8(static_cast<uint16_t>(w.address + k));
}

bool unchanged(const vm::Vm& v, const Watchpoint& w, const std::vector<uint8_t>& bytes) {
  for (uint32_t k = 0; k < w.size; ++k)
    if (v.read8(static_cast<uint16_t>(w.address + k)) != bytes[k]) return false;
  return true;
}

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
  // Hold: the other robot stopped at its own breakpoint at how.tick (the
  // match is brought to that tick), not a move of the hold at a stop.
  bool atOtherBreakpoint = false;
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

// Going backwards a change stops before what made it (the instruction or
// service at the boundary before the one that saw it), and the later value
// is the old one.
void Session::reverseWatchHit(Stop why) {
  std::swap(why.oldValue, why.newValue);
  why.reverse = true;
  // A library call's writes are judged once it is done: before the call.
  // A service's (writtenAt 0) happened in the last step alone.
  auto& seen = scan_->boundaries;
  size_t k = seen.size() - 1;
  if (why.writtenAt != 0)
    while (k > 0 && seen[k].inLibrary) --k;
  seen[k].hit = true;
  scan_->stops.emplace(seen[k].tick, std::move(why));
}

// What the next boundary's watchpoints compare with: this one.
void Session::noteBoundary(int robot, const vm::Vm& v) {
  LastBoundary& last = last_.at(static_cast<size_t>(robot));
  last.pc = v.pc();
  last.tick = v.now();
  last.interrupts = v.stats().interrupts;
  for (Watchpoint& w : watchpoints_)
    if (w.robot == robot) readInto(v, w, w.seen);
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

Stop Session::eventStopOf(const Breakpoint& b, int robot, Tick t) {
  Stop why;
  why.kind = Stop::Kind::Event;
  why.breakpoint = b.id;
  why.event = b.event;
  why.eventRobot = robot;
  why.note = fmt::format("at tick {}", t);
  return why;
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
    if (counting) {
      ++b.hits;
      if (b.ignore > 0) {
        --b.ignore;
        continue;
      }
    }
    why.kind = Stop::Kind::Breakpoint;
    why.breakpoint = b.id;
    return true;
  }
  return false;
}

bool Session::watchpointHit(int robot, Stop& why) {
  if (watchpoints_.empty()) return false;
  const vm::Vm& v = vm(robot);
  // A library routine writes over several steps: judged once it is done.
  // An interrupt service accepted between two of its steps (the serial
  // library's transmit service, the BIOS timer's: atomic) is judged at
  // once, on what changed since the step before.
  const bool serviced = serviceRan(robot, v);
  const bool inLibrary = v.inLibraryCall();
  if (inLibrary && !serviced) return false;
  for (size_t k = 0; k < watchpoints_.size(); ++k) {
    Watchpoint& w = watchpoints_[k];
    if (w.robot != robot || !w.enabled) continue;
    if (w.depth >= 0 && v.callDepth() + v.interruptDepth() < w.depth) {
      if (scan_) continue;
      why.kind = Stop::Kind::Watchpoint;
      why.breakpoint = w.id;
      why.note =
          fmt::format("watchpoint {} deleted: the call its variable lived in returned", w.id);
      why.removed = w.id;
      watchpoints_.erase(watchpoints_.begin() + static_cast<std::ptrdiff_t>(k));
      return true;
    }
    if (w.valid && unchanged(v, w, inLibrary ? w.seen : w.value)) continue;
    const bool first = !w.valid;
    readInto(v, w, w.value);
    w.valid = true;
    const std::string before = w.text;
    w.text = valueText(v, w);
    if (first) continue;
    w.writer = writer(robot, v);
    if (w.condition) {
      try {
        const inspect::Scope s = scope(robot, 0);
        if (!inspect::truth(s, w.condition->evaluate(s))) continue;
      } catch (const inspect::Error& e) {
        why.note = fmt::format("error in the condition of watchpoint {}: {}", w.id, e.what());
      }
    }
    if (!scan_) {
      ++w.hits;
      if (w.ignore > 0) {
        --w.ignore;
        continue;
      }
    }
    why.kind = Stop::Kind::Watchpoint;
    why.breakpoint = w.id;
    why.oldValue = before;
    why.newValue = w.text;
    why.writtenAt = serviced ? 0 : v.image().lineAt(last_.at(static_cast<size_t>(robot)).pc);
    why.writer = w.writer;
    return true;
  }
  return false;
}

// Whether an atomic interrupt service (the serial library's transmit
// service, the BIOS timer's) was accepted since the boundary before.
bool Session::serviceRan(int robot, const vm::Vm& v) const {
  const auto& irqs = v.stats().interrupts;
  const auto& before = last_.at(static_cast<size_t>(robot)).interrupts;
  for (vm::Irq irq : {vm::Irq::SerialTx, vm::Irq::Timer})
    if (irqs[static_cast<size_t>(irq)] != before[static_cast<size_t>(irq)]) return true;
  return false;
}

// Who made a change seen at this boundary: the service accepted at the
// boundary before, or the instruction that ran there (and the handler it
// ran in).
std::string Session::writer(int robot, const vm::Vm& v) const {
  const LastBoundary& last = last_.at(static_cast<size_t>(robot));
  const vm::Image& img = v.image();
  const vm::Symbol* fn = img.functionAt(last.pc);
  const std::string where =
      fmt::format("line {}{}", img.lineAt(last.pc), fn ? fmt::format(" in {}()", fn->name) : "");
  const auto& irqs = v.stats().interrupts;
  const auto ran = [&](vm::Irq irq) {
    return irqs[static_cast<size_t>(irq)] != last.interrupts[static_cast<size_t>(irq)];
  };
  if (ran(vm::Irq::SerialTx))
    return fmt::format(
        "the serial library's transmit interrupt (serial_tx), accepted at tick {} during {}",
        last.tick, where);
  if (ran(vm::Irq::Timer))
    return fmt::format("the BIOS timer service (PRT0), accepted at tick {} during {}", last.tick,
                       where);
  if (fn && fn->kind == vm::Symbol::Kind::Handler) return where + " [interrupt handler]";
  if (v.interruptDepth() > 0)
    for (const vm::Vm::Activation& a : v.activations())
      if (a.handler) {
        const vm::Symbol* h = img.functionAt(a.pc);
        return fmt::format("{} [in interrupt handler {}()]", where, h ? h->name : "?");
      }
  return where;
}

std::string Session::valueText(const vm::Vm& v, const Watchpoint& w) const {
  try {
    return inspect::format(inspect::Scope(v), w.object);
  } catch (const inspect::Error& e) {
    return fmt::format("<{}>", e.what());
  }
}

void Session::refreshWatchpoints() {
  for (Watchpoint& w : watchpoints_) {
    readInto(vm(w.robot), w, w.value);
    w.text = valueText(vm(w.robot), w);
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

// Every boundary of the held robot from the latest snapshot whose held clock
// is at or before `from` up to (not including) `end`, as a forward run
// meets them: each one when stepping, else at breakpoints and events only.
std::vector<Session::Boundary> Session::scanWindow(Tick from, Tick end, bool stepping, bool hits,
                                                   std::map<Tick, Stop>* stops) {
  restoreBefore(from, true);
  scan_ = Scan{end, stepping, hits, {}, {}, run_->view().vm(held_).now()};
  for (Watchpoint& w : watchpoints_) w.valid = false;
  try {
    forward();
  } catch (const ScanDone&) {
  } catch (...) {
    scan_.reset();
    throw;
  }
  std::vector<Boundary> found = std::move(scan_->boundaries);
  if (stops) stops->merge(scan_->stops);
  scan_.reset();
  return found;
}

void Session::countHit(const Stop& why) {
  if (why.kind != Stop::Kind::Breakpoint && why.kind != Stop::Kind::Event &&
      why.kind != Stop::Kind::Watchpoint)
    return;
  if (Breakpoint* b = findBreakpoint(why.breakpoint)) ++b->hits;
  for (Watchpoint& w : watchpoints_)
    if (w.id == why.breakpoint) ++w.hits;
}

std::optional<Session::Found> Session::searchBack(const Rewind& rw) {
  const Resume::Kind kind = rw.how.kind;
  const Tick c = rw.from;
  const int depthNow = rw.calls + rw.ints;
  std::map<Tick, Stop> stops;  // reverse-continue: what each hit reports
  const auto hitAt = [&](const Boundary& b) { return Found{b.tick, b.settled, stops.at(b.tick)}; };
  if (kind == Resume::Kind::ReverseContinue && watchpoints_.empty()) {
    // Breakpoints cost nothing to find: one pass from the start.
    const std::vector<Boundary> all = scanWindow(0, c, false, true, &stops);
    for (auto it = all.rbegin(); it != all.rend(); ++it)
      if (it->hit && it->tick < c) return hitAt(*it);
    return std::nullopt;
  }
  const bool stepping = true;
  const bool hits = kind == Resume::Kind::ReverseContinue;
  std::vector<Boundary> history;  // every boundary before c found so far, in order
  Tick windowEnd = c;
  const auto at = [](const Boundary& b) {
    return std::optional<Found>(Found{b.tick, b.settled, std::nullopt});
  };
  for (;;) {
    // The window before windowEnd: from the latest snapshot before it.
    Tick start = -1;
    for (auto it = snapshots_.rbegin(); it != snapshots_.rend(); ++it)
      if (it->second.robotClock(held_) < windowEnd) {
        start = it->second.robotClock(held_);
        break;
      }
    if (start < 0) return history.empty() ? std::nullopt : at(history.front());
    std::vector<Boundary> window = scanWindow(start, windowEnd, stepping, hits, &stops);
    history.insert(history.begin(), window.begin(), window.end());
    windowEnd = start;
    const bool complete = snapshots_.begin()->second.robotClock(held_) >= start;
    if (history.empty()) {
      if (complete) return std::nullopt;
      continue;
    }
    switch (kind) {
      case Resume::Kind::ReverseStepInstruction:
        return at(history.back());
      case Resume::Kind::ReverseContinue:
        for (auto it = history.rbegin(); it != history.rend(); ++it)
          if (it->hit) return hitAt(*it);
        break;
      case Resume::Kind::ReverseFinish:
        for (auto it = history.rbegin(); it != history.rend(); ++it)
          if (it->calls + it->ints < depthNow) return at(*it);
        break;
      default:
        if (const auto k = lineBefore(history, rw, complete)) return at(history[*k]);
        break;
    }
    if (complete) {
      const bool toStart = (kind == Resume::Kind::ReverseStep || kind == Resume::Kind::ReverseNext);
      return toStart ? at(history.front()) : std::nullopt;
    }
  }
}

// reverse-step, reverse-next (gdb's rules): from the middle of a line, back
// to where the robot entered it; from its start, to the start of the line
// before it (reverse-next passes over deeper calls and handlers). Out of a
// handler's first line, back to the instruction it interrupted. Handlers
// that interrupted the line on the way do not end it. Nothing while
// `history` (every boundary before the command's, oldest first) may not
// yet reach back far enough (not `complete`).
std::optional<size_t> Session::lineBefore(const std::vector<Boundary>& history, const Rewind& rw,
                                          bool complete) const {
  const bool over = rw.how.kind == Resume::Kind::ReverseNext;
  const int depthNow = rw.calls + rw.ints;
  std::vector<size_t> seen;
  for (size_t k = 0; k < history.size(); ++k)
    if (!over || history[k].calls + history[k].ints <= depthNow) seen.push_back(k);
  const auto same = [&](size_t a, int line, int calls, int ints) {
    const Boundary& b = history[a];
    return b.line == line && b.calls == calls && b.ints == ints;
  };
  // Back from seen[i] over the rest of the run of `line` it is in (and
  // handlers nested in that run); the run's first boundary, if known.
  const auto runStart = [&](ptrdiff_t i, int line, int calls, int ints) -> std::optional<size_t> {
    ptrdiff_t first = i;
    bool ended = false;  // something before the run is in the history
    for (ptrdiff_t k = i - 1; k >= 0 && !ended; --k) {
      const Boundary& b = history[seen[static_cast<size_t>(k)]];
      if (b.ints > ints && b.calls >= calls) continue;  // a handler inside the line
      if (same(seen[static_cast<size_t>(k)], line, calls, ints))
        first = k;
      else
        ended = true;
    }
    // Else the run may go on before the history, unless that is the start.
    if (!ended && !complete) return std::nullopt;
    return seen[static_cast<size_t>(first)];
  };
  const auto i = static_cast<ptrdiff_t>(seen.size()) - 1;
  if (i < 0) return std::nullopt;
  // The middle of a line: its start first.
  if (same(seen[static_cast<size_t>(i)], rw.line, rw.calls, rw.ints))
    return runStart(i, rw.line, rw.calls, rw.ints);
  const Boundary& prev = history[seen[static_cast<size_t>(i)]];
  if (prev.ints != rw.ints) return seen[static_cast<size_t>(i)];
  return runStart(i, prev.line, prev.calls, prev.ints);
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

Trigger& Session::trigger(int id) {
  if (Breakpoint* b = findBreakpoint(id)) return *b;
  for (Watchpoint& w : watchpoints_)
    if (w.id == id) return w;
  throw Error(fmt::format("no breakpoint or watchpoint {}", id));
}

void Session::setCondition(int id, const std::string& expression) {
  Trigger& t = trigger(id);
  if (expression.empty()) {
    t.condition.reset();
    return;
  }
  try {
    t.condition = std::make_shared<inspect::Expression>(expression);
  } catch (const inspect::Error& e) {
    throw Error(e.what());
  }
}

void Session::setIgnore(int id, int count) { trigger(id).ignore = std::max(count, 0); }

void Session::setEnabled(int id, bool enabled) {
  Trigger& t = trigger(id);
  if (enabled && !t.enabled)
    for (Watchpoint& w : watchpoints_)
      if (w.id == id) {
        // Compared from the value it has when enabled again.
        readInto(vm(w.robot), w, w.value);
        w.text = valueText(vm(w.robot), w);
      }
  t.enabled = enabled;
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

const Watchpoint& Session::watch(const std::string& expression, const std::string& condition,
                                 int robot) {
  if (robot < 0) robot = held_;
  if (robot >= robotCount()) throw Error("there is no such robot");
  Watchpoint w;
  try {
    w.expression = std::make_shared<inspect::Expression>(expression);
    if (!condition.empty()) w.condition = std::make_shared<inspect::Expression>(condition);
    const inspect::Scope s = robot == held_ ? scope() : scope(robot, 0);
    w.object = w.expression->evaluate(s);
    if (!w.object.inMemory)
      throw Error(fmt::format("'{}' is not an object in memory: nothing to watch", expression));
    // An auto: watched while the activation holding it lasts (its index
    // from the outermost, where calls and handlers both count).
    if (w.object.frame >= 0) w.depth = static_cast<int>(s.activations.size()) - 1 - w.object.frame;
    w.address = w.object.address;
    w.size = static_cast<uint32_t>(inspect::bytes(s, w.object).size());
    readInto(*s.vm, w, w.value);
    w.seen = w.value;
    w.text = inspect::format(s, w.object);
    w.valid = true;
  } catch (const inspect::Error& e) {
    throw Error(e.what());
  }
  w.id = nextId_++;
  w.robot = robot;
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
