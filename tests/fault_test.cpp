// Faults are loud everywhere, and --reload-on-fault (thesis Appendix A: "you
// will be allowed to reload if the system crashes"); sends that overwrite
// the previous frame are counted.
#include <gtest/gtest.h>

#include <algorithm>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "batch/bench.h"
#include "batch/tournament.h"
#include "config/config.h"
#include "plant/plant.h"
#include "runs/play.h"
#include "scheduler/match.h"
#include "support/test_host.h"
#include "support/traced.h"

using namespace simbot;
using nlohmann::json;

namespace {

// Arms the PIO as ICEMAN does but binds no vector ("#define INT_VEC"), and
// backs towards the south wire: the first crossing faults.
const std::string kFaulting = SIMBOT_SOURCE_DIR "/tests/faulting/unbound_vector.dc";
const std::string kTurret = SIMBOT_SOURCE_DIR "/programs/turret.dc";
constexpr scheduler::Tick kSecond = scheduler::kTicksPerSecond;

config::Profile defaultProfile() {
  return config::loadProfile(SIMBOT_SOURCE_DIR "/profiles/default.toml");
}

scheduler::MatchConfig soloConfig(scheduler::Tick end) {
  scheduler::MatchConfig c;
  c.arena = config::makeArenaConfig(defaultProfile(), 1);
  c.robots.push_back({"A", kFaulting, runs::compileProgramFile(kFaulting)});
  c.endTick = end;
  return c;
}

std::vector<json> records(const testkit::TracedRun& run, const std::string& type) {
  std::vector<json> out;
  for (const auto& line : run.trace) {
    json j = json::parse(line);
    if (j.at("type") == type) out.push_back(std::move(j));
  }
  return out;
}

TEST(Fault, UnboundVectorFaultsAtTheFirstWireCrossing) {
  const auto run = testkit::runTraced(soloConfig(10 * kSecond));
  const auto& a = run.robots[0];
  ASSERT_TRUE(a.fault.has_value());
  EXPECT_EQ(a.faults.size(), 1u);
  EXPECT_EQ(a.reloads, 0);
  EXPECT_NE(a.fault->message.find("pio_a interrupt through vector 0x10, which no #INT_VEC binds"),
            std::string::npos)
      << a.fault->message;
  // The fault comes at the aft detector's first edge_enter: the PIO raises
  // its request there, and the VM faults at the next boundary (at most one
  // instruction or 100-T-state library step later).
  const auto enters = records(run, "edge_enter");
  const auto faults = records(run, "fault");
  ASSERT_FALSE(enters.empty());
  ASSERT_EQ(faults.size(), 1u);
  EXPECT_EQ(enters[0].at("detector"), "aft");
  const auto enterT = enters[0].at("t").get<scheduler::Tick>();
  const auto faultT = faults[0].at("t").get<scheduler::Tick>();
  EXPECT_GE(faultT, enterT);
  EXPECT_LE(faultT - enterT, 100);
  EXPECT_DOUBLE_EQ(a.fault->timeS, static_cast<double>(faultT) / kSecond);
  EXPECT_TRUE(records(run, "reload").empty());
  EXPECT_EQ(a.console, std::vector<std::string>{"boot 1"});
}

TEST(Fault, ReloadRestartsFromMainWithMemoryAsAtLoadAndTheRunGoesOn) {
  scheduler::MatchConfig c = soloConfig(6 * kSecond);
  c.reloadOnFault = true;
  c.reloadDelay = kSecond;
  const auto run = testkit::runTraced(c);
  const auto& a = run.robots[0];
  EXPECT_EQ(run.endTick, 6 * kSecond);  // the run went on to its end
  ASSERT_GE(a.reloads, 1);
  const auto faults = records(run, "fault");
  const auto reloads = records(run, "reload");
  ASSERT_EQ(static_cast<int>(reloads.size()), a.reloads);
  ASSERT_EQ(a.faults.size(), faults.size());
  // Every fault but one ending too late is followed by its reload exactly
  // one delay later.
  ASSERT_TRUE(faults.size() == reloads.size() || faults.size() == reloads.size() + 1);
  for (size_t k = 0; k < reloads.size(); ++k) {
    EXPECT_EQ(reloads[k].at("t").get<scheduler::Tick>(),
              faults[k].at("t").get<scheduler::Tick>() + c.reloadDelay);
    EXPECT_EQ(reloads[k].at("reloads"), static_cast<int>(k) + 1);
  }
  if (faults.size() > reloads.size()) {
    EXPECT_GE(faults.back().at("t").get<scheduler::Tick>() + c.reloadDelay, c.endTick);
  }
  // main ran again each time, and `boots` was 0 again: memory as at load.
  EXPECT_EQ(a.console, std::vector<std::string>(static_cast<size_t>(a.reloads) + 1, "boot 1"));
  // The reloaded program armed its PIO and sent its motor string again: a
  // frame latched after the first reload (9 characters after its send).
  const auto reloadT = reloads[0].at("t").get<scheduler::Tick>();
  const auto latched = records(run, "frame_latched");
  EXPECT_TRUE(std::any_of(latched.begin(), latched.end(), [&](const json& j) {
    return j.at("t").get<scheduler::Tick>() > reloadT && j.at("bytes") == "frgrfrgr";
  }));
  // The motor controller kept the faulted program's command: nothing
  // latched, and the robot kept backing, between the fault and the reload.
  const auto faultT = faults[0].at("t").get<scheduler::Tick>();
  EXPECT_FALSE(std::any_of(latched.begin(), latched.end(), [&](const json& j) {
    const auto t = j.at("t").get<scheduler::Tick>();
    return t > faultT && t < reloadT;
  }));
  const auto results = records(run, "result");
  ASSERT_EQ(results.size(), 1u);
  EXPECT_EQ(results[0].at("reloads"), a.reloads);
  EXPECT_EQ(results[0].at("faulted"), true);
}

TEST(Fault, ReloadIsTheSameWithAndWithoutATrace) {
  scheduler::MatchConfig c = soloConfig(6 * kSecond);
  c.reloadOnFault = true;
  c.reloadDelay = kSecond;
  const auto plain = scheduler::runMatch(c);
  const auto traced = testkit::runTraced(c);
  EXPECT_EQ(plain.robots[0].reloads, traced.robots[0].reloads);
  EXPECT_EQ(plain.robots[0].cycles, traced.robots[0].cycles);
  EXPECT_EQ(plain.robots[0].framesLatched, traced.robots[0].framesLatched);
  ASSERT_EQ(plain.robots[0].faults.size(), traced.robots[0].faults.size());
  for (size_t k = 0; k < plain.robots[0].faults.size(); ++k)
    EXPECT_EQ(plain.robots[0].faults[k].timeS, traced.robots[0].faults[k].timeS);
}

TEST(Fault, ReloadDelayMustCoverTheSerialPort) {
  scheduler::MatchConfig c = soloConfig(kSecond);
  c.reloadOnFault = true;
  c.reloadDelay = scheduler::kMinReloadDelay - 1;
  EXPECT_THROW(scheduler::runMatch(c), std::invalid_argument);
  // The profiles' delay: 20 s, within its checked range.
  EXPECT_DOUBLE_EQ(defaultProfile().reload_delay_s, 20.0);
}

TEST(Fault, InAMatchTheOtherRobotPlaysOnAndTheFaultedOneLosesATie) {
  scheduler::MatchConfig c;
  c.arena = config::makeArenaConfig(defaultProfile(), 2);
  c.robots.push_back({"A", kFaulting, runs::compileProgramFile(kFaulting)});
  c.robots.push_back({"B", kTurret, runs::compileProgramFile(kTurret)});
  c.endTick = 30 * kSecond;
  c.reloadOnFault = true;
  c.reloadDelay = 20 * kSecond;
  const auto r = scheduler::runMatch(c);
  EXPECT_EQ(r.endTick, c.endTick);
  ASSERT_TRUE(r.robots[0].fault.has_value());
  EXPECT_EQ(r.robots[0].reloads, 1);  // the first fault is well before 10 s
  EXPECT_FALSE(r.robots[1].fault.has_value());
  EXPECT_GT(r.robots[1].framesLatched, 0);
  if (r.robots[0].hits == r.robots[1].hits) {
    EXPECT_EQ(r.winner, "B");
  }
}

TEST(Fault, TournamentRecordsFaultsAndReloadsPerGame) {
  batch::TournamentConfig c;
  c.programs = {kFaulting, kTurret};
  c.rounds = 2;
  c.seconds = 25;
  c.threads = 2;
  c.progress = false;
  c.reloadOnFault = true;
  const auto r = batch::runTournament(c, defaultProfile());
  ASSERT_EQ(r.games.size(), 2u);
  const json j = batch::tournamentJson(r);
  EXPECT_EQ(j.at("reload_on_fault"), true);
  for (const auto& game : j.at("games")) {
    // The faulting program is A in round 0 and B in round 1; it faults at
    // its first crossing (under a second) and is reloaded 20 s later.
    const bool faultingIsA = game.at("a") == kFaulting;
    const auto& fault = game.at(faultingIsA ? "fault_a" : "fault_b");
    ASSERT_TRUE(fault.is_string());
    EXPECT_NE(fault.get<std::string>().find("which no #INT_VEC binds"), std::string::npos);
    EXPECT_TRUE(game.at(faultingIsA ? "fault_b" : "fault_a").is_null());
    EXPECT_EQ(game.at(faultingIsA ? "reloads_a" : "reloads_b"), 1);
    EXPECT_EQ(game.at(faultingIsA ? "reloads_b" : "reloads_a"), 0);
  }
  for (const auto& s : j.at("standings"))
    EXPECT_EQ(s.at("faulted"), s.at("program") == kFaulting ? 2 : 0);
  EXPECT_NE(batch::tournamentFaults(r).find("which no #INT_VEC binds"), std::string::npos);
}

TEST(Fault, BenchHasAFaultColumnAndCountsFaultsPerProgram) {
  batch::BenchConfig c;
  c.programs = {kFaulting};
  c.family = "stationary";
  c.seeds = 2;
  c.seconds = 20;
  c.threads = 2;
  c.progress = false;
  const auto r = batch::runBench(c, defaultProfile());
  const std::string csv = batch::runsCsv(r);
  const auto header = csv.substr(0, csv.find('\n'));
  EXPECT_NE(header.find(",outcome,fault,"), std::string::npos);
  for (const auto& run : r.runs) {
    EXPECT_EQ(run.outcome, "fault");
    EXPECT_NE(run.fault.find("robot A faulted at"), std::string::npos);
    EXPECT_NE(run.fault.find("which no #INT_VEC binds"), std::string::npos);
    EXPECT_NE(csv.find(run.fault), std::string::npos);
  }
  const json s = batch::summaryJson(r);
  EXPECT_EQ(s.at("programs")[0].at("runs_faulted"), 2);
}

// ICEMAN's platform() without its 700-pass delay loop, called N times in a
// row: each send restarts the library before it has fetched the previous
// send's NUL.
std::string sender(int sends, bool delayLoop) {
  return "char buf[9];\nchar cc;\nint n, z;\n"
         "platform()\n{\n    cc = sizeof(buf);\n    ser_send_z1(buf,&cc);\n" +
         std::string(delayLoop ? "    for(z=0;z<700;z++);\n" : "") +
         "}\n"
         "main()\n{\n    ser_init_z1(0,9600/1200);\n    strcpy(buf,\"8fgr8fgr\");\n"
         "    for(n=0;n<" +
         std::to_string(sends) + ";n++) platform();\n}\n";
}

scheduler::RobotResult sendAndWait(int sends, bool delayLoop) {
  scheduler::MatchConfig c;
  c.arena = config::makeArenaConfig(defaultProfile(), 1);
  c.robots.push_back({"A", "sender.dc", testkit::compileOrDie(sender(sends, delayLoop))});
  // Long after main returns: every byte still in the port has gone out.
  c.endTick = kSecond;
  return scheduler::runMatch(c).robots[0];
}

TEST(FramesOverwritten, SendsWithoutTheDelayLoopOverwriteAllButTheLast) {
  // Closed form. Without the delay, the N sends all come within the first
  // character time (each platform() is a few hundred T-states; one
  // character is 9,600 ticks): the first send's byte 0 is in the shift
  // register and its byte 1 in the data register, so every later send finds
  // bytes of the previous one still unfetched (the NUL last of all). The
  // wire carries buf[0], buf[1], then the last send's 9 bytes: one frame
  // latches (the last 8 characters before the NUL are the frame), none is
  // rejected, N - 1 are overwritten.
  for (int n : {1, 2, 5, 12}) {
    const auto r = sendAndWait(n, false);
    EXPECT_EQ(r.framesOverwritten, n - 1) << n << " sends";
    EXPECT_EQ(r.framesLatched, 1) << n << " sends";
    EXPECT_EQ(r.framesRejected, 0) << n << " sends";
  }
  // With ICEMAN's delay loop every frame latches, none is overwritten: 700
  // passes outlast the 86,400 ticks a frame takes once a pass costs more
  // than 124 T-states, and a pass is seven instructions and a debug hook
  // (about 250; docs/cycle-model.md, "The cycle model").
  const auto paced = sendAndWait(5, true);
  EXPECT_EQ(paced.framesOverwritten, 0);
  EXPECT_EQ(paced.framesLatched, 5);
}

}  // namespace
