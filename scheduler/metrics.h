// Measurements of one robot's behaviour in a run (simbot bench), taken by a
// MatchObserver at exact ticks, and the small statistics the bench reports.
#pragma once
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "scheduler/match.h"

namespace simbot::scheduler {

// Eye readings above this count as "seeing the beacon" (background is 16).
inline constexpr int kSeenThreshold = 48;

// Collects the raw happenings of one robot (by default A) during a run.
class MetricsObserver final : public MatchObserver {
 public:
  explicit MetricsObserver(int robot = 0) : robot_(robot) {}
  void onEyeRead(int robot, Tick t, int channel, int value) override;
  void onInterruptAccepted(int robot, Tick t, vm::Irq irq) override;
  void onFrame(int robot, Tick t, bool latched) override;
  void onPlantEvent(Tick t, const plant::Event& e) override;

  // Closes the run at `endTick` (the stall time runs to it).
  void finish(Tick endTick);

  std::optional<Tick> acquire, aim, firstShot, firstHit;
  std::optional<Tick> edgeEnter, edgeAccept, edgeLatch, edgeLeave;
  int framesRejected = 0;
  Tick stallTicks = 0;

 private:
  void accumulateStall(Tick t);
  int robot_;
  // eyes: the last reading of each channel, whether the previous read was
  // channel 0 (for the left-then-right pair rule)
  int lastLeft_ = 16, lastRight_ = 16;
  bool haveLeft_ = false, haveRight_ = false;
  bool pairOpen_ = false;
  int pairLeft_ = 0;
  // stall: time while the beacon is seen and no frame latched for > 1 s
  Tick lastLatch_ = 0, stallClock_ = 0;
  bool seen_ = false;
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

// ---- statistics

// Two-sided Student-t quantile: the t with P(T <= t) = p for df degrees of
// freedom (p in (0, 1), df >= 1). Computed from the regularized incomplete
// beta function by bisection.
double studentTQuantile(double p, double df);
// CDF of Student's t.
double studentTCdf(double t, double df);

double mean(const std::vector<double>& v);
// Linear interpolation between order statistics (R type 7); v non-empty.
double quantile(std::vector<double> v, double q);

struct MetricSummary {
  std::string name;
  int reached = 0, censored = 0;
  std::optional<double> mean, median, p90, ciLow, ciHigh;  // CI needs n >= 2
};
MetricSummary summarize(const std::string& name, const std::vector<std::optional<double>>& values);

}  // namespace simbot::scheduler
