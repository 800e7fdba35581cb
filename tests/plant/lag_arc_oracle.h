// The exact motion of one robot that starts from rest with both wheel
// targets set at t = 0 and a first-order motor lag tau, independent of
// the plant's integrator: speed and turn rate follow the lag in closed
// form, the heading is their closed-form integral, and x and y are
// integrated by Boost.Math's Gauss-Kronrod quadrature.
//
//   ramp(t) = 1 - e^{-t/tau}
//   v(t) = V ramp(t),  V = (vl + vr) / 2
//   w(t) = W ramp(t),  W = (vl - vr) / track   (clockwise, as the plant)
//   H(t) = H0 + W (t - tau ramp(t))
//   x(t) = x0 + int_0^t v sin H,  y(t) = y0 + int_0^t v cos H
#pragma once

#include <boost/math/quadrature/gauss_kronrod.hpp>
#include <boost/math/tools/roots.hpp>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

namespace plant_test {

class LagArcOracle {
 public:
  struct Point {
    double x, y, h;  // ft, ft, rad (unwrapped)
  };

  // Positions are kept at every `grid` seconds up to `horizon`, so a query
  // integrates at most one grid interval.
  LagArcOracle(double x0, double y0, double h0Rad, double vl, double vr, double tau, double track,
               double horizon, double grid = 0.05)
      : x0_(x0),
        y0_(y0),
        h0_(h0Rad),
        v_(0.5 * (vl + vr)),
        w_((vl - vr) / track),
        tau_(tau),
        grid_(grid) {
    cum_.push_back({x0, y0});
    for (double a = 0; a < horizon; a += grid) {
      const auto d = piece(a, a + grid);
      cum_.push_back({cum_.back().first + d.first, cum_.back().second + d.second});
    }
  }

  double heading(double t) const { return h0_ + w_ * (t - tau_ * ramp(t)); }

  Point at(double t) const {
    auto k = static_cast<std::size_t>(t / grid_);
    if (k >= cum_.size()) k = cum_.size() - 1;
    const double a = static_cast<double>(k) * grid_;
    const auto d = piece(a, t);
    return {cum_[k].first + d.first, cum_[k].second + d.second, heading(t)};
  }

  // The time in [lo, hi] where g(at(t)) changes sign (g continuous, of
  // opposite signs at the ends), to a few ulps.
  template <class G>
  double root(G g, double lo, double hi) const {
    std::uintmax_t iters = 200;
    const auto r =
        boost::math::tools::toms748_solve([&](double t) { return g(at(t)); }, lo, hi,
                                          boost::math::tools::eps_tolerance<double>(50), iters);
    return 0.5 * (r.first + r.second);
  }

 private:
  double ramp(double t) const { return -std::expm1(-t / tau_); }

  std::pair<double, double> piece(double a, double b) const {
    if (b <= a) return {0.0, 0.0};
    using GK = boost::math::quadrature::gauss_kronrod<double, 31>;
    const double dx = GK::integrate([&](double t) { return v_ * ramp(t) * std::sin(heading(t)); },
                                    a, b, 3, 1e-13);
    const double dy = GK::integrate([&](double t) { return v_ * ramp(t) * std::cos(heading(t)); },
                                    a, b, 3, 1e-13);
    return {dx, dy};
  }

  double x0_, y0_, h0_, v_, w_, tau_, grid_;
  std::vector<std::pair<double, double>> cum_;
};

}  // namespace plant_test
