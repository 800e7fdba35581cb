// The decoder's side of the idioms (idioms.h): which one starts at an
// address, and what its pieces cost under this VM's cost table.
#include <algorithm>
#include <array>

#include "vm/state.h"

namespace simbot::vm {

namespace {
// The idioms by their first two opcodes, in kIdiomShapes' order (decoding
// runs at every VM's first run: a small program's whole run can be shorter).
struct ByStart {
  uint8_t first, second;
  std::array<int8_t, kIdiomCount> idioms;
  int count;
};
constexpr auto kByStart = [] {
  std::array<ByStart, kIdiomCount> table{};
  int used = 0;
  for (int i = 0; i < kIdiomCount; ++i) {
    const auto first = static_cast<uint8_t>(kIdiomShapes[i].pieces[0]);
    const auto second = static_cast<uint8_t>(kIdiomShapes[i].pieces[1]);
    int k = 0;
    while (k < used && !(table[k].first == first && table[k].second == second)) ++k;
    if (k == used) table[used++] = ByStart{first, second, {}, 0};
    table[k].idioms[table[k].count++] = static_cast<int8_t>(i);
  }
  return table;
}();
constexpr std::array<bool, 256> kStartsIdiom = [] {
  std::array<bool, 256> starts{};
  for (const IdiomShape& shape : kIdiomShapes) starts[static_cast<uint8_t>(shape.pieces[0])] = true;
  return starts;
}();
}  // namespace

bool Vm::State::wrapsAt(uint32_t address) const {
  return (padded[address + 1] | (padded[address + 2] << 8)) == 0xFFFF;
}

void Vm::State::setIdiomCosts() {
  for (int i = 0; i < kIdiomCount; ++i) {
    const IdiomShape& shape = kIdiomShapes[i];
    IdiomCost c;
    for (int k = 1; k < shape.n; ++k) {
      const auto o = static_cast<int>(shape.pieces[k]);
      c.base += costs.op[o];
      // The last piece ends at the next NEXT, unless it is longer than
      // kMaxStepTstates: then its steps' boundaries (L_Long_) must all
      // come before `limit` too, its end included.
      if (k == shape.n - 1 && costs.op[o] <= kMaxStepTstates) continue;
      // Its slowest path: unused path slots hold 0, which only errs high.
      const int32_t slowest =
          *std::max_element(costs.branchDelta[o].begin(), costs.branchDelta[o].end());
      c.span += costs.op[o] + static_cast<uint32_t>(std::max(slowest, 0));
    }
    const Op last = shape.pieces[shape.n - 1];
    if (shape.n == 4 && (last == Op::JZ || last == Op::JNZ)) {
      const auto& compare = costs.branchDelta[static_cast<int>(shape.pieces[2])];
      const auto& branch = costs.branchDelta[static_cast<int>(last)];
      for (int p = 0; p < 4; ++p)
        for (int t = 0; t < 2; ++t)
          c.path[p * 2 + t] =
              static_cast<uint32_t>(static_cast<int32_t>(c.base) + compare[p] + branch[t]);
    }
    idiomCosts[i] = c;
  }
  // A join's boundaries: after each of its closer's pieces (the last one's
  // is its target's start), then inside the target, at the slowest paths.
  auto slowest = [&](Op op) {
    const auto o = static_cast<int>(op);
    const int32_t delta =
        *std::max_element(costs.branchDelta[o].begin(), costs.branchDelta[o].end());
    return costs.op[o] + static_cast<uint32_t>(std::max(delta, 0));
  };
  // (Per closer and per target, then their sums: this runs at every VM's
  // first run.)
  std::array<uint32_t, kJoinCloserCount> closerSpan{};
  for (int c = 0; c < kJoinCloserCount; ++c) {
    const int closer = kJoinClosers[c];
    if (closer < 0) {
      closerSpan[c] = slowest(Op::JMP);  // INCGW a; JMP t
    } else {
      const IdiomShape& shape = kIdiomShapes[closer];
      for (int k = 1; k < shape.n; ++k) closerSpan[c] += slowest(shape.pieces[k]);
    }
  }
  std::array<uint32_t, kJoinTargetCount> targetSpan{};
  for (int t = 0; t < kJoinTargetCount; ++t) {
    const int target = kJoinTargets[t];
    targetSpan[t] = slowest(kIdiomShapes[target].pieces[0]) + idiomCosts[target].span;
  }
  for (int j = 0; j < kJoinEnd; ++j)
    joinSpans[j] = closerSpan[j / kJoinTargetCount] + targetSpan[j % kJoinTargetCount];
}

int Vm::State::idiomAt(uint32_t address) const {
  const auto end = static_cast<uint32_t>(dispatch.size());
  if (address >= end || !kStartsIdiom[dispatch[address]]) return -1;
  const uint8_t first = dispatch[address];
  const uint32_t next = address + static_cast<uint32_t>(instructionSize(static_cast<Op>(first)));
  if (next >= end) return -1;
  const uint8_t second = dispatch[next];
  for (const ByStart& group : kByStart) {
    if (group.count == 0) break;
    if (group.first != first || group.second != second) continue;
    for (int g = 0; g < group.count; ++g) {
      const int i = group.idioms[g];
      const IdiomShape& shape = kIdiomShapes[i];
      uint32_t a = address;
      int k = 0;
      for (; k < shape.n; ++k) {
        const auto o = static_cast<uint8_t>(shape.pieces[k]);
        // The first piece is dispatched as usual: it must be an ordinary one.
        if (a >= end || dispatch[a] != o || (k == 0 && costs.op[o] > kMaxStepTstates)) break;
        // The handlers read and write globals' words as one access: a word
        // at 0xFFFF, which wraps to 0x0000, runs unfused.
        if ((shape.pieces[k] == Op::LDGW || shape.pieces[k] == Op::STGW) && wrapsAt(a)) break;
        a += static_cast<uint32_t>(instructionSize(shape.pieces[k]));
      }
      if (k == shape.n) return i;
    }
    return -1;
  }
  return -1;
}

int Vm::State::joinAt(uint32_t address, int idiom) const {
  const auto end = static_cast<uint32_t>(dispatch.size());
  if (address >= end) return -1;
  // The closer, and where its JMP is.
  int closer = -1;
  uint32_t jump = 0;
  if (dispatch[address] == static_cast<uint8_t>(Op::INCGW) &&
      costs.op[static_cast<int>(Op::INCGW)] <= kMaxStepTstates) {
    closer = 0;
    jump = address + static_cast<uint32_t>(instructionSize(Op::INCGW));
    if (jump >= end || dispatch[jump] != static_cast<uint8_t>(Op::JMP) || wrapsAt(address))
      return -1;
  } else if (idiom >= 0) {
    for (int c = 1; c < kJoinCloserCount; ++c)
      if (kJoinClosers[c] == idiom) closer = c;
    if (closer < 0) return -1;
    jump = address;
    const IdiomShape& shape = kIdiomShapes[idiom];
    for (int k = 0; k < shape.n - 1; ++k)
      jump += static_cast<uint32_t>(instructionSize(shape.pieces[k]));
  } else {
    return -1;
  }
  // decode() made a JMP outside the code a trap: its target is in the code.
  const auto rel = static_cast<int16_t>(padded[jump + 1] | (padded[jump + 2] << 8));
  const auto target = static_cast<uint32_t>(static_cast<int64_t>(jump) + 3 + rel);
  const int there = idiomAt(target);
  for (int t = 0; t < kJoinTargetCount; ++t)
    if (kJoinTargets[t] == there) return closer * kJoinTargetCount + t;
  return -1;
}

}  // namespace simbot::vm
