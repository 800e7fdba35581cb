// Fast-forward of delay loops (issue 13). A marked loop (Image::delayLoops) whose code has the
// expected shape runs many passes in one step. Every pass from the same counter regime costs the
// same and touches nothing but its counter, so the VM measures one pass as stepped (arrival at the
// top to the next arrival, with no interrupt accepted in between) and then applies n more at once:
// the counter +n, the clock +n x the pass, the instruction count and the profile likewise. n stops
// short of the loop's exit and lands at or before the earliest tick at which anything can happen to
// this robot: the horizon of run() (the host stops a robot at every tick it raises a request or a
// device acts) and PRT0's next tick. The boundaries it skips are all before those, so nothing could
// have been accepted or stopped there; where it lands, the ordinary boundary follows. Breakpoints
// inside the loop turn it off.
#include "vm/state.h"

namespace simbot::vm {

void Vm::State::findLoops() {
  const auto& code = image->code;
  auto at = [&](uint32_t a) -> int { return a < code.size() ? code[a] : -1; };
  // Reads past the end of the code give 0 (a mark is not trusted yet).
  auto byte = [&](uint32_t a) -> uint32_t { return a < code.size() ? code[a] : 0; };
  auto u16at = [&](uint32_t a) { return byte(a) | (byte(a + 1) << 8); };
  auto u32at = [&](uint32_t a) { return u16at(a) | (u16at(a + 2) << 16); };
  auto is = [&](uint32_t a, Op op) { return at(a) == static_cast<int>(op); };
  auto rel = [&](uint32_t operand) {
    return static_cast<uint32_t>(static_cast<int32_t>(operand + 2) +
                                 static_cast<int16_t>(u16at(operand)));
  };
  for (const auto& mark : image->delayLoops) {
    uint32_t a = mark.top;
    if (mark.exit > code.size() || mark.exit <= a || mark.exit - a > kMaxLoopBytes) continue;
    const bool wide = is(a, Op::LDGL);
    if (!wide && !is(a, Op::LDGW)) continue;
    const uint32_t counter = u16at(a + 1);
    a += 3;
    if (!is(a, wide ? Op::PUSHL : Op::PUSHW)) continue;
    const uint32_t limit = wide ? u32at(a + 1) : u16at(a + 1);
    a += wide ? 5 : 3;
    const bool isSigned = is(a, Op::LTW) || is(a, Op::LEW) || is(a, Op::LTL) || is(a, Op::LEL);
    const bool inclusive = is(a, Op::LEW) || is(a, Op::LEUW) || is(a, Op::LEL) || is(a, Op::LEUL);
    const bool compares =
        wide ? is(a, Op::LTL) || is(a, Op::LTUL) || is(a, Op::LEL) || is(a, Op::LEUL)
             : is(a, Op::LTW) || is(a, Op::LTUW) || is(a, Op::LEW) || is(a, Op::LEUW);
    if (!compares) continue;
    a += 1;
    if (!is(a, Op::JZ) || rel(a + 1) != mark.exit) continue;
    a += 3;
    if (is(a, Op::DBG)) a += 1;
    if (!is(a, wide ? Op::INCGL : Op::INCGW) || u16at(a + 1) != counter) continue;
    a += 3;
    if (!is(a, Op::JMP) || rel(a + 1) != mark.top || a + 3 != mark.exit) continue;
    if (counter < kDataBase || counter + (wide ? 3 : 1) >= kMemorySize) continue;
    if (loopAtTop.empty()) loopAtTop.assign(code.size() + 1, -1);
    if (loopAtTop[mark.top] >= 0) continue;
    loopAtTop[mark.top] = static_cast<int16_t>(loops.size());
    loops.push_back(Loop{mark.top, mark.exit, counter, limit, wide, isSigned, inclusive});
  }
}

namespace {

using Loop = Vm::State::Loop;

// A counter value as a signed or unsigned number of the counter's width.
int64_t counterNumber(const Loop& loop, uint32_t x) {
  if (!loop.isSigned) return loop.wide ? int64_t{x} : int64_t{x & 0xFFFFu};
  return loop.wide ? static_cast<int32_t>(x) : static_cast<int16_t>(x);
}

// Passes still to run from `from` while the compare holds, the counter
// staying below the top of its range (it never wraps here).
int64_t passesLeft(const Loop& loop, uint32_t from) {
  const int64_t top = loop.isSigned ? (loop.wide ? INT32_MAX : INT16_MAX)
                                    : (loop.wide ? int64_t{UINT32_MAX} : int64_t{UINT16_MAX});
  const int64_t n = counterNumber(loop, loop.limit);
  const int64_t last = std::min(loop.inclusive ? n : n - 1, top - 1);
  const int64_t v = counterNumber(loop, from);
  return last >= v ? last - v + 1 : 0;
}

// The regime in which every pass costs the same: a signed compare's
// overflow branch is never taken when both sides are non-negative.
bool inRegime(const Loop& loop, uint32_t v) {
  return !loop.isSigned || (counterNumber(loop, v) >= 0 && counterNumber(loop, loop.limit) >= 0);
}

}  // namespace

bool Vm::State::fastForward(Tick until) {
  const int index = loopAtTop[pc];
  Loop& loop = loops[static_cast<size_t>(index)];
  uint32_t v = loop.wide ? rd32(loop.counter) : rd16(loop.counter);
  bool applied = false;
  const uint32_t mask = loop.wide ? 0xFFFFFFFFu : 0xFFFFu;
  const bool regime = inRegime(loop, v);
  if (measure.loop == index && measure.accepted == acceptances &&
      v == ((measure.counter + 1) & mask) && regime && !loop.breakpointInside &&
      inRegime(loop, measure.counter)) {
    const Tick pass = now - measure.start;
    loop.pass = pass;
    const Tick bound = std::min(until, nextTimer);
    const int64_t n =
        pass > 0 && bound > now ? std::min<int64_t>(passesLeft(loop, v), (bound - now) / pass) : 0;
    if (n > 0) {
      v += static_cast<uint32_t>(n);
      if (loop.wide)
        wr32(loop.counter, v);
      else
        wr16(loop.counter, v);
      now += n * pass;
      const uint64_t skipped =
          static_cast<uint64_t>(n) * (stats.instructions - measure.instructions);
      stats.instructions += skipped;
      stats.fastForwarded += skipped;
      if (profiling)
        for (uint32_t a = loop.top; a < loop.exit; ++a)
          profile[a] += static_cast<uint64_t>(n) * (profile[a] - measure.profile[a - loop.top]);
      applied = true;
    }
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
// runs that pass and the rest, each costing loop.pass, and touches nothing
// but its counter until the arrival at its top where the compare fails.
Tick Vm::State::quietUntil() const {
  if (fault || anyPending || lib.active || lib.awaitingBegin || burn || copy.left || halted ||
      measure.loop < 0)
    return now;
  const Loop& loop = loops[static_cast<size_t>(measure.loop)];
  if (pc < loop.top || pc >= loop.exit || measure.accepted != acceptances ||
      loop.breakpointInside || loop.pass <= 0 || !inRegime(loop, measure.counter))
    return now;
  const int64_t passes = passesLeft(loop, measure.counter);  // this one included
  if (passes <= 0) return now;
  return std::max(now, std::min(measure.start + passes * loop.pass, nextTimer));
}

}  // namespace simbot::vm
