// fuzz/tiny_run.h -- the small solo run the debugger's fuzz targets
// (fuzz_dap, fuzz_console) hold a session on: a program with a struct, an
// array, a pointer, a function with an auto and an endless loop, for 5
// simulated ms, so breakpoints, steps both ways, frames and variables run
// against a real match and each input stays cheap.
#pragma once
#include <utility>

#include "compiler/compiler.h"
#include "config/config.h"
#include "debug/dap.h"

namespace simbot::fuzz {

inline constexpr const char* kProgram = R"(struct point { int x; int y; };
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

inline debug::Launched tinyRun() {
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

}  // namespace simbot::fuzz
