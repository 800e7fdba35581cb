// simbot hardware [FILE] [--profile P] [--json]: every value a hardware
// file may set for one robot, with its units, valid range and source
// (config::hardwareKeys), and FILE checked by the loader of --hw. A form
// that edits a robot's values (issue 41) reads the JSON.
#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "cli/commands.h"
#include "config/config.h"
#include "config/hardware_keys.h"
#include "runs/play.h"
#include "sinks/json_text.h"

namespace simbot::cli {
namespace {

using config::HardwareKey;
using nlohmann::json;

const char* presenceName(HardwareKey::Presence p) {
  switch (p) {
    case HardwareKey::Presence::Required:
      return "required";
    case HardwareKey::Presence::OptionalSection:
      return "optional_section";
    case HardwareKey::Presence::Optional:
      return "optional";
  }
  return "";
}

const char* fromName(HardwareKey::From f) {
  switch (f) {
    case HardwareKey::From::Profile:
      return "profile";
    case HardwareKey::From::Hardware:
      return "hardware";
    case HardwareKey::From::BuiltIn:
      return "built-in";
  }
  return "";
}

json valueJson(const config::KeyValue& v) {
  return std::visit(
      [](const auto& x) -> json {
        using T = std::decay_t<decltype(x)>;
        if constexpr (std::is_same_v<T, std::monostate>)
          return nullptr;
        else if constexpr (std::is_same_v<T, std::string>)
          return sinks::jsonString(x, false);
        else
          return x;
      },
      v);
}

std::string valueText(const config::KeyValue& v) {
  return std::visit(
      [](const auto& x) -> std::string {
        using T = std::decay_t<decltype(x)>;
        if constexpr (std::is_same_v<T, std::monostate>)
          return "-";
        else if constexpr (std::is_same_v<T, std::vector<double>>)
          return fmt::format("[{}]", fmt::join(x, ", "));
        else
          return fmt::format("{}", x);
      },
      v);
}

json rangeJson(const HardwareKey& k, double lo, double hi, const std::string& unit) {
  if (!k.ranged) return nullptr;
  const auto number = [&](double v) {
    return k.integral ? json(static_cast<std::int64_t>(v)) : json(v);
  };
  return {{"lo", number(lo)}, {"hi", number(hi)}, {"or_zero", k.orZero}, {"unit", unit}};
}

json keyJson(const HardwareKey& k) {
  const bool set = k.from != HardwareKey::From::BuiltIn;
  return {{"section", k.section},
          {"key", k.key},
          {"kind", k.kind},
          {"units", k.units},
          {"choices", k.choices},
          {"internal_unit", k.ranged ? json(k.internalUnit) : json(nullptr)},
          {"range", rangeJson(k, k.lo, k.hi, k.internalUnit)},
          {"range_shown", rangeJson(k, k.shownLo, k.shownHi, k.shownUnit)},
          {"presence", presenceName(k.presence)},
          {"from", fromName(k.from)},
          {"value", valueJson(k.value)},
          {"unit", set && !k.unit.empty() ? json(k.unit) : json(nullptr)},
          {"source", set ? json(sinks::jsonString(k.source, false)) : json(nullptr)},
          {"loaded", valueJson(k.loaded)}};
}

// The valid values as a reader takes them: "1.2 .. 60", "0 or 0.001 .. 10",
// "auto|always|never", "true|false".
std::string rangeText(const HardwareKey& k) {
  if (k.ranged) return fmt::format("{}{} .. {}", k.orZero ? "0 or " : "", k.shownLo, k.shownHi);
  if (!k.choices.empty()) return fmt::format("{}", fmt::join(k.choices, "|"));
  return "true|false";
}

// The listing as an aligned table: one row a key, the source last. A
// value longer than kWidest (a speed table) runs past its column.
std::string tableText(const std::vector<HardwareKey>& keys) {
  constexpr std::size_t kWidest = 16;
  std::vector<std::array<std::string, 7>> rows = {
      {"KEY", "VALUE", "UNIT", "VALID (UNIT)", "UNITS", "FROM", "SOURCE"}};
  for (const HardwareKey& k : keys) {
    const bool set = k.from != HardwareKey::From::BuiltIn;
    rows.push_back({k.section + "." + k.key, set ? valueText(k.value) : valueText(k.loaded),
                    k.ranged ? k.shownUnit : "", rangeText(k),
                    fmt::format("{}", fmt::join(k.units, ",")), fromName(k.from),
                    set ? k.source : "-"});
  }
  std::array<std::size_t, 7> width{};
  for (const auto& row : rows)
    for (std::size_t c = 0; c < row.size(); ++c)
      width[c] = std::max(width[c], c == 1 ? std::min(row[c].size(), kWidest) : row[c].size());
  std::string out;
  for (const auto& row : rows) {
    std::string line;
    for (std::size_t c = 0; c + 1 < row.size(); ++c) {
      line += row[c];
      line += std::string(row[c].size() < width[c] ? width[c] - row[c].size() : 0, ' ') + "  ";
    }
    out += line + row.back() + "\n";
  }
  return out;
}

}  // namespace

Subcommand addHardwareCommand(CLI::App& app) {
  struct Options {
    runs::RunOptions run;
    std::string file;
    bool json = false;
  };
  auto o = std::make_shared<Options>();
  auto* cmd = app.add_subcommand(
      "hardware",
      "the values a hardware file may set for one robot, with their units, valid ranges and "
      "sources; checks FILE with the loader --hw uses");
  cmd->add_option("FILE", o->file,
                  "a hardware file: loaded over the profile as match --hw loads it (an error is "
                  "FILE:LINE:COL, exit status 1); its values replace the profile's");
  addRunOptions(cmd, o->run, runs::kHardware);
  cmd->add_flag("--json", o->json, "print the listing as JSON");
  cmd->footer(
      "Each key a hardware file may set: the profile's per-robot keys in its order, then "
      "[ports], then [secondary]. FROM is hardware (FILE sets it), profile, or built-in: "
      "neither sets it ([ports] bits, [secondary] without the table), and VALUE is the "
      "loader's built-in value, UNIT and SOURCE empty (JSON: value, unit and source null, "
      "loaded the built-in value). VALID is the range in UNIT (JSON: range in the internal "
      "unit, range_shown in the unit written). docs/plant.md has the JSON's fields.");
  return {cmd, [o] {
            return guarded([&] {
              const config::Profile profile =
                  runs::loadNamedProfile(o->run.profile.value_or("default"));
              const std::vector<HardwareKey> keys = config::hardwareKeys(profile, o->file);
              if (o->json) {
                json j = {{"profile",
                           {{"name", sinks::jsonString(profile.name, false)},
                            {"file", sinks::jsonString(profile.file, false)}}},
                          {"hardware", o->file.empty()
                                           ? json(nullptr)
                                           : json{{"file", sinks::jsonString(o->file, false)}}},
                          {"keys", json::array()}};
                for (const HardwareKey& k : keys) j["keys"].push_back(keyJson(k));
                std::cout << sinks::dumpJson(j, 2) << '\n';
                return 0;
              }
              std::cout << fmt::format("profile {} ({}){}\n\n", profile.name, profile.file,
                                       o->file.empty() ? "" : "; hardware file " + o->file);
              std::cout << tableText(keys);
              return 0;
            });
          }};
}

}  // namespace simbot::cli
