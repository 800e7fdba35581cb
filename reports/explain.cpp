// The explain report (see explain.h): one pass over the records in tick
// order, keeping only the open periods and the latest samples.
#include "reports/explain.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <sstream>
#include <tuple>
#include <type_traits>
#include <utility>

#include "plant/plant.h"
#include "reports/stall.h"
#include "sinks/json_text.h"
#include "sinks/trace_jsonl.h"

namespace simbot::reports::explain {

namespace {

namespace rec = trace::rec;
constexpr double kPi = 3.14159265358979323846;
constexpr const char* kNames[] = {"A", "B"};

double degrees(double rad) { return rad * (180.0 / kPi); }
// Degrees in (-180, 180].
double wrap180(double deg) {
  double w = std::fmod(deg, 360.0);
  if (w <= -180.0) w += 360.0;
  if (w > 180.0) w -= 360.0;
  return w;
}

struct Pose {
  Tick t = 0;
  double x = 0, y = 0, heading = 0;
};

Pose lerp(const Pose& a, const Pose& b, Tick t) {
  if (b.t == a.t) return b;
  const double f = static_cast<double>(t - a.t) / static_cast<double>(b.t - a.t);
  return {t, a.x + f * (b.x - a.x), a.y + f * (b.y - a.y),
          a.heading + f * wrap180(b.heading - a.heading)};
}

// "cfgrcfgr" -> "L +12 R +12": each wheel's speed step, negative in
// reverse, "stop" when its g/s character says stop; decoded by the motor
// controller's own rule (plant::parseMotorFrame). "" if it is not a frame.
std::string describeFrame(const std::string& f) {
  const auto frame = plant::parseMotorFrame(f);
  if (!frame) return "";
  auto wheel = [](const plant::WheelCommand& w) -> std::string {
    if (!w.go) return "stop";
    return fmt::format("{}{}", w.forward ? '+' : '-', w.speed);
  };
  return fmt::format("L {} R {}", wheel(frame->left), wheel(frame->right));
}

int median(std::vector<int> v) {
  if (v.empty()) return 0;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

}  // namespace

struct Explainer::State {
  Report report;
  plant::FieldParams field;  // the divider, from the run record
  int robots = 0;

  struct Sample {
    Pose pose;
    int eyeLeft = 0, eyeRight = 0, line = 0;
    std::string function;
    bool inHandler = false;
  };
  // The open stall window's samples (stall.h decides when it opens and
  // closes; this collects what the report says about it).
  struct Window {
    std::optional<Tick> start;
    std::vector<int> left, right;
    std::map<std::pair<int, std::string>, int> lines;
    double moved = 0, turned = 0;
    std::optional<Pose> last;
    int shots = 0, oneEye = 0;
  };
  struct Robot {
    double radius = 0;
    int eyeBackground = 16;
    std::vector<std::string> source;  // the program's lines
    std::optional<Sample> last, previous;
    std::string lastFrame;
    StallWatch stall;
    Window window;
    std::string halted;
    std::vector<std::size_t> handlers;                       // open handler runs
    std::map<std::string, std::size_t> touch;                // open contacts by what they touch
    std::map<std::size_t, std::optional<Pose>> handlerLast;  // a run's latest sample inside it
    // The chains of the latest send and the one before it (serial_send),
    // by tick: a frame_overwritten comes right after the send that made it.
    std::pair<Tick, std::string> lastCalls{-1, ""}, callsBefore{-1, ""};
    std::optional<std::pair<Tick, std::string>> lastFault;  // for its reload
  };
  Robot r[2];
  struct PendingShot {
    std::size_t shot;
    int target;
    double x, y, heading;  // the shooter's centre and heading at launch
  };
  std::vector<PendingShot> pending;
  std::map<std::int64_t, std::size_t> flying;  // ball number -> shot

  double tps() const { return report.ticks_per_second; }

  void aim(const PendingShot& p, const Pose& target) {
    Shot& s = report.shots[p.shot];
    const double dx = target.x - p.x, dy = target.y - p.y;
    s.range_ft = std::hypot(dx, dy);
    s.bearing_error_deg = wrap180(degrees(std::atan2(dx, dy)) - p.heading);
    s.target_in_view = std::abs(*s.bearing_error_deg) < 90.0 &&
                       !plant::dividerBlocks(p.x, p.y, target.x, target.y, field);
  }

  // Targets' samples at or after the launch resolve the pending shots.
  void resolveShots(int robot, const Sample& now) {
    std::erase_if(pending, [&](const PendingShot& p) {
      if (p.target != robot || report.shots[p.shot].t > now.pose.t) return false;
      const Tick t = report.shots[p.shot].t;
      const auto& prev = r[robot].previous;
      aim(p, prev && prev->pose.t <= t ? lerp(prev->pose, now.pose, t) : now.pose);
      return true;
    });
  }

  // After the robot's StallWatch was fed at `t`: the window that closed
  // there becomes a Stall if it was one, and a window opened there starts
  // collecting.
  void stallFed(int robot, std::optional<StallSpan> ended, Tick t, bool atEnd) {
    Window& w = r[robot].window;
    if (ended) {
      Stall s;
      s.robot = robot;
      s.from = ended->from;
      s.to = ended->to;
      s.to_end = atEnd && ended->to == t;
      s.samples = static_cast<int>(w.left.size());
      if (!w.left.empty()) {
        s.eye_left_median = median(w.left);
        s.eye_right_median = median(w.right);
        s.eye_left_min = *std::min_element(w.left.begin(), w.left.end());
        s.eye_left_max = *std::max_element(w.left.begin(), w.left.end());
        s.eye_right_min = *std::min_element(w.right.begin(), w.right.end());
        s.eye_right_max = *std::max_element(w.right.begin(), w.right.end());
      }
      for (const auto& [where, n] : w.lines) {
        const auto& src = r[robot].source;
        const int line = where.first;
        std::string text = line > 0 && line <= static_cast<int>(src.size())
                               ? src[static_cast<size_t>(line - 1)]
                               : "";
        const auto first = text.find_first_not_of(" \t");
        text = first == std::string::npos ? "" : text.substr(first);
        s.lines.push_back({line, where.second, text, n});
      }
      std::stable_sort(s.lines.begin(), s.lines.end(),
                       [](const auto& a, const auto& b) { return a.samples > b.samples; });
      s.last_frame = r[robot].lastFrame;
      s.moved_ft = w.moved;
      s.turned_deg = w.turned;
      s.halted = r[robot].halted;
      s.shots = w.shots;
      s.one_eye = 2 * w.oneEye > s.samples;
      report.stalls.push_back(std::move(s));
    }
    const std::optional<Tick> start = r[robot].stall.windowStart();
    if (w.start != start) {
      w = Window{};
      w.start = start;
    }
  }

  // A sample inside the robot's open stall window.
  void collect(Robot& me, const Sample& s) {
    Window& w = me.window;
    if (!w.start) return;
    const int bg = me.eyeBackground;
    if ((s.eyeLeft <= bg) != (s.eyeRight <= bg)) ++w.oneEye;
    w.left.push_back(s.eyeLeft);
    w.right.push_back(s.eyeRight);
    ++w.lines[{s.line, s.function}];
    if (w.last) {
      w.moved += std::hypot(s.pose.x - w.last->x, s.pose.y - w.last->y);
      w.turned += wrap180(s.pose.heading - w.last->heading);
    }
    w.last = s.pose;
  }

  void sample(Tick t, const rec::Sample& x) {
    Robot& me = r[x.robot];
    Sample s{{t, x.x_ft, x.y_ft, x.heading_deg},
             static_cast<int>(x.eye_left),
             static_cast<int>(x.eye_right),
             static_cast<int>(x.line),
             x.function,
             x.in_handler};
    me.previous = me.last;
    me.last = s;
    resolveShots(x.robot, s);
    stallFed(x.robot, me.stall.pose(t, x.x_ft, x.y_ft), t, false);
    for (const std::size_t run : me.handlers) {
      auto& last = me.handlerLast[run];
      if (last) report.handler_runs[run].moved_ft += std::hypot(x.x_ft - last->x, x.y_ft - last->y);
      last = s.pose;
    }
    collect(me, s);
  }

  template <class F>
  void eachOpenRun(int robot, F&& f) {
    for (const std::size_t run : r[robot].handlers) f(report.handler_runs[run]);
  }

  void entry(const trace::Entry& e) {
    report.end_t = std::max(report.end_t, e.t);
    std::visit([&](const auto& x) { on(e.t, x); }, e.record);
  }

  void on(Tick, const rec::Run& x) {
    report.ticks_per_second = static_cast<double>(x.ticks_per_second);
    report.seed = static_cast<std::uint64_t>(x.seed);
    report.profile = x.profile;
    robots = static_cast<int>(std::clamp<std::int64_t>(x.robots, 1, 2));
    report.robots.resize(static_cast<size_t>(robots));
    for (int i = 0; i < robots; ++i) report.robots[static_cast<size_t>(i)].name = kNames[i];
    field.divider_x_ft = x.divider_x_ft;
    field.divider_south_ft = x.divider_south_ft;
    field.divider_north_ft = x.divider_north_ft;
    field.divider_thickness_ft = x.divider_thickness_ft;
  }
  void on(Tick, const rec::RobotSetup& x) {
    if (x.robot >= robots) return;
    RobotInfo& info = report.robots[static_cast<size_t>(x.robot)];
    info.program = x.program;
    info.scripted = x.scripted;
    r[x.robot].radius = x.body_diameter_ft / 2;
    r[x.robot].eyeBackground = static_cast<int>(x.eye_background);
    std::istringstream in(x.source);
    for (std::string line; std::getline(in, line);) r[x.robot].source.push_back(line);
  }
  void on(Tick t, const rec::Sample& x) {
    if (x.robot < robots) sample(t, x);
  }
  void on(Tick t, const rec::FrameOverwritten& x) {
    if (x.robot >= robots) return;
    OverwrittenSend o;
    o.robot = x.robot;
    o.t = t;
    o.previous_t = x.previous_t;
    o.previous_count = static_cast<int>(x.previous_count);
    o.previous_bytes_fetched = static_cast<int>(x.fetched);
    const Robot& me = r[x.robot];
    if (!me.handlers.empty()) o.handler = report.handler_runs[me.handlers.back()].handler;
    auto calls = [](const std::pair<Tick, std::string>& c, Tick at) {
      return c.first == at ? c.second : std::string();
    };
    o.send = {static_cast<int>(x.line), x.function, static_cast<int>(x.caller_line),
              x.caller_function, calls(me.lastCalls, t)};
    o.previous = {static_cast<int>(x.previous_line), x.previous_function,
                  static_cast<int>(x.previous_caller_line), x.previous_caller_function,
                  calls(me.callsBefore, x.previous_t)};
    report.overwritten.push_back(std::move(o));
  }
  void on(Tick t, const rec::SerialSend& x) {
    if (x.robot >= robots) return;
    Robot& me = r[x.robot];
    me.callsBefore = std::exchange(me.lastCalls, {t, x.calls});
    eachOpenRun(x.robot, [](HandlerRun& h) { ++h.sends; });
  }
  void on(Tick t, const rec::SerialIsr& x) {
    if (x.robot >= robots) return;
    RobotInfo& info = report.robots[static_cast<size_t>(x.robot)];
    ++info.serial_isr_runs;
    info.serial_isr_total += x.end_t - t;
  }
  void on(Tick t, const rec::AdRead& x) {
    if (x.robot >= robots) return;
    const int channel = static_cast<int>(x.channel);
    stallFed(x.robot, r[x.robot].stall.eyeRead(t, channel, static_cast<int>(x.value)), t, false);
  }
  void on(Tick t, const rec::FrameLatched& x) {
    if (x.robot >= robots) return;
    // The stall that ends here still had the previous command in force.
    stallFed(x.robot, r[x.robot].stall.frameLatched(t), t, false);
    r[x.robot].lastFrame = x.bytes;
    eachOpenRun(x.robot, [&](HandlerRun& h) { h.frames.push_back(x.bytes); });
  }
  void on(Tick t, const rec::InterruptAccepted& x) {
    HandlerRun h;
    h.robot = x.robot;
    h.source = x.source;
    h.handler = x.handler;
    h.from = t;
    h.line = static_cast<int>(x.line);
    h.function = x.function;
    report.handler_runs.push_back(std::move(h));
    r[x.robot].handlers.push_back(report.handler_runs.size() - 1);
  }
  void on(Tick t, const rec::InterruptReturned& x) {
    auto& open = r[x.robot].handlers;
    for (auto it = open.rbegin(); it != open.rend(); ++it) {
      if (report.handler_runs[*it].source != x.source) continue;
      report.handler_runs[*it].to = t;
      r[x.robot].handlerLast.erase(*it);
      open.erase(std::next(it).base());
      break;
    }
  }
  void on(Tick t, const rec::Exit& x) {
    if (x.robot >= robots) return;
    r[x.robot].halted = "exited";
    stallFed(x.robot, r[x.robot].stall.halted(t), t, false);
    report.faults.push_back({x.robot, t, "main returned", 0, "", 0});
  }
  void on(Tick t, const rec::Fault& x) {
    if (x.robot >= robots) return;
    r[x.robot].halted = "faulted";
    r[x.robot].lastFault = {t, x.message};
    stallFed(x.robot, r[x.robot].stall.halted(t), t, false);
    report.faults.push_back(
        {x.robot, t, x.message, static_cast<int>(x.line), x.calls, static_cast<int>(x.depth)});
  }
  void on(Tick t, const rec::Reload& x) {
    if (x.robot >= robots) return;
    Robot& me = r[x.robot];
    me.halted.clear();
    stallFed(x.robot, me.stall.reloaded(t), t, false);
    std::string what =
        fmt::format("reloaded (--reload-on-fault, reload {}): main started again", x.reloads);
    if (me.lastFault)
      what += fmt::format(" {:.3f} s after the fault at {:.3f} s ({})",
                          static_cast<double>(t - me.lastFault->first) / tps(),
                          static_cast<double>(me.lastFault->first) / tps(), me.lastFault->second);
    report.faults.push_back({x.robot, t, std::move(what), 0, "", 0});
  }
  void on(Tick t, const rec::PlantFault& x) {
    report.faults.push_back({-1, t, "plant fault: " + x.message, 0, "", 0});
  }
  void on(Tick, const rec::EdgeEnter& x) {
    eachOpenRun(x.robot, [](HandlerRun& h) { ++h.edges; });
  }
  void on(Tick t, const rec::Contact& x) {
    report.contacts.push_back({x.robot, t, std::nullopt, x.bumper, x.with, false});
    r[x.robot].touch[x.with] = report.contacts.size() - 1;
    eachOpenRun(x.robot, [](HandlerRun& h) { ++h.contacts; });
  }
  void on(Tick t, const rec::ContactEnd& x) {
    auto& touch = r[x.robot].touch;
    if (const auto it = touch.find(x.with); it != touch.end()) {
      report.contacts[it->second].end_t = t;
      touch.erase(it);
    }
  }
  void on(Tick, const rec::ReflexStart& x) {
    // The reflex belongs to the latest contact of this robot on that bumper.
    for (auto it = report.contacts.rbegin(); it != report.contacts.rend(); ++it)
      if (it->robot == x.robot && it->bumper == x.bumper) {
        it->reflex = true;
        break;
      }
  }
  void on(Tick t, const rec::BallLaunch& x) {
    Shot s;
    s.robot = x.robot;
    s.gun = static_cast<int>(x.gun);
    s.ball = static_cast<int>(x.ball);
    s.t = t;
    s.muzzle_fps = std::hypot(x.vx_fps, x.vy_fps, x.vz_fps);
    report.shots.push_back(s);
    const std::size_t index = report.shots.size() - 1;
    flying[x.ball] = index;
    if (r[x.robot].window.start) ++r[x.robot].window.shots;
    eachOpenRun(x.robot, [](HandlerRun& h) { ++h.shots; });
    if (robots < 2) return;
    // The muzzle is the body's edge along the heading (plant/arena.cpp), so
    // the muzzle less a radius along it is the centre. The record's heading,
    // not the velocity: dispersion turns the ball, not the gun.
    const Robot& me = r[x.robot];
    PendingShot p{index, 1 - x.robot, 0, 0, 0};
    p.heading = x.heading_deg;
    const double h = p.heading * (kPi / 180.0);
    p.x = x.x_ft - me.radius * std::sin(h);
    p.y = x.y_ft - me.radius * std::cos(h);
    const auto& target = r[p.target].last;
    if (target && target->pose.t == t)
      aim(p, target->pose);
    else
      pending.push_back(p);
  }
  void on(Tick t, const rec::BallHit& x) {
    const auto it = flying.find(x.ball);
    if (it == flying.end()) return;
    Shot& s = report.shots[it->second];
    s.end_t = t;
    s.hit = true;
    s.ended = x.hit;
    flying.erase(it);
  }
  void on(Tick t, const rec::BallMiss& x) {
    const auto it = flying.find(x.ball);
    if (it == flying.end()) return;
    Shot& s = report.shots[it->second];
    s.end_t = t;
    s.ended = x.hit;
    s.miss_ft = x.closest_ft;
    flying.erase(it);
  }
  void on(Tick t, const rec::RefereePutBack& x) {
    report.referee.push_back(
        {x.robot, t, "put back inside the wire (its centre left the field)", 0, "", 0});
  }
  void on(Tick t, const rec::RefereeTurn& x) {
    report.referee.push_back(
        {x.robot, t, "turned 45 deg (too many bumper reflexes or edge events)", 0, "", 0});
  }
  void on(Tick, const rec::RobotResult& x) {
    if (x.robot >= robots) return;
    RobotInfo& info = report.robots[static_cast<size_t>(x.robot)];
    info.hits = static_cast<int>(x.hits);
    info.shots = static_cast<int>(x.shots);
    info.frames_latched = static_cast<int>(x.frames_latched);
    info.frames_rejected = static_cast<int>(x.frames_rejected);
    info.faulted = x.faulted;
    info.exited = x.exited;
    info.has_result = true;
  }
  void on(Tick, const rec::End& x) {
    report.winner = x.winner;
    report.coin = x.tie_broken_by_coin;
  }
  template <class R>
  void on(Tick, const R&) {}

  // The overwritten sends by robot and the two sends' sites, most first.
  void groupOverwrites() {
    using Site = std::tuple<int, std::string, int, std::string>;
    auto site = [](const SendSite& x) {
      return Site{x.line, x.function, x.caller_line, x.caller_function};
    };
    std::map<std::tuple<int, Site, Site>, std::size_t> index;
    auto& groups = report.overwrite_groups;
    for (const OverwrittenSend& o : report.overwritten) {
      const auto key = std::make_tuple(o.robot, site(o.send), site(o.previous));
      const auto [it, fresh] = index.emplace(key, groups.size());
      if (fresh) groups.push_back({o.robot, o.send, o.previous, 0, o.t, o.t});
      OverwriteGroup& g = groups[it->second];
      ++g.count;
      g.last = o.t;
    }
    std::stable_sort(groups.begin(), groups.end(), [](const auto& a, const auto& b) {
      return a.robot != b.robot ? a.robot < b.robot : a.count > b.count;
    });
  }

  // Ends every open period at the last tick.
  void finish() {
    const Tick end = report.end_t;
    for (const PendingShot& p : pending)
      if (const auto& target = r[p.target].last) aim(p, target->pose);
    pending.clear();
    for (int i = 0; i < robots; ++i) stallFed(i, r[i].stall.finish(end), end, true);
    std::map<std::pair<int, std::string>, HandlerTotal> totals;
    for (const HandlerRun& h : report.handler_runs) {
      HandlerTotal& total = totals[{h.robot, h.handler}];
      total.robot = h.robot;
      total.handler = h.handler;
      ++total.runs;
      const Tick length = h.to.value_or(end) - h.from;
      total.total += length;
      total.longest = std::max(total.longest, length);
    }
    for (auto& [key, total] : totals) report.handler_totals.push_back(total);
    groupOverwrites();
    std::stable_sort(report.stalls.begin(), report.stalls.end(),
                     [](const Stall& a, const Stall& b) { return a.from < b.from; });
  }
};

Explainer::Explainer() : state_(std::make_unique<State>()) {}
Explainer::~Explainer() = default;

void Explainer::write(const trace::Entry& entry) { state_->entry(entry); }

Report Explainer::report() const {
  State copy = *state_;
  copy.finish();
  return std::move(copy.report);
}

Report onlyRobot(const Report& in, int robot) {
  Report out = in;
  auto keep = [robot](auto& items) {
    std::erase_if(items, [robot](const auto& x) { return x.robot != robot && x.robot >= 0; });
  };
  keep(out.shots);
  keep(out.stalls);
  keep(out.overwritten);
  keep(out.overwrite_groups);
  keep(out.handler_runs);
  keep(out.handler_totals);
  keep(out.contacts);
  keep(out.referee);
  keep(out.faults);
  return out;
}

Report explainFile(const std::string& path) {
  Explainer explainer;
  const sinks::TraceRead read =
      sinks::readTrace(path, [&](const trace::Entry& e) { explainer.write(e); });
  std::cerr << sinks::cutShortWarning(path, read);
  return explainer.report();
}

// ---- rendering

namespace {

struct Fmt {
  const Report& r;
  std::string s(Tick t) const {
    return fmt::format("{:.3f}", static_cast<double>(t) / r.ticks_per_second);
  }
  std::string dur(Tick t) const {
    return fmt::format("{:.3f} s", static_cast<double>(t) / r.ticks_per_second);
  }
  std::string name(int robot) const { return robot >= 0 && robot < 2 ? kNames[robot] : "run"; }
  static std::string signedDeg(const std::optional<double>& d) {
    return d ? fmt::format("{:+.1f}", *d) : "-";
  }
  static std::string ft(const std::optional<double>& d) {
    return d ? fmt::format("{:.2f}", *d) : "-";
  }
  std::string result(const Shot& x) const {
    if (!x.end_t) return "still flying at the end";
    if (x.hit) return "hit";
    return fmt::format("miss by {} ft ({})", ft(x.miss_ft), x.ended);
  }
  std::string where(int line, const std::string& function) const {
    if (line <= 0) return function.empty() ? "start-up code" : function + "()";
    return fmt::format("line {}{}", line, function.empty() ? "" : " in " + function + "()");
  }
  // "line 78 in platform() (called from line 71 in main())".
  std::string send(const SendSite& x) const {
    if (x.line <= 0) return "an unknown line";
    std::string out = where(x.line, x.function);
    if (x.caller_line > 0) out += " (called from " + where(x.caller_line, x.caller_function) + ")";
    return out;
  }
  std::string overwrite(const OverwrittenSend& x) const {
    return fmt::format(
        "the send from {} restarted the send of {} s from {} when the port had taken {} of its "
        "{} bytes{}",
        send(x.send), s(x.previous_t), send(x.previous), x.previous_bytes_fetched, x.previous_count,
        x.handler.empty() ? "" : fmt::format("; handler {} in service", x.handler));
  }
  std::string group(const OverwriteGroup& x) const {
    return fmt::format("{} send{} from {} overwrote the send from {}; {} s .. {} s", x.count,
                       x.count == 1 ? "" : "s", send(x.send), send(x.previous), s(x.first),
                       s(x.last));
  }
  std::string frames(const std::vector<std::string>& f) const {
    if (f.empty()) return "no frame latched";
    std::string out = fmt::format("{} frame{} latched:", f.size(), f.size() == 1 ? "" : "s");
    for (const auto& frame : f)
      out += fmt::format(" {} ({})", sinks::jsonString(frame, true), describeFrame(frame));
    return out;
  }
  std::string meanwhile(const HandlerRun& h) const {
    std::string out = frames(h.frames);
    out += fmt::format("; {} send{}", h.sends, h.sends == 1 ? "" : "s");
    if (h.edges) out += fmt::format(", {} edge event{}", h.edges, h.edges == 1 ? "" : "s");
    if (h.contacts) out += fmt::format(", {} contact{}", h.contacts, h.contacts == 1 ? "" : "s");
    if (h.shots) out += fmt::format(", {} shot{}", h.shots, h.shots == 1 ? "" : "s");
    out += fmt::format("; moved {:.2f} ft", h.moved_ft);
    return out;
  }
  std::string eyes(const Stall& x) const {
    auto one = [](int med, int lo, int hi) {
      return lo == hi ? fmt::format("{}", med) : fmt::format("{} ({}..{})", med, lo, hi);
    };
    return fmt::format("left eye {}, right eye {}",
                       one(x.eye_left_median, x.eye_left_min, x.eye_left_max),
                       one(x.eye_right_median, x.eye_right_min, x.eye_right_max));
  }
  std::string lines(const Stall& x, std::size_t most) const {
    std::string out;
    for (std::size_t i = 0; i < x.lines.size() && i < most; ++i) {
      const auto& l = x.lines[i];
      if (i) out += "; ";
      out += fmt::format("{} ({}%)", where(l.line, l.function),
                         100 * l.samples / std::max(1, x.samples));
      if (!l.text.empty()) out += fmt::format(": `{}`", l.text);
    }
    if (x.lines.size() > most) out += fmt::format("; {} more lines", x.lines.size() - most);
    return out;
  }
  std::string until(const Stall& x) const {
    return x.to_end ? fmt::format("{} s (the end)", s(x.to)) : fmt::format("{} s", s(x.to));
  }
  // What the stall looks like: firing, or the one-eye case.
  std::string note(const Stall& x) const {
    std::string out;
    if (x.shots)
      out += fmt::format("; launched {} ball{} meanwhile", x.shots, x.shots == 1 ? "" : "s");
    if (x.one_eye)
      out +=
          "; one eye at background while the other sees the opponent: the one-eye dead-lock "
          "of thesis chapter X (no branch of the program handles it)";
    if (!x.halted.empty()) out += "; " + x.halted;
    return out;
  }
  // The longest stall, or null.
  static const Stall* longest(const Report& r) {
    const Stall* best = nullptr;
    for (const Stall& x : r.stalls)
      if (!best || x.to - x.from > best->to - best->from) best = &x;
    return best;
  }
  // A handler run's time in service; one that never returned, to the end.
  std::string inService(const HandlerRun& h) const {
    if (h.to) return dur(*h.to - h.from);
    return fmt::format("{} (still in service at the end, {} s: it never returned)",
                       dur(r.end_t - h.from), s(r.end_t));
  }
  // A fault's line and call chain: " (line 7; call depth 251: main:12 > deep:7 x 251)".
  static std::string faultWhere(const Event& x) {
    if (x.line <= 0 && x.calls.empty()) return "";
    std::string out = " (";
    if (x.line > 0) out += fmt::format("line {}", x.line);
    if (!x.calls.empty())
      out += fmt::format("{}call depth {}: {}", x.line > 0 ? "; " : "", x.depth, x.calls);
    return out + ")";
  }
  std::string contactEnd(const Contact& c) const {
    return c.end_t ? fmt::format("for {}", dur(*c.end_t - c.t)) : "until the end";
  }
};

constexpr const char* kSeeing =
    "seeing: the program's latest reading of either eye above 48, ICEMAN's own test; eye "
    "readings below are the 20-Hz samples'; simbot bench's stall_s is the total";

}  // namespace

std::vector<TextLine> textLines(const Report& r) {
  const Fmt f{r};
  std::vector<TextLine> out;
  auto add = [&](std::string text, std::optional<Tick> t = std::nullopt) {
    out.push_back({std::move(text), t});
  };
  add(fmt::format("simbot explain: {:.3f} s, seed {}, profile {}",
                  static_cast<double>(r.end_t) / r.ticks_per_second, r.seed, r.profile));
  for (std::size_t i = 0; i < r.robots.size(); ++i) {
    const RobotInfo& x = r.robots[i];
    add(fmt::format("  {} {}{}: {} hits / {} shots, {} frames latched, {} rejected{}{}", x.name,
                    x.program, x.scripted ? " (scripted beacon)" : "", x.hits, x.shots,
                    x.frames_latched, x.frames_rejected, x.faulted ? ", FAULTED" : "",
                    x.exited ? ", main returned" : ""));
  }
  if (!r.winner.empty()) add(fmt::format("  winner {}{}", r.winner, r.coin ? " (coin flip)" : ""));

  add("");
  add(fmt::format("Shots ({})", r.shots.size()));
  if (!r.shots.empty())
    add("  time s      robot gun  range ft  bearing err deg  muzzle ft/s  result");
  for (const Shot& x : r.shots)
    add(fmt::format("  {:>10}  {:<5} {:<3}  {:>8}  {:>15}  {:>11.1f}  {}{}", f.s(x.t),
                    f.name(x.robot), x.gun + 1, Fmt::ft(x.range_ft),
                    Fmt::signedDeg(x.bearing_error_deg), x.muzzle_fps, f.result(x),
                    x.range_ft && !x.target_in_view ? " (target out of view)" : ""),
        x.t);

  add("");
  add(
      fmt::format("Stalls: the program running and seeing the opponent, no motor frame latched "
                  "and the robot standing still, for more than 1 s ({})",
                  r.stalls.size()));
  add(fmt::format("  ({})", kSeeing));
  if (const Stall* x = Fmt::longest(r))
    add(fmt::format("  longest: {} {} s .. {} ({}), {}", f.name(x->robot), f.s(x->from),
                    f.until(*x), f.dur(x->to - x->from), f.eyes(*x)),
        x->from);
  for (const Stall& x : r.stalls) {
    add(fmt::format("  {} {} s .. {}: {} without a frame, {}", f.name(x.robot), f.s(x.from),
                    f.until(x), f.dur(x.to - x.from), f.eyes(x)),
        x.from);
    add(fmt::format("      on {}", f.lines(x, 3)));
    add(fmt::format("      command in force: {}; moved {:.2f} ft, turned {:+.0f} deg{}",
                    x.last_frame.empty() ? "none yet"
                                         : sinks::jsonString(x.last_frame, true) + " (" +
                                               describeFrame(x.last_frame) + ")",
                    x.moved_ft, x.turned_deg, f.note(x)));
  }

  add("");
  add(
      fmt::format("Sends overwritten: a ser_send_z1 before the port had taken the previous send's "
                  "last byte ({})",
                  r.overwritten.size()));
  if (!r.overwrite_groups.empty()) add("  by the two sends' lines, most first:");
  for (const OverwriteGroup& x : r.overwrite_groups)
    add(fmt::format("  {}: {}", f.name(x.robot), f.group(x)), x.first);
  if (!r.overwritten.empty()) add("  each:");
  for (const OverwrittenSend& x : r.overwritten)
    add(fmt::format("  {} {} s: {}", f.name(x.robot), f.s(x.t), f.overwrite(x)), x.t);

  add("");
  add("Handlers: time in service (acceptance to the end of RETI)");
  for (const HandlerTotal& x : r.handler_totals)
    add(fmt::format("  {} {}: {} run{}, {} in all, longest {}", f.name(x.robot), x.handler, x.runs,
                    x.runs == 1 ? "" : "s", f.dur(x.total), f.dur(x.longest)));
  for (std::size_t i = 0; i < r.robots.size(); ++i)
    if (r.robots[i].serial_isr_runs)
      add(fmt::format("  {} serial transmit interrupt: {} runs, {} in all", r.robots[i].name,
                      r.robots[i].serial_isr_runs, f.dur(r.robots[i].serial_isr_total)));
  for (const HandlerRun& x : r.handler_runs) {
    add(fmt::format("  {} {} s {} for {}, interrupting {}", f.name(x.robot), f.s(x.from), x.handler,
                    f.inService(x), f.where(x.line, x.function)),
        x.from);
    add("      meanwhile " + f.meanwhile(x));
  }

  add("");
  add(fmt::format("Contacts ({})", r.contacts.size()));
  for (const Contact& x : r.contacts)
    add(fmt::format("  {} {} s {} bumper touched the {}, {}{}", f.name(x.robot), f.s(x.t), x.bumper,
                    x.with, f.contactEnd(x), x.reflex ? "; reflex" : ""),
        x.t);

  add("");
  add(fmt::format("Referee ({})", r.referee.size()));
  for (const Event& x : r.referee)
    add(fmt::format("  {} {} s {}", f.name(x.robot), f.s(x.t), x.what), x.t);

  add("");
  add(fmt::format("Faults, exits and reloads ({})", r.faults.size()));
  for (const Event& x : r.faults)
    add(fmt::format("  {} {} s {}{}", f.name(x.robot), f.s(x.t), x.what, Fmt::faultWhere(x)), x.t);
  return out;
}

std::string text(const Report& r) {
  std::string out;
  for (const auto& line : textLines(r)) {
    out += line.text;
    out += '\n';
  }
  return out;
}

std::string markdown(const Report& r) {
  const Fmt f{r};
  std::string o;
  auto cell = [](std::string s) {  // a table cell: no pipes, no newlines
    std::string out;
    for (char c : s)
      out += c == '|' ? std::string("\\|") : c == '\n' ? std::string(" ") : std::string(1, c);
    return out;
  };
  o += fmt::format("# simbot explain\n\n{:.3f} s, seed {}, profile {}\n\n",
                   static_cast<double>(r.end_t) / r.ticks_per_second, r.seed, r.profile);
  o += "| robot | program | hits | shots | frames latched | rejected | faulted "
       "|\n|---|---|---|---|---|---|---|\n";
  for (const RobotInfo& x : r.robots)
    o += fmt::format("| {} | `{}` | {} | {} | {} | {} | {} |\n", x.name, cell(x.program), x.hits,
                     x.shots, x.frames_latched, x.frames_rejected, x.faulted ? "yes" : "no");
  if (!r.winner.empty())
    o += fmt::format("\nWinner: **{}**{}\n", r.winner, r.coin ? " (coin flip)" : "");

  o += fmt::format("\n## Shots ({})\n\n", r.shots.size());
  if (!r.shots.empty()) {
    o += "| time (s) | robot | gun | range (ft) | bearing error (deg) | muzzle (ft/s) | result |\n"
         "|---:|---|---:|---:|---:|---:|---|\n";
    for (const Shot& x : r.shots)
      o += fmt::format("| {} | {} | {} | {} | {} | {:.1f} | {}{} |\n", f.s(x.t), f.name(x.robot),
                       x.gun + 1, Fmt::ft(x.range_ft), Fmt::signedDeg(x.bearing_error_deg),
                       x.muzzle_fps, f.result(x),
                       x.range_ft && !x.target_in_view ? " (target out of view)" : "");
  }

  o += fmt::format(
      "\n## Stalls ({})\n\nThe program running and seeing the opponent, no motor frame latched "
      "and the robot standing still, for more than 1 s; {}.\n\n",
      r.stalls.size(), kSeeing);
  if (const Stall* x = Fmt::longest(r))
    o += fmt::format("Longest: **{}** {} s .. {} ({}), {}.\n\n", f.name(x->robot), f.s(x->from),
                     f.until(*x), f.dur(x->to - x->from), f.eyes(*x));
  for (const Stall& x : r.stalls)
    o += fmt::format(
        "- **{}** {} s .. {}: {} without a frame, {}; on {}; command in force: {}; moved {:.2f} "
        "ft, turned {:+.0f} deg{}\n",
        f.name(x.robot), f.s(x.from), f.until(x), f.dur(x.to - x.from), f.eyes(x), f.lines(x, 3),
        x.last_frame.empty() ? "none yet" : "`" + sinks::jsonString(x.last_frame, true) + "`",
        x.moved_ft, x.turned_deg, f.note(x));

  o += fmt::format(
      "\n## Sends overwritten ({})\n\nA `ser_send_z1` before the port had taken the previous "
      "send's last byte: the library re-points at `buf[0]`, so that frame is never latched as "
      "sent.\n\n",
      r.overwritten.size());
  if (!r.overwrite_groups.empty()) {
    o += "By the two sends' lines, most first:\n\n";
    for (const OverwriteGroup& x : r.overwrite_groups)
      o += fmt::format("- **{}** {}\n", f.name(x.robot), f.group(x));
    o += "\nEach:\n\n";
  }
  for (const OverwrittenSend& x : r.overwritten)
    o += fmt::format("- **{}** {} s: {}\n", f.name(x.robot), f.s(x.t), f.overwrite(x));

  o += "\n## Handlers\n\n| robot | handler | runs | total (s) | longest (s) "
       "|\n|---|---|---:|---:|---:|\n";
  for (const HandlerTotal& x : r.handler_totals)
    o += fmt::format("| {} | `{}` | {} | {} | {} |\n", f.name(x.robot), cell(x.handler), x.runs,
                     f.s(x.total), f.s(x.longest));
  for (std::size_t i = 0; i < r.robots.size(); ++i)
    if (r.robots[i].serial_isr_runs)
      o += fmt::format("| {} | serial transmit | {} | {} | |\n", r.robots[i].name,
                       r.robots[i].serial_isr_runs, f.s(r.robots[i].serial_isr_total));
  if (!r.handler_runs.empty()) o += "\n";
  for (const HandlerRun& x : r.handler_runs)
    o += fmt::format("- **{}** {} s `{}` for {}, interrupting {}; meanwhile {}\n", f.name(x.robot),
                     f.s(x.from), x.handler, f.inService(x), f.where(x.line, x.function),
                     f.meanwhile(x));

  o += fmt::format("\n## Contacts ({})\n\n", r.contacts.size());
  if (!r.contacts.empty()) {
    o += "| time (s) | robot | bumper | with | how long | reflex |\n|---:|---|---|---|---|---|\n";
    for (const Contact& x : r.contacts)
      o += fmt::format("| {} | {} | {} | {} | {} | {} |\n", f.s(x.t), f.name(x.robot), x.bumper,
                       x.with, f.contactEnd(x), x.reflex ? "yes" : "no");
  }
  o += fmt::format("\n## Referee ({})\n\n", r.referee.size());
  for (const Event& x : r.referee)
    o += fmt::format("- **{}** {} s {}\n", f.name(x.robot), f.s(x.t), x.what);
  o += fmt::format("\n## Faults, exits and reloads ({})\n\n", r.faults.size());
  for (const Event& x : r.faults)
    o += fmt::format("- **{}** {} s {}{}\n", f.name(x.robot), f.s(x.t), cell(x.what),
                     cell(Fmt::faultWhere(x)));
  return o;
}

nlohmann::json json(const Report& r) {
  using nlohmann::json;
  const double tps = r.ticks_per_second;
  auto sec = [tps](Tick t) { return static_cast<double>(t) / tps; };
  auto opt = [](const auto& v) { return v ? json(*v) : json(nullptr); };
  json j = {{"end_s", sec(r.end_t)},
            {"seed", r.seed},
            {"profile", r.profile},
            {"winner", r.winner},
            {"tie_broken_by_coin", r.coin}};
  json robots = json::array();
  for (const RobotInfo& x : r.robots)
    robots.push_back({{"name", x.name},
                      {"program", sinks::jsonString(x.program, false)},
                      {"scripted", x.scripted},
                      {"hits", x.hits},
                      {"shots", x.shots},
                      {"frames_latched", x.frames_latched},
                      {"frames_rejected", x.frames_rejected},
                      {"faulted", x.faulted},
                      {"exited", x.exited},
                      {"serial_isr_runs", x.serial_isr_runs},
                      {"serial_isr_s", sec(x.serial_isr_total)}});
  j["robots"] = robots;
  json shots = json::array();
  for (const Shot& x : r.shots)
    shots.push_back({{"robot", kNames[x.robot & 1]},
                     {"gun", x.gun + 1},
                     {"ball", x.ball},
                     {"t", x.t},
                     {"time_s", sec(x.t)},
                     {"range_ft", opt(x.range_ft)},
                     {"bearing_error_deg", opt(x.bearing_error_deg)},
                     {"muzzle_fps", x.muzzle_fps},
                     {"target_in_view", x.target_in_view},
                     {"hit", x.hit},
                     {"ended", x.ended},
                     {"end_s", x.end_t ? json(sec(*x.end_t)) : json(nullptr)},
                     {"miss_ft", opt(x.miss_ft)}});
  j["shots"] = shots;
  json stalls = json::array();
  for (const Stall& x : r.stalls) {
    json lines = json::array();
    for (const auto& l : x.lines)
      lines.push_back({{"line", l.line},
                       {"function", sinks::jsonString(l.function, false)},
                       {"source", sinks::jsonString(l.text, false)},
                       {"samples", l.samples}});
    stalls.push_back(
        {{"robot", kNames[x.robot & 1]},
         {"from_s", sec(x.from)},
         {"to_s", sec(x.to)},
         {"to_end", x.to_end},
         {"samples", x.samples},
         {"eye_left",
          {{"median", x.eye_left_median}, {"min", x.eye_left_min}, {"max", x.eye_left_max}}},
         {"eye_right",
          {{"median", x.eye_right_median}, {"min", x.eye_right_min}, {"max", x.eye_right_max}}},
         {"lines", lines},
         {"command", sinks::jsonString(x.last_frame, true)},
         {"moved_ft", x.moved_ft},
         {"turned_deg", x.turned_deg},
         {"halted", x.halted},
         {"shots", x.shots},
         {"one_eye", x.one_eye}});
  }
  j["stalls"] = stalls;
  // A send's site as fields named with `prefix`.
  auto site = [](json& o, const std::string& prefix, const SendSite& x) {
    o[prefix + "line"] = x.line;
    o[prefix + "function"] = sinks::jsonString(x.function, false);
    o[prefix + "caller_line"] = x.caller_line;
    o[prefix + "caller_function"] = sinks::jsonString(x.caller_function, false);
    o[prefix + "calls"] = sinks::jsonString(x.calls, false);
  };
  json sends = json::array();
  for (const OverwrittenSend& x : r.overwritten) {
    json o = {{"robot", kNames[x.robot & 1]},
              {"time_s", sec(x.t)},
              {"previous_s", sec(x.previous_t)},
              {"previous_count", x.previous_count},
              {"previous_bytes_fetched", x.previous_bytes_fetched},
              {"handler", sinks::jsonString(x.handler, false)}};
    site(o, "", x.send);
    site(o, "previous_", x.previous);
    sends.push_back(std::move(o));
  }
  j["overwritten_sends"] = sends;
  json groups = json::array();
  for (const OverwriteGroup& x : r.overwrite_groups) {
    json o = {{"robot", kNames[x.robot & 1]},
              {"count", x.count},
              {"first_s", sec(x.first)},
              {"last_s", sec(x.last)}};
    site(o, "", x.send);
    site(o, "previous_", x.previous);
    groups.push_back(std::move(o));
  }
  j["overwrite_groups"] = groups;
  json totals = json::array();
  for (const HandlerTotal& x : r.handler_totals)
    totals.push_back({{"robot", kNames[x.robot & 1]},
                      {"handler", sinks::jsonString(x.handler, false)},
                      {"runs", x.runs},
                      {"total_s", sec(x.total)},
                      {"longest_s", sec(x.longest)}});
  j["handlers"] = totals;
  json runs = json::array();
  for (const HandlerRun& x : r.handler_runs) {
    json frames = json::array();
    for (const auto& fr : x.frames) frames.push_back(sinks::jsonString(fr, true));
    runs.push_back({{"robot", kNames[x.robot & 1]},
                    {"source", x.source},
                    {"handler", sinks::jsonString(x.handler, false)},
                    {"from_s", sec(x.from)},
                    {"to_s", x.to ? json(sec(*x.to)) : json(nullptr)},
                    {"line", x.line},
                    {"function", sinks::jsonString(x.function, false)},
                    {"frames", frames},
                    {"sends", x.sends},
                    {"edges", x.edges},
                    {"contacts", x.contacts},
                    {"shots", x.shots},
                    {"moved_ft", x.moved_ft}});
  }
  j["handler_runs"] = runs;
  json contacts = json::array();
  for (const Contact& x : r.contacts)
    contacts.push_back({{"robot", kNames[x.robot & 1]},
                        {"time_s", sec(x.t)},
                        {"end_s", x.end_t ? json(sec(*x.end_t)) : json(nullptr)},
                        {"bumper", x.bumper},
                        {"with", x.with},
                        {"reflex", x.reflex}});
  j["contacts"] = contacts;
  auto events = [&](const std::vector<Event>& v) {
    json a = json::array();
    for (const Event& x : v)
      a.push_back({{"robot", x.robot < 0 ? json(nullptr) : json(kNames[x.robot & 1])},
                   {"time_s", sec(x.t)},
                   {"what", sinks::jsonString(x.what, false)},
                   {"line", x.line},
                   {"depth", x.depth},
                   {"calls", sinks::jsonString(x.calls, false)}});
    return a;
  };
  j["referee"] = events(r.referee);
  j["faults"] = events(r.faults);
  return j;
}

}  // namespace simbot::reports::explain
