// The explain report in words (see explain.h): the text `simbot explain`
// prints and the replay page's Explain panel shows, and the Markdown of
// --markdown; the same sections in the same order.
#include <fmt/format.h>

#include <algorithm>
#include <optional>
#include <string>
#include <vector>

#include "plant/plant.h"
#include "reports/explain.h"
#include "sinks/json_text.h"

namespace simbot::reports::explain {

namespace {

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

struct Fmt {
  const Report& r;
  std::string s(Tick t) const {
    return fmt::format("{:.3f}", static_cast<double>(t) / r.ticks_per_second);
  }
  std::string dur(Tick t) const {
    return fmt::format("{:.3f} s", static_cast<double>(t) / r.ticks_per_second);
  }
  std::string name(int robot) const { return robot >= 0 && robot < 2 ? kRobotNames[robot] : "run"; }
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
  if (r.course.empty()) return out;
  add("");
  add(fmt::format("Course: obstacles, mines, scatter shots, discs, deployables, resets ({})",
                  r.course.size()));
  for (std::size_t i = 0; i < r.robots.size(); ++i)
    if (r.scatter_shots[i])
      add(fmt::format("  {} scatter shots (Detect to Engage): {}", r.robots[i].name,
                      r.scatter_shots[i]));
  for (const Event& x : r.course)
    add(fmt::format("  {} {} s {}", f.name(x.robot), f.s(x.t), x.what), x.t);
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
  if (r.course.empty()) return o;
  o += fmt::format(
      "\n## Course: obstacles, mines, scatter shots, discs, deployables, resets ({})\n\n",
      r.course.size());
  for (std::size_t i = 0; i < r.robots.size(); ++i)
    if (r.scatter_shots[i])
      o += fmt::format("- **{}** scatter shots (Detect to Engage): {}\n", r.robots[i].name,
                       r.scatter_shots[i]);
  for (const Event& x : r.course)
    o += fmt::format("- **{}** {} s {}\n", f.name(x.robot), f.s(x.t), cell(x.what));
  return o;
}

}  // namespace simbot::reports::explain
