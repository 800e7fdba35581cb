// plant/arena_events.cpp -- the arena's event rules.
//
// What happens at an event's tick, in the fixed order process() documents:
// ball launches and outcomes, referee put-backs and turns, reflexes,
// contacts and edge detectors, each listed as an Event for the scheduler.
// The rules change a copy of the discrete state and the continuous state
// at the tick; the integrator (arena_integrator.cpp) makes them pending,
// applies them and re-initialises.
#include "plant/arena_impl.h"

namespace simbot::plant {

// ------------------------------------------------------------ event processing
Bumper Arena::Impl::sideOf(double headingRad, const Vec2& towards) {
  return geom::headingDir(headingRad).dot(towards) >= 0 ? Bumper::Front : Bumper::Back;
}

void Arena::Impl::startReflex(Discrete& d, const std::vector<double>& y, int i, Bumper side,
                              std::int64_t T, EventList& ev) {
  RobotDisc& r = d.r[static_cast<std::size_t>(i)];
  r.reflex = true;
  r.reflexSide = side;
  r.reflexS0 = y[static_cast<std::size_t>(i * kPerRobot + S)];
  r.reflexTicks.push(T);
  r.eventTicks.push(T);
  Event e{EventKind::ReflexStart};
  e.robot = static_cast<std::int8_t>(i);
  e.bumper = side;
  ev.push(e);
}

// Finds the reported crossing direction of a root, 0 if not reported.
int Arena::Impl::reported(const int* found, RootKind k, int who) const {
  const int j = found ? rootIndex(k, who) : -1;
  return j < 0 ? 0 : found[j];
}

// Applies everything that happens at tick T (time te) to (d, y) and lists
// the events, in this fixed order: ball launches; ball outcomes (floor,
// divider, obstacle, hit, leaving the field -- the floor first, so a ball
// reaching floor and robot together is a miss, thesis VIII.H); disc
// outcomes (the end of the path, then a hit, as a ball's divider before its
// hit); per robot: referee put-back, reflex end; contacts (robot-robot,
// divider, wall, obstacles) and the
// reflexes they start; edge detectors; the referee's turn. A put-back
// moves a robot, so contacts and edges are reconciled again after it; a
// turn moves its edge detectors, so edges are.
void Arena::Impl::process(std::int64_t T, double te, Discrete& d, std::vector<double>& y,
                          const int* found, EventList& ev) {
  double* ys = y.data();
  // -- launches
  for (int i = 0; i < nR; ++i) {
    RobotDisc& r = d.r[static_cast<std::size_t>(i)];
    for (int g = 0; g < 2; ++g) {
      if (r.launchTick[static_cast<std::size_t>(g)] < 0 ||
          r.launchTick[static_cast<std::size_t>(g)] > T)
        continue;
      r.launchTick[static_cast<std::size_t>(g)] = -1;
      if (r.ballsLeft[static_cast<std::size_t>(g)] <= 0) continue;
      int slot = -1;
      for (int b = 0; b < kMaxBalls && slot < 0; ++b)
        if (!d.balls[static_cast<std::size_t>(b)].active) slot = b;
      if (slot < 0) throw std::logic_error("plant: the ball table is full (see kMaxBalls)");
      d.ballSlots = std::max(d.ballSlots, slot + 1);
      r.ballsLeft[static_cast<std::size_t>(g)]--;
      r.shots++;
      const RobotParams& p = P(i);
      const double h = heading(ys, i);
      const Vec2 dir = geom::headingDir(h);
      const Vec2 muzzle = centre(ys, i) + radius(i) * dir;  // flush with the body edge (VIII.C)
      const double speed = p.muzzle_speed_fps * ys[i * kPerRobot + (g == 0 ? G1 : G2)] *
                           r.launchFactor[static_cast<std::size_t>(g)];
      // The dispersion turns the ball's velocity, not the muzzle, which
      // stays on the body: the speed splits into a horizontal part along
      // heading + azimuth and a vertical one. No dispersion leaves the
      // velocity bit for bit the ideal horizontal one (cos 0 = 1, h + 0 = h).
      const Dispersion& disp = r.launchDispersion[static_cast<std::size_t>(g)];
      const double elevation = geom::degToRad(disp.elevation_deg);
      const Vec2 flight = geom::headingDir(h + geom::degToRad(disp.azimuth_deg));
      const double across = speed * std::cos(elevation);
      Ball& b = d.balls[static_cast<std::size_t>(slot)];
      b = Ball{true,
               false,
               i,
               g,
               te,
               muzzle.x(),
               muzzle.y(),
               p.launch_height_ft,
               across * flight.x(),
               across * flight.y(),
               speed * std::sin(elevation)};
      ++d.inFlight;
      if (bodies.obstacleCount > 0 || d.blockCount > 0) ballMeetings(b, d, ys, te);
      Event e{EventKind::BallLaunch};
      e.robot = static_cast<std::int8_t>(i);
      e.gun = static_cast<std::int8_t>(g);
      e.ball = static_cast<std::int8_t>(slot);
      e.x = b.x0;
      e.y = b.y0;
      e.z = b.z0;
      e.vx = b.vx;
      e.vy = b.vy;
      e.vz = b.vz;
      e.heading_deg = geom::wrap360(geom::radToDeg(h));
      ev.push(e);
    }
  }
  // -- balls
  for (int s = 0; s < kMaxBalls; ++s) {
    Ball& b = d.balls[static_cast<std::size_t>(s)];
    if (!b.active) continue;
    double x, yy, z;
    ballAt(b, te, x, yy, z);
    if (nR == 2) b.closest = std::min(b.closest, ballGap(b, te, ys));
    Event e{EventKind::BallMiss};
    e.robot = static_cast<std::int8_t>(b.shooter);
    e.gun = static_cast<std::int8_t>(b.gun);
    e.ball = static_cast<std::int8_t>(s);
    e.x = x;
    e.y = yy;
    e.z = z;
    e.closest_ft = nR == 2 ? b.closest : -1;
    if (!b.rolling && (reported(found, RootKind::BallFloor, s) < 0 || z <= 0)) {
      if (cfg.field.count_floor_skips) {
        // Appendix A counts skips: the ball goes on along the floor
        // (assumption) and can still hit.
        // The root of z0 + vz s - g s^2 / 2 = 0, s > 0 (the stable form
        // for a ball going down; vz = 0 gives sqrt(2 z0 / g) exactly).
        const double gr = cfg.field.gravity_fps2;
        const double dt = b.vz == 0  ? std::sqrt(2 * b.z0 / gr)
                          : b.vz > 0 ? (b.vz + std::sqrt(b.vz * b.vz + 2 * gr * b.z0)) / gr
                                     : 2 * b.z0 / (std::sqrt(b.vz * b.vz + 2 * gr * b.z0) - b.vz);
        b.x0 += b.vx * dt;
        b.y0 += b.vy * dt;
        b.t0 += dt;
        b.rolling = true;
        if (bodies.obstacleCount > 0 || d.blockCount > 0) ballMeetings(b, d, ys, te);
        z = 0;
        Event skip = e;
        skip.kind = EventKind::BallSkip;
        skip.x = b.x0;
        skip.y = b.y0;
        skip.z = 0;
        ev.push(skip);
      } else {
        e.miss = MissReason::Floor;
        ev.push(e);
        b.active = false;
        --d.inFlight;
        continue;
      }
    }
    const bool inSlab =
        std::abs(x - cfg.field.divider_x_ft) <= cfg.field.divider_thickness_ft / 2 ||
        reported(found, RootKind::BallDivider, s) > 0;
    if (cfg.field.divider && inSlab && yy >= cfg.field.divider_south_ft &&
        yy <= cfg.field.divider_north_ft && z <= cfg.field.divider_height_ft) {
      e.miss = MissReason::Divider;
      ev.push(e);
      b.active = false;
      --d.inFlight;
      continue;
    }
    if (b.meetObstacle >= 0 && (reported(found, RootKind::BallObstacle, s) < 0 || te >= b.meetT)) {
      const bool block = b.meetObstacle >= kMaxObstacles;
      e.miss = block ? MissReason::Block : MissReason::Obstacle;
      e.obstacle =
          static_cast<std::int8_t>(block ? b.meetObstacle - kMaxObstacles : b.meetObstacle);
      ev.push(e);
      b.active = false;
      --d.inFlight;
      continue;
    }
    if (nR == 2) {
      double p2, d2;
      ballHitG(b, te, ys, p2, d2);
      const int tgt = 1 - b.shooter;
      const double R = radius(tgt);
      const bool crossed = reported(found, RootKind::BallHit, s) > 0 && p2 <= R * R;
      // Coming down through the body's height over it: a hit on the top.
      const bool onTop = reported(found, RootKind::BallTop, s) < 0;
      if ((crossed || d2 <= R * R) && (z <= P(tgt).target_height_ft || onTop)) {
        Event h = e;
        h.kind = EventKind::BallHit;
        h.other = static_cast<std::int8_t>(tgt);
        ev.push(h);
        d.r[static_cast<std::size_t>(b.shooter)].hits++;
        b.active = false;
        --d.inFlight;
        continue;
      }
    }
    if (reported(found, RootKind::BallOut, s) < 0 || ballOutG(b, te) < 0) {
      e.miss = MissReason::LeftField;
      ev.push(e);
      b.active = false;
      --d.inFlight;
    }
  }
  // -- discs
  for (int k = 0; k < kMaxDiscs; ++k)
    if (d.discs[static_cast<std::size_t>(k)].active) discOutcome(k, te, d, ys, found, ev);
  // -- robots
  bool moved = false;
  for (int i = 0; i < nR; ++i) {
    RobotDisc& r = d.r[static_cast<std::size_t>(i)];
    double* ry = ys + i * kPerRobot;
    if (reported(found, RootKind::OutOfField, i) < 0 || outG(ys, i) < 0) {
      // Its pushes end where it left the field.
      for (int k = 0; k < d.blockCount; ++k)
        if (d.blocks[static_cast<std::size_t>(k)].pusher == i)
          endPush(d, k, ys, te, ContactWith::None, -1, ev);
      const double hb = wireHalf - cfg.referee.putback_ft;
      ry[X] = std::clamp(ry[X], -hb, hb);
      ry[Y] = std::clamp(ry[Y], -hb, hb);
      Event e{EventKind::RefereePutBack};
      e.robot = static_cast<std::int8_t>(i);
      ev.push(e);
      moved = true;
    }
    if (r.reflex && (reported(found, RootKind::ReflexEnd, i) > 0 || reflexG(ys, i, d) >= 0)) {
      r.reflex = false;
      Event e{EventKind::ReflexEnd};
      e.robot = static_cast<std::int8_t>(i);
      e.bumper = r.reflexSide;
      ev.push(e);
    }
  }
  for (int pass = 0; pass < 3; ++pass) {
    const int* f = pass == 0 ? found : nullptr;
    // Contacts follow the centres alone, which a turn leaves where they
    // were: after a turn they stand as decided. Deciding them again from
    // the sign of a function that is zero to round-off at the tick of its
    // crossing could end a contact at the tick it began, or not, by the
    // last bit (a robot turned at its wall contact's tick, parallel to it).
    if (pass == 0 || moved) {
      contacts(T, d, y, f, ev);
      blockContacts(T, te, d, y, f, ev);
    }
    edges(d, y, f, ev);
    bool turned = false;
    for (int i = 0; i < nR; ++i) turned = refereeTurn(T, d, y, i, ev) || turned;
    if (!turned && !(moved && pass == 0)) break;
    if (pass > 0) moved = false;
  }
}

// Thesis VI.D auto_ref: more than reflex_limit bumper reflexes, or more
// than event_limit reflexes and edge-handler entries, within the window
// turn the robot by turn_deg and start the count again.
bool Arena::Impl::refereeDue(const RobotDisc& r, std::int64_t T) const {
  const std::int64_t from = T - timebase::ticksFromSeconds(cfg.referee.window_s);
  return r.reflexTicks.countSince(from) > cfg.referee.reflex_limit ||
         r.eventTicks.countSince(from) > cfg.referee.event_limit;
}

bool Arena::Impl::refereeTurn(std::int64_t T, Discrete& d, std::vector<double>& y, int i,
                              EventList& ev) {
  RobotDisc& r = d.r[static_cast<std::size_t>(i)];
  if (!refereeDue(r, T)) return false;
  y[static_cast<std::size_t>(i * kPerRobot + H)] += geom::degToRad(cfg.referee.turn_deg);
  r.reflexTicks.n = 0;
  r.eventTicks.n = 0;
  Event e{EventKind::RefereeTurn};
  e.robot = static_cast<std::int8_t>(i);
  ev.push(e);
  return true;
}

// Contacts start where their gap reaches 0 and end where the root
// function of the segment (contactG: the force while pushing, the gap
// while touching without pushing) reaches 0 from below; which contacts
// push is decided at the reset that follows (setActive).
void Arena::Impl::contacts(std::int64_t T, Discrete& d, std::vector<double>& y, const int* found,
                           EventList& ev) {
  const double* ys = y.data();
  auto contactEvent = [&](EventKind k, int i, Bumper b, ContactWith w, int other) {
    Event e{k};
    e.robot = static_cast<std::int8_t>(i);
    e.bumper = b;
    e.with = w;
    e.other = static_cast<std::int8_t>(other);
    ev.push(e);
  };
  auto touchingNow = [&](RootKind rk, contact::Kind ck, int i) {
    const int rep = reported(found, rk, i);
    return rep != 0 ? rep < 0 : sided(rk, i, contactG(ck, i, ys)) < 0;
  };
  if (nR == 2) {
    const bool c = touchingNow(RootKind::RobotRobot, contact::Kind::Robot, 0);
    if (c && !d.robotContact) {
      for (int i = 0; i < 2; ++i) {
        const Bumper side = sideOf(heading(ys, i), centre(ys, 1 - i) - centre(ys, i));
        contactEvent(EventKind::Contact, i, side, ContactWith::Robot, 1 - i);
        startReflex(d, y, i, side, T, ev);
      }
    } else if (!c && d.robotContact) {
      for (int i = 0; i < 2; ++i)
        contactEvent(EventKind::ContactEnd, i, Bumper::Front, ContactWith::Robot, 1 - i);
    }
    d.robotContact = c;
  }
  // A robot against a fixed obstacle (a wall, the divider, one of the
  // field's obstacles): contact starts (the bumper on the side facing the
  // obstacle, and its reflex) or ends.
  auto obstacle = [&](int i, RootKind rk, contact::Kind ck, bool& touching, ContactWith with,
                      int k = -1) {
    const int who = k < 0 ? i : obstacleRoot(i, k);
    const int rep = reported(found, rk, who);
    const bool c = rep != 0 ? rep < 0 : sided(rk, who, contactG(ck, i, ys, std::max(k, 0))) < 0;
    auto event = [&](EventKind kind, Bumper side) {
      Event e{kind};
      e.robot = static_cast<std::int8_t>(i);
      e.bumper = side;
      e.with = with;
      e.obstacle = static_cast<std::int8_t>(k);
      ev.push(e);
    };
    if (c && !touching) {
      std::array<double, 2 * kXY> q{};
      centresOf(ys, q.data());
      Vec2 normal;
      contact::gap(bodies, contact::Constraint{ck, i, std::max(k, 0)}, q.data(), &normal);
      const Bumper side = sideOf(heading(ys, i), -normal);
      event(EventKind::Contact, side);
      startReflex(d, y, i, side, T, ev);
    } else if (!c && touching) {
      event(EventKind::ContactEnd, Bumper::Front);
    }
    touching = c;
  };
  for (int i = 0; i < nR; ++i) {
    RobotDisc& r = d.r[static_cast<std::size_t>(i)];
    if (cfg.field.divider)
      obstacle(i, RootKind::Divider, contact::Kind::Divider, r.dividerContact,
               ContactWith::Divider);
    if (cfg.field.field_walls) {
      obstacle(i, RootKind::WallX, contact::Kind::WallX, r.wallContact[0], ContactWith::Wall);
      obstacle(i, RootKind::WallY, contact::Kind::WallY, r.wallContact[1], ContactWith::Wall);
    }
    for (int k = 0; k < bodies.obstacleCount; ++k)
      obstacle(i, RootKind::Obstacle, contact::Kind::Obstacle,
               r.obstacleContact[static_cast<std::size_t>(k)], ContactWith::Obstacle, k);
  }
}

void Arena::Impl::edges(Discrete& d, std::vector<double>& y, const int* found, EventList& ev) {
  for (int i = 0; i < nR; ++i) {
    RobotDisc& r = d.r[static_cast<std::size_t>(i)];
    for (int k = 0; k < 2; ++k) {
      const RootKind kind = k == 0 ? RootKind::EdgeFore : RootKind::EdgeAft;
      const int rep = reported(found, kind, i);
      const bool low = rep != 0 ? rep < 0 : sided(kind, i, edgeG(y.data(), i, k)) < 0;
      if (low == r.edgeLow[static_cast<std::size_t>(k)]) continue;
      r.edgeLow[static_cast<std::size_t>(k)] = low;
      Event e{low ? EventKind::EdgeEnter : EventKind::EdgeLeave};
      e.robot = static_cast<std::int8_t>(i);
      e.detector = k == 0 ? Detector::Fore : Detector::Aft;
      ev.push(e);
      // Not counted for the referee: a crossing counts only when the
      // program's edge handler is entered (edgeHandlerEntered).
    }
  }
}

}  // namespace simbot::plant
