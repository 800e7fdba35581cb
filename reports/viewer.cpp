// The replay page: the run's records as columns per kind, inlined in the
// viewer's template with its script, style and three.js (see viewer.h).
#include "reports/viewer.h"

#include <fmt/format.h>

#include <cerrno>
#include <cstring>
#include <optional>
#include <stdexcept>
#include <type_traits>

#include "reports/explain.h"
#include "reports/viewer_assets.h"
#include "sinks/json_text.h"
#include "sinks/user_error.h"
#include "timebase/tick.h"

namespace simbot::reports {

namespace {

using nlohmann::json;

// Replaces the one occurrence of `marker` in `page` by `text`.
void fill(std::string& page, std::string_view marker, std::string_view text) {
  const auto at = page.find(marker);
  if (at == std::string::npos || page.find(marker, at + 1) != std::string::npos)
    throw std::logic_error(fmt::format("viewer template: marker {} must occur once", marker));
  page.replace(at, marker.size(), text);
}

// Script text inlined in a <script> element must not close it early.
std::string_view script(std::string_view text, const char* what) {
  if (text.find("</script") != std::string_view::npos ||
      text.find("<!--") != std::string_view::npos)
    throw std::logic_error(fmt::format("viewer: {} cannot be inlined in a <script>", what));
  return text;
}

constexpr const char* kRobotNames[] = {"A", "B"};

// Record kinds the page's script never reads (reports/viewer/js/): left out
// of its data, so that they neither fill the page nor count toward its cap
// (--trace-costate's records, PIO and RS-485 writes, IFF1...). The Explain
// panel still sees them.
bool pageShows(std::string_view kind) {
  constexpr std::string_view kUnshown[] = {"costate",  "iff1",         "port_a",
                                           "port_b",   "rs485_enable", "contact_end",
                                           "path_leg", "disc_shooter"};
  for (const auto k : kUnshown)
    if (k == kind) return false;
  return true;
}

}  // namespace

// Columns per record kind: {"t": [...], field: [...], ...}; robot fields as
// 0/1. Watched variables from the samples, per robot and variable, as the
// ticks where the value changed and the values.
struct ReplaySink::Columns {
  json kinds = json::object();
  json watch = json::object();
  std::size_t records = 0;
  std::optional<trace::Tick> truncatedAt;  // the first record left out
  explain::Explainer explainer;            // the Explain panel: sees every record
};

ReplaySink::ReplaySink(const std::string& path) : path_(path), columns_(new Columns) {
  try {
    out_.emplace(path);
  } catch (const files::Error& e) {
    delete columns_;
    throw sinks::UserError(fmt::format("simbot: cannot write replay '{}': {}\n", path, e.what()));
  }
}

ReplaySink::~ReplaySink() { delete columns_; }

void ReplaySink::write(const trace::Entry& e) {
  columns_->explainer.write(e);
  const char* const kind = trace::kindOf(e.record).name;
  if (!pageShows(kind)) return;
  // A page is for a person to look at: beyond this many records (a program
  // flooding port B) the rest of the run is left out, and the page says so,
  // so that its memory stays bounded. The end of the run is always kept.
  constexpr std::size_t kMaxRecords = 1'000'000;
  const bool ending = std::holds_alternative<trace::rec::RobotResult>(e.record) ||
                      std::holds_alternative<trace::rec::End>(e.record);
  if (columns_->records >= kMaxRecords && !ending) {
    if (!columns_->truncatedAt) columns_->truncatedAt = e.t;
    return;
  }
  ++columns_->records;
  json& cols = columns_->kinds[kind];
  cols["t"].push_back(e.t);
  trace::forEachField(e.record, [&](const trace::FieldInfo& f, const auto& v) {
    using V = std::remove_cvref_t<decltype(v)>;
    json& col = cols[f.name];
    if constexpr (std::is_same_v<V, std::string>)
      col.push_back(sinks::jsonString(v, f.kind == trace::FieldKind::Bytes));
    else if constexpr (std::is_same_v<V, std::optional<std::int64_t>> ||
                       std::is_same_v<V, std::optional<double>>)
      col.push_back(v ? json(*v) : json(nullptr));
    else
      col.push_back(v);
  });
  if (!e.watch.empty() && std::holds_alternative<trace::rec::Sample>(e.record)) {
    const int robot = trace::robotOf(e.record);
    json& vars = columns_->watch[kRobotNames[robot & 1]];
    for (const auto& [name, value] : e.watch) {
      json& series = vars[name];
      const json v = std::visit([](const auto& x) { return json(x); }, value);
      if (series.contains("v") && !series["v"].empty() && series["v"].back() == v) continue;
      series["t"].push_back(e.t);
      series["v"].push_back(v);
    }
  }
}

json ReplaySink::data() const {
  // The Explain panel: the text report of `simbot explain`, line by line,
  // each with the tick it is about (or null).
  json report = json::array();
  for (const auto& line : explain::textLines(columns_->explainer.report()))
    report.push_back({sinks::jsonString(line.text, false), line.t ? json(*line.t) : json(nullptr)});
  return {{"format", "simbot-replay/1"},
          {"char_ticks", timebase::kTicksPerChar},
          {"explain", std::move(report)},
          {"kinds", columns_->kinds},
          {"watch", columns_->watch},
          {"truncated_at", columns_->truncatedAt ? json(*columns_->truncatedAt) : json(nullptr)}};
}

void ReplaySink::close() {
  if (!out_ || out_->committed()) return;
  const std::string page = replayPage(data());
  const bool written = std::fwrite(page.data(), 1, page.size(), out_->file()) == page.size();
  const int error = errno;
  try {
    if (!written) throw files::Error(std::strerror(error));
    out_->commit();
  } catch (const files::Error& e) {
    out_.reset();  // the temporary file goes; an old page stays
    throw sinks::UserError(fmt::format("simbot: writing replay '{}': {}\n", path_, e.what()));
  }
}

std::string replayPage(const json& data) {
  std::string text = sinks::dumpJson(data);
  // '<' only occurs inside JSON strings, where \u003c means the same: the
  // data can then never end its <script> element.
  std::string safe;
  safe.reserve(text.size() + text.size() / 64);
  for (char c : text) {
    if (c == '<')
      safe += "\\u003c";
    else
      safe.push_back(c);
  }
  std::string page(viewerHtml());
  fill(page, "/*simbot:css*/", viewerCss());
  fill(page, "/*simbot:three*/", script(threeJs(), "three.js"));
  fill(page, "/*simbot:orbit*/", script(orbitControlsJs(), "OrbitControls.js"));
  // The script's parts share one function scope, in strict mode.
  std::string viewer = "(function () {\n'use strict';\n";
  for (const auto& [name, part] : viewerScripts()) {
    viewer += fmt::format("// ---- {}\n", name);
    viewer += script(part, "the viewer's script");
    viewer += "\n";
  }
  viewer += "})();\n";
  fill(page, "/*simbot:viewer*/", viewer);
  fill(page, "/*simbot:data*/", safe);
  return page;
}

}  // namespace simbot::reports
