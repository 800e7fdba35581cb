// plant/plant.h -- the whole public interface of simbot's plant.
//
// The plant is everything physical in the 1997 NPS Robot Wars arena: the
// 16 x 16 ft field with its edge wire and divider, one or two robots (base,
// motor controller, bumpers, edge detectors, eyes, guns) and the balls in
// flight. It knows nothing of bytecode: the scheduler hands it latched motor
// frames and port B writes at exact ticks, asks it to integrate ahead with
// advance(), and samples sensors at exact ticks. Time in this interface is
// always integer ticks of the 9.216 MHz clock; seconds exist only inside the
// integrator (see DESIGN.md "Time and determinism"). Every physical number
// comes from a TOML profile (profiles/*.toml) that config/ reads and checks
// key by key into the structures below; per-robot hardware files bind port
// B bits and may override the robot's own values.
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "timebase/tick.h"

namespace simbot::plant {

namespace arena_detail {
struct Journal;
}

// ---------------------------------------------------------------- time
// The clock is defined once, in timebase/tick.h.
using timebase::kTicksPerSecond;

// Tick of a continuous-time event found at t seconds: ceil(t * 9,216,000),
// the ceiling of the exact real product (not of the rounded double product).
std::int64_t eventTickFromSeconds(double t);
// The double nearest to tick / 9,216,000 (used to hand times to ARKODE).
double secondsFromTick(std::int64_t tick);

// ---------------------------------------------------------------- parameters
// Internal units: feet, seconds, feet per second, degrees for angles that
// the user sees (headings, turn angle), dimensionless ratios, A/D readings.
struct Pose {
  double x_ft = 0;         // +x east, origin at the field's centre
  double y_ft = 0;         // +y north (away from the starting end)
  double heading_deg = 0;  // clockwise from +y, in [0, 360)
};

// A gun's magazine holds at most this many balls (the thesis: 15). The
// arena's table of balls in flight is sized from it (arena.cpp kMaxBalls).
inline constexpr int kMaxBallsPerGun = 16;

// A robot's battery (the profile's [battery], optional; battery.h has the
// model). Internal units: coulombs, volts, amperes, ohms, seconds. Off: the
// wheels and gun wheels run at the speed table's speeds for the whole run.
struct BatteryParams {
  bool enabled = false;
  double capacity_c = 0;                           // charge when full
  double voltage_full_v = 0, voltage_empty_v = 0;  // open circuit, linear in the charge
  double nominal_v = 0;       // the voltage the speed table and muzzle speed hold at
  double resistance_ohm = 0;  // internal resistance
  double board_a = 0;         // the controller board (always, in reset too)
  double drive_a = 0;         // one drive motor at step 15 (linear in the step)
  double gun_motor_a = 0;     // one gun-wheel motor on
  double solenoid_a = 0;      // one solenoid while its bit is high
  double brownout_v = 0;      // the board resets at or below this
  double hysteresis_v = 0;    // ... and restarts only at brownout_v + this or above
  double reset_hold_s = 0;    // ... and not before this long after the reset
  bool operator==(const BatteryParams&) const = default;
};

struct RobotParams {
  // body
  double body_diameter_ft = 0;
  double target_height_ft = 0;
  double edge_detector_inset_ft = 0;  // detector inside the body edge
  // base and motor controller
  double wheel_diameter_ft = 0;              // informational: the speed table is ground speed
  double track_ft = 0;                       // distance between the wheels
  std::array<double, 16> speed_table_fps{};  // ground speed for steps 0..f
  double left_trim = 1, right_trim = 1;      // per-wheel multiplicative trim
  // Seeded, per match (drawWheelTrims): each trim times its own factor
  // uniform in [1 - trim_spread, 1 + trim_spread]. 0 = the trims as given.
  double trim_spread = 0;
  double motor_lag_s = 0;  // first-order lag; 0 = instant
  double mass_lb = 35;     // how hard it pushes the other robot (contact.h)
  // Wheel-floor Coulomb friction coefficient: the robot's traction is
  // mass_lb * wheel_friction * g (a force), what it can push a block with
  // (DESIGN.md "The wider competition"; docs/plant.md "Deployables").
  double wheel_friction = 0.7;
  // bumper reflex (hard-wired in the motor controller)
  double reflex_distance_ft = 0;
  int reflex_speed_step = 15;
  // eyes
  double eye_max = 0, eye_background = 0, eye_saturation_ft = 0;
  double left_eye_width = 0, right_eye_width = 0, eye_nose = 0;  // same unit
  double noise_sigma = 0;              // A/D readings, Gaussian, before quantising
  double bad_reading_probability = 0;  // reading replaced by a random A/D value
  bool thesis_swapped_eyes = false;    // Appendix C: far eye gets the full value
  // guns
  double gun_wheel_lag_s = 0;         // first-order spin-up, motor on; 0 = instant
  double gun_wheel_coast_s = 0;       // first-order coast-down, motor off; 0 = instant
  bool gun_motors_always_on = false;  // thesis Appendix E: port B motor bits ignored
  double stroke_s = 0;                // solenoid rising edge -> launch
  double muzzle_speed_fps = 0;        // at full gun-wheel speed
  // Seeded, per launch (muzzleFactor): the muzzle speed times a factor
  // uniform in [1 - spread, 1 + spread]. 0 = every ball at muzzle_speed_fps.
  double muzzle_speed_spread = 0;
  // Seeded, per launch (drawDispersion): the ball leaves turned from the
  // heading by an azimuth (+ = clockwise, like the heading) and raised by an
  // elevation, each normal with mean 0 and this standard deviation (deg),
  // independently. 0 and 0 = every ball horizontal along the heading.
  double azimuth_sigma_deg = 0, elevation_sigma_deg = 0;
  double launch_height_ft = 0;
  int balls_per_gun = 0;
  // Per stroke that would launch: the gun jams (launches nothing, now or
  // later, this match), or misfires (launches nothing; the ball stays
  // chambered for the next stroke). DESIGN.md: an option.
  double jam_probability = 0, misfire_probability = 0;
  BatteryParams battery;
};

// ---------------------------------------------------------------- obstacles
// Fixed obstacles on the field (DESIGN.md "The wider competition": a
// weighted mine, the mountain), placed by a scenario or a rules file and
// checked by config/ (a convex shape inside the field, clear of the start
// poses). Rigid like the divider: a body touching one is a contact at its
// exact tick (contact.h), a ball that meets one below its height ends
// there (a miss, "obstacle"), and one taller than the beacon hides the
// beacon from an eye when it stands between them.
inline constexpr int kMaxObstacles = 16;
inline constexpr int kMaxObstacleVertices = 16;
// At most this many obstacles touch one robot at once (contact.h's fixed
// constraint table); one more is the run's plant fault.
inline constexpr int kMaxObstacleContacts = 4;

struct ObstaclePoint {
  double x_ft = 0, y_ft = 0;
};
struct Obstacle {
  enum class Kind : std::uint8_t { Circle, Box, Polygon };
  Kind kind = Kind::Circle;
  std::string name;   // empty: "obstacle N" (obstacleLabel)
  bool mine = false;  // an instructor's weighted mine (a rules file may forbid them)
  double height_ft = 0;
  double x_ft = 0, y_ft = 0;  // a circle's or box's centre; a polygon's vertex mean
  double radius_ft = 0;       // a circle's
  // A box: width along x and depth along y before it is turned clockwise
  // (as headings turn) by angle_deg about its centre.
  double width_ft = 0, depth_ft = 0, angle_deg = 0;
  // A box's corners or a polygon's vertices, convex, counter-clockwise
  // (makeBox, makePolygon); empty for a circle.
  std::vector<ObstaclePoint> points;
};
// A box's obstacle with its corners; a polygon's from its vertices in
// either order (counter-clockwise afterwards). makePolygon does not check
// convexity: config/ refuses what is not convex before.
Obstacle makeBox(double x, double y, double width, double depth, double angleDeg, double height);
Obstacle makePolygon(const std::vector<ObstaclePoint>& points, double height);
const char* obstacleKindName(Obstacle::Kind k);

struct FieldParams {
  double size_ft = 0;              // square side
  double wire_inset_ft = 0;        // wire ring inside the edge
  double wire_sensitivity_ft = 0;  // detector reads low within this of the wire
  bool field_walls = true;         // a body touching the field edge trips a bumper
  double divider_x_ft = 0, divider_south_ft = 0, divider_north_ft = 0;
  double divider_thickness_ft = 0, divider_height_ft = 0;
  // A course without a divider (a rule set's course.divider = false): no
  // contact, no ball stopped, no beacon hidden by it.
  bool divider = true;
  std::array<Pose, 2> start{};  // A, B
  // Robots put down by hand (placeByHand): the centre uniform in a disc of
  // this radius around the start pose, the heading uniform within +- this
  // many degrees of it. 0 and 0 = exactly at the start poses.
  double placement_radius_ft = 0;
  double placement_heading_deg = 0;
  double gravity_fps2 = 0;
  bool count_floor_skips = false;
  // The standard beacon's height above the floor (every robot carries the
  // course's beacon on the course's base): an obstacle taller hides it.
  double beacon_height_ft = 0.75;
  std::vector<Obstacle> obstacles;  // at most kMaxObstacles
};
// How traces and messages name obstacle `index` (0-based) of the field:
// "obstacle N" (N from 1), and "obstacle N (NAME)" when it has a name.
std::string obstacleLabel(const FieldParams& field, int index);

// The referee's limits are at most this; arena.cpp keeps the last
// kMaxRefereeLimit + 1 event ticks per robot, enough to see one too many.
inline constexpr int kMaxRefereeLimit = 15;

struct RefereeParams {
  int reflex_limit = 3;  // more than this many reflexes in the window -> turn
  int event_limit = 5;   // more than this many reflexes + edge-handler entries -> turn
  double window_s = 10;
  double putback_ft = 1.5;  // inside the wire
  double turn_deg = 45;
  // Detect to Engage (a rule set's [course]; thesis Appendix A): judged
  // by the scheduler at each launch when judge_scatter. A launch is a
  // scatter shot when neither of the shooter's eyes reads above
  // detect_threshold; its hit counts only if scatter_scores.
  bool judge_scatter = false;
  double detect_threshold = 0;
  bool scatter_scores = true;
};

// A launcher's magazine holds at most this many discs (the thesis,
// Appendix A: a secondary weapon's magazine at most fifteen rounds; a rules
// file may refuse more). The arena's table of discs in flight is sized
// from it (arena_impl.h kMaxDiscs).
inline constexpr int kMaxDiscsPerLauncher = 16;

// A secondary weapon (DESIGN.md "The wider competition"), from a hardware
// file's [secondary] table. None: the disc shooter's bit is logged only.
enum class SecondaryKind : std::uint8_t { None, Disc };
// "disc" (the hardware file's and the trace's word); "none" for None.
const char* secondaryKindName(SecondaryKind k);

// The disc launcher: a rising edge of its port B bit (Hardware::
// disc_shooter_bit) sends one disc from the body's rim along the heading,
// flat at launch_height_ft, its speed decaying with linear drag,
// v = v0 e^{-t/tau}, until it strikes a robot, a wall or the divider, or
// its speed falls below stop_speed_fps (docs/plant.md, "The disc launcher").
struct SecondaryWeapon {
  SecondaryKind kind = SecondaryKind::None;
  int magazine = 0;  // discs, at most kMaxDiscsPerLauncher
  double launch_speed_fps = 0;
  double launch_height_ft = 0;
  double drag_time_s = 0;  // tau
  double stop_speed_fps = 0;
  double diameter_ft = 0;
};

// ---------------------------------------------------------------- deployables
// What a robot carries and sets down behind it on a rising edge of a port B
// bit (DESIGN.md "The wider competition"; docs/plant.md "Deployables"), from
// a hardware file's [[deployables]]. At most one per bit.
enum class DeployKind : std::uint8_t { Block, DecoyLight, DecoyScreen };
// "block", "decoy_light", "decoy_screen" (the hardware file's and the
// trace's words).
const char* deployKindName(DeployKind k);
inline constexpr int kMaxDeployKinds = 8;  // one per port B bit at most
inline constexpr int kMaxDeployCount = 16;
// Blocks are bodies of the plant (arena_blocks.cpp): its fixed tables hold
// kMaxBlocks on the field, so config/ refuses a robot whose [[deployables]]
// carry more than kMaxBlocksPerRobot blocks over all its block tables.
inline constexpr int kMaxBlocksPerRobot = 16;
inline constexpr int kMaxBlocks = 2 * kMaxBlocksPerRobot;

struct Deployable {
  DeployKind kind = DeployKind::Block;
  int bit = 0;
  int count = 0;
  // A block: width across the robot's heading, depth along it, height; a
  // screen: width (across the heading) and height; a light: its height.
  double width_ft = 0, depth_ft = 0, height_ft = 0;
  double mass_lb = 0, floor_friction = 0;  // a block
  // A light's kappa over the eye's own beacon kappa ((max - background)
  // r_sat^2): 1 is as bright as the standard beacon.
  double intensity = 0;
};

// One item set down on the field (Arena::deployed): what, whose, where.
// A block's or screen's footprint is turned by `heading_deg` (the robot's
// at release): its width across that heading.
struct Deployed {
  DeployKind kind = DeployKind::Block;
  int robot = 0;
  int table = 0;  // index in the robot's Hardware::deployables
  std::int64_t tick = 0;
  double x_ft = 0, y_ft = 0, heading_deg = 0;
  double width_ft = 0, depth_ft = 0, height_ft = 0, intensity = 0;
};

// An item is set down this far behind the body's back rim (assumption:
// clear of the rim, so the robot that drops it does not touch it then).
inline constexpr double kDeployClearanceFt = 0.02;

// The item `d` (table `table` of robot `robot`'s deployables) set down at
// `tick` behind a robot at `pose` with a body of `bodyRadius`: its centre
// on the line of the heading, kDeployClearanceFt behind the back rim (a
// block's back face there, its near face half its depth behind).
Deployed placeDeployable(const Deployable& d, int robot, int table, std::int64_t tick,
                         const Pose& pose, double bodyRadius);

// The items on the field an eye reads among (deployables.cpp).
struct EyeScene {
  const Deployed* items = nullptr;
  int count = 0;
};
// The unquantised signals of robot selfRobot's eyes with the items of
// `scene` on the field: the opponent's beacon and the opponent's decoy
// lights add (docs/plant.md "Deployables": c_i = min(intensity_i kappa /
// r_i^2, max - background) on the near eye, c_i f_i on the far one), each
// hidden by the divider, an obstacle, a block or a screen taller than it.
// `beaconScreen` (if not null): the index in scene.items of the decoy
// screen that hid the opponent's beacon, else -1.
void eyeSignalsAmong(const Pose& self, int selfRobot, const Pose* opponent, const RobotParams& p,
                     const FieldParams& field, const EyeScene& scene, double& left, double& right,
                     int* beaconScreen = nullptr);

// Port B bindings of one robot (bits 0..7).
struct Hardware {
  std::array<int, 2> gun_motor_bit{3, 7};
  std::array<int, 2> gun_solenoid_bit{4, 5};
  int disc_shooter_bit = 6;  // logged only, unless `secondary` is a disc launcher
  SecondaryWeapon secondary;
  std::vector<Deployable> deployables;  // [[deployables]], at most one per bit
};

// The integrator failed (a SUNDIALS call returned an error). The profile
// checks keep it from happening; if it still does, the run ends there
// with a fault of the plant, not an internal error.
class SolverError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The version of the SUNDIALS the plant was built with ("7.1.1").
const char* sundialsVersion();

// ---------------------------------------------------------------- motor frames
struct WheelCommand {
  int speed = 0;        // 0..15
  bool forward = true;  // 'f' / 'r'
  bool go = false;      // 'g' / 's'
  char counter = '0';   // distance counter byte (unused)
  bool operator==(const WheelCommand&) const = default;
};
struct MotorFrame {
  WheelCommand left, right;
  bool operator==(const MotorFrame&) const = default;
};
// Parses the 8 characters the controller latched. nullopt if the length is
// not 8 or any character is invalid (speed 0-9a-f lowercase, f/r, g/s,
// counter any non-NUL byte).
std::optional<MotorFrame> parseMotorFrame(std::string_view chars);
// Signed ground speed (ft/s) one wheel runs at for a command: speed table,
// direction, go/stop, the wheel's trim.
double wheelSpeedFps(const WheelCommand& cmd, const RobotParams& p, bool leftWheel);

// ---------------------------------------------------------------- optics
struct EyeReadings {
  int left = 16;   // channel 0
  int right = 16;  // channel 1
  // The decoy screen (its index in Arena::deployed) that hid the opponent's
  // beacon from these eyes, or -1: the beacon in front of them, not hidden
  // by the divider or an obstacle (eyeSignalsAmong).
  int beaconScreen = -1;
};
// Source of raw random bits (one seeded generator per purpose, owned by the
// caller). The plant turns bits into numbers with its own code.
class RandomBits {
 public:
  virtual ~RandomBits() = default;
  virtual std::uint64_t next() = 0;
};
// A uniform double in [0, 1) from the top 53 bits of a draw.
inline double unit53(std::uint64_t bits) { return static_cast<double>(bits >> 11) * 0x1.0p-53; }
// A uniform double in (0, 1] from the top 53 bits (safe for log).
inline double unit53Open0(std::uint64_t bits) {
  return static_cast<double>((bits >> 11) + 1) * 0x1.0p-53;
}

// SplitMix64, a small reference generator for tests and callers.
class SplitMix64 final : public RandomBits {
 public:
  explicit SplitMix64(std::uint64_t seed) : s_(seed) {}
  std::uint64_t next() override;
  // Same position in the same stream.
  bool operator==(const SplitMix64& other) const { return s_ == other.s_; }

 private:
  std::uint64_t s_;
};

// The eye model of DESIGN.md (thesis VII.C, Appendix C). `opponent` null:
// no beacon in the arena (background on both eyes).
// `channels` selects the eyes computed; the other one reads as the default
// 16 but its noise words are drawn all the same (optics.cpp).
enum class EyeChannels : std::uint8_t { Both, Left, Right };
// `scene` (robot selfRobot's view of the deployed items): the eyes read
// eyeSignalsAmong's signals instead; null, or no items: chapter VII's one
// beacon, as always.
EyeReadings computeEyes(const Pose& self, const Pose* opponent, const RobotParams& eyes,
                        const FieldParams& field, RandomBits* noise = nullptr,
                        EyeChannels channels = EyeChannels::Both, const EyeScene* scene = nullptr,
                        int selfRobot = 0);
// Unquantised signal S of the near eye and the far-eye fraction f; exposed
// for tests and the viewer. seen=false when out of view or blocked.
struct EyeGeometry {
  bool seen = false;
  double range_ft = 0;
  double gamma_deg = 0;  // bearing off the centre line, + = opponent to the right
  double near_signal = 0;
  double far_fraction = 0;
};
EyeGeometry eyeGeometry(const Pose& self, const Pose& opponent, const RobotParams& eyes,
                        const FieldParams& field);
// True if the segment between the two centres passes through the divider.
bool dividerBlocks(double ax, double ay, double bx, double by, const FieldParams& field);
// Gap between a round body (centre x, y; radius) and the divider, in ft;
// negative when they overlap.
double dividerClearance(double x, double y, double radius, const FieldParams& field);
// True if the segment between the two points passes through an obstacle
// taller than the field's beacon height (which hides the beacon).
bool obstacleBlocks(double ax, double ay, double bx, double by, const FieldParams& field);
// Gap between a round body and an obstacle's footprint, in ft; negative
// when they overlap.
double obstacleClearance(double x, double y, double radius, const Obstacle& obstacle);

// ---------------------------------------------------------------- events
enum class Detector : std::uint8_t { Fore = 0, Aft = 1 };
enum class Bumper : std::uint8_t { Front = 0, Back = 1 };
enum class ContactWith : std::uint8_t { None, Robot, Divider, Wall, Obstacle, Block };
// Why a ball or disc flight ended without a hit. LeftField: it reached a
// field wall; Stopped: a disc slowed below its stop speed; Obstacle: it met
// a fixed obstacle (the event's `obstacle`); Block: a block set down (the
// event's `obstacle` is the block's index on the field).
enum class MissReason : std::uint8_t { None, Floor, Divider, LeftField, Stopped, Obstacle, Block };

enum class EventKind : std::uint8_t {
  EdgeEnter,       // robot, detector: detector now reads low
  EdgeLeave,       // robot, detector: detector reads high again
  Contact,         // robot, bumper, with (other = the other robot, if Robot)
  ContactEnd,      // robot, with
  ReflexStart,     // robot, bumper
  ReflexEnd,       // robot, bumper
  BallLaunch,      // robot = shooter, gun, ball (slot); x, y, z, vx, vy, vz: the flight
  BallHit,         // robot = shooter, gun, ball, other = target; x, y, z: where
  BallMiss,        // robot = shooter, gun, ball, miss; x, y, z: where; closest_ft
  BallSkip,        // robot = shooter, gun, ball; x, y: on the floor, rolling on
  RefereePutBack,  // robot: centre left the field, put back inside the wire
  RefereeTurn,     // robot: too many reflexes/events, turned by turn_deg
  SolenoidStroke,  // (from setPortB) robot, gun: launch due after the stroke
  GunEmpty,        // (from setPortB) robot, gun: solenoid fired, magazine empty
  GunMisfire,      // (from setPortB) robot, gun: the stroke launched nothing
  GunJammed,       // (from setPortB) robot, gun: jammed now or before, launched nothing
  DiscShooter,     // (from setPortB) robot: disc shooter bit rose (logged only)
  // The disc launcher (Hardware::secondary); `ball` is the disc's number.
  DiscFire,   // (from setPortB) robot, ball; x, y, z, vx, vy: the flight's start
  DiscEmpty,  // (from setPortB) robot: the bit rose, the magazine is empty
  DiscHit,    // robot = shooter, ball, other = target; x, y, z: where
  DiscMiss,   // robot = shooter, ball, miss; x, y, z: where; closest_ft
  // (from setPortB) robot, gun = its deployables table: an item set down
  // (ball = its number in the table, from 1; x, y, heading_deg: where),
  // or the table was empty.
  Deploy,
  DeployEmpty,
  // (from setPortB) robot, gun = its table: a block that would not fit
  // where it would be set down (x, y: there) stays on the robot.
  DeployBlocked,
  // A robot starts or stops pushing a block (arena_blocks.cpp): robot,
  // ball = the block's index on the field (from 0, in release order);
  // x, y: the block's centre; at the end z = the distance pushed (ft) and
  // `with` (and `obstacle`, `other`) what stopped the block: None when the
  // robot stopped driving into it or slid off it, else a wall, the
  // divider, an obstacle, another block, or the other robot touching it.
  PushStart,
  PushEnd,
};
const char* eventKindName(EventKind k);

struct Event {
  EventKind kind{};
  std::int8_t robot = 0;
  std::int8_t other = -1;
  Detector detector = Detector::Fore;
  Bumper bumper = Bumper::Front;
  ContactWith with = ContactWith::None;
  MissReason miss = MissReason::None;
  std::int8_t gun = -1;
  std::int8_t ball = -1;  // a ball's slot, or a disc's (disc events)
  // With Obstacle, or a miss on one: its index in the field's list; with
  // Block: the block's index on the field (release order, from 0).
  std::int8_t obstacle = -1;
  // Balls: position (ft) at the event, and at a launch the velocity (ft/s):
  // the flight is x + vx s, y + vy s, z + vz s - g s^2 / 2 after the launch
  // tick; and the shooter's heading (deg) then, from which the ball's
  // azimuth dispersion turned it.
  // PushStart: x, y the block's centre, vx, vy the pusher's (ft).
  double x = 0, y = 0, z = 0, vx = 0, vy = 0, vz = 0;
  double heading_deg = 0;
  // A miss: the ball's closest distance to the other robot's body (ft), the
  // smaller of that when it passed abreast of the body's centre and at the
  // end of its flight; negative when there is no other robot.
  double closest_ft = -1;
};

// Fixed-capacity list: nothing allocated while advancing. Copies copy only
// the events it holds, and the storage is not value-initialised: only the
// first size() events are ever constructed or read (zeroing all 8 KB on
// every advance() was 5 % of a match's time, by perf).
class EventList {
 public:
  static constexpr std::size_t kCapacity = 128;
  EventList() = default;
  EventList(const EventList& o) : n_(o.n_) {
    std::uninitialized_copy(o.begin(), o.end(), s_.items);
  }
  EventList& operator=(const EventList& o) {
    if (this == &o) return *this;
    n_ = o.n_;
    std::uninitialized_copy(o.begin(), o.end(), s_.items);
    return *this;
  }
  // A full list is a bug in this capacity, never a reason to lose an event.
  void push(const Event& e) {
    if (n_ == kCapacity)
      throw std::length_error("plant: more than " + std::to_string(kCapacity) +
                              " events at one tick");
    std::construct_at(s_.items + n_++, e);
  }
  void clear() { n_ = 0; }
  std::size_t size() const { return n_; }
  bool empty() const { return n_ == 0; }
  const Event& operator[](std::size_t i) const { return s_.items[i]; }
  const Event* begin() const { return s_.items; }
  const Event* end() const { return s_.items + n_; }

 private:
  static_assert(std::is_trivially_copyable_v<Event> && std::is_trivially_destructible_v<Event>);
  union Storage {
    Storage() {}  // leaves the events unconstructed
    Event items[kCapacity];
  } s_;
  std::size_t n_ = 0;
};

struct AdvanceResult {
  std::int64_t tick = 0;  // tick reached
  EventList events;       // discrete plant events at that tick (may be empty)
};

struct IntegratorStats {
  long steps = 0;
  long rhs_evals = 0;
  long reinits = 0;
  long roots = 0;
};

// Continuous state of one robot at a tick (for tests, traces, the viewer).
struct RobotState {
  Pose pose;
  double left_fps = 0, right_fps = 0;  // wheel ground speeds
  double odometer_ft = 0;              // signed path length
  std::array<double, 2> gun_wheel{};   // fraction of full speed
};

struct BallView {
  int shooter = 0, gun = 0, slot = 0;
  double x_ft = 0, y_ft = 0, z_ft = 0;
};

// ---------------------------------------------------------------- arena
struct RobotSetup {
  RobotParams params;
  Hardware hardware;
  Pose start;
};
struct ArenaConfig {
  FieldParams field;
  RefereeParams referee;
  std::vector<RobotSetup> robots;  // 1 (solo: no beacon to see) or 2
};

// ---------------------------------------------------------------- seeded variation
// DESIGN.md: the default profile's robots differ from match to match. Every
// draw comes from the caller's generator for that purpose and robot (the
// scheduler derives one per (seed, purpose, robot)), so one purpose's draws
// never shift another's; a zero amount draws nothing and changes nothing.

// Robots put down by hand. For each robot in order (A, then B) draws three
// words per attempt from streams[i]: radius R sqrt(u1), direction 2 pi u2,
// heading offset H (2 u3 - 1) (R, H: the field's placement_radius_ft and
// placement_heading_deg). An attempt is kept if the body lies inside the
// field, clear of the divider, the obstacles and every robot placed
// before it;
// otherwise the robot draws again, at most kPlacementAttempts times, and
// after that stays exactly at its start pose. streams.size() must be
// config.robots.size().
inline constexpr int kPlacementAttempts = 16;
void placeByHand(ArenaConfig& config, const std::vector<RandomBits*>& streams);
// True if a robot of radius r centred at (x, y) lies inside the field and
// clear of the divider and every obstacle (the placement test above,
// without other robots).
bool placementFits(double x, double y, double r, const FieldParams& field);
// Per-match wheel trims: left then right, one word each, each trim times
// 1 + trim_spread (2 u - 1). No draw if trim_spread is 0.
void drawWheelTrims(RobotParams& params, RandomBits& bits);
// One launch's muzzle-speed factor, 1 + muzzle_speed_spread (2 u - 1) from
// one word; exactly 1 with no draw if the spread is 0 or bits is null.
double muzzleFactor(const RobotParams& params, RandomBits* bits);
// One launch's angular dispersion (deg): azimuth and elevation from one
// Box-Muller pair, two words (u1 in (0, 1], u2 in [0, 1)):
// r = sqrt(-2 ln u1), azimuth = azimuth_sigma_deg r cos(2 pi u2),
// elevation = elevation_sigma_deg r sin(2 pi u2): two independent normals.
// Exactly {0, 0} with no draw if both sigmas are 0 or bits is null.
struct Dispersion {
  double azimuth_deg = 0, elevation_deg = 0;
};
Dispersion drawDispersion(const RobotParams& params, RandomBits* bits);

// The arena integrates all robots and balls: closed forms and one ARKODE
// ERKStep instance.
//
// Protocol (all ticks): advance(stop) integrates from now() towards stop and
// returns at the first tick that has discrete events, or at stop. Those
// events are a prediction: they are applied when the scheduler proceeds
// (the next advance(), or a setWheels/setPortB at that same tick, which
// applies them first). A setWheels/setPortB at an earlier tick c (not before
// the last re-initialisation) that changes the plant discards the
// prediction and re-initialises at c from dense output. Queries take any
// tick from the last re-initialisation to now(); at a tick with events they
// describe the state after the events.
//
// Where advance() stops does not change the results: the integrator takes
// whole steps (the last may pass stop; the next advance() goes on from
// there), is stopped only at a scheduled ball launch, and a root found past
// stop is kept for the advance() whose stop reaches its tick. The same inputs
// at the same ticks give bit-identical states, events and statistics however
// the caller chops time into advance() calls.
class Arena {
 public:
  explicit Arena(const ArenaConfig& config);
  ~Arena();
  // The arena as a value (a snapshot of a match). SUNDIALS keeps its
  // integrator's state private, so a copy is a new arena of the same
  // configuration on which every call that changed this one is made again,
  // in order, with the random words it drew; an arena's state depends on
  // nothing else (arena.cpp, "Stepping"), so the copy goes on exactly as
  // this one would. It costs the replay: about the time the plant took so
  // far. Only an arena that keeps its journal, from before its first call,
  // can be copied (std::logic_error otherwise).
  void keepJournal();
  Arena(const Arena& other);
  // Where an arena that keeps its journal is now, without copying it: an
  // arena made from the mark is the arena as it was then (it replays the
  // calls before the mark; later calls to the marked arena leave the mark
  // as it was). A debugger's snapshots cost one mark each.
  struct Mark {
    std::shared_ptr<const arena_detail::Journal> journal;
    std::size_t calls = 0, draws = 0;
  };
  Mark mark() const;
  explicit Arena(const Mark& mark);
  Arena& operator=(const Arena& other);

  int robotCount() const;
  std::int64_t now() const;             // tick reached by the integrator
  std::int64_t lastReinitTick() const;  // earliest tick queries accept

  // A latched motor frame. Returns false (and does nothing, no reinit) if it
  // equals the frame already latched.
  bool setWheels(int robot, const MotorFrame& frame, std::int64_t tick);
  // A scripted drive (a beacon on a path, no program): the wheels' target
  // ground speeds in ft/s, bypassing the speed table and trims. From then on
  // motor frames no longer move this robot; the bumper reflex still does.
  // Returns false (no reinit) if the drive is already these speeds.
  bool setDrive(int robot, double leftFps, double rightFps, std::int64_t tick);
  // The robot's battery (battery.h): from `tick` its wheel and gun-wheel
  // targets are the speed table's times `scale` (terminal over nominal
  // voltage, > 0). Returns false (no reinit) if the scale is already this.
  bool setSupply(int robot, double scale, std::int64_t tick);
  double supply(int robot) const;  // the scale now in force (1 without a battery)
  // A write to PIO port B. Returns the immediate events (solenoid strokes,
  // empty guns, misfires and jams, disc shooter; a disc launcher's disc
  // leaves at the write's tick, with its strike there if it touches
  // something at once); launches and strikes come later from advance(). `gunLuck` draws a stroke's
  // jam or misfire (one draw per stroke that would launch, only if the robot's probabilities are
  // not both 0); null: guns never jam or misfire. `muzzle` draws each launching stroke's
  // muzzleFactor (null: factor 1), `dispersion` its drawDispersion (null: along the heading,
  // horizontal).
  EventList setPortB(int robot, std::uint8_t value, std::int64_t tick,
                     RandomBits* gunLuck = nullptr, RandomBits* muzzle = nullptr,
                     RandomBits* dispersion = nullptr);

  // The motor controller's bumper reflex, as if that bumper switch closed
  // at `tick` (an injected bump). A reflex under way starts over. Returns
  // the ReflexStart event.
  EventList triggerReflex(int robot, Bumper side, std::int64_t tick);

  AdvanceResult advance(std::int64_t stopTick);
  // The caller stops at `tick` (in [lastReinitTick(), now()]) after all:
  // now() becomes `tick`, the events the last advance() returned at a later
  // tick are dropped, and the advance() whose stop reaches their tick
  // reports them again, as if the last advance() had been given `tick` as
  // its stop. The integrator's steps stay (as after an advance() whose last
  // step overshot its stop).
  void retreat(std::int64_t tick);
  // A ball or disc is in flight or a launch is scheduled (at now(), after
  // any pending events).
  bool ballsInFlight() const;

  Pose pose(int robot, std::int64_t tick) const;
  RobotState state(int robot, std::int64_t tick) const;
  bool edgeDetectorLow(int robot, Detector d, std::int64_t tick) const;
  EyeReadings eyeReadings(int robot, std::int64_t tick, RandomBits* noise = nullptr,
                          EyeChannels channels = EyeChannels::Both) const;
  std::vector<BallView> balls(std::int64_t tick) const;

  bool inReflex(int robot) const;  // at now(), after any pending events
  int ballsLeft(int robot, int gun) const;
  int shots(int robot) const;
  int hits(int robot) const;
  // The disc launcher's discs sent, hits and discs left (0 without one);
  // its hits are not in hits().
  int discShots(int robot) const;
  int discHits(int robot) const;
  // Every item set down so far (deployables), in tick order, where it was
  // set down (a block pushed since is elsewhere: blockCentre).
  const std::vector<Deployed>& deployed() const;
  // Block k's centre (k: its index on the field, release order) at `tick`.
  Pose blockCentre(int k, std::int64_t tick) const;
  // The distance robot `robot` has pushed blocks so far, ft.
  double blockPushedFt(int robot) const;
  int discsLeft(int robot) const;
  IntegratorStats stats() const;

  // The program's PIO (edge) interrupt handler was entered at `tick` (the
  // scheduler: a PIO interrupt accepted). The referee counts these with the
  // bumper reflexes (thesis VI.D: robots stuck in the edge routine); a wire
  // crossing of a robot whose PIO is not armed counts for nothing. Returns
  // the RefereeTurn event if this entry makes the referee turn the robot.
  EventList edgeHandlerEntered(int robot, std::int64_t tick);

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace simbot::plant
