#include "cli/commands.h"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <map>
#include <memory>

#include "batch/bench.h"
#include "batch/compare.h"
#include "batch/run_table.h"
#include "batch/tournament.h"
#include "cli/version.h"
#include "config/config.h"
#include "runs/play.h"
#include "runs/scenario.h"
#include "sinks/json_text.h"
#include "sinks/user_error.h"
#include "timebase/tick.h"

namespace simbot::cli {

#ifdef SIMBOT_PYTHON
std::string pythonModuleDir() {
  std::error_code ec;
  const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    const auto installed = self.parent_path().parent_path() / SIMBOT_PYTHON_INSTALL_DIR;
    if (std::filesystem::exists(installed / "simbot" / "sweep.py", ec)) return installed.string();
  }
  return SIMBOT_PYTHON_BUILD_DIR;
}

void execPython(const std::string& pythonPath, std::vector<std::string> args,
                const std::string& what) {
  std::string path = pythonPath;
  if (const char* old = std::getenv("PYTHONPATH"); old && *old) path += std::string(":") + old;
  setenv("PYTHONPATH", path.c_str(), 1);
  args.insert(args.begin(), SIMBOT_PYTHON);
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  std::cout.flush();
  execv(SIMBOT_PYTHON, argv.data());
  throw sinks::UserError(
      fmt::format("simbot: {}: cannot run {}: {}\n", what, SIMBOT_PYTHON, std::strerror(errno)));
}
#endif

int guarded(const std::function<int()>& body) {
  try {
    return body();
  } catch (const sinks::UserError& e) {
    std::cerr << e.what();
    return 1;
  } catch (const config::ConfigError& e) {
    std::cerr << e.what() << '\n';
    return 1;
  }
}

namespace {}  // namespace

CLI::Validator seedValidator() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        constexpr std::string_view kMax = "18446744073709551615";  // 2^64 - 1
        const bool digits = !text.empty() && text.size() <= kMax.size() &&
                            text.find_first_not_of("0123456789") == std::string::npos;
        if (!digits || (text.size() == kMax.size() && text > kMax))
          return "a seed is an integer from 0 to 18446744073709551615, got '" + text + "'";
        return "";
      },
      "SEED");
}

Subcommand addBenchCommand(CLI::App& app) {
  struct Options {
    runs::RunOptions run;
    std::vector<std::string> programs;
  };
  auto o = std::make_shared<Options>();
  auto* cmd = app.add_subcommand("bench", "scenario families over many seeds, with statistics");
  cmd->add_option("PROGRAM", o->programs, "programs under test (each is robot A)")->required();
  addRunOptions(cmd, o->run, runs::kBench);
  cmd->get_option("--seeds")->required();
  cmd->callback([cmd] {
    if (cmd->count("--family") == 0 && cmd->count("--scenario") == 0)
      throw CLI::RequiredError("--family or --scenario");
  });
  return {
      cmd, [o] {
        return guarded([&] {
          const auto start = std::chrono::steady_clock::now();
          const runs::RunOptions& run = o->run;
          std::optional<config::Scenario> scenario;
          if (!run.scenario.empty()) scenario = config::loadScenario(run.scenario);
          batch::BenchConfig c = batch::benchConfig(run, scenario);
          c.programs = o->programs;
          const config::Profile loaded = runs::loadRunProfile(
              runs::preferCommandLine(run.profile.has_value(),
                                      scenario ? scenario->profile : std::nullopt,
                                      run.profile.value_or("default")),
              runs::runRules(run, scenario));
          batch::checkBenchConfig(c);
          std::string label = batch::benchLabel(c);
          std::replace(label.begin(), label.end(), ' ', '-');
          const std::string dir = run.out.empty() ? "out/bench-" + label : run.out;
          // Checked now; written once the programs compile (runBench).
          batch::RunTable table({dir,
                                 "runs.csv",
                                 {"summary.json", "summary.md"},
                                 batch::benchHeader(),
                                 batch::benchSettings(c, loaded),
                                 simbotVersion(),
                                 run.resume});
          batch::StopOnSignals signals;
          const batch::BenchResult r = batch::runBench(c, loaded, {&table, &signals.requested()});
          batch::writeBenchOutputs(r, table);
          std::cout << (run.json ? sinks::dumpJson(batch::summaryJson(r), 2) + "\n"
                                 : batch::summaryMarkdown(r));
          std::cerr << batch::benchWarnings(r) << batch::benchFaults(r);
          const auto done = std::count_if(r.runs.begin(), r.runs.end(),
                                          [](const batch::BenchRun& each) { return each.done; });
          const double wall =
              std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
          if (r.stopped) {
            std::cerr << fmt::format(
                "simbot: bench stopped by signal {} with {} of {} runs done ({:.1f} s wall); "
                "{}/runs.csv and the summary hold them; --resume continues\n",
                signals.signal(), done, r.runs.size(), wall, dir);
            return 128 + signals.signal();
          }
          std::cerr << fmt::format(
              "simbot: {} runs in {:.1f} s wall; wrote {}/runs.csv, summary.json, summary.md\n",
              r.runs.size(), wall, dir);
          return 0;
        });
      }};
}

Subcommand addCompareCommand(CLI::App& app) {
  struct Options {
    runs::RunOptions run;
    std::vector<std::string> programs;
  };
  auto o = std::make_shared<Options>();
  auto* cmd = app.add_subcommand(
      "compare", "the same seeded runs for two programs (or two profiles), each metric tested");
  cmd->add_option("PROGRAM", o->programs,
                  "program A and program B (one program: A and B differ in --profile-b)")
      ->required()
      ->expected(1, 2);
  addRunOptions(cmd, o->run, runs::kCompare);
  cmd->get_option("--family")->required();
  cmd->get_option("--seeds")->required();
  return {cmd, [o] {
            return guarded([&] {
              const runs::RunOptions& run = o->run;
              const std::string profileA = run.profile.value_or("default");
              const std::string profileB = run.profileB.empty() ? profileA : run.profileB;
              if (o->programs.size() == 1 && profileB == profileA)
                throw sinks::UserError(
                    "simbot: compare needs two programs, or one program and --profile-b\n");
              const std::string outDir = run.out.empty() ? "out/compare" : run.out;
              batch::BenchConfig a = batch::benchConfig(run), b = a;
              a.seedKey = b.seedKey = "compare";
              a.programs = {o->programs[0]};
              b.programs = {o->programs.back()};
              batch::CompareResult r;
              const std::string rules = run.rules.value_or("");
              const config::Profile pa = runs::loadRunProfile(profileA, rules);
              const config::Profile pb = runs::loadRunProfile(profileB, rules);
              r.profileA = pa.name;
              r.profileB = pb.name;
              batch::checkBenchConfig(a);
              const auto out = [&](const char* name) {
                return (std::filesystem::path(outDir) / name).string();
              };
              std::vector<std::string> inputs = batch::benchInputs(a, pa);
              for (const auto& path : batch::benchInputs(b, pb)) inputs.push_back(path);
              batch::checkBatchOutputs(inputs, {out("runs-a.csv"), out("runs-b.csv")});
              // Made now (an unusable location fails before any run); written at the end.
              batch::makeOutputFolder(outDir);
              batch::StopOnSignals signals;
              r.a = batch::runBench(a, pa, {nullptr, &signals.requested()});
              if (!r.a.stopped) r.b = batch::runBench(b, pb, {nullptr, &signals.requested()});
              if (r.a.stopped || r.b.stopped) {
                std::cerr << fmt::format("simbot: compare stopped by signal {}\n",
                                         signals.signal());
                return 128 + signals.signal();
              }
              batch::writeFileAtomically(out("runs-a.csv"), batch::runsCsv(r.a));
              batch::writeFileAtomically(out("runs-b.csv"), batch::runsCsv(r.b));
              r.rows = batch::compareRuns(r.a, r.b);
              std::cout << (run.json ? sinks::dumpJson(batch::compareJson(r), 2) + "\n"
                                     : batch::compareMarkdown(r));
              std::cerr << batch::benchWarnings(r.a) << batch::benchFaults(r.a)
                        << batch::benchWarnings(r.b) << batch::benchFaults(r.b);
              return 0;
            });
          }};
}

Subcommand addTournamentCommand(CLI::App& app) {
  struct Options {
    runs::RunOptions run;
    std::vector<std::string> programs;
  };
  auto o = std::make_shared<Options>();
  auto* cmd = app.add_subcommand("tournament", "round robin after thesis Appendix A");
  cmd->add_option("PROGRAM", o->programs, "the programs (two or more)")->required();
  addRunOptions(cmd, o->run, runs::kTournament);
  return {cmd, [o] {
            return guarded([&] {
              const runs::RunOptions& run = o->run;
              const config::Profile profile =
                  runs::loadRunProfile(run.profile.value_or("default"), run.rules.value_or(""));
              batch::TournamentConfig config;
              config.programs = o->programs;
              config.rounds = run.rounds;
              if (run.length) config.seconds = timebase::secondsFromTicks(*run.length);  // exact
              config.masterSeed = run.seed.value_or(config.masterSeed);
              config.threads = run.threads.value_or(0);
              config.reloadOnFault = run.reloadOnFault;
              const std::string outDir = run.out.empty() ? "out/tournament" : run.out;
              batch::checkTournamentConfig(config);
              batch::RunTable table({outDir,
                                     "games.csv",
                                     {"standings.json", "standings.md"},
                                     batch::tournamentHeader(),
                                     batch::tournamentSettings(config, profile),
                                     simbotVersion(),
                                     run.resume});
              batch::StopOnSignals signals;
              const batch::TournamentResult r =
                  batch::runTournament(config, profile, &table, &signals.requested());
              batch::writeTournamentOutputs(r, table);
              if (run.json)
                std::cout << sinks::dumpJson(batch::tournamentJson(r), 2) << '\n';
              else
                std::cout << batch::standingsTable(r);
              std::cerr << batch::tournamentFaults(r);
              if (r.stopped) {
                std::cerr << fmt::format(
                    "simbot: tournament stopped by signal {}; {}/games.csv and the standings "
                    "hold the games played; --resume continues\n",
                    signals.signal(), outDir);
                return 128 + signals.signal();
              }
              return 0;
            });
          }};
}

}  // namespace simbot::cli
