// The bench's per-run measurements (bench_metrics.h).
#include "batch/bench_metrics.h"

#include <algorithm>
#include <cmath>

namespace simbot::batch {

using scheduler::kTicksPerSecond;

// ---- observer

void MetricsObserver::onEyeRead(int robot, Tick t, int channel, int value) {
  if (robot != robot_ || (channel != 0 && channel != 1)) return;
  if (value != lastEye_[channel]) {
    lastEye_[channel] = value;
    addStallInput(kFromVm, {t, 0, value, StallInput::Kind::Eye, static_cast<uint8_t>(channel)});
  }
  if (channel == 0) {
    pairOpen_ = true;
    pairLeft_ = value;
  } else {
    // A pair: this right-eye read follows a left-eye read directly.
    if (pairOpen_) {
      const int l = pairLeft_, r = value;
      const MetricThresholds& th = thresholds_;
      if (!acquire && l > th.seen && r > th.seen) acquire = t;
      if (!aim && std::abs(l - r) <= th.aimMaxDiff && l + r >= th.aimMinSum) aim = t;
    }
    pairOpen_ = false;
  }
}

void MetricsObserver::onInterruptAccepted(int robot, Tick t, vm::Irq irq) {
  if (robot == robot_ && irq == vm::Irq::Pio) pioAccepts_.push_back(t);
}

void MetricsObserver::onFrame(int robot, Tick t, bool latched) {
  if (robot != robot_) return;
  if (!latched) {
    ++framesRejected;
    return;
  }
  addStallInput(kFromEvents, {t, 0, 0, StallInput::Kind::Latch});
  latches_.push_back(t);
}

void MetricsObserver::onPose(int robot, Tick t, double x_ft, double y_ft) {
  if (robot != robot_) return;
  addStallInput(kFromSamples, {t, 0, static_cast<int32_t>(poses_.size()), StallInput::Kind::Pose});
  poses_.push_back({x_ft, y_ft});
}

void MetricsObserver::onHalt(int robot, Tick t) {
  if (robot == robot_) addStallInput(kFromVm, {t, 0, 0, StallInput::Kind::Halt});
}

void MetricsObserver::onReload(int robot, Tick t) {
  if (robot != robot_) return;
  lastEye_[0] = lastEye_[1] = -1;
  addStallInput(kFromEvents, {t, 0, 0, StallInput::Kind::Reload});
}

void MetricsObserver::onPlantEvent(Tick t, const plant::Event& e) {
  if (e.robot != robot_) return;
  switch (e.kind) {
    case plant::EventKind::BallLaunch:
      if (!firstShot || t < *firstShot) firstShot = t;
      break;
    case plant::EventKind::BallHit:
      if (!firstHit || t < *firstHit) firstHit = t;
      break;
    case plant::EventKind::EdgeEnter:
      if (!edgeEnter || t < *edgeEnter) {
        edgeEnter = t;
        edgeDetector_ = e.detector;
      }
      break;
    case plant::EventKind::EdgeLeave:
      // Detector in the low bit so that finish() can filter by detector.
      leaves_.push_back(t * 2 + (e.detector == plant::Detector::Aft ? 1 : 0));
      break;
    default:
      break;
  }
}

void MetricsObserver::addStallInput(StallSource source, StallInput input) {
  input.call = stallCalls_++;
  stallInputs_[source].push_back(input);
}

void MetricsObserver::finish(Tick endTick) {
  // By tick, and within a tick in the order of the calls, which is the
  // trace's: each source's list by tick (stable: its calls are in order),
  // then the lists merged by (tick, call).
  const auto byTick = [](const StallInput& a, const StallInput& b) { return a.t < b.t; };
  for (auto& list : stallInputs_)
    if (!std::is_sorted(list.begin(), list.end(), byTick))
      std::stable_sort(list.begin(), list.end(), byTick);
  std::array<size_t, kStallSources> next{};
  reports::StallWatch stall = stall_;
  for (;;) {
    const StallInput* first = nullptr;
    size_t from = 0;
    for (size_t s = 0; s < kStallSources; ++s) {
      if (next[s] == stallInputs_[s].size()) continue;
      const StallInput& in = stallInputs_[s][next[s]];
      if (!first || in.t < first->t || (in.t == first->t && in.call < first->call)) {
        first = &in;
        from = s;
      }
    }
    if (!first) break;
    ++next[from];
    const StallInput& in = *first;
    switch (in.kind) {
      case StallInput::Kind::Eye:
        stall.eyeRead(in.t, in.channel, in.value);
        break;
      case StallInput::Kind::Latch:
        stall.frameLatched(in.t);
        break;
      case StallInput::Kind::Pose: {
        const auto& [x, y] = poses_[static_cast<size_t>(in.value)];
        stall.pose(in.t, x, y);
        break;
      }
      case StallInput::Kind::Halt:
        stall.halted(in.t);
        break;
      case StallInput::Kind::Reload:
        stall.reloaded(in.t);
        break;
    }
  }
  stall.finish(endTick);
  stallTicks = stall.total();
  std::sort(pioAccepts_.begin(), pioAccepts_.end());
  std::sort(latches_.begin(), latches_.end());
  std::sort(leaves_.begin(), leaves_.end());
  edgeAccept = edgeLatch = edgeLeave = std::nullopt;
  if (!edgeEnter) return;
  const auto accept = std::lower_bound(pioAccepts_.begin(), pioAccepts_.end(), *edgeEnter);
  if (accept == pioAccepts_.end()) return;
  edgeAccept = *accept;
  const auto latch = std::upper_bound(latches_.begin(), latches_.end(), *edgeAccept);
  if (latch == latches_.end()) return;
  edgeLatch = *latch;
  const Tick bit = edgeDetector_ == plant::Detector::Aft ? 1 : 0;
  for (Tick packed : leaves_)
    if (packed / 2 >= *edgeLatch && packed % 2 == bit) {
      edgeLeave = packed / 2;
      break;
    }
}

const std::vector<std::string>& metricNames() {
  static const std::vector<std::string> names = {
      "acquire_s",    "aim_s",           "first_shot_s", "first_hit_s",   "shots",
      "hits",         "hit_ratio",       "edge_enter_s", "edge_accept_s", "edge_latch_s",
      "edge_leave_s", "frames_rejected", "stall_s"};
  return names;
}

RunMetrics collectMetrics(const MetricsObserver& o, const RobotResult& robot) {
  auto time = [](const std::optional<Tick>& t) -> std::optional<double> {
    if (!t) return std::nullopt;
    return timebase::secondsFromTicks(*t);
  };
  auto leg = [](const std::optional<Tick>& from,
                const std::optional<Tick>& to) -> std::optional<double> {
    if (!from || !to) return std::nullopt;
    return timebase::secondsFromTicks(*to - *from);
  };
  RunMetrics m;
  m.values = {time(o.acquire),
              time(o.aim),
              time(o.firstShot),
              time(o.firstHit),
              static_cast<double>(robot.shots),
              static_cast<double>(robot.hits),
              robot.shots > 0 ? std::optional<double>(static_cast<double>(robot.hits) / robot.shots)
                              : std::nullopt,
              time(o.edgeEnter),
              leg(o.edgeEnter, o.edgeAccept),
              leg(o.edgeAccept, o.edgeLatch),
              leg(o.edgeLatch, o.edgeLeave),
              static_cast<double>(o.framesRejected),
              timebase::secondsFromTicks(o.stallTicks)};
  return m;
}

}  // namespace simbot::batch
