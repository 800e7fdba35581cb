// One match: the round loop described in match.h, the robots' VMs and the
// trace. The robots' buses (ports, A/D, serial library hooks, interrupt
// notifications) are in robot_bus.cpp, the plant events' records in
// plant_records.cpp, the result in match_result.cpp; the classes in
// match_impl.h.
//
// Larger rounds. A round is a run of sub-rounds, each exactly one round of
// the one-character protocol of match.h: every VM runs to h_k = min(next
// queued event, a_k + 9,600, the plant's next event), a_k the earliest tick
// at which a VM can act (Vm::quietUntil, at least the earliest VM clock
// t_k). What a round saves is the plant's round trip: the plant is
// advanced once, to P = min(next queued event that is not a serial byte,
// the finish of a NUL already in a serial port, t + 8 x 9,600) (only to
// the first sub-round's horizon while a ball is in flight or a launch is
// scheduled), and a sub-round ends the round when
//   (a) its VMs made a plant input (port B write, injected bump, edge
//       handler entry): inputs are applied at the end of the sub-round, as
//       at the end of a one-character round;
//   (b) a queued event is due at its horizon, or the plant's event is (h_k
//       is the plant's stop P or its event tick), but see (d);
//   (c) (solo runs) every robot has exited or faulted;
//   (d) serial bytes due at h_k (and nothing else) are taken between the
//       sub-rounds, as at the end of a round, and the round goes on unless
//       a byte latched a frame with new wheel speeds (that re-initialises
//       the plant at h_k, as an input would).
// Claim: a run gives the same VM instructions, bus accesses, events and
// trace records, at the same ticks, as with one plant advance per round.
// Proof, by the sub-rounds of one round, which have no (a) or (b) before
// the last: (1) the horizons are the same: h_k uses the same queue and VM
// clocks, and the plant's event tick is the same because advance() is
// independent of how time is chopped (plant.h: the same steps, roots and
// held roots whatever the stops), so the first root at or before P is the
// one the per-sub-round advances would have reported, at the same tick,
// and none lies before it. (2) What a VM sees is the same: eye readings
// come from dense output at their tick, which the chopping does not change
// either, and port A and the interrupt requests change only at events (at
// horizons, none inside). (3) Nothing a sub-round could do between rounds
// is skipped: with no input, no queued event due and no plant event, the
// end of a one-character round only takes samples up to h_k, done here
// before the next sub-round so that records keep their order. (4) When a
// round ends at h_k < P (by (a) or (c), or a new queued event earlier than
// P), Arena::retreat(h_k) puts the plant where advance(h_k) would have: its
// clock at h_k, a predicted event past h_k held for the advance() that
// reaches its tick; inputs then re-initialise at their ticks <= h_k as
// before. The only difference is work: steps taken past an input's tick
// are thrown away at the re-initialisation, so IntegratorStats' steps and
// rhs_evals can be higher (by at most the steps of 8 characters per
// input), and roots (ARKODE's root returns) too, a root found in those
// steps being found again; no state, event or record depends on them. A ball in flight
// keeps the plant to one sub-round because a root with no event (a ball's
// closest approach) updates the ball's closest distance when the plant
// reaches it, and one past an input's tick would not be found on the
// re-initialised trajectory.
// (5) Rule (d): a byte done only changes its robot's link, port and
// interrupt request (no VM runs, so nothing else sees it before h_k) and,
// when it completes a frame, the latched command. A latch that keeps the
// wheel speeds changes neither the state nor the right-hand side, so the
// prediction holds (Arena::setWheels keeps it, as it does between rounds);
// one that changes them re-initialises the plant at h_k, leaving it where
// retreat(h_k) and the same input would have, and the round ends there
// (only a NUL latches; P stops at one already in a port because the steps
// past it would mostly be thrown away, which cost what the rounds save). The
// byte's records and samples come in the order the end of a round gives
// them (samples up to h_k, then the byte), and before the next sub-round
// the horizon is min(queue, earliest VM clock + 9,600, plant event), which
// is what the next round would have computed, by (1), except that the
// plant's stop is still this round's P: a sub-round may end at P where the
// next round would have gone on. A VM's run does not depend on where its
// time is cut when nothing reaches it in between (runTo already cuts it at
// every trace snapshot, and JSON with and without --trace is the same), so
// only the split of instructions between fast-forwarded and dispatched can
// differ.
// (6) A robot quiet past a sub-round's horizon (Vm::quietUntil: inside a
// measured delay loop, no bus access, acceptance or PRT0 tick before its
// arrival where the compare fails), and past the most a run overshoots
// its horizon (vm::kMaxRunOvershoot: PRT0's tick, not an instruction
// boundary, could otherwise fall inside the run's last instruction and
// be requested at its end), sits the sub-round out when no trace
// or debugger looks at it between sub-rounds: its run to the horizon
// would make no record, no bus access and no input, and nothing between
// the sub-rounds reads it but its own serial byte, before which it runs
// to the horizon (all of them do before a NUL, which may latch a frame).
// It runs at the next sub-round it is not quiet past, or at the round's
// end, where every robot is at the horizon before anything else: one run
// where there were several, the same instructions by (5). Its
// quietUntil, and so every later horizon, is the same as if it had run:
// fast-forward moves the measured pass's start and counter together, and
// the arrival they give stays where it was. A trace and --no-fast-forward
// (quietUntil is then the clock) never sit out, and the JSON must be
// theirs (tests/fast_forward_test.py).
// (7) Chained sub-rounds. While one robot runs alone (every other has
// faulted, is held in reset or sits the sub-round out by (6)) with no
// trace, observer or debugger, its VM takes the next sub-round's horizon
// as it reaches one (vm::Continuation, SubRoundChain) instead of
// returning to this loop and being run again: 548,000 VM entries become
// 68,500 in bench/programs/histogram.dc. It does so only where the loop
// would do nothing but take that horizon (and the robot's own bytes, (9)):
// no input made, no other queued event and not the plant's stop at the
// horizon, not every robot exited, the robot not sitting the next
// sub-round out and every other running robot sitting it out; the
// horizon is the loop's own (noteQuiet, subRoundHorizon, capped by the
// plant's stop). A robot that sits out keeps its quiet tick (it does not
// run), so the loop's test for it at the next horizon is the one made
// here. Samples are taken only with a trace or an observer, and the
// robots not running do nothing when run. So the same horizons are taken
// in the same order, the VM's run goes on from its boundary as a new
// run() would (vm.h), and every record is the same.
// The VM takes the next horizon itself (vm::Continuation::cap, step)
// where asking would give the same: it has called nothing here since the
// last answer, in the same run() (runTo acts between runs, at a line
// injection or main's return), so the queue, the inputs, the exits and
// every other robot's quiet_ are as they were (nothing else runs); it is
// before min(queue, the plant's stop), so none of the conditions above
// ends the chain; it is not quiet past its clock, so it cannot sit the
// next sub-round out, and the horizon is min(that cap, the others'
// earliest action + one character, its clock + one character); and that
// horizon lies at least an overshoot before the quiet tick of every other
// running robot (Continuation::unaskedUpTo), so they sit it out.
// (8) In a solo run a round lets the plant run further ahead
// (kSoloRoundLookahead): by (1) the plant's steps, roots and events do not
// depend on where its time is cut, and the sub-rounds' horizons are the
// ones the shorter rounds gave, as nothing happened at the ends of those
// rounds but taking the next horizon. Only the integration thrown away at
// an input can be longer (by (4); not in a match, where a robot that
// faults leaves the other alone: the JSON's integrator steps grew; solo,
// every program's JSON is the same, measured: docs/benchmarks.md), and a
// plant fault ends the run where its round began, up to 64 characters
// earlier.
// (9) A chained robot takes its own serial bytes due at a horizon
// (ownByteAt) as rule (d) takes them between sub-rounds, when each is the
// first event due there and no NUL: such a byte changes only its own
// robot's link, port and interrupt request (a NUL may latch a frame, and
// every robot runs to the horizon before it), the other robots sit the
// sub-round out and read nothing of it, and nothing else runs in between
// (samples need a trace or an observer). Anything else due there ends the
// chain, after the bytes taken: the loop then finds the rest as rule (d)
// would have after them, in the queue's order. So a robot that sends
// while the other waits in a delay loop, or alone, no longer returns to
// this loop at every byte it sends (docs/benchmarks.md, issue 42's sixth
// part: the 180-s match's VM runs, measured).
// (10) Two running robots both stop at every horizon: between them the
// lookahead (in the sense of conservative parallel simulation,
// Chandy-Misra-Bryant) is zero. Rules (6), (7) and (9) are each robot's
// lookahead where it has one: a robot quiet past a horizon makes nothing
// the other sees before its quiet tick, and a robot alone runs on through
// horizons and its own bytes. A running robot's next instruction, though,
// may be an input, which reaches the plant at its tick: a port B write
// that moves anything (a gun motor, a solenoid's stroke, a disc, a block:
// Arena::setPortB) re-initialises the one integration every robot shares,
// so every later pose comes from other steps, the other robot's too, by
// last bits (tests/plant/coupling_test.cpp); a decoy set down shines at
// once (tests/chain_test.py); an edge handler's entry or an injected bump
// may re-initialise it too, or bring the referee's turn of the robot. The
// other robot sees each from the end of the sub-round, (a). So each eye
// read after a horizon depends on what the other robot did up to it, and
// neither may pass a horizon before the other has reached it: any byte of
// either, even a non-NUL one that (9) takes inside a chain, ends both runs
// there. What that leaves to gain is measured in docs/benchmarks.md
// (issue 42's eighth part).
#include "scheduler/match.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <deque>
#include <stdexcept>

#include "scheduler/match_impl.h"

namespace simbot::scheduler {

namespace detail {

// A robot on a scripted path follows it exactly: its wheels have no lag.
// The arena this match plays in: the configured one with this seed's
// variation (DESIGN.md), each purpose drawn from its own stream of (seed,
// purpose, robot): the hand placement, then each robot's wheel trims.
plant::ArenaConfig arenaConfigFor(const MatchConfig& config) {
  plant::ArenaConfig arena = config.arena;
  for (size_t i = 0; i < config.robots.size() && i < arena.robots.size(); ++i)
    if (!config.robots[i].path.empty()) arena.robots[i].params.motor_lag_s = 0;
  std::vector<plant::SplitMix64> placement;
  for (size_t i = 0; i < arena.robots.size() && i < config.robots.size(); ++i) {
    placement.emplace_back(streamSeed(config.seed, "placement-" + config.robots[i].name));
    plant::SplitMix64 trim(streamSeed(config.seed, "wheel-trim-" + config.robots[i].name));
    plant::drawWheelTrims(arena.robots[i].params, trim);
  }
  std::vector<plant::RandomBits*> streams;
  for (plant::SplitMix64& s : placement) streams.push_back(&s);
  if (streams.size() == arena.robots.size()) plant::placeByHand(arena, streams);
  return arena;
}

// ---- match ------------------------------------------------------------------

MatchState::MatchState(const MatchConfig& config)
    : config_(config),
      arenaConfig_(std::make_shared<const plant::ArenaConfig>(arenaConfigFor(config))),
      coin_(streamSeed(config.seed, "coin")),
      fired_(config.injections.size()),
      injectionAddress_(config.injections.size()),
      clock_(config.timeParts) {}

Match::Match(const MatchConfig& config) : MatchState(config), arena_(*arenaConfig_) {
  if (config.snapshots) arena_.keepJournal();
  for (trace::Sink* sink : config.sinks) trace_.attach(sink);
  if (config.robots.empty() || config.robots.size() > 2)
    throw std::invalid_argument("a match needs one or two robots");
  const vm::CostTable costs = vm::makeCostTable(config.knobs);
  for (size_t i = 0; i < config.robots.size(); ++i)
    robots_.emplace_back(
        std::make_unique<Robot>(*this, static_cast<int>(i), config.robots[i], costs, config.seed));
  if (config.reloadOnFault && config.reloadDelay < kMinReloadDelay)
    throw std::invalid_argument(
        fmt::format("a reload must wait at least {} ticks (the serial port's two characters)",
                    kMinReloadDelay));
  resolveWatches();
  link();
  queue_.schedule(config.endTick, EventClass::EndOfRound, {QueuedEvent::Kind::EndOfRound, 0, 0});
  for (size_t i = 0; i < config.robots.size(); ++i) {
    for (const DriveLeg& leg : config.robots[i].path)
      if (leg.duration <= 0) throw std::invalid_argument("a path leg must last at least a tick");
    if (!config.robots[i].path.empty())
      queue_.schedule(0, EventClass::MotorLatch,
                      {QueuedEvent::Kind::DriveLeg, static_cast<int>(i), 0});
  }
  // Batteries (power.cpp): a robot with a program whose profile has one
  // draws its board's current from tick 0.
  for (auto& r : robots_) {
    const plant::BatteryParams& b =
        arenaConfig_->robots[static_cast<size_t>(r->index)].params.battery;
    if (!b.enabled || !r->spec.path.empty()) continue;
    r->battery.emplace(b);
    powerChanged(r->index, 0);
  }
  for (size_t k = 0; k < config.injections.size(); ++k) {
    const Injection& in = config.injections[k];
    if (in.robot < 0 || in.robot >= static_cast<int>(robots_.size()))
      throw std::invalid_argument("injection for a robot that is not in this run: " + in.text);
    Robot& r = *robots_[static_cast<size_t>(in.robot)];
    if (in.line > 0) {
      const auto& lines = r.spec.image.lines;
      const auto at = std::find(lines.begin(), lines.end(), in.line);
      if (at == lines.end())
        throw std::invalid_argument(
            fmt::format("{}: line {} of {} has no code", in.text, in.line, r.spec.program));
      const std::optional<uint32_t> head = r.spec.image.loopHead(in.line);
      if (in.pass && !head)
        throw std::invalid_argument(fmt::format(
            "{}: line {} of {} holds no whole loop (pass:N#K counts the passes of a loop "
            "written on one line; line:N#K counts entries into a line)",
            in.text, in.line, r.spec.program));
      if (!in.pass && head)
        warnings_.push_back(fmt::format(
            "--inject {}: line {} of {} holds a whole loop; line:N#K counts entries into "
            "the line (runs of its first instruction, once before each run of the loop), "
            "not passes of the loop; for pass {} of the loop write pass:{}#{}",
            in.text, in.line, r.spec.program, in.count, in.line, in.count));
      const auto address = in.pass ? *head : static_cast<uint32_t>(at - lines.begin());
      r.lineInjections[address].push_back(static_cast<int>(k));
      injectionAddress_[k] = address;
      r.vm().setBreakpoint(address);
    } else {
      queue_.schedule(in.tick, EventClass::Injection,
                      {QueuedEvent::Kind::Inject, in.robot, static_cast<int>(k)});
    }
  }
}

Match::Match(const Match& other) : MatchView(), MatchState(other), arena_(other.arena_) { link(); }

Match::Match(const MatchState& state, const plant::Arena::Mark& mark)
    : MatchView(), MatchState(state), arena_(mark) {
  link();
}

void Match::link() {
  for (auto& r : robots_) r->attach(*this);
  orderRobots();
}

void Match::orderRobots() {
  quiet_.assign(robots_.size(), INT64_MIN);
  runOrder_.clear();
  if (config_.debugger)
    runOrder_.push_back(robots_.at(static_cast<size_t>(config_.debugRobot)).get());
  for (const auto& r : robots_)
    if (!config_.debugger || r->index != config_.debugRobot) runOrder_.push_back(r.get());
}

void Match::bringOthersTo(int robot, Tick t) {
  for (const auto& r : robots_)
    if (r->index != robot && r->running() && r->now() < t) r->runTo(t);
}

plant::Pose Match::pose(int robot, Tick t) const {
  return arena_.pose(robot, std::clamp(t, arena_.lastReinitTick(), arena_.now()));
}

Tick MatchState::earliestClock() const {
  Tick t = INT64_MAX;
  for (const auto& r : robots_)
    if (r->running()) t = std::min(t, r->now());
  return t == INT64_MAX ? queue_.nextTick() : t;
}

void Match::noteQuiet() {
  // A robot still behind has not run, nor taken a byte, since its value
  // was noted (nothing else reaches a VM inside a round): it is the same.
  for (const auto& r : robots_)
    if (!r->behind)
      quiet_[static_cast<size_t>(r->index)] = r->running() ? r->quietUntil() : INT64_MIN;
}

Tick Match::earliestAction() const {
  Tick t = INT64_MAX;
  for (const Tick q : quiet_)
    if (q != INT64_MIN) t = std::min(t, q);
  return t == INT64_MAX ? queue_.nextTick() : t;
}

// --watch EXPR: a global, a static local as FUNCTION.VAR (both read
// directly), or any lvalue the debugger's print takes (inspect.h: autos in
// scope, members, elements, slices, through pointers), of every robot whose
// program has the names it uses. The value is read from the robot's memory
// when the record is made (for samples: at the robot's first boundary at
// or after the sample tick).
void Match::resolveWatches() {
  for (const auto& name : config_.watches) {
    bool found = false;
    for (auto& r : robots_) {
      for (const auto& s : r->spec.image.symbols) {
        if (s.name != name ||
            (s.kind != vm::Symbol::Kind::Global && s.kind != vm::Symbol::Kind::Static &&
             s.kind != vm::Symbol::Kind::Param) ||
            s.value == vm::Symbol::Value::Aggregate || s.value == vm::Symbol::Value::Code)
          continue;
        r->watches.push_back({name, static_cast<uint16_t>(s.address), s.value, nullptr});
        found = true;
      }
    }
    if (found) continue;
    std::shared_ptr<const inspect::Expression> expression;
    try {
      expression = std::make_shared<const inspect::Expression>(name);
    } catch (const inspect::Error& e) {
      throw std::invalid_argument("--watch " + name + ": " + e.what());
    }
    for (auto& r : robots_) {
      if (!inspect::namesExist(r->spec.image, *expression)) continue;
      // One that can never be evaluated (1/0) is refused, not recorded as null.
      try {
        inspect::check(r->spec.image, *expression);
      } catch (const inspect::Error& e) {
        throw std::invalid_argument("--watch " + name + ": " + e.what());
      }
      r->watches.push_back({name, 0, vm::Symbol::Value::Aggregate, expression});
      found = true;
    }
    if (!found)
      throw std::invalid_argument("--watch " + name +
                                  ": a name in it is no variable of any robot's program (a "
                                  "static or auto of a function is NAME or FUNCTION::NAME)");
  }
}

void Match::emit(Tick t, trace::Record record) {
  const int robot = trace::robotOf(record);
  trace::Watch watch;
  if (robot >= 0 && robot < static_cast<int>(robots_.size()))
    watch = robots_[static_cast<size_t>(robot)]->tracedWatch(t);
  trace_.emit(t, std::move(record), std::move(watch));
}

void Match::applyReflex(Tick t, int robot, plant::Bumper side, const trace::Watch* watch) {
  sampleUpTo(t);
  const plant::EventList events = [&] {
    const PartScope plant(clock_, PartClock::Plant);
    return arena_.triggerReflex(robot, side, t);
  }();
  handlePlantEvents(t, events, watch, robot);
}

// Leg `leg` of a robot's scripted path starts at t; leg == path size is
// the stop after the last leg.
void Match::startLeg(Tick t, int robot, int leg) {
  const RobotSpec& spec = config_.robots[static_cast<size_t>(robot)];
  const auto& path = spec.path;
  if (leg == static_cast<int>(path.size()) && spec.repeatPath) leg = 0;
  const bool stop = leg == static_cast<int>(path.size());
  const DriveLeg drive = stop ? DriveLeg{} : path[static_cast<size_t>(leg)];
  sampleUpTo(t);
  {
    const PartScope plant(clock_, PartClock::Plant);
    arena_.setDrive(robot, drive.leftFps, drive.rightFps, t);
  }
  if (trace_.on())
    emit(t, trace::rec::PathLeg{robot, stop ? std::nullopt : std::optional<int64_t>(leg),
                                drive.leftFps, drive.rightFps});
  if (!stop)
    queue_.schedule(t + drive.duration, EventClass::MotorLatch,
                    {QueuedEvent::Kind::DriveLeg, robot, leg + 1});
}

// Integrates the plant from its clock up to t (after an input re-initialised
// it earlier), handling the plant events before t at their ticks. Returns
// true if it advanced; then `step` is the last advance, and its events at
// t are the caller's.
bool Match::advancePlantTo(Tick t, plant::AdvanceResult& step) {
  if (arena_.now() >= t) return false;
  while (arena_.now() < t) {
    {
      const PartScope plant(clock_, PartClock::Plant);
      step = arena_.advance(t);
    }
    if (step.tick < t) {
      sampleUpTo(step.tick);
      handlePlantEvents(step.tick, step.events);
    }
  }
  return true;
}

void Match::applyInputs() {
  // Stable by tick, in place: std::stable_sort would allocate a buffer every
  // round with inputs; a round has a handful, mostly in order already.
  // A debugger holding robot B runs B first in each round: ties in tick
  // go by robot, so that the robots' inputs reach the plant in the order
  // the usual run order (A, then B) gives them.
  const bool byRobot = config_.debugger && config_.debugRobot != 0;
  for (auto it = inputs_.begin(); it != inputs_.end(); ++it)
    std::rotate(std::upper_bound(inputs_.begin(), it, *it,
                                 [byRobot](const PlantInput& a, const PlantInput& b) {
                                   return a.tick < b.tick ||
                                          (byRobot && a.tick == b.tick && a.robot < b.robot);
                                 }),
                it, it + 1);
  for (const auto& w : inputs_) {
    // An earlier input of this round may have re-initialised the plant at
    // its tick: integrate up to this one. Plant events at this tick come
    // before the input, as plant events do.
    plant::AdvanceResult step;
    if (advancePlantTo(w.tick, step)) {
      sampleUpTo(w.tick);
      handlePlantEvents(w.tick, step.events);
    }
    const trace::Watch* watch = w.watch.empty() ? nullptr : &w.watch;
    if (w.kind == PlantInput::Kind::Reflex) {
      applyReflex(w.tick, w.robot, w.bumper, watch);
      continue;
    }
    if (w.kind == PlantInput::Kind::EdgeHandler) {
      sampleUpTo(w.tick);
      const plant::EventList events = [&] {
        const PartScope plant(clock_, PartClock::Plant);
        return arena_.edgeHandlerEntered(w.robot, w.tick);
      }();
      handlePlantEvents(w.tick, events, watch, w.robot);
      continue;
    }
    sampleUpTo(w.tick);
    const plant::EventList immediate = [&] {
      const PartScope plant(clock_, PartClock::Plant);
      board::Board& b = robots_[static_cast<size_t>(w.robot)]->board;
      return arena_.setPortB(w.robot, w.value, w.tick, &b.gunLuck, &b.muzzle, &b.dispersion);
    }();
    for (const auto& e : immediate) {
      if (config_.observer) config_.observer->onPlantEvent(w.tick, e);
      emitPlant(w.tick, e, watch, w.robot);
    }
    Robot& r = *robots_[static_cast<size_t>(w.robot)];
    r.portB = w.value;
    if (r.battery) powerChanged(w.robot, w.tick);
  }
  inputs_.clear();
}

void Match::handlePlantEvents(Tick t, const plant::EventList& events, const trace::Watch* watch,
                              int watchRobot) {
  for (const auto& e : events) {
    if (config_.observer) config_.observer->onPlantEvent(t, e);
    if (e.kind == plant::EventKind::EdgeEnter || e.kind == plant::EventKind::EdgeLeave) {
      Robot& r = *robots_[static_cast<size_t>(e.robot)];
      // Fore detector on port A bit 1, aft on bit 0; low within range.
      const uint8_t bit = e.detector == plant::Detector::Fore ? 0x02 : 0x01;
      if (e.kind == plant::EventKind::EdgeEnter)
        r.board.plantLow |= bit;
      else
        r.board.plantLow &= static_cast<uint8_t>(~bit);
      // The plant's record first, then the port's (in emission order).
      emitPlant(t, e, watch, watchRobot);
      r.updateEdgeLines(t);
      continue;
    }
    emitPlant(t, e, watch, watchRobot);
    if (arenaConfig_->referee.judge_scatter) judgeLaunch(t, e);
    if (e.kind == plant::EventKind::ReflexStart || e.kind == plant::EventKind::ReflexEnd) {
      Robot& r = *robots_[static_cast<size_t>(e.robot)];
      r.reflexOn = e.kind == plant::EventKind::ReflexStart;
      if (r.battery) powerChanged(e.robot, t);
    }
    if (config_.debugger &&
        (e.kind == plant::EventKind::Contact || e.kind == plant::EventKind::BallLaunch))
      robots_[static_cast<size_t>(e.robot)]->debugEvent(
          t, e.kind == plant::EventKind::Contact ? DebugEvent::Contact : DebugEvent::Shot);
  }
}

// DESIGN.md "The wider competition": the referee's Detect to Engage. The
// eyes are judged at the launch tick (the shot the referee sees leave the
// muzzle; a stroke that launches nothing is no shot) by the optics model
// without noise: where the robot points, not what its program last read
// (docs/rules.md).
void Match::judgeLaunch(Tick t, const plant::Event& e) {
  if (e.kind != plant::EventKind::BallLaunch && e.kind != plant::EventKind::BallHit) return;
  if (e.ball < 0 || static_cast<size_t>(e.ball) >= kBallSlots || e.robot < 0 || e.robot > 1)
    throw std::logic_error("a ball slot or shooter out of range");
  const size_t slot = static_cast<size_t>(e.ball), r = static_cast<size_t>(e.robot);
  const plant::RefereeParams& referee = arenaConfig_->referee;
  if (e.kind == plant::EventKind::BallHit) {
    if (scatterBall_[slot] && !referee.scatter_scores) ++unscoredHits_[r];
    return;
  }
  const plant::EyeReadings eyes = [&] {
    const PartScope plant(clock_, PartClock::Plant);
    return arena_.eyeReadings(e.robot, t);
  }();
  const double threshold = referee.detect_threshold;
  const bool scatter = !(eyes.left > threshold || eyes.right > threshold);
  scatterBall_[slot] = scatter;
  if (!scatter) return;
  ++scatterShots_[r];
  if (trace_.on())
    emit(t,
         trace::rec::ScatterShot{e.robot, e.gun, e.ball, eyes.left, eyes.right, threshold,
                                 referee.scatter_scores},
         {});
}

// Trace samples at fixed ticks, read from dense output once the plant has
// passed them and before any input discards that part of the trajectory.
// An observer gets the same poses (MatchObserver::onPose).
void Match::sampleUpTo(Tick t) {
  const bool tracing = trace_.on();
  if (!tracing && !config_.observer) return;
  const Tick limit = std::min(t, arena_.now());
  while (nextSample_ <= limit) {
    if (nextSample_ >= arena_.lastReinitTick()) {
      for (int i = 0; i < arena_.robotCount(); ++i) {
        const plant::RobotState s = arena_.state(i, nextSample_);
        if (config_.observer) config_.observer->onPose(i, nextSample_, s.pose.x_ft, s.pose.y_ft);
        if (!tracing) continue;
        const plant::EyeReadings eyes = arena_.eyeReadings(i, nextSample_);
        Robot::Snapshot at = robots_[static_cast<size_t>(i)]->snapshotFor(nextSample_);
        emit(nextSample_,
             trace::rec::Sample{i, s.pose.x_ft, s.pose.y_ft, s.pose.heading_deg, s.left_fps,
                                s.right_fps, eyes.left, eyes.right, at.line,
                                at.function ? at.function->name : "", at.inHandler},
             std::move(at.watch));
      }
    }
    nextSample_ += config_.sampleInterval;
  }
}

MatchResult Match::run() {
  runUntil(kNoPause);
  return end();
}

bool Match::runUntil(Tick pause) {
  if (!begun_) {
    begun_ = true;
    if (trace_.on()) emitSetup();
  }
  if (over_) return false;
  clock_.start();
  try {
    rounds(pause);
  } catch (const plant::SolverError& e) {
    // The plant cannot go on: the run ends where the failing round began,
    // with everything before it kept.
    result_.plantFault = FaultInfo{e.what(), timebase::secondsFromTicks(roundStart_), 0, 0, {}};
    result_.endTick = roundStart_;
    over_ = true;
    if (trace_.on()) emit(roundStart_, trace::rec::PlantFault{e.what()}, {});
  }
  clock_.stop();
  return !over_;
}

MatchResult Match::end() {
  runUntil(kNoPause);
  MatchResult result = std::move(result_);
  result.parts = clock_.times();
  finish(result);
  return result;
}

void Match::rounds(Tick pause) {
  bool& over = over_;
  MatchResult& result = result_;
  while (!over) {
    const Tick t = earliestClock();
    if (t >= pause) return;  // paused between rounds
    ++rounds_;
    if (config_.stop && config_.stop->load(std::memory_order_relaxed)) throw Stopped();
    roundStart_ = t;
    if (trace_.on()) trace_.flushBefore(std::min(t, arena_.now()));
    noteQuiet();
    Tick horizon = subRoundHorizon();
    // The plant goes further than the first sub-round when no ball is in
    // flight, past serial bytes (header comment: "Larger rounds", (d)).
    Tick plantStop = horizon;
    if (!arena_.ballsInFlight()) {
      const Tick lookahead = robots_.size() == 1 ? kSoloRoundLookahead : kRoundLookahead;
      plantStop = queue_.nextTickExcept(EventClass::SerialByte, t + lookahead);
      // Not past a NUL that may latch new wheel speeds: the steps beyond it
      // would be thrown away (measured: they cost what the rounds save).
      for (const auto& r : robots_)
        if (const auto nul = r->board.serial.nulDone()) plantStop = std::min(plantStop, *nul);
    }
    // (Lambdas, here and below, so that the results are built in place.)
    plant::AdvanceResult step = [&] {
      const PartScope plant(clock_, PartClock::Plant);
      return arena_.advance(plantStop);
    }();
    for (;;) {
      horizon = std::min(horizon, step.tick);
      {
        const PartScope vms(clock_, PartClock::Vm);
        Robot* const alone = runsAlone(horizon);
        for (Robot* r : runOrder_) {
          if (sitsOut(*r, horizon)) {
            r->behind = true;
          } else if (r == alone) {
            r->behind = false;
            SubRoundChain chain{*this, *r, horizon, step.tick};
            r->runTo(horizon, &chain);
            subRounds_ += chain.taken;
          } else {
            r->behind = false;
            r->runTo(horizon);
          }
        }
      }
      if (horizon == step.tick || !inputs_.empty() || (config_.stopWhenAllExited && allExited()))
        break;
      sampleUpTo(horizon);  // before the next sub-round's records, as between rounds
      if (queue_.nextTick() == horizon && !serialBytesInRound(horizon)) break;
      ++subRounds_;
      noteQuiet();
      horizon = subRoundHorizon();
    }
    for (Robot* r : runOrder_) catchUp(*r, horizon);
    if (config_.stopWhenAllExited && allExited()) {
      // The run ends where the last robot stopped, not at the round's
      // horizon: where that falls depends on how long the rounds were
      // (fast-forward makes longer ones), and the run must not.
      Tick stopped = roundStart_;
      for (const auto& r : robots_)
        stopped = std::max(stopped, r->vm().fault() ? r->vm().fault()->tick : r->result.exitTick);
      horizon = std::min(horizon, stopped);
    }
    if (horizon < step.tick) {
      // The round ends before the plant's stop: it goes back to the horizon
      // (a prediction is kept for later), as if it had stopped there.
      const PartScope plant(clock_, PartClock::Plant);
      arena_.retreat(horizon);
      step.tick = horizon;
      step.events.clear();
    }
    if (!inputs_.empty()) {
      inputsHorizon_ = horizon;
      applyInputs();
      inputsHorizon_ = -1;
      // A re-initialisation discarded the plant's prediction: find it again.
      advancePlantTo(horizon, step);
    }
    sampleUpTo(horizon);
    betweenRounds_ = true;  // every VM is at the horizon
    handlePlantEvents(horizon, step.events);
    while (!queue_.empty() && queue_.nextTick() == horizon) {
      const auto entry = queue_.pop();
      switch (entry.payload.kind) {
        case QueuedEvent::Kind::SerialByte:
          sampleUpTo(horizon);
          robots_[static_cast<size_t>(entry.payload.robot)]->byteDone(horizon);
          break;
        case QueuedEvent::Kind::DriveLeg:
          startLeg(horizon, entry.payload.robot, entry.payload.index);
          break;
        case QueuedEvent::Kind::Inject: {
          Robot& r = *robots_[static_cast<size_t>(entry.payload.robot)];
          r.inject(horizon, config_.injections[static_cast<size_t>(entry.payload.index)]);
          break;
        }
        case QueuedEvent::Kind::Reload:
          sampleUpTo(horizon);
          robots_[static_cast<size_t>(entry.payload.robot)]->reload(horizon);
          break;
        case QueuedEvent::Kind::Power:
          powerEvent(entry.payload.robot, entry.payload.index, horizon);
          break;
        case QueuedEvent::Kind::ReleaseEdge: {
          Robot& r = *robots_[static_cast<size_t>(entry.payload.robot)];
          r.board.injectedLow &= static_cast<uint8_t>(~entry.payload.index);
          r.updateEdgeLines(horizon);
          break;
        }
        case QueuedEvent::Kind::EndOfRound:
          over = true;
          break;
      }
    }
    betweenRounds_ = false;
    if (config_.stopWhenAllExited && allExited()) over = true;
    if (over) {
      result.endTick = horizon;
      sampleUpTo(horizon);
    }
  }
}

Robot* Match::runsAlone(Tick horizon) const {
  if (trace_.on() || config_.observer || config_.debugger) return nullptr;
  Robot* alone = nullptr;
  for (const auto& r : robots_) {
    if (!r->running() || sitsOut(*r, horizon)) continue;
    if (alone) return nullptr;
    alone = r.get();
  }
  return alone;
}

// Rule (9) of "Larger rounds": the queue's next event, due at the
// horizon, taken as serialBytesInRound takes it when it is the robot's own
// serial byte and no NUL (which may latch a frame). False, with nothing
// taken, otherwise.
bool Match::ownByteAt(Robot& r, Tick horizon) {
  const QueuedEvent& next = queue_.top().payload;
  if (next.kind != QueuedEvent::Kind::SerialByte || next.robot != r.index ||
      r.board.serial.nulDone() == horizon)
    return false;
  queue_.pop();
  r.byteDone(horizon);
  return true;
}

// The round loop's work after a sub-round's runs (rounds()), where it would
// only take the next horizon; the horizon itself where it would do more.
Tick Match::SubRoundChain::nextHorizon(Tick) {
  cap = INT64_MIN;  // the VM asks at the next horizon unless set below
  // (All have exited only if the robot has: the others are held, faulted
  // or quiet in a delay loop.)
  if (horizon == plantTick || !match.inputs_.empty() ||
      (match.config_.stopWhenAllExited && robot.result.exited && match.allExited()))
    return horizon;
  // Its own bytes due here (rule (9)); anything else due ends the chain.
  while (match.queue_.nextTick() == horizon)
    if (!match.ownByteAt(robot, horizon)) return horizon;
  // noteQuiet for the one robot that has run (the others' values stand).
  match.quiet_[static_cast<size_t>(robot.index)] = robot.quietUntil();
  const Tick next = std::min(match.subRoundHorizon(), plantTick);
  if (match.sitsOut(robot, next)) return horizon;
  // Every other robot still running sits the next sub-round out too (its
  // quiet tick is its earliest action; the others' are INT64_MIN).
  Tick othersQuiet = INT64_MAX;
  for (const auto& r : match.robots_) {
    if (r.get() == &robot || !r->running()) continue;
    if (!match.sitsOut(*r, next)) return horizon;
    othersQuiet = std::min(othersQuiet, match.quiet_[static_cast<size_t>(r->index)]);
  }
  ++match.subRounds_;
  horizon = next;
  // The ones after it while the VM calls nothing here and is not quiet
  // past its clock (header comment, (7)): what the lines above give then,
  // up to the last the others sit out (sitsOut: an overshoot before their
  // quiet tick; they have not run, so they are behind it).
  cap = std::min(match.queue_.nextTick(), plantTick);
  step = kLookahead;
  unaskedUpTo = INT64_MAX;
  if (othersQuiet != INT64_MAX) {
    cap = std::min(cap, othersQuiet + kLookahead);
    unaskedUpTo = othersQuiet - vm::kMaxRunOvershoot;
  }
  return next;
}

// Rule (d) of "Larger rounds": the serial bytes due at the horizon of a
// sub-round, taken inside the round. False when the round must end there
// instead: another kind of queued event is due at the horizon, or a frame
// latched with new wheel speeds re-initialised the plant at the horizon
// (then the plant's prediction is gone and the round ends as it would
// have after an input).
bool Match::serialBytesInRound(Tick horizon) {
  while (!queue_.empty() && queue_.nextTick() == horizon &&
         queue_.top().payload.kind == QueuedEvent::Kind::SerialByte) {
    const auto entry = queue_.pop();
    Robot& r = *robots_[static_cast<size_t>(entry.payload.robot)];
    // Rule (6): the byte's robot at the horizon, where its interrupt
    // request is raised; every robot there for a NUL, which may latch a
    // frame (and then, as at any input, all of them are).
    if (r.board.serial.nulDone() == horizon)
      for (Robot* other : runOrder_) catchUp(*other, horizon);
    catchUp(r, horizon);
    r.byteDone(horizon);
  }
  return arena_.now() > horizon && (queue_.empty() || queue_.nextTick() != horizon);
}

void Match::faulted(int robot, Tick t) {
  if (!config_.reloadOnFault) return;
  const Tick at = t + config_.reloadDelay;
  if (at >= config_.endTick) return;  // the run is over before the reload
  robots_[static_cast<size_t>(robot)]->reloadPending = true;
  queue_.schedule(at, EventClass::Reload, {QueuedEvent::Kind::Reload, robot, 0});
}

}  // namespace detail

uint64_t streamSeed(uint64_t seed, const std::string& purpose) {
  // FNV-1a of the purpose, mixed with the master seed through SplitMix64.
  uint64_t h = 1469598103934665603ull;
  for (char c : purpose) h = (h ^ static_cast<uint8_t>(c)) * 1099511628211ull;
  plant::SplitMix64 mix(seed ^ h);
  return mix.next();
}

MatchResult runMatch(const MatchConfig& config) {
  detail::Match match(config);
  return match.run();
}

MatchRun::MatchRun(const MatchConfig& config) : match_(std::make_unique<detail::Match>(config)) {}
MatchRun::MatchRun(const MatchRun& other)
    : match_(std::make_unique<detail::Match>(*other.match_)) {}
MatchRun& MatchRun::operator=(const MatchRun& other) {
  if (this != &other) match_ = std::make_unique<detail::Match>(*other.match_);
  return *this;
}
MatchRun::~MatchRun() = default;
bool MatchRun::runUntil(Tick tick) { return match_->runUntil(tick); }
Tick MatchRun::now() const { return match_->roundStart(); }
MatchResult MatchRun::finish() { return match_->end(); }
const MatchView& MatchRun::view() const { return *match_; }

void MatchRun::setDebugBreakpoints(int robot, const std::vector<uint32_t>& addresses) {
  detail::Robot& r = match_->robot(robot);
  if (r.debugBreakpoints == addresses) return;
  auto ownedByMatch = [&](uint32_t a) { return a == r.mainReturn || r.lineInjections.count(a); };
  for (uint32_t a : r.debugBreakpoints)
    if (!ownedByMatch(a)) r.vm().setBreakpoint(a, false);
  for (uint32_t a : addresses) r.vm().setBreakpoint(a, true);
  r.debugBreakpoints = addresses;
}

MatchRun::Snapshot::Snapshot() = default;
MatchRun::Snapshot::Snapshot(Snapshot&&) noexcept = default;
MatchRun::Snapshot& MatchRun::Snapshot::operator=(Snapshot&&) noexcept = default;
MatchRun::Snapshot::~Snapshot() = default;
Tick MatchRun::Snapshot::now() const { return state_->roundStart(); }
Tick MatchRun::Snapshot::robotClock(int robot) const {
  return state_->robots_[static_cast<size_t>(robot)]->now();
}
bool MatchRun::Snapshot::robotFaulted(int robot) const {
  return state_->robots_[static_cast<size_t>(robot)]->vm().fault() != nullptr;
}

// What changes and the plant's mark: no plant is built until a restore.
MatchRun::Snapshot MatchRun::snapshot() const {
  Snapshot s;
  s.mark_ = match_->arena().mark();
  s.state_ = std::make_unique<detail::MatchState>(match_->state());
  // Its robots belong to no match until a restore links them.
  for (auto& r : s.state_->robots_) r->match = nullptr;
  return s;
}

void MatchRun::restore(const Snapshot& snapshot) {
  match_ = std::make_unique<detail::Match>(*snapshot.state_, snapshot.mark_);
  // The held robot's boundary at the snapshot is the first it looks at.
  if (match_->debugger()) match_->robot(match_->debugRobot()).debugLook = true;
}

std::string_view debugEventName(DebugEvent e) {
  switch (e) {
    case DebugEvent::FrameLatched:
      return "frame";
    case DebugEvent::EdgeAccepted:
      return "edge";
    case DebugEvent::Contact:
      return "contact";
    case DebugEvent::Shot:
      return "shot";
    case DebugEvent::Fault:
      return "fault";
  }
  return "?";
}

}  // namespace simbot::scheduler
