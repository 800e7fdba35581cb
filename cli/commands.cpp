#include "cli/commands.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
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

namespace simbot::cli {

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

void addThresholdOptions(CLI::App& cmd, batch::MetricThresholds& t) {
  cmd.add_option("--seen-threshold", t.seen,
                 "eye reading above which the beacon counts as seen: both eyes for acquire_s, "
                 "either for stall_s (default 48, ICEMAN's)")
      ->check(CLI::Range(0, 1'000'000));
  cmd.add_option("--aim-max-diff", t.aimMaxDiff,
                 "aim_s: largest |left - right| eye difference (default 50, ICEMAN's)")
      ->check(CLI::Range(0, 1'000'000));
  cmd.add_option("--aim-min-sum", t.aimMinSum,
                 "aim_s: smallest left + right eye sum (default 800, ICEMAN's)")
      ->check(CLI::Range(0, 1'000'000));
}

Subcommand addBenchCommand(CLI::App& app) {
  struct Options {
    batch::BenchConfig config;
    std::string out, profile = "default", scenario;
    bool resume = false, json = false;
    CLI::Option *seconds = nullptr, *seed = nullptr, *profileOption = nullptr;
  };
  auto o = std::make_shared<Options>();
  auto* cmd = app.add_subcommand("bench", "scenario families over many seeds, with statistics");
  addThresholdOptions(*cmd, o->config.thresholds);
  cmd->add_flag("--json", o->json, "print the summary as JSON (summary.json) instead of tables");
  cmd->add_option("PROGRAM", o->config.programs, "programs under test (each is robot A)")
      ->required();
  auto* family =
      cmd->add_option("--family", o->config.family, "stationary, circle, head-to-head or edge");
  cmd->add_option("--seeds", o->config.seeds, "runs per program")
      ->required()
      ->check(CLI::Range(1, 1'000'000));
  o->seconds =
      cmd->add_option("--seconds", o->config.seconds, "simulated seconds per run (default 60)");
  o->seed = cmd->add_option("--seed", o->config.masterSeed, "master seed (default 1)")
                ->check(seedValidator());
  cmd->add_option("--threads", o->config.threads, "worker threads (default: all cores)")
      ->check(CLI::Range(1, 1024));
  cmd->add_option("--out", o->out, "output directory (default out/bench-FAMILY)");
  cmd->add_flag("--resume", o->resume,
                "continue an interrupted bench from the runs.csv in its output directory");
  cmd->add_option("--median", o->config.median,
                  "a Kaplan-Meier median on an exact 0.5 plateau: upper (its upper end, as "
                  "statsmodels; the default) or midpoint (as SAS and R's survival)")
      ->transform(CLI::CheckedTransformer(
          std::map<std::string, stats::QuantileRule>{{"upper", stats::QuantileRule::FirstBelow},
                                                     {"midpoint", stats::QuantileRule::Midpoint}}));
  o->profileOption =
      cmd->add_option("--profile", o->profile, "profile name or file (default: default)");
  cmd->add_option("--opponent", o->config.opponent, "robot B's program (head-to-head)");
  auto* scenario = cmd->add_option(
      "--scenario", o->scenario,
      "scenario file: profile, hardware and injections; without --family also the poses and B");
  cmd->callback([family, scenario] {
    if (family->count() == 0 && scenario->count() == 0)
      throw CLI::RequiredError("--family or --scenario");
  });
  return {
      cmd, [o] {
        return guarded([&] {
          const auto start = std::chrono::steady_clock::now();
          batch::BenchConfig& c = o->config;
          std::string profile = o->profile;
          if (!o->scenario.empty()) {
            c.scenario = config::loadScenario(o->scenario);
            profile = runs::preferCommandLine(o->profileOption->count() > 0, c.scenario->profile,
                                              profile);
            c.seconds =
                runs::preferCommandLine(o->seconds->count() > 0, c.scenario->seconds, c.seconds);
            c.masterSeed =
                runs::preferCommandLine(o->seed->count() > 0, c.scenario->seed, c.masterSeed);
          }
          const config::Profile loaded = runs::loadNamedProfile(profile);
          batch::checkBenchConfig(c);
          std::string label = batch::benchLabel(c);
          std::replace(label.begin(), label.end(), ' ', '-');
          const std::string dir = o->out.empty() ? "out/bench-" + label : o->out;
          // Checked now; written once the programs compile (runBench).
          batch::RunTable table({dir,
                                 "runs.csv",
                                 {"summary.json", "summary.md"},
                                 batch::benchHeader(),
                                 batch::benchSettings(c, loaded),
                                 simbotVersion(),
                                 o->resume});
          batch::StopOnSignals signals;
          const batch::BenchResult r = batch::runBench(c, loaded, {&table, &signals.requested()});
          batch::writeBenchOutputs(r, table);
          std::cout << (o->json ? sinks::dumpJson(batch::summaryJson(r), 2) + "\n"
                                : batch::summaryMarkdown(r));
          std::cerr << batch::benchWarnings(r) << batch::benchFaults(r);
          const auto done = std::count_if(r.runs.begin(), r.runs.end(),
                                          [](const batch::BenchRun& run) { return run.done; });
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
    batch::BenchConfig config;
    std::vector<std::string> programs;
    std::string profile = "default", profileB, out = "out/compare";
    bool json = false;
  };
  auto o = std::make_shared<Options>();
  auto* cmd = app.add_subcommand(
      "compare", "the same seeded runs for two programs (or two profiles), each metric tested");
  cmd->add_option("PROGRAM", o->programs,
                  "program A and program B (one program: A and B differ in --profile-b)")
      ->required()
      ->expected(1, 2);
  cmd->add_option("--family", o->config.family, "stationary, circle, head-to-head or edge")
      ->required();
  cmd->add_option("--seeds", o->config.seeds, "runs per side")
      ->required()
      ->check(CLI::Range(1, 1'000'000));
  cmd->add_option("--seconds", o->config.seconds, "simulated seconds per run (default 60)");
  cmd->add_option("--seed", o->config.masterSeed, "master seed (default 1)")
      ->check(seedValidator());
  cmd->add_option("--threads", o->config.threads, "worker threads (default: all cores)")
      ->check(CLI::Range(1, 1024));
  cmd->add_option("--opponent", o->config.opponent, "robot B's program (head-to-head)");
  cmd->add_option("--profile", o->profile, "A's profile name or file (default: default)");
  cmd->add_option("--profile-b", o->profileB, "B's profile (default: A's)");
  cmd->add_option("--out", o->out, "where runs-a.csv and runs-b.csv go (default out/compare)");
  cmd->add_flag("--json", o->json, "print the comparison as JSON");
  addThresholdOptions(*cmd, o->config.thresholds);
  return {cmd, [o] {
            return guarded([&] {
              const std::string profileB = o->profileB.empty() ? o->profile : o->profileB;
              if (o->programs.size() == 1 && profileB == o->profile)
                throw sinks::UserError(
                    "simbot: compare needs two programs, or one program and --profile-b\n");
              batch::BenchConfig a = o->config, b = o->config;
              a.seedKey = b.seedKey = "compare";
              a.programs = {o->programs[0]};
              b.programs = {o->programs.back()};
              batch::CompareResult r;
              const config::Profile pa = runs::loadNamedProfile(o->profile);
              const config::Profile pb = runs::loadNamedProfile(profileB);
              r.profileA = pa.name;
              r.profileB = pb.name;
              batch::checkBenchConfig(a);
              const auto out = [&](const char* name) {
                return (std::filesystem::path(o->out) / name).string();
              };
              std::vector<std::string> inputs = batch::benchInputs(a, pa);
              for (const auto& path : batch::benchInputs(b, pb)) inputs.push_back(path);
              batch::checkBatchOutputs(inputs, {out("runs-a.csv"), out("runs-b.csv")});
              // Made now (an unusable location fails before any run); written at the end.
              batch::makeOutputFolder(o->out);
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
              std::cout << (o->json ? sinks::dumpJson(batch::compareJson(r), 2) + "\n"
                                    : batch::compareMarkdown(r));
              std::cerr << batch::benchWarnings(r.a) << batch::benchFaults(r.a)
                        << batch::benchWarnings(r.b) << batch::benchFaults(r.b);
              return 0;
            });
          }};
}

Subcommand addTournamentCommand(CLI::App& app) {
  struct Options {
    batch::TournamentConfig config;
    std::string profile = "default", out = "out/tournament";
    bool json = false, resume = false;
    double seconds = 0;  // copied to config.seconds only if given
    CLI::Option* secondsOption = nullptr;
  };
  auto o = std::make_shared<Options>();
  auto* cmd = app.add_subcommand("tournament", "round robin after thesis Appendix A");
  cmd->add_option("PROGRAM", o->config.programs, "the programs (two or more)")->required();
  cmd->add_option("--rounds", o->config.rounds, "rounds per pair, sides swapped (default 2)")
      ->check(CLI::Range(1, 10'000));
  o->secondsOption = cmd->add_option("--seconds", o->seconds,
                                     "round length (default: the profile's round_length)");
  cmd->add_option("--seed", o->config.masterSeed, "master seed (default 1)")
      ->check(seedValidator());
  cmd->add_option("--threads", o->config.threads, "worker threads (default: all cores)")
      ->check(CLI::Range(1, 1024));
  cmd->add_option("--profile", o->profile, "profile name or file (default: default)");
  cmd->add_option("--out", o->out, "output directory (default out/tournament)");
  cmd->add_flag("--resume", o->resume,
                "continue an interrupted tournament from the games.csv in its output directory");
  cmd->add_flag("--json", o->json, "print standings and games as JSON");
  cmd->add_flag("--reload-on-fault", o->config.reloadOnFault,
                "reload a faulted program after the profile's [match] reload_delay: it starts "
                "again from main with its memory as at load (thesis Appendix A)");
  return {cmd, [o] {
            return guarded([&] {
              const config::Profile profile = runs::loadNamedProfile(o->profile);
              if (o->secondsOption->count() > 0) o->config.seconds = o->seconds;
              batch::checkTournamentConfig(o->config);
              batch::RunTable table({o->out,
                                     "games.csv",
                                     {"standings.json", "standings.md"},
                                     batch::tournamentHeader(),
                                     batch::tournamentSettings(o->config, profile),
                                     simbotVersion(),
                                     o->resume});
              batch::StopOnSignals signals;
              const batch::TournamentResult r =
                  batch::runTournament(o->config, profile, &table, &signals.requested());
              batch::writeTournamentOutputs(r, table);
              if (o->json)
                std::cout << sinks::dumpJson(batch::tournamentJson(r), 2) << '\n';
              else
                std::cout << batch::standingsTable(r);
              std::cerr << batch::tournamentFaults(r);
              if (r.stopped) {
                std::cerr << fmt::format(
                    "simbot: tournament stopped by signal {}; {}/games.csv and the standings "
                    "hold the games played; --resume continues\n",
                    signals.signal(), o->out);
                return 128 + signals.signal();
              }
              return 0;
            });
          }};
}

}  // namespace simbot::cli
