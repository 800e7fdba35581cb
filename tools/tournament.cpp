// simbot tournament (tournament.h).
#include "tools/tournament.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "scheduler/match.h"
#include "tools/runner.h"

namespace simbot::tools {

TournamentResult runTournament(const TournamentConfig& config, const plant::Profile& profile) {
  if (config.programs.size() < 2) throw ToolError("simbot: a tournament needs two programs\n");
  if (config.rounds <= 0) throw ToolError("simbot: --rounds must be positive\n");
  if (!(config.seconds > 0) || config.seconds > 1e6)
    throw ToolError(fmt::format("simbot: --seconds must be in (0, 1e6], got {}\n", config.seconds));
  std::vector<vm::Image> images;
  for (const auto& p : config.programs) images.push_back(compileProgramFile(p));

  TournamentResult result;
  result.config = config;
  const int n = static_cast<int>(config.programs.size());
  for (int i = 0; i < n; ++i)
    for (int j = i + 1; j < n; ++j)
      for (int k = 0; k < config.rounds; ++k) {
        TournamentGame g;
        g.i = i;
        g.j = j;
        g.round = k;
        g.a = k % 2 == 0 ? i : j;  // sides swapped each round
        g.b = k % 2 == 0 ? j : i;
        g.seed =
            scheduler::streamSeed(config.masterSeed, fmt::format("tournament/{}/{}/{}", i, j, k));
        result.games.push_back(g);
      }
  const auto endTick =
      static_cast<scheduler::Tick>(std::llround(config.seconds * scheduler::kTicksPerSecond));
  auto job = [&](size_t index) {
    TournamentGame& g = result.games[index];
    scheduler::MatchConfig mc;
    mc.arena = plant::makeArenaConfig(profile, 2);
    const auto ua = static_cast<size_t>(g.a), ub = static_cast<size_t>(g.b);
    mc.robots.push_back({"A", config.programs[ua], images[ua]});
    mc.robots.push_back({"B", config.programs[ub], images[ub]});
    mc.endTick = endTick;
    mc.seed = g.seed;
    const scheduler::MatchResult r = scheduler::runMatch(mc);
    g.hitsA = r.robots[0].hits;
    g.hitsB = r.robots[1].hits;
    g.winner = r.winner == "A" ? g.a : g.b;
    g.coin = r.tieBrokenByCoin;
  };
  parallelFor(result.games.size(), config.threads, job, "tournament", config.progress);

  std::vector<Standing> table(static_cast<size_t>(n));
  for (int p = 0; p < n; ++p) table[static_cast<size_t>(p)].program = p;
  for (const auto& g : result.games) {
    Standing& a = table[static_cast<size_t>(g.a)];
    Standing& b = table[static_cast<size_t>(g.b)];
    ++a.played;
    ++b.played;
    a.hitsFor += g.hitsA;
    a.hitsAgainst += g.hitsB;
    b.hitsFor += g.hitsB;
    b.hitsAgainst += g.hitsA;
    Standing& w = g.winner == g.a ? a : b;
    Standing& l = g.winner == g.a ? b : a;
    ++w.wins;
    ++w.points;
    ++l.losses;
  }
  std::stable_sort(table.begin(), table.end(), [](const Standing& x, const Standing& y) {
    if (x.points != y.points) return x.points > y.points;
    const int dx = x.hitsFor - x.hitsAgainst, dy = y.hitsFor - y.hitsAgainst;
    if (dx != dy) return dx > dy;
    if (x.hitsFor != y.hitsFor) return x.hitsFor > y.hitsFor;
    return x.program < y.program;
  });
  result.standings = table;
  return result;
}

std::string standingsTable(const TournamentResult& result) {
  const auto& c = result.config;
  size_t width = 7;
  for (const auto& p : c.programs) width = std::max(width, p.size());
  std::string out =
      fmt::format("{:>4}  {:<{}}  {:>6} {:>4} {:>6} {:>8} {:>12} {:>6}\n", "rank", "program", width,
                  "played", "wins", "losses", "hits for", "hits against", "points");
  int rank = 0;
  for (const auto& s : result.standings)
    out += fmt::format("{:>4}  {:<{}}  {:>6} {:>4} {:>6} {:>8} {:>12} {:>6}\n", ++rank,
                       c.programs[static_cast<size_t>(s.program)], width, s.played, s.wins,
                       s.losses, s.hitsFor, s.hitsAgainst, s.points);
  return out;
}

nlohmann::json tournamentJson(const TournamentResult& result) {
  const auto& c = result.config;
  nlohmann::json standings = nlohmann::json::array(), games = nlohmann::json::array();
  int rank = 0;
  for (const auto& s : result.standings)
    standings.push_back({{"rank", ++rank},
                         {"program", c.programs[static_cast<size_t>(s.program)]},
                         {"played", s.played},
                         {"wins", s.wins},
                         {"losses", s.losses},
                         {"hits_for", s.hitsFor},
                         {"hits_against", s.hitsAgainst},
                         {"points", s.points}});
  for (const auto& g : result.games)
    games.push_back({{"a", c.programs[static_cast<size_t>(g.a)]},
                     {"b", c.programs[static_cast<size_t>(g.b)]},
                     {"round", g.round},
                     {"seed", g.seed},
                     {"hits_a", g.hitsA},
                     {"hits_b", g.hitsB},
                     {"winner", c.programs[static_cast<size_t>(g.winner)]},
                     {"tie_broken_by_coin", g.coin}});
  return {{"rounds", c.rounds},          {"seconds", c.seconds},   {"master_seed", c.masterSeed},
          {"points", "1 per round won"}, {"standings", standings}, {"games", games}};
}

}  // namespace simbot::tools
