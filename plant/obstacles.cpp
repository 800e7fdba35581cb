// plant/obstacles.cpp -- fixed obstacles' shapes, names and the tests the
// eyes and the hand placement make against them (plant.h, "obstacles").
// The arena's contacts and balls use the same shapes (geometry.h Convex).
#include <algorithm>
#include <cmath>

#include "plant/geometry.h"
#include "plant/plant.h"

namespace simbot::plant {

Obstacle makeBox(double x, double y, double width, double depth, double angleDeg, double height) {
  Obstacle o;
  o.kind = Obstacle::Kind::Box;
  o.x_ft = x;
  o.y_ft = y;
  o.width_ft = width;
  o.depth_ft = depth;
  o.angle_deg = angleDeg;
  o.height_ft = height;
  // Turned clockwise by the angle, as headings turn: the box's own x axis
  // (width) is (cos a, -sin a), its y axis (depth) (sin a, cos a).
  const double a = geom::degToRad(angleDeg);
  const geom::Vec2 ux(std::cos(a), -std::sin(a)), uy(std::sin(a), std::cos(a));
  const double corners[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};  // counter-clockwise
  for (const auto& c : corners) {
    const geom::Vec2 p = geom::Vec2(x, y) + (c[0] * width / 2) * ux + (c[1] * depth / 2) * uy;
    o.points.push_back({p.x(), p.y()});
  }
  return o;
}

Obstacle makePolygon(const std::vector<ObstaclePoint>& points, double height) {
  Obstacle o;
  o.kind = Obstacle::Kind::Polygon;
  o.height_ft = height;
  o.points = points;
  double area2 = 0;
  for (std::size_t k = 0; k < points.size(); ++k) {
    const ObstaclePoint& a = points[k];
    const ObstaclePoint& b = points[(k + 1) % points.size()];
    area2 += a.x_ft * b.y_ft - b.x_ft * a.y_ft;
    o.x_ft += a.x_ft / static_cast<double>(points.size());
    o.y_ft += a.y_ft / static_cast<double>(points.size());
  }
  if (area2 < 0) std::reverse(o.points.begin(), o.points.end());
  return o;
}

const char* obstacleKindName(Obstacle::Kind k) {
  switch (k) {
    case Obstacle::Kind::Circle:
      return "circle";
    case Obstacle::Kind::Box:
      return "box";
    case Obstacle::Kind::Polygon:
      return "polygon";
  }
  return "?";
}

std::string obstacleLabel(const FieldParams& field, int index) {
  std::string label = "obstacle " + std::to_string(index + 1);
  if (index >= 0 && index < static_cast<int>(field.obstacles.size()) &&
      !field.obstacles[static_cast<std::size_t>(index)].name.empty())
    label += " (" + field.obstacles[static_cast<std::size_t>(index)].name + ")";
  return label;
}

bool obstacleBlocks(double ax, double ay, double bx, double by, const FieldParams& field) {
  const geom::Vec2 a(ax, ay), d = geom::Vec2(bx, by) - a;
  for (const Obstacle& o : field.obstacles) {
    if (!(o.height_ft > field.beacon_height_ft)) continue;
    double lo = 0, hi = 0;
    if (geom::clipLine(a, d, geom::convexOf(o), 0.0, 1.0, lo, hi)) return true;
  }
  return false;
}

double obstacleClearance(double x, double y, double radius, const Obstacle& obstacle) {
  return geom::signedDistance(geom::Vec2(x, y), geom::convexOf(obstacle), nullptr) - radius;
}

}  // namespace simbot::plant
