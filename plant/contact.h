// plant/contact.h -- internal: rigid contacts between the robots' bodies,
// the field walls, the divider and the obstacles (DESIGN.md "Continuous
// motion").
//
// Bodies are rigid and round. While a contact is active its gap g (distance
// between the surfaces, ft) may not shrink: the velocities the wheels would
// give (the "free" velocities of the centres) are replaced by the closest
// velocities, in the metric of the robots' masses, whose normal components
// keep every active gap constant:
//
//   v = v_free + M^-1 G^T mu,   (G M^-1 G^T) mu = -G v_free
//
// where row c of G is the gradient of gap c with respect to the centres
// (its unit normal, pointing away from the obstacle) and mu_c (ft/s, in
// masses relative to the mean) is the normal speed the contact takes away.
// A contact pushes only: it is active while mu_c > 0 and ends (a root of the
// arena) when mu_c reaches 0; it starts when its gap reaches 0.
//
// The model this is (each assumption also in docs/plant.md):
// - A wall, the divider, an obstacle or a resting block (arena_blocks.cpp;
//   a block being pushed is no constraint) is fixed and frictionless: it takes away the
//   normal component and the centre slides along it at the tangential
//   speed the wheels give (the wheels slip sideways). The contact force
//   passes through the centre of the round body, so it exerts no torque and
//   the heading stays the wheels' closed form.
// - Two robots: their normal speeds become one common speed, the
//   mass-weighted mean of the two (momentum along the normal is kept, an
//   inelastic push): with equal masses a robot driving at 2 ft/s into a
//   stopped one pushes it at 1 ft/s, the pusher's wheels slipping forward
//   and the pushed one's backward (it has no brake). Tangential speeds are
//   kept (no friction between the bodies).
// - A robot pushed into a wall stops along that wall's normal with the
//   pusher: the solve handles every active contact together.
//
// Nothing here allocates: at most kMaxActive constraints, Eigen's
// fixed-capacity matrices.
#pragma once

#include <array>
#include <cstdint>

#include "plant/geometry.h"

namespace simbot::plant::contact {

enum class Kind : std::uint8_t { WallX, WallY, Divider, Robot, Obstacle };

// Each robot can touch one of the east/west walls, one of the north/south
// walls, the divider and up to kMaxObstacleContacts obstacles; and the two
// robots each other.
inline constexpr int kMaxActive = 2 * (3 + kMaxObstacleContacts) + 1;

struct Constraint {
  Kind kind = Kind::WallX;
  int robot = 0;     // the robot (for Robot: 0, the pair)
  int obstacle = 0;  // for Obstacle: its index in Bodies::obstacles
};

struct Active {
  int count = 0;
  std::array<Constraint, kMaxActive> c{};
  // Any constraint whose normal turns as the bodies move (the divider's
  // or an obstacle's corners, a round obstacle, the other robot):
  // curvature then needs the full derivative.
  bool turning() const {
    for (int j = 0; j < count; ++j)
      if (c[static_cast<std::size_t>(j)].kind != Kind::WallX &&
          c[static_cast<std::size_t>(j)].kind != Kind::WallY)
        return true;
    return false;
  }
};

struct Bodies {
  int robots = 1;
  std::array<double, 2> radius{};
  // Mean mass over each robot's mass (dimensionless): equal masses give 1.
  std::array<double, 2> invMass{1, 1};
  double half = 8;  // the field walls are at |x|, |y| = half
  geom::Rect divider{};
  // The field's obstacles (fixed, like the divider), then from index
  // kMaxObstacles the blocks on the field where they rest (arena_blocks.cpp).
  int obstacleCount = 0;
  std::array<geom::Convex, kMaxObstacles + kMaxBlocks> obstacles{};
};

// Gap (ft) of constraint c at centres q (x0, y0, x1, y1), and its unit
// normal for the constraint's robot (for Robot: robot 0's; robot 1's is
// its negative).
double gap(const Bodies& b, const Constraint& c, const double* q, geom::Vec2* normal = nullptr);

// Projects the free velocities vFree (2 a robot) onto the velocities every
// active contact allows (the formula above) into v; mu (if not null)
// receives each active contact's mu_c, in the order of `active`. v may be
// vFree.
void project(const Bodies& b, const Active& active, const double* q, const double* vFree, double* v,
             double* mu = nullptr);

}  // namespace simbot::plant::contact
