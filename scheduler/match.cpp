// One match: the round loop described in match.h, the robots' buses (ports,
// A/D, serial library hooks, interrupt notifications) and the trace.
//
// Larger rounds. A round is a run of sub-rounds, each exactly one round of
// the one-character protocol of match.h: from t_k = the earliest VM clock,
// every VM runs to h_k = min(next queued event, t_k + 9,600, the plant's
// next event). What a round saves is the plant's round trip: the plant is
// advanced once, to P = min(next queued event, t + 8 x 9,600) (only to the
// first sub-round's horizon while a ball is in flight or a launch is
// scheduled), and a sub-round ends the round when
//   (a) its VMs made a plant input (port B write, injected bump, edge
//       handler entry): inputs are applied at the end of the sub-round, as
//       at the end of a one-character round;
//   (b) a queued event is due at its horizon, or the plant's event is (h_k
//       is the plant's stop P or its event tick);
//   (c) (solo runs) every robot has exited or faulted.
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
// input); no state, event or record depends on them. A ball in flight
// keeps the plant to one sub-round because a root with no event (a ball's
// closest approach) updates the ball's closest distance when the plant
// reaches it, and one past an input's tick would not be found on the
// re-initialised trajectory.
#include "scheduler/match.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <deque>
#include <stdexcept>

#include "plant/pio.h"
#include "plant/serial_link.h"
#include "scheduler/event_queue.h"
#include "scheduler/part_clock.h"

namespace simbot::scheduler {

namespace {

constexpr Tick kLookahead = plant::kTicksPerChar;
// How far the plant integrates ahead in one round (header comment, "Larger
// rounds"): eight character times. Integration past an input's tick is
// thrown away at the input, so this bounds the work wasted per input.
constexpr Tick kRoundLookahead = 8 * plant::kTicksPerChar;

// Queued events; the plant's own events come from Arena::advance.
struct QueuedEvent {
  enum class Kind : uint8_t { SerialByte, DriveLeg, Inject, ReleaseEdge, Reload, EndOfRound } kind;
  int robot = 0;
  int index = 0;  // injection number, path leg, or the detector bit to release
};

// A plant input made by a robot during a round: a port B write, a bump
// injected at a program point, or the entry into its PIO (edge) handler,
// which the referee counts. Applied after the round, in tick order.
struct PlantInput {
  Tick tick;
  int robot;
  enum class Kind : uint8_t { PortB, Reflex, EdgeHandler } kind;
  uint8_t value;  // port B
  plant::Bumper bumper;
};

class Match;

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

// A VM's clock starts at 0 when it is made; a VM made for a reload starts
// at tick `base` of the match, so every tick it reports is moved by `base`.
class ShiftedBus : public vm::Bus {
 public:
  explicit ShiftedBus(vm::Bus& to) : to_(to) {}
  Tick base = 0;
  void out(Tick t, uint16_t port, uint8_t value) override { to_.out(t + base, port, value); }
  uint8_t in(Tick t, uint16_t port) override { return to_.in(t + base, port); }
  int adSample(Tick t, int channel) override { return to_.adSample(t + base, channel); }
  void hvEnable(Tick t) override { to_.hvEnable(t + base); }
  void serialInit(Tick t, int mode, int divisor) override {
    to_.serialInit(t + base, mode, divisor);
  }
  void serialSend(Tick t, uint16_t buf, uint16_t cc) override { to_.serialSend(t + base, buf, cc); }
  void serialTxService(Tick t, vm::Vm& v) override { to_.serialTxService(t + base, v); }
  void console(Tick t, std::string_view line) override { to_.console(t + base, line); }
  void interruptAccepted(Tick t, vm::Irq irq, uint32_t pc) override {
    to_.interruptAccepted(t + base, irq, pc);
  }
  void interruptReturned(Tick t, vm::Irq irq) override { to_.interruptReturned(t + base, irq); }
  void iffChanged(Tick t, bool iff1) override { to_.iffChanged(t + base, iff1); }
  bool wantCostateEvents() const override { return to_.wantCostateEvents(); }
  void costate(Tick t, uint16_t coData, CostateEvent e, int line) override {
    to_.costate(t + base, coData, e, line);
  }

 private:
  vm::Bus& to_;
};

// One robot: its VM, the devices its program talks to, and its counters.
class Robot : public vm::Bus, public plant::RobotMemory {
 public:
  Robot(Match& match, int index, const RobotSpec& spec, const vm::CostTable& costs, uint64_t seed);

  // The robot's clock (match ticks) and its program's VM.
  Tick now() const { return bus.base + vm_->now(); }
  vm::Vm& vm() { return *vm_; }
  const vm::Vm& vm() const { return *vm_; }
  // A VM as at load, its clock at t: fresh memory (with the profile's
  // power-on fill), the breakpoints the match needs.
  void powerOn(Tick t);
  // --reload-on-fault: the faulted program starts again at t.
  void reload(Tick t);
  bool reloadPending = false;
  bool faultSeen = false;  // this VM's fault is recorded

  // vm::Bus
  void out(Tick t, uint16_t port, uint8_t value) override;
  uint8_t in(Tick t, uint16_t port) override;
  int adSample(Tick t, int channel) override;
  void serialSend(Tick t, uint16_t buf, uint16_t cc) override;
  void serialTxService(Tick t, vm::Vm& v) override;
  void console(Tick t, std::string_view line) override;
  void interruptAccepted(Tick t, vm::Irq irq, uint32_t pc) override;
  void interruptReturned(Tick t, vm::Irq irq) override;
  void iffChanged(Tick t, bool iff1) override;
  bool wantCostateEvents() const override;
  void costate(Tick t, uint16_t coData, CostateEvent e, int line) override;
  // plant::RobotMemory
  uint8_t read8(uint16_t a) const override { return vm_->read8(a); }
  void write8(uint16_t a, uint8_t v) override { vm_->write8(a, v); }

  // Runs the VM to `horizon` (its clock ends at or after it).
  void runTo(Tick horizon);
  void byteDone(Tick t);
  // Port A's edge lines: low while the plant says so or an injection holds.
  void updateEdgeLines(Tick t);
  void inject(Tick t, const Injection& injection);
  uint8_t plantLow = 0, injectedLow = 0;
  std::map<uint32_t, std::vector<int>> lineInjections;  // code address -> injections
  // Executions of each injection point, over the whole run (a reload does
  // not restart the count).
  std::map<uint32_t, int> lineHits;
  struct Watch {
    std::string name;
    uint16_t address;
    std::string type;
  };
  std::vector<Watch> watches;
  trace::Watch watchedValues() const;
  void scheduleSerial(Tick t);
  void updateSerialRequest();

  // Where the program was at each sample tick (traced runs): taken at the
  // VM's first instruction boundary at or after the tick.
  struct Snapshot {
    Tick tick;
    int line;
    const vm::Symbol* function;
    bool inHandler;
    trace::Watch watch;
  };
  std::deque<Snapshot> snapshots;
  Tick nextSnapshot = 0;
  void takeSnapshots();
  Snapshot snapshotFor(Tick t);
  std::string handlerName() const;

  const RobotSpec& spec;
  int index;
  Match& match;
  const vm::CostTable& costs;
  ShiftedBus bus;
  std::unique_ptr<vm::Vm> vm_;
  plant::SplitMix64 memoryFill;  // power-on RAM (profile random_memory)
  // T-states of earlier VMs of this robot (reloads), for profiles.
  std::vector<uint64_t> earlierProfile;
  uint64_t earlierSerialIsrCycles = 0;
  uint64_t earlierTimerIsrCycles = 0;
  uint64_t earlierInstructions = 0, earlierFastForwarded = 0;
  plant::SerialLink link;
  // What the serial library had still to fetch of the current send after
  // its last step: a new send while it is above zero overwrites that frame.
  // (Read back after each step, since the program may rewrite *cc itself.)
  uint16_t sendCcAddress = 0;
  int sendUnfetched = 0;
  plant::PioPortA pio;
  uint8_t edgeLines = 0xFF;
  int enb485 = -1;  // never written
  std::array<int64_t, 2> adReads{};
  // Interrupts accepted per source (vm::Irq), over the whole run; put into
  // the result's map by name at the end, so counting one allocates nothing.
  std::array<uint64_t, vm::kIrqCount> interruptCounts{};
  std::array<int, 2> lastAdValue{-1, -1};
  Tick serialEventAt = -1;
  Tick serialIsrAccepted = 0;
  plant::SplitMix64 noise;
  plant::SplitMix64 gunLuck;  // jams and misfires
  plant::SplitMix64 muzzle;   // muzzle-speed spread, one draw per launching stroke
  RobotResult result;
  uint32_t mainReturn;
};

class Match {
 public:
  explicit Match(const MatchConfig& config)
      : config_(config),
        costs_(vm::makeCostTable(config.knobs)),
        arenaConfig_(arenaConfigFor(config)),
        arena_(arenaConfig_),
        coin_(streamSeed(config.seed, "coin")),
        clock_(config.timeParts) {
    for (trace::Sink* sink : config.sinks) trace_.attach(sink);
    if (config.robots.empty() || config.robots.size() > 2)
      throw std::invalid_argument("a match needs one or two robots");
    for (size_t i = 0; i < config.robots.size(); ++i)
      robots_.push_back(std::make_unique<Robot>(*this, static_cast<int>(i), config.robots[i],
                                                costs_, config.seed));
    if (config.reloadOnFault && config.reloadDelay < kMinReloadDelay)
      throw std::invalid_argument(
          fmt::format("a reload must wait at least {} ticks (the serial port's two characters)",
                      kMinReloadDelay));
    resolveWatches();
    queue_.schedule(config.endTick, EventClass::EndOfRound, {QueuedEvent::Kind::EndOfRound, 0, 0});
    for (size_t i = 0; i < config.robots.size(); ++i) {
      for (const DriveLeg& leg : config.robots[i].path)
        if (leg.duration <= 0) throw std::invalid_argument("a path leg must last at least a tick");
      if (!config.robots[i].path.empty())
        queue_.schedule(0, EventClass::MotorLatch,
                        {QueuedEvent::Kind::DriveLeg, static_cast<int>(i), 0});
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
        const std::optional<uint32_t> head = loopHead(r.spec.image, in.line);
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

  MatchResult run();
  // The round loop; `roundStart` is the tick the current round began at.
  void rounds(MatchResult& result, Tick& roundStart);

  plant::Arena& arena() { return arena_; }
  PartClock& clock() { return clock_; }
  bool tracing() const { return trace_.on(); }
  bool profiling() const { return config_.profile; }
  bool tracingCostates() const { return config_.traceCostate && trace_.on(); }
  // Robot `robot` faulted at t: its reload, if the run asks for one.
  void faulted(int robot, Tick t);
  // Injection `injection` (one of config_.injections) fired.
  void fired(const Injection& injection) {
    fired_[static_cast<size_t>(&injection - config_.injections.data())] = true;
  }
  Tick sampleInterval() const { return config_.sampleInterval; }
  // A record at tick t, with the watched variables of its robot as they are
  // now in that robot's memory.
  void emit(Tick t, trace::Record record);
  void emit(Tick t, trace::Record record, trace::Watch watch) {
    trace_.emit(t, std::move(record), std::move(watch));
  }
  EventQueue<QueuedEvent>& queue() { return queue_; }
  std::vector<PlantInput>& inputs() { return inputs_; }
  bool betweenRounds() const { return betweenRounds_; }
  void applyReflex(Tick t, int robot, plant::Bumper side);
  void startLeg(Tick t, int robot, int leg);
  const Injection& injection(int k) const { return config_.injections[static_cast<size_t>(k)]; }
  const std::string& name(int robot) const {
    return config_.robots[static_cast<size_t>(robot)].name;
  }
  MatchObserver* observer() const { return config_.observer; }
  const plant::RobotParams& robotParams(int robot) const {
    return arenaConfig_.robots[static_cast<size_t>(robot)].params;
  }

 private:
  Tick earliestClock() const;
  bool allExited() const {
    return std::all_of(robots_.begin(), robots_.end(), [](const auto& r) {
      return (r->result.exited || r->vm().fault()) && !r->reloadPending;
    });
  }
  void applyInputs();
  bool advancePlantTo(Tick t, plant::AdvanceResult& step);
  void resolveWatches();
  void emitSetup();
  trace::Record plantRecord(const plant::Event& e) const;
  void handlePlantEvents(Tick t, const plant::EventList& events);
  void sampleUpTo(Tick t);
  void finish(MatchResult& result);

  const MatchConfig& config_;
  vm::CostTable costs_;
  plant::ArenaConfig arenaConfig_;  // config_.arena with this seed's variation
  plant::Arena arena_;
  trace::Tracer trace_;
  plant::SplitMix64 coin_;
  EventQueue<QueuedEvent> queue_;
  std::vector<std::unique_ptr<Robot>> robots_;
  std::vector<PlantInput> inputs_;
  std::vector<std::string> warnings_;
  std::vector<bool> fired_ = std::vector<bool>(config_.injections.size());
  std::vector<uint32_t> injectionAddress_ = std::vector<uint32_t>(config_.injections.size());
  int hitsAt(const Injection& in, uint32_t address) const {
    const auto& hits = robots_[static_cast<size_t>(in.robot)]->lineHits;
    const auto it = hits.find(address);
    return it == hits.end() ? 0 : it->second;
  }
  bool betweenRounds_ = false;
  Tick nextSample_ = 0;
  uint64_t rounds_ = 0;
  uint64_t subRounds_ = 0;  // sub-rounds after the first of each round
  PartClock clock_;
};

// ---- robot ------------------------------------------------------------------

Robot::Robot(Match& m, int i, const RobotSpec& s, const vm::CostTable& costs_, uint64_t seed)
    : spec(s),
      index(i),
      match(m),
      costs(costs_),
      bus(*this),
      memoryFill(streamSeed(seed, "memory-fill-" + s.name)),
      noise(streamSeed(seed, "eye-noise-" + s.name)),
      gunLuck(streamSeed(seed, "gun-" + s.name)),
      muzzle(streamSeed(seed, "muzzle-" + s.name)),
      mainReturn(s.image.entry + static_cast<uint32_t>(vm::instructionSize(vm::Op::CALL))) {
  result.name = s.name;
  result.program = s.program;
  powerOn(0);
}

void Robot::powerOn(Tick t) {
  bus.base = t;
  // The timer service is this robot's controller's (profile [controller]).
  vm::CostTable table = costs;
  table.knobs.timerService = static_cast<vm::TimerService>(match.robotParams(index).timer_service);
  table.knobs.fastForward = costs.knobs.fastForward && match.robotParams(index).fast_forward;
  vm_ = std::make_unique<vm::Vm>(spec.image, bus, table);
  faultSeen = false;
  vm_->setBreakpoint(mainReturn);
  for (const auto& [address, injections] : lineInjections) vm_->setBreakpoint(address);
  if (match.profiling()) vm_->enableProfile();
  // A reload draws the next bytes of the same stream: RAM after a power
  // cycle holds new garbage, not the same.
  if (match.robotParams(index).random_memory) vm_->fillMemory([this] { return memoryFill.next(); });
}

void Robot::reload(Tick t) {
  reloadPending = false;
  if (match.profiling()) {
    const auto& p = vm_->profile();
    earlierProfile.resize(std::max(earlierProfile.size(), p.size()));
    for (size_t a = 0; a < p.size(); ++a) earlierProfile[a] += p[a];
    earlierSerialIsrCycles += vm_->serialIsrCycles();
    earlierTimerIsrCycles += vm_->timerIsrCycles();
    earlierInstructions += vm_->stats().instructions;
    earlierFastForwarded += vm_->stats().fastForwarded;
  }
  powerOn(t);
  ++result.reloads;
  result.exited = false;
  // The controller's reset clears the Z180's serial port, the library and
  // the PIO (unarmed: no edge interrupt until the program arms it again);
  // the delay is long enough that no byte is left in the port. The motor
  // controller keeps its latched command; the receiver's partial frame is
  // dropped with the link's state (a fragment from before the crash never
  // joins the reloaded program's frames).
  if (!link.idle()) throw std::logic_error("a reload with bytes still in the serial port");
  link = plant::SerialLink{};
  sendCcAddress = 0;
  sendUnfetched = 0;
  serialEventAt = -1;
  pio = plant::PioPortA{};
  // The reset PIO sees the lines as they are; unarmed, it raises nothing.
  if (pio.setInputs(edgeLines)) throw std::logic_error("an unarmed PIO raised an interrupt");
  enb485 = -1;
  // Samples up to t were taken from the faulted VM: the new one's start at
  // the next sample tick.
  snapshots.clear();
  const Tick interval = match.sampleInterval();
  nextSnapshot = (t / interval + 1) * interval;
  if (match.tracing()) match.emit(t, trace::rec::Reload{index, result.reloads});
}

void Robot::runTo(Tick horizon) {
  const bool tracing = match.tracing();
  for (;;) {
    if (tracing) takeSnapshots();
    if (now() >= horizon) return;
    const vm::Stop stop =
        vm_->run((tracing ? std::min(horizon, nextSnapshot) : horizon) - bus.base);
    if (stop == vm::Stop::Fault) {
      const vm::Fault* f = vm_->fault();
      const Tick at = bus.base + f->tick;
      if (!faultSeen) {
        faultSeen = true;
        FaultInfo info{f->message, timebase::secondsFromTicks(at), f->line};
        if (!result.fault) result.fault = info;
        result.faults.push_back(info);
        if (tracing) match.emit(at, trace::rec::Fault{index, f->message, f->line});
        match.faulted(index, at);
      }
      return;
    }
    if (stop != vm::Stop::Breakpoint) continue;
    if (vm_->pc() == mainReturn) {
      result.exited = true;
      result.exitTick = now();
      if (tracing) match.emit(now(), trace::rec::Exit{index});
    }
    if (auto it = lineInjections.find(vm_->pc()); it != lineInjections.end()) {
      const int hit = ++lineHits[vm_->pc()];
      for (int k : it->second)
        if (match.injection(k).count == hit) inject(now(), match.injection(k));
    }
  }
}

// The VM's state at its first boundary at or after each sample tick it has
// reached: it was stopped there (runTo), or it idled there (halted).
void Robot::takeSnapshots() {
  while (nextSnapshot <= now()) {
    snapshots.push_back(Snapshot{nextSnapshot, vm_->line(), spec.image.functionAt(vm_->pc()),
                                 vm_->interruptDepth() > 0, watchedValues()});
    nextSnapshot += match.sampleInterval();
  }
}

// The snapshot of sample tick t; a faulted robot stays where it faulted.
Robot::Snapshot Robot::snapshotFor(Tick t) {
  while (!snapshots.empty() && snapshots.front().tick < t) snapshots.pop_front();
  if (!snapshots.empty() && snapshots.front().tick == t) return snapshots.front();
  const uint32_t pc = vm_->pc();
  return Snapshot{t, vm_->fault() ? vm_->fault()->line : spec.image.lineAt(pc),
                  spec.image.functionAt(pc), false, watchedValues()};
}

void Robot::out(Tick t, uint16_t port, uint8_t value) {
  switch (port) {
    case vm::kPortPIOCA:
      pio.control(value);
      return;
    case vm::kPortPIODA:
      pio.writeData(value);
      return;
    case vm::kPortPIODB:
      match.inputs().push_back({t, index, PlantInput::Kind::PortB, value, plant::Bumper::Front});
      if (match.tracing()) match.emit(t, trace::rec::PortB{index, value});
      return;
    case vm::kPortENB485:
      if (match.tracing() && value != enb485) match.emit(t, trace::rec::Rs485{index, value});
      enb485 = value;
      return;
    default:
      return;  // PIOCB set-up and unknown ports have no effect here
  }
}

uint8_t Robot::in(Tick, uint16_t port) {
  if (port == vm::kPortPIODA) return pio.read();
  return 0xFF;
}

int Robot::adSample(Tick t, int channel) {
  // Only the eye asked for is computed; the noise stream advances as for both.
  const plant::EyeChannels asked = channel == 0   ? plant::EyeChannels::Left
                                   : channel == 1 ? plant::EyeChannels::Right
                                                  : plant::EyeChannels::Both;
  const plant::EyeReadings e = [&] {
    const PartScope plant(match.clock(), PartClock::Plant);
    return match.arena().eyeReadings(index, t, &noise, asked);
  }();
  const int value = channel == 0 ? e.left : channel == 1 ? e.right : 0;
  if (match.observer()) match.observer()->onEyeRead(index, t, channel, value);
  if (channel == 0 || channel == 1) {
    // Traced as a step when it differs: a search loop reads thousands a second.
    const auto c = static_cast<size_t>(channel);
    ++adReads[c];
    if (match.tracing() && value != lastAdValue[c])
      match.emit(t, trace::rec::AdRead{index, channel, value, adReads[c]});
    lastAdValue[c] = value;
  }
  return value;
}

void Robot::serialSend(Tick t, uint16_t buf, uint16_t cc) {
  if (match.tracing()) match.emit(t, trace::rec::SerialSend{index, vm_->read8(cc)});
  if (sendUnfetched > 0) ++result.framesOverwritten;
  link.send(t, buf, cc, *this);
  sendCcAddress = cc;
  sendUnfetched = vm_->read8(cc);
  scheduleSerial(t);
  updateSerialRequest();
}

void Robot::serialTxService(Tick t, vm::Vm&) {
  link.service(t, *this);
  sendUnfetched = vm_->read8(sendCcAddress);
  scheduleSerial(t);
  updateSerialRequest();
}

// A byte that entered the shift register is on the wire for one character
// time, ending at nextByteDone().
void Robot::scheduleSerial(Tick) {
  const auto done = link.nextByteDone();
  if (done && *done != serialEventAt) {
    serialEventAt = *done;
    if (match.tracing())
      match.emit(*done - plant::kTicksPerChar, trace::rec::SerialByte{index, link.shifting()});
    match.queue().schedule(*done, EventClass::SerialByte,
                           {QueuedEvent::Kind::SerialByte, index, 0});
  }
}

void Robot::updateSerialRequest() {
  if (link.requestingInterrupt())
    vm_->request(vm::Irq::SerialTx);
  else
    vm_->cancelRequest(vm::Irq::SerialTx);
}

void Robot::byteDone(Tick t) {
  serialEventAt = -1;
  if (auto frame = link.byteDone(t)) {
    if (match.observer()) match.observer()->onFrame(index, t, frame->command.has_value());
    if (frame->command) {
      ++result.framesLatched;
      const PartScope plant(match.clock(), PartClock::Plant);
      match.arena().setWheels(index, *frame->command, t);
    } else {
      ++result.framesRejected;
    }
    if (match.tracing()) {
      if (frame->command)
        match.emit(t, trace::rec::FrameLatched{index, frame->bytes});
      else
        match.emit(t, trace::rec::FrameRejected{index, frame->bytes});
    }
  }
  scheduleSerial(t);
  updateSerialRequest();
}

// Each watched variable's value as its C type reads it.
trace::Watch Robot::watchedValues() const {
  trace::Watch values;
  for (const auto& w : watches) {
    const bool isUnsigned = w.type.find("unsigned") != std::string::npos;
    trace::WatchValue v;
    if (w.type.find('*') != std::string::npos) {
      v = std::int64_t{vm_->read16(w.address)};
    } else if (w.type.find("float") != std::string::npos ||
               w.type.find("double") != std::string::npos) {
      v = static_cast<double>(std::bit_cast<float>(vm_->read32(w.address)));
    } else if (w.type.find("long") != std::string::npos) {
      const uint32_t raw = vm_->read32(w.address);
      v = isUnsigned ? std::int64_t{raw} : std::int64_t{static_cast<int32_t>(raw)};
    } else if (w.type.find("char") != std::string::npos) {
      v = std::int64_t{vm_->read8(w.address)};
    } else {
      const uint16_t raw = vm_->read16(w.address);
      v = isUnsigned ? std::int64_t{raw} : std::int64_t{static_cast<int16_t>(raw)};
    }
    values.emplace_back(w.name, v);
  }
  return values;
}

void Robot::updateEdgeLines(Tick t) {
  const auto lines = static_cast<uint8_t>(~(plantLow | injectedLow));
  if (lines != edgeLines && match.tracing()) match.emit(t, trace::rec::PortA{index, lines});
  edgeLines = lines;
  if (pio.setInputs(edgeLines)) vm_->request(vm::Irq::Pio, pio.vector());
}

void Robot::inject(Tick t, const Injection& injection) {
  match.fired(injection);
  if (match.tracing()) match.emit(t, trace::rec::Injection{index, injection.text, vm_->line()});
  switch (injection.source) {
    case InjectSource::EdgeFore:
    case InjectSource::EdgeAft: {
      const uint8_t bit = injection.source == InjectSource::EdgeFore ? 0x02 : 0x01;
      injectedLow |= bit;
      updateEdgeLines(t);
      match.queue().schedule(t + kInjectedEdgePulse, EventClass::Injection,
                             {QueuedEvent::Kind::ReleaseEdge, index, bit});
      return;
    }
    case InjectSource::BumperFront:
    case InjectSource::BumperBack: {
      const plant::Bumper side = injection.source == InjectSource::BumperFront
                                     ? plant::Bumper::Front
                                     : plant::Bumper::Back;
      // Between rounds (a time or tick) the plant takes it at once; at a
      // program point it waits for the end of the round with port B writes.
      if (match.betweenRounds())
        match.applyReflex(t, index, side);
      else
        match.inputs().push_back({t, index, PlantInput::Kind::Reflex, 0, side});
      return;
    }
  }
}

void Robot::console(Tick t, std::string_view line) {
  result.console.emplace_back(line);
  if (match.tracing()) match.emit(t, trace::rec::Console{index, std::string(line)});
}

// The #INT_VEC handler the PIO's vector selects.
std::string Robot::handlerName() const {
  for (const auto& v : spec.image.vectors)
    if (v.vector == pio.vector()) return v.handlerName;
  return "";
}

void Robot::interruptAccepted(Tick t, vm::Irq irq, uint32_t pc) {
  ++interruptCounts[static_cast<size_t>(irq)];
  if (match.observer()) match.observer()->onInterruptAccepted(index, t, irq);
  if (irq == vm::Irq::Pio) {
    pio.accepted();
    match.inputs().push_back({t, index, PlantInput::Kind::EdgeHandler, 0, plant::Bumper::Front});
  }
  // The BIOS timer service (1,024 a second) is counted, not traced.
  if (!match.tracing() || irq == vm::Irq::Timer) return;
  if (irq == vm::Irq::SerialTx) {
    serialIsrAccepted = t;  // traced as one span when it returns
    return;
  }
  const vm::Symbol* fn = spec.image.functionAt(pc);
  match.emit(t, trace::rec::InterruptAccepted{index, std::string(vm::irqName(irq)),
                                              spec.image.lineAt(pc), fn ? fn->name : "",
                                              irq == vm::Irq::Pio ? handlerName() : ""});
}

void Robot::interruptReturned(Tick t, vm::Irq irq) {
  if (irq == vm::Irq::SerialTx) {
    if (match.tracing()) match.emit(serialIsrAccepted, trace::rec::SerialIsr{index, t});
    return;
  }
  if (irq != vm::Irq::Pio) return;
  if (match.tracing())
    match.emit(t, trace::rec::InterruptReturned{index, std::string(vm::irqName(irq))});
  if (pio.returned()) vm_->request(vm::Irq::Pio, pio.vector());
}

void Robot::iffChanged(Tick t, bool iff1) {
  if (match.tracing()) match.emit(t, trace::rec::Iff1{index, iff1});
}

bool Robot::wantCostateEvents() const { return match.tracingCostates(); }

// The costatement is named by its CoData's symbol: the name a named one
// was given, "costate@LINE" for an unnamed one (FUNCTION.costate@LINE).
void Robot::costate(Tick t, uint16_t coData, CostateEvent e, int line) {
  std::string name = fmt::format("0x{:04x}", coData);
  for (const auto& s : spec.image.symbols)
    if (s.address == coData && s.size == vm::kCoDataSize &&
        (s.kind == vm::Symbol::Kind::Global || s.kind == vm::Symbol::Kind::Static)) {
      name = s.name.substr(s.name.find('.') + 1);
      break;
    }
  static constexpr const char* kEvent[] = {"enter", "yield", "end"};
  match.emit(t, trace::rec::Costate{index, name, kEvent[static_cast<int>(e)], line});
}

// ---- match ------------------------------------------------------------------

Tick Match::earliestClock() const {
  Tick t = INT64_MAX;
  for (const auto& r : robots_)
    if (!r->vm().fault()) t = std::min(t, r->now());
  return t == INT64_MAX ? queue_.nextTick() : t;
}

// --watch VAR: a global, or a static local as FUNCTION.VAR, of any robot
// whose program has it; scalars only. The value is read from the robot's
// memory when the record is made (for samples: at the end of the round that
// contains the sample tick, at most 9,600 ticks later).
void Match::resolveWatches() {
  for (const auto& name : config_.watches) {
    bool found = false;
    for (auto& r : robots_) {
      for (const auto& s : r->spec.image.symbols) {
        if (s.name != name) continue;
        if (s.kind != vm::Symbol::Kind::Global && s.kind != vm::Symbol::Kind::Static &&
            s.kind != vm::Symbol::Kind::Param)
          throw std::invalid_argument("--watch " + name + ": only globals and static locals " +
                                      "can be watched ('" + name + "' is an auto variable)");
        if (s.size > 4 || s.type.find('[') != std::string::npos ||
            s.type.find("struct") != std::string::npos || s.type.find("union") != std::string::npos)
          throw std::invalid_argument("--watch " + name + ": only scalar variables can be watched");
        r->watches.push_back({name, static_cast<uint16_t>(s.address), s.type});
        found = true;
      }
    }
    if (!found)
      throw std::invalid_argument("--watch " + name + ": no such global or static variable " +
                                  "(a static local is FUNCTION.NAME)");
  }
}

void Match::emit(Tick t, trace::Record record) {
  const int robot = trace::robotOf(record);
  trace::Watch watch;
  if (robot >= 0 && robot < static_cast<int>(robots_.size()))
    watch = robots_[static_cast<size_t>(robot)]->watchedValues();
  trace_.emit(t, std::move(record), std::move(watch));
}

// The run's set-up: the first records of every trace.
void Match::emitSetup() {
  const plant::FieldParams& f = arenaConfig_.field;
  emit(0,
       trace::rec::Run{"simbot-trace/1", static_cast<int64_t>(config_.seed), config_.profileName,
                       static_cast<int64_t>(robots_.size()), config_.endTick, kTicksPerSecond,
                       config_.sampleInterval, f.size_ft, f.wire_inset_ft, f.wire_sensitivity_ft,
                       f.field_walls, f.divider_x_ft, f.divider_south_ft, f.divider_north_ft,
                       f.divider_thickness_ft, f.divider_height_ft, f.gravity_fps2},
       {});
  for (const auto& r : robots_) {
    const plant::RobotSetup& setup = arenaConfig_.robots[static_cast<size_t>(r->index)];
    const plant::RobotParams& p = setup.params;
    std::string source;
    for (const auto& line : r->spec.image.sourceLines) source += line + "\n";
    const auto limit = [&p](double width) {
      return std::atan(width / p.eye_nose) * 180.0 / 3.14159265358979323846;
    };
    emit(0,
         trace::rec::RobotSetup{r->index,
                                r->spec.program,
                                std::move(source),
                                !r->spec.path.empty(),
                                setup.start.x_ft,
                                setup.start.y_ft,
                                setup.start.heading_deg,
                                p.body_diameter_ft,
                                p.target_height_ft,
                                p.track_ft,
                                p.edge_detector_inset_ft,
                                limit(p.left_eye_width),
                                limit(p.right_eye_width),
                                p.eye_max,
                                p.eye_background,
                                p.eye_saturation_ft,
                                p.launch_height_ft,
                                p.muzzle_speed_fps,
                                p.balls_per_gun,
                                setup.hardware.gun_motor_bit[0],
                                setup.hardware.gun_solenoid_bit[0],
                                setup.hardware.gun_motor_bit[1],
                                setup.hardware.gun_solenoid_bit[1],
                                setup.hardware.disc_shooter_bit},
         {});
  }
}

void Match::applyReflex(Tick t, int robot, plant::Bumper side) {
  sampleUpTo(t);
  const plant::EventList events = [&] {
    const PartScope plant(clock_, PartClock::Plant);
    return arena_.triggerReflex(robot, side, t);
  }();
  handlePlantEvents(t, events);
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
  for (auto it = inputs_.begin(); it != inputs_.end(); ++it)
    std::rotate(
        std::upper_bound(inputs_.begin(), it, *it,
                         [](const PlantInput& a, const PlantInput& b) { return a.tick < b.tick; }),
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
    if (w.kind == PlantInput::Kind::Reflex) {
      applyReflex(w.tick, w.robot, w.bumper);
      continue;
    }
    if (w.kind == PlantInput::Kind::EdgeHandler) {
      sampleUpTo(w.tick);
      const plant::EventList events = [&] {
        const PartScope plant(clock_, PartClock::Plant);
        return arena_.edgeHandlerEntered(w.robot, w.tick);
      }();
      handlePlantEvents(w.tick, events);
      continue;
    }
    sampleUpTo(w.tick);
    const plant::EventList immediate = [&] {
      const PartScope plant(clock_, PartClock::Plant);
      return arena_.setPortB(w.robot, w.value, w.tick,
                             &robots_[static_cast<size_t>(w.robot)]->gunLuck,
                             &robots_[static_cast<size_t>(w.robot)]->muzzle);
    }();
    for (const auto& e : immediate) {
      if (config_.observer) config_.observer->onPlantEvent(w.tick, e);
      if (trace_.on()) emit(w.tick, plantRecord(e));
    }
  }
  inputs_.clear();
}

// The trace record of a plant event.
trace::Record Match::plantRecord(const plant::Event& e) const {
  namespace rec = trace::rec;
  const int r = e.robot;
  const auto side = [](plant::Bumper b) { return b == plant::Bumper::Front ? "front" : "back"; };
  const auto with = [](plant::ContactWith w) {
    return w == plant::ContactWith::Robot     ? "robot"
           : w == plant::ContactWith::Divider ? "divider"
                                              : "wall";
  };
  const auto missed = [](plant::MissReason m) {
    return m == plant::MissReason::Floor     ? "floor"
           : m == plant::MissReason::Divider ? "divider"
                                             : "wall";
  };
  switch (e.kind) {
    case plant::EventKind::EdgeEnter:
      return rec::EdgeEnter{r, e.detector == plant::Detector::Fore ? "fore" : "aft"};
    case plant::EventKind::EdgeLeave:
      return rec::EdgeLeave{r, e.detector == plant::Detector::Fore ? "fore" : "aft"};
    case plant::EventKind::Contact:
      return rec::Contact{r, side(e.bumper), with(e.with)};
    case plant::EventKind::ContactEnd:
      return rec::ContactEnd{r, with(e.with)};
    case plant::EventKind::ReflexStart:
      return rec::ReflexStart{r, side(e.bumper)};
    case plant::EventKind::ReflexEnd:
      return rec::ReflexEnd{r, side(e.bumper)};
    case plant::EventKind::BallLaunch:
      return rec::BallLaunch{r, e.gun, e.ball, e.x, e.y, e.z, e.vx, e.vy};
    case plant::EventKind::BallSkip:
      return rec::BallSkip{r, e.gun, e.ball, e.x, e.y};
    case plant::EventKind::BallHit:
      return rec::BallHit{r, e.gun, e.other, e.ball, "robot", e.x, e.y, e.z};
    case plant::EventKind::BallMiss:
      return rec::BallMiss{
          r,      e.gun,
          e.ball, missed(e.miss),
          e.x,    e.y,
          e.z,    e.closest_ft >= 0 ? std::optional<double>(e.closest_ft) : std::nullopt};
    case plant::EventKind::RefereePutBack:
      return rec::RefereePutBack{r};
    case plant::EventKind::RefereeTurn:
      return rec::RefereeTurn{r};
    case plant::EventKind::SolenoidStroke:
      return rec::SolenoidStroke{r, e.gun};
    case plant::EventKind::GunEmpty:
      return rec::GunEmpty{r, e.gun};
    case plant::EventKind::GunMisfire:
      return rec::GunMisfire{r, e.gun};
    case plant::EventKind::GunJammed:
      return rec::GunJammed{r, e.gun};
    case plant::EventKind::DiscShooter:
      return rec::DiscShooter{r, -1};
  }
  throw std::logic_error("plant event without a trace record");
}

void Match::handlePlantEvents(Tick t, const plant::EventList& events) {
  for (const auto& e : events) {
    if (config_.observer) config_.observer->onPlantEvent(t, e);
    if (e.kind == plant::EventKind::EdgeEnter || e.kind == plant::EventKind::EdgeLeave) {
      Robot& r = *robots_[static_cast<size_t>(e.robot)];
      // Fore detector on port A bit 1, aft on bit 0; low within range.
      const uint8_t bit = e.detector == plant::Detector::Fore ? 0x02 : 0x01;
      if (e.kind == plant::EventKind::EdgeEnter)
        r.plantLow |= bit;
      else
        r.plantLow &= static_cast<uint8_t>(~bit);
      // The plant's record first, then the port's (in emission order).
      if (trace_.on()) emit(t, plantRecord(e));
      r.updateEdgeLines(t);
      continue;
    }
    if (trace_.on()) emit(t, plantRecord(e));
  }
}

// Trace samples at fixed ticks, read from dense output once the plant has
// passed them and before any input discards that part of the trajectory.
void Match::sampleUpTo(Tick t) {
  if (!trace_.on()) return;
  const Tick limit = std::min(t, arena_.now());
  while (nextSample_ <= limit) {
    if (nextSample_ >= arena_.lastReinitTick()) {
      for (int i = 0; i < arena_.robotCount(); ++i) {
        const plant::RobotState s = arena_.state(i, nextSample_);
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
  MatchResult result;
  if (trace_.on()) emitSetup();
  Tick roundStart = 0;
  clock_.start();
  try {
    rounds(result, roundStart);
  } catch (const plant::SolverError& e) {
    // The plant cannot go on: the run ends where the failing round began,
    // with everything before it kept.
    result.plantFault = FaultInfo{e.what(), timebase::secondsFromTicks(roundStart), 0};
    result.endTick = roundStart;
    if (trace_.on()) emit(roundStart, trace::rec::PlantFault{e.what()}, {});
  }
  clock_.stop();
  result.parts = clock_.times();
  finish(result);
  return result;
}

void Match::rounds(MatchResult& result, Tick& roundStart) {
  bool over = false;
  while (!over) {
    ++rounds_;
    if (config_.stop && config_.stop->load(std::memory_order_relaxed)) throw Stopped();
    const Tick t = earliestClock();
    roundStart = t;
    if (trace_.on()) trace_.flushBefore(std::min(t, arena_.now()));
    Tick horizon = std::min(queue_.nextTick(), t + kLookahead);
    // The plant goes further than the first sub-round when no ball is in
    // flight (header comment: "Larger rounds").
    const Tick plantStop =
        arena_.ballsInFlight() ? horizon : std::min(queue_.nextTick(), t + kRoundLookahead);
    // (Lambdas, here and below, so that the results are built in place.)
    plant::AdvanceResult step = [&] {
      const PartScope plant(clock_, PartClock::Plant);
      return arena_.advance(plantStop);
    }();
    for (;;) {
      horizon = std::min(horizon, step.tick);
      {
        const PartScope vms(clock_, PartClock::Vm);
        for (auto& r : robots_) r->runTo(horizon);
      }
      if (horizon == step.tick || !inputs_.empty() || queue_.nextTick() == horizon ||
          (config_.stopWhenAllExited && allExited()))
        break;
      sampleUpTo(horizon);  // before the next sub-round's records, as between rounds
      ++subRounds_;
      horizon = std::min(queue_.nextTick(), earliestClock() + kLookahead);
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
      applyInputs();
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
        case QueuedEvent::Kind::ReleaseEdge: {
          Robot& r = *robots_[static_cast<size_t>(entry.payload.robot)];
          r.injectedLow &= static_cast<uint8_t>(~entry.payload.index);
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

void Match::faulted(int robot, Tick t) {
  if (!config_.reloadOnFault) return;
  const Tick at = t + config_.reloadDelay;
  if (at >= config_.endTick) return;  // the run is over before the reload
  robots_[static_cast<size_t>(robot)]->reloadPending = true;
  queue_.schedule(at, EventClass::Reload, {QueuedEvent::Kind::Reload, robot, 0});
}

void Match::finish(MatchResult& result) {
  result.rounds = rounds_;
  result.warnings = warnings_;
  for (size_t k = 0; k < fired_.size(); ++k) {
    if (fired_[k]) continue;
    const Injection& in = config_.injections[k];
    const RobotSpec& robot = config_.robots[static_cast<size_t>(in.robot)];
    result.warnings.push_back(
        in.line > 0
            ? fmt::format("--inject {} never fired: {} of {} ran {} time(s) before the run ended",
                          in.text,
                          in.pass ? "the loop on line " + std::to_string(in.line)
                                  : "line " + std::to_string(in.line),
                          robot.program, hitsAt(in, injectionAddress_[k]))
            : fmt::format("--inject {} never fired: the run ended at {:.6f} s", in.text,
                          timebase::secondsFromTicks(result.endTick)));
  }
  result.integrator = arena_.stats();
  for (auto& r : robots_) {
    RobotResult rr = r->result;
    rr.hits = arena_.hits(r->index);
    rr.shots = arena_.shots(r->index);
    // The clock at main's return, or at the end of the run: a VM's clock
    // runs on to the last round's horizon after main returns, and may stand
    // one instruction past the end.
    rr.cycles = static_cast<uint64_t>(rr.exited ? rr.exitTick : std::min(r->now(), result.endTick));
    rr.vmClock = static_cast<uint64_t>(r->now());
    rr.vmInstructions = r->vm().stats().instructions + r->earlierInstructions;
    rr.vmFastForwarded = r->vm().stats().fastForwarded + r->earlierFastForwarded;
    if (config_.profile) {
      rr.profile = r->vm().profile();
      rr.profile.resize(std::max(rr.profile.size(), r->earlierProfile.size()));
      for (size_t a = 0; a < r->earlierProfile.size(); ++a) rr.profile[a] += r->earlierProfile[a];
      rr.serialIsrCycles = r->vm().serialIsrCycles() + r->earlierSerialIsrCycles;
      rr.timerIsrCycles = r->vm().timerIsrCycles() + r->earlierTimerIsrCycles;
    }
    for (vm::Irq irq : {vm::Irq::Pio, vm::Irq::Timer, vm::Irq::SerialTx})
      rr.interrupts[std::string(vm::irqName(irq))] += r->interruptCounts[static_cast<size_t>(irq)];
    // After a plant fault the plant answers only from its last re-initialisation.
    rr.finalPose =
        arena_.pose(r->index, std::clamp(result.endTick, arena_.lastReinitTick(), arena_.now()));
    result.robots.push_back(std::move(rr));
  }
  if (result.robots.size() == 2) {
    const int a = result.robots[0].hits, b = result.robots[1].hits;
    const bool faultA = result.robots[0].fault.has_value();
    const bool faultB = result.robots[1].fault.has_value();
    if (a != b) {
      result.winner = a > b ? "A" : "B";
    } else if (faultA != faultB) {
      result.winner = faultA ? "B" : "A";  // a robot that faulted loses a tied round
    } else {
      result.tieBrokenByCoin = true;
      result.winner = (coin_.next() >> 63) ? "B" : "A";
    }
  }
  if (trace_.on()) {
    for (const auto& rr : result.robots) {
      const int i = &rr - result.robots.data();
      emit(result.endTick,
           trace::rec::RobotResult{i, rr.hits, rr.shots, rr.framesLatched, rr.framesRejected,
                                   rr.framesOverwritten, static_cast<int64_t>(rr.cycles),
                                   rr.fault.has_value(), rr.reloads, rr.exited},
           {});
    }
    emit(result.endTick, trace::rec::End{result.winner, result.tieBrokenByCoin}, {});
  }
  trace_.close();
}

}  // namespace

namespace {

// A non-negative decimal number of `unit`s as an exact tick count: digits
// are scaled as integers so that "12.5s" is exactly 115,200,000 ticks.
Tick parseDuration(const std::string& digits, int64_t ticksPerUnit, const std::string& whole) {
  const auto bad = [&] {
    return std::invalid_argument("'" + whole +
                                 "': WHEN must be a time (12.5s, 800ms), a tick (115200000t) "
                                 "or a program point (line:N#K, pass:N#K)");
  };
  if (digits.empty()) throw bad();
  int64_t integer = 0, fraction = 0, scale = 1;
  bool point = false;
  for (char ch : digits) {
    if (ch == '.' && !point) {
      point = true;
      continue;
    }
    if (ch < '0' || ch > '9') throw bad();
    if (integer > 1'000'000'000 || scale > 1'000'000'000) throw bad();
    if (point) {
      fraction = fraction * 10 + (ch - '0');
      scale *= 10;
    } else {
      integer = integer * 10 + (ch - '0');
    }
  }
  const int64_t ticks = integer * ticksPerUnit + fraction * ticksPerUnit / scale;
  if (fraction * ticksPerUnit % scale != 0)
    throw std::invalid_argument("'" + whole + "' is not a whole number of ticks");
  return ticks;
}

int parsePositive(const std::string& s, const std::string& whole, const char* what) {
  if (s.empty() || s.size() > 9 || s.find_first_not_of("0123456789") != std::string::npos ||
      std::stoi(s) <= 0)
    throw std::invalid_argument("'" + whole + "': " + what + " must be a positive integer");
  return std::stoi(s);
}

}  // namespace

Injection parseInjection(const std::string& text, int robotCount) {
  Injection in;
  in.text = text;
  const auto colon = text.find(':');
  const auto at = text.find('@');
  if (colon == std::string::npos || at == std::string::npos || at < colon)
    throw std::invalid_argument("'" + text + "': expected ROBOT:SOURCE@WHEN");
  const std::string robot = text.substr(0, colon);
  const std::string source = text.substr(colon + 1, at - colon - 1);
  const std::string when = text.substr(at + 1);
  if (robot == "A")
    in.robot = 0;
  else if (robot == "B" && robotCount > 1)
    in.robot = 1;
  else
    throw std::invalid_argument("'" + text + "': no robot '" + robot + "' in this run");
  if (source == "edge_fore")
    in.source = InjectSource::EdgeFore;
  else if (source == "edge_aft")
    in.source = InjectSource::EdgeAft;
  else if (source == "bumper_front")
    in.source = InjectSource::BumperFront;
  else if (source == "bumper_back")
    in.source = InjectSource::BumperBack;
  else
    throw std::invalid_argument("'" + text +
                                "': SOURCE must be edge_fore, edge_aft, "
                                "bumper_front or bumper_back");
  const bool pass = when.rfind("pass:", 0) == 0;
  if (when.rfind("line:", 0) == 0 || pass) {
    const auto hash = when.find('#');
    if (hash == std::string::npos)
      throw std::invalid_argument("'" + text + "': a program point is line:N#K or pass:N#K");
    in.pass = pass;
    in.line = parsePositive(when.substr(5, hash - 5), text, "the line N");
    in.count = parsePositive(when.substr(hash + 1), text, "the execution count K");
  } else if (when.size() > 2 && when.compare(when.size() - 2, 2, "ms") == 0) {
    in.tick = parseDuration(when.substr(0, when.size() - 2), kTicksPerSecond / 1000, text);
  } else if (!when.empty() && when.back() == 's') {
    in.tick = parseDuration(when.substr(0, when.size() - 1), kTicksPerSecond, text);
  } else if (!when.empty() && when.back() == 't') {
    in.tick = parseDuration(when.substr(0, when.size() - 1), 1, text);
  } else {
    parseDuration("", 1, text);  // throws the WHEN message
  }
  return in;
}

std::optional<uint32_t> loopHead(const vm::Image& image, int line) {
  std::optional<uint32_t> head;
  const auto& code = image.code;
  for (uint32_t at = 0; at < code.size();) {
    if (code[at] >= vm::kOpCount) return head;  // not code: the walk cannot go on
    const auto op = static_cast<vm::Op>(code[at]);
    const auto size = static_cast<uint32_t>(vm::instructionSize(op));
    if (at + size > code.size()) break;
    if (vm::info(op).shape == vm::Shape::REL16 && image.lineAt(at) == line) {
      const auto rel = static_cast<int16_t>(code[at + 1] | (code[at + 2] << 8));
      const int64_t target = int64_t{at} + size + rel;
      if (target >= 0 && target <= at && image.lineAt(static_cast<uint32_t>(target)) == line &&
          (!head || target < *head))
        head = static_cast<uint32_t>(target);
    }
    at += size;
  }
  return head;
}

uint64_t streamSeed(uint64_t seed, const std::string& purpose) {
  // FNV-1a of the purpose, mixed with the master seed through SplitMix64.
  uint64_t h = 1469598103934665603ull;
  for (char c : purpose) h = (h ^ static_cast<uint8_t>(c)) * 1099511628211ull;
  plant::SplitMix64 mix(seed ^ h);
  return mix.next();
}

MatchResult runMatch(const MatchConfig& config) {
  Match match(config);
  return match.run();
}

}  // namespace simbot::scheduler
