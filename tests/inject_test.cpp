// Interrupt injection through the match engine: at an exact tick and at a
// program point (line:N#K), into a program sitting in a delay loop.
#include <gtest/gtest.h>

#include <algorithm>
#include <nlohmann/json.hpp>
#include <optional>

#include "config/config.h"
#include "plant/plant.h"
#include "scheduler/match.h"
#include "support/programs.h"
#include "support/test_host.h"
#include "support/traced.h"

using namespace simbot;

namespace {

// Arms port A as ICEMAN does; the handler records where the loop was.
const std::string kDelay = R"(#INT_VEC PIOA_VEC edge
int z, seen, hits;
interrupt reti edge()
{
    seen = z;
    hits++;
}
main()
{
)" + std::string(testkit::kArmPortA) +
                           R"(    for (z = 0; z < 20000; z++)
        ;
    printf("%d %d %d\n", z, seen, hits);
}
)";
constexpr int kLoopBodyLine = 17;  // the lone ";"

struct SoloRun {
  scheduler::MatchResult result;
  std::vector<nlohmann::json> trace;
  const nlohmann::json* find(const std::string& type) const {
    for (const auto& j : trace)
      if (j.at("type") == type) return &j;
    return nullptr;
  }
};

// The delay program alone, run until main returns, traced.
scheduler::MatchConfig soloConfig(const std::vector<std::string>& injections) {
  scheduler::MatchConfig c;
  c.arena =
      config::makeArenaConfig(config::loadProfile(SIMBOT_SOURCE_DIR "/profiles/default.toml"), 1);
  c.robots.push_back({"A", "delay.dc", testkit::compileOrDie(kDelay, "delay.dc")});
  c.endTick = 10 * scheduler::kTicksPerSecond;
  c.stopWhenAllExited = true;
  for (const auto& text : injections) c.injections.push_back(config::parseInjection(text, 1));
  return c;
}

SoloRun solo(const std::vector<std::string>& injections) {
  const testkit::TracedRun traced = testkit::runTraced(soloConfig(injections));
  SoloRun run{traced, {}};
  for (const auto& line : traced.trace) run.trace.push_back(nlohmann::json::parse(line));
  return run;
}

TEST(Inject, EdgeAtATickInterruptsTheDelayLoopExactly) {
  const SoloRun plain = solo({});
  ASSERT_TRUE(plain.result.robots[0].exited);
  ASSERT_EQ(plain.result.robots[0].console, std::vector<std::string>{"20000 0 0"});
  const vm::Tick request = 1'000'003;  // well inside the loop
  const SoloRun injected = solo({"A:edge_fore@" + std::to_string(request) + "t"});
  const auto* accepted = injected.find("interrupt_accepted");
  const auto* returned = injected.find("interrupt_returned");
  ASSERT_NE(accepted, nullptr);
  ASSERT_NE(returned, nullptr);
  const vm::Tick acceptedAt = accepted->at("t").get<vm::Tick>();

  // The same program on a bare VM: the first boundary at or after the
  // request, and z there.
  const auto img = testkit::compileOrDie(kDelay, "delay.dc");
  testkit::TestHost host;
  vm::Vm v(img, host, vm::makeCostTable(vm::calibratedKnobs()));
  while (v.now() < request) v.run(request);
  EXPECT_EQ(acceptedAt, v.now());
  const uint16_t zAtBoundary = v.read16(static_cast<uint16_t>(testkit::symbol(img, "z").address));

  // The loop resumed where it was and the run grew by the handler's time
  // (and by the debug-port time of the longer line printf writes at the end).
  const vm::Tick handlerTime = returned->at("t").get<vm::Tick>() - acceptedAt;
  const std::string line = "20000 " + std::to_string(zAtBoundary) + " 1";
  EXPECT_EQ(injected.result.robots[0].console, std::vector<std::string>{line});
  // Per character: the debug port's 1,600 T-states and printf's own 52 (see
  // DelayLoop.PrintfChargesEachCharacter in timing_test.cpp).
  const vm::Tick longerPrintf =
      static_cast<vm::Tick>(line.size() - std::string("20000 0 0").size()) *
      (vm::calibratedKnobs().printfCharTstates + 52);
  EXPECT_EQ(injected.result.robots[0].exitTick,
            plain.result.robots[0].exitTick + handlerTime + longerPrintf);
  EXPECT_EQ(injected.result.robots[0].interrupts.at("pio_a"), 1u);
}

TEST(Inject, ProgramPointLandsOnTheKthPass) {
  const SoloRun injected = solo({"A:edge_aft@line:" + std::to_string(kLoopBodyLine) + "#1234"});
  // The 1234th execution of the loop body's first instruction is the pass
  // with z == 1233; the handler is accepted before it runs.
  EXPECT_EQ(injected.result.robots[0].console, std::vector<std::string>{"20000 1233 1"});
  const auto* inj = injected.find("injection");
  ASSERT_NE(inj, nullptr);
  EXPECT_EQ(inj->at("line"), kLoopBodyLine);
  const auto* accepted = injected.find("interrupt_accepted");
  ASSERT_NE(accepted, nullptr);
  EXPECT_EQ(accepted->at("t"), inj->at("t"));
  EXPECT_EQ(accepted->at("line"), kLoopBodyLine);
}

TEST(Inject, InjectedEdgeIsAPulse) {
  const SoloRun injected = solo({"A:edge_fore@100ms", "A:edge_fore@120ms", "A:edge_fore@200ms"});
  // 120 ms falls inside the 50-ms pulse of the first: no new falling edge.
  EXPECT_EQ(injected.result.robots[0].interrupts.at("pio_a"), 2u);
}

TEST(Inject, BumpTriggersTheReflexAtItsTick) {
  scheduler::MatchConfig c;
  const auto profile = config::loadProfile(SIMBOT_SOURCE_DIR "/profiles/thesis-1997.toml");
  c.arena = config::makeArenaConfig(profile, 1);
  c.arena.robots[0].start = {0, 0, 0};  // field centre, facing north
  c.robots.push_back({"A", "idle.dc", testkit::compileOrDie("main()\n{\n    while (1);\n}\n")});
  c.endTick = 5 * scheduler::kTicksPerSecond;
  c.injections.push_back(config::parseInjection("A:bumper_front@1s", 1));
  const auto r = testkit::runTraced(c);
  vm::Tick start = -1, end = -1;
  for (const auto& line : r.trace) {
    const auto j = nlohmann::json::parse(line);
    if (j.at("type") == "reflex_start") start = j.at("t").get<vm::Tick>();
    if (j.at("type") == "reflex_end") end = j.at("t").get<vm::Tick>();
  }
  EXPECT_EQ(start, scheduler::kTicksPerSecond);
  EXPECT_GT(end, start);
  // Full reverse for the profile's reflex distance, straight back (south).
  EXPECT_NEAR(r.robots[0].finalPose.x_ft, 0.0, 1e-9);
  EXPECT_NEAR(r.robots[0].finalPose.y_ft, -profile.robot.reflex_distance_ft, 1e-6);
}

TEST(Inject, WatchedVariableAppearsInTraceRecords) {
  scheduler::MatchConfig c = soloConfig({"A:edge_fore@line:17#500"});
  c.watches = {"z", "hits"};
  const auto r = testkit::runTraced(c);
  bool sawAcceptance = false;
  for (const auto& line : r.trace) {
    const auto j = nlohmann::json::parse(line);
    if (j.at("type") != "interrupt_accepted") continue;
    sawAcceptance = true;
    EXPECT_EQ(j.at("watch").at("z"), 499);  // the loop variable when it was interrupted
    EXPECT_EQ(j.at("watch").at("hits"), 0);
  }
  EXPECT_TRUE(sawAcceptance);
  c.watches = {"nosuch"};
  EXPECT_THROW(testkit::runTraced(c), std::invalid_argument);
}

// Each scalar kind is read as its C type (Dynamic C: char unsigned, int 16
// bits, long 32, float IEEE single, pointers 16): values by hand, and the
// pointer's is the address the image gives the struct it points to. An
// array or a struct is refused; a pointer to a struct is a scalar.
TEST(Inject, WatchedValuesAsTheirTypesReadThem) {
  const char* source =
      "struct pt { int x; int y; };\n"
      "struct pt s;\n"
      "struct pt *p;\n"
      "char c;\n"
      "int i;\n"
      "unsigned int u;\n"
      "long l;\n"
      "unsigned long ul;\n"
      "float f;\n"
      "int a[3];\n"
      "int twice(int n) { return n * 2; }\n"
      "main()\n"
      "{\n"
      "    p = &s; c = 200; i = twice(-1); u = 65534; l = -100000L; ul = 3000000000UL; f = 1.5;\n"
      "    while (1);\n"
      "}\n";
  scheduler::MatchConfig c = soloConfig({});
  c.robots[0] = {"A", "types.dc", testkit::compileOrDie(source, "types.dc")};
  c.endTick = scheduler::kTicksPerSecond;
  c.stopWhenAllExited = false;
  c.watches = {"p", "c", "i", "u", "l", "ul", "f", "twice.n"};
  const auto r = testkit::runTraced(c);
  std::optional<nlohmann::json> last;
  for (const auto& line : r.trace) {
    const auto j = nlohmann::json::parse(line);
    if (j.at("type") == "sample" && j.contains("watch")) last = j.at("watch");
  }
  ASSERT_TRUE(last.has_value());
  uint32_t address = 0;
  for (const auto& sym : c.robots[0].image.symbols)
    if (sym.name == "s") address = sym.address;
  ASSERT_NE(address, 0u);
  EXPECT_EQ(last->at("p"), address);
  EXPECT_EQ(last->at("c"), 200);
  EXPECT_EQ(last->at("i"), -2);
  EXPECT_EQ(last->at("u"), 65534);
  EXPECT_EQ(last->at("l"), -100000);
  EXPECT_EQ(last->at("ul"), 3000000000LL);
  EXPECT_EQ(last->at("f"), 1.5);
  EXPECT_EQ(last->at("twice.n"), -1);  // a static function's parameter, FUNCTION.NAME
  // Any lvalue simbot debug's print takes (issue 26): an aggregate as the
  // debugger prints it, a member through a pointer, a slice; a function or
  // a name no program has is refused.
  c.watches = {"s", "a", "p->x", "a[1]@2", "i * 2"};
  std::optional<nlohmann::json> more;
  for (const auto& line : testkit::runTraced(c).trace) {
    const auto j = nlohmann::json::parse(line);
    if (j.at("type") == "sample" && j.contains("watch")) more = j.at("watch");
  }
  ASSERT_TRUE(more.has_value());
  EXPECT_EQ(more->at("s"), "{x = 0, y = 0}");
  EXPECT_EQ(more->at("a"), "{0, 0, 0}");
  EXPECT_EQ(more->at("p->x"), 0);
  EXPECT_EQ(more->at("a[1]@2"), "{0, 0}");
  EXPECT_EQ(more->at("i * 2"), -4);
  for (const char* refused : {"main", "nosuch.x", "s.", "x"}) {
    c.watches = {refused};
    EXPECT_THROW(testkit::runTraced(c), std::invalid_argument) << refused;
  }
}

// A watched auto is read from the innermost frame when it is in scope
// there, and is null elsewhere (#class auto: f's n lives on the stack).
TEST(Inject, WatchedAutosAreNullOutOfScope) {
  const char* source =
      "#class auto\n"
      "int f(int n) { int k; for (k = 0; k < 2000; k++); return n + k; }\n"
      "main()\n"
      "{\n"
      "    int r;\n"
      "    while (1) r = f(7);\n"
      "}\n";
  scheduler::MatchConfig c = soloConfig({});
  c.robots[0] = {"A", "autos.dc", testkit::compileOrDie(source, "autos.dc")};
  c.endTick = scheduler::kTicksPerSecond;
  c.stopWhenAllExited = false;
  c.watches = {"n", "r"};
  int inF = 0, inMain = 0;
  for (const auto& line : testkit::runTraced(c).trace) {
    const auto j = nlohmann::json::parse(line);
    if (j.at("type") != "sample" || !j.contains("watch")) continue;
    const auto& w = j.at("watch");
    if (w.at("n").is_null()) {
      // main's frame: no n; r is its auto, once main's ENTER has made the
      // frame (not yet at tick 0, at the start-up code's first instruction).
      ++inMain;
      EXPECT_EQ(w.at("r").is_null(), j.at("t") == 0) << j.dump();
    } else {
      ++inF;  // f's frame: n is 7, main's r is not in scope
      EXPECT_EQ(w.at("n"), 7);
      EXPECT_TRUE(w.at("r").is_null());
    }
  }
  EXPECT_GT(inF, 0);
  EXPECT_EQ(inMain + inF, 21);  // 20 Hz samples from 0 to 1 s
}

TEST(Inject, ParsesWhenForms) {
  EXPECT_EQ(config::parseInjection("A:edge_fore@12.5s", 1).tick, 115'200'000);
  EXPECT_EQ(config::parseInjection("A:edge_aft@800ms", 1).tick, 7'372'800);
  EXPECT_EQ(config::parseInjection("B:bumper_back@115200000t", 2).tick, 115'200'000);
  const auto p = config::parseInjection("A:edge_fore@line:42#3", 1);
  EXPECT_EQ(p.line, 42);
  EXPECT_EQ(p.count, 3);
  for (const char* bad :
       {"A:edge_fore", "C:edge_fore@1s", "B:edge_fore@1s", "A:laser@1s", "A:edge_fore@soon",
        "A:edge_fore@line:4", "A:edge_fore@line:0#1", "A:edge_fore@0.00000001s", "A:edge_fore@-1s"})
    EXPECT_THROW(config::parseInjection(bad, 1), std::invalid_argument) << bad;
}

}  // namespace

namespace {

// A one-line delay loop, as ICEMAN's platform() writes it: line:N#K and
// pass:N#K name different things on it.
const std::string kOneLine = R"(#INT_VEC PIOA_VEC edge
int z, seen, hits;
interrupt reti edge()
{
    seen = z;
    hits++;
}
main()
{
)" + std::string(testkit::kArmPortA) +
                             R"(    for (z = 0; z < 700; z++);
    printf("%d %d %d\n", z, seen, hits);
}
)";
constexpr int kOneLineLoop = 16;

scheduler::MatchResult oneLine(const std::vector<std::string>& injections) {
  scheduler::MatchConfig c = soloConfig({});
  c.robots[0] = {"A", "oneline.dc", testkit::compileOrDie(kOneLine, "oneline.dc")};
  for (const auto& text : injections) c.injections.push_back(config::parseInjection(text, 1));
  return scheduler::runMatch(c);
}

bool mentions(const std::vector<std::string>& warnings, const std::string& what) {
  return std::any_of(warnings.begin(), warnings.end(),
                     [&](const std::string& w) { return w.find(what) != std::string::npos; });
}

}  // namespace

TEST(Inject, PassTargetsTheKthPassOfALoopOnOneLine) {
  // The loop's head (z < 700) runs at the start of pass K with z == K - 1,
  // and once more, as the 701st, for the test that ends the loop (z == 700).
  for (int k : {1, 2, 350, 700, 701}) {
    const auto r = oneLine({"A:edge_aft@pass:16#" + std::to_string(k)});
    EXPECT_EQ(r.robots[0].console, std::vector<std::string>{"700 " + std::to_string(k - 1) + " 1"})
        << "pass " << k;
    EXPECT_TRUE(r.warnings.empty()) << r.warnings.front();
  }
  // There is no 702nd: it never fires, and the run says so.
  const auto never = oneLine({"A:edge_aft@pass:16#702"});
  EXPECT_EQ(never.robots[0].console, std::vector<std::string>{"700 0 0"});
  ASSERT_EQ(never.warnings.size(), 1u);
  EXPECT_TRUE(mentions(never.warnings, "A:edge_aft@pass:16#702 never fired"));
  EXPECT_TRUE(mentions(never.warnings, "ran 701 time(s)"));
}

TEST(Inject, LineOnALineHoldingALoopCountsEntriesAndSaysSo) {
  // The line is entered once: line:16#1 fires before z = 0 runs (z still
  // 0 from power-on), line:16#2 never fires; each says what it counts.
  const auto first = oneLine({"A:edge_fore@line:16#1"});
  EXPECT_EQ(first.robots[0].console, std::vector<std::string>{"700 0 1"});
  EXPECT_TRUE(mentions(first.warnings, "line:N#K counts entries into the line"));
  EXPECT_TRUE(mentions(first.warnings, "pass:16#1"));
  const auto second = oneLine({"A:edge_fore@line:16#2"});
  EXPECT_EQ(second.robots[0].console, std::vector<std::string>{"700 0 0"});
  EXPECT_TRUE(mentions(second.warnings, "A:edge_fore@line:16#2 never fired: line 16"));
  EXPECT_TRUE(mentions(second.warnings, "ran 1 time(s)"));
  // The body line of the other program holds no whole loop: no note there.
  EXPECT_TRUE(
      solo({"A:edge_aft@line:" + std::to_string(kLoopBodyLine) + "#5"}).result.warnings.empty());
}

TEST(Inject, PassNeedsALoopOnTheLine) {
  const auto img = testkit::compileOrDie(kOneLine, "oneline.dc");
  EXPECT_TRUE(img.loopHead(kOneLineLoop).has_value());
  EXPECT_FALSE(img.loopHead(17).has_value());  // the printf
  EXPECT_THROW(oneLine({"A:edge_aft@pass:17#1"}), std::invalid_argument);
  EXPECT_THROW(config::parseInjection("A:edge_aft@pass:16", 1), std::invalid_argument);
  EXPECT_TRUE(config::parseInjection("A:edge_aft@pass:16#3", 1).pass);
}

TEST(Inject, InjectionsThatNeverFiredAreNamed) {
  // The program returns from main long before 9 s (20,000 passes of a few
  // hundred T-states: about half a second), so the run ends first; the
  // 100-ms one fires.
  // The loop body runs 20,000 times, never a 20,001st.
  const std::string body = "A:edge_aft@line:" + std::to_string(kLoopBodyLine) + "#20001";
  const SoloRun run = solo({"A:edge_fore@100ms", "A:bumper_front@9s", body});
  ASSERT_EQ(run.result.warnings.size(), 2u);
  EXPECT_TRUE(mentions(run.result.warnings, "A:bumper_front@9s never fired: the run ended at"));
  EXPECT_TRUE(mentions(run.result.warnings, body + " never fired"));
  EXPECT_TRUE(mentions(run.result.warnings, "ran 20000 time(s)"));
  EXPECT_FALSE(mentions(run.result.warnings, "A:edge_fore@100ms"));
}
