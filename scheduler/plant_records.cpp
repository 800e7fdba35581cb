// The trace records of the plant's events (plant.h EventKind): what each
// one says, for the round loop (match.cpp) to emit at its tick.
#include <fmt/format.h>

#include <optional>
#include <stdexcept>
#include <string>

#include "scheduler/match_impl.h"

namespace simbot::scheduler::detail {

// A plant event's record at t, with `watch` (robot `watchRobot`'s values at
// t, taken when it was there) for that robot's records.
void Match::emitPlant(Tick t, const plant::Event& e, const trace::Watch* watch, int watchRobot) {
  if (!trace_.on()) return;
  if (watch && e.robot == watchRobot)
    emit(t, plantRecord(e), *watch);
  else
    emit(t, plantRecord(e));
}

// The trace record of a plant event.
trace::Record Match::plantRecord(const plant::Event& e) const {
  namespace rec = trace::rec;
  const int r = e.robot;
  const auto side = [](plant::Bumper b) { return b == plant::Bumper::Front ? "front" : "back"; };
  const auto obstacle = [&](int index) { return plant::obstacleLabel(arenaConfig_->field, index); };
  const auto with = [&](plant::ContactWith w, int index) -> std::string {
    return w == plant::ContactWith::Robot      ? "robot"
           : w == plant::ContactWith::Divider  ? "divider"
           : w == plant::ContactWith::Obstacle ? obstacle(index)
           : w == plant::ContactWith::Block    ? fmt::format("block {}", index + 1)
                                               : "wall";
  };
  const auto missed = [&](plant::MissReason m, int index) -> std::string {
    return m == plant::MissReason::Floor      ? "floor"
           : m == plant::MissReason::Divider  ? "divider"
           : m == plant::MissReason::Stopped  ? "stopped"
           : m == plant::MissReason::Obstacle ? obstacle(index)
           : m == plant::MissReason::Block    ? fmt::format("block {}", index + 1)
                                              : "wall";
  };
  switch (e.kind) {
    case plant::EventKind::EdgeEnter:
      return rec::EdgeEnter{r, e.detector == plant::Detector::Fore ? "fore" : "aft"};
    case plant::EventKind::EdgeLeave:
      return rec::EdgeLeave{r, e.detector == plant::Detector::Fore ? "fore" : "aft"};
    case plant::EventKind::Contact:
      return rec::Contact{r, side(e.bumper), with(e.with, e.obstacle)};
    case plant::EventKind::ContactEnd:
      return rec::ContactEnd{r, with(e.with, e.obstacle)};
    case plant::EventKind::ReflexStart:
      return rec::ReflexStart{r, side(e.bumper)};
    case plant::EventKind::ReflexEnd:
      return rec::ReflexEnd{r, side(e.bumper)};
    case plant::EventKind::BallLaunch:
      return rec::BallLaunch{r, e.gun, e.ball, e.x, e.y, e.z, e.vx, e.vy, e.vz, e.heading_deg};
    case plant::EventKind::BallSkip:
      return rec::BallSkip{r, e.gun, e.ball, e.x, e.y};
    case plant::EventKind::BallHit:
      return rec::BallHit{r, e.gun, e.other, e.ball, "robot", e.x, e.y, e.z};
    case plant::EventKind::BallMiss:
      return rec::BallMiss{
          r,      e.gun,
          e.ball, missed(e.miss, e.obstacle),
          e.x,    e.y,
          e.z,    e.closest_ft >= 0 ? std::optional<double>(e.closest_ft) : std::nullopt};
    case plant::EventKind::RefereePutBack:
      return rec::RefereePutBack{r};
    case plant::EventKind::RefereeTurn:
      return rec::RefereeTurn{r};
    case plant::EventKind::SolenoidStroke:
      return rec::SolenoidStroke{r, e.gun};
    case plant::EventKind::GunEmpty:
      return rec::GunEmpty{r, e.gun};
    case plant::EventKind::GunMisfire:
      return rec::GunMisfire{r, e.gun};
    case plant::EventKind::GunJammed:
      return rec::GunJammed{r, e.gun};
    case plant::EventKind::DiscShooter:
      return rec::DiscShooter{r, -1};
    case plant::EventKind::DiscFire:
      return rec::DiscFire{
          r,
          e.ball,
          e.x,
          e.y,
          e.z,
          e.vx,
          e.vy,
          arenaConfig_->robots[static_cast<size_t>(r)].hardware.secondary.drag_time_s,
          e.heading_deg};
    case plant::EventKind::DiscEmpty:
      return rec::DiscEmpty{r};
    case plant::EventKind::Deploy:
    case plant::EventKind::DeployEmpty:
    case plant::EventKind::DeployBlocked: {
      const plant::Deployable& d = arenaConfig_->robots[static_cast<size_t>(r)]
                                       .hardware.deployables[static_cast<size_t>(e.gun)];
      if (e.kind == plant::EventKind::DeployEmpty)
        return rec::DeployEmpty{r, plant::deployKindName(d.kind), d.bit};
      if (e.kind == plant::EventKind::DeployBlocked)
        return rec::DeployBlocked{r, plant::deployKindName(d.kind), d.bit, e.x, e.y};
      return rec::Deploy{r, plant::deployKindName(d.kind), e.ball, d.bit, e.x, e.y, e.heading_deg};
    }
    case plant::EventKind::DiscHit:
      return rec::DiscHit{r, e.other, e.ball, e.x, e.y, e.z};
    case plant::EventKind::PushStart:
      return rec::PushStart{r, e.ball + 1, e.x, e.y, e.vx, e.vy};
    case plant::EventKind::PushEnd:
      return rec::PushEnd{
          r,
          e.ball + 1,
          e.x,
          e.y,
          e.z,
          e.with == plant::ContactWith::None ? std::string("drive") : with(e.with, e.obstacle)};
    case plant::EventKind::DiscMiss:
      return rec::DiscMiss{r,
                           e.ball,
                           missed(e.miss, e.obstacle),
                           e.x,
                           e.y,
                           e.z,
                           e.closest_ft >= 0 ? std::optional<double>(e.closest_ft) : std::nullopt};
  }
  throw std::logic_error("plant event without a trace record");
}

}  // namespace simbot::scheduler::detail
