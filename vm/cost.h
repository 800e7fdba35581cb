// The cycle model: every opcode and library call costs the T-states of the
// Z180 sequence written beside it (opcodes.def, builtins.def), summed here at
// compile time from the Z180 timings in z180.def, plus memory wait states.
// Calibration may move only the knobs in CostKnobs; nothing depends on a
// program's text.
#pragma once
#include <array>
#include <cstdint>
#include <string_view>

#include "bytecode.h"

namespace simbot::vm {

struct Z180Insn {
  std::string_view mnemonic;
  int tstates;
  int memCycles;
};

inline constexpr Z180Insn kZ180[] = {
#define Z180_INSN(m, t, mc) {m, t, mc},
#include "z180.def"
#undef Z180_INSN
};

struct SeqCost {
  int tstates = 0;
  int memCycles = 0;
  int insns = 0;
};

// Sum of a "MNEMONIC; MNEMONIC; ..." sequence. An unknown mnemonic is a
// compile-time error (the throw is not a constant expression).
constexpr SeqCost sequenceCost(std::string_view seq) {
  SeqCost total;
  while (!seq.empty()) {
    auto end = seq.find(';');
    auto item = seq.substr(0, end);
    while (!item.empty() && item.front() == ' ') item.remove_prefix(1);
    while (!item.empty() && item.back() == ' ') item.remove_suffix(1);
    if (!item.empty()) {
      bool found = false;
      for (const auto& z : kZ180) {
        if (z.mnemonic == item) {
          total.tstates += z.tstates;
          total.memCycles += z.memCycles;
          ++total.insns;
          found = true;
          break;
        }
      }
      if (!found) throw "unknown Z180 mnemonic in cost sequence";
    }
    if (end == std::string_view::npos) break;
    seq.remove_prefix(end + 1);
  }
  return total;
}

inline constexpr auto kOpSeqCost = [] {
  std::array<SeqCost, kOpCount> a{};
  for (int i = 0; i < kOpCount; ++i) a[i] = sequenceCost(kOpInfo[i].z180);
  return a;
}();

inline constexpr auto kLibCallCost = [] {
  std::array<SeqCost, kLibCount> a{};
  for (int i = 0; i < kLibCount; ++i) a[i] = sequenceCost(kLibInfo[i].callSeq);
  return a;
}();

inline constexpr auto kLibStepCost = [] {
  std::array<SeqCost, kLibCount> a{};
  for (int i = 0; i < kLibCount; ++i) a[i] = sequenceCost(kLibInfo[i].stepSeq);
  return a;
}();

// The only numbers calibration may move (README, "Cycle model").
struct CostKnobs {
  // Extra T-states per memory cycle (Z180 DCNTL MWI bits: 0..3).
  int memWaitStates = 0;
  // Body of the RST 28h debug hook run at each statement of a debug build
  // (the RST itself is in the DBG opcode's sequence).
  int debugHookTstates = 0;
  // A/D conversion time inside ad_rd8, from start of conversion to result.
  int adConversionTstates = 0;
  // Serial library's transmit-interrupt service body per byte (after the
  // acceptance cost): fetch from buf, decrement *cc, write TDR.
  int serialIsrTstates = 0;
  // Debug-port time per printf character.
  int printfCharTstates = 0;
  // Whether the handler epilogue ends with EI before RETI (DESIGN.md).
  bool epilogueEi = true;
};

// Tables resolved against the knobs, built once per VM configuration.
struct CostTable {
  std::array<uint32_t, kOpCount> op{};
  std::array<uint32_t, kLibCount> libCall{};
  std::array<uint32_t, kLibCount> libStep{};
  uint32_t interruptAccept = 0;  // IM2 acknowledge + handler register saves
  uint32_t serialIsr = 0;        // acceptance + library ISR body
  uint32_t adConversion = 0;
  uint32_t printfChar = 0;
  CostKnobs knobs;
};

CostTable makeCostTable(const CostKnobs& knobs);

// The knobs' calibrated values (README states the prediction before them).
CostKnobs calibratedKnobs();
// The knobs before calibration: figures from the hardware documentation.
CostKnobs uncalibratedKnobs();

}  // namespace simbot::vm
