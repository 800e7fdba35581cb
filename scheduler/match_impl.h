// scheduler/match_impl.h -- internal: the classes of one match.
//
// A match is its round loop (Match, match.cpp; its result, match_result.cpp)
// and its robots, each a board (board/board.h: the VM and the devices its
// program talks to) and what the match keeps of it (Robot). The robot's
// bus -- how a VM's port writes, A/D reads, serial library calls and interrupt
// notifications become plant inputs, queued events and trace records -- is
// in robot_bus.cpp, apart from the round loop; both see these classes, in
// namespace detail. Nothing outside scheduler/ includes this header.
#pragma once

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <deque>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "board/board.h"
#include "inspect/inspect.h"
#include "plant/battery.h"
#include "plant/motor_receiver.h"
#include "scheduler/event_queue.h"
#include "scheduler/match.h"
#include "scheduler/part_clock.h"

namespace simbot::scheduler::detail {

constexpr Tick kLookahead = timebase::kTicksPerChar;
// How far the plant integrates ahead in one round (header comment, "Larger
// rounds"): eight character times. Integration past an input's tick is
// thrown away at the input, so this bounds the work wasted per input.
constexpr Tick kRoundLookahead = 8 * timebase::kTicksPerChar;
// The same in a solo run (header comment of match.cpp, (8)): its robot's
// sub-rounds chain (rule (7)), so a round's end is most of what a round
// costs, and only its own inputs end a round early. Sixty-four
// characters: the pure-compute comparison programs (bench/vs_lua.py) 4-8 %
// less CPU time than with eight.
constexpr Tick kSoloRoundLookahead = 64 * timebase::kTicksPerChar;

// Queued events; the plant's own events come from Arena::advance.
struct QueuedEvent {
  enum class Kind : uint8_t {
    SerialByte,
    DriveLeg,
    Inject,
    ReleaseEdge,
    Reload,
    Power,  // index kBrownOutCheck or kRestart (power.cpp)
    EndOfRound
  } kind;
  int robot = 0;
  int index = 0;  // injection number, path leg, the detector bit to release, or a power event
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
  // The robot's watched variables at `tick` (traced runs that watch some):
  // the plant's records of this input are made after the robot has run on
  // to the round's end, and carry the values of their own tick.
  trace::Watch watch = {};
};

class Match;

// A robot on a scripted path follows it exactly: its wheels have no lag.
// The arena this match plays in: the configured one with this seed's
// variation (DESIGN.md), each purpose drawn from its own stream of (seed,
// purpose, robot): the hand placement, then each robot's wheel trims.
plant::ArenaConfig arenaConfigFor(const MatchConfig& config);

// One robot: its board (the VM, the devices its program talks to, its
// counters), the motor controller's receiver, and what the match keeps of
// it (injections, watches, samples, its result). Robot is the board's bus.
class Robot : public vm::Bus {
 public:
  Robot(Match& match, int index, const RobotSpec& spec, const vm::CostTable& costs, uint64_t seed);
  // A robot is a value: its copy is the compiler's, so that a member added
  // later is copied with the rest. A copy belongs to no match and its board
  // talks to no bus until the match that holds it attaches it.
  Robot(const Robot&) = default;
  Robot& operator=(const Robot&) = delete;
  void attach(Match& match);

  // The robot's clock (match ticks) and its program's VM.
  Tick now() const { return board.cpu.now(); }
  Tick quietUntil() const { return board.cpu.quietUntil(); }
  vm::Vm& vm() { return board.cpu; }
  const vm::Vm& vm() const { return board.cpu; }
  // --reload-on-fault: the controller's reset at t; the faulted program
  // starts again.
  void reload(Tick t);
  // The board's reset at t, as at power-on (reload, a brown-out's end, an
  // injected reset): the program starts again from main.
  void restartProgram(Tick t);
  // Power (power.cpp, docs/plant.md "Batteries"): the robot's battery (none
  // when its profile has no battery, or it follows a scripted path), the
  // board held in reset by a brown-out, and what draws current: the motor
  // controller's latched command, its bumper reflex, port B.
  std::optional<plant::Battery> battery;
  bool powerOff = false;
  plant::MotorFrame motorCommand{};
  bool reflexOn = false;
  uint8_t portB = 0;
  Tick brownOutCheckAt = -1;  // the earliest brown-out check queued, or -1
  Tick restartAt = -1;        // the end of the brown-out's reset, or -1
  // The VM runs (not faulted, not held in reset).
  bool running() const { return !board.cpu.fault() && !powerOff; }
  bool reloadPending = false;
  bool faultSeen = false;  // this VM's fault is recorded
  // Sat out a sub-round, quiet past its horizon (match.cpp "Larger
  // rounds", (6)): its clock is behind until it next runs.
  bool behind = false;

  // vm::Bus
  void out(Tick t, uint16_t port, uint8_t value) override;
  uint8_t in(Tick t, uint16_t port) override;
  int adSample(Tick t, int channel) override;
  void emitScreenHides(Tick t, int item, bool hidden);
  void serialSend(Tick t, uint16_t buf, uint16_t cc) override;
  void serialTxService(Tick t, vm::Vm& v) override;
  void console(Tick t, std::string_view line) override;
  void interruptAccepted(Tick t, vm::Irq irq, uint32_t pc) override;
  void interruptReturned(Tick t, vm::Irq irq) override;
  void iffChanged(Tick t, bool iff1) override;
  bool wantCostateEvents() const override;
  void costate(Tick t, uint16_t coData, CostateEvent e, int line) override;

  // Runs the VM to `horizon` (its clock ends at or after it). With `more`
  // (a robot that runs alone, with no trace and no debugger), through the
  // sub-rounds after it that `more` gives (match.cpp, rule (7) of "Larger
  // rounds"), which `horizon` follows.
  void runTo(const Tick& horizon, vm::Continuation* more = nullptr);
  // The same for the robot a debugger holds (MatchConfig::debugger).
  void debugRunTo(Tick horizon);
  void noteFault();                        // the VM faulted: record it once
  void noteBreakpoint();                   // the VM stopped at one of the match's breakpoints
  void look(scheduler::DebugHook& hook);   // the debugger looks at this boundary
  bool debugLook = false;                  // an event asked the debugger to look
  std::vector<uint32_t> debugBreakpoints;  // MatchRun::setDebugBreakpoints
  // An event for the debugger at t: if it wants to look, at the next
  // boundary of the robot it holds.
  void debugEvent(Tick t, DebugEvent e);
  void byteDone(Tick t);
  // Port A's edge lines: low while the plant says so or an injection holds.
  void updateEdgeLines(Tick t);
  void inject(Tick t, const Injection& injection);
  std::map<uint32_t, std::vector<int>> lineInjections;  // code address -> injections
  // Executions of each injection point, over the whole run (a reload does
  // not restart the count).
  std::map<uint32_t, int> lineHits;
  // A global or static read directly, or (`expression`) any lvalue the
  // debugger's print takes, read from the innermost frame.
  struct Watch {
    std::string name;
    uint16_t address;
    vm::Symbol::Value value;
    std::shared_ptr<const inspect::Expression> expression;
  };
  std::vector<Watch> watches;
  trace::Watch watchedValues() const;
  // The values a record at tick t made now carries, in a traced run that
  // watches variables (else nothing, no allocation): the memory at the
  // start of tick t (docs/trace.md, "watch"), which is what it holds now
  // unless a library call's effect at t changed it (`tickStart`).
  trace::Watch tracedWatch(Tick t) const;
  std::optional<std::pair<Tick, trace::Watch>> tickStart;
  trace::WatchValue expressionValue(const inspect::Expression& e) const;
  void scheduleSerial(Tick t);

  // Where a send came from (traced runs only, so an untraced run builds no
  // text): its ser_send_z1 call and the call of the function it is in.
  struct SendSite {
    Tick t = -1;  // the send's T0
    int line = 0;
    std::string function;
    int callerLine = 0;
    std::string callerFunction;
    std::string calls;  // the serial_send record's chain
  };
  SendSite sendSite(Tick t) const;
  // "FUNCTION:LINE > ..." of frames, outermost first, " > interrupt > "
  // after a handler's interrupted code, a run of n equal entries written
  // once as "FUNCTION:LINE x n" (a recursion that overflowed the stack).
  std::string chainText(const std::vector<vm::Vm::Frame>& frames) const;
  // The chain and depth of the fault under way (every fault, traced or not:
  // faults are rare): the calls and handlers not yet returned from, then the
  // faulting instruction; depth counts the calls and handlers.
  std::pair<std::string, int> faultChain() const;
  [[gnu::noinline]] void traceSend(Tick t, int count);
  [[gnu::noinline]] void traceOverwrite(Tick t, const board::OverwrittenSend& overwritten);

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
  Match* match;  // the match that holds it (attach)
  // Its clock is the match's; a reload resets it.
  board::Board board;
  plant::MotorReceiver receiver;
  Tick serialEventAt = -1;
  Tick serialIsrAccepted = 0;
  // The watched variables as the serial service found them: its record, made
  // when it returns, is at its acceptance tick (docs/trace.md, "watch").
  trace::Watch serialIsrWatch;
  // The latest send and the one before it: a frame_overwritten names both.
  SendSite lastSend, sendBefore;
  RobotResult result;
  uint32_t mainReturn;
  // --trace-costate: where each costatement (by its CoData's address) rests,
  // so that only its changes of state are recorded (Robot::costate).
  enum class CoRest : uint8_t { Started, FromTop, Waiting, Resumed, Ended };
  struct CoState {
    CoRest rest = CoRest::Started;
    int line = 0;  // Waiting, Resumed: the line it gave way at
  };
  std::map<uint16_t, CoState> costates;
};

// An owning pointer that copies what it owns: a class holding one copies
// with = default, and what it owns keeps its address (a robot is its VM's
// bus).
template <class T>
class Owned {
 public:
  explicit Owned(std::unique_ptr<T> p) : p_(std::move(p)) {}
  Owned(const Owned& other) : p_(std::make_unique<T>(*other.p_)) {}
  Owned(Owned&&) noexcept = default;
  Owned& operator=(const Owned& other) {
    p_ = std::make_unique<T>(*other.p_);
    return *this;
  }
  Owned& operator=(Owned&&) noexcept = default;
  ~Owned() = default;
  T* get() const { return p_.get(); }
  T* operator->() const { return p_.get(); }
  T& operator*() const { return *p_; }

 private:
  std::unique_ptr<T> p_;
};

// All of a match but its plant and the links between its parts (each
// robot's match, its VM's bus): a value whose copy is the compiler's, so
// that a member added later is in every copy and snapshot (the copy test:
// snapshot_test.cpp). A snapshot (MatchRun::Snapshot) is one of these and
// the plant's journal mark.
struct MatchState {
  explicit MatchState(const MatchConfig& config);

  Tick earliestClock() const;
  Tick roundStart() const { return over_ ? result_.endTick : earliestClock(); }

  const MatchConfig& config_;
  // config_.arena with this seed's variation: constant, shared by the copies.
  std::shared_ptr<const plant::ArenaConfig> arenaConfig_;
  trace::Tracer trace_;
  plant::SplitMix64 coin_;
  EventQueue<QueuedEvent> queue_;
  std::vector<Owned<Robot>> robots_;
  std::vector<PlantInput> inputs_;
  std::vector<std::string> warnings_;
  std::vector<bool> fired_;
  std::vector<uint32_t> injectionAddress_;
  bool betweenRounds_ = false;
  // The run so far: runUntil stops between rounds and goes on later.
  bool begun_ = false, over_ = false;
  Tick roundStart_ = 0;  // the tick the current round began at
  // While a round's inputs are applied: its horizon, which every VM has run
  // to (power.cpp takes a brown-out no earlier), else -1.
  Tick inputsHorizon_ = -1;
  MatchResult result_;
  Tick nextSample_ = 0;
  uint64_t rounds_ = 0;
  uint64_t subRounds_ = 0;  // sub-rounds after the first of each round
  PartClock clock_;
  // Detect to Engage (the arena's referee judge_scatter): each robot's
  // scatter shots, which ball slots in flight are scatter shots, and each
  // robot's hits by scatter shots that do not score.
  static constexpr size_t kBallSlots = 128;  // above the arena's 64
  std::array<int, 2> scatterShots_{};
  std::array<int, 2> unscoredHits_{};
  std::array<bool, kBallSlots> scatterBall_{};
};

class Match : public MatchView, private MatchState {
 public:
  explicit Match(const MatchConfig& config);
  // A copy: the state (the compiler's copy), the plant copied by replay
  // (MatchConfig::snapshots), and the links made again.
  Match(const Match& other);
  // The match a snapshot holds: its state and the plant made from its mark.
  Match(const MatchState& state, const plant::Arena::Mark& mark);
  Match& operator=(const Match&) = delete;
  const MatchState& state() const { return *this; }

  // The whole run (runUntil and end).
  MatchResult run();
  static constexpr Tick kNoPause = INT64_MAX;
  // Runs the rounds that start before `pause`; false once the run is over.
  bool runUntil(Tick pause);
  // Runs to the end; the result.
  MatchResult end();
  using MatchState::roundStart;
  // The round loop, until the run is over or the next round would start at
  // or after `pause`.
  void rounds(Tick pause);
  bool serialBytesInRound(Tick horizon);

  plant::Arena& arena() { return arena_; }
  const plant::Arena& arena() const { return arena_; }
  Robot& debugged() { return *robots_[static_cast<size_t>(config_.debugRobot)]; }
  Robot& robot(int i) { return *robots_[static_cast<size_t>(i)]; }
  PartClock& clock() { return clock_; }
  bool tracing() const { return trace_.on(); }
  bool profiling() const { return config_.profile; }
  bool tracingCostates() const { return config_.traceCostate && trace_.on(); }
  // Robot `robot` faulted at t: its reload, if the run asks for one.
  void faulted(int robot, Tick t);
  // Power (power.cpp). What robot `robot` draws changed at t (a latched
  // frame, a port B write, a reflex's start or end): its battery's current,
  // the wheels' supply scale and its next brown-out check.
  void powerChanged(int robot, Tick t);
  // A queued power event of robot `robot` at t.
  void powerEvent(int robot, int what, Tick t);
  // The board's reset at t: by a brown-out (held until the voltage
  // recovers), or injected (the program starts again at t).
  void resetBoard(int robot, Tick t, bool injected);
  void brownOutEnds(int robot, Tick t);
  void queueBrownOutCheck(int robot, Tick t);
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
  void applyReflex(Tick t, int robot, plant::Bumper side, const trace::Watch* watch = nullptr);
  void startLeg(Tick t, int robot, int leg);
  const Injection& injection(int k) const { return config_.injections[static_cast<size_t>(k)]; }
  const std::string& name(int robot) const {
    return config_.robots[static_cast<size_t>(robot)].name;
  }
  MatchObserver* observer() const { return config_.observer; }
  DebugHook* debugger() const { return config_.debugger; }
  int debugRobot() const { return config_.debugRobot; }
  // The robots other than `robot` run up to t (inside a round, before a
  // debugger looks at `robot` at t).
  void bringOthersTo(int robot, Tick t);
  Tick robotClock(int robot) const { return robots_[static_cast<size_t>(robot)]->now(); }

  // MatchView
  int robotCount() const override { return static_cast<int>(robots_.size()); }
  const vm::Vm& vm(int robot) const override { return robots_[static_cast<size_t>(robot)]->vm(); }
  const RobotSpec& spec(int robot) const override {
    return config_.robots[static_cast<size_t>(robot)];
  }
  std::string describe(Tick t) const override;
  plant::Pose pose(int robot, Tick t) const override;

 private:
  // Each robot's match and its VM's bus, and the order they run in.
  void link();
  // Each robot's Vm::quietUntil (match ticks; INT64_MIN for one that has
  // faulted or is held in reset), kept in quiet_ for the horizon it gives
  // (earliestAction) and the sub-round that starts there (sitsOut):
  // nothing runs in between. A robot sitting sub-rounds out keeps its
  // value.
  void noteQuiet();
  // The earliest tick at which a robot that has not faulted can act: the
  // least of quiet_ (the queue's next tick when none can).
  Tick earliestAction() const;
  // Rule (6) of "Larger rounds": whether robot r, quiet past the
  // sub-round's horizon, sits it out.
  bool sitsOut(const Robot& r, Tick horizon) const {
    // Not with a trace (its samples say where each program is) or a
    // debugger (it looks at any robot between rounds).
    // Quiet past a run's overshoot of the horizon too: PRT0's next tick,
    // one bound of quietUntil, may fall inside the run's last instruction.
    return quiet_[static_cast<size_t>(r.index)] >= horizon + vm::kMaxRunOvershoot &&
           !config_.debugger && !trace_.on() && r.now() < horizon;
  }
  // The next sub-round's horizon before the plant's stop caps it:
  // min(next queued event, earliest action + one character time).
  Tick subRoundHorizon() const {
    return std::min(queue_.nextTick(), earliestAction() + kLookahead);
  }
  // Rule (7) of "Larger rounds": the robot that runs alone this
  // sub-round, when its sub-rounds may chain; null otherwise.
  Robot* runsAlone(Tick horizon) const;
  bool ownByteAt(Robot& r, Tick horizon);
  // Its VM's continuation: the next sub-round's horizon as it reaches
  // `horizon` (which it sets), or `horizon` where the round loop has more
  // to do (the plant's stop is `plantTick`).
  struct SubRoundChain final : vm::Continuation {
    Match& match;
    Robot& robot;
    Tick plantTick;
    SubRoundChain(Match& m, Robot& r, Tick& h, Tick p)
        : Continuation(h), match(m), robot(r), plantTick(p) {}
    Tick nextHorizon(Tick reached) override;
  };
  // Robot r at the horizon again after sitting sub-rounds out.
  void catchUp(Robot& r, Tick horizon) {
    if (!r.behind) return;
    r.behind = false;
    r.runTo(horizon);
  }
  bool allExited() const {
    return std::all_of(robots_.begin(), robots_.end(), [](const auto& r) {
      return (r->result.exited || r->vm().fault()) && !r->reloadPending && !r->powerOff;
    });
  }
  void applyInputs();
  bool advancePlantTo(Tick t, plant::AdvanceResult& step);
  void resolveWatches();
  void emitSetup();
  trace::Record plantRecord(const plant::Event& e) const;
  // `watch` (may be null): robot `watchRobot`'s watched variables at t, for
  // its records, when it has run past t since.
  // A launch judged by Detect to Engage (a scatter_shot record), and a
  // hit counted or not by it.
  void judgeLaunch(Tick t, const plant::Event& launch);
  void handlePlantEvents(Tick t, const plant::EventList& events,
                         const trace::Watch* watch = nullptr, int watchRobot = -1);
  void emitPlant(Tick t, const plant::Event& e, const trace::Watch* watch, int watchRobot);
  void sampleUpTo(Tick t);
  void finish(MatchResult& result);

  plant::Arena arena_;
  // The order robots run in a round: the one a debugger holds first.
  std::vector<Robot*> runOrder_;
  std::vector<Tick> quiet_;  // per robot, at the last earliestAction()
  void orderRobots();
  int hitsAt(const Injection& in, uint32_t address) const {
    const auto& hits = robots_[static_cast<size_t>(in.robot)]->lineHits;
    const auto it = hits.find(address);
    return it == hits.end() ? 0 : it->second;
  }
};

}  // namespace simbot::scheduler::detail
