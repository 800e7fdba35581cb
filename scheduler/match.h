// The scheduler: runs one match (or a solo run) of robot programs in the
// arena, interleaving their VMs with the serial links, the PIO, the guns and
// the plant's continuous motion. It owns time; the VMs know nothing of
// robots and the plant knows nothing of bytecode.
//
// Co-simulation protocol, one round at a time (t = the earliest VM clock):
//   1. h = min(next queued event, a + 9,600), where a >= t is the earliest
//      tick at which a VM can act (Vm::quietUntil: its clock, or, while it
//      runs a delay loop fast-forward has measured, the arrival at the
//      loop's top where the compare fails; no bus access or acceptance
//      comes before it unless the host raises a request, at an event). The
//      lookahead of one character time is exact: a robot's program reaches
//      another robot only through a latched motor frame, which happens when
//      a NUL leaves the shift register, at least 9,600 ticks after the byte
//      entered it, which its VM did at or after a; so no event another VM
//      could observe is created inside a round.
//   2. The plant integrates ahead to h; its first root, if earlier, caps h.
//      (Several such rounds share one plant advance when nothing happens
//      between them: match.cpp, "Larger rounds"; MatchResult::rounds counts
//      the plant's rounds. A robot that runs alone takes such sub-rounds
//      in one run of its VM: rule (7) there.)
//   3. Each VM runs to h (every instruction starting before h; bus accesses
//      happen at boundaries before h). Port reads see device state as of the
//      last processed event; eye readings come from dense output at their
//      exact tick. Port B writes are collected.
//   4. Port B writes go to the plant in tick order (they may re-initialise
//      the integrator at their tick; robot motion does not depend on them).
//   5. Plant events at h, then queued events at h, in the queue's order
//      (event_queue.h); interrupt requests they cause are raised at h, so
//      each is accepted at the first boundary at or after h.
// Trace samples never move a horizon: they are read from dense output after
// the fact, so a run with --trace gives the same results as one without.
// A traced VM stops at each sample tick (run(until) executes the same
// instructions whether it is stopped there or not) so that the sample can
// say where the program was.
//
// The trace (trace/trace.h): records are emitted as the round loop learns of
// them and handed to the sinks in tick order. At the start of a round no
// record can come before min(earliest VM clock, the plant's clock): every VM
// event is at or after its VM's clock, every plant event after the plant's,
// and samples up to the plant's clock were taken at the end of the last
// round. Records before that bound are written then.
#pragma once
#include <array>
#include <atomic>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "board/settings.h"
#include "plant/plant.h"
#include "timebase/tick.h"
#include "trace/trace.h"
#include "vm/cost.h"
#include "vm/image.h"
#include "vm/vm.h"

namespace simbot::scheduler {

// The clock is defined once, in timebase/tick.h.
using timebase::kTicksPerSecond;
using timebase::Tick;

// One leg of a scripted drive: the wheels' ground speeds for a duration.
struct DriveLeg {
  Tick duration = 0;  // > 0
  double leftFps = 0, rightFps = 0;
};

// A robot's controller settings (the profile's [controller]; config/ reads
// them): its board's own.
using ControllerKnobs = board::Settings;

struct RobotSpec {
  RobotSpec() = default;
  RobotSpec(std::string name_, std::string program_, vm::Image image_)
      : name(std::move(name_)), program(std::move(program_)), image(std::move(image_)) {}

  std::string name;     // "A", "B"
  std::string program;  // path as given
  vm::Image image;
  // A beacon on a scripted path (its program does nothing): the legs start
  // at tick 0, each at the exact tick the previous one ends; after the last
  // the robot stops, or the path starts over with `repeatPath`.
  std::vector<DriveLeg> path;
  bool repeatPath = false;
  ControllerKnobs controller;
};

// An interrupt source injected by the user (DESIGN.md tool contract;
// config::parseInjection reads --inject's text).
// Reset: the board's reset at that tick (a "fried" board, DESIGN.md "The
// wider competition"): the program starts again from main at once.
enum class InjectSource : uint8_t { EdgeFore, EdgeAft, BumperFront, BumperBack, Reset };

struct Injection {
  int robot = 0;
  InjectSource source = InjectSource::EdgeFore;
  // When: at `tick`, or (line > 0) at the `count`-th execution of the first
  // instruction the line table gives for `line` (line:N#K: it counts entries
  // into the line), or with `pass` at the `count`-th time control reaches the
  // head of the loop written on that line (pass:N#K: it counts passes), at
  // the boundary before it.
  Tick tick = 0;
  int line = 0;
  int count = 1;
  bool pass = false;
  std::string text;  // as the user wrote it, for the trace
};

// An injected edge holds its detector low for this long (assumption, DESIGN).
inline constexpr Tick kInjectedEdgePulse = kTicksPerSecond / 20;  // 50 ms

// Optional hooks for measurements (simbot bench). Called from the round loop
// at the exact tick of each happening; an observer only reads, so a run with
// one gives the same results as one without. Per robot, eye reads and frames
// arrive in tick order; plant events may arrive after later eye reads.
struct MatchObserver {
  virtual ~MatchObserver() = default;
  virtual void onEyeRead(int /*robot*/, Tick, int /*channel*/, int /*value*/) {}
  virtual void onInterruptAccepted(int /*robot*/, Tick, vm::Irq) {}
  virtual void onFrame(int /*robot*/, Tick, bool /*latched*/) {}
  virtual void onPlantEvent(Tick, const plant::Event&) {}
  // The robots' poses at the trace's sample ticks (every sample interval,
  // the same ticks and values as the trace's sample records), and the
  // program's faults, exits (main returned) and reloads, at their records'
  // ticks. Called in the order the simulation learns of them, which is not
  // always tick order: an observer that needs tick order sorts them (stably:
  // within a tick this is the trace's order).
  virtual void onPose(int /*robot*/, Tick, double /*x_ft*/, double /*y_ft*/) {}
  virtual void onHalt(int /*robot*/, Tick) {}
  virtual void onReload(int /*robot*/, Tick) {}
};

// What a debugger sees of a match stopped at one of its robot's
// instruction boundaries (DebugHook) or over (MatchRun::view).
class MatchView {
 public:
  virtual ~MatchView() = default;
  virtual int robotCount() const = 0;
  virtual const vm::Vm& vm(int robot) const = 0;
  virtual const RobotSpec& spec(int robot) const = 0;
  // The arena at `t` (a tick the plant has reached and not left behind:
  // the debugged robot's clock at a stop): each robot's pose, wheel speeds,
  // last eye readings, port lines, the latched motor command and the
  // serial link, one line per item.
  virtual std::string describe(Tick t) const = 0;
  // The robots' poses at `t` (as describe's).
  virtual plant::Pose pose(int robot, Tick t) const = 0;
};

// Happenings a debugger may stop at (break on an event).
enum class DebugEvent : uint8_t { FrameLatched, EdgeAccepted, Contact, Shot, Fault };
std::string_view debugEventName(DebugEvent e);  // "frame", "edge", "contact", "shot", "fault"

// A debugger's hold on one robot (simbot debug; MatchConfig::debugger).
// The match calls boundary() at that robot's instruction boundaries
// inside the rounds, at the exact tick, with the other robots run up to
// othersTo(its clock) first (each to its first boundary at or after that
// tick): before every instruction while stepping(), else at the first
// boundary at or after until(), at its VM's breakpoints, after an event()
// that asked to look, and at its fault. boundary() may throw: the match
// is then abandoned (the debugger restores a snapshot). On return the
// robot goes on: stepping() must be true or until() past its clock.
// Nothing here changes what the match does.
class DebugHook {
 public:
  virtual ~DebugHook() = default;
  virtual bool stepping() const = 0;
  virtual Tick until() const = 0;
  // The tick the other robots are brought to when the debugged robot
  // stops at `clock`: `clock` itself, or an earlier tick when the hold
  // moved to this robot from another that stopped there (the robots then
  // stand where they stood, none of them run on).
  virtual Tick othersTo(Tick clock) const { return clock; }
  // Whether a look first makes a library call's effect due at the robot's
  // clock happen (Vm::settle: the boundary after the call, where a step
  // ends); else the robot is looked at as it is at that tick, the effect
  // still to come after the events of the tick (where a time is gone to).
  virtual bool settles() const { return stepping(); }
  virtual void boundary(const MatchView& view) = 0;
  // At tick t (inside or between the rounds); true: look at the debugged
  // robot's next boundary.
  virtual bool event(int robot, Tick t, DebugEvent e) = 0;
  // Another robot stopped at one of its VM's breakpoints (MatchRun::
  // setDebugBreakpoints), at its boundary inside a round.
  virtual void otherBreakpoint(const MatchView& view, int robot) = 0;
  // While watching(robot), another robot runs one instruction at a time and
  // otherBoundary() looks at each of its boundaries (a data breakpoint on
  // it); a library call's effect due there is made to happen first, as in
  // a step. otherBoundary() may throw as boundary() does.
  virtual bool watching(int /*robot*/) const { return false; }
  virtual void otherBoundary(const MatchView& /*view*/, int /*robot*/) {}
};

struct MatchConfig {
  std::vector<RobotSpec> robots;  // 1 (solo) or 2
  plant::ArenaConfig arena;
  Tick endTick = 180 * kTicksPerSecond;
  uint64_t seed = 1;
  bool stopWhenAllExited = false;  // solo: until main returns
  vm::CostKnobs knobs = vm::calibratedKnobs();
  std::vector<Injection> injections;
  std::vector<std::string> watches;  // variables added to trace records
  bool traceCostate = false;         // costate records (--trace-costate)
  bool profile = false;              // per-instruction cycle counts (simbot profile)
  // The trace goes to each sink (not owned), in tick order; none: no trace
  // is built at all.
  std::vector<trace::Sink*> sinks;
  std::string profileName;                     // for the trace's run record
  std::string rulesName, rulesFile;            // for the trace's rules record (--rules)
  Tick sampleInterval = kTicksPerSecond / 20;  // trace samples: 20 Hz
  MatchObserver* observer = nullptr;           // not owned; may be null
  // Checked once a round: when it becomes true the run throws Stopped (a
  // batch command stopping on SIGINT). Not owned; may be null.
  const std::atomic<bool>* stop = nullptr;
  // Thesis Appendix A, "you will be allowed to reload if the system
  // crashes": a robot that faults is reloaded `reloadDelay` ticks later (the
  // profile's [match] reload_delay). Its VM starts again from main with
  // memory as at load (the power-on fill rules of the start), its PIO and
  // serial port reset; the motor controller, a separate board, keeps the
  // last latched command meanwhile. No reload is done at or after the end.
  bool reloadOnFault = false;
  Tick reloadDelay = 0;  // at least kMinReloadDelay
  // Measure the wall time spent in the VMs, the plant and the scheduler
  // (MatchResult::parts; bench/match_bench). Off: no clock is read.
  bool timeParts = false;
  // The run can be copied (MatchRun): the plant keeps the journal its copy
  // replays. Off: nothing is kept.
  bool snapshots = false;
  // simbot debug: the hook that holds robot `debugRobot` (not owned; needs
  // snapshots). That robot runs first in each round.
  DebugHook* debugger = nullptr;
  int debugRobot = 0;
};

// A reload waits at least this long, so that the bytes a faulted robot's
// serial port still held (two characters) are on the wire before its port
// is reset.
inline constexpr Tick kMinReloadDelay = 2 * timebase::kTicksPerChar;

// A run abandoned because MatchConfig::stop became true.
struct Stopped : std::runtime_error {
  Stopped() : std::runtime_error("stopped") {}
};

struct FaultInfo {
  std::string message;
  double timeS = 0;
  int line = 0;
  int depth = 0;      // calls and handlers under way (the trace's fault record)
  std::string calls;  // their chain, ending at the fault: main:12 > deep:7 x 251
};

// A robot's secondary weapon (plant::Hardware::secondary) when the run
// ended: discs sent and hits, counted apart from the guns' shots and hits.
struct SecondaryResult {
  std::string kind;  // "disc"
  int shots = 0, hits = 0;
};

struct RobotResult {
  std::string name, program;
  int hits = 0, shots = 0;
  // Detect to Engage (the arena's referee judge_scatter): launches with
  // neither eye above the rules' threshold. None when no rules judge them.
  std::optional<int> scatterShots;
  std::optional<SecondaryResult> secondary;  // none without a secondary weapon
  // Items of [[deployables]] set down, by plant::DeployKind (block, decoy
  // light, decoy screen); zeros without any.
  std::array<int, 3> deployed{};
  double blockPushFt = 0;  // blocks this robot pushed, ft (plant/arena_blocks.cpp)
  int framesLatched = 0, framesRejected = 0;
  // Sends that restarted the serial library before it had fetched the last
  // byte of the previous send (its NUL): that frame can never latch.
  int framesOverwritten = 0;
  std::map<std::string, uint64_t> interrupts;  // per source
  uint64_t cycles = 0;  // the clock at main's return, or at the end of the run
  // The VM's own clock when the run ended: all it charged, including the
  // instruction straddling the end and anything after main returned
  // (interrupt handlers, halted time up to the end of the run; a run that
  // stops at main's return ends at its HALT). simbot profile adds up to
  // this.
  uint64_t vmClock = 0;
  // Bytecode instructions run (library steps included), and of those the
  // ones fast-forward applied without dispatching them. The second depends
  // on where the run was stopped (a trace's samples stop it more often), so
  // it is a benchmark figure, not part of a run's result.
  uint64_t vmInstructions = 0;
  uint64_t vmFastForwarded = 0;
  std::optional<FaultInfo> fault;  // the first fault
  std::vector<FaultInfo> faults;   // every fault, in order (more than one after reloads)
  int reloads = 0;                 // MatchConfig::reloadOnFault
  // Board resets by cause: the battery browned out, or --inject A:reset@WHEN.
  int resetsBrownOut = 0, resetsInjected = 0;
  // The battery's terminal voltage when the run ended (none: no battery).
  std::optional<double> batteryVFinal;
  plant::Pose finalPose;
  std::vector<std::string> console;
  bool exited = false;
  Tick exitTick = 0;
  // With MatchConfig::profile: T-states charged at each code address
  // (interrupt acceptance to the handler's first instruction), and those
  // of the serial library's transmit interrupts.
  std::vector<uint64_t> profile;
  uint64_t serialIsrCycles = 0;
  uint64_t timerIsrCycles = 0;  // the BIOS timer service (PRT0)
};

// Wall seconds of a run by part (MatchConfig::timeParts): the VMs running
// (without the plant queries they make), the plant (integration, inputs,
// eye readings), and the scheduler (everything else: round loop, queue,
// trace). Zero when not measured.
struct PartTimes {
  double vm_s = 0, plant_s = 0, scheduler_s = 0;
};

struct MatchResult {
  Tick endTick = 0;
  std::vector<RobotResult> robots;
  plant::IntegratorStats integrator;
  std::string winner;  // "A"/"B"; empty for solo
  bool tieBrokenByCoin = false;
  uint64_t rounds = 0;
  // The integrator failed (plant::SolverError): the run ended at the start
  // of the round that failed, and this says why (line is 0).
  std::optional<FaultInfo> plantFault;
  // Findings about the run's set-up that did not stop it (injections that
  // never fired, a line:N#K on a line that holds a whole loop), one line
  // each, for the tools to print as warnings.
  std::vector<std::string> warnings;
  PartTimes parts;
};

MatchResult runMatch(const MatchConfig& config);

namespace detail {
class Match;
struct MatchState;
}  // namespace detail

// A match that stops between rounds and is a value: a copy (a snapshot)
// holds everything of it, both boards, the scheduler's queue, the plant,
// every random stream and the trace records not yet written, and goes on
// byte for byte as the original would; the copy writes to the same trace
// sinks. Needs MatchConfig::snapshots (the plant keeps its journal: a
// copy replays it, arena.cpp).
class MatchRun {
 public:
  explicit MatchRun(const MatchConfig& config);
  MatchRun(const MatchRun& other);
  MatchRun& operator=(const MatchRun& other);
  ~MatchRun();
  // Runs every round that starts before `tick`; false once the match is over.
  bool runUntil(Tick tick);
  // Where the next round starts (every robot's clock is at or past it).
  Tick now() const;
  // Runs to the end: the result, as runMatch's.
  MatchResult finish();
  // The state between rounds (after runUntil returned), for a debugger.
  const MatchView& view() const;
  // A debugger's breakpoints in robot `robot`'s program (code addresses):
  // they replace its earlier ones; the match's own (main's return, line
  // injections) stay.
  void setDebugBreakpoints(int robot, const std::vector<uint32_t>& addresses);

  // A snapshot holds only what changes: both boards (not their programs,
  // which every copy shares) and the scheduler's state, and of the plant a
  // mark in its journal (Arena::Mark), nothing built; restoring it replays
  // the plant. The snapshot stays valid whatever this run does later,
  // restores included.
  class Snapshot {
   public:
    Snapshot(Snapshot&&) noexcept;
    Snapshot& operator=(Snapshot&&) noexcept;
    ~Snapshot();
    Tick now() const;  // the snapshot's MatchRun::now()
    Tick robotClock(int robot) const;
    bool robotFaulted(int robot) const;

   private:
    friend class MatchRun;
    Snapshot();
    std::unique_ptr<detail::MatchState> state_;
    plant::Arena::Mark mark_;
  };
  Snapshot snapshot() const;
  // With a debugger, it then looks at its robot's first boundary.
  void restore(const Snapshot& snapshot);

 private:
  std::unique_ptr<detail::Match> match_;
};

// Seeded stream for one purpose (DESIGN.md: one generator per purpose).
uint64_t streamSeed(uint64_t seed, const std::string& purpose);

}  // namespace simbot::scheduler
