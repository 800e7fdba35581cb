// config/hardware_keys.cpp -- what a hardware file may set for one robot
// (config.h hardwareKeys; simbot hardware): the key table's per-robot
// keys, [ports] and [secondary], each with its units and range, its value
// as the profile or the hardware file writes it, and the value the loader
// leaves. The files are checked by their loaders first (loadProfile,
// loadHardware), so what is read here again is known to be well formed.
#include "config/hardware_keys.h"

#include <fmt/format.h>
#include <toml++/toml.h>

#include <algorithm>
#include <cstdlib>
#include <string_view>

#include "config/config.h"
#include "config/profile_keys.h"
#include "config/text.h"

namespace simbot::config {
namespace {

using keys::KeyDef;
using keys::Kind;

// The entry [section] key = { ... } of `doc`, if it is written there.
const toml::table* entryOf(const toml::table* doc, const KeyDef& def) {
  const toml::node* section = doc ? doc->get(def.section) : nullptr;
  const toml::table* table = section ? section->as_table() : nullptr;
  const toml::node* entry = table ? table->get(def.key) : nullptr;
  return entry ? entry->as_table() : nullptr;
}

// A `value` as written (the loader has checked its type).
KeyValue writtenValue(const toml::node& n) {
  if (const auto* i = n.as_integer()) return i->get();
  if (const auto* f = n.as_floating_point()) return f->get();
  if (const auto* b = n.as_boolean()) return b->get();
  if (const auto* s = n.as_string()) return s->get();
  std::vector<double> table;
  if (const auto* a = n.as_array())
    for (const toml::node& e : *a)
      table.push_back(e.as_integer() ? static_cast<double>(e.as_integer()->get())
                                     : e.value_or(0.0));
  return table;
}

template <class Words, class Value>
std::string wordOf(const Words& words, Value v) {
  for (const auto& [word, value] : words)
    if (value == v) return word;
  return "";
}

template <class Words>
std::vector<std::string> wordsOf(const Words& words) {
  std::vector<std::string> out;
  for (const auto& each : words) out.emplace_back(each.first);
  return out;
}

// What the loader left at `t`, in the internal unit.
KeyValue loadedValue(const keys::Target& t) {
  if (t.d) return *t.d;
  if (t.i) return std::int64_t{*t.i};
  if (t.b) return *t.b;
  if (t.choice) return wordOf(keys::kChoices, *t.choice);
  if (t.cpu) return wordOf(keys::kCpuChoices, *t.cpu);
  if (t.secondary) return std::string(plant::secondaryKindName(*t.secondary));
  if (t.table) return std::vector<double>(t.table->begin(), t.table->end());
  return std::monostate{};
}

double twelveDigits(double x) { return std::strtod(fmt::format("{:.12g}", x).c_str(), nullptr); }

HardwareKey::Presence presenceOf(const KeyDef& def) {
  using P = HardwareKey::Presence;
  const std::string_view section = def.section;
  if (section == "ports" || (section == "secondary" && std::string_view(def.key) == "bit"))
    return P::Optional;
  return section == "secondary" || def.optionalSection ? P::OptionalSection : P::Required;
}

}  // namespace

std::vector<HardwareKey> hardwareKeys(const Profile& profile, const std::string& hardwareFile) {
  Profile robot = profile;
  plant::Hardware hardware;
  std::optional<toml::table> hardwareDoc;
  if (!hardwareFile.empty()) {
    hardware = loadHardware(hardwareFile, robot.robot, robot.controller);
    hardwareDoc = parseToml(readFile(hardwareFile), hardwareFile);
  }
  const toml::table profileDoc = parseToml(readFile(profile.file), profile.file);

  std::vector<const KeyDef*> defs;
  for (const KeyDef& d : keys::keyTable())
    if (d.perRobot) defs.push_back(&d);
  for (const KeyDef& d : keys::portTable()) defs.push_back(&d);
  for (const KeyDef& d : keys::secondaryTable()) defs.push_back(&d);

  std::vector<HardwareKey> out;
  for (const KeyDef* def : defs) {
    HardwareKey k;
    k.section = def->section;
    k.key = def->key;
    k.kind = keys::kindName(def->kind);
    const keys::Target target = def->target(robot, hardware);
    const bool worded = def->kind == Kind::Bool || def->kind == Kind::Choice;
    if (!worded) {
      // "ft, in, m" as a list.
      const std::string_view all = keys::allowedUnits(def->kind);
      for (std::size_t at = 0; at <= all.size();) {
        const std::size_t comma = std::min(all.find(", ", at), all.size());
        k.units.emplace_back(all.substr(at, comma - at));
        at = comma + 2;
      }
      k.internalUnit = keys::internalUnit(def->kind);
      k.ranged = true;
      k.lo = def->bounds.lo;
      k.hi = def->bounds.hi;
      k.orZero = def->bounds.orZero;
      k.integral = def->kind == Kind::Count || def->kind == Kind::Step || def->kind == Kind::Bit;
    } else if (target.choice) {
      k.choices = wordsOf(keys::kChoices);
    } else if (target.cpu) {
      k.choices = wordsOf(keys::kCpuChoices);
    } else if (target.secondary) {
      k.choices = wordsOf(keys::kSecondaryChoices);
    }
    k.presence = presenceOf(*def);
    const toml::table* inHardware = entryOf(hardwareDoc ? &*hardwareDoc : nullptr, *def);
    const toml::table* entry = inHardware ? inHardware : entryOf(&profileDoc, *def);
    k.from = inHardware ? HardwareKey::From::Hardware
             : entry    ? HardwareKey::From::Profile
                        : HardwareKey::From::BuiltIn;
    if (entry) {
      if (const toml::node* value = entry->get("value")) k.value = writtenValue(*value);
      if (const toml::node* unit = entry->get("unit")) k.unit = unit->value_or(std::string());
      if (const toml::node* source = entry->get("source"))
        k.source = source->value_or(std::string());
    }
    k.loaded = loadedValue(target);
    if (k.ranged) {
      k.shownUnit = k.unit.empty() ? k.internalUnit : k.unit;
      const double factor = keys::unitFactor(def->kind, k.shownUnit);
      k.shownLo = twelveDigits(k.lo / factor);
      k.shownHi = twelveDigits(k.hi / factor);
    }
    out.push_back(std::move(k));
  }
  return out;
}

}  // namespace simbot::config
