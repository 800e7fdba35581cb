// simbot tournament: a round robin after thesis Appendix A. Every pair of
// programs plays `rounds` rounds, sides swapped each round; the most valid
// hits wins a round, a tie goes to the seeded coin (MatchResult::winner).
// Points: 1 per round won (Appendix A ranks by rounds won; it gives no
// points scheme). Standings are sorted by points, then hit difference, then
// hits for, then the order the programs were given.
#pragma once
#include <atomic>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "batch/run_table.h"
#include "config/config.h"
#include "plant/plant.h"

namespace simbot::batch {

struct TournamentConfig {
  std::vector<std::string> programs;
  int rounds = 2;
  std::optional<double> seconds;  // round length; none: the profile's [match] round_length
  uint64_t masterSeed = 1;
  int threads = 0;
  bool progress = true;
  // Thesis Appendix A, "you will be allowed to reload if the system
  // crashes": a faulted program restarts after the profile's
  // [match] reload_delay (scheduler::MatchConfig::reloadOnFault).
  bool reloadOnFault = false;
};

struct TournamentGame {
  int i = 0, j = 0, round = 0;  // the pair (i < j) and the round number
  int a = 0, b = 0;             // program indices playing as A and B
  uint64_t seed = 0;            // streamSeed(master, "tournament/<i>/<j>/<round>")
  bool done = false;            // played, now or in the batch this one resumes
  int hitsA = 0, hitsB = 0;
  int winner = 0;  // program index
  bool coin = false;
  // One line each on what faulted (empty: nothing): robot A, robot B, the
  // plant or simbot itself ("error: ...", a game that could not be played:
  // it counts as a loss for neither and is not in the standings).
  std::string faultA, faultB, plantFault;
  int reloadsA = 0, reloadsB = 0;  // --reload-on-fault
};

struct Standing {
  int program = 0;
  int played = 0, wins = 0, losses = 0, hitsFor = 0, hitsAgainst = 0, points = 0;
  int faulted = 0;  // games in which the program faulted
};

struct TournamentResult {
  TournamentConfig config;
  std::vector<TournamentGame> games;  // pair by pair, round by round
  std::vector<Standing> standings;    // ranked, from the games played
  bool stopped = false;               // a signal stopped it: some games were not played
};

// UserError if the configuration cannot run.
void checkTournamentConfig(const TournamentConfig& config);
// The round length: --seconds if given, else the profile's round_length.
double roundSeconds(const TournamentConfig& config, const config::Profile& profile);
// games.csv's columns, and the settings that identify a tournament.
CsvRow tournamentHeader();
nlohmann::json tournamentSettings(const TournamentConfig& config, const config::Profile& profile);

// Plays every game not already in `table` (resume); each finished game goes
// to the table as it completes. The table begins (RunTable::begin) only
// once every program is compiled and the resumed rows are checked. `stop`
// (may be null) stops the tournament.
TournamentResult runTournament(const TournamentConfig& config, const config::Profile& profile,
                               RunTable* table = nullptr, const std::atomic<bool>* stop = nullptr);
// Rewrites games.csv in order and writes standings.json and standings.md
// beside it.
void writeTournamentOutputs(const TournamentResult& result, RunTable& table);
// One line per game with a fault (robot A, robot B, the plant).
std::string tournamentFaults(const TournamentResult& result);
std::string standingsTable(const TournamentResult& result);
nlohmann::json tournamentJson(const TournamentResult& result);

}  // namespace simbot::batch
