// config/sweep.cpp -- sweep files (config.h loadSweep): the grid of bench
// runs a sweep file describes, checked, and each grid point's profile (the
// sweep's profile with the point's values written into its TOML). Running
// the grid is batch/'s job (batch/sweep.cpp).
#include <fmt/format.h>
#include <toml++/toml.h>

#include <algorithm>
#include <filesystem>
#include <sstream>

#include "config/config.h"
#include "config/text.h"
#include "timebase/tick.h"

namespace simbot::config {

namespace {

namespace fs = std::filesystem;

// A profile or a profile key the sweep names that is not there: reported
// as it is, not as a grid point's error.
struct NotInTheSweep : ConfigError {
  using ConfigError::ConfigError;
};

std::string dirOf(const std::string& file) {
  const fs::path dir = fs::path(file).parent_path();
  return dir.empty() ? "." : dir.string();
}

}  // namespace

std::string sweepPath(const SweepSpec& spec, const std::string& path) {
  if (path.empty() || fs::path(path).is_absolute()) return path;
  return (fs::path(dirOf(spec.file)) / path).string();
}

std::string sweepProfilePath(const SweepSpec& spec) {
  const std::string asFile = sweepPath(spec, spec.profile);
  std::error_code ec;
  if (fs::is_regular_file(asFile, ec)) return asFile;
  if (const auto shipped = shippedProfilePath(spec.profile)) return *shipped;
  throw NotInTheSweep(fmt::format("simbot: {}: no profile '{}' (a file, or one of profiles/*.toml)",
                                  spec.file, spec.profile));
}

namespace {

std::string tomlText(const toml::node& node) {
  std::ostringstream out;
  node.visit([&out](const auto& n) { out << n; });
  return out.str();
}

std::vector<std::string> stringArray(const SweepSpec& spec, const toml::table& doc, const char* key,
                                     bool required) {
  std::vector<std::string> out;
  const toml::node* node = doc.get(key);
  if (!node) {
    if (required) failAt(spec.file, doc.source(), fmt::format("missing key '{}'", key));
    return out;
  }
  const toml::array* array = node->as_array();
  if (!array || array->empty())
    failAt(spec.file, node->source(), fmt::format("'{}' must be a list of strings", key));
  for (const toml::node& e : *array) {
    const auto s = e.value<std::string>();
    if (!s || !e.is_string())
      failAt(spec.file, e.source(), fmt::format("'{}' must be a list of strings", key));
    out.push_back(*s);
  }
  return out;
}

}  // namespace

std::vector<size_t> sweepPointValues(const SweepSpec& spec, size_t point) {
  std::vector<size_t> at(spec.grid.size());
  for (size_t k = spec.grid.size(); k-- > 0;) {
    at[k] = point % spec.grid[k].second.size();
    point /= spec.grid[k].second.size();
  }
  return at;
}

namespace {

size_t saturatingProduct(size_t a, size_t b) {
  size_t product = 0;
  return __builtin_mul_overflow(a, b, &product) ? SIZE_MAX : product;
}

// Grid point `point`'s profile from the sweep profile's parsed text.
Profile pointProfile(const SweepSpec& spec, const std::string& base, toml::table doc,
                     size_t point) {
  const std::vector<size_t> at = sweepPointValues(spec, point);
  for (size_t k = 0; k < spec.grid.size(); ++k) {
    const std::string& key = spec.grid[k].first;
    const auto dot = key.find('.');
    toml::table* section = doc.get_as<toml::table>(key.substr(0, dot));
    toml::node* entry = section ? section->get(key.substr(dot + 1)) : nullptr;
    if (!entry)
      throw NotInTheSweep(
          fmt::format("simbot: {}: no profile key '{}' in {}", spec.file, key, base));
    const toml::table value = toml::parse("v = " + spec.grid[k].second[at[k]]);
    if (toml::table* described = entry->as_table())
      described->insert_or_assign("value", *value.get("v"));
    else
      section->insert_or_assign(key.substr(dot + 1), *value.get("v"));
  }
  std::ostringstream text;
  text << doc;
  return parseProfile(text.str(), fmt::format("{} (grid point {} of {})", base, point, spec.file));
}

// Every point's profile, the sweep profile read and parsed once.
std::vector<Profile> pointProfiles(const SweepSpec& spec) {
  const std::string base = sweepProfilePath(spec);
  const std::string text = readFile(base);
  toml::table doc;
  try {
    checkTomlText(text, base);
    doc = toml::parse(text, base);
  } catch (const toml::parse_error& e) {
    // The profile's own checker words the error (FILE:LINE:COL).
    return {parseProfile(text, base)};
  }
  std::vector<Profile> out;
  const size_t points = sweepPoints(spec);
  out.reserve(points);
  for (size_t point = 0; point < points; ++point) {
    try {
      out.push_back(pointProfile(spec, base, doc, point));
    } catch (const NotInTheSweep&) {
      throw;
    } catch (const ConfigError& e) {
      if (spec.grid.empty()) throw;
      // The profile checker's words, without its FILE:LINE:COL (the
      // profile as rewritten for this point).
      std::string what = e.what();
      const auto at = what.find("error: ");
      if (at != std::string::npos) what = what.substr(at + 7);
      throw ConfigError(spec.file, 1, 1, fmt::format("grid point {}: {}", point, what));
    }
  }
  return out;
}

}  // namespace

size_t sweepPoints(const SweepSpec& spec) {
  size_t n = 1;
  for (const auto& [key, values] : spec.grid) n = saturatingProduct(n, values.size());
  return n;
}

Profile sweepProfile(const SweepSpec& spec, size_t point) {
  Profile p =
      point < spec.pointProfiles.size() ? spec.pointProfiles[point] : pointProfiles(spec).at(point);
  if (spec.rules.present) applyRules(spec.rules, p);
  return p;
}

SweepSpec loadSweep(const std::string& path, const std::vector<std::string>& families) {
  SweepSpec spec;
  spec.file = path;
  toml::table doc = parseToml(readFile(path), path);
  for (auto&& [key, node] : doc) {
    static const std::vector<std::string> known = {"programs", "opponents", "families", "seeds",
                                                   "seconds",  "profile",   "rules",    "grid"};
    if (std::find(known.begin(), known.end(), std::string(key.str())) == known.end())
      failAt(
          path, key.source(),
          fmt::format("unknown key '{}' (programs, opponents, families, seeds, seconds, profile, "
                      "rules, grid)",
                      key.str()));
  }
  spec.programs = stringArray(spec, doc, "programs", true);
  spec.opponents = stringArray(spec, doc, "opponents", false);
  spec.families = stringArray(spec, doc, "families", true);
  for (const auto& f : spec.families)
    if (std::find(families.begin(), families.end(), f) == families.end())
      failAt(path, doc.get("families")->source(),
             fmt::format("unknown family '{}' (stationary, circle, head-to-head, edge)", f));
  const bool headToHead =
      std::find(spec.families.begin(), spec.families.end(), "head-to-head") != spec.families.end();
  if (headToHead && spec.opponents.empty())
    failAt(path, doc.get("families")->source(), "the head-to-head family needs 'opponents'");
  if (!headToHead && !spec.opponents.empty())
    failAt(path, doc.get("opponents")->source(),
           "'opponents' play only in the head-to-head family");
  std::error_code ec;
  for (const auto* list : {&spec.programs, &spec.opponents})
    for (const auto& p : *list)
      if (!fs::is_regular_file(sweepPath(spec, p), ec))
        throw ConfigError(fmt::format("simbot: {}: no such program '{}'", path, p));
  // Written as a time; kept in seconds for the bench it configures (a
  // whole number of ticks, so the bench's tick is this one).
  if (const toml::node* s = doc.get("seconds"))
    spec.seconds = timebase::secondsFromTicks(timeValue(*s, path, "seconds", true));
  if (const toml::node* p = doc.get("profile")) {
    if (!p->is_string()) failAt(path, p->source(), "'profile' is a string");
    spec.profile = *p->value<std::string>();
  }
  if (const toml::node* r = doc.get("rules")) {
    if (!r->is_string()) failAt(path, r->source(), "'rules' is a string");
    const std::string name = *r->value<std::string>();
    const std::string asFile = sweepPath(spec, name);
    std::error_code exists;
    if (fs::is_regular_file(asFile, exists))
      spec.rules = loadRules(asFile);
    else if (const auto shipped = shippedRulesPath(name))
      spec.rules = loadRules(*shipped);
    else
      failAt(path, r->source(),
             fmt::format("'rules': no rule set '{}' (a file, or one of rules/*.toml)", name));
  }
  const toml::table* seeds = doc.get_as<toml::table>("seeds");
  if (!seeds) failAt(path, doc.source(), "missing table [seeds] (first, count)");
  for (auto&& [key, node] : *seeds) {
    const bool first = key.str() == "first";
    bool ok = false;
    uint64_t value = 0;
    if (first) {
      const std::optional<uint64_t> seed = seedValue(node);
      ok = seed.has_value();
      value = seed.value_or(0);
    } else if (key.str() == "count" && node.is_integer()) {
      const int64_t n = node.value_or<int64_t>(0);
      ok = n >= 1 && n <= 1'000'000;
      value = static_cast<uint64_t>(n);
    }
    if (!ok)
      failAt(path, node.source(),
             "[seeds] holds first (an integer >= 0, or a string of digits up to 2^64 - 1) and "
             "count (an integer from 1 to 1000000)");
    (first ? spec.firstSeed : spec.seedCount) = value;
  }
  if (spec.seedCount - 1 > UINT64_MAX - spec.firstSeed)
    failAt(path, seeds->source(), "[seeds] first + count - 1 is past 2^64 - 1, the last seed");
  if (const toml::node* g = doc.get("grid")) {
    const toml::table* grid = g->as_table();
    if (!grid) failAt(path, g->source(), "'grid' is a table");
    for (auto&& [key, node] : *grid) {
      const toml::array* values = node.as_array();
      const std::string name(key.str());
      if (name.find('.') == std::string::npos || !values || values->empty())
        failAt(path, node.source(),
               "a grid entry is \"section.key\" = [values...] (a key of the profile)");
      std::vector<std::string> texts;
      for (const toml::node& v : *values) texts.push_back(tomlText(v));
      spec.grid.emplace_back(name, std::move(texts));
    }
    if (sweepPoints(spec) > kMaxSweepPoints)
      failAt(path, g->source(), fmt::format("the grid has more than {} points", kMaxSweepPoints));
  }
  size_t pairs = 0;
  for (const auto& f : spec.families) pairs += f == "head-to-head" ? spec.opponents.size() : 1;
  const size_t runs = saturatingProduct(
      saturatingProduct(saturatingProduct(sweepPoints(spec), spec.programs.size()), pairs),
      static_cast<size_t>(spec.seedCount));
  if (runs > kMaxSweepRuns)
    failAt(path, doc.source(),
           fmt::format("the sweep describes {} runs, more than the {} a sweep may have: split "
                       "it into several files",
                       runs == SIZE_MAX ? "over 2^64" : fmt::format("{}", runs), kMaxSweepRuns));
  // Every point's profile now: a bad value is an error before any run.
  try {
    spec.pointProfiles = pointProfiles(spec);
    // And under the rules (a field the rules make smaller, ...).
    if (spec.rules.present)
      for (size_t point = 0; point < spec.pointProfiles.size(); ++point) sweepProfile(spec, point);
  } catch (const ConfigError& e) {
    const std::string what = e.what();
    if (const toml::node* g = doc.get("grid"); g && what.rfind(spec.file + ":1:1: ", 0) == 0)
      failAt(path, g->source(), what.substr(what.find("error: ") + 7));
    throw;
  }
  return spec;
}

}  // namespace simbot::config
