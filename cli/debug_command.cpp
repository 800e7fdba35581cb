// simbot debug A.dc [B.dc] [run options] [--batch FILE] [--robot B]: the
// debugger's command line (debug/console.h) over a session (debug/session.h).
#include <fmt/format.h>
#include <unistd.h>

#include <atomic>
#include <csignal>
#include <iostream>
#include <sstream>

#include "cli/commands.h"
#include "debug/console.h"
#include "debug/session.h"
#include "files/files.h"
#include "runs/play.h"
#include "sinks/user_error.h"

namespace simbot::cli {

int debugCommand(const std::vector<std::string>& programs, const runs::RunOptions& o) {
  const std::string& batch = o.batch;
  const std::string& robot = o.robot;
  std::vector<files::Named> inputs;
  scheduler::MatchConfig config = runs::buildConfig(
      programs, o, programs.size() == 1 ? runs::ScenarioUse::Solo : runs::ScenarioUse::Match,
      &inputs);
  config.stopWhenAllExited = programs.size() == 1;
  if (o.noFastForward) config.knobs.fastForward = false;
  std::vector<std::string> paths;
  int held = -1;
  for (size_t i = 0; i < config.robots.size(); ++i) {
    paths.push_back(config.robots[i].program);
    if (config.robots[i].name == robot) held = static_cast<int>(i);
  }
  if (held < 0)
    throw sinks::UserError(
        fmt::format("simbot: debug: --robot {}: this run has no robot {}\n", robot, robot));
  std::istringstream script;
  std::unique_ptr<debug::LineSource> lines;
  if (!batch.empty()) {
    try {
      script.str(files::readInput(batch, files::kMaxConfigBytes));
    } catch (const files::Error& e) {
      throw sinks::UserError(fmt::format("simbot: debug: --batch {}: {}\n", batch, e.what()));
    }
    lines = debug::streamLines(script, true);
  } else if (isatty(STDIN_FILENO)) {
    lines = debug::terminalLines();
  } else {
    lines = debug::streamLines(std::cin, false);
  }
  debug::Console console(*lines, std::cout);
  // At a terminal, Ctrl-C stops the command that is running (as in gdb)
  // instead of the program.
  static std::atomic<bool> interrupted{false};
  const bool terminal = batch.empty() && isatty(STDIN_FILENO);
  if (terminal) {
    struct sigaction action {};
    action.sa_handler = [](int) { interrupted.store(true); };
    sigemptyset(&action.sa_mask);
    ::sigaction(SIGINT, &action, nullptr);
  }
  try {
    debug::Session session(config, paths, held);
    session.run(console, terminal ? &interrupted : nullptr);
  } catch (const std::invalid_argument& e) {
    throw sinks::UserError(fmt::format("simbot: {}\n", e.what()));
  }
  std::cout.flush();
  // Commands read from a file or a pipe that failed make the run fail, as
  // a script's would; at a terminal the user saw each error and went on.
  return !terminal && console.errors() > 0 ? 1 : 0;
}

}  // namespace simbot::cli
