// config/inject.cpp -- the --inject specification (config.h
// parseInjection): ROBOT:SOURCE@WHEN into the scheduler's Injection. Scenario
// files' [A]/[B] inject lists are read by the same parser, so a spec means
// the same wherever it is written.
#include <cstdint>
#include <stdexcept>
#include <string>

#include "config/config.h"
#include "timebase/written.h"

namespace simbot::config {

namespace {

// WHEN as a time, in timebase/written.h's grammar ("12.5s" is exactly
// 115,200,000 ticks, "300us" is between two ticks and refused); a number
// alone is no time here.
scheduler::Tick parseWhen(const std::string& when, const std::string& whole) {
  try {
    return timebase::parseTime(when, timebase::BareNumber::Refused);
  } catch (const timebase::TimeError& e) {
    if (e.kind() == timebase::TimeError::Kind::NotATime)
      throw std::invalid_argument("'" + whole +
                                  "': WHEN must be a time (12.5s, 800ms, 300us, 115200000t) or "
                                  "a program point (line:N#K, pass:N#K)");
    throw std::invalid_argument("'" + whole + "': " + e.what());
  }
}

int parsePositive(const std::string& s, const std::string& whole, const char* what) {
  if (s.empty() || s.size() > 9 || s.find_first_not_of("0123456789") != std::string::npos ||
      std::stoi(s) <= 0)
    throw std::invalid_argument("'" + whole + "': " + what + " must be a positive integer");
  return std::stoi(s);
}

}  // namespace

scheduler::Injection parseInjection(const std::string& text, int robotCount) {
  scheduler::Injection in;
  in.text = text;
  const auto colon = text.find(':');
  const auto at = text.find('@');
  if (colon == std::string::npos || at == std::string::npos || at < colon)
    throw std::invalid_argument("'" + text + "': expected ROBOT:SOURCE@WHEN");
  const std::string robot = text.substr(0, colon);
  const std::string source = text.substr(colon + 1, at - colon - 1);
  const std::string when = text.substr(at + 1);
  if (robot == "A")
    in.robot = 0;
  else if (robot == "B" && robotCount > 1)
    in.robot = 1;
  else
    throw std::invalid_argument("'" + text + "': no robot '" + robot + "' in this run");
  if (source == "edge_fore")
    in.source = scheduler::InjectSource::EdgeFore;
  else if (source == "edge_aft")
    in.source = scheduler::InjectSource::EdgeAft;
  else if (source == "bumper_front")
    in.source = scheduler::InjectSource::BumperFront;
  else if (source == "bumper_back")
    in.source = scheduler::InjectSource::BumperBack;
  else if (source == "reset")
    in.source = scheduler::InjectSource::Reset;
  else
    throw std::invalid_argument("'" + text +
                                "': SOURCE must be edge_fore, edge_aft, "
                                "bumper_front, bumper_back or reset");
  const bool pass = when.rfind("pass:", 0) == 0;
  if (when.rfind("line:", 0) == 0 || pass) {
    const auto hash = when.find('#');
    if (hash == std::string::npos)
      throw std::invalid_argument("'" + text + "': a program point is line:N#K or pass:N#K");
    // A reset stops the whole board: at a program point the VM has run on
    // past it by the time the scheduler could act, so only times are taken.
    if (in.source == scheduler::InjectSource::Reset)
      throw std::invalid_argument("'" + text +
                                  "': a reset is injected at a time (12.5s, 115200000t), not at "
                                  "a program point");
    in.pass = pass;
    in.line = parsePositive(when.substr(5, hash - 5), text, "the line N");
    in.count = parsePositive(when.substr(hash + 1), text, "the execution count K");
  } else {
    in.tick = parseWhen(when, text);
  }
  return in;
}

}  // namespace simbot::config
