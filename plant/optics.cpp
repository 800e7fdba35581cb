// plant/optics.cpp -- the eyes: a pure function of two poses (thesis VII).
//
// DESIGN.md fixes the model: the beacon is seen only for |gamma| < 90 deg
// and when the segment between the centres misses the divider and every
// obstacle taller than the beacon. The near eye
// (on the opponent's side) sees S = max within r_sat, else kappa / r^2 +
// background with kappa = (max - background) r_sat^2 (Appendix C's MAX_EYE;
// the printed 36578/38578 are typos). The far eye sees S * f with
// f = max(0, 1 - |gamma| / phi), phi = atan(far eye width / nose), which is
// what Appendix C's optics() computes (eq. 7.3 as printed is garbled). At
// gamma = 0 both eyes get S. Readings are 8-bit A/D steps times 16: clamp(16
// floor(S / 16), 16, max). Appendix C hands the full value to the far eye;
// the profile's thesis_swapped_eyes reproduces that, off by default.
//
// Optional noise: Gaussian (sigma in reading units, Box-Muller from raw
// bits) and "bad readings" replaced by a uniformly random 8-bit A/D value.
// Raw 64-bit words come from the caller's generator and are turned into
// numbers here, never with std::*_distribution, whose output differs
// between library versions. Draw order per call: left eye then right; per
// eye two words for the Gaussian (if sigma > 0), then one for the bad-reading
// test and one more for the bad value (if the probability > 0). A read of
// one eye (an A/D read of one channel) computes only that eye but draws the
// other eye's words all the same, so the stream never depends on which
// channel a program reads.
#include <cmath>

#include "plant/geometry.h"
#include "plant/last_call.h"
#include "plant/plant.h"

namespace simbot::plant {
namespace {

double atanOf(double x) { return std::atan(x); }

int quantise(double s, const RobotParams& p) {
  double q = 16.0 * std::floor(s / 16.0);
  q = std::clamp(q, 16.0, p.eye_max);
  return static_cast<int>(q);
}

// One eye's reading of signal s with the profile's noise: the Gaussian,
// then the bad-reading test, then quantised.
//
// The Gaussian's words are always drawn, but its arithmetic (a log, a
// square root and a cosine, most of a read's cost) is skipped where it
// cannot change the reading: s already gives the lowest one (16) and the
// draw's cosine is certainly negative (2 pi u2 at least 0.02 pi inside
// (pi / 2, 3 pi / 2), where cos is below -0.06, far beyond libm's error),
// so z <= 0, s + sigma z <= s (a sum never rises when a non-positive
// number is added) and the reading stays 16: about half the reads of a
// background, the usual signal.
int noisyReading(double s, const RobotParams& p, RandomBits* rng) {
  if (!rng) return quantise(s, p);
  if (p.noise_sigma > 0) {
    const std::uint64_t w1 = rng->next(), w2 = rng->next();
    const double u2 = unit53(w2);
    if (!(u2 > 0.26 && u2 < 0.74 && quantise(s, p) == 16)) {
      const double u1 = unit53Open0(w1);
      const double z = std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * geom::kPi * u2);
      s += p.noise_sigma * z;
    }
  }
  if (p.bad_reading_probability > 0) {
    if (unit53(rng->next()) < p.bad_reading_probability) {
      const int badValue = static_cast<int>(rng->next() >> 56) * 16;  // a random 8-bit A/D value
      return quantise(badValue, p);
    }
  }
  return quantise(s, p);
}

// The draws noisyReading makes for an eye nobody asked for, without the
// arithmetic: the same words, in the same order, so the stream stays where
// a read of both eyes would leave it.
void skipNoise(const RobotParams& p, RandomBits* rng) {
  if (!rng) return;
  if (p.noise_sigma > 0) {
    rng->next();
    rng->next();
  }
  if (p.bad_reading_probability > 0 && unit53(rng->next()) < p.bad_reading_probability) rng->next();
}

}  // namespace

std::uint64_t SplitMix64::next() {
  std::uint64_t z = (s_ += 0x9E3779B97F4A7C15ull);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

bool dividerBlocks(double ax, double ay, double bx, double by, const FieldParams& field) {
  if (!field.divider) return false;
  return geom::segmentHitsRect(geom::Vec2(ax, ay), geom::Vec2(bx, by), geom::dividerRect(field));
}

double dividerClearance(double x, double y, double radius, const FieldParams& field) {
  if (!field.divider) return HUGE_VAL;
  const geom::Vec2 c(x, y);
  return (c - geom::closestPointOnRect(c, geom::dividerRect(field))).norm() - radius;
}

EyeGeometry eyeGeometry(const Pose& self, const Pose& opp, const RobotParams& p,
                        const FieldParams& field) {
  EyeGeometry g;
  const double dx = opp.x_ft - self.x_ft, dy = opp.y_ft - self.y_ft;
  g.range_ft = std::sqrt(dx * dx + dy * dy);
  // Bearing clockwise from +y, then relative to our heading: + = right.
  const double bearing = geom::radToDeg(std::atan2(dx, dy));
  g.gamma_deg = geom::wrap180(bearing - self.heading_deg);
  if (!(std::abs(g.gamma_deg) < 90.0)) return g;
  if (dividerBlocks(self.x_ft, self.y_ft, opp.x_ft, opp.y_ft, field)) return g;
  if (!field.obstacles.empty() && obstacleBlocks(self.x_ft, self.y_ft, opp.x_ft, opp.y_ft, field))
    return g;
  g.seen = true;
  if (g.range_ft <= p.eye_saturation_ft) {
    g.near_signal = p.eye_max;
  } else {
    const double kappa = (p.eye_max - p.eye_background) * p.eye_saturation_ft * p.eye_saturation_ft;
    g.near_signal = kappa / (g.range_ft * g.range_ft) + p.eye_background;
  }
  // The far eye is the right one when the opponent is to the left.
  const double farWidth = g.gamma_deg < 0 ? p.right_eye_width : p.left_eye_width;
  // The same one or two widths on every read: atan once per profile (a
  // pure function's last value, per thread: LastCall).
  thread_local LastCall<&atanOf> farEyeAtan;
  const double phi = geom::radToDeg(farEyeAtan(farWidth / p.eye_nose));
  g.far_fraction = std::max(0.0, 1.0 - std::abs(g.gamma_deg) / phi);
  return g;
}

EyeReadings computeEyes(const Pose& self, const Pose* opponent, const RobotParams& p,
                        const FieldParams& field, RandomBits* noise, EyeChannels channels,
                        const EyeScene* scene, int selfRobot) {
  double sLeft = p.eye_background, sRight = p.eye_background;
  int beaconScreen = -1;
  if (scene && scene->count > 0) {
    eyeSignalsAmong(self, selfRobot, opponent, p, field, *scene, sLeft, sRight, &beaconScreen);
  } else if (opponent) {
    const EyeGeometry g = eyeGeometry(self, *opponent, p, field);
    if (g.seen) {
      double nearS = g.near_signal, farS = g.near_signal * g.far_fraction;
      if (p.thesis_swapped_eyes) std::swap(nearS, farS);
      if (g.gamma_deg < 0) {  // opponent to the left: left eye is near
        sLeft = nearS;
        sRight = farS;
      } else if (g.gamma_deg > 0) {
        sRight = nearS;
        sLeft = farS;
      } else {
        sLeft = sRight = g.near_signal;
      }
    }
  }
  EyeReadings r;
  r.beaconScreen = beaconScreen;
  if (channels != EyeChannels::Right) {
    r.left = noisyReading(sLeft, p, noise);
  } else {
    skipNoise(p, noise);
  }
  if (channels != EyeChannels::Left) {
    r.right = noisyReading(sRight, p, noise);
  } else {
    skipNoise(p, noise);
  }
  return r;
}

}  // namespace simbot::plant
