// The constant half of a VM (program.h): the image decoded once for its
// cost table, and the dispatch tables a VM's breakpoints patch.
#include "vm/program.h"

#include <algorithm>

#include "vm/state.h"

namespace simbot::vm::detail {

Program::Program(const Image& img, const CostTable& table) : image(&img), costs(table) {
  const auto& code = image->code;
  const auto size = static_cast<uint32_t>(code.size());
  padded = code;
  padded.resize(size + kCodePad, 0);
  returnFrame = image->returnFrames();
  // The code is instructions end to end (the compiler puts no data in it).
  instructionStart.assign(size, 0);
  for (uint32_t a = 0; a < size;) {
    instructionStart[a] = 1;
    a += code[a] < kOpCount ? static_cast<uint32_t>(instructionSize(static_cast<Op>(code[a]))) : 1;
  }
  handlerFor.fill(-1);
  for (const auto& v : image->vectors) handlerFor[v.vector] = v.handler;
  findLoops();
  setSuperSpans();
  plain = std::make_shared<const Dispatch>(*this, decode(), std::vector<uint8_t>{});
}

int64_t Program::relTargetAt(uint32_t address) const {
  return int64_t{address} + 3 + static_cast<int16_t>(le16(&padded[address + 1]));
}

// Per code address the opcode the fast path may run there, else kTrap.
std::vector<uint8_t> Program::decode() const {
  const auto& code = image->code;
  const auto size = static_cast<uint32_t>(code.size());
  std::vector<uint8_t> ops(size + kCodePad, kTrap);
  for (uint32_t a = 0; a < size; ++a) {
    const uint8_t b = code[a];
    if (b >= kOpCount) continue;
    const Op op = static_cast<Op>(b);
    if (a + static_cast<uint32_t>(instructionSize(op)) > size) continue;
    if ((op == Op::JMP || op == Op::JZ || op == Op::JNZ) &&
        (relTargetAt(a) < 0 || relTargetAt(a) >= size))
      continue;
    if (op == Op::CALL && static_cast<uint32_t>(padded[a + 1] | (padded[a + 2] << 8)) >= size)
      continue;
    ops[a] = b;
  }
  if (costs.knobs.fastForward)
    for (const Loop& loop : loops) ops[loop.top] = kTrap;
  return ops;
}

// Fast-forward's loops (fast_forward.cpp): a marked loop (Image::delayLoops)
// whose code has the expected shape.
void Program::findLoops() {
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
    Loop loop{mark.top, mark.exit, counter, limit, wide, isSigned, inclusive};
    const int64_t top = isSigned ? (wide ? INT32_MAX : INT16_MAX)
                                 : (wide ? int64_t{UINT32_MAX} : int64_t{UINT16_MAX});
    const int64_t n = loop.number(limit);
    loop.last = std::min(inclusive ? n : n - 1, top - 1);
    loop.limitInRegime = !isSigned || n >= 0;
    loops.push_back(loop);
  }
}

void Program::setSuperSpans() {
  auto slowest = [&](Op op) {
    const auto o = static_cast<int>(op);
    return std::max(0, *std::max_element(costs.branchDelta[o].begin(), costs.branchDelta[o].end()));
  };
  for (int i = 0; i < kSuperCount; ++i) {
    const SuperShape& shape = kSuperShapes[i];
    // The boundary after the last piece is NEXT's to test, as the
    // unfused piece's would be; a long last piece's steps have boundaries
    // before it (L_Long_), the last at most a tick before its end.
    uint32_t span = static_cast<uint32_t>(slowest(shape.pieces[0]));
    for (int k = 1; k < shape.n - 1; ++k)
      span += costs.op[static_cast<int>(shape.pieces[k])] +
              static_cast<uint32_t>(slowest(shape.pieces[k]));
    const auto last = static_cast<int>(shape.pieces[shape.n - 1]);
    if (costs.op[last] > kMaxStepTstates)
      span += costs.op[last] - 1 + static_cast<uint32_t>(slowest(shape.pieces[shape.n - 1]));
    superSpan[i] = span;
    superAfter[i] = {};
    for (int k = shape.n - 2; k >= 0; --k)
      superAfter[i][k] = superAfter[i][k + 1] + costs.op[static_cast<int>(shape.pieces[k + 1])];
  }
}

// ---- dispatch ---------------------------------------------------------------

Dispatch::Dispatch(const Program& program, std::vector<uint8_t> ops,
                   std::vector<uint8_t> breakpoints)
    : ops_(std::move(ops)), breakpoints_(std::move(breakpoints)) {
  const auto set = [](uint8_t b) { return b != 0; };
  anyBreakpoint_ = std::any_of(breakpoints_.begin(), breakpoints_.end(), set);
  // Kept here, so that no arrival at a loop's top scans its bytes.
  loopBreak_.assign(program.loops.size(), 0);
  if (anyBreakpoint_)
    for (size_t k = 0; k < program.loops.size(); ++k)
      loopBreak_[k] = std::any_of(breakpoints_.begin() + program.loops[k].top,
                                  breakpoints_.begin() + program.loops[k].exit, set);
}

std::shared_ptr<const Dispatch> Dispatch::withBreakpoint(const Program& program, uint32_t address,
                                                         bool enabled) const {
  const size_t size = program.image->code.size() + 1;
  std::vector<uint8_t> breakpoints = breakpoints_;
  if (breakpoints.empty()) breakpoints.assign(size, 0);
  std::vector<uint8_t> ops = ops_;
  breakpoints[address] = enabled ? 1 : 0;
  ops[address] = enabled ? Program::kTrap : program.plain->ops_[address];
  if (std::none_of(breakpoints.begin(), breakpoints.end(), [](uint8_t b) { return b != 0; }))
    return program.plain;
  return std::make_shared<const Dispatch>(program, std::move(ops), std::move(breakpoints));
}

int Dispatch::superinstructionAt(const Program& program, uint32_t address) const {
  const auto end = static_cast<uint32_t>(ops_.size());
  if (address >= end || ops_[address] >= kOpCount) return -1;
  const int first = ops_[address];
  for (int j = kSuperByFirst.begin[static_cast<size_t>(first)];
       j < kSuperByFirst.begin[static_cast<size_t>(first) + 1]; ++j) {
    const int i = kSuperByFirst.entry[static_cast<size_t>(j)];
    const SuperShape& shape = kSuperShapes[i];
    uint32_t a = address;
    int k = 0;
    for (; k < shape.n; ++k) {
      const auto o = static_cast<uint8_t>(shape.pieces[k]);
      // The first piece is dispatched as usual: it must be an ordinary one.
      if (a >= end || ops_[a] != o || (k == 0 && program.costs.op[o] > kMaxStepTstates)) break;
      // decode() made a JMP or CALL out of the code a trap: its target is in it.
      if (shape.pieces[k] == Op::JMP)
        a = static_cast<uint32_t>(program.relTargetAt(a));
      else if (shape.pieces[k] == Op::CALL)
        a = le16(&program.padded[a + 1]);
      else
        a += static_cast<uint32_t>(instructionSize(shape.pieces[k]));
    }
    if (k == shape.n) return i;
  }
  return -1;
}

const Fast* Dispatch::build(int k, const Program& program, const Labels& labels) const {
  const std::lock_guard<std::mutex> lock(building_);
  auto& table = fast_[static_cast<size_t>(k)];
  if (table.empty()) {
    table.resize(ops_.size());
    for (uint32_t a = 0; a < ops_.size(); ++a) {
      const uint8_t o = ops_[a];
      const bool trap = o == Program::kTrap;
      const bool isLong = !trap && program.costs.op[o] > kMaxStepTstates;
      const void* label = isLong ? labels.longOp : labels.op[o];
      if (labels.super && !trap && !isLong) {
        const int s = superinstructionAt(program, a);
        if (s >= 0) label = labels.super[s];
      }
      const uint32_t cost = trap ? 0u : isLong ? kMaxStepTstates : program.costs.op[o];
      table[a] = Fast{label, cost, o};
    }
    built_[static_cast<size_t>(k)].store(table.data(), std::memory_order_release);
  }
  return table.data();
}

}  // namespace simbot::vm::detail
