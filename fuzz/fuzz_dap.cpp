// libFuzzer target: simbot dap's server on any bytes as its client's
// input: the framing, the JSON, each request's checks and its answer. A
// launch request (any program name; "missing.dc" fails as a missing file
// would) starts a session on a small solo program that runs 5 simulated ms,
// so breakpoints, steps both ways, frames, variables and evaluate run
// against a real match. Every input must end in the server returning 0:
// no crash, hang or undefined behaviour, and no exception out of it.
#include <cstddef>
#include <cstdint>
#include <sstream>
#include <string>

#include "debug/dap.h"
#include "fuzz/tiny_run.h"

using namespace simbot;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const debug::Launched run = fuzz::tinyRun();
  std::istringstream in(std::string(reinterpret_cast<const char*>(data), size));
  std::ostringstream out;
  debug::DapServer server(in, out, [](const debug::LaunchRequest& r) {
    if (r.program == "missing.dc") throw debug::Error("missing.dc: no such file");
    return run;
  });
  return server.serve();
}
