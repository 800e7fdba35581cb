// The replay viewer: one self-contained HTML page (scripts, styles, three.js
// and the run's data inlined; no network, no server) that shows a run from
// its trace: the field from above, a 3-D view with the 1997 program's six
// cameras, playback, event lanes and eye curves on one time axis, each
// robot's source with the line it is executing, and the Explain panel (the
// report of `simbot explain`, reports/explain.h).
//
// The page's data is built from the trace records alone (trace/trace.h),
// so `simbot match --replay F.html` and `simbot view TRACE.jsonl -o F.html`
// on that match's trace write the same page.
#pragma once
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "files/files.h"
#include "trace/trace.h"

namespace simbot::reports {

// Collects a run's records into the viewer's data (columns per record kind)
// and writes the page when the run ends. Its temporary file is opened now
// and renamed into place when the page is whole (files::Output).
class ReplaySink final : public trace::Sink {
 public:
  explicit ReplaySink(const std::string& path);
  ~ReplaySink() override;
  ReplaySink(const ReplaySink&) = delete;
  ReplaySink& operator=(const ReplaySink&) = delete;
  void write(const trace::Entry& entry) override;
  void close() override;
  // The page's data so far (tests).
  nlohmann::json data() const;

  struct Columns;

 private:
  std::string path_;
  std::optional<files::Output> out_;
  Columns* columns_;
};

// The page around `data` (tests; ReplaySink::close writes it).
std::string replayPage(const nlohmann::json& data);

}  // namespace simbot::reports
