// The debugger: a match (or a solo run) held at one robot's instruction
// boundaries, in simulated time, forwards and backwards (simbot debug,
// simbot dap).
//
// A position is the held robot's clock at one of its instruction
// boundaries: every instruction costs T-states, so the tick names the
// boundary, and a match is deterministic, so it names the whole match's
// state there (the other robot run up to the same tick, the plant's dense
// output at it). Going forward, the match runs with a scheduler::DebugHook
// that stops the held robot where a command says. Going back, the session
// restores the latest snapshot before the target (MatchRun::Snapshot, one
// every kSnapshotInterval of the held robot's time, taken as the run
// first passes it, fewer far from where the session is) and runs forward
// to the target's tick: a state reached backwards is the state reached
// forwards. Commands that look back for a place (reverse-step,
// reverse-continue) first replay the snapshots' windows recording where
// the robot was, then go to the place found.
//
// A Controller (the terminal's command interpreter, the DAP server) is
// asked what to do at every stop; the session's accessors serve it there.
#pragma once
#include <array>
#include <atomic>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "inspect/inspect.h"
#include "scheduler/match.h"
#include "timebase/tick.h"

namespace simbot::debug {

using timebase::Tick;

// A command the session refuses (a line with no code, an unknown name): one
// line for the user; the session stays where it was.
struct Error : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Snapshots are taken this often (the held robot's time); a reverse command
// replays at most a few such windows. 0.5 s: 360 in a 180-s match.
inline constexpr Tick kSnapshotInterval = timebase::kTicksPerSecond / 2;
// Every snapshot within this many intervals (8 s) of where the session is
// is kept; farther away they thin out (Session::thinSnapshots).
inline constexpr int64_t kDenseSnapshots = 16;

// What breakpoints and watchpoints share: one numbering, a condition, an
// ignore count, an enable switch and a hit count (gdb's condition,
// ignore, enable, disable and delete take either).
struct Trigger {
  int id = 0;
  std::shared_ptr<inspect::Expression> condition;  // none: always
  int ignore = 0;                                  // hits still to pass over
  int hits = 0;
  bool enabled = true;
};

struct Breakpoint : Trigger {
  enum class Kind : uint8_t { Line, Function, Time, Event };
  Kind kind = Kind::Line;
  int robot = 0;         // Line, Function: the program it is in
  int line = 0;          // Line, Function: where it stops
  uint32_t address = 0;  // Line, Function: the instruction it stops before
  std::string function;  // Function: its name; Line: the function the line is in
  Tick tick = 0;         // Time: the first boundary at or after it
  scheduler::DebugEvent event{};
  bool temporary = false;
  bool passed = false;  // Time: its tick has been reached
};

// A data breakpoint: a change of its object's value is a hit when the
// condition holds then (a change ignored or not stopped at is still the
// value compared with next).
struct Watchpoint : Trigger {
  int robot = 0;
  std::shared_ptr<inspect::Expression> expression;
  inspect::Value object;  // what it watches: fixed when it is set
  // An object on the stack (an auto's) is watched while the activation it
  // lives in has not returned: that activation's index counted from the
  // outermost (calls and handlers; -1: a global's or a static's).
  int depth = -1;
  uint16_t address = 0;  // the object's bytes: fixed when it is set
  uint32_t size = 0;
  std::vector<uint8_t> value;  // as last reported (or when it was set)
  std::vector<uint8_t> seen;   // at the held robot's latest boundary
  std::string text;            // the value as printed
  bool valid = false;
  std::string writer;  // who made the last change seen (Stop::writer)
};

// Why the session stopped, for the controller to report.
struct Stop {
  enum class Kind : uint8_t {
    Entry,       // the program's first instruction
    Breakpoint,  // `breakpoint`
    Watchpoint,  // `breakpoint` is the watchpoint's id; old and new values
    Event,       // `event`
    Step,        // a step, next, finish, until or stepi ended
    Time,        // advance TIME, a tick breakpoint
    Fault,       // the held robot faulted
    Goto,        // reached by goto, a reverse command or a change of robot
    End,         // the match is over
  };
  Kind kind = Kind::Entry;
  int breakpoint = 0;
  scheduler::DebugEvent event{};
  int eventRobot = 0;
  std::string oldValue, newValue;  // Watchpoint, in the direction of travel
  int writtenAt = 0;               // Watchpoint: the line that wrote it (0: a service)
  // Watchpoint: who wrote it, as a sentence's object: "line 195 in INT1()
  // [interrupt handler]", "the serial library's transmit interrupt ...".
  std::string writer;
  // Reached going backwards (reverse-continue): the robot stands at the
  // boundary before the instruction or service that made the change, so
  // the old value is the later one.
  bool reverse = false;
  // A watchpoint the session removed at this stop (0: none): the call its
  // variable lived in returned.
  int removed = 0;
  std::string note;  // more to say (a reverse search that found nothing)
};

// How to go on from a stop.
struct Resume {
  enum class Kind : uint8_t {
    Continue,
    Step,
    Next,
    Finish,
    StepInstruction,
    Until,        // next, but not back to an earlier line of a loop
    AdvanceLine,  // to `line` in this frame, or its return
    AdvanceTime,  // to `tick`
    ReverseStep,
    ReverseNext,
    ReverseStepInstruction,
    ReverseContinue,
    ReverseFinish,
    Goto,     // to `tick`
    Restart,  // from the start, on to the first breakpoint
    Hold,     // hold robot `robot` where it stands (Session::anchor)
    Quit,
  };
  Kind kind = Kind::Continue;
  Tick tick = 0;
  int line = 0;
  int robot = 0;
};

struct FrameInfo {
  std::string function;  // "" if the address is in no function
  int line = 0;
  uint32_t pc = 0;
  bool handler = false;      // an interrupt handler's activation
  bool interrupted = false;  // the code a handler interrupted (the next frame in)
  std::string arguments;     // "n=3, p=0x1234"
};

class Session;

class Controller {
 public:
  virtual ~Controller() = default;
  // The session stopped: inspect it through its accessors, change its
  // breakpoints, and say how to go on.
  virtual Resume stopped(Session& session, const Stop& why) = 0;
  // The session goes on after a stop, its interrupt flag cleared (a
  // Ctrl-C typed while stopped() decided is not for the next command): a
  // controller that sets the flag from another thread sets it again here
  // if a request to stop came in that time (simbot dap's disconnect).
  virtual void resuming() {}
  // The interrupt flag stopped a running command: true ends the session
  // there (run() returns at once), false holds the robot where the match
  // got to and reports that stop.
  virtual bool quitOnInterrupt() { return false; }
};

class Session final : private scheduler::DebugHook {
 public:
  // `programs` as given (the files of robots A and B), for names in
  // breakpoints and listings; `held` the robot held first.
  Session(scheduler::MatchConfig config, std::vector<std::string> programs, int held = 0);
  ~Session() override;
  Session(const Session&) = delete;
  Session& operator=(const Session&) = delete;

  // Runs the session until the controller quits (or its input ends).
  // `interrupt` (may be null; Ctrl-C at a terminal sets it) stops a
  // command that is running: the robot is held where the match got to,
  // at the start of its next round.
  void run(Controller& controller, std::atomic<bool>* interrupt = nullptr);

  // ---- at a stop ----
  int robot() const { return held_; }
  int robotCount() const { return static_cast<int>(config_.robots.size()); }
  std::string robotName(int robot) const;
  const std::string& program(int robot) const;
  // Snapshots kept now (Session::thinSnapshots): bounded, however long
  // the session.
  std::size_t snapshotsKept() const { return snapshots_.size(); }
  Tick now() const;        // the held robot's clock
  Tick matchTick() const;  // where the match is: its end once it is over
  // The tick this stop is at: every robot stands at its first instruction
  // boundary at or after it. The held robot's clock, unless the hold moved
  // to this robot from another (robot B): the tick the other stopped at,
  // which a move back returns to (no robot runs on when the hold moves).
  Tick anchor() const { return anchor_; }
  bool over() const { return over_; }
  const scheduler::MatchView& view() const;
  const vm::Vm& vm(int robot) const;
  // Names and evaluation from the selected frame of the held robot.
  int frame() const { return frame_; }
  void selectFrame(int frame);  // Error if there is no such frame
  inspect::Scope scope() const;
  inspect::Scope scope(int robot, int frame) const;
  std::vector<FrameInfo> backtrace(int robot) const;
  std::string source(int robot, int line) const;  // the text of a source line
  int lineCount(int robot) const;
  // The robot a "B:12", "fig92.dc:12" or "12" names, and the rest ("12").
  int robotOf(std::string& where) const;
  // The robot an expression names with "A:" or "B:" before it (FUNCTION::
  // NAME keeps its two colons), that prefix taken off; else the held one.
  int robotOfExpression(std::string& expression) const;

  // ---- breakpoints, watchpoints ----
  // LINE in `robot`'s program (moved to the next line with code), FUNCTION
  // (its first instruction), a tick, an event. Error if there is none.
  const Breakpoint& breakAtLine(int robot, int line, bool temporary = false);
  const Breakpoint& breakAtFunction(int robot, const std::string& name, bool temporary = false);
  const Breakpoint& breakAtTick(Tick tick, bool temporary = false);
  const Breakpoint& breakAtEvent(scheduler::DebugEvent event, bool temporary = false);
  // A location as `break` (and DAP's function breakpoints) write it:
  // "tick N", a time (12.5s, 20ms), a LINE or a FUNCTION (a handler too),
  // each of them after "B:" or "FILE:" for another robot's program (lines
  // and functions are A's otherwise), or an event (frame, edge, contact,
  // shot, fault; a function of that name wins).
  const Breakpoint& breakAt(const std::string& location, bool temporary = false);
  // Each of these takes a breakpoint's or a watchpoint's number.
  void setCondition(int id, const std::string& expression);  // "" removes it
  void setIgnore(int id, int count);
  void setEnabled(int id, bool enabled);
  void remove(int id);
  void removeAll();
  const std::vector<Breakpoint>& breakpoints() const { return breakpoints_; }
  // A data breakpoint on an lvalue of `robot` (-1: the held one), evaluated
  // now in its selected frame (another robot's: its innermost), with an
  // optional condition (watch EXPR if COND). Another robot's watchpoints
  // stop the match going forwards (the session then holds that robot);
  // going backwards only the held robot's are looked for.
  const Watchpoint& watch(const std::string& expression, const std::string& condition = "",
                          int robot = -1);
  const std::vector<Watchpoint>& watchpoints() const { return watchpoints_; }
  // Messages about the other robots since the last stop (a fault of one).
  std::vector<std::string> takeNotices();

 private:
  // Thrown out of the match from a stop: the command goes back in time (or
  // moves the hold), which the session does from its snapshots.
  struct Rewind {
    Resume how;
    Tick from = 0;  // where the command was given: the held robot's clock
    int line = 0, calls = 0, ints = 0;
    Stop arrival;
    // Hold: the other robot stopped at its own breakpoint at how.tick (the
    // match is brought to that tick), not a move of the hold at a stop.
    bool atOtherBreakpoint = false;
  };
  struct ScanDone {};
  struct Mode {
    Resume::Kind kind = Resume::Kind::Goto;
    Tick tick = 0;  // Goto, AdvanceTime: the target
    int line = 0;   // AdvanceLine
    // Where the command started: the clock, line and depths, and whether a
    // library call's effect was still due there (a step makes it happen).
    Tick startTick = 0;
    int startLine = 0, startCalls = 0, startInts = 0;
    bool startPending = false;
    // Goto: to the boundary after a library call's effect due at `tick` (a
    // place a step or a breakpoint reached), not to the tick before it.
    bool settled = false;
    Stop arrival;  // Goto: the stop to report there
    // Goto after the hold moved: the other robots stop at `tick` (they
    // stand where they stood), the held robot at its first boundary at or
    // after it.
    bool anchored = false;
  };
  struct Boundary {
    Tick tick;
    int line, calls, ints;
    bool hit;        // a breakpoint, watchpoint or event would stop here
    bool settled;    // no library effect was still due there (Mode::settled)
    bool inLibrary;  // between two steps of a library call
  };
  struct Scan {
    Tick end = 0;
    bool stepping = true;
    bool hits = false;  // record breakpoint hits (reverse-continue)
    std::vector<Boundary> boundaries;
    std::map<Tick, Stop> stops;  // what each hit would report, by its boundary's tick
    Tick start = 0;              // the held robot's clock at the window's snapshot
  };
  // A place found going backwards, and what to report there.
  struct Found {
    Tick tick;
    bool settled;
    std::optional<Stop> why;
  };

  // scheduler::DebugHook
  bool stepping() const override;
  Tick until() const override;
  Tick othersTo(Tick clock) const override;
  bool settles() const override;
  void boundary(const scheduler::MatchView& view) override;
  bool event(int robot, Tick t, scheduler::DebugEvent e) override;
  void otherBreakpoint(const scheduler::MatchView& view, int robot) override;
  bool watching(int robot) const override;
  void otherBoundary(const scheduler::MatchView& view, int robot) override;

  void forward();
  void takeSnapshot();
  void thinSnapshots(int64_t present);
  void restoreBefore(Tick target, bool inclusive);
  void applyBreakpoints();
  void startMode(const Resume& how, const Stop& arrival = {});
  bool shouldStop(Stop& why);
  bool breakpointHit(int robot, Stop& why, bool counting);
  bool watchpointHit(int robot, Stop& why);
  void refreshWatchpoints();
  void park(const Stop& why);
  void handle(const Resume& how);
  void perform(const Rewind& rewind);
  std::vector<Boundary> scanWindow(Tick from, Tick end, bool stepping, bool hits,
                                   std::map<Tick, Stop>* stops = nullptr);
  std::optional<size_t> lineBefore(const std::vector<Boundary>& history, const Rewind& rw,
                                   bool complete) const;
  bool serviceRan(int robot, const vm::Vm& v) const;
  std::string valueText(const vm::Vm& v, const Watchpoint& w) const;
  Stop eventStopOf(const Breakpoint& b, int robot, Tick t);
  std::optional<Found> searchBack(const Rewind& rewind);
  std::string writer(int robot, const vm::Vm& v) const;
  void noteBoundary(int robot, const vm::Vm& v);
  void reverseWatchHit(Stop why);  // a watchpoint hit of a scan, going backwards
  void countHit(const Stop& why);
  Breakpoint& addBreakpoint(Breakpoint b);
  Breakpoint* findBreakpoint(int id);
  Trigger& trigger(int id);  // a breakpoint or watchpoint; Error if none

  scheduler::MatchConfig config_;
  std::vector<std::string> programs_;
  int held_ = 0;
  Controller* controller_ = nullptr;
  std::atomic<bool>* interrupt_ = nullptr;
  std::unique_ptr<scheduler::MatchRun> run_;
  std::map<int64_t, scheduler::MatchRun::Snapshot> snapshots_;  // by kSnapshotInterval
  const scheduler::MatchView* view_ = nullptr;                  // at a stop inside a round
  bool over_ = false;
  int frame_ = 0;
  Mode mode_;
  std::optional<Scan> scan_;
  std::vector<Breakpoint> breakpoints_;
  std::vector<Watchpoint> watchpoints_;
  int nextId_ = 1;
  Tick lastStop_ = -1;
  Tick anchor_ = 0;
  bool leftLine_ = false;  // AdvanceLine: the robot has been off the line
  // Each robot's boundary before this one (watchpoints' writer): its
  // instruction, tick, and the interrupts accepted by then (an atomic
  // service, the serial library's or the timer's, ran in between when they
  // differ).
  struct LastBoundary {
    uint32_t pc = 0;
    Tick tick = 0;
    std::array<uint64_t, vm::kIrqCount> interrupts{};
  };
  std::array<LastBoundary, 2> last_{};
  std::optional<Stop> eventStop_;
  std::vector<std::string> notices_;
};

// "12.5s", "20ms", "300us", "9216t", "123456" (ticks): a time the user
// wrote, in timebase/written.h's grammar, a number alone ticks. Error if it
// is none, or not a whole number of ticks (naming the two nearest).
Tick parseTime(const std::string& text);
// Whether a word is written as a time with a unit (12.5s, 20ms, 9216t), not a line.
bool looksLikeTime(const std::string& word);
// "1.500000 s", as stops and breakpoints show a tick's time.
std::string secondsText(Tick t);
// A program's file name without its directories, as listings show it.
std::string fileName(const std::string& path);

}  // namespace simbot::debug
