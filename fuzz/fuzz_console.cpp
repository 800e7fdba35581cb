// libFuzzer target: simbot debug's command line. Each input is a script as
// --batch reads it (one command a line, at most kMaxLines), run by the
// console against a session on a small solo program for 5 simulated ms
// (fuzz/tiny_run.h): breakpoints, watchpoints, stepping both ways, goto,
// print and its formats, frames, info, list, the robot command. A refused
// command is one line and the session goes on; nothing may crash, hang,
// trip the sanitizers or throw out of the session.
#include <cstddef>
#include <cstdint>
#include <sstream>
#include <string>

#include "debug/console.h"
#include "debug/session.h"
#include "fuzz/tiny_run.h"

using namespace simbot;

namespace {

constexpr size_t kMaxLines = 64;

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const debug::Launched run = fuzz::tinyRun();
  std::istringstream input(std::string(reinterpret_cast<const char*>(data), size));
  std::string script;
  size_t n = 0;
  for (std::string line; n < kMaxLines && std::getline(input, line); ++n) script += line + "\n";
  std::istringstream lines(script);
  std::ostringstream out;
  const auto source = debug::streamLines(lines, true);
  debug::Console console(*source, out);
  debug::Session session(run.config, run.programs);
  session.run(console);
  return 0;
}
