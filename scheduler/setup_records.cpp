// The first records of every trace: the run, the rules, the obstacles and
// each robot's set-up, as the round loop (match.cpp) emits them at tick 0.
#include <cmath>
#include <string>
#include <vector>

#include "scheduler/match_impl.h"

namespace simbot::scheduler::detail {

// The run's set-up: the first records of every trace.
void Match::emitSetup() {
  const plant::FieldParams& f = arenaConfig_->field;
  emit(0,
       trace::rec::Run{"simbot-trace/1", static_cast<int64_t>(config_.seed), config_.profileName,
                       static_cast<int64_t>(robots_.size()), config_.endTick, kTicksPerSecond,
                       config_.sampleInterval, f.size_ft, f.wire_inset_ft, f.wire_sensitivity_ft,
                       f.field_walls, f.divider_x_ft, f.divider_south_ft, f.divider_north_ft,
                       f.divider_thickness_ft, f.divider_height_ft, f.gravity_fps2},
       {});
  const plant::RefereeParams& referee = arenaConfig_->referee;
  if (referee.judge_scatter)
    emit(0,
         trace::rec::Rules{config_.rulesName, config_.rulesFile, f.divider, f.count_floor_skips,
                           referee.detect_threshold, referee.scatter_scores},
         {});
  for (std::size_t k = 0; k < f.obstacles.size(); ++k) {
    const plant::Obstacle& o = f.obstacles[k];
    std::vector<double> points;
    for (const plant::ObstaclePoint& p : o.points) {
      points.push_back(p.x_ft);
      points.push_back(p.y_ft);
    }
    emit(0,
         trace::rec::Obstacle{static_cast<int64_t>(k + 1), o.name, plant::obstacleKindName(o.kind),
                              o.mine, o.height_ft, o.x_ft, o.y_ft, o.radius_ft, std::move(points)},
         {});
  }
  for (const auto& r : robots_) {
    const plant::RobotSetup& setup = arenaConfig_->robots[static_cast<size_t>(r->index)];
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
    const plant::SecondaryWeapon& w = setup.hardware.secondary;
    if (w.kind != plant::SecondaryKind::None)
      emit(
          0,
          trace::rec::Secondary{r->index, plant::secondaryKindName(w.kind),
                                setup.hardware.disc_shooter_bit, w.magazine, w.launch_speed_fps,
                                w.launch_height_ft, w.drag_time_s, w.stop_speed_fps, w.diameter_ft},
          {});
    for (const plant::Deployable& d : setup.hardware.deployables)
      emit(0, trace::rec::Deployables{r->index, plant::deployKindName(d.kind), d.bit, d.count}, {});
  }
}

}  // namespace simbot::scheduler::detail
