// The cycle table: each opcode's cost is the exact sum of the Z180 sequence
// written beside it, along the path it takes, with the Z180's published
// T-states; knobs act globally and stay within their hardware ranges.
// Expected figures are summed by hand from the Z180 table in comments.
#include <gtest/gtest.h>

#include <stdexcept>

#include "vm/cost_sums.h"

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
  // IM2 acknowledge (the Z180's 18, z180.def) and the six register saves
  // of an interrupt function.
  EXPECT_EQ(t.interruptAccept, 18u + 4 * 11u + 2 * 14u);
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

// The 16-bit shifts: LD A,E; OR A; JR Z jumps over a DJNZ loop of n passes
// (n = the count's low byte). Z180 table: POP DE 9; EX DE,HL 3; LD A,E 4;
// OR A 4 = 20, then
//   n = 0:  JR Z taken 8 = 28;
//   n >= 1: JR Z not taken 6; LD B,A 4 = 30; n x body; DJNZ taken 9
//           (n - 1) times and not taken 7 once.
// SHLW's body is ADD HL,HL 7: n = 1 is 30 + 7 + 7 = 44, n = 5 is
// 30 + 35 + 36 + 7 = 108, n = 15 is 30 + 105 + 126 + 7 = 268; each pass
// after the first adds 7 + 9 = 16. SHRW's and SHRUW's body is SRA H (SRL
// H) 7; RR L 7 = 14: n = 1 is 51, n = 5 is 30 + 70 + 36 + 7 = 143,
// n = 15 is 30 + 210 + 126 + 7 = 373; each further pass 14 + 9 = 23.
TEST(Cost, ShiftsChargeTheirLoopPerPass) {
  const auto t = makeCostTable(uncalibratedKnobs());
  for (Op op : {Op::SHLW, Op::SHRW, Op::SHRUW}) {
    const bool left = op == Op::SHLW;
    const std::string_view seq = kOpInfo[static_cast<int>(op)].z180;
    EXPECT_EQ(sequenceCost(seq, 1).tstates, 28) << seq;  // n = 0: JR Z taken
    EXPECT_EQ(sequenceCost(seq, 0, 1).tstates, left ? 44 : 51) << seq;
    EXPECT_EQ(sequenceCost(seq, 0, 5).tstates, left ? 108 : 143) << seq;
    EXPECT_EQ(sequenceCost(seq, 0, 15).tstates, left ? 268 : 373) << seq;
    EXPECT_EQ(sequenceCost(seq).branches, 1) << seq;  // the loop's DJNZ is not a path branch
    // The table: op[] is one pass, path 1 the skip, loopPass[] each further pass.
    EXPECT_EQ(opCost(t, op), left ? 44u : 51u);
    EXPECT_EQ(delta(t, op, 1), left ? 28 - 44 : 28 - 51);
    EXPECT_EQ(t.loopPass[static_cast<int>(op)], left ? 16u : 23u);
  }
  // No other opcode has a loop.
  for (int i = 0; i < kOpCount; ++i) {
    const Op op = static_cast<Op>(i);
    if (op == Op::SHLW || op == Op::SHRW || op == Op::SHRUW) continue;
    EXPECT_EQ(t.loopPass[i], 0u) << kOpInfo[i].name;
  }
  // Calibrated refresh (2 every 20, +10 %) rounds the first pass and each
  // further pass on its own, so the charge is linear in n: SHLW's first
  // pass 44 + 4 = 48 (4.4 rounds down), each further pass 16 + 2 = 18
  // (1.6 rounds up), the skip 28 + 3 = 31: 31 for n = 0, 30 + 18 n after.
  const auto c = makeCostTable(calibratedKnobs());
  EXPECT_EQ(opCost(c, Op::SHLW), 48u);
  EXPECT_EQ(c.loopPass[static_cast<int>(Op::SHLW)], 18u);
  EXPECT_EQ(opCost(c, Op::SHLW) + c.branchDelta[static_cast<int>(Op::SHLW)][1], 31u);
}

// abs (argument in HL): CALL 16; LD A,H 4; OR A 4 = 24, then
//   not negative: JP P taken 9; RET 9 = 42;
//   negative:     JP P not taken 6; EX DE,HL 3; LD HL,0 9; OR A 4;
//                 SBC HL,DE 10; RET 9 = 65.
// libCall[] is the not-taken (negative) path; libTakenDelta[] the
// difference to the taken one. Every other routine costs the same on
// every path, so its delta is 0.
TEST(Cost, AbsChargesThePathOfItsArgumentsSign) {
  const auto t = makeCostTable(uncalibratedKnobs());
  EXPECT_EQ(libCost(t, Lib::ABS), 65u);
  EXPECT_EQ(t.libTakenDelta[static_cast<int>(Lib::ABS)], 42 - 65);
  for (int i = 0; i < kLibCount; ++i) {
    if (static_cast<Lib>(i) == Lib::ABS) continue;
    EXPECT_EQ(t.libTakenDelta[i], 0) << kLibInfo[i].name;
    EXPECT_TRUE(pathsCostTheSame(kLibInfo[i].callSeq)) << kLibInfo[i].name;
  }
  EXPECT_FALSE(pathsCostTheSame(kLibInfo[static_cast<int>(Lib::ABS)].callSeq));
  EXPECT_TRUE(libPathFromArguments(Lib::ABS));
  EXPECT_FALSE(libPathFromArguments(Lib::FABS));
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
