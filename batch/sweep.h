// simbot sweep: a grid of bench runs (programs x families x opponents x
// profile parameters x seeds) from one TOML file, expanded into an ordered
// list with a stable run index. Each run is one bench run (runBench with
// one seed) and depends on its row alone, so rows are the same whoever
// runs them: the local thread pool here, a Dask cluster through the Python
// module (python/simbot/sweep.py), or a batch scheduler's array job running
// one --shard each. Rows are written in run-index order as soon as a
// prefix is complete, so an interrupted sweep keeps every row before its
// first unfinished run, and --resume continues from there.
#pragma once
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "batch/run_table.h"
#include "config/config.h"
#include "plant/plant.h"

namespace simbot::batch {

// The sweep file as config/ reads it (config.h).
using config::SweepSpec;

struct SweepRun {
  size_t index = 0;
  size_t point = 0;  // the grid point (index into the cartesian product)
  std::string program, family, opponent;
  uint64_t seed = 0;
};

// Run index = ((point x programs + program) x family/opponent pairs + pair)
// x seeds + seed: seeds vary fastest.
std::vector<SweepRun> expandSweep(const SweepSpec& spec);
CsvRow sweepHeader(const SweepSpec& spec);
// Runs one row; deterministic from the row.
CsvRow runSweepRow(const SweepSpec& spec, const SweepRun& run);
// What is wrong with `row` as the table's row of `run` ("" if nothing):
// the columns the run alone decides (run, program, family, opponent,
// master_seed, the grid values and stream_seed), for --resume.
std::string sweepRowMismatch(const SweepSpec& spec, const SweepRun& run, const CsvRow& row);

// "K/N" (1 <= K <= N) into K and N; UserError otherwise.
std::pair<size_t, size_t> parseShard(const std::string& text);
// Shard K of N holds the contiguous block of runs [begin, end): shards
// concatenated in order are the whole table.
std::pair<size_t, size_t> shardRange(size_t runs, size_t k, size_t n);

// What is wrong with a kept row as run `index`'s ("" if nothing).
using SweepRowCheck = std::function<std::string(size_t index, const CsvRow& row)>;

// The table of runs [begin, end), written in run-index order. Rows may
// arrive in any order; each is written (and flushed) once every row before
// it is. With `resume`, an existing file's complete rows are kept (checked
// against the header, the run indices and `check`, before anything is
// written) and a row cut short is dropped.
class SweepWriter {
 public:
  SweepWriter(const std::string& path, const CsvRow& header, bool writeHeader, size_t begin,
              size_t end, bool resume, const SweepRowCheck& check = {});
  ~SweepWriter();
  SweepWriter(const SweepWriter&) = delete;
  SweepWriter& operator=(const SweepWriter&) = delete;
  // The first run not in the file yet (begin, unless resumed).
  size_t next() const { return next_; }
  // Run `index`'s row (begin <= index < end); thread-safe.
  void put(size_t index, const CsvRow& row);
  // Rows put but not yet written (waiting for an earlier one).
  size_t pending() const;
  // UserError unless every run up to `end` was written; closes the file.
  void finish();

 private:
  void writeLocked(const std::string& text);
  std::string path_;
  std::optional<RowFile> rows_;
  size_t next_, end_;
  std::vector<std::pair<size_t, std::string>> waiting_;  // sorted by index
  mutable std::mutex mutex_;
};

// Everything a sweep (or one shard of it) does before its first run, one
// code for the local threads (cli/sweep_command.cpp) and the Dask driver
// (python/simbot/sweep.py), so that either resumes the other's table.
class SweepOutput {
 public:
  // Checks, and writes nothing: every program and opponent compiles (its
  // warnings printed once), no output (OUT, OUT.batch.json) is an input,
  // and with `resume` OUT.batch.json holds these settings (the same simbot
  // `version`, shard, header and input contents). `shard` is "K/N".
  SweepOutput(const SweepSpec& spec, const std::string& out, const std::string& shard, bool header,
              bool resume, const std::string& version);
  // The shard's runs, [begin, end) of all.
  size_t begin() const { return begin_; }
  size_t end() const { return end_; }
  const std::vector<SweepRun>& runs() const { return runs_; }
  // Makes OUT's folder, then: with resume, keeps OUT's complete rows, each
  // checked to be this sweep's run (sweepRowMismatch); without, removes the
  // old OUT.batch.json, writes the header and then OUT.batch.json. The
  // writer appends the rest.
  std::unique_ptr<SweepWriter> open() const;

 private:
  SweepSpec spec_;
  std::string out_;
  bool header_, resume_;
  BatchSettings settings_;
  std::vector<SweepRun> runs_;
  size_t begin_ = 0, end_ = 0;
};

}  // namespace simbot::batch
