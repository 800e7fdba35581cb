// config/obstacles.cpp -- the [[obstacles]] array (obstacles.h) and the
// checks of obstacles against a run's field and start poses (config.h
// checkObstacles).
#include "config/obstacles.h"

#include <fmt/format.h>

#include <cmath>
#include <initializer_list>
#include <numbers>

#include "config/text.h"

namespace simbot::config {

namespace {

SourcePos posOf(const toml::node& n) {
  return {static_cast<int>(n.source().begin.line), static_cast<int>(n.source().begin.column)};
}

class ObstacleReader {
 public:
  explicit ObstacleReader(const std::string& file) : file_(file) {}

  [[noreturn]] void fail(const toml::node& n, const std::string& msg) const {
    failAt(file_, n.source(), msg);
  }

  double number(const toml::node& n, const std::string& name) const {
    double v = 0;
    if (const auto* i = n.as_integer())
      v = static_cast<double>(i->get());
    else if (const auto* f = n.as_floating_point())
      v = f->get();
    else
      fail(n, fmt::format("'{}' must be a number", name));
    if (!std::isfinite(v)) fail(n, fmt::format("'{}' must be finite", name));
    // Far beyond any field (profiles allow 100 ft); the field is checked
    // when the run is set up (checkObstacles).
    if (std::abs(v) > 1000)
      fail(n, fmt::format("'{}' must be between -1000 and 1000, got {}", name, v));
    return v;
  }

  const toml::node& need(const toml::table& t, const char* key, const std::string& where) const {
    const toml::node* v = t.get(key);
    if (!v) fail(t, fmt::format("{} has no '{}'", where, key));
    return *v;
  }
  double coordinate(const toml::table& t, const char* key, const std::string& where) const {
    return number(need(t, key, where), where + "." + key);
  }
  double size(const toml::table& t, const char* key, const std::string& where) const {
    const toml::node& n = need(t, key, where);
    const double v = number(n, where + "." + key);
    if (!(v > 0)) fail(n, fmt::format("'{}.{}' must be greater than 0, got {}", where, key, v));
    return v;
  }

  // points_ft = [[x, y], ...]: 3 to kMaxObstacleVertices points, a convex
  // polygon that is not degenerate (no repeated or collinear corner, some
  // area) and winds round once.
  std::vector<plant::ObstaclePoint> points(const toml::node& n, const std::string& where) const {
    const std::string name = where + ".points_ft";
    const toml::array* arr = n.as_array();
    if (!arr) fail(n, fmt::format("'{}' must be an array of [x, y] points", name));
    if (arr->size() < 3 || arr->size() > static_cast<std::size_t>(plant::kMaxObstacleVertices))
      fail(n, fmt::format("'{}' must have 3 to {} points, got {}", name,
                          plant::kMaxObstacleVertices, arr->size()));
    std::vector<plant::ObstaclePoint> pts;
    for (const toml::node& e : *arr) {
      const toml::array* xy = e.as_array();
      if (!xy || xy->size() != 2) fail(e, fmt::format("each of '{}' must be [x, y]", name));
      pts.push_back({number(*xy->get(0), name), number(*xy->get(1), name)});
    }
    double minX = HUGE_VAL, maxX = -HUGE_VAL, minY = HUGE_VAL, maxY = -HUGE_VAL;
    for (const auto& p : pts) {
      minX = std::min(minX, p.x_ft);
      maxX = std::max(maxX, p.x_ft);
      minY = std::min(minY, p.y_ft);
      maxY = std::max(maxY, p.y_ft);
    }
    const double extent2 = (maxX - minX) * (maxX - minX) + (maxY - minY) * (maxY - minY);
    // A turn this small relative to the polygon's size is none: a corner
    // on a straight edge, or a point given twice.
    const double eps = 1e-9 * extent2;
    const std::size_t count = pts.size();
    int sign = 0;
    double winding = 0;
    for (std::size_t k = 0; k < count; ++k) {
      const auto& a = pts[k];
      const auto& b = pts[(k + 1) % count];
      const auto& c = pts[(k + 2) % count];
      const double ex = b.x_ft - a.x_ft, ey = b.y_ft - a.y_ft;
      const double fx = c.x_ft - b.x_ft, fy = c.y_ft - b.y_ft;
      const double cross = ex * fy - ey * fx;
      if (!(std::abs(cross) > eps) || extent2 == 0)
        fail(n, fmt::format("'{}' is degenerate: point {} ({}, {}) repeats a point or lies on a "
                            "straight line with its neighbours",
                            name, (k + 1) % count + 1, b.x_ft, b.y_ft));
      const int s = cross > 0 ? 1 : -1;
      if (sign != 0 && s != sign)
        fail(n, fmt::format("'{}' is not convex: it turns the other way at point {} ({}, {})", name,
                            (k + 1) % count + 1, b.x_ft, b.y_ft));
      sign = s;
      winding += std::atan2(cross, ex * fx + ey * fy);
    }
    if (std::abs(winding) > 3 * std::numbers::pi)
      fail(n, fmt::format("'{}' is not convex: its edges cross (it winds round more than once)",
                          name));
    return pts;
  }

  ObstacleSpec obstacle(const toml::node& n, std::size_t index) const {
    const std::string where = fmt::format("obstacles[{}]", index);
    const toml::table* t = n.as_table();
    if (!t) fail(n, fmt::format("'{}' must be a table ([[obstacles]])", where));
    const toml::node* kind = t->get("kind");
    if (!kind) fail(n, fmt::format("{} has no 'kind' (\"circle\", \"box\" or \"polygon\")", where));
    const std::optional<std::string> k = kind->value<std::string>();
    if (!kind->is_string() || (*k != "circle" && *k != "box" && *k != "polygon"))
      fail(*kind, fmt::format("'{}.kind' must be \"circle\", \"box\" or \"polygon\"", where));
    plant::Obstacle o;
    if (*k == "circle") {
      onlyKeys(*t, file_, where + " (a circle)",
               {"kind", "name", "mine", "x_ft", "y_ft", "radius_ft", "height_ft"});
      o.kind = plant::Obstacle::Kind::Circle;
      o.x_ft = coordinate(*t, "x_ft", where);
      o.y_ft = coordinate(*t, "y_ft", where);
      o.radius_ft = size(*t, "radius_ft", where);
      o.height_ft = size(*t, "height_ft", where);
    } else if (*k == "box") {
      onlyKeys(*t, file_, where + " (a box)",
               {"kind", "name", "mine", "x_ft", "y_ft", "width_ft", "depth_ft", "angle_deg",
                "height_ft"});
      const double x = coordinate(*t, "x_ft", where), y = coordinate(*t, "y_ft", where);
      const double w = size(*t, "width_ft", where), d = size(*t, "depth_ft", where);
      double angle = 0;
      if (const toml::node* a = t->get("angle_deg")) {
        angle = number(*a, where + ".angle_deg");
        if (std::abs(angle) > 360)
          fail(*a,
               fmt::format("'{}.angle_deg' must be between -360 and 360, got {}", where, angle));
      }
      o = plant::makeBox(x, y, w, d, angle, size(*t, "height_ft", where));
    } else {
      onlyKeys(*t, file_, where + " (a polygon)",
               {"kind", "name", "mine", "points_ft", "height_ft"});
      const auto pts = points(need(*t, "points_ft", where), where);
      o = plant::makePolygon(pts, size(*t, "height_ft", where));
    }
    if (const toml::node* nm = t->get("name")) {
      const std::optional<std::string> s = nm->value<std::string>();
      if (!nm->is_string() || s->empty() || s->size() > 40)
        fail(*nm, fmt::format("'{}.name' must be a string of 1 to 40 characters", where));
      for (const char c : *s)
        if (!((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
              c == ' ' || c == '-' || c == '_' || c == '.'))
          fail(*nm,
               fmt::format("'{}.name' may hold letters, digits, spaces, '-', '_' and '.'", where));
      o.name = *s;
    }
    if (const toml::node* m = t->get("mine")) {
      if (!m->is_boolean()) fail(*m, fmt::format("'{}.mine' must be true or false", where));
      o.mine = *m->value<bool>();
    }
    return {std::move(o), posOf(n)};
  }

 private:
  const std::string& file_;
};

}  // namespace

std::vector<ObstacleSpec> parseObstacles(const toml::node& node, const std::string& file) {
  const ObstacleReader r(file);
  const toml::array* arr = node.as_array();
  if (!arr) r.fail(node, "'obstacles' must be an array of tables ([[obstacles]])");
  if (arr->size() > static_cast<std::size_t>(plant::kMaxObstacles))
    r.fail(*arr->get(plant::kMaxObstacles),
           fmt::format("at most {} obstacles, got {}", plant::kMaxObstacles, arr->size()));
  std::vector<ObstacleSpec> out;
  for (std::size_t i = 0; i < arr->size(); ++i) out.push_back(r.obstacle(*arr->get(i), i));
  return out;
}

void checkObstacles(const std::vector<ObstacleSpec>& obstacles, const std::string& file,
                    const plant::ArenaConfig& arena) {
  const double half = arena.field.size_ft / 2;
  for (std::size_t k = 0; k < obstacles.size(); ++k) {
    const plant::Obstacle& o = obstacles[k].obstacle;
    auto fail = [&](const std::string& msg) {
      throw ConfigError(file, obstacles[k].pos.line, obstacles[k].pos.column,
                        fmt::format("obstacle {} {}", k + 1, msg));
    };
    bool inside = true;
    if (o.kind == plant::Obstacle::Kind::Circle)
      inside = std::abs(o.x_ft) + o.radius_ft <= half && std::abs(o.y_ft) + o.radius_ft <= half;
    for (const plant::ObstaclePoint& p : o.points)
      inside = inside && std::abs(p.x_ft) <= half && std::abs(p.y_ft) <= half;
    if (!inside)
      fail(fmt::format("reaches outside the {}-ft field (|x|, |y| <= {} ft)", arena.field.size_ft,
                       half));
    for (std::size_t i = 0; i < arena.robots.size(); ++i) {
      const plant::RobotSetup& r = arena.robots[i];
      if (plant::obstacleClearance(r.start.x_ft, r.start.y_ft, r.params.body_diameter_ft / 2, o) <=
          0)
        fail(fmt::format("overlaps robot {}'s start pose ({}, {}) ft", static_cast<char>('A' + i),
                         r.start.x_ft, r.start.y_ft));
    }
  }
}

}  // namespace simbot::config
