// scheduler/robot.cpp -- one robot of a match: its board and program, how
// it runs to a round's horizon (alone, or held or watched by a debugger:
// DebugHook), its faults, exits, injections, reloads and trace samples.
// What its VM's bus accesses do is in robot_bus.cpp; the round loop in
// match.cpp.
#include <fmt/format.h>

#include <algorithm>
#include <string>
#include <utility>
#include <vector>

#include "scheduler/match_impl.h"

namespace simbot::scheduler::detail {

Robot::Robot(Match& m, int i, const RobotSpec& s, const vm::CostTable& costs, uint64_t seed)
    : spec(s),
      index(i),
      match(&m),
      board(s.image, *this, costs,
            board::StreamSeeds{
                streamSeed(seed, "memory-fill-" + s.name), streamSeed(seed, "eye-noise-" + s.name),
                streamSeed(seed, "gun-" + s.name), streamSeed(seed, "muzzle-" + s.name),
                streamSeed(seed, "dispersion-" + s.name)},
            s.controller),
      mainReturn(s.image.entry + static_cast<uint32_t>(vm::instructionSize(vm::Op::CALL))) {
  result.name = s.name;
  result.program = s.program;
  board.cpu.setBreakpoint(mainReturn);
  if (m.profiling()) board.cpu.enableProfile();
}

void Robot::attach(Match& m) {
  match = &m;
  board.attach(*this);
}

void Robot::reload(Tick t) {
  reloadPending = false;
  // A brown-out's reset holds the board: its end starts the program.
  if (powerOff) return;
  // The delay is long enough that no byte is left in the port.
  restartProgram(t);
  ++result.reloads;
  if (match->tracing()) match->emit(t, trace::rec::Reload{index, result.reloads});
  if (match->observer()) match->observer()->onReload(index, t);
}

void Robot::restartProgram(Tick t) {
  costates.clear();  // the restarted program's costatements start afresh
  // The VM keeps its breakpoints (main's return, the injections) and counters.
  board.reset(t);
  faultSeen = false;
  result.exited = false;
  // The motor controller keeps its latched command; the receiver's partial
  // frame is dropped (a fragment from before the crash never joins the
  // reloaded program's frames).
  receiver.clear();
  serialEventAt = -1;
  // Samples up to t were taken from the program before: the restarted one's
  // start at the next sample tick.
  snapshots.clear();
  const Tick interval = match->sampleInterval();
  nextSnapshot = (t / interval + 1) * interval;
}

void Robot::runTo(const Tick& horizon, vm::Continuation* more) {
  if (powerOff) return;  // held in reset: no instruction runs
  DebugHook* hook = match->debugger();
  if (hook && index == match->debugRobot()) return debugRunTo(horizon);
  const bool tracing = match->tracing();
  for (;;) {
    if (tracing) takeSnapshots();
    if (now() >= horizon) return;
    // A debugger's data breakpoint on this robot: one instruction at a time.
    const bool watched = hook && !board.cpu.halted() && hook->watching(index);
    if (watched && board.cpu.effectPending()) {
      board.cpu.settle();
      if (board.cpu.fault()) return noteFault();
      hook->otherBoundary(*match, index);
      continue;
    }
    Tick until = tracing ? std::min(horizon, nextSnapshot) : horizon;
    if (watched) until = std::min(until, now() + 1);
    const vm::Stop stop = board.cpu.run(until, more);
    if (stop == vm::Stop::Fault) return noteFault();
    if (stop == vm::Stop::Breakpoint) {
      noteBreakpoint();
      if (hook) hook->otherBreakpoint(*match, index);
    }
    if (watched) hook->otherBoundary(*match, index);
  }
}

void Robot::noteFault() {
  if (faultSeen) return;
  faultSeen = true;
  const vm::Fault* f = board.cpu.fault();
  const Tick at = f->tick;
  auto [calls, depth] = faultChain();
  FaultInfo info{f->message, timebase::secondsFromTicks(at), f->line, depth, calls};
  if (!result.fault) result.fault = info;
  result.faults.push_back(info);
  if (match->tracing())
    match->emit(at, trace::rec::Fault{index, f->message, f->line, depth, std::move(calls)});
  if (match->observer()) match->observer()->onHalt(index, at);
  match->faulted(index, at);
  debugEvent(at, DebugEvent::Fault);
}

void Robot::noteBreakpoint() {
  if (board.cpu.pc() == mainReturn) {
    result.exited = true;
    result.exitTick = now();
    if (match->tracing()) match->emit(now(), trace::rec::Exit{index});
    if (match->observer()) match->observer()->onHalt(index, now());
  }
  if (auto it = lineInjections.find(board.cpu.pc()); it != lineInjections.end()) {
    const int hit = ++lineHits[board.cpu.pc()];
    for (int k : it->second)
      if (match->injection(k).count == hit) inject(now(), match->injection(k));
  }
}

// The debugged robot runs as runTo runs it, stopping where the debugger
// asks (DebugHook): each run of the VM ends at the horizon, a sample tick,
// the debugger's tick or the next instruction when stepping. A halted VM
// (main returned) is never stepped: its clock runs on without boundaries.
void Robot::debugRunTo(Tick horizon) {
  DebugHook& hook = *match->debugger();
  const bool tracing = match->tracing();
  for (;;) {
    if (tracing) takeSnapshots();
    if (now() >= horizon || board.cpu.fault()) return;
    const bool stepping = hook.stepping() && !board.cpu.halted();
    // A step from a library call's last tick ends after its effect.
    if (debugLook || (!stepping && hook.until() <= now()) ||
        (stepping && board.cpu.effectPending())) {
      debugLook = false;
      look(hook);
      continue;
    }
    Tick until = tracing ? std::min(horizon, nextSnapshot) : horizon;
    until = std::min(until, stepping ? now() + 1 : hook.until());
    const vm::Stop stop = board.cpu.run(until);
    if (stop == vm::Stop::Fault) {
      noteFault();
      look(hook);
      return;
    }
    if (stop == vm::Stop::Breakpoint) noteBreakpoint();
    if (stop == vm::Stop::Breakpoint || stop == vm::Stop::Host ||
        (stepping && !board.cpu.halted())) {
      // At or past the horizon the round's events there (serial bytes,
      // roots, requests) are still to come: looked at in the next round,
      // after them, as any place reached there is.
      if (now() >= horizon) {
        debugLook = true;
        return;
      }
      look(hook);
    }
  }
}

void Robot::look(DebugHook& hook) {
  if (hook.settles() && board.cpu.effectPending()) {
    board.cpu.settle();
    if (board.cpu.fault()) noteFault();
  }
  match->bringOthersTo(index, hook.othersTo(now()));
  hook.boundary(*match);
}

void Robot::debugEvent(Tick t, DebugEvent e) {
  DebugHook* hook = match->debugger();
  if (!hook || !hook->event(index, t, e)) return;
  Robot& held = match->debugged();
  // Inside the held robot's own run: it stops at its next boundary.
  if (&held == this && e != DebugEvent::Fault && !match->betweenRounds())
    board.cpu.stopAtNextBoundary();
  else
    held.debugLook = true;
}

// The VM's state at its first boundary at or after each sample tick it has
// reached: it was stopped there (runTo), or it idled there (halted).
void Robot::takeSnapshots() {
  while (nextSnapshot <= now()) {
    snapshots.push_back(Snapshot{nextSnapshot, board.cpu.line(),
                                 spec.image.functionAt(board.cpu.pc()),
                                 board.cpu.interruptDepth() > 0, watchedValues()});
    nextSnapshot += match->sampleInterval();
  }
}

// The snapshot of sample tick t; a faulted robot stays where it faulted.
Robot::Snapshot Robot::snapshotFor(Tick t) {
  while (!snapshots.empty() && snapshots.front().tick < t) snapshots.pop_front();
  if (!snapshots.empty() && snapshots.front().tick == t) return snapshots.front();
  const uint32_t pc = board.cpu.pc();
  return Snapshot{t, board.cpu.fault() ? board.cpu.fault()->line : spec.image.lineAt(pc),
                  spec.image.functionAt(pc), false, watchedValues()};
}

}  // namespace simbot::scheduler::detail
