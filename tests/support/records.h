// The typed trace records of one kind, in tick order, from a collected run.
#pragma once
#include <utility>
#include <variant>
#include <vector>

#include "trace/trace.h"

namespace simbot::testkit {

// Every record of kind R (of one robot, or of all when robot < 0).
template <class R>
std::vector<std::pair<trace::Tick, R>> recordsOf(const std::vector<trace::Entry>& entries,
                                                 int robot = -1) {
  std::vector<std::pair<trace::Tick, R>> out;
  for (const auto& e : entries)
    if (const R* r = std::get_if<R>(&e.record))
      if (robot < 0 || trace::robotOf(e.record) == robot) out.emplace_back(e.t, *r);
  return out;
}

}  // namespace simbot::testkit
