// debug/points.cpp -- breakpoints and watchpoints: setting them, and
// telling at a boundary whether one is hit and who wrote a watched value
// (session.h explains the model).
#include <fmt/format.h>

#include <algorithm>
#include <charconv>

#include "debug/session.h"

namespace simbot::debug {

using scheduler::DebugEvent;

namespace {

// A watched object's bytes (no allocation once `bytes` has its size).
void readInto(const vm::Vm& v, const Watchpoint& w, std::vector<uint8_t>& bytes) {
  bytes.resize(w.size);
  for (uint32_t k = 0; k < w.size; ++k) bytes[k] = v.read8(static_cast<uint16_t>(w.address + k));
}

bool unchanged(const vm::Vm& v, const Watchpoint& w, const std::vector<uint8_t>& bytes) {
  for (uint32_t k = 0; k < w.size; ++k)
    if (v.read8(static_cast<uint16_t>(w.address + k)) != bytes[k]) return false;
  return true;
}

}  // namespace

// What the next boundary's watchpoints compare with: this one.
void Session::noteBoundary(int robot, const vm::Vm& v) {
  LastBoundary& last = last_.at(static_cast<size_t>(robot));
  last.pc = v.pc();
  last.tick = v.now();
  last.interrupts = v.stats().interrupts;
  for (Watchpoint& w : watchpoints_)
    if (w.robot == robot) readInto(v, w, w.seen);
}

// Going backwards a change stops before what made it (the instruction or
// service at the boundary before the one that saw it), and the later value
// is the old one.
void Session::reverseWatchHit(Stop why) {
  std::swap(why.oldValue, why.newValue);
  why.reverse = true;
  // A library call's writes are judged once it is done: before the call.
  // A service's (writtenAt 0) happened in the last step alone.
  auto& seen = scan_->boundaries;
  size_t k = seen.size() - 1;
  if (why.writtenAt != 0)
    while (k > 0 && seen[k].inLibrary) --k;
  seen[k].hit = true;
  scan_->stops.emplace(seen[k].tick, std::move(why));
}

Stop Session::eventStopOf(const Breakpoint& b, int robot, Tick t) {
  Stop why;
  why.kind = Stop::Kind::Event;
  why.breakpoint = b.id;
  why.event = b.event;
  why.eventRobot = robot;
  why.note = fmt::format("at tick {}", t);
  return why;
}

bool Session::breakpointHit(int robot, Stop& why, bool counting) {
  const vm::Vm& v = vm(robot);
  if (v.fault() || v.inLibraryCall()) return false;
  const uint32_t pc = v.pc();
  for (Breakpoint& b : breakpoints_) {
    if (!b.enabled || b.robot != robot || b.address != pc ||
        (b.kind != Breakpoint::Kind::Line && b.kind != Breakpoint::Kind::Function))
      continue;
    if (b.condition) {
      try {
        const inspect::Scope s = scope(robot, 0);
        if (!inspect::truth(s, b.condition->evaluate(s))) continue;
      } catch (const inspect::Error& e) {
        why.note = fmt::format("error in the condition of breakpoint {}: {}", b.id, e.what());
      }
    }
    if (counting) {
      ++b.hits;
      if (b.ignore > 0) {
        --b.ignore;
        continue;
      }
    }
    why.kind = Stop::Kind::Breakpoint;
    why.breakpoint = b.id;
    return true;
  }
  return false;
}

bool Session::watchpointHit(int robot, Stop& why) {
  if (watchpoints_.empty()) return false;
  const vm::Vm& v = vm(robot);
  // A library routine writes over several steps: judged once it is done.
  // An interrupt service accepted between two of its steps (the serial
  // library's transmit service, the BIOS timer's: atomic) is judged at
  // once, on what changed since the step before.
  const bool serviced = serviceRan(robot, v);
  const bool inLibrary = v.inLibraryCall();
  if (inLibrary && !serviced) return false;
  for (size_t k = 0; k < watchpoints_.size(); ++k) {
    Watchpoint& w = watchpoints_[k];
    if (w.robot != robot || !w.enabled) continue;
    if (w.depth >= 0 && v.callDepth() + v.interruptDepth() < w.depth) {
      if (scan_) continue;
      why.kind = Stop::Kind::Watchpoint;
      why.breakpoint = w.id;
      why.note =
          fmt::format("watchpoint {} deleted: the call its variable lived in returned", w.id);
      why.removed = w.id;
      watchpoints_.erase(watchpoints_.begin() + static_cast<std::ptrdiff_t>(k));
      return true;
    }
    if (w.valid && unchanged(v, w, inLibrary ? w.seen : w.value)) continue;
    const bool first = !w.valid;
    readInto(v, w, w.value);
    w.valid = true;
    const std::string before = w.text;
    w.text = valueText(v, w);
    if (first) continue;
    w.writer = writer(robot, v);
    if (w.condition) {
      try {
        const inspect::Scope s = scope(robot, 0);
        if (!inspect::truth(s, w.condition->evaluate(s))) continue;
      } catch (const inspect::Error& e) {
        why.note = fmt::format("error in the condition of watchpoint {}: {}", w.id, e.what());
      }
    }
    if (!scan_) {
      ++w.hits;
      if (w.ignore > 0) {
        --w.ignore;
        continue;
      }
    }
    why.kind = Stop::Kind::Watchpoint;
    why.breakpoint = w.id;
    why.oldValue = before;
    why.newValue = w.text;
    why.writtenAt = serviced ? 0 : v.image().lineAt(last_.at(static_cast<size_t>(robot)).pc);
    why.writer = w.writer;
    return true;
  }
  return false;
}

// Whether an atomic interrupt service (the serial library's transmit
// service, the BIOS timer's) was accepted since the boundary before.
bool Session::serviceRan(int robot, const vm::Vm& v) const {
  const auto& irqs = v.stats().interrupts;
  const auto& before = last_.at(static_cast<size_t>(robot)).interrupts;
  for (vm::Irq irq : {vm::Irq::SerialTx, vm::Irq::Timer})
    if (irqs[static_cast<size_t>(irq)] != before[static_cast<size_t>(irq)]) return true;
  return false;
}

// Who made a change seen at this boundary: the service accepted at the
// boundary before, or the instruction that ran there (and the handler it
// ran in).
std::string Session::writer(int robot, const vm::Vm& v) const {
  const LastBoundary& last = last_.at(static_cast<size_t>(robot));
  const vm::Image& img = v.image();
  const vm::Symbol* fn = img.functionAt(last.pc);
  const std::string where =
      fmt::format("line {}{}", img.lineAt(last.pc), fn ? fmt::format(" in {}()", fn->name) : "");
  const auto& irqs = v.stats().interrupts;
  const auto ran = [&](vm::Irq irq) {
    return irqs[static_cast<size_t>(irq)] != last.interrupts[static_cast<size_t>(irq)];
  };
  if (ran(vm::Irq::SerialTx))
    return fmt::format(
        "the serial library's transmit interrupt (serial_tx), accepted at tick {} during {}",
        last.tick, where);
  if (ran(vm::Irq::Timer))
    return fmt::format("the BIOS timer service (PRT0), accepted at tick {} during {}", last.tick,
                       where);
  if (fn && fn->kind == vm::Symbol::Kind::Handler) return where + " [interrupt handler]";
  if (v.interruptDepth() > 0)
    for (const vm::Vm::Activation& a : v.activations())
      if (a.handler) {
        const vm::Symbol* h = img.functionAt(a.pc);
        return fmt::format("{} [in interrupt handler {}()]", where, h ? h->name : "?");
      }
  return where;
}

std::string Session::valueText(const vm::Vm& v, const Watchpoint& w) const {
  try {
    return inspect::format(inspect::Scope(v), w.object);
  } catch (const inspect::Error& e) {
    return fmt::format("<{}>", e.what());
  }
}

void Session::refreshWatchpoints() {
  for (Watchpoint& w : watchpoints_) {
    readInto(vm(w.robot), w, w.value);
    w.text = valueText(vm(w.robot), w);
    w.valid = true;
  }
}

void Session::countHit(const Stop& why) {
  if (why.kind != Stop::Kind::Breakpoint && why.kind != Stop::Kind::Event &&
      why.kind != Stop::Kind::Watchpoint)
    return;
  if (Breakpoint* b = findBreakpoint(why.breakpoint)) ++b->hits;
  for (Watchpoint& w : watchpoints_)
    if (w.id == why.breakpoint) ++w.hits;
}

Breakpoint& Session::addBreakpoint(Breakpoint b) {
  b.id = nextId_++;
  breakpoints_.push_back(std::move(b));
  applyBreakpoints();
  return breakpoints_.back();
}

Breakpoint* Session::findBreakpoint(int id) {
  for (Breakpoint& b : breakpoints_)
    if (b.id == id) return &b;
  return nullptr;
}

const Breakpoint& Session::breakAtLine(int robot, int line, bool temporary) {
  if (robot < 0 || robot >= robotCount()) throw Error("there is no such robot");
  const vm::Image& img = config_.robots[static_cast<size_t>(robot)].image;
  if (line < 1 || line > static_cast<int>(img.sourceLines.size()))
    throw Error(
        fmt::format("{} has no line {} (it has {})", program(robot), line, img.sourceLines.size()));
  // The first instruction of the line, or of the next line that has code.
  std::optional<uint32_t> at;
  int found = 0;
  for (int l = line; l <= static_cast<int>(img.sourceLines.size()) && !at; ++l) {
    const auto it = std::find(img.lines.begin(), img.lines.end(), l);
    if (it != img.lines.end()) {
      at = static_cast<uint32_t>(it - img.lines.begin());
      found = l;
    }
  }
  if (!at) throw Error(fmt::format("no code at or after line {} of {}", line, program(robot)));
  Breakpoint b;
  b.kind = Breakpoint::Kind::Line;
  b.robot = robot;
  b.line = found;
  b.address = *at;
  const vm::Symbol* fn = img.functionAt(*at);
  b.function = fn ? fn->name : "";
  b.temporary = temporary;
  return addBreakpoint(std::move(b));
}

const Breakpoint& Session::breakAtFunction(int robot, const std::string& name, bool temporary) {
  if (robot < 0 || robot >= robotCount()) throw Error("there is no such robot");
  const vm::Image& img = config_.robots[static_cast<size_t>(robot)].image;
  for (const vm::Symbol& s : img.symbols) {
    if ((s.kind != vm::Symbol::Kind::Function && s.kind != vm::Symbol::Kind::Handler) ||
        s.name != name)
      continue;
    // Past the prologue (its ENTER and the parameters' stores, on the
    // line of the function's name): at the first instruction of the body,
    // where the parameters can be read. A handler whose first instruction
    // is already its body's stops at its entry.
    uint32_t at = s.address;
    while (at < s.address + s.size && at < img.lines.size() && img.lines[at] == s.line) ++at;
    if (at >= s.address + s.size || at >= img.lines.size()) at = s.address;
    Breakpoint b;
    b.kind = Breakpoint::Kind::Function;
    b.robot = robot;
    b.function = name;
    b.address = at;
    b.line = img.lineAt(at);
    b.temporary = temporary;
    return addBreakpoint(std::move(b));
  }
  throw Error(fmt::format("no function '{}' in {}", name, program(robot)));
}

const Breakpoint& Session::breakAtTick(Tick tick, bool temporary) {
  Breakpoint b;
  b.kind = Breakpoint::Kind::Time;
  b.tick = tick;
  b.temporary = temporary;
  b.passed = run_ && tick <= now();
  return addBreakpoint(std::move(b));
}

const Breakpoint& Session::breakAtEvent(DebugEvent event, bool temporary) {
  Breakpoint b;
  b.kind = Breakpoint::Kind::Event;
  b.event = event;
  b.temporary = temporary;
  return addBreakpoint(std::move(b));
}

const Breakpoint& Session::breakAt(const std::string& location, bool temporary) {
  std::string where = location;
  const bool named = where.find(':') != std::string::npos;
  const int robot = robotOf(where);
  if (!named && where.rfind("tick ", 0) == 0) {
    return breakAtTick(parseTime(where.substr(5)), temporary);  // a number alone: ticks
  }
  if (!named && looksLikeTime(where)) return breakAtTick(parseTime(where), temporary);
  int line = 0;
  const auto [end, error] = std::from_chars(where.data(), where.data() + where.size(), line);
  if (!where.empty() && error == std::errc() && end == where.data() + where.size())
    return breakAtLine(robot, line, temporary);
  if (!named)
    for (DebugEvent e : {DebugEvent::FrameLatched, DebugEvent::EdgeAccepted, DebugEvent::Contact,
                         DebugEvent::Shot, DebugEvent::Fault}) {
      if (where != scheduler::debugEventName(e)) continue;
      for (const vm::Symbol& sym : config_.robots[static_cast<size_t>(robot)].image.symbols)
        if (sym.name == where &&
            (sym.kind == vm::Symbol::Kind::Function || sym.kind == vm::Symbol::Kind::Handler))
          return breakAtFunction(robot, where, temporary);
      return breakAtEvent(e, temporary);
    }
  return breakAtFunction(robot, where, temporary);
}

Trigger& Session::trigger(int id) {
  if (Breakpoint* b = findBreakpoint(id)) return *b;
  for (Watchpoint& w : watchpoints_)
    if (w.id == id) return w;
  throw Error(fmt::format("no breakpoint or watchpoint {}", id));
}

void Session::setCondition(int id, const std::string& expression) {
  Trigger& t = trigger(id);
  if (expression.empty()) {
    t.condition.reset();
    return;
  }
  try {
    t.condition = std::make_shared<inspect::Expression>(expression);
  } catch (const inspect::Error& e) {
    throw Error(e.what());
  }
}

void Session::setIgnore(int id, int count) { trigger(id).ignore = std::max(count, 0); }

void Session::setEnabled(int id, bool enabled) {
  Trigger& t = trigger(id);
  if (enabled && !t.enabled)
    for (Watchpoint& w : watchpoints_)
      if (w.id == id) {
        // Compared from the value it has when enabled again.
        readInto(vm(w.robot), w, w.value);
        w.text = valueText(vm(w.robot), w);
      }
  t.enabled = enabled;
  applyBreakpoints();
}

void Session::remove(int id) {
  const auto before = breakpoints_.size() + watchpoints_.size();
  breakpoints_.erase(std::remove_if(breakpoints_.begin(), breakpoints_.end(),
                                    [&](const Breakpoint& b) { return b.id == id; }),
                     breakpoints_.end());
  watchpoints_.erase(std::remove_if(watchpoints_.begin(), watchpoints_.end(),
                                    [&](const Watchpoint& w) { return w.id == id; }),
                     watchpoints_.end());
  if (before == breakpoints_.size() + watchpoints_.size())
    throw Error(fmt::format("no breakpoint or watchpoint {}", id));
  applyBreakpoints();
}

void Session::removeAll() {
  breakpoints_.clear();
  watchpoints_.clear();
  applyBreakpoints();
}

const Watchpoint& Session::watch(const std::string& expression, const std::string& condition,
                                 int robot) {
  if (robot < 0) robot = held_;
  if (robot >= robotCount()) throw Error("there is no such robot");
  Watchpoint w;
  try {
    w.expression = std::make_shared<inspect::Expression>(expression);
    if (!condition.empty()) w.condition = std::make_shared<inspect::Expression>(condition);
    const inspect::Scope s = robot == held_ ? scope() : scope(robot, 0);
    w.object = w.expression->evaluate(s);
    if (!w.object.inMemory)
      throw Error(fmt::format("'{}' is not an object in memory: nothing to watch", expression));
    // An auto: watched while the activation holding it lasts (its index
    // from the outermost, where calls and handlers both count).
    if (w.object.frame >= 0) w.depth = static_cast<int>(s.activations.size()) - 1 - w.object.frame;
    w.address = w.object.address;
    w.size = static_cast<uint32_t>(inspect::bytes(s, w.object).size());
    readInto(*s.vm, w, w.value);
    w.seen = w.value;
    w.text = inspect::format(s, w.object);
    w.valid = true;
  } catch (const inspect::Error& e) {
    throw Error(e.what());
  }
  w.id = nextId_++;
  w.robot = robot;
  watchpoints_.push_back(std::move(w));
  return watchpoints_.back();
}

}  // namespace simbot::debug
