// The cycle model: every opcode and library call costs the T-states of the
// Z180 sequence written beside it (opcodes.def, builtins.def), summed at
// compile time from the Z180 timings in z180.def (cost_sums.h), plus wait
// states and DRAM refresh.
// Calibration may move only the knobs in CostKnobs; nothing depends on a
// program's text.
#pragma once
#include <array>
#include <cstdint>
#include <string_view>

#include "bytecode.h"

namespace simbot::vm {

// The Z180 revision the board carries (the profile's [controller] cpu):
// the original Z80180 or the later Z8S180 (and Z8L180), whose figures
// differ for a few instructions (z180.def Z180_REVISED).
enum class CpuRevision : uint8_t { Z80180, Z8S180 };

// Paths through an opcode's sequence: at most two branches, so four paths.
inline constexpr int kMaxOpBranches = 2;
inline constexpr int kOpPaths = 1 << kMaxOpBranches;

inline constexpr int kTimerIsrPaths = 4;
// The service's millisecond rule, as numbers: each tick adds 125/128 ms.
inline constexpr uint32_t kMsFractionStep = 125;
inline constexpr uint32_t kMsFractionOne = 128;
static_assert(kMsFractionStep * 1024 == kMsFractionOne * 1000, "125/128 ms a tick is 1000/1024");

// Whether the BIOS timer service runs (DESIGN.md: Dynamic C links only the
// libraries a program uses). Not a calibration knob: a profile option.
enum class TimerService : uint8_t {
  Auto,    // only when the program uses the timer library (Image::timer)
  Always,  // in every program (the service's time is stolen from all)
  Never,   // never (the counters stand still)
};

// The only numbers calibration may move (docs/cycle-model.md); each has a
// hardware meaning and a hardware range, checked by makeCostTable.
struct CostKnobs {
  // Extra T-states per memory cycle (Z180 DCNTL MWI bits: 0..3; the chip
  // resets to 3).
  int memWaitStates = 0;
  // Extra T-states per I/O cycle (Z180 DCNTL IWI bits: 1..4; the chip
  // resets to 4).
  int ioWaitStates = 1;
  // DRAM refresh (Z180 RCR): 0 = off, else a refresh cycle of 2 or 3
  // T-states (REFW) every refreshInterval T-states (CYC: 10, 20, 40, 80).
  // The chip resets to 3 every 10. Charged as an average stretch of every
  // CPU sequence, rounded per instruction.
  int refreshTstates = 0;
  int refreshInterval = 80;
  // A/D conversion time inside ad_rd8, from start of conversion to result.
  int adConversionTstates = 0;
  // Serial library's transmit-interrupt service body per byte (after the
  // acceptance cost): fetch from buf, decrement *cc, write TDR.
  int serialIsrTstates = 0;
  // Debug-port time per printf character.
  int printfCharTstates = 0;
  // Whether the handler epilogue ends with EI before RETI (DESIGN.md).
  bool epilogueEi = true;
  // Not calibration: the chip on the board (z180.def Z180_REVISED). The
  // 1997 Tiny Giant's documentation (thesis VI.A cites Zworld 1993)
  // predates the Z8S180: the original Z80180.
  CpuRevision cpu = CpuRevision::Z80180;
  // Not calibration: whether PRT0 and the BIOS timer service run.
  TimerService timerService = TimerService::Auto;
  // Not calibration: run marked delay loops in one step where nothing can
  // happen to the robot meanwhile (exact; off for checking).
  bool fastForward = true;
  bool operator==(const CostKnobs&) const = default;
};

// Tables resolved against the knobs, built once per VM configuration.
struct CostTable {
  std::array<uint32_t, kOpCount> op{};
  std::array<uint32_t, kLibCount> libCall{};
  std::array<uint32_t, kLibCount> libStep{};         // the last unit of an inner loop
  std::array<uint32_t, kLibCount> libStepLooping{};  // each unit before it
  // Added to op[] when the instruction's branches go the way `path` says
  // (bit k: k-th branch taken); path 0 is 0 (op[] is the not-taken path).
  std::array<std::array<int32_t, kOpPaths>, kOpCount> branchDelta{};
  // Added for each pass of an opcode's loop after the first (op[] has the
  // first): an n-pass loop costs op[] + (n - 1) x loopPass[]. Each pass is
  // rounded for refresh on its own, so the figure is exactly linear in n.
  std::array<uint32_t, kOpCount> loopPass{};
  // Added to libCall[] when a call's branch is taken (path 1); 0 but for
  // the routines whose path comes from their argument (abs).
  std::array<int32_t, kLibCount> libTakenDelta{};
  uint32_t autoFrameRet = 0;  // RET of a frame that ran ENTER: POP IX
  uint32_t ldirRepeat = 0;    // an LDIR byte after which BC is not yet 0 (COPY)
  // COPY in its parts (vm/instructions.h): the sequence before LDIR, and
  // the rest of op[COPY] (LDIR's last byte and what follows it).
  uint32_t copyHead = 0;
  uint32_t copyLast = 0;
  uint32_t interruptAccept = 0;  // IM2 acknowledge + handler register saves
  uint32_t serialIsr = 0;        // acceptance + library ISR body
  // The timer service along each path (bit 0: no millisecond due, bit 1:
  // no second due), acceptance included.
  std::array<uint32_t, kTimerIsrPaths> timerIsr{};
  int32_t costateStoppedDelta = 0;  // COSTATE on a STOPPED costatement
  uint32_t adConversion = 0;
  uint32_t printfChar = 0;
  CostKnobs knobs;
  bool operator==(const CostTable&) const = default;
};

// Throws std::invalid_argument when a knob is outside its hardware range.
CostTable makeCostTable(const CostKnobs& knobs);

// The knobs' calibrated values (docs/cycle-model.md states the prediction before them).
CostKnobs calibratedKnobs();
// The knobs before calibration: figures from the hardware documentation.
CostKnobs uncalibratedKnobs();

}  // namespace simbot::vm
