// plant/arena.cpp -- the arena: closed-form wheels, ARKODE, discrete events.
//
// This file is the arena's protocol with the scheduler: the public Arena
// methods (inputs, advance/retreat, queries). The implementation is
// split by job (arena_impl.h): the root functions in arena_roots.cpp, the
// integrator and dense output in arena_integrator.cpp, the event rules in
// arena_events.cpp, the rigid contacts in contact.cpp. The design of the
// whole follows.
//
// Motion. Between two inputs that change it (a segment), each robot's
// wheel speeds follow a first-order lag toward their targets, so they, the
// heading (their integral), a signed odometer (for the bumper reflex
// distance) and the gun wheels (fraction of full speed, spin-up with the
// motor on, coast-down with it off) are closed forms of time
// (arena_impl.h, Motion). Only the centres' x and y have none: one ARKODE
// ERKStep instance (Dormand-Prince 5(4), the pair's last stage reused as
// the next step's first) integrates them, 2 values a robot. A one-step
// method restarts for free at an input (ARKODE's reset keeps its planned
// step), where CVODE's multistep method started again at order 1 with a
// tiny step. Balls in flight are closed forms too (straight line at the
// muzzle speed, z = h - g t^2 / 2) that live only in the root functions,
// and so are a disc launcher's discs (arena_discs.cpp: a straight line,
// s = v0 tau (1 - e^{-t/tau}), flat).
// A zero time constant starts the segment at the target.
//
// Contacts are rigid (contact.h): while a body pushes against a wall, the
// divider or the other robot, the right-hand side takes the velocity into
// the contact away; contacts start and end at roots.
//
// Events. Every discrete change (edge detector entering or leaving the wire's
// range, contact starting or ending, reflex end, ball hit or miss, centre
// leaving the field) is the zero of a root function; ARKODE locates it
// (a root return) at t, and it happens at tick T = ceil(t * 9,216,000)
// (time.cpp), or the tick before when the crossing is on it (crossedTick).
// At T we evaluate every root function again on the state at T and compare
// with the discrete flags: a function ARKODE reported takes its new side
// from the reported crossing direction (immune to round-off at T), every
// other one from its sign at T, which also catches a second crossing inside
// the same tick. A root that changes nothing (a ball passing the divider's
// plane beside the wall, the closest approach of a ball that misses) lets
// integration go on without a reset; it only updates the ball's closest
// distance to its target, which its ball_miss reports.
//
// The events at T are a prediction (DESIGN.md "co-simulation"): advance()
// returns them and keeps the post-event state aside; they are applied (and
// ARKODE reset, as at every discontinuity in SUNDIALS' examples) when the
// scheduler proceeds, or discarded if an input at an earlier tick changes
// the plant. Hence an input can reset at any tick between the last reset
// and now().
//
// Stepping is independent of how the caller chops time. advance(stop) does
// not stop ARKODE at `stop`: it takes whole internal steps until ARKODE has
// returned a time at or past the stop (the last step may overshoot it; the
// segments keep the overshoot for the next advance(), which steps only if
// they do not reach its stop yet). ARKODE is given a stop time only at a
// discontinuity known when the segment starts: the next ball launch, set at
// every reset (an input that schedules a launch resets). A root whose tick
// lies beyond the caller's stop is held, not reported: the call returns at
// its stop, and a later advance() whose stop reaches the root's tick
// reports it there, with the same events, exactly as a single long
// advance() would have. A reset drops a held root (it lies past the
// input's tick). Between resets the sequence of calls to ARKODE is
// therefore the same whatever the stops were, and so are the steps, the
// step bounds (set from the state at each step's end), the segments, the
// roots and every query; tout, the only argument that is not a state of
// the plant, matters only to the first step's guess and is a fixed
// horizon past the integrator's own time.
//
// Dense output. ARKODE runs in its one-step mode; after every internal step
// we keep the quintic Hermite polynomial of x and y matching their values,
// slopes and curvatures at both ends of the step (arena_integrator.cpp), so
// a query at any tick since the last reset evaluates it and the closed
// forms without touching the integrator: results never depend on whether
// (or how often) anyone queried. The buffers are cleared, not freed, at
// each reset, so after warm-up nothing is allocated per step.
//
// Root finding only sees sign changes between step ends, so a step never
// lets a point of a robot move farther than the nearest edge, wall,
// divider or robot is, and at least 1 inch (stepBound): an edge detector
// cannot cross the 4-inch band around the wire unnoticed, nor two bodies
// graze unnoticed. Balls move 100 times faster, so their root functions
// are built not to graze: the hit function is the along-track offset to
// the opponent's centre plus the half-chord (zero at the entry point of a
// hit and at the closest approach of a miss), the divider function the
// signed distance past the wall's near face along the ball's travel, the
// floor a concave parabola, the field's boundary a convex function the
// ball starts inside of.
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "plant/arena_impl.h"

namespace simbot::plant {

// ---------------------------------------------------------------- Arena

Arena::Arena(const ArenaConfig& config) : impl_(std::make_unique<Impl>(config)) {}
Arena::~Arena() = default;

int Arena::robotCount() const { return impl_->nR; }
std::int64_t Arena::now() const { return impl_->now; }
std::int64_t Arena::lastReinitTick() const { return impl_->segTick; }

bool Arena::setWheels(int robot, const MotorFrame& frame, std::int64_t tick) {
  Impl& m = *impl_;
  const Journal::Entry entry =
      m.enter({.kind = Journal::Kind::SetWheels, .robot = robot, .tick = tick, .frame = frame});
  m.checkRobot(robot);
  m.checkInputTick(tick);
  const bool committedAtTick = m.pending && tick == m.pendingTick;
  const Discrete& cur = committedAtTick ? m.pendingD : m.D;
  const RobotDisc& r = cur.r[static_cast<std::size_t>(robot)];
  if (r.latched == frame) return false;
  const RobotParams& p = m.P(robot);
  const bool sameSpeeds =
      wheelSpeedFps(r.latched.left, p, true) == wheelSpeedFps(frame.left, p, true) &&
      wheelSpeedFps(r.latched.right, p, false) == wheelSpeedFps(frame.right, p, false);
  if (r.reflex || r.driven || sameSpeeds) {
    // The reflex overrides motor strings, and the frame takes effect when it
    // ends; a scripted drive overrides them for good. Either way the
    // right-hand side is unchanged: no reinit.
    m.D.r[static_cast<std::size_t>(robot)].latched = frame;
    if (m.pending) m.pendingD.r[static_cast<std::size_t>(robot)].latched = frame;
    return true;
  }
  m.rewindTo(tick);
  m.D.r[static_cast<std::size_t>(robot)].latched = frame;
  m.reinit(tick, m.timeOfTick(tick), m.tmp);
  return true;
}

bool Arena::setDrive(int robot, double leftFps, double rightFps, std::int64_t tick) {
  Impl& m = *impl_;
  const Journal::Entry entry = m.enter({.kind = Journal::Kind::SetDrive,
                                        .robot = robot,
                                        .tick = tick,
                                        .left = leftFps,
                                        .right = rightFps});
  m.checkRobot(robot);
  m.checkInputTick(tick);
  const bool committedAtTick = m.pending && tick == m.pendingTick;
  const RobotDisc& r = (committedAtTick ? m.pendingD : m.D).r[static_cast<std::size_t>(robot)];
  const std::array<double, 2> drive{leftFps, rightFps};
  if (r.driven && r.drive == drive) return false;
  if (r.reflex) {
    // The reflex overrides the drive as it does motor strings.
    for (Discrete* d : {&m.D, &m.pendingD}) {
      d->r[static_cast<std::size_t>(robot)].driven = true;
      d->r[static_cast<std::size_t>(robot)].drive = drive;
    }
    return true;
  }
  m.rewindTo(tick);
  m.D.r[static_cast<std::size_t>(robot)].driven = true;
  m.D.r[static_cast<std::size_t>(robot)].drive = drive;
  m.reinit(tick, m.timeOfTick(tick), m.tmp);
  return true;
}

bool Arena::setSupply(int robot, double scale, std::int64_t tick) {
  Impl& m = *impl_;
  const Journal::Entry entry =
      m.enter({.kind = Journal::Kind::SetSupply, .robot = robot, .tick = tick, .left = scale});
  m.checkRobot(robot);
  m.checkInputTick(tick);
  if (!(scale > 0) || !std::isfinite(scale))
    throw std::invalid_argument("plant: a supply scale must be positive and finite");
  const bool committedAtTick = m.pending && tick == m.pendingTick;
  const RobotDisc& r = (committedAtTick ? m.pendingD : m.D).r[static_cast<std::size_t>(robot)];
  if (r.supply == scale) return false;
  m.rewindTo(tick);
  m.D.r[static_cast<std::size_t>(robot)].supply = scale;
  m.reinit(tick, m.timeOfTick(tick), m.tmp);
  return true;
}

double Arena::supply(int robot) const {
  impl_->checkRobot(robot);
  return impl_->D.r[static_cast<std::size_t>(robot)].supply;
}

EventList Arena::setPortB(int robot, std::uint8_t value, std::int64_t tick, RandomBits* gunLuck,
                          RandomBits* muzzle, RandomBits* dispersion) {
  Impl& m = *impl_;
  const Journal::Entry entry = m.enter({.kind = Journal::Kind::SetPortB,
                                        .robot = robot,
                                        .tick = tick,
                                        .value = value,
                                        .gunLuck = gunLuck != nullptr,
                                        .muzzle = muzzle != nullptr,
                                        .dispersion = dispersion != nullptr});
  Journal::Recorder gunLuckRecorder(m.journal.get(), gunLuck, 0);
  Journal::Recorder muzzleRecorder(m.journal.get(), muzzle, 1);
  Journal::Recorder dispersionRecorder(m.journal.get(), dispersion, 2);
  gunLuck = gunLuckRecorder.use();
  muzzle = muzzleRecorder.use();
  dispersion = dispersionRecorder.use();
  EventList ev;
  m.checkRobot(robot);
  m.checkInputTick(tick);
  if (m.pending && tick == m.pendingTick) m.commit();
  const RobotDisc& old = m.D.r[static_cast<std::size_t>(robot)];
  if (old.portB == value) return ev;
  const Hardware& hw = m.cfg.robots[static_cast<std::size_t>(robot)].hardware;
  const RobotParams& p = m.P(robot);
  auto bit = [](std::uint8_t v, int b) { return ((v >> b) & 1) != 0; };

  RobotDisc next = old;
  next.portB = value;
  bool rhsChanges = false, scheduleChanges = false;
  for (int g = 0; g < 2; ++g) {
    const bool on = bit(value, hw.gun_motor_bit[static_cast<std::size_t>(g)]);
    if (on != old.gunOn[static_cast<std::size_t>(g)] && !p.gun_motors_always_on) rhsChanges = true;
    next.gunOn[static_cast<std::size_t>(g)] = on;
    const int sb = hw.gun_solenoid_bit[static_cast<std::size_t>(g)];
    if (bit(value, sb) && !bit(old.portB, sb)) {
      Event e{EventKind::SolenoidStroke};
      e.robot = static_cast<std::int8_t>(robot);
      e.gun = static_cast<std::int8_t>(g);
      const double jam = p.jam_probability, misfire = p.misfire_probability;
      if (old.ballsLeft[static_cast<std::size_t>(g)] <= 0) {
        e.kind = EventKind::GunEmpty;
      } else if (old.gunJammed[static_cast<std::size_t>(g)]) {
        e.kind = EventKind::GunJammed;
      } else if (old.launchTick[static_cast<std::size_t>(g)] >= 0) {
        // A stroke already under way ignores the new edge.
      } else if (const double u = gunLuck && (jam > 0 || misfire > 0) ? unit53(gunLuck->next()) : 1;
                 u < jam) {
        e.kind = EventKind::GunJammed;
        next.gunJammed[static_cast<std::size_t>(g)] = true;
      } else if (u < jam + misfire) {
        e.kind = EventKind::GunMisfire;
      } else {
        next.launchTick[static_cast<std::size_t>(g)] =
            tick + timebase::ticksFromSeconds(p.stroke_s);
        next.launchFactor[static_cast<std::size_t>(g)] = muzzleFactor(p, muzzle);
        next.launchDispersion[static_cast<std::size_t>(g)] = drawDispersion(p, dispersion);
        scheduleChanges = true;
      }
      ev.push(e);
    }
  }
  // A disc launcher sends its disc at the edge's tick (arena_discs.cpp);
  // without one the bit is only logged.
  bool discLaunch = false;
  if (bit(value, hw.disc_shooter_bit) && !bit(old.portB, hw.disc_shooter_bit)) {
    Event e{EventKind::DiscShooter};
    e.robot = static_cast<std::int8_t>(robot);
    if (hw.secondary.kind != SecondaryKind::Disc)
      ev.push(e);
    else if (old.discsLeft > 0)
      discLaunch = true;  // its disc_fire comes with the launch below
    else
      ev.push(Event{EventKind::DiscEmpty, e.robot});
  }
  // Deployables: one item set down at the edge's tick while the table has
  // any left (deployables.cpp). Nothing that moves changes, but a block is
  // a new body (arena_blocks.cpp): it must fit where it is set down, and
  // the root functions are made again with it.
  std::array<Block, kMaxDeployKinds> newBlocks{};
  int nNewBlocks = 0;
  for (std::size_t k = 0; k < hw.deployables.size(); ++k) {
    const Deployable& dep = hw.deployables[k];
    if (!bit(value, dep.bit) || bit(old.portB, dep.bit)) continue;
    int& left = m.deployLeft[static_cast<std::size_t>(robot)][k];
    Event e{left > 0 ? EventKind::Deploy : EventKind::DeployEmpty};
    e.robot = static_cast<std::int8_t>(robot);
    e.gun = static_cast<std::int8_t>(k);
    if (left > 0) {
      const Deployed item = placeDeployable(dep, robot, static_cast<int>(k), tick,
                                            pose(robot, tick), m.radius(robot));
      if (dep.kind == DeployKind::Block) {
        const Discrete& now = m.discreteAt(tick);
        if (now.blockCount + nNewBlocks >= kMaxBlocks)
          throw std::logic_error("plant: the block table is full (see kMaxBlocks)");
        Block& b = newBlocks[static_cast<std::size_t>(nNewBlocks)];
        b.item = static_cast<int>(m.deployed.size());
        b.robot = robot;
        b.x = item.x_ft;
        b.y = item.y_ft;
        const double h = geom::degToRad(item.heading_deg);
        b.ax = std::cos(h);
        b.ay = -std::sin(h);
        b.halfWidth = item.width_ft / 2;
        b.halfDepth = item.depth_ft / 2;
        b.height = item.height_ft;
        b.load = dep.mass_lb * dep.floor_friction;
        // Against what is on the field then (and the blocks released with it).
        Discrete probe = now;
        for (int j = 0; j < nNewBlocks; ++j)
          probe.blocks[static_cast<std::size_t>(probe.blockCount++)] =
              newBlocks[static_cast<std::size_t>(j)];
        probe.blocks[static_cast<std::size_t>(probe.blockCount)] = b;
        m.stateAt(tick, m.blockY);
        if (!m.blockFits(probe, m.blockShape(probe, probe.blockCount, m.blockY.data()),
                         m.blockY.data())) {
          e.kind = EventKind::DeployBlocked;
          e.x = item.x_ft;
          e.y = item.y_ft;
          e.heading_deg = item.heading_deg;
          ev.push(e);
          continue;
        }
        ++nNewBlocks;
      }
      m.deployed.push_back(item);
      --left;
      e.ball = static_cast<std::int8_t>(dep.count - left);
      e.x = item.x_ft;
      e.y = item.y_ft;
      e.heading_deg = item.heading_deg;
    }
    ev.push(e);
  }
  if (!rhsChanges && !scheduleChanges && !discLaunch && nNewBlocks == 0) {
    // Nothing that moves changes: the prediction stays valid.
    for (Discrete* d : {&m.D, &m.pendingD}) {
      d->r[static_cast<std::size_t>(robot)].portB = value;
      d->r[static_cast<std::size_t>(robot)].gunJammed = next.gunJammed;
    }
    return ev;
  }
  m.rewindTo(tick);
  m.D.r[static_cast<std::size_t>(robot)] = next;
  if (nNewBlocks > 0) {
    for (int j = 0; j < nNewBlocks; ++j)
      m.D.blocks[static_cast<std::size_t>(m.D.blockCount++)] =
          newBlocks[static_cast<std::size_t>(j)];
    m.flightsSeeBlocks(m.D, m.tmp.data(), m.timeOfTick(tick));
  }
  if (discLaunch) m.launchDisc(m.D, m.tmp, robot, m.timeOfTick(tick), ev);
  m.reinit(tick, m.timeOfTick(tick), m.tmp);
  return ev;
}

EventList Arena::triggerReflex(int robot, Bumper side, std::int64_t tick) {
  Impl& m = *impl_;
  const Journal::Entry entry =
      m.enter({.kind = Journal::Kind::TriggerReflex, .robot = robot, .tick = tick, .side = side});
  EventList ev;
  m.checkRobot(robot);
  m.rewindTo(tick);
  m.startReflex(m.D, m.tmp, robot, side, tick, ev);
  m.reinit(tick, m.timeOfTick(tick), m.tmp);
  return ev;
}

EventList Arena::edgeHandlerEntered(int robot, std::int64_t tick) {
  Impl& m = *impl_;
  const Journal::Entry entry =
      m.enter({.kind = Journal::Kind::EdgeHandlerEntered, .robot = robot, .tick = tick});
  EventList ev;
  m.checkRobot(robot);
  m.checkInputTick(tick);
  if (m.pending && tick == m.pendingTick) m.commit();
  const auto i = static_cast<std::size_t>(robot);
  RobotDisc& r = m.D.r[i];
  // The prediction at a later tick stays valid unless it counted events of
  // this robot itself (its referee check there did not see this entry).
  const bool keep = !m.pending || (m.pendingD.r[i].eventTicks.n == r.eventTicks.n &&
                                   m.pendingD.r[i].eventTicks.t == r.eventTicks.t);
  r.eventTicks.push(tick);
  if (!m.refereeDue(r, tick)) {
    if (m.pending) {
      if (keep) {
        m.pendingD.r[i].eventTicks.push(tick);
      } else {
        m.rewindTo(tick);
        m.reinit(tick, m.timeOfTick(tick), m.tmp);
      }
    }
    return ev;
  }
  m.rewindTo(tick);
  m.refereeTurn(tick, m.D, m.tmp, robot, ev);
  // The turn moves the robot's edge detectors: edges are reconciled after
  // it, as after a turn at a plant event (process(); its contacts stand).
  for (int pass = 0; pass < 3; ++pass) {
    m.edges(m.D, m.tmp, nullptr, ev);
    bool turned = false;
    for (int j = 0; j < m.nR; ++j) turned = m.refereeTurn(tick, m.D, m.tmp, j, ev) || turned;
    if (!turned) break;
  }
  m.reinit(tick, m.timeOfTick(tick), m.tmp);
  return ev;
}

AdvanceResult Arena::advance(std::int64_t stopTick) {
  const Journal::Entry entry = impl_->enter({.kind = Journal::Kind::Advance, .tick = stopTick});
  return impl_->advance(stopTick);
}
void Arena::retreat(std::int64_t tick) {
  const Journal::Entry entry = impl_->enter({.kind = Journal::Kind::Retreat, .tick = tick});
  impl_->retreat(tick);
}

bool Arena::ballsInFlight() const {
  const Impl& m = *impl_;
  for (const Discrete* d : {&m.D, &m.pendingD}) {
    if (d == &m.pendingD && !m.pending) break;
    if (d->inFlight > 0 || m.nextLaunchIn(*d) >= 0) return true;
  }
  return false;
}

RobotState Arena::state(int robot, std::int64_t tick) const {
  const Impl& m = *impl_;
  m.checkRobot(robot);
  std::vector<double>& y = m.qtmp;
  m.stateAt(tick, y);
  const double* r = y.data() + robot * kPerRobot;
  RobotState s;
  s.pose = Pose{r[X], r[Y], geom::wrap360(geom::radToDeg(r[H]))};
  s.left_fps = r[VL];
  s.right_fps = r[VR];
  s.odometer_ft = r[S];
  s.gun_wheel = {r[G1], r[G2]};
  return s;
}

namespace {
// x, y and the heading in radians as a Pose (heading in degrees, [0, 360)).
Pose poseOf(const std::array<double, 3>& xyh) {
  const auto [x, y, h] = xyh;
  return Pose{x, y, geom::wrap360(geom::radToDeg(h))};
}
}  // namespace

Pose Arena::pose(int robot, std::int64_t tick) const {
  const Impl& m = *impl_;
  m.checkRobot(robot);
  return poseOf(m.poseAt(robot, tick));
}

bool Arena::edgeDetectorLow(int robot, Detector d, std::int64_t tick) const {
  const Impl& m = *impl_;
  m.checkQueryTick(tick);
  return m.discreteAt(tick).r[static_cast<std::size_t>(robot)].edgeLow[static_cast<std::size_t>(d)];
}

EyeReadings Arena::eyeReadings(int robot, std::int64_t tick, RandomBits* noise,
                               EyeChannels channels) const {
  const Impl& m = *impl_;
  m.checkRobot(robot);
  // Both poses at once when there are two robots (the tick's record found
  // once).
  Pose poses[2];
  if (m.nR < 2) {
    poses[robot] = poseOf(m.poseAt(robot, tick));
  } else {
    const auto both = m.posesAt(tick);
    poses[0] = poseOf(both[0]);
    poses[1] = poseOf(both[1]);
  }
  const Pose& self = poses[robot];
  // The items set down by `tick` (deployed is in tick order).
  EyeScene scene{m.deployed.data(), 0};
  while (scene.count < static_cast<int>(m.deployed.size()) &&
         m.deployed[static_cast<std::size_t>(scene.count)].tick <= tick)
    ++scene.count;
  // Blocks where they are at `tick` (a push moves them).
  const Discrete& d = m.discreteAt(tick);
  if (d.blockCount > 0) {
    m.eyeItems.assign(m.deployed.begin(), m.deployed.begin() + scene.count);
    m.stateAt(tick, m.blockY);
    for (int k = 0; k < d.blockCount; ++k) {
      const auto item = static_cast<std::size_t>(d.blocks[static_cast<std::size_t>(k)].item);
      if (item >= m.eyeItems.size()) continue;
      const Vec2 c = m.blockAt(d, k, m.blockY.data());
      m.eyeItems[item].x_ft = c.x();
      m.eyeItems[item].y_ft = c.y();
    }
    scene.items = m.eyeItems.data();
  }
  if (m.nR < 2)
    return computeEyes(self, nullptr, m.P(robot), m.cfg.field, noise, channels, &scene, robot);
  return computeEyes(self, &poses[1 - robot], m.P(robot), m.cfg.field, noise, channels, &scene,
                     robot);
}

std::vector<BallView> Arena::balls(std::int64_t tick) const {
  const Impl& m = *impl_;
  m.checkQueryTick(tick);
  const Discrete& d = m.discreteAt(tick);
  const double t = (m.pending && tick == m.pendingTick) ? m.pendingTime : m.timeOfTick(tick);
  std::vector<BallView> out;
  for (int s = 0; s < kMaxBalls; ++s) {
    const Ball& b = d.balls[static_cast<std::size_t>(s)];
    if (!b.active) continue;
    BallView v;
    v.shooter = b.shooter;
    v.gun = b.gun;
    v.slot = s;
    m.ballAt(b, t, v.x_ft, v.y_ft, v.z_ft);
    out.push_back(v);
  }
  return out;
}

bool Arena::inReflex(int robot) const {
  const Impl& m = *impl_;
  return m.discreteAt(m.now).r[static_cast<std::size_t>(robot)].reflex;
}
int Arena::ballsLeft(int robot, int gun) const {
  const Impl& m = *impl_;
  return m.discreteAt(m.now)
      .r[static_cast<std::size_t>(robot)]
      .ballsLeft[static_cast<std::size_t>(gun)];
}
int Arena::shots(int robot) const {
  const Impl& m = *impl_;
  return m.discreteAt(m.now).r[static_cast<std::size_t>(robot)].shots;
}
int Arena::hits(int robot) const {
  const Impl& m = *impl_;
  return m.discreteAt(m.now).r[static_cast<std::size_t>(robot)].hits;
}

int Arena::discShots(int robot) const {
  const Impl& m = *impl_;
  return m.discreteAt(m.now).r[static_cast<std::size_t>(robot)].discShots;
}
const std::vector<Deployed>& Arena::deployed() const { return impl_->deployed; }

Pose Arena::blockCentre(int k, std::int64_t tick) const {
  const Impl& m = *impl_;
  m.checkQueryTick(tick);
  const Discrete& d = m.discreteAt(tick);
  if (k < 0 || k >= d.blockCount) throw std::out_of_range("plant: block index");
  m.stateAt(tick, m.blockY);
  const Vec2 c = m.blockAt(d, k, m.blockY.data());
  return Pose{
      c.x(), c.y(),
      m.deployed[static_cast<std::size_t>(d.blocks[static_cast<std::size_t>(k)].item)].heading_deg};
}

double Arena::blockPushedFt(int robot) const {
  const Impl& m = *impl_;
  m.checkRobot(robot);
  return m.discreteAt(m.now).r[static_cast<std::size_t>(robot)].pushedFt;
}

int Arena::discHits(int robot) const {
  const Impl& m = *impl_;
  return m.discreteAt(m.now).r[static_cast<std::size_t>(robot)].discHits;
}
int Arena::discsLeft(int robot) const {
  const Impl& m = *impl_;
  return m.discreteAt(m.now).r[static_cast<std::size_t>(robot)].discsLeft;
}

IntegratorStats Arena::stats() const {
  const Impl& m = *impl_;
  // ARKODE's counters run on over resets (a reset keeps them); the dense
  // output's own right-hand sides are counted with them.
  IntegratorStats s = m.acc;
  s.steps = m.arenaSteps();
  s.rhs_evals = m.arenaRhsEvals() + m.ownRhs;
  return s;
}

const char* eventKindName(EventKind k) {
  switch (k) {
    case EventKind::EdgeEnter:
      return "edge_enter";
    case EventKind::EdgeLeave:
      return "edge_leave";
    case EventKind::Contact:
      return "contact";
    case EventKind::ContactEnd:
      return "contact_end";
    case EventKind::ReflexStart:
      return "reflex_start";
    case EventKind::ReflexEnd:
      return "reflex_end";
    case EventKind::BallLaunch:
      return "ball_launch";
    case EventKind::BallHit:
      return "ball_hit";
    case EventKind::BallMiss:
      return "ball_miss";
    case EventKind::BallSkip:
      return "ball_skip";
    case EventKind::RefereePutBack:
      return "referee_put_back";
    case EventKind::RefereeTurn:
      return "referee_turn";
    case EventKind::SolenoidStroke:
      return "solenoid_stroke";
    case EventKind::GunEmpty:
      return "gun_empty";
    case EventKind::GunMisfire:
      return "gun_misfire";
    case EventKind::GunJammed:
      return "gun_jammed";
    case EventKind::DiscShooter:
      return "disc_shooter";
    case EventKind::DiscFire:
      return "disc_fire";
    case EventKind::DiscEmpty:
      return "disc_empty";
    case EventKind::DiscHit:
      return "disc_hit";
    case EventKind::DiscMiss:
      return "disc_miss";
    case EventKind::Deploy:
      return "deploy";
    case EventKind::DeployEmpty:
      return "deploy_empty";
    case EventKind::DeployBlocked:
      return "deploy_blocked";
    case EventKind::PushStart:
      return "push_start";
    case EventKind::PushEnd:
      return "push_end";
  }
  return "?";
}

const char* secondaryKindName(SecondaryKind k) {
  return k == SecondaryKind::Disc ? "disc" : "none";
}

}  // namespace simbot::plant
