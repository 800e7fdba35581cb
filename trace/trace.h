// trace/trace.h -- the whole interface of simbot's trace: typed records,
// the sink interface, and the tracer that puts records in tick order.
//
// The record kinds and their fields are defined once, in trace/records.def;
// this header turns that list into one struct per kind (namespace rec), the
// Record variant, and a table of names and fields that sinks and readers
// walk. The scheduler emits records through a Tracer; sinks (JSONL, the
// replay viewer, VCD: sinks/, reports/) receive them. With no sink attached nothing
// is built: emitters test `tracer.on()` first.
//
// Order. A record is emitted when the simulation learns of it, which is not
// always in tick order (each robot's VM runs a whole round before the next,
// the plant reports later). The tracer keeps records until the scheduler
// says no earlier tick can come (flushBefore), then hands them to the sinks
// sorted by (tick, emission sequence): the same order on every run, with
// memory bounded by one co-simulation round.
#pragma once
#include <climits>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <variant>
#include <vector>

#include "timebase/tick.h"

namespace simbot::trace {

using timebase::Tick;

enum class FieldKind : std::uint8_t { Robot, Int, Real, Bool, Text, Bytes, OptInt, OptReal, Reals };

template <FieldKind>
struct FieldTypeOf;
template <>
struct FieldTypeOf<FieldKind::Robot> {
  using type = int;
};
template <>
struct FieldTypeOf<FieldKind::Int> {
  using type = std::int64_t;
};
template <>
struct FieldTypeOf<FieldKind::Real> {
  using type = double;
};
template <>
struct FieldTypeOf<FieldKind::Bool> {
  using type = bool;
};
template <>
struct FieldTypeOf<FieldKind::Text> {
  using type = std::string;
};
template <>
struct FieldTypeOf<FieldKind::Bytes> {
  using type = std::string;
};
template <>
struct FieldTypeOf<FieldKind::OptInt> {
  using type = std::optional<std::int64_t>;
};
template <>
struct FieldTypeOf<FieldKind::OptReal> {
  using type = std::optional<double>;
};
template <>
struct FieldTypeOf<FieldKind::Reals> {
  using type = std::vector<double>;
};

// One struct per record kind, members in definition order.
namespace rec {
#define FIELD(kind, member, doc) typename FieldTypeOf<FieldKind::kind>::type member{};
#define TRACE_RECORD(Type, name, doc, ...) \
  struct Type {                            \
    __VA_ARGS__                            \
  };
#include "trace/records.def"
#undef TRACE_RECORD
#undef FIELD
}  // namespace rec

#define FIELD(kind, member, doc)
#define TRACE_RECORD(Type, name, doc, ...) rec::Type,
using Record = std::variant<
#include "trace/records.def"
    std::monostate>;  // last, so the list can end with a comma; never emitted
#undef TRACE_RECORD
#undef FIELD

// The kinds and their fields, in definition order (index = Record::index()).
struct FieldInfo {
  const char* name;
  FieldKind kind;
  const char* doc;
};
struct KindInfo {
  const char* name;
  const char* doc;
  std::span<const FieldInfo> fields;
};
std::span<const KindInfo> kinds();
// Index of the kind named `name`, or -1.
int kindIndex(std::string_view name);
const KindInfo& kindOf(const Record& record);

#define FIELD(kind, member, doc) f(FieldInfo{#member, FieldKind::kind, doc}, r.member);
#define TRACE_RECORD(Type, name, doc, ...)      \
  template <class F>                            \
  void visitFields(rec::Type& r, F&& f) {       \
    __VA_ARGS__                                 \
  }                                             \
  template <class F>                            \
  void visitFields(const rec::Type& r, F&& f) { \
    __VA_ARGS__                                 \
  }
#include "trace/records.def"
#undef TRACE_RECORD
#undef FIELD

// Calls f(FieldInfo, member) for every field of the record, in order; the
// member is a reference to the field's value (typed by its kind).
template <class R, class F>
void forEachField(R& record, F&& f) {
  std::visit(
      [&](auto& r) {
        if constexpr (!std::is_same_v<std::remove_cvref_t<decltype(r)>, std::monostate>)
          visitFields(r, f);
      },
      record);
}

// The robot a record belongs to (its `robot` field), or -1.
int robotOf(const Record& record);

// The manual's table (docs/trace.md) of record kinds and their fields, made from the
// definition (tests/trace_test.cpp checks that the page holds it).
std::string recordsMarkdown();

// Values of --watch expressions, read from the robot's memory when the
// record was made: integers, float for a float, the debugger's text for an
// aggregate (a struct, an array, buf as its string and bytes), null when
// the expression names an auto that is not in scope there.
using WatchValue = std::variant<std::int64_t, double, std::string, std::nullptr_t>;
using Watch = std::vector<std::pair<std::string, WatchValue>>;

struct Entry {
  Tick t = 0;
  Record record;
  Watch watch;  // empty unless variables are watched
};

// Where records go, in tick order.
class Sink {
 public:
  virtual ~Sink() = default;
  virtual void write(const Entry& entry) = 0;
  // The run is over (every record has been written).
  virtual void close() {}
};

// Keeps every entry in memory (tests, small runs).
class Collector final : public Sink {
 public:
  // Out of line: copying an Entry instantiates the Record variant's copy
  // for every kind, about a second of compile time in each file that
  // includes this header.
  void write(const Entry& entry) override;
  std::vector<Entry> entries;
};

class Tracer {
 public:
  void attach(Sink* sink) { sinks_.push_back(sink); }
  bool on() const { return !sinks_.empty(); }
  // A record at tick t; t must not be before the last flushBefore bound.
  void emit(Tick t, Record record, Watch watch = {});
  // No record before `bound` will be emitted any more: write those held.
  void flushBefore(Tick bound);
  // Writes everything held and closes the sinks.
  void close();

 private:
  struct Held {
    std::uint64_t seq;
    Entry entry;
  };
  std::vector<Sink*> sinks_;
  std::vector<Held> held_;
  std::uint64_t seq_ = 0;
  Tick flushed_ = INT64_MIN;
};

}  // namespace simbot::trace
