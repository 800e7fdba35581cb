// Resolves the cycle table against the calibration knobs.
#include <stdexcept>
#include <string>

#include "vm/cost_sums.h"

namespace simbot::vm {

namespace {

// T-states of a sequence with the knobs' wait states and DRAM refresh.
uint32_t resolve(const SeqCost& c, const CostKnobs& k) {
  const int chip = c.tstates + (k.cpu == CpuRevision::Z8S180 ? c.z8s180Delta : 0);
  const int base = chip + k.memWaitStates * c.memCycles + k.ioWaitStates * c.ioCycles;
  // Refresh: one cycle of refreshTstates every refreshInterval T-states of
  // CPU time, charged as that average stretch, rounded to the nearest
  // T-state per sequence.
  const int refresh = k.refreshTstates == 0
                          ? 0
                          : (base * k.refreshTstates + k.refreshInterval / 2) / k.refreshInterval;
  return static_cast<uint32_t>(base + refresh);
}

// IM 2 acknowledge, then the handler prologue Dynamic C emits for an
// `interrupt` function: save AF, BC, DE, HL, IX, IY.
constexpr SeqCost kAcceptSeq =
    sequenceCost("INTACK IM2; PUSH rr; PUSH rr; PUSH rr; PUSH rr; PUSH IX; PUSH IX");
// The serial library's transmit ISR wrapper: acknowledge, save AF/HL/DE,
// (body: knob), restore, EI, RETI.
constexpr SeqCost kSerialIsrSeq =
    sequenceCost("INTACK IM2; PUSH rr; PUSH rr; PUSH rr; POP rr; POP rr; POP rr; EI; RETI");
constexpr SeqCost kCoStoppedSeq = sequenceCost(kCostateStoppedSeq, 1);
constexpr auto kTimerPathSeq = [] {
  std::array<SeqCost, kTimerIsrPaths> a{};
  for (unsigned p = 0; p < kTimerIsrPaths; ++p) a[p] = sequenceCost(kTimerIsrSeq, p);
  if (a[0].branches != 2) throw "the timer service has two branches";
  return a;
}();
constexpr SeqCost kEiSeq = sequenceCost("EI");
constexpr SeqCost kHookSeq = sequenceCost(kDebugHookSeq);
constexpr SeqCost kAutoRetSeq = sequenceCost(kAutoFrameRetSeq);

void checkRange(const char* name, int value, int lo, int hi) {
  if (value < lo || value > hi)
    throw std::invalid_argument(std::string(name) + " = " + std::to_string(value) +
                                " is outside its hardware range " + std::to_string(lo) + ".." +
                                std::to_string(hi));
}

}  // namespace

CostTable makeCostTable(const CostKnobs& knobs) {
  checkRange("memory wait states (DCNTL MWI)", knobs.memWaitStates, 0, 3);
  checkRange("I/O wait states (DCNTL IWI)", knobs.ioWaitStates, 1, 4);
  if (knobs.refreshTstates != 0) {
    checkRange("refresh cycle T-states (RCR REFW)", knobs.refreshTstates, 2, 3);
    const int n = knobs.refreshInterval;
    if (n != 10 && n != 20 && n != 40 && n != 80)
      throw std::invalid_argument("refresh interval (RCR CYC) must be 10, 20, 40 or 80 T-states");
  }
  CostTable t;
  t.knobs = knobs;
  for (int i = 0; i < kOpCount; ++i) {
    t.op[i] = resolve(kOpPathCost[i][0], knobs);
    for (int p = 0; p < kOpPaths; ++p)
      t.branchDelta[i][p] =
          static_cast<int32_t>(resolve(kOpPathCost[i][p], knobs)) - static_cast<int32_t>(t.op[i]);
    t.loopPass[i] = resolve(kOpLoopPass[i], knobs);
  }
  t.op[static_cast<int>(Op::DBG)] += resolve(kHookSeq, knobs);
  if (!knobs.epilogueEi) t.op[static_cast<int>(Op::RETI)] -= resolve(kEiSeq, knobs);
  for (int i = 0; i < kLibCount; ++i) {
    t.libCall[i] = resolve(kLibCallCost[i], knobs);
    t.libTakenDelta[i] = static_cast<int32_t>(resolve(kLibPathCost[i][1], knobs)) -
                         static_cast<int32_t>(t.libCall[i]);
    t.libStep[i] = resolve(kLibStepCost[i], knobs);
    t.libStepLooping[i] = resolve(kLibStepLoopingCost[i], knobs);
  }
  t.autoFrameRet = resolve(kAutoRetSeq, knobs);
  t.ldirRepeat = resolve(sequenceCost("LDIR", 1), knobs);
  t.copyHead = resolve(kCopyHeadCost, knobs);
  t.copyLast = t.op[static_cast<int>(Op::COPY)] - t.copyHead;
  t.interruptAccept = resolve(kAcceptSeq, knobs);
  t.serialIsr = resolve(kSerialIsrSeq, knobs) + static_cast<uint32_t>(knobs.serialIsrTstates);
  for (int p = 0; p < kTimerIsrPaths; ++p) t.timerIsr[p] = resolve(kTimerPathSeq[p], knobs);
  t.costateStoppedDelta = static_cast<int32_t>(resolve(kCoStoppedSeq, knobs)) -
                          static_cast<int32_t>(t.op[static_cast<int>(Op::COSTATE)]);
  t.adConversion = static_cast<uint32_t>(knobs.adConversionTstates);
  t.printfChar = static_cast<uint32_t>(knobs.printfCharTstates);
  return t;
}

// Figures from the hardware documentation and the era's run-time, before
// any measurement against ICEMAN (docs/cycle-model.md).
CostKnobs uncalibratedKnobs() {
  CostKnobs k;
  k.memWaitStates = 0;   // Tiny Giant: 9.216 MHz Z180 with fast SRAM
  k.ioWaitStates = 1;    // the fewest DCNTL allows
  k.refreshTstates = 0;  // SRAM: no DRAM to refresh
  k.refreshInterval = 80;
  k.adConversionTstates = 276;  // ~30 us serial A/D conversion (estimate)
  k.serialIsrTstates = 120;     // fetch *buf++, DEC (cc), OUT TDR, test (estimate)
  k.printfCharTstates = 1600;   // debug port at 57,600 baud: 10 bits a char
  return k;
}

// Calibrated against the one timing a program states (ICEMAN: 500 passes of
// its slow-spin branch ~ 10 s; tests/timing_test.cpp, whose
// CalibratedKnobsAreTheHardwareSettingNearestTenSeconds prints the whole
// table). Every cost is the exact sum of the emitted sequence (one CALL per
// library call, POP IX only for #class auto frames, branches by the way
// they go, the debug hook's 51 T-states as written); the only freedom left
// is the hardware setting. Predictions (MWI memory / IWI I/O wait states,
// RCR refresh):
//   MWI 0, IWI 1, refresh off (before calibration)   9.002 s
//   MWI 0, IWI 4, refresh off                        9.003 s
//   MWI 1, IWI 1..4, refresh off                     11.723 s
//   MWI 0, IWI 4, refresh 2 every 80 / 40            9.237 / 9.470 s
//   MWI 0, IWI 4, refresh 3 every 80 / 40            9.315 / 9.742 s
//   MWI 0, IWI 4, refresh 2 every 20                 9.898 s  <- chosen
//   MWI 0, IWI 4, refresh 3 every 20                 10.328 s
//   MWI 0, IWI 4, refresh 2 / 3 every 10             10.794 / 11.689 s
//   (reset state: MWI 3, IWI 4, refresh 3 every 10   22.263 s)
// (on the default Z80180, RETI 22 T-states; issue 38 moved each by 5-7 ms
// from the Z8S180's 12, through the serial ISR's RETI on every byte sent)
// Chosen: the setting nearest 10 s. Memory wait states 0 (the BIOS sets
// DCNTL for the board's fast SRAM), I/O wait states 4 (DCNTL's reset value:
// nothing on the I/O bus needs it changed), refresh 2 T-states every 20
// (RCR written by the BIOS; refresh steals bus time whether or not there is
// DRAM to refresh). Each is within its hardware range; none is stretched.
CostKnobs calibratedKnobs() {
  CostKnobs k = uncalibratedKnobs();
  k.ioWaitStates = 4;
  k.refreshTstates = 2;
  k.refreshInterval = 20;
  return k;
}

}  // namespace simbot::vm
