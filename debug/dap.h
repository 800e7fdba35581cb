// simbot dap: the debugger (session.h) over the Debug Adapter Protocol, the
// one VS Code speaks to its debug adapters: JSON messages, each after a
// "Content-Length: N" header and a blank line, requests in on one stream,
// responses and events out on the other.
//
// A DAP session: `initialize` (answered with the capabilities), `launch`
// (the run's programs and options, built by the front end's Launcher), the
// `initialized` event, then the configuration requests (setBreakpoints,
// setFunctionBreakpoints, setDataBreakpoints) up to `configurationDone`,
// after which the match runs (or holds at its first instruction with
// stopOnEntry). At each stop the server sends a `stopped` event and answers
// requests (threads, stackTrace, scopes, variables, evaluate, breakpoints)
// until one resumes the robot (continue, next, stepIn, stepOut, stepBack,
// reverseContinue) or ends the session (disconnect, terminate).
//
// Requests are read on a thread of their own (dap_wire.h), and checked
// there: one that cannot be used is answered with an error and the session
// goes on. While the match runs they wait for the next stop, but
// disconnect and terminate end the session at once and pause stops the
// match where it got to (the session's interrupt flag).
//
// Threads are the robots: thread 1 is A, thread 2 is B; the `stopped`
// event names the held robot's. A stack frame's id is its index in its
// robot's backtrace (0 innermost) plus kDapFrameStride times the robot's
// index. Variables references are handed out afresh at each stop.
#pragma once
#include <cstdint>
#include <functional>
#include <iosfwd>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "debug/session.h"
#include "scheduler/match.h"

namespace simbot::debug {

inline constexpr int kDapFrameStride = 1 << 16;

// The `launch` request's arguments, as `simbot debug` takes them.
struct LaunchRequest {
  std::string program;         // robot A's file
  std::string opponent;        // B's; empty: a solo run
  std::optional<Tick> length;  // `seconds`, in timebase/written.h's grammar
  std::optional<uint64_t> seed;
  std::optional<std::string> profile;
  std::string scenario;
  std::string robot = "A";  // the robot held first
  bool stopOnEntry = false;
  std::string cwd;  // relative paths are taken from here (the launcher changes to it)
};

// The run a launch request names: its configuration and each robot's file
// (for source paths in stack frames and breakpoints).
struct Launched {
  scheduler::MatchConfig config;
  std::vector<std::string> programs;
};

// Builds the run (the front end's runs::buildConfig); any exception is the
// launch request's error message.
using Launcher = std::function<Launched(const LaunchRequest&)>;

class DapServer final : public Controller {
 public:
  DapServer(std::istream& in, std::ostream& out, Launcher launcher);
  ~DapServer() override;
  DapServer(const DapServer&) = delete;
  DapServer& operator=(const DapServer&) = delete;

  // Serves the client until it disconnects or its stream ends; the exit
  // status (0).
  int serve();

  Resume stopped(Session& session, const Stop& why) override;
  void resuming() override;
  bool quitOnInterrupt() override;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace simbot::debug
