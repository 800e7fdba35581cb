// simbot tournament (tournament.h).
#include "batch/tournament.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <stdexcept>

#include "batch/parallel.h"
#include "config/config.h"
#include "runs/play.h"
#include "scheduler/match.h"
#include "sinks/json_text.h"
#include "sinks/user_error.h"
#include "timebase/written.h"

namespace simbot::batch {

CsvRow tournamentHeader() {
  return {"pair_i",
          "pair_j",
          "round",
          "a",
          "b",
          "seed",
          "hits_a",
          "hits_b",
          "winner",
          "winner_side",
          "tie_broken_by_coin",
          "fault_a",
          "fault_b",
          "plant_fault",
          "reloads_a",
          "reloads_b"};
}

nlohmann::json tournamentSettings(const TournamentConfig& c, const config::Profile& profile) {
  return {{"command", "tournament"},
          {"programs", c.programs},
          {"rounds", c.rounds},
          {"seconds", roundSeconds(c, profile)},
          {"master_seed", c.masterSeed},
          {"profile", profile.name},
          {"profile_file", profile.file},
          {"reload_on_fault", c.reloadOnFault},
          {"reload_delay_s", profile.reload_delay_s},
          {"contents", inputContents([&] {
             std::vector<std::string> paths = c.programs;
             paths.push_back(profile.file);
             if (profile.course.present) paths.push_back(profile.course.file);
             return paths;
           }())}};
}

namespace {

// a, b and winner are the programs' names as given; pair_i and pair_j their
// places in the list (from 0); winner_side says which robot won (A or B).
CsvRow gameRow(const TournamentGame& g, const std::vector<std::string>& programs) {
  const auto name = [&](int p) { return programs[static_cast<size_t>(p)]; };
  return {std::to_string(g.i),
          std::to_string(g.j),
          std::to_string(g.round),
          name(g.a),
          name(g.b),
          std::to_string(g.seed),
          std::to_string(g.hitsA),
          std::to_string(g.hitsB),
          name(g.winner),
          g.winner == g.a ? "A" : "B",
          g.coin ? "1" : "0",
          g.faultA,
          g.faultB,
          g.plantFault,
          std::to_string(g.reloadsA),
          std::to_string(g.reloadsB)};
}

// A row of games.csv that is not one of this tournament's games.
struct NotThisTournament : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// The game a row of games.csv records; sides and winner are checked against
// the pair and round (the names must be the programs this tournament plays).
TournamentGame gameFromRow(const CsvRow& r, const std::vector<std::string>& programs) {
  TournamentGame g;
  g.i = std::stoi(r.at(0));
  g.j = std::stoi(r.at(1));
  g.round = std::stoi(r.at(2));
  const int n = static_cast<int>(programs.size());
  if (g.i < 0 || g.j <= g.i || g.j >= n || g.round < 0)
    throw NotThisTournament(
        fmt::format("pair {}-{} is not one of this tournament's {} programs' "
                    "pairs",
                    g.i, g.j, n));
  g.a = g.round % 2 == 0 ? g.i : g.j;
  g.b = g.round % 2 == 0 ? g.j : g.i;
  for (const auto& [field, side] : {std::pair{3, g.a}, std::pair{4, g.b}})
    if (r.at(static_cast<size_t>(field)) != programs[static_cast<size_t>(side)])
      throw NotThisTournament(fmt::format(
          "pair {}-{} round {} has '{}' as robot {}, but this tournament plays '{}' there", g.i,
          g.j, g.round, r.at(static_cast<size_t>(field)), field == 3 ? "A" : "B",
          programs[static_cast<size_t>(side)]));
  g.seed = std::stoull(r.at(5));
  g.hitsA = std::stoi(r.at(6));
  g.hitsB = std::stoi(r.at(7));
  if (r.at(9) != "A" && r.at(9) != "B") throw std::out_of_range("winner_side");
  g.winner = r.at(9) == "A" ? g.a : g.b;
  if (r.at(8) != programs[static_cast<size_t>(g.winner)]) throw std::out_of_range("winner");
  g.coin = r.at(10) == "1";
  g.faultA = r.at(11);
  g.faultB = r.at(12);
  g.plantFault = r.at(13);
  g.reloadsA = std::stoi(r.at(14));
  g.reloadsB = std::stoi(r.at(15));
  g.done = true;
  return g;
}

// Every fault of the robot in the game, in one line ("" if none).
std::string robotFault(const scheduler::RobotResult& r) {
  std::string out;
  for (size_t k = 0; k < r.faults.size(); ++k) {
    const auto& f = r.faults[k];
    out += fmt::format("{}faulted at {:.6f} s, line {}: {}{}", out.empty() ? "" : "; ", f.timeS,
                       f.line, f.message, k < static_cast<size_t>(r.reloads) ? " (reloaded)" : "");
  }
  return out;
}

bool played(const TournamentGame& g) { return g.done && g.plantFault.rfind("error: ", 0) != 0; }

}  // namespace

void checkTournamentConfig(const TournamentConfig& config) {
  if (config.programs.size() < 2)
    throw sinks::UserError("simbot: a tournament needs two programs\n");
  if (config.rounds <= 0) throw sinks::UserError("simbot: --rounds must be positive\n");
  try {  // read by the one grammar already, except from a caller that set it
    if (config.seconds) timebase::runLengthFromSeconds(*config.seconds);
  } catch (const timebase::TimeError& e) {
    throw sinks::UserError(fmt::format("simbot: --seconds: {}\n", e.what()));
  }
}

double roundSeconds(const TournamentConfig& config, const config::Profile& profile) {
  return config.seconds.value_or(profile.round_length_s);
}

TournamentResult runTournament(const TournamentConfig& config, const config::Profile& profile,
                               RunTable* table, const std::atomic<bool>* stop) {
  checkTournamentConfig(config);
  std::vector<vm::Image> images;
  for (const auto& p : config.programs) images.push_back(runs::compileProgramFile(p));

  TournamentResult result;
  result.config = config;
  result.config.seconds = roundSeconds(config, profile);
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
  // Games an earlier, interrupted tournament played (--resume): each must
  // be one of this tournament's games (its programs and seed), once.
  if (table) {
    for (const PreviousRow& row : table->previous()) {
      const std::string where = table->where(row.line);
      TournamentGame g;
      try {
        g = gameFromRow(row.fields, config.programs);
      } catch (const NotThisTournament& e) {
        throw sinks::UserError(fmt::format("simbot: --resume: {}: {}\n", where, e.what()));
      } catch (const std::exception&) {
        throw sinks::UserError(fmt::format("simbot: --resume: {}: a malformed row\n", where));
      }
      const auto at = std::find_if(result.games.begin(), result.games.end(), [&](const auto& x) {
        return x.i == g.i && x.j == g.j && x.round == g.round;
      });
      if (at == result.games.end())
        throw sinks::UserError(fmt::format(
            "simbot: --resume: {}: pair {}-{} round {} is not one of this tournament's games\n",
            where, g.i, g.j, g.round));
      if (at->seed != g.seed)
        throw sinks::UserError(fmt::format(
            "simbot: --resume: {}: pair {}-{} round {} has seed {}, but this tournament's has "
            "seed {} (a row from another batch)\n",
            where, g.i, g.j, g.round, g.seed, at->seed));
      if (at->done)
        throw sinks::UserError(
            fmt::format("simbot: --resume: {}: pair {}-{} round {} is there twice\n", where, g.i,
                        g.j, g.round));
      *at = g;
    }
    // Inputs compiled, rows checked: only now does the folder change.
    table->begin();
  }
  std::vector<size_t> todo;
  for (size_t k = 0; k < result.games.size(); ++k)
    if (!result.games[k].done) todo.push_back(k);
  const scheduler::Tick endTick = timebase::ticksFromSeconds(*result.config.seconds);
  auto job = [&](size_t k) {
    TournamentGame& g = result.games[todo[k]];
    scheduler::MatchConfig mc;
    mc.arena = config::makeArenaConfig(profile, 2);
    const auto ua = static_cast<size_t>(g.a), ub = static_cast<size_t>(g.b);
    mc.robots.push_back({"A", config.programs[ua], images[ua]});
    mc.robots.push_back({"B", config.programs[ub], images[ub]});
    for (scheduler::RobotSpec& robot : mc.robots) robot.controller = profile.controller;
    mc.endTick = endTick;
    mc.seed = g.seed;
    mc.stop = stop;
    mc.reloadOnFault = config.reloadOnFault;
    mc.reloadDelay = timebase::ticksFromSeconds(profile.reload_delay_s);
    try {
      const scheduler::MatchResult r = scheduler::runMatch(mc);
      g.hitsA = r.robots[0].hits;
      g.hitsB = r.robots[1].hits;
      g.winner = r.winner == "A" ? g.a : g.b;
      g.coin = r.tieBrokenByCoin;
      g.faultA = robotFault(r.robots[0]);
      g.faultB = robotFault(r.robots[1]);
      g.reloadsA = r.robots[0].reloads;
      g.reloadsB = r.robots[1].reloads;
      if (r.plantFault)
        g.plantFault = fmt::format("the integrator failed at {:.6f} s: {}", r.plantFault->timeS,
                                   r.plantFault->message);
    } catch (const scheduler::Stopped&) {
      return;  // abandoned: played again by --resume
    } catch (const std::exception& e) {
      g.plantFault = fmt::format("error: internal error: {}", e.what());
    }
    g.done = true;
    if (table) table->append(gameRow(g, config.programs));
  };
  parallelFor(todo.size(), config.threads, job, "tournament", config.progress, stop);
  result.stopped = std::any_of(result.games.begin(), result.games.end(),
                               [](const TournamentGame& g) { return !g.done; });

  std::vector<Standing> standings(static_cast<size_t>(n));
  for (int p = 0; p < n; ++p) standings[static_cast<size_t>(p)].program = p;
  for (const auto& g : result.games) {
    if (!played(g)) continue;
    Standing& a = standings[static_cast<size_t>(g.a)];
    Standing& b = standings[static_cast<size_t>(g.b)];
    ++a.played;
    ++b.played;
    a.hitsFor += g.hitsA;
    a.hitsAgainst += g.hitsB;
    b.hitsFor += g.hitsB;
    b.hitsAgainst += g.hitsA;
    a.faulted += !g.faultA.empty();
    b.faulted += !g.faultB.empty();
    Standing& w = g.winner == g.a ? a : b;
    Standing& l = g.winner == g.a ? b : a;
    ++w.wins;
    ++w.points;
    ++l.losses;
  }
  std::stable_sort(standings.begin(), standings.end(), [](const Standing& x, const Standing& y) {
    if (x.points != y.points) return x.points > y.points;
    const int dx = x.hitsFor - x.hitsAgainst, dy = y.hitsFor - y.hitsAgainst;
    if (dx != dy) return dx > dy;
    if (x.hitsFor != y.hitsFor) return x.hitsFor > y.hitsFor;
    return x.program < y.program;
  });
  result.standings = standings;
  return result;
}

namespace {

// A program name as a Markdown table cell: | and \ escaped, a line break
// (possible in a file name) a space.
std::string markdownCell(const std::string& text) {
  std::string out;
  for (const char ch : text) {
    if (ch == '|' || ch == '\\') out += '\\';
    out += ch == '\n' || ch == '\r' ? ' ' : ch;
  }
  return out;
}

}  // namespace

std::string standingsTable(const TournamentResult& result) {
  const auto& c = result.config;
  std::vector<std::string> names;
  size_t width = 7;
  for (const auto& s : result.standings) {
    names.push_back(markdownCell(c.programs[static_cast<size_t>(s.program)]));
    width = std::max(width, names.back().size());
  }
  // A Markdown table (GitHub's pipe tables), its columns padded so that it
  // reads as a table in a terminal too.
  std::string out = fmt::format(
      "| rank | {:<{}} | played | wins | losses | hits for | hits against | points | faulted |\n",
      "program", width);
  out += fmt::format(
      "| ---: | :{:-<{}} | -----: | ---: | -----: | -------: | -----------: | -----: | ------: |\n",
      "", width - 1);
  int rank = 0;
  for (const auto& s : result.standings) {
    out +=
        fmt::format("| {:>4} | {:<{}} | {:>6} | {:>4} | {:>6} | {:>8} | {:>12} | {:>6} | {:>7} |\n",
                    rank + 1, names[static_cast<size_t>(rank)], width, s.played, s.wins, s.losses,
                    s.hitsFor, s.hitsAgainst, s.points, s.faulted);
    ++rank;
  }
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
                         {"points", s.points},
                         {"faulted", s.faulted}});
  const auto fault = [](const std::string& f) {
    return f.empty() ? nlohmann::json(nullptr) : nlohmann::json(f);
  };
  for (const auto& g : result.games) {
    if (!g.done) continue;
    games.push_back({{"a", c.programs[static_cast<size_t>(g.a)]},
                     {"b", c.programs[static_cast<size_t>(g.b)]},
                     {"round", g.round},
                     {"seed", g.seed},
                     {"hits_a", g.hitsA},
                     {"hits_b", g.hitsB},
                     {"winner", c.programs[static_cast<size_t>(g.winner)]},
                     {"tie_broken_by_coin", g.coin},
                     {"fault_a", fault(g.faultA)},
                     {"fault_b", fault(g.faultB)},
                     {"plant_fault", fault(g.plantFault)},
                     {"reloads_a", g.reloadsA},
                     {"reloads_b", g.reloadsB}});
  }
  return {{"rounds", c.rounds},
          {"seconds", c.seconds.value_or(0)},  // runTournament always sets it
          {"master_seed", c.masterSeed},
          {"reload_on_fault", c.reloadOnFault},
          {"points", "1 per round won"},
          {"standings", standings},
          {"games", games}};
}

void writeTournamentOutputs(const TournamentResult& result, RunTable& table) {
  std::vector<CsvRow> rows;
  for (const auto& g : result.games)
    if (g.done) rows.push_back(gameRow(g, result.config.programs));
  table.rewrite(rows);
  const std::filesystem::path dir = table.dir();
  writeFileAtomically((dir / "standings.json").string(),
                      sinks::dumpJson(tournamentJson(result), 2) + "\n");
  writeFileAtomically((dir / "standings.md").string(), standingsTable(result));
}

std::string tournamentFaults(const TournamentResult& result) {
  std::string out;
  const auto& names = result.config.programs;
  for (const auto& g : result.games) {
    if (!g.done) continue;
    const std::string game = fmt::format("{} vs {}, round {}", names[static_cast<size_t>(g.a)],
                                         names[static_cast<size_t>(g.b)], g.round + 1);
    if (!g.faultA.empty())
      out += fmt::format("simbot: tournament: {}: robot A ({}) {}\n", game,
                         names[static_cast<size_t>(g.a)], g.faultA);
    if (!g.faultB.empty())
      out += fmt::format("simbot: tournament: {}: robot B ({}) {}\n", game,
                         names[static_cast<size_t>(g.b)], g.faultB);
    if (!g.plantFault.empty())
      out += fmt::format("simbot: tournament: {}: {}\n", game, g.plantFault);
  }
  return out;
}

}  // namespace simbot::batch
