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
// refuses a table that another batch (or another simbot) wrote, and each
// row it keeps must be one of this batch's runs (its program and seed).
// Nothing in the output folder changes until the batch's inputs are
// compiled and checked (RunTable::begin).
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
// another 'P.dc' (its contents changed)", "was run by simbot X, not
// simbot Y".
std::string settingsChange(const nlohmann::json& earlier, const nlohmann::json& now);

// The contents of a batch's input files, for its settings: {path:
// files::fingerprint(path)}, so that --resume refuses a batch whose
// program or profile was edited in between.
nlohmann::json inputContents(const std::vector<std::string>& paths);

// One check for every batch command (bench, compare, tournament, sweep):
// UserError naming both when one of the batch's outputs is one of its
// inputs or two outputs are one file (files::checkDistinct: by device and
// inode, so "./x" and a hard link are caught), before anything is written.
void checkBatchOutputs(const std::vector<std::string>& inputs,
                       const std::vector<std::string>& outputs);

// Makes the folder `dir` (and its parents; "" is the current one) for a
// batch's outputs; UserError "cannot use 'DIR' for the outputs: REASON".
void makeOutputFolder(const std::string& dir);

// A batch's settings file (DIR/batch.json, a sweep's OUT.batch.json): what
// the batch is (its options, the fingerprints of every input in
// "contents", and "simbot", the simbot --version that began it). One
// reader and writer for every batch, local or on Dask: --resume checks it
// before anything is written; a new batch removes the old one before its
// table is replaced and writes its own after, so that a batch killed in
// between is never resumed under another's settings.
class BatchSettings {
 public:
  BatchSettings(std::string path, nlohmann::json settings, const std::string& version);
  const std::string& path() const { return path_; }
  // The files the batch reads (the keys of "contents").
  std::vector<std::string> inputs() const;
  // --resume's check: UserError "simbot: --resume: WHAT was run ..." unless
  // the file holds these settings: another simbot version first, naming
  // both, then the first other setting.
  void checkResume(const std::string& what) const;
  void remove() const;
  void write() const;

 private:
  std::string path_;
  nlohmann::json settings_;
};

// What a RunTable is: the table DIR/FILE with its header, the other
// outputs the batch writes beside it at the end, and its settings.
struct TableSpec {
  std::string dir, file;
  std::vector<std::string> summaries;  // file names in dir
  CsvRow header;
  nlohmann::json settings;  // its "contents" are the batch's inputs
  std::string version;      // simbot --version (cli::simbotVersion())
  bool resume = false;
};

// A row of an earlier, interrupted batch, with where it is: its record
// number in the table (the header is record 1).
struct PreviousRow {
  size_t line = 0;
  CsvRow fields;
};

class RunTable {
 public:
  // Checks everything and writes nothing: no output is an input, and with
  // `resume` that batch.json holds the same settings and the table's
  // complete rows (read back now; a line cut short by a kill is dropped)
  // are this header's. A batch calls begin() once its inputs are compiled
  // and the previous rows checked against it, so that a batch refused for
  // bad input leaves the folder as it was.
  explicit RunTable(TableSpec spec);
  ~RunTable();
  RunTable(const RunTable&) = delete;
  RunTable& operator=(const RunTable&) = delete;

  // Rows of the earlier, interrupted batch (resume only).
  const std::vector<PreviousRow>& previous() const { return previous_; }
  // "DIR/FILE:LINE", for a message about a previous row.
  std::string where(size_t line) const;
  // Makes the folder and opens the table: with resume, the table keeps its
  // complete rows; without, the old batch.json and summaries go, the table
  // is replaced by its header and batch.json written. UserError when the
  // location cannot be written (before any run).
  void begin();
  // Appends one finished run; safe from worker threads; flushed.
  void append(const CsvRow& row);
  // Rewrites the whole table in its final order.
  void rewrite(const std::vector<CsvRow>& rows);
  const std::string& dir() const { return spec_.dir; }

 private:
  TableSpec spec_;
  std::string path_;
  BatchSettings settings_;
  std::optional<RowFile> rows_;
  std::vector<PreviousRow> previous_;
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
