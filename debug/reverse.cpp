// debug/reverse.cpp -- going backwards: replaying the snapshots' windows
// to find where a reverse command stops (session.h explains the model).
#include <algorithm>

#include "debug/session.h"

namespace simbot::debug {

// Every boundary of the held robot from the latest snapshot whose held clock
// is at or before `from` up to (not including) `end`, as a forward run
// meets them: each one when stepping, else at breakpoints and events only.
std::vector<Session::Boundary> Session::scanWindow(Tick from, Tick end, bool stepping, bool hits,
                                                   std::map<Tick, Stop>* stops) {
  restoreBefore(from, true);
  scan_ = Scan{end, stepping, hits, {}, {}, run_->view().vm(held_).now()};
  for (Watchpoint& w : watchpoints_) w.valid = false;
  try {
    forward();
  } catch (const ScanDone&) {
  } catch (...) {
    scan_.reset();
    throw;
  }
  std::vector<Boundary> found = std::move(scan_->boundaries);
  if (stops) stops->merge(scan_->stops);
  scan_.reset();
  return found;
}

std::optional<Session::Found> Session::searchBack(const Rewind& rw) {
  const Resume::Kind kind = rw.how.kind;
  const Tick c = rw.from;
  const int depthNow = rw.calls + rw.ints;
  std::map<Tick, Stop> stops;  // reverse-continue: what each hit reports
  const auto hitAt = [&](const Boundary& b) { return Found{b.tick, b.settled, stops.at(b.tick)}; };
  if (kind == Resume::Kind::ReverseContinue && watchpoints_.empty()) {
    // Breakpoints cost nothing to find: one pass from the start.
    const std::vector<Boundary> all = scanWindow(0, c, false, true, &stops);
    for (auto it = all.rbegin(); it != all.rend(); ++it)
      if (it->hit && it->tick < c) return hitAt(*it);
    return std::nullopt;
  }
  const bool stepping = true;
  const bool hits = kind == Resume::Kind::ReverseContinue;
  std::vector<Boundary> history;  // every boundary before c found so far, in order
  Tick windowEnd = c;
  const auto at = [](const Boundary& b) {
    return std::optional<Found>(Found{b.tick, b.settled, std::nullopt});
  };
  for (;;) {
    // The window before windowEnd: from the latest snapshot before it.
    Tick start = -1;
    for (auto it = snapshots_.rbegin(); it != snapshots_.rend(); ++it)
      if (it->second.robotClock(held_) < windowEnd) {
        start = it->second.robotClock(held_);
        break;
      }
    if (start < 0) return history.empty() ? std::nullopt : at(history.front());
    std::vector<Boundary> window = scanWindow(start, windowEnd, stepping, hits, &stops);
    history.insert(history.begin(), window.begin(), window.end());
    windowEnd = start;
    const bool complete = snapshots_.begin()->second.robotClock(held_) >= start;
    if (history.empty()) {
      if (complete) return std::nullopt;
      continue;
    }
    switch (kind) {
      case Resume::Kind::ReverseStepInstruction:
        return at(history.back());
      case Resume::Kind::ReverseContinue:
        for (auto it = history.rbegin(); it != history.rend(); ++it)
          if (it->hit) return hitAt(*it);
        break;
      case Resume::Kind::ReverseFinish:
        for (auto it = history.rbegin(); it != history.rend(); ++it)
          if (it->calls + it->ints < depthNow) return at(*it);
        break;
      default:
        if (const auto k = lineBefore(history, rw, complete)) return at(history[*k]);
        break;
    }
    if (complete) {
      const bool toStart = (kind == Resume::Kind::ReverseStep || kind == Resume::Kind::ReverseNext);
      return toStart ? at(history.front()) : std::nullopt;
    }
  }
}

// reverse-step, reverse-next (gdb's rules): from the middle of a line, back
// to where the robot entered it; from its start, to the start of the line
// before it (reverse-next passes over deeper calls and handlers). Out of a
// handler's first line, back to the instruction it interrupted. Handlers
// that interrupted the line on the way do not end it. Nothing while
// `history` (every boundary before the command's, oldest first) may not
// yet reach back far enough (not `complete`).
std::optional<size_t> Session::lineBefore(const std::vector<Boundary>& history, const Rewind& rw,
                                          bool complete) const {
  const bool over = rw.how.kind == Resume::Kind::ReverseNext;
  const int depthNow = rw.calls + rw.ints;
  std::vector<size_t> seen;
  for (size_t k = 0; k < history.size(); ++k)
    if (!over || history[k].calls + history[k].ints <= depthNow) seen.push_back(k);
  const auto same = [&](size_t a, int line, int calls, int ints) {
    const Boundary& b = history[a];
    return b.line == line && b.calls == calls && b.ints == ints;
  };
  // Back from seen[i] over the rest of the run of `line` it is in (and
  // handlers nested in that run); the run's first boundary, if known.
  const auto runStart = [&](ptrdiff_t i, int line, int calls, int ints) -> std::optional<size_t> {
    ptrdiff_t first = i;
    bool ended = false;  // something before the run is in the history
    for (ptrdiff_t k = i - 1; k >= 0 && !ended; --k) {
      const Boundary& b = history[seen[static_cast<size_t>(k)]];
      if (b.ints > ints && b.calls >= calls) continue;  // a handler inside the line
      if (same(seen[static_cast<size_t>(k)], line, calls, ints))
        first = k;
      else
        ended = true;
    }
    // Else the run may go on before the history, unless that is the start.
    if (!ended && !complete) return std::nullopt;
    return seen[static_cast<size_t>(first)];
  };
  const auto i = static_cast<ptrdiff_t>(seen.size()) - 1;
  if (i < 0) return std::nullopt;
  // The middle of a line: its start first.
  if (same(seen[static_cast<size_t>(i)], rw.line, rw.calls, rw.ints))
    return runStart(i, rw.line, rw.calls, rw.ints);
  const Boundary& prev = history[seen[static_cast<size_t>(i)]];
  if (prev.ints != rw.ints) return seen[static_cast<size_t>(i)];
  return runStart(i, prev.line, prev.calls, prev.ints);
}

}  // namespace simbot::debug
