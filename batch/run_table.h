// Batch work that loses nothing (bench, tournament): each finished run is
// appended to a CSV table as it completes (a header written once, every
// line flushed, every write checked), the output location is checked
// before the first run, SIGINT and SIGTERM stop the batch cleanly, and
// --resume continues an interrupted batch from its table. At the end the
// table is rewritten in the batch's own order (through a temporary file and
// a rename), so an interrupted and resumed batch gives the very table an
// uninterrupted one gives.
//
// The batch's settings are kept beside the table (batch.json): --resume
// refuses a table that another batch wrote.
#pragma once
#include <atomic>
#include <cstdio>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

namespace simbot::batch {

using CsvRow = std::vector<std::string>;

// A CSV field (RFC 4180): quoted when it holds a comma, a quote or a line
// break, with quotes doubled.
std::string csvField(const std::string& text);
// The fields joined by commas, without a line end.
std::string csvLine(const CsvRow& fields);
// One record of a table: the line and RFC 4180's CRLF line end.
std::string csvRecord(const CsvRow& fields);
// The complete records of a table's text, without their line ends: a record
// ends at CRLF or LF outside quotes (a line break inside a quoted field
// belongs to the field); a last record with no line end (cut short by a
// kill) is left out.
std::vector<std::string> csvRecords(const std::string& text);
// One line back into fields; throws std::invalid_argument if malformed.
CsvRow parseCsvLine(const std::string& line);

// Writes `text` to `path` through `path`.tmp and a rename; UserError on any
// failure.
void writeFileAtomically(const std::string& path, const std::string& text);

// A table's file that rows are appended to, each append whole or absent:
// a write that fails (a full disk) is cut back to where it began, and from
// then on nothing more is appended (the batch stops; --resume continues).
// Safe from worker threads.
class RowFile {
 public:
  explicit RowFile(const std::string& path);  // UserError if it cannot be opened
  ~RowFile();
  RowFile(const RowFile&) = delete;
  RowFile& operator=(const RowFile&) = delete;
  // UserError "simbot: writing 'PATH': REASON; the batch stopped at once
  // ..."; false, writing nothing, once an earlier append failed.
  bool append(const std::string& rows);

 private:
  std::string path_;
  int fd_ = -1;
  bool failed_ = false;
  std::mutex mutex_;
};

// What differs between a batch's recorded settings and this one's, for
// --resume's refusal: "was run with seeds 20, not 30", "was run with
// another 'P.dc' (its contents changed)".
std::string settingsChange(const nlohmann::json& earlier, const nlohmann::json& now);

// The contents of a batch's input files, for its settings: {path:
// files::fingerprint(path)}, so that --resume refuses a batch whose
// program or profile was edited in between.
nlohmann::json inputContents(const std::vector<std::string>& paths);

// --resume's check: UserError unless `settingsPath` holds `settings`,
// naming what changed ("simbot: --resume: WHAT was run with ...").
void checkResumeSettings(const std::string& settingsPath, const nlohmann::json& settings,
                         const std::string& what);

class RunTable {
 public:
  // The table `dir`/`file` with `header`, for the batch `settings`. The
  // directory is made and the file opened now (a location that cannot be
  // written is an error before any run). Without `resume` the table starts
  // empty; with it, the complete rows already there are read back (a line
  // cut short by a kill is dropped) after checking the header and that
  // batch.json holds the same settings.
  RunTable(const std::string& dir, const std::string& file, const CsvRow& header,
           const nlohmann::json& settings, bool resume);
  ~RunTable();
  RunTable(const RunTable&) = delete;
  RunTable& operator=(const RunTable&) = delete;

  // Rows of the earlier, interrupted batch (resume only).
  const std::vector<CsvRow>& previous() const { return previous_; }
  // Appends one finished run; safe from worker threads; flushed.
  void append(const CsvRow& row);
  // Rewrites the whole table in its final order.
  void rewrite(const std::vector<CsvRow>& rows);
  const std::string& dir() const { return dir_; }

 private:
  std::string dir_, path_;
  CsvRow header_;
  std::optional<RowFile> rows_;
  std::vector<CsvRow> previous_;
};

// SIGINT and SIGTERM set `requested` while an instance lives (the previous
// handlers come back after). A batch stops taking runs and abandons those
// under way (MatchConfig::stop).
class StopOnSignals {
 public:
  StopOnSignals();
  ~StopOnSignals();
  StopOnSignals(const StopOnSignals&) = delete;
  StopOnSignals& operator=(const StopOnSignals&) = delete;
  const std::atomic<bool>& requested() const;
  int signal() const;  // the signal that stopped the batch, or 0
};

}  // namespace simbot::batch
