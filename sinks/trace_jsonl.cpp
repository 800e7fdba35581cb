#include "sinks/trace_jsonl.h"

#include <fmt/format.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <new>
#include <stdexcept>
#include <type_traits>

#include "sinks/json_text.h"
#include "sinks/user_error.h"
#include "timebase/tick.h"

namespace simbot::sinks {

namespace {

using nlohmann::json;
using trace::FieldKind;

constexpr const char* kRobotNames[] = {"A", "B"};

}  // namespace

json traceJson(const trace::Entry& e) {
  json j = json::object();
  j["type"] = trace::kindOf(e.record).name;
  trace::forEachField(e.record, [&](const trace::FieldInfo& f, const auto& v) {
    using V = std::remove_cvref_t<decltype(v)>;
    if constexpr (std::is_same_v<V, int>) {
      if (f.kind == FieldKind::Robot && v >= 0 && v < 2)
        j[f.name] = kRobotNames[v];
      else
        j[f.name] = v;
    } else if constexpr (std::is_same_v<V, std::string>) {
      j[f.name] = jsonString(v, f.kind == FieldKind::Bytes);
    } else if constexpr (std::is_same_v<V, std::optional<std::int64_t>> ||
                         std::is_same_v<V, std::optional<double>>) {
      j[f.name] = v ? json(*v) : json(nullptr);
    } else {
      j[f.name] = v;
    }
  });
  j["t"] = e.t;
  j["time_s"] = timebase::secondsFromTicks(e.t);
  if (!e.watch.empty()) {
    json w = json::object();
    for (const auto& item : e.watch)  // (clang 14 cannot capture a structured binding)
      std::visit([&](const auto& x) { w[item.first] = x; }, item.second);
    j["watch"] = std::move(w);
  }
  return j;
}

std::string traceLine(const trace::Entry& e) { return traceJson(e).dump(); }

trace::Entry traceEntry(const json& j) {
  if (!j.is_object()) throw std::invalid_argument("a record must be a JSON object");
  const auto type = j.find("type");
  if (type == j.end() || !type->is_string())
    throw std::invalid_argument("a record needs a \"type\"");
  const int kind = trace::kindIndex(type->get<std::string>());
  if (kind < 0)
    throw std::invalid_argument("unknown record type \"" + type->get<std::string>() + "\"");
  trace::Entry e;
  const auto t = j.find("t");
  if (t == j.end() || !t->is_number_integer())
    throw std::invalid_argument("a record needs a tick \"t\"");
  e.t = t->get<trace::Tick>();
  // Default-construct the variant's alternative number `kind`.
  [&]<size_t... I>(std::index_sequence<I...>) {
    ((I == static_cast<size_t>(kind) ? (e.record.emplace<I>(), 0) : 0), ...);
  }
  (std::make_index_sequence<std::variant_size_v<trace::Record> - 1>{});
  trace::forEachField(e.record, [&](const trace::FieldInfo& f, auto& v) {
    using V = std::remove_cvref_t<decltype(v)>;
    const auto it = j.find(f.name);
    const auto bad = [&](const char* want) {
      return std::invalid_argument(
          fmt::format("{}: \"{}\" must be {}{}", type->get<std::string>(), f.name, want,
                      it == j.end() ? " (missing: a trace from an older simbot?)" : ""));
    };
    if (it == j.end()) {
      if constexpr (std::is_same_v<V, std::optional<std::int64_t>> ||
                    std::is_same_v<V, std::optional<double>>)
        throw bad("a number or null");
      else
        throw bad(f.kind == FieldKind::Robot ? "\"A\" or \"B\"" : "present");
    }
    if constexpr (std::is_same_v<V, int>) {
      if (!it->is_string() || (*it != "A" && *it != "B")) throw bad("\"A\" or \"B\"");
      v = *it == "A" ? 0 : 1;
    } else if constexpr (std::is_same_v<V, std::int64_t>) {
      if (!it->is_number_integer()) throw bad("an integer");
      v = it->get<std::int64_t>();
    } else if constexpr (std::is_same_v<V, double>) {
      if (!it->is_number()) throw bad("a number");
      v = it->get<double>();
    } else if constexpr (std::is_same_v<V, bool>) {
      if (!it->is_boolean()) throw bad("true or false");
      v = it->get<bool>();
    } else if constexpr (std::is_same_v<V, std::string>) {
      if (!it->is_string()) throw bad("a string");
      v = f.kind == FieldKind::Bytes ? bytesFromJsonString(it->get<std::string>())
                                     : it->get<std::string>();
    } else if constexpr (std::is_same_v<V, std::optional<std::int64_t>>) {
      if (it->is_null())
        v.reset();
      else if (it->is_number_integer())
        v = it->get<std::int64_t>();
      else
        throw bad("an integer or null");
    } else if constexpr (std::is_same_v<V, std::optional<double>>) {
      if (it->is_null())
        v.reset();
      else if (it->is_number())
        v = it->get<double>();
      else
        throw bad("a number or null");
    } else if constexpr (std::is_same_v<V, std::vector<double>>) {
      if (!it->is_array()) throw bad("an array of numbers");
      v.clear();
      for (const auto& x : *it) {
        if (!x.is_number()) throw bad("an array of numbers");
        v.push_back(x.get<double>());
      }
    }
  });
  if (const auto w = j.find("watch"); w != j.end()) {
    if (!w->is_object()) throw std::invalid_argument("\"watch\" must be an object");
    for (const auto& [name, value] : w->items()) {
      if (value.is_number_integer())
        e.watch.emplace_back(name, value.get<std::int64_t>());
      else if (value.is_number())
        e.watch.emplace_back(name, value.get<double>());
      else if (value.is_string())
        e.watch.emplace_back(name, value.get<std::string>());
      else if (value.is_null())
        e.watch.emplace_back(name, nullptr);
      else
        throw std::invalid_argument("watched values must be numbers, strings or null");
    }
  }
  return e;
}

JsonlSink::JsonlSink(const std::string& path) : path_(path) {
  try {
    file_ = out_.emplace(path).file();
  } catch (const files::Error& e) {
    throw UserError(fmt::format("simbot: cannot write trace '{}': {}\n", path, e.what()));
  }
}

JsonlSink::~JsonlSink() = default;

void JsonlSink::fail(const std::string& reason) const {
  throw UserError(fmt::format("simbot: writing trace '{}': {}\n", path_, reason));
}

void JsonlSink::write(const trace::Entry& entry) {
  std::string line = traceLine(entry);
  line.push_back('\n');
  if (std::fwrite(line.data(), 1, line.size(), file_) != line.size()) fail(std::strerror(errno));
}

void JsonlSink::close() {
  if (!file_) return;
  file_ = nullptr;
  try {
    out_->commit();
  } catch (const files::Error& e) {
    fail(e.what());
  }
}

TraceRead readTrace(const std::string& path, const std::function<void(const trace::Entry&)>& each) {
  std::optional<files::Input> in;
  try {
    in.emplace(path, files::kMaxTraceBytes);
  } catch (const files::Error& e) {
    throw UserError(fmt::format("{}:1: error: cannot read the trace: {}\n", path, e.what()));
  }
  TraceRead read;
  std::string line;
  int number = 0;
  bool header = false, whole = false;
  while (true) {
    try {
      if (!in->readLine(line, whole, files::kMaxTraceLineBytes)) break;
    } catch (const files::LineTooLong& e) {
      throw UserError(fmt::format("{}:{}: error: {}: no record of a simbot trace is that long\n",
                                  path, number + 1, e.what()));
    } catch (const files::Error& e) {
      throw UserError(
          fmt::format("{}:{}: error: cannot read the trace: {}\n", path, number + 1, e.what()));
    } catch (const std::bad_alloc&) {
      throw UserError(
          fmt::format("{}:{}: error: out of memory reading the trace\n", path, number + 1));
    }
    ++number;
    if (line.empty()) continue;
    trace::Entry e;
    try {
      e = traceEntry(json::parse(line));
    } catch (const std::bad_alloc&) {
      throw UserError(fmt::format("{}:{}: error: out of memory reading the trace\n", path, number));
    } catch (const std::exception& ex) {
      // A last line with no line end that does not parse: the run that
      // wrote it was killed or its disk filled. What came before is whole.
      if (!whole && header) {
        read.cutShortAtLine = number;
        break;
      }
      std::string what = ex.what();
      if (const auto at = what.find("] ");
          what.rfind("[json.exception", 0) == 0 && at != std::string::npos)
        what = what.substr(at + 2);  // nlohmann's parse error, without its tag
      throw UserError(fmt::format("{}:{}: error: {}\n", path, number, what));
    }
    if (!header && !std::holds_alternative<trace::rec::Run>(e.record))
      throw UserError(fmt::format(
          "{}:{}: error: not a simbot trace: it must start with a \"run\" record\n", path, number));
    header = true;
    read.ended = std::holds_alternative<trace::rec::End>(e.record);
    read.lastTick = e.t;
    ++read.records;
    try {
      each(e);
    } catch (const std::bad_alloc&) {
      throw UserError(fmt::format(
          "{}:{}: error: out of memory keeping the trace's records up to here\n", path, number));
    }
  }
  if (!header) throw UserError(fmt::format("{}:1: error: the trace is empty\n", path));
  return read;
}

std::string cutShortWarning(const std::string& path, const TraceRead& read) {
  if (read.ended) return "";
  const std::string where =
      read.cutShortAtLine
          ? fmt::format("{}:{}: its last line is not a whole record", path, read.cutShortAtLine)
          : fmt::format("{}: it has no \"end\" record", path);
  return fmt::format(
      "simbot: warning: {}: the run that wrote it was cut short (killed, or its disk filled); "
      "read up to its last whole record, at {:.6f} s\n",
      where, timebase::secondsFromTicks(read.lastTick));
}

}  // namespace simbot::sinks
