// The cycle table: each opcode's cost is the sum of the Z180 sequence written
// beside it, with the Z180's published T-states; knobs act globally.
#include "vm/cost.h"

#include <gtest/gtest.h>

using namespace simbot::vm;

namespace {

uint32_t opCost(const CostTable& t, Op op) { return t.op[static_cast<int>(op)]; }

TEST(Cost, SequencesSumPublishedTstates) {
  const auto t = makeCostTable(uncalibratedKnobs());
  EXPECT_EQ(opCost(t, Op::LDGW), 11u + 15u);        // PUSH HL; LD HL,(nn)
  EXPECT_EQ(opCost(t, Op::STGW), 16u + 9u);         // LD (nn),HL; POP HL
  EXPECT_EQ(opCost(t, Op::INCGW), 15u + 4u + 16u);  // LD HL,(nn); INC HL; LD (nn),HL
  EXPECT_EQ(opCost(t, Op::JMP), 9u);
  EXPECT_EQ(opCost(t, Op::CALL), 16u);
  EXPECT_EQ(opCost(t, Op::RET), 12u + 9u);  // POP IX; RET
  EXPECT_EQ(opCost(t, Op::EI), 3u);
  EXPECT_EQ(opCost(t, Op::DBG), 11u + static_cast<uint32_t>(uncalibratedKnobs().debugHookTstates));
  // IM2 acknowledge and the six register saves of an interrupt function.
  EXPECT_EQ(t.interruptAccept, 19u + 4 * 11u + 2 * 14u);
}

TEST(Cost, EveryOpcodeHasACost) {
  const auto t = makeCostTable(uncalibratedKnobs());
  for (int i = 0; i < kOpCount; ++i) EXPECT_GT(t.op[i], 0u) << kOpInfo[i].name;
}

TEST(Cost, LibraryStepsAreAtMost100Tstates) {
  const auto t = makeCostTable(calibratedKnobs());
  for (int i = 0; i < kLibCount; ++i) EXPECT_LE(t.libStep[i], 100u) << kLibInfo[i].name;
}

TEST(Cost, WaitStatesChargeEveryMemoryCycle) {
  auto k = uncalibratedKnobs();
  const auto base = makeCostTable(k);
  k.memWaitStates = 1;
  const auto slow = makeCostTable(k);
  // PUSH HL: 3 memory cycles; LD HL,(nn): 5.
  EXPECT_EQ(opCost(slow, Op::LDGW), opCost(base, Op::LDGW) + 8u);
}

TEST(Cost, EpilogueWithoutEiIsCheaper) {
  auto k = uncalibratedKnobs();
  const auto with = makeCostTable(k);
  k.epilogueEi = false;
  const auto without = makeCostTable(k);
  EXPECT_EQ(opCost(with, Op::RETI), opCost(without, Op::RETI) + 3u);
}

}  // namespace
