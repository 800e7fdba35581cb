// sinks/ (namespace simbot::sinks): where a run's trace records go once
// the scheduler has emitted them, as files other programs read: JSONL
// (this header; also read back, for simbot explain and view), VCD (vcd.h),
// and the JSON text they are written with (json_text.h). It knows the
// trace's records, never a command or a report; reports/, runs/ and
// batch/ build on it. Its UserError (user_error.h) is the user-error type
// of every part above the simulator.
//
// The trace as JSONL: one JSON object per record, in tick order, with the
// record's fields (trace/records.def) plus `type`, `t`, `time_s` and, when
// variables are watched, `watch`. Keys are written in sorted order.
//
// Strings: a Text field (file names, messages, program text) is written as
// UTF-8, byte for byte when it is valid UTF-8 and as Latin-1 otherwise; a
// Bytes field (what a robot sent or printed) always as Latin-1, one
// character U+0000..U+00FF per byte, so that it reads back exactly.
#pragma once
#include <cstdio>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "files/files.h"
#include "trace/trace.h"

namespace simbot::sinks {

nlohmann::json traceJson(const trace::Entry& entry);
std::string traceLine(const trace::Entry& entry);

// Reads one record; throws std::invalid_argument naming what is wrong.
trace::Entry traceEntry(const nlohmann::json& json);

// Writes the trace to a file as it streams in, through a temporary file
// beside it (files::Output) that close() renames into place: a path that
// cannot be written is an error before the run, and a run that fails or is
// killed leaves an existing file as it was. Write errors throw UserError.
class JsonlSink final : public trace::Sink {
 public:
  explicit JsonlSink(const std::string& path);
  ~JsonlSink() override;
  JsonlSink(const JsonlSink&) = delete;
  JsonlSink& operator=(const JsonlSink&) = delete;
  void write(const trace::Entry& entry) override;
  void close() override;

 private:
  [[noreturn]] void fail(const std::string& reason) const;
  std::string path_;
  std::optional<files::Output> out_;
  std::FILE* file_ = nullptr;  // out_'s, until close()
};

// Keeps the JSONL lines in memory (tests).
class JsonlLines final : public trace::Sink {
 public:
  void write(const trace::Entry& entry) override { lines.push_back(traceLine(entry)); }
  std::vector<std::string> lines;
};

// What readTrace read: whether the trace ends as a finished run's does
// (with its "end" record) and, if not, where it was cut short.
struct TraceRead {
  int records = 0;
  trace::Tick lastTick = 0;
  bool ended = false;      // its last record is "end"
  int cutShortAtLine = 0;  // a last line without a line end that did not parse
};

// Reads a JSONL trace file record by record (a regular file within
// files::kMaxTraceBytes, each line within files::kMaxTraceLineBytes, so
// that memory stays bounded whatever the file holds). Bad input throws
// UserError "FILE:LINE: error: MESSAGE" (a line too long, as soon as the
// limit is passed; memory running out, as that); a trace cut short (a last
// partial line, no "end" record) is read up to its last whole record, and
// said so by cutShortWarning.
TraceRead readTrace(const std::string& path, const std::function<void(const trace::Entry&)>& each);
// The warning line for a trace that was cut short; empty for a whole one.
std::string cutShortWarning(const std::string& path, const TraceRead& read);

}  // namespace simbot::sinks
