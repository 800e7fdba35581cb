// config/expectations.cpp -- expectations files (config.h loadExpectations):
// what `simbot check` runs and what it judges (docs/check.md).
//
//   seconds  = 60                       # each run's length (a written time)
//   seed     = [1, 2, 3]                # or one seed
//   opponent = "../programs/x.dc"       # or "stationary:8ft", or "none"
//   rules    = "se3015-1997w"           # optional; profile likewise
//   [[check]]
//   name = "..."                        # and exactly one of:
//   no_fault = true | hits_at_least = N | shots_at_most = N |
//   no_scatter_shot = true | no_overwritten_send = true | frames_at_least = N |
//   after = { record = KIND, FIELD = VALUE, ... }, within_s = S,
//   expect = { record = KIND, FIELD = VALUE, ... }
//
// Record kinds and their fields are trace/records.def's, checked here so
// that a misspelt field is an error at its line, not a step that never
// triggers.
#include <fmt/format.h>
#include <toml++/toml.h>

#include <filesystem>

#include "config/config.h"
#include "config/text.h"
#include "timebase/tick.h"
#include "trace/trace.h"

namespace simbot::config {

namespace {

namespace fs = std::filesystem;

class ExpectationsReader {
 public:
  explicit ExpectationsReader(std::string file) : file_(std::move(file)) {}

  Expectations read(const toml::table& root) {
    Expectations e;
    e.file = file_;
    onlyKeys(root, file_, "an expectations file",
             {"seconds", "seed", "opponent", "profile", "rules", "check"});
    e.length = timebase::ticksFromSeconds(60);
    if (const toml::node* n = root.get("seconds")) e.length = timeValue(*n, file_, "seconds", true);
    readSeeds(root, e);
    readOpponent(root, e);
    if (const toml::node* n = root.get("profile")) e.profile = pathOrName(*n, "profile");
    if (const toml::node* n = root.get("rules")) e.rules = pathOrName(*n, "rules");
    const toml::node* checks = root.get("check");
    if (!checks) failAt(file_, root.source(), "no [[check]]: nothing to check");
    const toml::array* list = checks->as_array();
    if (!list || !list->is_array_of_tables())
      failAt(file_, checks->source(), "'check' is an array of tables: write [[check]]");
    if (list->size() > kMaxChecks)
      failAt(file_, checks->source(), fmt::format("at most {} checks", kMaxChecks));
    for (const toml::node& node : *list) e.checks.push_back(readCheck(*node.as_table(), e));
    return e;
  }

 private:
  void readSeeds(const toml::table& root, Expectations& e) {
    const toml::node* n = root.get("seed");
    if (!n) {
      e.seeds = {1};
      return;
    }
    const auto one = [&](const toml::node& s) {
      const std::optional<std::uint64_t> seed = seedValue(s);
      if (!seed)
        failAt(file_, s.source(),
               "a seed is an integer >= 0, or a string of digits up to 2^64 - 1");
      return *seed;
    };
    if (const toml::array* list = n->as_array()) {
      if (list->empty()) failAt(file_, n->source(), "'seed' lists no seed");
      if (list->size() > kMaxCheckSeeds)
        failAt(file_, n->source(), fmt::format("at most {} seeds", kMaxCheckSeeds));
      for (const toml::node& s : *list) e.seeds.push_back(one(s));
    } else {
      e.seeds = {one(*n)};
    }
  }

  void readOpponent(const toml::table& root, Expectations& e) {
    const toml::node* n = root.get("opponent");
    if (!n) return;  // none
    if (!n->is_string()) failAt(file_, n->source(), "'opponent' is a string");
    const std::string text = *n->value<std::string>();
    if (text == "none") return;
    if (text.starts_with("stationary:")) {
      const std::string range = text.substr(11);
      double ft = 0;
      std::size_t used = 0;
      try {
        ft = std::stod(range, &used);
      } catch (const std::exception&) {
        used = 0;
      }
      if (used == 0 || range.substr(used) != "ft" || !(ft >= 1.5 && ft <= 20))
        failAt(file_, n->source(),
               fmt::format("'{}': a stationary opponent is \"stationary:Nft\", N from 1.5 to 20",
                           text));
      e.opponent = Expectations::Opponent::Stationary;
      e.stationaryFt = ft;
      return;
    }
    e.opponent = Expectations::Opponent::Program;
    e.opponentProgram = relative(text);
    std::error_code ec;
    if (!fs::is_regular_file(e.opponentProgram, ec))
      failAt(file_, n->source(),
             fmt::format("'opponent': no program '{}' (a path from this file's directory, "
                         "\"stationary:Nft\" or \"none\")",
                         text));
  }

  // A profile or rule set: a file beside this one if there is one, else a
  // shipped one's name (runs/ resolves names).
  std::string pathOrName(const toml::node& n, const char* key) {
    if (!n.is_string()) failAt(file_, n.source(), fmt::format("'{}' is a string", key));
    const std::string text = *n.value<std::string>();
    std::error_code ec;
    const std::string asFile = relative(text);
    return fs::is_regular_file(asFile, ec) ? asFile : text;
  }

  std::string relative(const std::string& path) const {
    if (path.empty() || fs::path(path).is_absolute()) return path;
    const fs::path dir = fs::path(file_).parent_path();
    return ((dir.empty() ? fs::path(".") : dir) / path).string();
  }

  Check readCheck(const toml::table& t, const Expectations& e) {
    Check c;
    c.pos = {static_cast<int>(t.source().begin.line), static_cast<int>(t.source().begin.column)};
    onlyKeys(t, file_, "a [[check]]",
             {"name", "no_fault", "hits_at_least", "shots_at_most", "no_scatter_shot",
              "no_overwritten_send", "frames_at_least", "after", "within_s", "expect"});
    const toml::node* name = t.get("name");
    if (!name || !name->is_string() || name->value<std::string>()->empty())
      failAt(file_, name ? name->source() : t.source(), "a [[check]] needs a name (a string)");
    c.name = *name->value<std::string>();
    struct Kind {
      const char* key;
      CheckKind kind;
      bool count;
    };
    static constexpr Kind kKinds[] = {
        {"no_fault", CheckKind::NoFault, false},
        {"hits_at_least", CheckKind::HitsAtLeast, true},
        {"shots_at_most", CheckKind::ShotsAtMost, true},
        {"no_scatter_shot", CheckKind::NoScatterShot, false},
        {"no_overwritten_send", CheckKind::NoOverwrittenSend, false},
        {"frames_at_least", CheckKind::FramesAtLeast, true},
        {"after", CheckKind::Step, false},
    };
    int kinds = 0;
    for (const Kind& k : kKinds) {
      const toml::node* n = t.get(k.key);
      if (!n) continue;
      ++kinds;
      c.kind = k.kind;
      if (k.kind == CheckKind::Step) continue;
      if (k.count) {
        if (!n->is_integer() || n->value_or<std::int64_t>(-1) < 0 ||
            n->value_or<std::int64_t>(-1) > 1'000'000)
          failAt(file_, n->source(), fmt::format("'{}' is an integer from 0 to 1000000", k.key));
        c.count = n->value_or<std::int64_t>(0);
      } else if (!n->is_boolean() || !n->value_or(false)) {
        failAt(file_, n->source(), fmt::format("'{}' is written '{} = true'", k.key, k.key));
      }
    }
    if (kinds != 1)
      failAt(file_, t.source(),
             fmt::format("check '{}' needs exactly one of no_fault, hits_at_least, "
                         "shots_at_most, no_scatter_shot, no_overwritten_send, "
                         "frames_at_least or after/within_s/expect",
                         c.name));
    if (c.kind == CheckKind::NoScatterShot && !e.rules)
      failAt(file_, t.get("no_scatter_shot")->source(),
             "'no_scatter_shot' needs 'rules': only a rule set judges Detect to Engage");
    if (c.kind == CheckKind::Step) {
      const toml::node* within = t.get("within_s");
      const toml::node* expect = t.get("expect");
      if (!within || !expect)
        failAt(file_, t.source(),
               fmt::format("check '{}': a step has after, within_s and expect", c.name));
      c.after = readPattern(*t.get("after"), "after");
      c.expect = readPattern(*expect, "expect");
      c.within = timeValue(*within, file_, "within_s", true);
    } else {
      for (const char* key : {"within_s", "expect"})
        if (const toml::node* n = t.get(key))
          failAt(file_, n->source(), fmt::format("'{}' belongs to a step (with 'after')", key));
    }
    return c;
  }

  RecordPattern readPattern(const toml::node& n, const char* key) {
    const toml::table* t = n.as_table();
    if (!t)
      failAt(
          file_, n.source(),
          fmt::format("'{}' is an inline table: {{ record = \"KIND\", FIELD = VALUE, ... }}", key));
    RecordPattern p;
    const toml::node* record = t->get("record");
    if (!record || !record->is_string())
      failAt(file_, n.source(), fmt::format("'{}' needs record = \"KIND\"", key));
    p.kind = *record->value<std::string>();
    const int index = trace::kindIndex(p.kind);
    if (index < 0)
      failAt(file_, record->source(),
             fmt::format("no record kind '{}' (docs/trace.md lists them)", p.kind));
    const trace::KindInfo& info = trace::kinds()[static_cast<std::size_t>(index)];
    for (auto&& [field, value] : *t) {
      if (field.str() == "record") continue;
      const trace::FieldInfo* f = nullptr;
      for (const trace::FieldInfo& candidate : info.fields)
        if (field.str() == candidate.name) f = &candidate;
      if (!f) {
        std::string names;
        for (const trace::FieldInfo& candidate : info.fields)
          names += (names.empty() ? "" : ", ") + std::string(candidate.name);
        failAt(file_, field.source(),
               fmt::format("a {} record has no field '{}' (it has {})", p.kind, field.str(),
                           names.empty() ? "none" : names));
      }
      p.fields.push_back({std::string(field.str()), fieldValue(*f, value)});
    }
    return p;
  }

  // A field's value as the record's JSONL line has it.
  decltype(RecordPattern::Field::value) fieldValue(const trace::FieldInfo& f, const toml::node& v) {
    using K = trace::FieldKind;
    const auto wrong = [&](const char* what) -> decltype(RecordPattern::Field::value) {
      failAt(file_, v.source(), fmt::format("'{}' is {}", f.name, what));
    };
    switch (f.kind) {
      case K::Robot:
        if (v.is_string() && (*v.value<std::string>() == "A" || *v.value<std::string>() == "B"))
          return *v.value<std::string>();
        return wrong("a robot: \"A\" or \"B\"");
      case K::Int:
      case K::OptInt:
        if (v.is_integer()) return *v.value<std::int64_t>();
        return wrong("an integer");
      case K::Real:
      case K::OptReal:
        if (v.is_integer()) return static_cast<double>(*v.value<std::int64_t>());
        if (v.is_floating_point()) return *v.value<double>();
        return wrong("a number");
      case K::Bool:
        if (v.is_boolean()) return *v.value<bool>();
        return wrong("true or false");
      case K::Text:
      case K::Bytes:
        if (v.is_string()) return *v.value<std::string>();
        return wrong("a string");
      case K::Reals:
        break;
    }
    return wrong("a list of numbers, which a check cannot compare");
  }

  std::string file_;
};

}  // namespace

Expectations loadExpectations(const std::string& path) {
  const std::string text = readFile(path);
  const toml::table root = parseToml(text, path);
  return ExpectationsReader(path).read(root);
}

}  // namespace simbot::config
