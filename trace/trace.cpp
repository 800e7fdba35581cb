// The kind table generated from trace/records.def, and the tracer's
// ordering buffer (see trace.h).
#include "trace/trace.h"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace simbot::trace {

namespace {

#define FIELD(kind, member, doc) FieldInfo{#member, FieldKind::kind, doc},
#define TRACE_RECORD(Type, name, doc, ...) constexpr FieldInfo kFields_##Type[] = {__VA_ARGS__};
#include "trace/records.def"
#undef TRACE_RECORD
#undef FIELD

#define FIELD(kind, member, doc)
#define TRACE_RECORD(Type, name, doc, ...) KindInfo{name, doc, kFields_##Type},
constexpr KindInfo kKinds[] = {
#include "trace/records.def"
};
#undef TRACE_RECORD
#undef FIELD

static_assert(std::size(kKinds) + 1 == std::variant_size_v<Record>,
              "one KindInfo per record struct (and the unused monostate)");

}  // namespace

std::span<const KindInfo> kinds() { return kKinds; }

int kindIndex(std::string_view name) {
  for (std::size_t i = 0; i < std::size(kKinds); ++i)
    if (name == kKinds[i].name) return static_cast<int>(i);
  return -1;
}

const KindInfo& kindOf(const Record& record) {
  if (record.index() >= std::size(kKinds)) throw std::logic_error("trace: an empty record");
  return kKinds[record.index()];
}

int robotOf(const Record& record) {
  int robot = -1;
  forEachField(record, [&](const FieldInfo& f, const auto& value) {
    if constexpr (std::is_same_v<std::remove_cvref_t<decltype(value)>, int>)
      if (f.kind == FieldKind::Robot && std::string_view(f.name) == "robot") robot = value;
  });
  return robot;
}

std::string recordsMarkdown() {
  std::string out = "| record | what it records | fields |\n|---|---|---|\n";
  for (const KindInfo& k : kKinds) {
    out += "| `";
    out += k.name;
    out += "` | ";
    out += k.doc;
    out += " | ";
    for (size_t i = 0; i < k.fields.size(); ++i) {
      if (i) out += ", ";
      out += "`";
      out += k.fields[i].name;
      out += "`";
    }
    out += " |\n";
  }
  return out;
}

void Collector::write(const Entry& entry) { entries.push_back(entry); }

void Tracer::emit(Tick t, Record record, Watch watch) {
  if (t < flushed_)
    throw std::logic_error("trace: a record at tick " + std::to_string(t) +
                           " after the records up to tick " + std::to_string(flushed_) +
                           " were written");
  held_.push_back({seq_++, Entry{t, std::move(record), std::move(watch)}});
}

void Tracer::flushBefore(Tick bound) {
  if (bound <= flushed_) return;
  flushed_ = bound;
  const auto ready = std::stable_partition(held_.begin(), held_.end(),
                                           [bound](const Held& h) { return h.entry.t < bound; });
  std::sort(held_.begin(), ready, [](const Held& a, const Held& b) {
    return a.entry.t != b.entry.t ? a.entry.t < b.entry.t : a.seq < b.seq;
  });
  for (auto it = held_.begin(); it != ready; ++it)
    for (Sink* s : sinks_) s->write(it->entry);
  held_.erase(held_.begin(), ready);
}

void Tracer::close() {
  flushBefore(INT64_MAX);
  for (Sink* s : sinks_) s->close();
}

}  // namespace simbot::trace
