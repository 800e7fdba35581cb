// The explain report (see explain.h), made: one pass over the records in
// tick order, keeping only the open periods and the latest samples. The
// report is written out in words by explain_text.cpp and as JSON by
// explain_json.cpp.
#include "reports/explain.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <set>
#include <sstream>
#include <string>
#include <tuple>
#include <utility>

#include "plant/plant.h"
#include "reports/stall.h"
#include "sinks/trace_jsonl.h"

namespace simbot::reports::explain {

namespace {

namespace rec = trace::rec;
constexpr double kPi = 3.14159265358979323846;

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
    for (int i = 0; i < robots; ++i) report.robots[static_cast<size_t>(i)].name = kRobotNames[i];
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
    if (mines.contains(x.with))
      course(x.robot, t, fmt::format("{} bumper tripped by a mine: {}", x.bumper, x.with));
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
    if (x.hit.starts_with("obstacle"))
      course(x.robot, t,
             fmt::format("ball {} (gun {}) stopped by an obstacle: {}", x.ball, s.gun + 1, x.hit));
    if (x.hit.starts_with("block"))
      course(x.robot, t,
             fmt::format("ball {} (gun {}) stopped by a block: {}", x.ball, s.gun + 1, x.hit));
  }
  // ---- the wider competition (DESIGN.md)
  std::set<std::string> mines;  // the labels of the obstacles with mine = true
  void course(int robot, Tick t, std::string what) {
    report.course.push_back({robot, t, std::move(what), 0, "", 0});
  }
  void on(Tick t, const rec::Obstacle& x) {
    const std::string label = x.name.empty() ? fmt::format("obstacle {}", x.index)
                                             : fmt::format("obstacle {} ({})", x.index, x.name);
    if (x.mine) mines.insert(label);
    const std::string shape =
        x.kind == "circle" ? fmt::format("circle of radius {:.2f} ft", x.radius_ft) : x.kind;
    course(-1, t,
           fmt::format("{}: {} at ({:.2f}, {:.2f}) ft, {:.2f} ft high{}", label, shape, x.x_ft,
                       x.y_ft, x.height_ft, x.mine ? ", a mine" : ""));
  }
  void on(Tick t, const rec::ScatterShot& x) {
    ++report.scatter_shots[x.robot & 1];
    course(x.robot, t,
           fmt::format("scatter shot: gun {} ball {} fired with eyes {}/{}, neither above {:g}{}",
                       x.gun + 1, x.ball, x.eye_left, x.eye_right, x.threshold,
                       x.scores ? "" : "; its hit would not score"));
  }
  void on(Tick t, const rec::Reset& x) {
    const std::string volts = x.voltage_v ? fmt::format(" ({:.2f} V)", *x.voltage_v) : "";
    course(x.robot, t,
           x.cause == "brown_out"
               ? fmt::format("brown-out at {:.1f} s{}: the board reset (brown-out {})",
                             static_cast<double>(t) / tps(), volts, x.resets)
               : fmt::format("injected reset at {:.1f} s{}: the board reset (injected {})",
                             static_cast<double>(t) / tps(), volts, x.resets));
  }
  void on(Tick t, const rec::Restart& x) {
    course(x.robot, t,
           fmt::format("restarted from main at {:.1f} s{}", static_cast<double>(t) / tps(),
                       x.voltage_v ? fmt::format(" ({:.2f} V)", *x.voltage_v) : ""));
  }
  void on(Tick t, const rec::DiscFire& x) {
    course(x.robot, t,
           fmt::format("disc {} fired, heading {:.1f} deg, {:.1f} ft/s", x.disc, x.heading_deg,
                       std::hypot(x.vx_fps, x.vy_fps)));
  }
  void on(Tick t, const rec::DiscHit& x) {
    course(x.robot, t, fmt::format("disc {} hit {}", x.disc, kRobotNames[x.target & 1]));
  }
  void on(Tick t, const rec::DiscMiss& x) {
    const std::string how = x.hit == "stopped" ? "stopped on the floor" : "struck the " + x.hit;
    course(x.robot, t,
           fmt::format("disc {} missed: {} at ({:.2f}, {:.2f}) ft{}", x.disc, how, x.x_ft, x.y_ft,
                       x.closest_ft ? fmt::format(", closest {:.2f} ft", *x.closest_ft) : ""));
  }
  void on(Tick t, const rec::DiscEmpty& x) {
    course(x.robot, t, "disc launcher fired empty: nothing flies");
  }
  void on(Tick t, const rec::Deploy& x) {
    std::string kind = x.kind;
    std::replace(kind.begin(), kind.end(), '_', ' ');
    course(x.robot, t,
           fmt::format("set down {} {} (bit {}) at ({:.2f}, {:.2f}) ft", kind, x.number, x.bit,
                       x.x_ft, x.y_ft));
  }
  // Whose beacon the robot's eyes lost behind a screen, or found again.
  void on(Tick t, const rec::ScreenHides& x) {
    course(x.robot, t,
           fmt::format("{} {} a decoy screen ({}'s screen {})", kRobotNames[(1 - x.robot) & 1],
                       x.hidden ? "hidden by" : "no longer hidden by", kRobotNames[x.owner & 1],
                       x.number));
  }
  void on(Tick t, const rec::DeployBlocked& x) {
    course(x.robot, t,
           fmt::format("could not set down a block (bit {}): no room at ({:.2f}, {:.2f}) ft", x.bit,
                       x.x_ft, x.y_ft));
  }
  // A push in one sentence at its end: how far, where to, what stopped it.
  void on(Tick t, const rec::PushEnd& x) {
    const bool named = x.by.starts_with("obstacle") || x.by.starts_with("block");
    const std::string why = x.by == "drive" ? ""
                            : x.by == "robot"
                                ? "; the other robot held it"
                                : (named ? "; stopped by " : "; stopped by the ") + x.by;
    course(x.robot, t,
           fmt::format("pushed block {} {:.3f} ft, to ({:.2f}, {:.2f}) ft{}", x.block, x.pushed_ft,
                       x.x_ft, x.y_ft, why));
  }
  void on(Tick t, const rec::DeployEmpty& x) {
    std::string kind = x.kind;
    std::replace(kind.begin(), kind.end(), '_', ' ');
    course(x.robot, t, fmt::format("no {} left to set down (bit {})", kind, x.bit));
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
  keep(out.course);
  return out;
}

Report explainFile(const std::string& path) {
  Explainer explainer;
  const sinks::TraceRead read =
      sinks::readTrace(path, [&](const trace::Entry& e) { explainer.write(e); });
  std::cerr << sinks::cutShortWarning(path, read);
  return explainer.report();
}

}  // namespace simbot::reports::explain
