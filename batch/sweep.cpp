// simbot sweep (sweep.h): the sweep file's expansion into runs (config/
// reads the file), one run's row and the ordered writer. The command
// (local threads, or the Python module's Dask driver for --dask) is
// cli/sweep_command.cpp.
#include "batch/sweep.h"

#include <fmt/format.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <tuple>

#include "batch/bench.h"
#include "config/config.h"
#include "runs/play.h"
#include "sinks/user_error.h"

namespace simbot::batch {

namespace {

namespace fs = std::filesystem;

struct Pair {
  std::string family, opponent;
};

std::vector<Pair> familyPairs(const SweepSpec& spec) {
  std::vector<Pair> pairs;
  for (const auto& f : spec.families) {
    if (f == "head-to-head")
      for (const auto& o : spec.opponents) pairs.push_back({f, o});
    else
      pairs.push_back({f, ""});
  }
  return pairs;
}

}  // namespace

std::vector<SweepRun> expandSweep(const SweepSpec& spec) {
  std::vector<SweepRun> runs;
  const auto pairs = familyPairs(spec);
  for (size_t point = 0; point < config::sweepPoints(spec); ++point)
    for (const auto& program : spec.programs)
      for (const auto& pair : pairs)
        for (uint64_t s = 0; s < spec.seedCount; ++s)
          runs.push_back(
              {runs.size(), point, program, pair.family, pair.opponent, spec.firstSeed + s});
  return runs;
}

namespace {

// The bench's columns a sweep row keeps (the program and the run index are
// the sweep's own), and what they are called in the sweep's table.
bool keptBenchColumn(const std::string& name) { return name != "program" && name != "run"; }
std::string sweepName(const std::string& benchName) {
  return benchName == "seed" ? "stream_seed" : benchName;
}

}  // namespace

CsvRow sweepHeader(const SweepSpec& spec) {
  CsvRow header = {"run", "program", "family", "opponent", "master_seed"};
  for (const auto& [key, values] : spec.grid) header.push_back(key);
  for (const auto& name : benchHeader())
    if (keptBenchColumn(name)) header.push_back(sweepName(name));
  return header;
}

namespace {

// The bench a sweep row is: run 0 of the row's program, family and
// opponent, with the row's master seed, under its grid point's profile.
BenchConfig sweepBench(const SweepSpec& spec, const SweepRun& run) {
  BenchConfig c;
  c.programs = {config::sweepPath(spec, run.program)};
  c.family = run.family;
  c.opponent = config::sweepPath(spec, run.opponent);
  c.seeds = 1;
  c.seconds = spec.seconds;
  c.masterSeed = run.seed;
  c.threads = 1;
  c.progress = false;
  return c;
}

// The columns a row's run alone decides: run, program, family, opponent,
// master_seed and the grid values.
CsvRow sweepRowKey(const SweepSpec& spec, const SweepRun& run) {
  CsvRow row = {std::to_string(run.index), run.program, run.family, run.opponent,
                std::to_string(run.seed)};
  const std::vector<size_t> at = config::sweepPointValues(spec, run.point);
  for (size_t k = 0; k < spec.grid.size(); ++k) row.push_back(spec.grid[k].second[at[k]]);
  return row;
}

}  // namespace

CsvRow runSweepRow(const SweepSpec& spec, const SweepRun& run) {
  const BenchResult result = runBench(sweepBench(spec, run), config::sweepProfile(spec, run.point));
  // The bench's own row, through its own CSV (one header line, one row).
  const std::string csv = runsCsv(result);
  // Line ends may be LF or CRLF (RFC 4180's).
  const auto chomp = [](std::string line) {
    while (!line.empty() && (line.back() == '\n' || line.back() == '\r')) line.pop_back();
    return line;
  };
  const size_t eol = csv.find('\n');
  const CsvRow names = parseCsvLine(chomp(csv.substr(0, eol)));
  const std::string body = chomp(csv.substr(eol + 1));
  if (body.empty())
    throw std::logic_error("simbot: sweep: the bench gave no row for run " +
                           std::to_string(run.index));
  const CsvRow benchRow = parseCsvLine(body);
  CsvRow row = sweepRowKey(spec, run);
  for (size_t i = 0; i < names.size() && i < benchRow.size(); ++i)
    if (keptBenchColumn(names[i])) row.push_back(benchRow[i]);
  return row;
}

std::string sweepRowMismatch(const SweepSpec& spec, const SweepRun& run, const CsvRow& row) {
  const CsvRow header = sweepHeader(spec);
  CsvRow expected = sweepRowKey(spec, run);
  const BenchConfig bench = sweepBench(spec, run);
  expected.push_back(std::to_string(benchRunSeed(bench, bench.programs[0], 0)));  // stream_seed
  for (size_t k = 0; k < expected.size(); ++k)
    if (k >= row.size() || row[k] != expected[k])
      return fmt::format(
          "run {}'s {} is '{}', but this sweep's run {} has '{}' (a row from "
          "another batch)",
          run.index, header[k], k < row.size() ? row[k] : "", run.index, expected[k]);
  return "";
}

std::pair<size_t, size_t> parseShard(const std::string& text) {
  const auto slash = text.find('/');
  const auto number = [](const std::string& s) -> size_t {
    if (s.empty() || s.size() > 6 || s.find_first_not_of("0123456789") != std::string::npos)
      return 0;
    return std::stoul(s);
  };
  const size_t k = slash == std::string::npos ? 0 : number(text.substr(0, slash));
  const size_t n = slash == std::string::npos ? 0 : number(text.substr(slash + 1));
  if (k < 1 || n < 1 || k > n)
    throw sinks::UserError(
        fmt::format("simbot: --shard takes K/N with 1 <= K <= N, got '{}'\n", text));
  return {k, n};
}

std::pair<size_t, size_t> shardRange(size_t runs, size_t k, size_t n) {
  return {runs * (k - 1) / n, runs * k / n};
}

SweepWriter::SweepWriter(const std::string& path, const CsvRow& header, bool writeHeader,
                         size_t begin, size_t end, bool resume, const SweepRowCheck& check)
    : path_(path), next_(begin), end_(end) {
  const fs::path dir = fs::path(path).parent_path();
  std::error_code ec;
  if (!dir.empty()) fs::create_directories(dir, ec);
  std::string kept;
  if (resume && fs::exists(path, ec)) {
    std::ifstream in(path, std::ios::binary);
    const std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
    const auto records = csvRecords(text);
    size_t r = 0;
    if (writeHeader) {
      if (records.empty() || records[0] != csvLine(header)) {
        if (!records.empty())
          throw sinks::UserError(fmt::format(
              "{}:1: error: --resume: not this sweep's table (its header differs)\n", path));
      } else {
        kept += records[r++] + "\r\n";
      }
    }
    if (!writeHeader || !kept.empty()) {
      for (; r < records.size(); ++r) {
        CsvRow row;
        try {
          row = parseCsvLine(records[r]);
        } catch (const std::invalid_argument& e) {
          throw sinks::UserError(
              fmt::format("{}: error: --resume: row {}: {}\n", path, r + 1, e.what()));
        }
        if (row.size() != header.size() || row[0] != std::to_string(next_) || next_ >= end_)
          throw sinks::UserError(
              fmt::format("{}:{}: error: --resume: this row is not run {} of this sweep (or "
                          "shard)\n",
                          path, r + 1, next_));
        if (check)
          if (const std::string wrong = check(next_, row); !wrong.empty())
            throw sinks::UserError(fmt::format("{}:{}: error: --resume: {}\n", path, r + 1, wrong));
        kept += records[r] + "\r\n";
        ++next_;
      }
    }
    writeFileAtomically(path, kept);
  } else {
    writeFileAtomically(path, writeHeader ? csvRecord(header) : "");
  }
  rows_.emplace(path);
}

SweepWriter::~SweepWriter() = default;

void SweepWriter::writeLocked(const std::string& text) {
  if (!rows_) throw sinks::UserError(fmt::format("simbot: sweep: '{}' is finished\n", path_));
  if (!rows_->append(text))
    throw sinks::UserError(
        fmt::format("simbot: sweep: '{}' stopped after a failed write\n", path_));
}

void SweepWriter::put(size_t index, const CsvRow& row) {
  std::lock_guard lock(mutex_);
  // Finished: nothing changes (a row taken now would count as written).
  if (!rows_) throw sinks::UserError(fmt::format("simbot: sweep: '{}' is finished\n", path_));
  if (index < next_ || index >= end_)
    throw std::logic_error(fmt::format("simbot: sweep: run {} is not awaited", index));
  const auto at = std::lower_bound(waiting_.begin(), waiting_.end(), index,
                                   [](const auto& w, size_t i) { return w.first < i; });
  waiting_.insert(at, {index, csvRecord(row)});
  std::string ready;
  size_t n = 0;
  while (n < waiting_.size() && waiting_[n].first == next_ + n) ready += waiting_[n++].second;
  if (ready.empty()) return;
  // Counted as written only once they are in the file.
  writeLocked(ready);
  next_ += n;
  waiting_.erase(waiting_.begin(), waiting_.begin() + static_cast<std::ptrdiff_t>(n));
}

size_t SweepWriter::pending() const {
  std::lock_guard lock(mutex_);
  return waiting_.size();
}

void SweepWriter::finish() {
  std::lock_guard lock(mutex_);
  rows_.reset();
  if (next_ != end_)
    throw sinks::UserError(fmt::format(
        "simbot: sweep: {} rows are missing from '{}' (first missing: run {}); --resume "
        "continues\n",
        end_ - next_, path_, next_));
}

// ---- before the first run

namespace {

nlohmann::json sweepSettings(const SweepSpec& spec, const std::string& shard, bool header) {
  std::vector<std::string> inputs = {spec.file, config::sweepProfilePath(spec)};
  if (spec.rules.present) inputs.push_back(spec.rules.file);
  for (const auto* list : {&spec.programs, &spec.opponents})
    for (const auto& p : *list) inputs.push_back(config::sweepPath(spec, p));
  return {{"command", "sweep"},
          {"shard", shard},
          {"header", header},
          {"contents", inputContents(inputs)}};
}

}  // namespace

SweepOutput::SweepOutput(const SweepSpec& spec, const std::string& out, const std::string& shard,
                         bool header, bool resume, const std::string& version)
    : spec_(spec),
      out_(out),
      header_(header),
      resume_(resume),
      settings_(out + ".batch.json", sweepSettings(spec, shard, header), version) {
  const auto [k, n] = parseShard(shard);
  checkBatchOutputs(settings_.inputs(), {out_, settings_.path()});
  if (resume_) settings_.checkResume(fmt::format("the sweep in '{}'", out_));
  // Every program a run plays compiles (its warnings shown once, here).
  for (const auto* list : {&spec_.programs, &spec_.opponents})
    for (const auto& p : *list) runs::compileProgramFile(config::sweepPath(spec_, p));
  runs_ = expandSweep(spec_);
  std::tie(begin_, end_) = shardRange(runs_.size(), k, n);
}

std::unique_ptr<SweepWriter> SweepOutput::open() const {
  makeOutputFolder(fs::path(out_).parent_path().string());
  const SweepRowCheck check = [this](size_t index, const CsvRow& row) {
    return sweepRowMismatch(spec_, runs_[index], row);
  };
  if (resume_)
    return std::make_unique<SweepWriter>(out_, sweepHeader(spec_), header_, begin_, end_, true,
                                         check);
  settings_.remove();
  auto writer =
      std::make_unique<SweepWriter>(out_, sweepHeader(spec_), header_, begin_, end_, false);
  settings_.write();
  return writer;
}

}  // namespace simbot::batch
