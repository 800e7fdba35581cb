// simbot sweep (sweep.h): the sweep file's expansion into runs (config/
// reads the file), one run's row, the ordered writer, and the command
// (local threads, or the Python module's Dask driver for --dask).
#include "tools/sweep.h"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>

#include "config/config.h"
#include "tools/bench.h"
#include "tools/runner.h"

namespace simbot::tools {

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

CsvRow runSweepRow(const SweepSpec& spec, const SweepRun& run) {
  BenchConfig c;
  c.programs = {config::sweepPath(spec, run.program)};
  c.family = run.family;
  c.opponent = config::sweepPath(spec, run.opponent);
  c.seeds = 1;
  c.seconds = spec.seconds;
  c.masterSeed = run.seed;
  c.threads = 1;
  c.progress = false;
  const BenchResult result = runBench(c, config::sweepProfile(spec, run.point));
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
  CsvRow row = {std::to_string(run.index), run.program, run.family, run.opponent,
                std::to_string(run.seed)};
  const std::vector<size_t> at = config::sweepPointValues(spec, run.point);
  for (size_t k = 0; k < spec.grid.size(); ++k) row.push_back(spec.grid[k].second[at[k]]);
  for (size_t i = 0; i < names.size() && i < benchRow.size(); ++i)
    if (keptBenchColumn(names[i])) row.push_back(benchRow[i]);
  return row;
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
    throw ToolError(fmt::format("simbot: --shard takes K/N with 1 <= K <= N, got '{}'\n", text));
  return {k, n};
}

std::pair<size_t, size_t> shardRange(size_t runs, size_t k, size_t n) {
  return {runs * (k - 1) / n, runs * k / n};
}

namespace {

// A CSV file's records (a quoted field may hold a line break); a last
// record without its line end is left out (cut short by a kill).
}  // namespace

SweepWriter::SweepWriter(const std::string& path, const CsvRow& header, bool writeHeader,
                         size_t begin, size_t end, bool resume)
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
          throw ToolError(fmt::format(
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
          throw ToolError(fmt::format("{}: error: --resume: row {}: {}\n", path, r + 1, e.what()));
        }
        if (row.size() != header.size() || row[0] != std::to_string(next_) || next_ >= end_)
          throw ToolError(
              fmt::format("{}: error: --resume: row {} is not run {} of this sweep (or shard)\n",
                          path, r + 1, next_));
        kept += records[r] + "\r\n";
        ++next_;
      }
    }
    writeFileAtomically(path, kept);
    file_ = std::fopen(path.c_str(), "ab");
  } else {
    file_ = std::fopen(path.c_str(), "wb");
    if (file_ && writeHeader) writeLocked(csvRecord(header));
  }
  if (!file_)
    throw ToolError(fmt::format("simbot: cannot write '{}': {}\n", path, std::strerror(errno)));
}

SweepWriter::~SweepWriter() {
  if (file_) std::fclose(file_);
}

void SweepWriter::writeLocked(const std::string& text) {
  if (std::fwrite(text.data(), 1, text.size(), file_) != text.size() || std::fflush(file_) != 0)
    throw ToolError(fmt::format("simbot: cannot write '{}': {}\n", path_, std::strerror(errno)));
}

void SweepWriter::put(size_t index, const CsvRow& row) {
  std::lock_guard lock(mutex_);
  if (index < next_ || index >= end_)
    throw std::logic_error(fmt::format("simbot: sweep: run {} is not awaited", index));
  const auto at = std::lower_bound(waiting_.begin(), waiting_.end(), index,
                                   [](const auto& w, size_t i) { return w.first < i; });
  waiting_.insert(at, {index, csvRecord(row)});
  std::string ready;
  size_t n = 0;
  while (n < waiting_.size() && waiting_[n].first == next_) {
    ready += waiting_[n++].second;
    ++next_;
  }
  waiting_.erase(waiting_.begin(), waiting_.begin() + static_cast<std::ptrdiff_t>(n));
  if (!ready.empty()) writeLocked(ready);
}

size_t SweepWriter::pending() const {
  std::lock_guard lock(mutex_);
  return waiting_.size();
}

void SweepWriter::finish() {
  std::lock_guard lock(mutex_);
  const int closed = std::fclose(file_);
  file_ = nullptr;
  if (closed != 0)
    throw ToolError(fmt::format("simbot: cannot write '{}': {}\n", path_, std::strerror(errno)));
  if (next_ != end_)
    throw ToolError(fmt::format(
        "simbot: sweep: {} rows are missing from '{}' (first missing: run {}); --resume "
        "continues\n",
        end_ - next_, path_, next_));
}

namespace {

struct SweepOptions {
  std::string file, out, shard = "1/1", dask;
  int threads = 0;
  bool noHeader = false, resume = false;
};

std::string defaultOut(const SweepOptions& o) {
  return "out/sweep-" + fs::path(o.file).stem().string() + ".csv";
}

// --dask: the Python module's driver (python/simbot/sweep.py) runs the
// sweep on the cluster, with the same writer and the same rows.
[[noreturn]] void execDaskDriver(const SweepOptions& o) {
#ifdef SIMBOT_PYTHON
  // The module beside an installed simbot (PREFIX/bin/../SITE), else the
  // build tree's.
  std::string path = SIMBOT_PYTHON_BUILD_DIR;
  std::error_code ec;
  const fs::path self = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    const fs::path installed = self.parent_path().parent_path() / SIMBOT_PYTHON_INSTALL_DIR;
    if (fs::exists(installed / "simbot" / "sweep.py", ec)) path = installed.string();
  }
  if (const char* old = std::getenv("PYTHONPATH"); old && *old) path += std::string(":") + old;
  setenv("PYTHONPATH", path.c_str(), 1);
  std::vector<std::string> args = {SIMBOT_PYTHON, "-m",      "simbot.sweep", o.file,   "--out",
                                   o.out,         "--shard", o.shard,        "--dask", o.dask};
  if (o.noHeader) args.push_back("--no-header");
  if (o.resume) args.push_back("--resume");
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  std::cout.flush();
  execv(SIMBOT_PYTHON, argv.data());
  throw ToolError(
      fmt::format("simbot: --dask: cannot run {}: {}\n", SIMBOT_PYTHON, std::strerror(errno)));
#else
  (void)o;
  throw ToolError(
      "simbot: --dask needs the Python module, which this build does not have (sanitizer "
      "builds leave it out)\n");
#endif
}

int runSweepCommand(SweepOptions& o) {
  if (o.out.empty()) o.out = defaultOut(o);
  const auto [k, n] = parseShard(o.shard);
  const SweepSpec spec = config::loadSweep(o.file, benchFamilies());
  if (!o.dask.empty()) execDaskDriver(o);
  const std::vector<SweepRun> runs = expandSweep(spec);
  const auto [begin, end] = shardRange(runs.size(), k, n);
  SweepWriter writer(o.out, sweepHeader(spec), !o.noHeader, begin, end, o.resume);
  const size_t first = writer.next();
  StopOnSignals signals;
  parallelFor(
      end - first, o.threads,
      [&](size_t i) {
        if (signals.requested()) return;
        writer.put(first + i, runSweepRow(spec, runs[first + i]));
      },
      "sweep", true, &signals.requested());
  if (signals.requested()) {
    std::cerr << fmt::format(
        "simbot: sweep stopped by signal {}; {} holds runs {} to {}; --resume continues\n",
        signals.signal(), o.out, begin, writer.next());
    return 128 + signals.signal();
  }
  writer.finish();
  std::cerr << fmt::format("simbot: {} runs (runs {} to {} of {}); wrote {}\n", end - begin, begin,
                           end, runs.size(), o.out);
  return 0;
}

}  // namespace

Subcommand addSweepCommand(CLI::App& app) {
  auto o = std::make_shared<SweepOptions>();
  auto* cmd = app.add_subcommand(
      "sweep", "bench runs over a grid of programs, families, seeds and profile values");
  cmd->add_option("SWEEP", o->file, "sweep file (TOML)")->required();
  cmd->add_option("--out", o->out, "the table to write (CSV; default out/sweep-NAME.csv)");
  cmd->add_option("--threads", o->threads, "worker threads (default: all cores)")
      ->check(CLI::Range(1, 1024));
  cmd->add_option("--shard", o->shard,
                  "run only part K of N (K/N): a contiguous block of the runs, so the parts "
                  "concatenated in order are the whole table");
  cmd->add_flag("--no-header", o->noHeader,
                "leave out the header line (for shards after the first)");
  cmd->add_flag("--resume", o->resume,
                "keep the complete rows of an existing table and run the rest");
  cmd->add_option("--dask", o->dask,
                  "run on a Dask cluster through the Python module: tcp://HOST:PORT, or "
                  "local:N for a local cluster of N worker processes");
  return {cmd, [o] { return guarded([&] { return runSweepCommand(*o); }); }};
}

}  // namespace simbot::tools
