// The run options' table (runs/run_options.def) as a command's CLI11
// options: every command that runs something takes its options from here,
// so an option, its help and its check are written once.
#include <CLI/CLI.hpp>
#include <optional>
#include <string>
#include <vector>

#include "cli/commands.h"
#include "runs/play.h"
#include "timebase/written.h"

namespace simbot::cli {

namespace {

CLI::Validator checked(const runs::OptionCheck& check) {
  return CLI::Validator(
      [check](std::string& text) -> std::string { return runs::checkOption(check, text); }, "");
}

// A time: the run's length, in timebase/written.h's grammar (its message
// names the ticks either side of a time that is not a whole tick).
CLI::Validator runLengthValidator() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        try {
          timebase::parseRunLength(text);
          return "";
        } catch (const timebase::TimeError& e) {
          return e.what();
        }
      },
      "TIME");
}

void addRunOption(CLI::App* cmd, const char* flag, bool& value, const runs::OptionCheck&,
                  const char* help) {
  cmd->add_flag(flag, value, help);
}
void addRunOption(CLI::App* cmd, const char* flag, std::optional<uint64_t>& value,
                  const runs::OptionCheck&, const char* help) {
  cmd->add_option(flag, value, help)->check(seedValidator());
}
void addRunOption(CLI::App* cmd, const char* flag, std::optional<timebase::Tick>& value,
                  const runs::OptionCheck&, const char* help) {
  cmd->add_option_function<std::string>(
         flag, [&value](const std::string& text) { value = timebase::parseRunLength(text); }, help)
      ->check(runLengthValidator());
}
template <class T>
void addRunOption(CLI::App* cmd, const char* flag, T& value, const runs::OptionCheck& check,
                  const char* help) {
  CLI::Option* option = cmd->add_option(flag, value, help);
  if (check.lo <= check.hi || !check.words.empty()) option->check(checked(check));
}

}  // namespace

void addRunOptions(CLI::App* cmd, runs::RunOptions& o, unsigned command) {
  using enum runs::RunOptionUse;
  using runs::anything, runs::range, runs::oneOf;
#define RUN_OPTION(member, Type, initial, flag, keyword, where, check, help) \
  if ((where)&command) addRunOption(cmd, flag, o.member, check, help);
#include "runs/run_options.def"
#undef RUN_OPTION
}

}  // namespace simbot::cli
