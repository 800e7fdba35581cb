// plant/contact.cpp -- the rigid contacts' gaps and velocity projection
// (the model is in contact.h).
#include "plant/contact.h"

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <cmath>

namespace simbot::plant::contact {

using geom::Vec2;

double gap(const Bodies& b, const Constraint& c, const double* q, Vec2* normal) {
  const auto i = static_cast<std::size_t>(c.robot);
  const Vec2 p(q[2 * i], q[2 * i + 1]);
  switch (c.kind) {
    case Kind::WallX:
      if (normal) *normal = Vec2(p.x() >= 0 ? -1.0 : 1.0, 0.0);
      return b.half - std::abs(p.x()) - b.radius[i];
    case Kind::WallY:
      if (normal) *normal = Vec2(0.0, p.y() >= 0 ? -1.0 : 1.0);
      return b.half - std::abs(p.y()) - b.radius[i];
    case Kind::Divider: {
      const Vec2 d = p - geom::closestPointOnRect(p, b.divider);
      const double len = d.norm();
      // A centre inside the divider cannot happen (placement and rigid
      // contact keep it out); the normal then points east.
      if (normal) *normal = len > 0 ? Vec2(d / len) : Vec2(1.0, 0.0);
      return len - b.radius[i];
    }
    case Kind::Obstacle:
      return geom::signedDistance(p, b.obstacles[static_cast<std::size_t>(c.obstacle)], normal) -
             b.radius[i];
    case Kind::Robot: {
      const Vec2 d = Vec2(q[0], q[1]) - Vec2(q[2], q[3]);
      const double len = d.norm();
      if (normal) *normal = len > 0 ? Vec2(d / len) : Vec2(1.0, 0.0);
      return len - b.radius[0] - b.radius[1];
    }
  }
  return 1.0;
}

void project(const Bodies& b, const Active& active, const double* q, const double* vFree, double* v,
             double* mu) {
  const int k = active.count;
  const int nv = 2 * b.robots;
  if (v != vFree)
    for (int j = 0; j < nv; ++j) v[j] = vFree[j];
  if (k == 0) return;
  // Rows of G as (robot, normal) pairs: one entry for a fixed obstacle,
  // two (n for robot 0, -n for robot 1) for the pair.
  std::array<Vec2, kMaxActive> nrm;
  for (int j = 0; j < k; ++j)
    gap(b, active.c[static_cast<std::size_t>(j)], q, &nrm[static_cast<std::size_t>(j)]);
  auto row = [&](int j, int robot) -> Vec2 {
    const Constraint& c = active.c[static_cast<std::size_t>(j)];
    const Vec2& n = nrm[static_cast<std::size_t>(j)];
    if (c.kind == Kind::Robot) return robot == 0 ? n : Vec2(-n);
    return c.robot == robot ? n : Vec2(0.0, 0.0);
  };
  using Mat = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxActive, kMaxActive>;
  using Col = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxActive, 1>;
  Mat A(k, k);
  Col rhs(k);
  for (int j = 0; j < k; ++j) {
    double gv = 0;
    for (int r = 0; r < b.robots; ++r) gv += row(j, r).dot(Vec2(vFree[2 * r], vFree[2 * r + 1]));
    rhs(j) = -gv;
    for (int l = 0; l < k; ++l) {
      double a = 0;
      for (int r = 0; r < b.robots; ++r)
        a += b.invMass[static_cast<std::size_t>(r)] * row(j, r).dot(row(l, r));
      A(j, l) = a;
    }
  }
  Col m(k);
  if (k == 1) {
    m(0) = rhs(0) / A(0, 0);
  } else {
    m = Eigen::LDLT<Mat>(A).solve(rhs);
  }
  for (int j = 0; j < k; ++j) {
    if (mu) mu[j] = m(j);
    for (int r = 0; r < b.robots; ++r) {
      const Vec2 d = b.invMass[static_cast<std::size_t>(r)] * m(j) * row(j, r);
      v[2 * r] += d.x();
      v[2 * r + 1] += d.y();
    }
  }
}

}  // namespace simbot::plant::contact
