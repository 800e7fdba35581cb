// config/scenario.cpp -- scenario files (config.h parseScenario,
// loadScenario): a checked walk over toml++'s document.
//
// The walk knows every key of every table, so an unknown key, a wrong type,
// a value out of range or a missing companion key is reported at its line.
// Paths are resolved against the scenario's directory and checked to exist
// while loading, so that the error names the scenario's line; the files
// they name (profiles, hardware files, programs) report their own errors.
// Things that depend on the profile or the program (a start pose inside
// the field, a line that has code) are checked when runs/ applies the
// scenario to a run (runs/scenario.cpp), still naming the scenario's line.
#include <fmt/format.h>
#include <toml++/toml.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>

#include "config/config.h"
#include "config/obstacles.h"
#include "config/text.h"
#include "timebase/written.h"

namespace simbot::config {

namespace {

namespace fs = std::filesystem;

SourcePos posOf(const toml::source_region& where) {
  return {static_cast<int>(where.begin.line), static_cast<int>(where.begin.column)};
}

class Walker {
 public:
  Walker(std::string file, std::string baseDir)
      : file_(std::move(file)), base_(std::move(baseDir)) {}

  [[noreturn]] void fail(SourcePos at, const std::string& msg) const {
    throw ConfigError(file_, at.line, at.column, msg);
  }
  [[noreturn]] void fail(const toml::node& n, const std::string& msg) const {
    fail(posOf(n.source()), msg);
  }

  toml::table parse(std::string_view text) const { return parseToml(text, file_); }

  // A number within [lo, hi]. Integers are read as integers: toml++ gives
  // no double for one it cannot represent exactly (beyond 2^53).
  double number(const toml::node& n, const std::string& name, double lo, double hi) const {
    double v = 0;
    if (const auto* i = n.as_integer())
      v = static_cast<double>(i->get());
    else if (const auto* f = n.as_floating_point())
      v = f->get();
    else
      fail(n, fmt::format("'{}' must be a number", name));
    if (!std::isfinite(v)) fail(n, fmt::format("'{}' must be finite", name));
    if (v < lo || v > hi)
      fail(n, fmt::format("'{}' must be between {} and {}, got {}", name, lo, hi, v));
    return v;
  }
  double positive(const toml::node& n, const std::string& name, double hi) const {
    const double v = number(n, name, -std::numeric_limits<double>::max(), hi);
    if (!(v > 0)) fail(n, fmt::format("'{}' must be greater than 0, got {}", name, v));
    return v;
  }
  std::string string(const toml::node& n, const std::string& name) const {
    if (!n.is_string()) fail(n, fmt::format("'{}' must be a string", name));
    const std::string s = *n.value<std::string>();
    if (s.empty()) fail(n, fmt::format("'{}' must not be empty", name));
    return s;
  }
  // A file named relative to the scenario's directory; it must exist.
  std::string file(const toml::node& n, const std::string& name) const {
    const std::string s = string(n, name);
    fs::path p = s;
    if (p.is_relative()) p = fs::path(base_) / p;
    std::error_code ec;
    if (!fs::is_regular_file(p, ec))
      fail(n, fmt::format("'{}': no file '{}'", name, p.lexically_normal().string()));
    return p.lexically_normal().string();
  }

  // start = { x_ft = ..., y_ft = ..., heading_deg = ... }
  plant::Pose pose(const toml::node& n, const std::string& name) const {
    const toml::table* t = n.as_table();
    if (!t)
      fail(n, fmt::format("'{}' must be a table {{ x_ft = ..., y_ft = ..., heading_deg = ... }}",
                          name));
    onlyKeys(*t, file_, "'" + name + "'", {"x_ft", "y_ft", "heading_deg"});
    auto need = [&](const char* key) {
      const toml::node* v = t->get(key);
      if (!v) fail(n, fmt::format("'{}' has no '{}'", name, key));
      // Poses are checked against the field when the run is set up.
      return key == std::string_view("heading_deg") ? number(*v, name + "." + key, -3600, 3600)
                                                    : number(*v, name + "." + key, -100, 100);
    };
    plant::Pose p{need("x_ft"), need("y_ft"), need("heading_deg")};
    p.heading_deg = std::fmod(p.heading_deg, 360.0);
    if (p.heading_deg < 0) p.heading_deg += 360;
    return p;
  }

  void robot(const toml::table& t, const char* section, ScenarioRobot& r) const {
    if (const toml::node* n = t.get("start")) {
      r.start = pose(*n, std::string(section) + ".start");
      r.startPos = posOf(n->source());
    }
    if (const toml::node* n = t.get("hardware"))
      r.hardware = file(*n, std::string(section) + ".hardware");
    if (const toml::node* n = t.get("inject")) {
      const toml::array* arr = n->as_array();
      if (!arr)
        fail(*n, fmt::format("'{}.inject' must be an array of \"SOURCE@WHEN\" strings", section));
      for (const toml::node& e : *arr) {
        const std::string what = string(e, std::string(section) + ".inject");
        // Checked now; the robot is the section's, so the message quotes
        // the text without the "A:" put in front of it here.
        try {
          parseInjection(std::string("A:") + what, 1);
        } catch (const std::invalid_argument& err) {
          std::string msg = err.what();
          if (const auto at = msg.find("'A:"); at != std::string::npos) msg.erase(at + 1, 2);
          fail(e, msg);
        }
        r.inject.push_back({what, posOf(e.source())});
      }
    }
  }

  //   { forward_ft = D, speed_fps = V }
  //   { arc_radius_ft = R, turn_deg = T, speed_fps = V }
  //   { spin_deg = T, speed_fps = V }
  //   { wait_s = S }
  PathLeg leg(const toml::node& n, size_t index) const {
    const std::string name = fmt::format("B.path[{}]", index);
    const toml::table* t = n.as_table();
    if (!t)
      fail(n, fmt::format("'{}' must be a table (forward_ft, arc_radius_ft, spin_deg or wait_s)",
                          name));
    onlyKeys(*t, file_, "'" + name + "'",
             {"forward_ft", "arc_radius_ft", "turn_deg", "spin_deg", "wait_s", "speed_fps"});
    PathLeg leg;
    leg.pos = posOf(n.source());
    const int kinds = (t->contains("forward_ft") ? 1 : 0) + (t->contains("arc_radius_ft") ? 1 : 0) +
                      (t->contains("spin_deg") ? 1 : 0) + (t->contains("wait_s") ? 1 : 0);
    if (kinds != 1)
      fail(n,
           fmt::format("'{}' must have exactly one of forward_ft, arc_radius_ft, spin_deg, wait_s",
                       name));
    const toml::node* speed = t->get("speed_fps");
    const toml::node* turn = t->get("turn_deg");
    if (turn && !t->contains("arc_radius_ft"))
      fail(*turn, fmt::format("'{}': turn_deg belongs to an arc (arc_radius_ft)", name));
    if (const toml::node* w = t->get("wait_s")) {
      if (speed) fail(*speed, fmt::format("'{}': a wait has no speed_fps", name));
      leg.kind = PathLeg::Kind::Wait;
      leg.wait = timeValue(*w, file_, name + ".wait_s", false);
      // A leg shorter than a tick is refused where the path is driven
      // (runs/driveLegs), with the other legs; longer than any run is pointless.
      if (leg.wait > timebase::kMaxRunTicks)
        fail(*w, fmt::format("'{}.wait_s' is longer than the longest run (1e6 s)", name));
      return leg;
    }
    if (!speed) fail(n, fmt::format("'{}' has no 'speed_fps'", name));
    leg.speedFps = positive(*speed, name + ".speed_fps", 20);
    if (const toml::node* f = t->get("forward_ft")) {
      leg.kind = PathLeg::Kind::Forward;
      leg.forwardFt = number(*f, name + ".forward_ft", -1e4, 1e4);
      if (leg.forwardFt == 0) fail(*f, fmt::format("'{}.forward_ft' must not be 0", name));
    } else if (const toml::node* r = t->get("arc_radius_ft")) {
      leg.kind = PathLeg::Kind::Arc;
      leg.radiusFt = positive(*r, name + ".arc_radius_ft", 1e4);
      if (!turn) fail(n, fmt::format("'{}' has no 'turn_deg' (the arc's signed angle)", name));
      leg.turnDeg = number(*turn, name + ".turn_deg", -36000, 36000);
      if (leg.turnDeg == 0) fail(*turn, fmt::format("'{}.turn_deg' must not be 0", name));
    } else {
      const toml::node& s = *t->get("spin_deg");
      leg.kind = PathLeg::Kind::Spin;
      leg.turnDeg = number(s, name + ".spin_deg", -36000, 36000);
      if (leg.turnDeg == 0) fail(s, fmt::format("'{}.spin_deg' must not be 0", name));
    }
    return leg;
  }

  Scenario walk(const toml::table& root) const {
    Scenario s;
    s.file = file_;
    onlyKeys(root, file_, "the scenario",
             {"profile", "rules", "seconds", "seed", "A", "B", "obstacles"});
    if (const toml::node* n = root.get("obstacles")) s.obstacles = parseObstacles(*n, file_);
    if (const toml::node* n = root.get("profile")) {
      const std::string v = string(*n, "profile");
      const bool isPath = v.find('/') != std::string::npos || fs::path(v).extension() == ".toml";
      if (isPath) {
        s.profile = file(*n, "profile");
      } else {
        if (!shippedProfilePath(v))
          fail(*n, fmt::format(
                       "'profile': no profile '{}' in profiles/ (or give a path to a .toml)", v));
        s.profile = v;
      }
    }
    if (const toml::node* n = root.get("rules")) {
      const std::string v = string(*n, "rules");
      const bool isPath = v.find('/') != std::string::npos || fs::path(v).extension() == ".toml";
      if (isPath) {
        s.rules = file(*n, "rules");
      } else {
        if (!shippedRulesPath(v))
          fail(*n,
               fmt::format("'rules': no rule set '{}' in rules/ (or give a path to a .toml)", v));
        s.rules = v;
      }
    }
    if (const toml::node* n = root.get("seconds")) s.length = timeValue(*n, file_, "seconds", true);
    if (const toml::node* n = root.get("seed")) {
      const auto seed = seedValue(*n);
      if (!seed)
        fail(*n,
             "'seed' must be an integer from 0 to 2^63 - 1, or a string of digits up to "
             "\"18446744073709551615\"");
      s.seed = *seed;
    }
    if (const toml::node* n = root.get("A")) {
      const toml::table* t = n->as_table();
      if (!t) fail(*n, "'A' must be a table ([A])");
      onlyKeys(*t, file_, "[A]", {"start", "hardware", "inject"});
      robot(*t, "A", s.a);
    }
    if (const toml::node* n = root.get("B")) {
      const toml::table* t = n->as_table();
      if (!t) fail(*n, "'B' must be a table ([B])");
      onlyKeys(*t, file_, "[B]",
               {"program", "beacon", "start", "hardware", "inject", "path", "repeat"});
      robot(*t, "B", s.b);
      s.opponentPos = posOf(n->source());
      const toml::node* program = t->get("program");
      const toml::node* beacon = t->get("beacon");
      if (program && beacon) fail(*beacon, "[B] is either a program or a beacon, not both");
      if (program) {
        s.opponent = Scenario::Opponent::Program;
        s.opponentPos = posOf(program->source());
        s.program = file(*program, "B.program");
      } else if (beacon) {
        if (!beacon->is_boolean() || !*beacon->value<bool>())
          fail(*beacon, "'B.beacon' must be true (or leave it out and give B.program)");
        s.opponent = Scenario::Opponent::Beacon;
        s.opponentPos = posOf(beacon->source());
      }
      const toml::node* path = t->get("path");
      const toml::node* repeat = t->get("repeat");
      if ((path || repeat) && s.opponent != Scenario::Opponent::Beacon)
        fail(path ? *path : *repeat, "only a beacon (B.beacon = true) drives a path");
      if (const toml::node* inject = t->get("inject");
          inject && s.opponent == Scenario::Opponent::Beacon)
        fail(*inject, "a beacon has no program to interrupt; B.inject needs B.program");
      if (path) {
        const toml::array* arr = path->as_array();
        if (!arr || arr->empty()) fail(*path, "'B.path' must be a non-empty array of legs");
        for (size_t i = 0; i < arr->size(); ++i) s.path.push_back(leg(*arr->get(i), i));
      }
      if (repeat) {
        if (!repeat->is_boolean()) fail(*repeat, "'B.repeat' must be true or false");
        s.repeatPath = *repeat->value<bool>();
      }
    }
    return s;
  }

 private:
  std::string file_, base_;
};

}  // namespace

Scenario parseScenario(std::string_view text, const std::string& sourceName,
                       const std::string& baseDir) {
  Walker w(sourceName, baseDir);
  return w.walk(w.parse(text));
}

Scenario loadScenario(const std::string& path) {
  const std::string text = readFile(path);
  const fs::path dir = fs::path(path).parent_path();
  return parseScenario(text, path, dir.empty() ? "." : dir.string());
}

}  // namespace simbot::config
