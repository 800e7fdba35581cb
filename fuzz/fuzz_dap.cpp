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

#include "compiler/compiler.h"
#include "config/config.h"
#include "debug/dap.h"

using namespace simbot;

namespace {

constexpr const char* kProgram = R"(struct point { int x; int y; };
struct point p;
int data[4];
long total;
char name[6] = "robot";
int *where;

int twice(int n)
{
    int k;
    k = n + n;
    return k;
}

main()
{
    int i;
    where = &data[1];
    for (i = 0; ; i++) {
        data[i & 3] = twice(i);
        p.x = i;
        p.y = *where;
        total = total + i;
    }
}
)";

debug::Launched tinyRun() {
  const config::Profile profile = config::loadProfile(SIMBOT_PROFILES_DIR "/default.toml");
  compiler::Result compiled = compiler::compile(kProgram, "fuzz.dc");
  debug::Launched run;
  run.config.arena = config::makeArenaConfig(profile, 1);
  run.config.robots.push_back({"A", "fuzz.dc", std::move(*compiled.image)});
  run.config.endTick = scheduler::kTicksPerSecond / 200;
  run.config.stopWhenAllExited = true;
  run.programs.push_back("fuzz.dc");
  return run;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const debug::Launched run = tinyRun();
  std::istringstream in(std::string(reinterpret_cast<const char*>(data), size));
  std::ostringstream out;
  debug::DapServer server(in, out, [](const debug::LaunchRequest& r) {
    if (r.program == "missing.dc") throw debug::Error("missing.dc: no such file");
    return run;
  });
  return server.serve();
}
