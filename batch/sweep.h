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

// "K/N" (1 <= K <= N) into K and N; UserError otherwise.
std::pair<size_t, size_t> parseShard(const std::string& text);
// Shard K of N holds the contiguous block of runs [begin, end): shards
// concatenated in order are the whole table.
std::pair<size_t, size_t> shardRange(size_t runs, size_t k, size_t n);

// The table of runs [begin, end), written in run-index order. Rows may
// arrive in any order; each is written (and flushed) once every row before
// it is. With `resume`, an existing file's complete rows are kept (checked
// against the header and the run indices) and a row cut short is dropped.
class SweepWriter {
 public:
  SweepWriter(const std::string& path, const CsvRow& header, bool writeHeader, size_t begin,
              size_t end, bool resume);
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

}  // namespace simbot::batch
