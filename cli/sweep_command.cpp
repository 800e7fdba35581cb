// simbot sweep FILE.toml: batch/sweep.h runs the grid on this machine's
// threads, one --shard of it, or (--dask) hands it to the Python module's
// driver, which runs the same rows on a Dask cluster.
#include <fmt/format.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "batch/bench.h"
#include "batch/parallel.h"
#include "batch/sweep.h"
#include "cli/commands.h"
#include "cli/version.h"
#include "config/config.h"
#include "sinks/user_error.h"

namespace simbot::cli {

namespace fs = std::filesystem;

namespace {

struct SweepOptions {
  std::string file, out, shard = "1/1", dask;
  int threads = 0;
  bool noHeader = false, resume = false;
  std::vector<std::string> warningOptions;  // -Wno-NAME, -Werror (main() applies them)
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
  throw sinks::UserError(
      fmt::format("simbot: --dask: cannot run {}: {}\n", SIMBOT_PYTHON, std::strerror(errno)));
#else
  (void)o;
  throw sinks::UserError(
      "simbot: --dask needs the Python module, which this build does not have (sanitizer "
      "builds leave it out)\n");
#endif
}

int runSweepCommand(SweepOptions& o) {
  if (o.out.empty()) o.out = defaultOut(o);
  batch::parseShard(o.shard);
  if (!o.dask.empty()) {
    if (!o.warningOptions.empty())
      throw sinks::UserError(
          "simbot: sweep: -W options apply to this process's compiles; the Dask workers compile "
          "with the default warnings (leave them out with --dask)\n");
    // The driver checks and opens the table with the same code as below
    // (batch::SweepOutput), fingerprint and all.
    execDaskDriver(o);
  }
  const batch::SweepSpec spec = config::loadSweep(o.file, batch::benchFamilies());
  const batch::SweepOutput output(spec, o.out, o.shard, !o.noHeader, o.resume, simbotVersion());
  const std::vector<batch::SweepRun>& runs = output.runs();
  const size_t begin = output.begin(), end = output.end();
  const std::unique_ptr<batch::SweepWriter> opened = output.open();
  batch::SweepWriter& writer = *opened;
  const size_t first = writer.next();
  batch::StopOnSignals signals;
  batch::parallelFor(
      end - first, o.threads,
      [&](size_t i) {
        if (signals.requested()) return;
        writer.put(first + i, batch::runSweepRow(spec, runs[first + i]));
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
  return {cmd, [o, cmd] {
            o->warningOptions = cmd->remaining();
            return guarded([&] { return runSweepCommand(*o); });
          }};
}

}  // namespace simbot::cli
