// The cycle table: each opcode's cost is the exact sum of the Z180 sequence
// written beside it, along the path it takes, with the Z180's published
// T-states; knobs act globally and stay within their hardware ranges.
// Expected figures are summed by hand from the Z180 table in comments.
#include "vm/cost.h"

#include <gtest/gtest.h>

#include <stdexcept>

using namespace simbot::vm;

namespace {

uint32_t opCost(const CostTable& t, Op op) { return t.op[static_cast<int>(op)]; }
int32_t delta(const CostTable& t, Op op, int path) {
  return t.branchDelta[static_cast<int>(op)][path];
}
uint32_t libCost(const CostTable& t, Lib l) { return t.libCall[static_cast<int>(l)]; }

// Uncalibrated knobs: no memory wait states, 1 I/O wait state, no refresh.
TEST(Cost, SequencesSumPublishedTstates) {
  const auto t = makeCostTable(uncalibratedKnobs());
  EXPECT_EQ(opCost(t, Op::LDGW), 11u + 15u);        // PUSH HL; LD HL,(nn)
  EXPECT_EQ(opCost(t, Op::STGW), 16u + 9u);         // LD (nn),HL; POP HL
  EXPECT_EQ(opCost(t, Op::INCGW), 15u + 4u + 16u);  // LD HL,(nn); INC HL; LD (nn),HL
  EXPECT_EQ(opCost(t, Op::JMP), 9u);
  EXPECT_EQ(opCost(t, Op::CALL), 16u);
  EXPECT_EQ(opCost(t, Op::EI), 3u);
  // IM2 acknowledge and the six register saves of an interrupt function.
  EXPECT_EQ(t.interruptAccept, 19u + 4 * 11u + 2 * 14u);
}

TEST(Cost, ALibraryCallIsChargedOneCall) {
  const auto t = makeCostTable(uncalibratedKnobs());
  EXPECT_EQ(opCost(t, Op::LIB), 0u);  // the CALL is in the routine's sequence
  // outport: POP BC 9; POP HL 9; CALL 16; LD C,L 4; OUT (C),A 10 + 1 I/O
  // wait; RET 9 = 58.
  EXPECT_EQ(libCost(t, Lib::OUTPORT), 9u + 9 + 16 + 4 + 10 + 1 + 9);
  // ad_rd8: LD HL,nn 9; ADD HL,DE 7; CALL 16; OUT 10+1; OUT 10+1;
  // IN A,(n) 9+1; LD r,r 4; LD r,n 6; 4 x (SLA 7; RL 7); RET 9 = 171.
  EXPECT_EQ(libCost(t, Lib::AD_RD8), 9u + 7 + 16 + 11 + 11 + 10 + 4 + 6 + 4 * 14 + 9);
  // hv_enb: CALL 16; LD A,n 6; OUT (n),A 10+1; RET 9 = 42.
  EXPECT_EQ(libCost(t, Lib::HV_ENB), 16u + 6 + 11 + 9);
}

TEST(Cost, SerialCallsSaveDisableAndRestoreTheInterruptState) {
  const auto t = makeCostTable(uncalibratedKnobs());
  // ser_send_z1: POP 9; POP 9; CALL 16; LD A,I 6; PUSH AF 11; DI 3;
  // LD (nn),HL 16; LD (nn),DE 19; LD r,(HL) 6; LD A,(DE) 6; OUT 10+1;
  // LD A,(nn) 12; OR 4; OUT 10+1; POP AF 9; JP PO not taken 6; EI 3;
  // RET 9 = 166 (JP PO taken, 9, skips the EI: the same 166).
  EXPECT_EQ(libCost(t, Lib::SER_SEND_Z1),
            9u + 9 + 16 + 6 + 11 + 3 + 16 + 19 + 6 + 6 + 11 + 12 + 4 + 11 + 9 + 6 + 3 + 9);
  EXPECT_EQ(sequenceCost(kLibInfo[static_cast<int>(Lib::SER_SEND_Z1)].callSeq, 1).tstates,
            sequenceCost(kLibInfo[static_cast<int>(Lib::SER_SEND_Z1)].callSeq, 0).tstates);
  // ser_init_z1: POP 9; POP 9; CALL 16; LD A,I 6; PUSH AF 11; DI 3;
  // 4 x OUT 10+1; LD HL,nn 9; LD (nn),HL 16; LD (nn),HL 16; POP AF 9;
  // JP PO 6; EI 3; RET 9 = 166.
  EXPECT_EQ(libCost(t, Lib::SER_INIT_Z1),
            9u + 9 + 16 + 6 + 11 + 3 + 4 * 11 + 9 + 16 + 16 + 9 + 6 + 3 + 9);
  EXPECT_TRUE(kLibAtomic[static_cast<int>(Lib::SER_SEND_Z1)]);
  EXPECT_TRUE(kLibAtomic[static_cast<int>(Lib::SER_INIT_Z1)]);
  EXPECT_FALSE(kLibAtomic[static_cast<int>(Lib::STRCPY)]);
  EXPECT_FALSE(kLibAtomic[static_cast<int>(Lib::AD_RD8)]);
}

TEST(Cost, RetPopsIxOnlyForAutoFrames) {
  const auto t = makeCostTable(uncalibratedKnobs());
  EXPECT_EQ(opCost(t, Op::RET), 9u);  // static class: RET alone
  EXPECT_EQ(t.autoFrameRet, 12u);     // #class auto adds POP IX
}

TEST(Cost, BranchesChargeTheWayTheyGo) {
  const auto t = makeCostTable(uncalibratedKnobs());
  // JZ: LD A,L 4; OR H 4; POP HL 9; JP Z 6 not taken = 23; taken 9 = 26.
  EXPECT_EQ(opCost(t, Op::JZ), 23u);
  EXPECT_EQ(delta(t, Op::JZ, 1), 3);
  EXPECT_EQ(opCost(t, Op::JNZ), 23u);
  EXPECT_EQ(delta(t, Op::JNZ, 1), 3);
  // EQW: POP DE 9; OR A 4; SBC HL,DE 10; LD HL,0 9; JR NZ 6 not taken;
  // INC HL 4 = 42 (result 1); taken: JR 8 and no INC = 40 (result 0).
  EXPECT_EQ(opCost(t, Op::EQW), 42u);
  EXPECT_EQ(delta(t, Op::EQW, 1), -2);
  // LTW: POP 9; EX DE,HL 3; OR 4; SBC 10; LD HL,0 9 = 35, then
  //   overflow, result 1:     JP PO 6; XOR 4; JP 6; INC 4 = 55
  //   no overflow, result 1:  JP PO 9;        JP 6; INC 4 = 54
  //   overflow, result 0:     JP PO 6; XOR 4; JP 9        = 54
  //   no overflow, result 0:  JP PO 9;        JP 9        = 53
  EXPECT_EQ(opCost(t, Op::LTW), 55u);
  EXPECT_EQ(delta(t, Op::LTW, 1), -1);
  EXPECT_EQ(delta(t, Op::LTW, 2), -1);
  EXPECT_EQ(delta(t, Op::LTW, 3), -2);
  // LNOTW: LD A,L 4; OR H 4; LD HL,0 9; JR NZ 6; INC HL 4 = 27; taken 25.
  EXPECT_EQ(opCost(t, Op::LNOTW), 27u);
  EXPECT_EQ(delta(t, Op::LNOTW, 1), -2);
  // Opcodes without branches have no deltas.
  EXPECT_EQ(delta(t, Op::LDGW, 1), 0);
}

TEST(Cost, DebugHookIsItsSequenceWithJrNotTaken) {
  const auto t = makeCostTable(uncalibratedKnobs());
  // RST 28h 11; hook: PUSH AF 11; LD A,(nn) 12; OR A 4; JR NZ 6 (not
  // taken: no debugger attached); POP AF 9; RET 9 = 51.
  EXPECT_EQ(sequenceCost(kDebugHookSeq).tstates, 51);
  EXPECT_EQ(opCost(t, Op::DBG), 11u + 51u);
}

TEST(Cost, EveryOpcodeButLibHasACost) {
  const auto t = makeCostTable(uncalibratedKnobs());
  for (int i = 0; i < kOpCount; ++i) {
    if (static_cast<Op>(i) == Op::LIB) continue;
    EXPECT_GT(t.op[i], 0u) << kOpInfo[i].name;
  }
}

TEST(Cost, LibraryStepsAreAtMost100Tstates) {
  const auto t = makeCostTable(calibratedKnobs());
  for (int i = 0; i < kLibCount; ++i) EXPECT_LE(t.libStep[i], 100u) << kLibInfo[i].name;
}

TEST(Cost, WaitStatesChargeEveryMemoryAndIoCycle) {
  auto k = uncalibratedKnobs();
  const auto base = makeCostTable(k);
  k.memWaitStates = 1;
  const auto slow = makeCostTable(k);
  // PUSH HL: 3 memory cycles; LD HL,(nn): 5.
  EXPECT_EQ(opCost(slow, Op::LDGW), opCost(base, Op::LDGW) + 8u);
  // A taken JP cc reads 3 bytes, a not-taken one 2: the delta grows by 1.
  EXPECT_EQ(delta(slow, Op::JZ, 1), 3 + 1);
  k = uncalibratedKnobs();
  k.ioWaitStates = 4;
  const auto slowIo = makeCostTable(k);
  // outport has one I/O cycle (OUT (C),A): 1 -> 4 wait states.
  EXPECT_EQ(libCost(slowIo, Lib::OUTPORT), libCost(base, Lib::OUTPORT) + 3u);
  EXPECT_EQ(opCost(slowIo, Op::LDGW), opCost(base, Op::LDGW));
}

TEST(Cost, RefreshStretchesEverySequence) {
  auto k = uncalibratedKnobs();
  k.refreshTstates = 2;
  k.refreshInterval = 20;
  const auto t = makeCostTable(k);
  // 2 T-states every 20: +10 %, rounded per sequence. LDGW 26 -> 26 + 3;
  // JMP 9 -> 9 + 1; INCGW 35 -> 35 + 4 (3.5 rounds up).
  EXPECT_EQ(opCost(t, Op::LDGW), 29u);
  EXPECT_EQ(opCost(t, Op::JMP), 10u);
  EXPECT_EQ(opCost(t, Op::INCGW), 39u);
}

TEST(Cost, KnobsStayWithinTheirHardwareRanges) {
  auto bad = [](auto change) {
    auto k = uncalibratedKnobs();
    change(k);
    EXPECT_THROW(makeCostTable(k), std::invalid_argument);
  };
  bad([](CostKnobs& k) { k.memWaitStates = 4; });
  bad([](CostKnobs& k) { k.memWaitStates = -1; });
  bad([](CostKnobs& k) { k.ioWaitStates = 0; });
  bad([](CostKnobs& k) { k.ioWaitStates = 5; });
  bad([](CostKnobs& k) { k.refreshTstates = 1; });
  bad([](CostKnobs& k) {
    k.refreshTstates = 2;
    k.refreshInterval = 30;
  });
  EXPECT_NO_THROW(makeCostTable(calibratedKnobs()));
}

TEST(Cost, EpilogueWithoutEiIsCheaper) {
  auto k = uncalibratedKnobs();
  const auto with = makeCostTable(k);
  k.epilogueEi = false;
  const auto without = makeCostTable(k);
  EXPECT_EQ(opCost(with, Op::RETI), opCost(without, Op::RETI) + 3u);
}

}  // namespace
