// runs/options.cpp -- the checks of the run options' values
// (runs/run_options.def), shared by the command line and the Python module.
#include <fmt/format.h>

#include <charconv>
#include <string>
#include <string_view>

#include "runs/play.h"
#include "sinks/user_error.h"
#include "timebase/written.h"

namespace simbot::runs {

std::string checkOption(const OptionCheck& check, const std::string& text) {
  if (check.lo <= check.hi) {
    std::int64_t value = 0;
    const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
    if (error != std::errc() || end != text.data() + text.size() || value < check.lo ||
        value > check.hi)
      return fmt::format("'{}' is not an integer from {} to {}", text, check.lo, check.hi);
  }
  if (!check.words.empty()) {
    for (std::string_view rest = check.words;;) {
      const auto bar = rest.find('|');
      if (rest.substr(0, bar) == text) return "";
      if (bar == std::string_view::npos) break;
      rest.remove_prefix(bar + 1);
    }
    std::string words(check.words);
    for (char& c : words)
      if (c == '|') c = ' ';
    return fmt::format("'{}' is not one of: {}", text, words);
  }
  return "";
}

timebase::Tick parseLengthOption(const std::string& text) {
  try {
    return timebase::parseRunLength(text);
  } catch (const timebase::TimeError& e) {
    throw sinks::UserError(fmt::format("simbot: --seconds: {}\n", e.what()));
  }
}

}  // namespace simbot::runs
