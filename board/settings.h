// board/settings.h -- the board's own settings (the profile's
// [controller]), apart from board.h so that a run's configuration names
// them without the board.
#pragma once
#include "vm/cost.h"

namespace simbot::board {

// The board's settings, the profile's [controller] (config/ reads them).
struct Settings {
  vm::TimerService timerService = vm::TimerService::Auto;
  // Delay loops run in one exact step (with the match's CostKnobs::
  // fastForward off, no board's do).
  bool fastForward = true;
  // The Z180 revision on the board: the figures of the instructions that
  // differ between them (vm/z180.def).
  vm::CpuRevision cpu = vm::CpuRevision::Z80180;
  // Power-on RAM from a seeded stream (StreamSeeds::memoryFill), not zeros.
  bool randomMemory = false;
  bool operator==(const Settings&) const = default;
};

// The match's cost table with a board's settings: its timer service,
// fast-forward unless it turns it off, and its CPU revision (whose figures
// make a table of their own).
vm::CostTable costsFor(const vm::CostTable& match, const Settings& settings);

}  // namespace simbot::board
