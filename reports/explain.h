// reports/ (namespace simbot::reports): what a recorded run did, for a
// reader, made from the trace's records alone: the explain report (this
// header) and the replay page that shows it (viewer.h; the page's files
// are reports/viewer/, compiled in by viewer_assets.cpp). It reads traces
// through sinks/ and knows nothing of the command line.
//
// `simbot explain`: a report a student can read, made from a run's trace
// records alone (trace/records.def): each shot (range, bearing error, muzzle
// speed, hit or miss distance), stalls (the program seeing the opponent and
// no motor frame latched for more than 1 s, stall.h: thesis chapter X's
// one-eye dead-lock is one),
// overwritten sends, time inside handlers and what the robot did meanwhile,
// contacts, referee actions and faults, and what the wider competition
// added (obstacles and mines, scatter shots, discs, deployables, resets).
//
// The Explainer is a trace sink: `simbot explain` feeds it a JSONL trace,
// the replay page (reports/viewer.cpp) feeds it the run's records, so the
// command and the page's Explain panel show the same report. It keeps only
// what the report needs (no record history).
#pragma once
#include <cstdint>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "timebase/tick.h"
#include "trace/trace.h"

namespace simbot::reports::explain {

using trace::Tick;

// The robots' names in a report: robot 0 is A, 1 is B.
inline constexpr const char* kRobotNames[] = {"A", "B"};

// A shot: one ball_launch and how its flight ended.
struct Shot {
  int robot = 0;
  int gun = 0;
  int ball = 0;
  Tick t = 0;
  // Centre to centre at launch, and the target's bearing from the shooter's
  // centre minus the gun's heading (+ = target to the right); none in a solo
  // run. The shooter's centre and heading are exact (the muzzle is flush
  // with the body edge along the heading); the target's centre is
  // interpolated linearly between its 20-Hz samples around the launch.
  std::optional<double> range_ft, bearing_error_deg;
  double muzzle_fps = 0;
  // DESIGN.md's eye rule: the target within 90 deg of the heading and the
  // segment between the centres clear of the divider.
  bool target_in_view = false;
  std::optional<Tick> end_t;  // ball_hit or ball_miss (none: still flying at the end)
  bool hit = false;
  std::string ended;              // robot, floor, divider or wall
  std::optional<double> miss_ft;  // ball_miss's closest_ft
};

// A stall (reports/stall.h, the one definition): the program seeing the
// opponent (its latest reading of either eye above 48) and no motor frame
// latched, for more than 1 s. What follows `to_end` describes it from the
// 20-Hz samples inside it.
struct Stall {
  int robot = 0;
  Tick from = 0, to = 0;
  bool to_end = false;  // still stalled when the run ended
  int samples = 0;
  int eye_left_median = 0, eye_left_min = 0, eye_left_max = 0;
  int eye_right_median = 0, eye_right_min = 0, eye_right_max = 0;
  struct Line {
    int line = 0;
    std::string function;
    std::string text;  // the source line
    int samples = 0;
  };
  std::vector<Line> lines;  // where the samples found the program, most often first
  std::string last_frame;   // the motor command still in force (empty: none latched yet)
  double moved_ft = 0;      // path length between the samples
  double turned_deg = 0;    // net heading change
  std::string halted;       // "exited" or "faulted" if main had returned or it faulted
  int shots = 0;            // balls it launched meanwhile (a firing routine's delay loops)
  // Most samples had one eye at background and the other above it: the case
  // ICEMAN has no branch for (thesis chapter X's dead-lock).
  bool one_eye = false;
};

// Where a send came from (the serial_send and frame_overwritten records):
// its ser_send_z1 call's line and function, and the call of that function
// (caller_line 0: none, a send in main or in a handler's own code).
struct SendSite {
  int line = 0;  // 0: not known
  std::string function;
  int caller_line = 0;
  std::string caller_function;
  std::string calls;  // the whole chain, outermost first (serial_send's `calls`)
};

// A ser_send_z1 before the port had taken (fetched into its data register)
// the previous send's last byte: the library re-points at buf[0], so the
// rest of the previous frame is never sent and that frame never latches.
struct OverwrittenSend {
  int robot = 0;
  Tick t = 0;
  Tick previous_t = 0;
  int previous_count = 0;
  int previous_bytes_fetched = 0;
  std::string handler;  // the handler in service at the new send ("" if none)
  SendSite send;        // the send that overwrote
  SendSite previous;    // the send it overwrote
};

// The overwritten sends of one robot with the same two sends, the most
// frequent pair first: which line overwrites which.
struct OverwriteGroup {
  int robot = 0;
  SendSite send, previous;  // `calls` of the first of them
  int count = 0;
  Tick first = 0, last = 0;
};

// One handler run: acceptance to the end of its RETI.
struct HandlerRun {
  int robot = 0;
  std::string source, handler;
  Tick from = 0;
  std::optional<Tick> to;  // none: still in service at the end
  int line = 0;            // what it interrupted
  std::string function;
  std::vector<std::string> frames;  // motor frames latched meanwhile
  int sends = 0, edges = 0, contacts = 0, shots = 0;
  double moved_ft = 0;  // path length between the samples inside the run
};

struct HandlerTotal {
  int robot = 0;
  std::string handler;
  int runs = 0;
  Tick total = 0, longest = 0;
};

struct Contact {
  int robot = 0;
  Tick t = 0;
  std::optional<Tick> end_t;
  std::string bumper, with;
  bool reflex = false;  // the motor controller's reflex started
};

struct Event {
  int robot = -1;  // -1: the run (plant fault)
  Tick t = 0;
  std::string what;
  int line = 0;
  // A fault's call chain (the fault record's calls: main:12 > deep:7 x 251)
  // and depth, the calls and handlers under way; "" and 0 for the others.
  std::string calls;
  int depth = 0;
};

struct RobotInfo {
  std::string name, program;
  bool scripted = false;
  int hits = 0, shots = 0, frames_latched = 0, frames_rejected = 0;
  bool faulted = false, exited = false, has_result = false;
  int serial_isr_runs = 0;
  Tick serial_isr_total = 0;
};

struct Report {
  double ticks_per_second =
      static_cast<double>(timebase::kTicksPerSecond);  // until the run record says
  Tick end_t = 0;                                      // the last record's tick
  std::uint64_t seed = 0;
  std::string profile, winner;
  bool coin = false;
  std::vector<RobotInfo> robots;
  std::vector<Shot> shots;
  std::vector<Stall> stalls;
  std::vector<OverwrittenSend> overwritten;
  std::vector<OverwriteGroup> overwrite_groups;
  std::vector<HandlerRun> handler_runs;
  std::vector<HandlerTotal> handler_totals;
  std::vector<Contact> contacts;
  std::vector<Event> referee;
  std::vector<Event> faults;  // faults, exits, reloads and plant faults, in tick order
  // The wider competition (DESIGN.md), in tick order: obstacles on the
  // field, mines that tripped a bumper, balls stopped by an obstacle,
  // scatter shots, discs, deployables set down, resets. Empty (and not printed) without them.
  std::vector<Event> course;
  int scatter_shots[2] = {0, 0};
};

class Explainer final : public trace::Sink {
 public:
  Explainer();
  ~Explainer() override;
  Explainer(const Explainer&) = delete;
  Explainer& operator=(const Explainer&) = delete;
  void write(const trace::Entry& entry) override;
  // The report of the records so far (open periods end at the last tick).
  Report report() const;

  struct State;

 private:
  std::unique_ptr<State> state_;
};

// Only robot `robot`'s items (0 A, 1 B); the run's faults stay.
Report onlyRobot(const Report& report, int robot);

// A line of the text report; `t` is the tick it is about, if any (the
// replay page makes such lines seek there).
struct TextLine {
  std::string text;
  std::optional<Tick> t;
};
// The report in words (explain_text.cpp) and as JSON (explain_json.cpp).
std::vector<TextLine> textLines(const Report& report);
std::string text(const Report& report);
std::string markdown(const Report& report);
nlohmann::json json(const Report& report);

// Reads a JSONL trace (sinks/trace_jsonl.h: bad input throws UserError
// "FILE:LINE: error: ...").
Report explainFile(const std::string& path);

}  // namespace simbot::reports::explain
