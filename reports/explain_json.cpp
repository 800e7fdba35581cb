// The explain report as JSON (see explain.h): `simbot explain --json`.
#include <string>
#include <vector>

#include "reports/explain.h"
#include "sinks/json_text.h"

namespace simbot::reports::explain {

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
    shots.push_back({{"robot", kRobotNames[x.robot & 1]},
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
        {{"robot", kRobotNames[x.robot & 1]},
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
    json o = {{"robot", kRobotNames[x.robot & 1]},
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
    json o = {{"robot", kRobotNames[x.robot & 1]},
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
    totals.push_back({{"robot", kRobotNames[x.robot & 1]},
                      {"handler", sinks::jsonString(x.handler, false)},
                      {"runs", x.runs},
                      {"total_s", sec(x.total)},
                      {"longest_s", sec(x.longest)}});
  j["handlers"] = totals;
  json runs = json::array();
  for (const HandlerRun& x : r.handler_runs) {
    json frames = json::array();
    for (const auto& fr : x.frames) frames.push_back(sinks::jsonString(fr, true));
    runs.push_back({{"robot", kRobotNames[x.robot & 1]},
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
    contacts.push_back({{"robot", kRobotNames[x.robot & 1]},
                        {"time_s", sec(x.t)},
                        {"end_s", x.end_t ? json(sec(*x.end_t)) : json(nullptr)},
                        {"bumper", x.bumper},
                        {"with", x.with},
                        {"reflex", x.reflex}});
  j["contacts"] = contacts;
  auto events = [&](const std::vector<Event>& v) {
    json a = json::array();
    for (const Event& x : v)
      a.push_back({{"robot", x.robot < 0 ? json(nullptr) : json(kRobotNames[x.robot & 1])},
                   {"time_s", sec(x.t)},
                   {"what", sinks::jsonString(x.what, false)},
                   {"line", x.line},
                   {"depth", x.depth},
                   {"calls", sinks::jsonString(x.calls, false)}});
    return a;
  };
  j["referee"] = events(r.referee);
  j["faults"] = events(r.faults);
  // Only for a run with the wider competition's elements: the JSON of any
  // other run stays as it was.
  if (!r.course.empty()) {
    j["course"] = events(r.course);
    j["scatter_shots"] = {r.scatter_shots[0], r.scatter_shots[1]};
  }
  return j;
}

}  // namespace simbot::reports::explain
