// _simbot: the C++ side of the Python module `simbot` (python/simbot/).
// Every entry point is the CLI's own code (runs/play.h for solo and match,
// batch/bench.h, batch/sweep.h, cli/version.h), so a result here is the CLI's result:
// simbot.match(A, B) is `simbot match A B --json`, parsed. JSON and CSV
// cross as text and are parsed on the Python side. Runs release the GIL,
// so Python threads (a Dask worker's) run them in parallel.
#include <fmt/format.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "batch/bench.h"
#include "batch/sweep.h"
#include "cli/version.h"
#include "compiler/compiler.h"
#include "config/config.h"
#include "files/files.h"
#include "runs/play.h"
#include "sinks/json_text.h"
#include "sinks/trace_jsonl.h"
#include "sinks/user_error.h"
#include "timebase/tick.h"
#include "vm/vm.h"

namespace py = pybind11;
using namespace simbot;

namespace {

std::string withoutNewline(std::string text) {
  while (!text.empty() && text.back() == '\n') text.pop_back();
  return text;
}

py::dict compileProgram(const std::string& path, bool disasm) {
  const auto result = compiler::compileFile(path);
  std::vector<compiler::Diagnostic> all = result.warnings;
  all.insert(all.end(), result.errors.begin(), result.errors.end());
  std::stable_sort(all.begin(), all.end(), [](const auto& a, const auto& b) {
    return a.line != b.line ? a.line < b.line : a.column < b.column;
  });
  std::vector<std::string> diagnostics;
  for (const auto& d : all) diagnostics.push_back(withoutNewline(d.format()));
  py::dict out;
  out["ok"] = result.image.has_value();
  out["diagnostics"] = diagnostics;
  out["disasm"] = result.image && disasm ? py::cast(vm::disassemble(*result.image)) : py::none();
  return out;
}

// A run option from its Python keyword (runs/run_options.def): None
// leaves it unset, as an option not given on the command line; a value is
// checked as the command line checks it, and refused naming the option.
template <class T>
void setRunOption(T& member, py::handle value, const char* flag, const runs::OptionCheck& check) {
  if (value.is_none()) return;
  member = value.cast<T>();
  if constexpr (std::is_integral_v<T> || std::is_same_v<T, std::optional<int>>) {
    if (const std::string problem = runs::checkOption(check, py::str(value).cast<std::string>());
        !problem.empty())
      throw sinks::UserError(fmt::format("simbot: {}: {}\n", flag, problem));
  }
}
// A run's length: a number of seconds (its shortest decimal, as Python
// prints it) or a string in the grammar of a written time ("300ms").
void setRunOption(std::optional<timebase::Tick>& member, py::handle value, const char*,
                  const runs::OptionCheck&) {
  if (value.is_none()) return;
  if (py::isinstance<py::bool_>(value) ||
      !(py::isinstance<py::str>(value) || py::isinstance<py::int_>(value) ||
        py::isinstance<py::float_>(value)))
    throw py::type_error("seconds: a number of seconds or a time such as \"800ms\"");
  member = runs::parseLengthOption(py::str(value).cast<std::string>());
}

// How Python passes a run option: a value (None: not given), a list, or
// a flag.
template <class T>
constexpr const char* runOptionKind() {
  if constexpr (std::is_same_v<T, bool>) return "flag";
  if constexpr (std::is_same_v<T, std::vector<std::string>>) return "list";
  return "value";
}

// The Python keywords of the run options that `use` (runs::kPython:
// simbot.solo and simbot.match; runs::kPythonBench: simbot.bench) takes,
// and their kinds, in their order: the package builds the functions'
// signatures from them.
std::vector<std::pair<std::string, std::string>> runOptionKeywords(unsigned use) {
  std::vector<std::pair<std::string, std::string>> keywords;
#define RUN_OPTION(member, Type, initial, flag, keyword, where, check, help) \
  if ((where)&use) keywords.emplace_back(keyword, runOptionKind<Type>());
  {
    using enum runs::RunOptionUse;
#include "runs/run_options.def"
  }
#undef RUN_OPTION
  return keywords;
}

// The run options `use` takes, from Python keywords; TypeError for a
// keyword that is none of them.
runs::RunOptions runOptionsFrom(const py::kwargs& options, unsigned use) {
  runs::RunOptions o;
  size_t used = 0;
  using runs::anything, runs::range, runs::oneOf;
#define RUN_OPTION(member, Type, initial, flag, keyword, where, check, help) \
  if (((where)&use) && options.contains(keyword)) {                          \
    setRunOption(o.member, options[keyword], flag, check);                   \
    ++used;                                                                  \
  }
  {
    using enum runs::RunOptionUse;
#include "runs/run_options.def"
  }
#undef RUN_OPTION
  if (used != options.size())
    for (const auto known = runOptionKeywords(use); const auto& [key, value] : options) {
      const auto name = key.cast<std::string>();
      if (std::none_of(known.begin(), known.end(), [&](const auto& k) { return k.first == name; }))
        throw py::type_error("unexpected keyword argument '" + name + "'");
    }
  return o;
}

// solo (one program) or match (two) with the run options as keywords: the
// CLI's JSON, the trace's JSONL lines when asked for, and the run's
// warnings.
py::tuple playRun(const std::vector<std::string>& programs, bool keepTrace,
                  const py::kwargs& options) {
  runs::RunOptions o = runOptionsFrom(options, runs::kPython);
  sinks::JsonlLines lines;
  if (keepTrace) o.sinks.push_back(&lines);
  const bool solo = programs.size() == 1;
  std::string json;
  std::vector<std::string> warnings;
  {
    py::gil_scoped_release release;
    const runs::Played played = runs::play(programs, o, solo);
    json = sinks::dumpJson(solo ? runs::soloJson(played) : runs::matchJson(played), 2);
    warnings = played.result.warnings;
  }
  return py::make_tuple(json, lines.lines, warnings);
}

// simbot bench's runs with its options as keywords (family, seeds,
// seconds, seed, profile, opponent, threads): summary.json and runs.csv.
py::tuple benchRuns(const std::vector<std::string>& programs, const py::kwargs& options) {
  const runs::RunOptions o = runOptionsFrom(options, runs::kPythonBench);
  py::gil_scoped_release release;
  batch::BenchConfig c = batch::benchConfig(o);
  c.programs = programs;
  c.progress = false;
  const config::Profile loaded =
      runs::loadRunProfile(o.profile.value_or("default"), o.rules.value_or(""));
  const batch::BenchResult r = batch::runBench(c, loaded);
  py::gil_scoped_acquire acquire;
  return py::make_tuple(sinks::dumpJson(batch::summaryJson(r), 2), batch::runsCsv(r));
}

struct Sweep {
  batch::SweepSpec spec;
  std::vector<batch::SweepRun> runs;
  explicit Sweep(const std::string& path)
      : spec(config::loadSweep(path, batch::benchFamilies())), runs(batch::expandSweep(spec)) {}
  // Every program the sweep plays (its programs, then its opponents), as
  // the paths a run opens, each once.
  std::vector<std::string> programs() const {
    std::vector<std::string> out;
    for (const auto* list : {&spec.programs, &spec.opponents})
      for (const auto& p : *list)
        if (const std::string path = config::sweepPath(spec, p);
            std::find(out.begin(), out.end(), path) == out.end())
          out.push_back(path);
    return out;
  }
  batch::CsvRow row(size_t index) const {
    if (index >= runs.size()) throw py::index_error("no run " + std::to_string(index));
    py::gil_scoped_release release;
    return batch::runSweepRow(spec, runs[index]);
  }
  // The CLI's own checks and table (batch::SweepOutput), with this
  // build's simbot version, which the CLI's is.
  std::unique_ptr<batch::SweepOutput> output(const std::string& out, const std::string& shard,
                                             bool header, bool resume) const {
    return std::make_unique<batch::SweepOutput>(spec, out, shard, header, resume,
                                                cli::simbotVersion());
  }
};

// batch::shardRange with its K/N checked (the CLI's come from parseShard):
// 1 <= k <= n, and runs * n within size_t.
std::pair<size_t, size_t> checkedShardRange(size_t runs, size_t k, size_t n) {
  if (k < 1 || n < 1 || k > n)
    throw py::value_error("shard_range: needs 1 <= k <= n, got k " + std::to_string(k) + ", n " +
                          std::to_string(n));
  if (runs > std::numeric_limits<size_t>::max() / n)
    throw py::value_error("shard_range: " + std::to_string(runs) + " runs is too many");
  return batch::shardRange(runs, k, n);
}

std::unique_ptr<batch::SweepWriter> makeSweepWriter(const std::string& path,
                                                    const batch::CsvRow& header, bool writeHeader,
                                                    size_t begin, size_t end, bool resume) {
  if (begin > end)
    throw py::value_error("SweepWriter: begin " + std::to_string(begin) + " is after end " +
                          std::to_string(end));
  if (header.empty()) throw py::value_error("SweepWriter: the header is empty");
  return std::make_unique<batch::SweepWriter>(path, header, writeHeader, begin, end, resume);
}

// A Dask worker's compilations keep their warnings to themselves: the driver
// prints each program's once (python/simbot/sweep.py), as a local sweep does.
void silenceCompileWarnings() {
  compiler::Options options;
  for (const auto& info : compiler::warningList())
    options.disabledWarnings.insert(std::string(info.name));
  runs::setCompileOptions(options);
}

}  // namespace

PYBIND11_MODULE(_simbot, m) {
  m.doc() = "simbot's C++ core (use the package `simbot`)";
  static py::exception<std::runtime_error> error(m, "Error", PyExc_RuntimeError);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const sinks::UserError& e) {
      error(withoutNewline(e.what()).c_str());
    } catch (const config::ConfigError& e) {
      error(withoutNewline(e.what()).c_str());
    }
  });
  m.def("compile", &compileProgram, py::arg("path"), py::arg("disasm") = false);
  m.def("play", &playRun, py::arg("programs"), py::arg("keep_trace"));
  m.def("run_options", [] { return runOptionKeywords(runs::kPython); });
  m.def("bench_options", [] { return runOptionKeywords(runs::kPythonBench); });
  m.def("bench", &benchRuns, py::arg("programs"));
  py::class_<Sweep>(m, "Sweep")
      .def(py::init<const std::string&>(), py::arg("path"))
      .def("__len__", [](const Sweep& s) { return s.runs.size(); })
      .def("header", [](const Sweep& s) { return batch::sweepHeader(s.spec); })
      .def("programs", &Sweep::programs)
      .def("row", &Sweep::row, py::arg("index"))
      .def("output", &Sweep::output, py::arg("out"), py::arg("shard"), py::arg("header"),
           py::arg("resume"));
  py::class_<batch::SweepOutput>(m, "SweepOutput")
      .def("begin", &batch::SweepOutput::begin)
      .def("end", &batch::SweepOutput::end)
      .def("open", &batch::SweepOutput::open);
  m.attr("MAX_TRACE_BYTES") = files::kMaxTraceBytes;
  m.attr("MAX_TRACE_LINE_BYTES") = files::kMaxTraceLineBytes;
  m.def("parse_shard", &batch::parseShard, py::arg("text"));
  m.def("shard_range", &checkedShardRange, py::arg("runs"), py::arg("k"), py::arg("n"));
  m.def("silence_compile_warnings", &silenceCompileWarnings);
  py::class_<batch::SweepWriter>(m, "SweepWriter")
      .def(py::init(&makeSweepWriter), py::arg("path"), py::arg("header"), py::arg("write_header"),
           py::arg("begin"), py::arg("end"), py::arg("resume"))
      .def("next", &batch::SweepWriter::next)
      .def("put", &batch::SweepWriter::put, py::arg("index"), py::arg("row"))
      .def("pending", &batch::SweepWriter::pending)
      .def("finish", &batch::SweepWriter::finish);
}
