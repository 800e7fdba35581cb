// simbot dap: the debugger over the Debug Adapter Protocol (debug/dap.h) on
// stdin and stdout, for VS Code (docs/vscode.md). The launch request's
// arguments make the run as `simbot debug`'s options do.
#include <fmt/format.h>
#include <unistd.h>

#include <cerrno>
#include <filesystem>
#include <iostream>
#include <streambuf>

#include "cli/commands.h"
#include "debug/dap.h"
#include "runs/play.h"
#include "sinks/user_error.h"

namespace simbot::cli {

namespace {

// An output stream onto a file descriptor: the protocol's own copy of
// stdout, so that nothing else the process prints can reach the client.
class FdBuffer final : public std::streambuf {
 public:
  explicit FdBuffer(int fd) : fd_(fd) { setp(buffer_, buffer_ + sizeof buffer_); }
  ~FdBuffer() override { sync(); }
  FdBuffer(const FdBuffer&) = delete;
  FdBuffer& operator=(const FdBuffer&) = delete;

 protected:
  int_type overflow(int_type c) override {
    if (sync() != 0) return traits_type::eof();
    if (!traits_type::eq_int_type(c, traits_type::eof())) {
      *pptr() = traits_type::to_char_type(c);
      pbump(1);
    }
    return traits_type::not_eof(c);
  }
  int sync() override {
    const char* p = pbase();
    while (p < pptr()) {
      const ssize_t n = ::write(fd_, p, static_cast<size_t>(pptr() - p));
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) return -1;
      p += n;
    }
    setp(buffer_, buffer_ + sizeof buffer_);
    return 0;
  }

 private:
  int fd_;
  char buffer_[8192];
};

debug::Launched launch(const debug::LaunchRequest& r) {
  if (!r.cwd.empty()) {
    std::error_code ec;
    std::filesystem::current_path(r.cwd, ec);
    if (ec) throw debug::Error(fmt::format("cwd '{}': {}", r.cwd, ec.message()));
  }
  runs::RunOptions o;
  o.length = r.length;
  o.seed = r.seed;
  o.profile = r.profile;
  o.scenario = r.scenario;
  std::vector<std::string> programs{r.program};
  if (!r.opponent.empty()) programs.push_back(r.opponent);
  debug::Launched run;
  run.config = runs::buildConfig(
      programs, o, programs.size() == 1 ? runs::ScenarioUse::Solo : runs::ScenarioUse::Match);
  run.config.stopWhenAllExited = programs.size() == 1;
  for (const scheduler::RobotSpec& robot : run.config.robots) run.programs.push_back(robot.program);
  return run;
}

}  // namespace

int dapCommand() {
  // The protocol keeps stdout; whatever else writes to it (a stray
  // message) goes to stderr instead.
  std::cout.flush();
  const int protocol = ::dup(STDOUT_FILENO);
  if (protocol < 0 || ::dup2(STDERR_FILENO, STDOUT_FILENO) < 0)
    throw sinks::UserError("simbot: dap: cannot set up stdout for the protocol\n");
  FdBuffer buffer(protocol);
  std::ostream out(&buffer);
  debug::DapServer server(std::cin, out, launch);
  const int status = server.serve();
  out.flush();
  ::close(protocol);
  return status;
}

}  // namespace simbot::cli
