// Measurements of one robot's behaviour in a run (simbot bench), taken by a
// scheduler::MatchObserver at exact ticks (the bench's statistics are in
// stats/). What they measure is the bench's, not the match's: ICEMAN's own
// tests of acquiring and aiming, the edge legs, the stall time.
#pragma once
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "reports/stall.h"
#include "scheduler/match.h"

namespace simbot::batch {

using scheduler::RobotResult;
using scheduler::Tick;

// What counts as acquiring and aiming at the beacon, on the eye readings of
// one left-then-right pair. The defaults are ICEMAN's own tests (thesis
// program: "seen" above 48, the background being 16; aimed when the eyes
// differ by at most 50 and sum to at least 800); simbot bench takes others
// with --seen-threshold, --aim-max-diff and --aim-min-sum.
struct MetricThresholds {
  int seen = 48;        // both eyes above this: acquired (either: seeing, for stall_s)
  int aimMaxDiff = 50;  // |left - right| at most this ...
  int aimMinSum = 800;  // ... and left + right at least this: aimed
};

// Collects the raw happenings of one robot (by default A) during a run.
class MetricsObserver final : public scheduler::MatchObserver {
 public:
  explicit MetricsObserver(int robot = 0, MetricThresholds thresholds = {})
      : robot_(robot),
        thresholds_(thresholds),
        stall_(reports::StallRule{.seen = thresholds.seen}) {}
  void onEyeRead(int robot, Tick t, int channel, int value) override;
  void onInterruptAccepted(int robot, Tick t, vm::Irq irq) override;
  void onFrame(int robot, Tick t, bool latched) override;
  void onPlantEvent(Tick t, const plant::Event& e) override;
  void onPose(int robot, Tick t, double x_ft, double y_ft) override;
  void onHalt(int robot, Tick t) override;
  void onReload(int robot, Tick t) override;

  // Closes the run at `endTick` (a stall still open runs to it).
  void finish(Tick endTick);

  std::optional<Tick> acquire, aim, firstShot, firstHit;
  std::optional<Tick> edgeEnter, edgeAccept, edgeLatch, edgeLeave;
  int framesRejected = 0;
  Tick stallTicks = 0;  // the stalls' total (reports/stall.h), set by finish()

 private:
  int robot_;
  MetricThresholds thresholds_;
  // whether the previous read was channel 0, and its reading (for the
  // left-then-right pair rule)
  bool pairOpen_ = false;
  int pairLeft_ = 0;
  reports::StallWatch stall_;
  // What the StallWatch is fed, kept until finish() feeds it in tick order
  // (the observer's calls are not: a pose sample comes after the VM ran
  // past it). Eye readings only where they change, as the trace's ad_read.
  // 24 bytes: an edge run keeps a quarter of a million of them.
  struct StallInput {
    Tick t;
    uint64_t call = 0;  // its place among all the calls
    int32_t value = 0;  // an eye's reading; a pose's index in poses_
    enum class Kind : uint8_t { Eye, Latch, Pose, Halt, Reload } kind;
    uint8_t channel = 0;
  };
  // One list per source, each in tick order but for rare cases, so that
  // finish() merges them instead of sorting them all: the robot's VM (eye
  // readings, halts), the plant's samples (poses), the events between
  // rounds (latches, reloads).
  enum StallSource : uint8_t { kFromVm, kFromSamples, kFromEvents, kStallSources };
  void addStallInput(StallSource source, StallInput input);
  std::array<std::vector<StallInput>, kStallSources> stallInputs_;
  std::vector<std::array<double, 2>> poses_;  // x, y (ft) of each Pose input
  uint64_t stallCalls_ = 0;
  int lastEye_[2] = {-1, -1};
  // edge legs, kept raw and resolved in finish()
  std::optional<plant::Detector> edgeDetector_;
  std::vector<Tick> pioAccepts_, latches_, leaves_;
};

// The metric values of one run in a fixed order (names below); nullopt =
// never reached (censored).
struct RunMetrics {
  std::vector<std::optional<double>> values;
};
const std::vector<std::string>& metricNames();
RunMetrics collectMetrics(const MetricsObserver& o, const RobotResult& robot);

}  // namespace simbot::batch
