// The bench's per-run measurements and its statistics (metrics.h).
#include "scheduler/metrics.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace simbot::scheduler {

// ---- observer

void MetricsObserver::accumulateStall(Tick t) {
  if (t <= stallClock_) return;
  if (seen_) {
    const Tick from = std::max(stallClock_, lastLatch_ + kTicksPerSecond);
    if (t > from) stallTicks += t - from;
  }
  stallClock_ = t;
}

void MetricsObserver::onEyeRead(int robot, Tick t, int channel, int value) {
  if (robot != robot_ || (channel != 0 && channel != 1)) return;
  accumulateStall(t);
  if (channel == 0) {
    lastLeft_ = value;
    haveLeft_ = true;
    pairOpen_ = true;
    pairLeft_ = value;
  } else {
    lastRight_ = value;
    haveRight_ = true;
    // A pair: this right-eye read follows a left-eye read directly.
    if (pairOpen_) {
      const int l = pairLeft_, r = value;
      if (!acquire && l > kSeenThreshold && r > kSeenThreshold) acquire = t;
      if (!aim && std::abs(l - r) <= 50 && l + r >= 800) aim = t;
    }
    pairOpen_ = false;
  }
  seen_ = (haveLeft_ && lastLeft_ > kSeenThreshold) || (haveRight_ && lastRight_ > kSeenThreshold);
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
  accumulateStall(t);
  lastLatch_ = t;
  latches_.push_back(t);
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

void MetricsObserver::finish(Tick endTick) {
  accumulateStall(endTick);
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
      "acquire_s", "aim_s",         "first_shot_s", "first_hit_s",  "shots",           "hits",
      "hit_ratio", "edge_accept_s", "edge_latch_s", "edge_leave_s", "frames_rejected", "stall_s"};
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
              leg(o.edgeEnter, o.edgeAccept),
              leg(o.edgeAccept, o.edgeLatch),
              leg(o.edgeLatch, o.edgeLeave),
              static_cast<double>(o.framesRejected),
              timebase::secondsFromTicks(o.stallTicks)};
  return m;
}

// ---- statistics

namespace {

// Continued fraction of the incomplete beta function (modified Lentz).
double betaContinuedFraction(double a, double b, double x) {
  constexpr double kTiny = 1e-300, kEps = 1e-16;
  const double qab = a + b, qap = a + 1, qam = a - 1;
  double c = 1, d = 1 - qab * x / qap;
  if (std::fabs(d) < kTiny) d = kTiny;
  d = 1 / d;
  double h = d;
  for (int m = 1; m <= 10000; ++m) {
    const double m2 = 2.0 * m;
    double aa = m * (b - m) * x / ((qam + m2) * (a + m2));
    d = 1 + aa * d;
    if (std::fabs(d) < kTiny) d = kTiny;
    c = 1 + aa / c;
    if (std::fabs(c) < kTiny) c = kTiny;
    d = 1 / d;
    h *= d * c;
    aa = -(a + m) * (qab + m) * x / ((a + m2) * (qap + m2));
    d = 1 + aa * d;
    if (std::fabs(d) < kTiny) d = kTiny;
    c = 1 + aa / c;
    if (std::fabs(c) < kTiny) c = kTiny;
    d = 1 / d;
    const double del = d * c;
    h *= del;
    if (std::fabs(del - 1) < kEps) break;
  }
  return h;
}

// Regularized incomplete beta I_x(a, b).
double incompleteBeta(double a, double b, double x) {
  if (x <= 0) return 0;
  if (x >= 1) return 1;
  const double lnFront =
      std::lgamma(a + b) - std::lgamma(a) - std::lgamma(b) + a * std::log(x) + b * std::log1p(-x);
  if (x < (a + 1) / (a + b + 2)) return std::exp(lnFront) * betaContinuedFraction(a, b, x) / a;
  return 1 - std::exp(lnFront) * betaContinuedFraction(b, a, 1 - x) / b;
}

}  // namespace

double studentTCdf(double t, double df) {
  const double x = df / (df + t * t);
  const double tail = 0.5 * incompleteBeta(df / 2, 0.5, x);  // P(T > |t|)
  return t >= 0 ? 1 - tail : tail;
}

double studentTQuantile(double p, double df) {
  if (!(p > 0 && p < 1) || !(df >= 1)) throw std::invalid_argument("studentTQuantile: bad input");
  if (p == 0.5) return 0;
  if (p < 0.5) return -studentTQuantile(1 - p, df);
  double lo = 0, hi = 1;
  while (studentTCdf(hi, df) < p) hi *= 2;
  for (int i = 0; i < 200 && hi - lo > 1e-12 * hi; ++i) {
    const double mid = 0.5 * (lo + hi);
    (studentTCdf(mid, df) < p ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

double mean(const std::vector<double>& v) {
  double sum = 0;
  for (double x : v) sum += x;
  return v.empty() ? 0 : sum / static_cast<double>(v.size());
}

double quantile(std::vector<double> v, double q) {
  if (v.empty()) throw std::invalid_argument("quantile of an empty sample");
  std::sort(v.begin(), v.end());
  const double pos = q * static_cast<double>(v.size() - 1);
  const auto i = static_cast<size_t>(std::floor(pos));
  if (i + 1 >= v.size()) return v.back();
  const double frac = pos - static_cast<double>(i);
  return v[i] + frac * (v[i + 1] - v[i]);
}

MetricSummary summarize(const std::string& name, const std::vector<std::optional<double>>& values) {
  MetricSummary s;
  s.name = name;
  std::vector<double> reached;
  for (const auto& v : values) {
    if (v)
      reached.push_back(*v);
    else
      ++s.censored;
  }
  s.reached = static_cast<int>(reached.size());
  if (reached.empty()) return s;
  const double m = mean(reached);
  s.mean = m;
  s.median = quantile(reached, 0.5);
  s.p90 = quantile(reached, 0.9);
  if (reached.size() >= 2) {
    double ss = 0;
    for (double x : reached) ss += (x - m) * (x - m);
    const double n = static_cast<double>(reached.size());
    const double sd = std::sqrt(ss / (n - 1));
    const double half = studentTQuantile(0.975, n - 1) * sd / std::sqrt(n);
    s.ciLow = m - half;
    s.ciHigh = m + half;
  }
  return s;
}

}  // namespace simbot::scheduler
