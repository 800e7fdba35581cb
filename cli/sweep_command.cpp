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
  std::string file;
  runs::RunOptions run;  // --out, --threads, --shard, --no-header, --resume, --dask
  std::vector<std::string> warningOptions;  // -Wno-NAME, -Werror (main() applies them)
};

std::string defaultOut(const SweepOptions& o) {
  return "out/sweep-" + fs::path(o.file).stem().string() + ".csv";
}

// --dask: the Python module's driver (python/simbot/sweep.py) runs the
// sweep on the cluster, with the same writer and the same rows.
[[noreturn]] void execDaskDriver(const SweepOptions& o) {
#ifdef SIMBOT_PYTHON
  std::vector<std::string> args = {"-m",      "simbot.sweep", o.file,   "--out",   o.run.out,
                                   "--shard", o.run.shard,    "--dask", o.run.dask};
  if (o.run.noHeader) args.push_back("--no-header");
  if (o.run.resume) args.push_back("--resume");
  execPython(pythonModuleDir(), std::move(args), "--dask");
#else
  (void)o;
  throw sinks::UserError(
      "simbot: --dask needs the Python module, which this build does not have (sanitizer "
      "builds leave it out)\n");
#endif
}

int runSweepCommand(SweepOptions& o) {
  if (o.run.out.empty()) o.run.out = defaultOut(o);
  batch::parseShard(o.run.shard);
  if (!o.run.dask.empty()) {
    if (!o.warningOptions.empty())
      throw sinks::UserError(
          "simbot: sweep: -W options apply to this process's compiles; the Dask workers compile "
          "with the default warnings (leave them out with --dask)\n");
    if (o.run.rules)
      throw sinks::UserError(
          "simbot: sweep: --rules is not passed to the Dask workers; write rules = \"NAME\" in "
          "the sweep file\n");
    // The driver checks and opens the table with the same code as below
    // (batch::SweepOutput), fingerprint and all.
    execDaskDriver(o);
  }
  batch::SweepSpec spec = config::loadSweep(o.file, batch::benchFamilies());
  if (o.run.rules) {  // over the sweep file's own, checked at every point before any run
    spec.rules = runs::loadNamedRules(*o.run.rules);
    for (size_t point = 0; point < spec.pointProfiles.size(); ++point)
      config::sweepProfile(spec, point);
  }
  const batch::SweepOutput output(spec, o.run.out, o.run.shard, !o.run.noHeader, o.run.resume,
                                  simbotVersion());
  const std::vector<batch::SweepRun>& runs = output.runs();
  const size_t begin = output.begin(), end = output.end();
  const std::unique_ptr<batch::SweepWriter> opened = output.open();
  batch::SweepWriter& writer = *opened;
  const size_t first = writer.next();
  batch::StopOnSignals signals;
  batch::parallelFor(
      end - first, o.run.threads.value_or(0),
      [&](size_t i) {
        if (signals.requested()) return;
        writer.put(first + i, batch::runSweepRow(spec, runs[first + i]));
      },
      "sweep", true, &signals.requested());
  if (signals.requested()) {
    std::cerr << fmt::format(
        "simbot: sweep stopped by signal {}; {} holds runs {} to {}; --resume continues\n",
        signals.signal(), o.run.out, begin, writer.next());
    return 128 + signals.signal();
  }
  writer.finish();
  std::cerr << fmt::format("simbot: {} runs (runs {} to {} of {}); wrote {}\n", end - begin, begin,
                           end, runs.size(), o.run.out);
  return 0;
}

}  // namespace

Subcommand addSweepCommand(CLI::App& app) {
  auto o = std::make_shared<SweepOptions>();
  auto* cmd = app.add_subcommand(
      "sweep", "bench runs over a grid of programs, families, seeds and profile values");
  cmd->add_option("SWEEP", o->file, "sweep file (TOML)")->required();
  addRunOptions(cmd, o->run, runs::kSweep);
  return {cmd, [o, cmd] {
            o->warningOptions = cmd->remaining();
            return guarded([&] { return runSweepCommand(*o); });
          }};
}

}  // namespace simbot::cli
