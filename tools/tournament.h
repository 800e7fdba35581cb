// simbot tournament: a round robin after thesis Appendix A. Every pair of
// programs plays `rounds` rounds, sides swapped each round; the most valid
// hits wins a round, a tie goes to the seeded coin (MatchResult::winner).
// Points: 1 per round won (Appendix A ranks by rounds won; it gives no
// points scheme). Standings are sorted by points, then hit difference, then
// hits for, then the order the programs were given.
#pragma once
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "plant/plant.h"

namespace simbot::tools {

struct TournamentConfig {
  std::vector<std::string> programs;
  int rounds = 2;
  double seconds = 180;
  uint64_t masterSeed = 1;
  int threads = 0;
  bool progress = true;
};

struct TournamentGame {
  int i = 0, j = 0, round = 0;  // the pair (i < j) and the round number
  int a = 0, b = 0;             // program indices playing as A and B
  uint64_t seed = 0;            // streamSeed(master, "tournament/<i>/<j>/<round>")
  int hitsA = 0, hitsB = 0;
  int winner = 0;  // program index
  bool coin = false;
};

struct Standing {
  int program = 0;
  int played = 0, wins = 0, losses = 0, hitsFor = 0, hitsAgainst = 0, points = 0;
};

struct TournamentResult {
  TournamentConfig config;
  std::vector<TournamentGame> games;  // pair by pair, round by round
  std::vector<Standing> standings;    // ranked
};

TournamentResult runTournament(const TournamentConfig& config, const plant::Profile& profile);
std::string standingsTable(const TournamentResult& result);
nlohmann::json tournamentJson(const TournamentResult& result);

}  // namespace simbot::tools
