// Fast-forward of delay loops (issue 13). A marked loop (Image::delayLoops) whose code has the
// expected shape runs many passes in one step. Every pass from the same counter regime costs the
// same and touches nothing but its counter, so the VM measures one pass as stepped (arrival at the
// top to the next arrival, with no interrupt accepted in between) and then applies n more at once:
// the counter +n, the clock +n x the pass, the instruction count and the profile likewise. Once a
// loop's pass is measured, later arrivals (another run, another entry) apply at once. n stops
// short of the loop's exit and lands at or before the earliest tick at which anything can happen to
// this robot: the horizon of run() (the host stops a robot at every tick it raises a request or a
// device acts) and PRT0's next tick. The boundaries it skips are all before those, so nothing could
// have been accepted or stopped there; where it lands, the ordinary boundary follows. Breakpoints
// inside the loop turn it off. Which loops have that shape is the Program's (program.cpp
// findLoops).
#include "vm/state.h"

namespace simbot::vm {

namespace {

using Loop = Program::Loop;

// Passes still to run from `from` while the compare holds, the counter
// staying below the top of its range (it never wraps here).
int64_t passesLeft(const Loop& loop, uint32_t from) {
  const int64_t v = loop.number(from);
  return loop.last >= v ? loop.last - v + 1 : 0;
}

// The regime in which every pass costs the same: a signed compare's
// overflow branch is never taken when both sides are non-negative.
bool inRegime(const Loop& loop, uint32_t v) {
  return !loop.isSigned || (loop.limitInRegime && loop.number(v) >= 0);
}

}  // namespace

// n more passes of loop k from counter value v at once, n as many as stay
// below the loop's exit and land at or before min(until, PRT0's tick);
// `measured`: the pass just stepped is the measure (the profile's deltas
// are taken from it).
[[gnu::always_inline]] inline bool Vm::State::applyPasses(size_t k, uint32_t& v, Tick until,
                                                          bool measured) {
  const Loop& loop = program->loops[k];
  const Tick pass = loopPass[k];
  const Tick bound = std::min(until, nextTimer);
  const int64_t n =
      pass > 0 && bound > now ? std::min<int64_t>(passesLeft(loop, v), (bound - now) / pass) : 0;
  if (n <= 0) return false;
  v += static_cast<uint32_t>(n);
  if (loop.wide)
    wr32(loop.counter, v);
  else
    wr16(loop.counter, v);
  now += n * pass;
  const uint64_t skipped = static_cast<uint64_t>(n) * loopInstructions[k];
  stats.instructions += skipped;
  stats.fastForwarded += skipped;
  if (profiling && measured)
    for (uint32_t a = loop.top; a < loop.exit; ++a)
      profile[a] += static_cast<uint64_t>(n) * (profile[a] - measure.profile[a - loop.top]);
  return true;
}

bool Vm::State::fastForward(Tick until) {
  const int index = program->loopAtTop[pc];
  const Loop& loop = program->loops[static_cast<size_t>(index)];
  uint32_t v = loop.wide ? rd32(loop.counter) : rd16(loop.counter);
  bool applied = false;
  const uint32_t mask = loop.wide ? 0xFFFFFFFFu : 0xFFFFu;
  const auto k = static_cast<size_t>(index);
  if (dispatch->breakpointInLoop(k) || !inRegime(loop, v)) {
    // Stepped: nothing is applied, the pass is measured all the same.
  } else if (measure.loop == index && measure.accepted == acceptances &&
             v == ((measure.counter + 1) & mask) && inRegime(loop, measure.counter) &&
             passesLeft(loop, measure.counter) > 0) {
    // The pass just stepped was one (the compare held at its start: not
    // an exit at the top of an unsigned counter's range and a re-entry
    // at 0): its cost and count, the same for every pass of the regime.
    loopPass[k] = now - measure.start;
    loopInstructions[k] = stats.instructions - measure.instructions;
    applied = applyPasses(k, v, until, true);
  } else if (loopPass[k] > 0 && !profiling && !(anyPending && iff1)) {
    // A pass of this loop was measured before (at an earlier entry or
    // run): it costs what every pass does, so the passes are applied at
    // this first arrival, where the measured one would have been stepped
    // first. They land where stepping one pass and applying the rest
    // would: n' = floor((B - t) / p) = 1 + floor((B - t - p) / p). The
    // profiling run keeps measuring (its profile takes the pass's
    // per-instruction deltas). Not while a request IFF1 lets in waits for
    // EI's shadow: it is accepted inside the pass that would be stepped.
    applied = applyPasses(k, v, until, false);
  }
  // The pass that starts here is measured (after passes applied, the VM has
  // landed at the top: quietUntil needs the measure there too).
  measure.loop = index;
  measure.start = now;
  measure.counter = v;
  measure.instructions = stats.instructions;
  measure.accepted = acceptances;
  if (profiling)
    std::copy(profile.begin() + loop.top, profile.begin() + loop.exit, measure.profile.begin());
  return applied;
}

// While the VM is inside the pass that began at measure.start (the compare
// held there and nothing was accepted since, so it only counts), the loop
// runs that pass and the rest, each costing its measured pass (loopPass), and touches nothing
// but its counter until the arrival at its top where the compare fails.
Tick Vm::State::quietUntil() const {
  if (fault || anyPending || lib.active || lib.awaitingBegin || burn || copy.left || halted ||
      measure.loop < 0)
    return now;
  const auto index = static_cast<size_t>(measure.loop);
  const Loop& loop = program->loops[index];
  const Tick pass = loopPass[index];
  if (pc < loop.top || pc >= loop.exit || measure.accepted != acceptances ||
      dispatch->breakpointInLoop(index) || pass <= 0 || !inRegime(loop, measure.counter))
    return now;
  const int64_t passes = passesLeft(loop, measure.counter);  // this one included
  if (passes <= 0) return now;
  return std::max(now, std::min(measure.start + passes * pass, nextTimer));
}

Tick Vm::quietUntil() const { return s_->quietUntil(); }

}  // namespace simbot::vm
