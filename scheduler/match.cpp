// One match: the round loop described in match.h, the robots' buses (ports,
// A/D, serial library hooks, interrupt notifications) and the trace.
#include "scheduler/match.h"

#include <fmt/format.h>

#include <algorithm>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "plant/pio.h"
#include "plant/serial_link.h"
#include "scheduler/event_queue.h"

namespace simbot::scheduler {

namespace {

constexpr Tick kLookahead = plant::kTicksPerChar;

double seconds(Tick t) { return static_cast<double>(t) / kTicksPerSecond; }

// Queued events; the plant's own events come from Arena::advance.
struct QueuedEvent {
  enum class Kind : uint8_t { SerialByte, EndOfRound } kind;
  int robot = 0;
};

class Trace {
 public:
  explicit Trace(bool enabled) : enabled_(enabled) {}
  bool enabled() const { return enabled_; }
  void add(Tick t, nlohmann::json record) {
    if (!enabled_) return;
    record["t"] = t;
    record["time_s"] = seconds(t);
    records_.push_back({t, seq_++, std::move(record)});
  }
  std::vector<std::string> lines() {
    std::stable_sort(records_.begin(), records_.end(), [](const Record& a, const Record& b) {
      return a.tick != b.tick ? a.tick < b.tick : a.seq < b.seq;
    });
    std::vector<std::string> out;
    out.reserve(records_.size());
    for (const auto& r : records_) out.push_back(r.json.dump());
    return out;
  }

 private:
  struct Record {
    Tick tick;
    uint64_t seq;
    nlohmann::json json;
  };
  bool enabled_;
  uint64_t seq_ = 0;
  std::vector<Record> records_;
};

struct PortBWrite {
  Tick tick;
  int robot;
  uint8_t value;
};

class Match;

// One robot: its VM, the devices its program talks to, and its counters.
class Robot : public vm::Bus, public plant::RobotMemory {
 public:
  Robot(Match& match, int index, const RobotSpec& spec, const vm::CostTable& costs, uint64_t seed);

  // vm::Bus
  void out(Tick t, uint16_t port, uint8_t value) override;
  uint8_t in(Tick t, uint16_t port) override;
  int adSample(Tick t, int channel) override;
  void serialSend(Tick t, uint16_t buf, uint16_t cc) override;
  void serialTxService(Tick t, vm::Vm& v) override;
  void console(Tick t, std::string_view line) override;
  void interruptAccepted(Tick t, vm::Irq irq, uint32_t pc) override;
  void interruptReturned(Tick t, vm::Irq irq) override;
  // plant::RobotMemory
  uint8_t read8(uint16_t a) const override { return vm_.read8(a); }
  void write8(uint16_t a, uint8_t v) override { vm_.write8(a, v); }

  // Runs the VM to `horizon` (its clock ends at or after it).
  void runTo(Tick horizon);
  void byteDone(Tick t);
  void setEdgeLines(Tick t, uint8_t lines);
  void scheduleSerial();
  void updateSerialRequest();

  const RobotSpec& spec;
  int index;
  Match& match;
  vm::Vm vm_;
  plant::SerialLink link;
  plant::PioPortA pio;
  uint8_t edgeLines = 0xFF;
  Tick serialEventAt = -1;
  plant::SplitMix64 noise;
  RobotResult result;
  uint32_t mainReturn;
};

class Match {
 public:
  explicit Match(const MatchConfig& config)
      : config_(config),
        costs_(vm::makeCostTable(config.knobs)),
        arena_(config.arena),
        trace_(config.trace),
        coin_(streamSeed(config.seed, "coin")) {
    if (config.robots.empty() || config.robots.size() > 2)
      throw std::invalid_argument("a match needs one or two robots");
    for (size_t i = 0; i < config.robots.size(); ++i)
      robots_.push_back(std::make_unique<Robot>(*this, static_cast<int>(i), config.robots[i],
                                                costs_, config.seed));
    queue_.schedule(config.endTick, EventClass::EndOfRound, {QueuedEvent::Kind::EndOfRound, 0});
  }

  MatchResult run();

  plant::Arena& arena() { return arena_; }
  Trace& trace() { return trace_; }
  EventQueue<QueuedEvent>& queue() { return queue_; }
  std::vector<PortBWrite>& portB() { return portBWrites_; }
  const std::string& name(int robot) const {
    return config_.robots[static_cast<size_t>(robot)].name;
  }

 private:
  Tick earliestClock() const;
  void applyPortB();
  void handlePlantEvents(Tick t, const plant::EventList& events);
  void sampleUpTo(Tick t);
  void finish(MatchResult& result);

  const MatchConfig& config_;
  vm::CostTable costs_;
  plant::Arena arena_;
  Trace trace_;
  plant::SplitMix64 coin_;
  EventQueue<QueuedEvent> queue_;
  std::vector<std::unique_ptr<Robot>> robots_;
  std::vector<PortBWrite> portBWrites_;
  Tick nextSample_ = 0;
  uint64_t rounds_ = 0;
};

// ---- robot ------------------------------------------------------------------

Robot::Robot(Match& m, int i, const RobotSpec& s, const vm::CostTable& costs, uint64_t seed)
    : spec(s),
      index(i),
      match(m),
      vm_(s.image, *this, costs),
      noise(streamSeed(seed, "eye-noise-" + s.name)),
      mainReturn(s.image.entry + static_cast<uint32_t>(vm::instructionSize(vm::Op::CALL))) {
  result.name = s.name;
  result.program = s.program;
  vm_.setBreakpoint(mainReturn);
}

void Robot::runTo(Tick horizon) {
  while (vm_.now() < horizon) {
    const vm::Stop stop = vm_.run(horizon);
    if (stop == vm::Stop::Fault) {
      if (!result.fault) {
        const vm::Fault* f = vm_.fault();
        result.fault = FaultInfo{f->message, seconds(f->tick), f->line};
        match.trace().add(
            f->tick,
            {{"type", "fault"}, {"robot", spec.name}, {"message", f->message}, {"line", f->line}});
      }
      return;
    }
    if (stop == vm::Stop::Breakpoint && vm_.pc() == mainReturn) {
      result.exited = true;
      result.exitTick = vm_.now();
      match.trace().add(vm_.now(), {{"type", "exit"}, {"robot", spec.name}});
    }
  }
}

void Robot::out(Tick t, uint16_t port, uint8_t value) {
  switch (port) {
    case vm::kPortPIOCA:
      pio.control(value);
      return;
    case vm::kPortPIODA:
      pio.writeData(value);
      return;
    case vm::kPortPIODB:
      match.portB().push_back({t, index, value});
      match.trace().add(t, {{"type", "port_b"}, {"robot", spec.name}, {"value", value}});
      return;
    default:
      return;  // PIOCB set-up, ENB485 and unknown ports have no effect here
  }
}

uint8_t Robot::in(Tick, uint16_t port) {
  if (port == vm::kPortPIODA) return pio.read();
  return 0xFF;
}

int Robot::adSample(Tick t, int channel) {
  const plant::EyeReadings e = match.arena().eyeReadings(index, t, &noise);
  return channel == 0 ? e.left : channel == 1 ? e.right : 0;
}

void Robot::serialSend(Tick t, uint16_t buf, uint16_t cc) {
  match.trace().add(t, {{"type", "serial_send"}, {"robot", spec.name}, {"count", vm_.read8(cc)}});
  link.send(t, buf, cc, *this);
  scheduleSerial();
  updateSerialRequest();
}

void Robot::serialTxService(Tick t, vm::Vm&) {
  link.service(t, *this);
  scheduleSerial();
  updateSerialRequest();
}

void Robot::scheduleSerial() {
  const auto done = link.nextByteDone();
  if (done && *done != serialEventAt) {
    serialEventAt = *done;
    match.queue().schedule(*done, EventClass::SerialByte, {QueuedEvent::Kind::SerialByte, index});
  }
}

void Robot::updateSerialRequest() {
  if (link.requestingInterrupt())
    vm_.request(vm::Irq::SerialTx);
  else
    vm_.cancelRequest(vm::Irq::SerialTx);
}

void Robot::byteDone(Tick t) {
  serialEventAt = -1;
  if (auto frame = link.byteDone(t)) {
    if (frame->command) {
      ++result.framesLatched;
      match.arena().setWheels(index, *frame->command, t);
    } else {
      ++result.framesRejected;
    }
    match.trace().add(t, {{"type", frame->command ? "frame_latched" : "frame_rejected"},
                          {"robot", spec.name},
                          {"bytes", frame->bytes}});
  }
  scheduleSerial();
  updateSerialRequest();
}

void Robot::setEdgeLines(Tick, uint8_t lines) {
  edgeLines = lines;
  if (pio.setInputs(lines)) vm_.request(vm::Irq::Pio, pio.vector());
}

void Robot::console(Tick t, std::string_view line) {
  result.console.emplace_back(line);
  match.trace().add(t, {{"type", "console"}, {"robot", spec.name}, {"text", std::string(line)}});
}

void Robot::interruptAccepted(Tick t, vm::Irq irq, uint32_t pc) {
  ++result.interrupts[std::string(vm::irqName(irq))];
  if (irq == vm::Irq::Pio) pio.accepted();
  if (irq == vm::Irq::SerialTx || !match.trace().enabled()) return;
  const vm::Symbol* fn = spec.image.functionAt(pc);
  match.trace().add(t, {{"type", "interrupt_accepted"},
                        {"robot", spec.name},
                        {"source", vm::irqName(irq)},
                        {"line", spec.image.lineAt(pc)},
                        {"function", fn ? fn->name : ""}});
}

void Robot::interruptReturned(Tick t, vm::Irq irq) {
  if (irq != vm::Irq::Pio) return;
  match.trace().add(
      t, {{"type", "interrupt_returned"}, {"robot", spec.name}, {"source", vm::irqName(irq)}});
  if (pio.returned()) vm_.request(vm::Irq::Pio, pio.vector());
}

// ---- match ------------------------------------------------------------------

Tick Match::earliestClock() const {
  Tick t = INT64_MAX;
  for (const auto& r : robots_)
    if (!r->vm_.fault()) t = std::min(t, r->vm_.now());
  return t == INT64_MAX ? queue_.nextTick() : t;
}

void Match::applyPortB() {
  std::stable_sort(portBWrites_.begin(), portBWrites_.end(),
                   [](const PortBWrite& a, const PortBWrite& b) { return a.tick < b.tick; });
  for (const auto& w : portBWrites_) {
    sampleUpTo(w.tick);
    const plant::EventList immediate = arena_.setPortB(w.robot, w.value, w.tick);
    for (const auto& e : immediate)
      trace_.add(
          w.tick,
          {{"type", plant::eventKindName(e.kind)}, {"robot", name(e.robot)}, {"gun", e.gun}});
  }
  portBWrites_.clear();
}

void Match::handlePlantEvents(Tick t, const plant::EventList& events) {
  for (const auto& e : events) {
    nlohmann::json rec = {{"type", plant::eventKindName(e.kind)}, {"robot", name(e.robot)}};
    switch (e.kind) {
      case plant::EventKind::EdgeEnter:
      case plant::EventKind::EdgeLeave: {
        Robot& r = *robots_[static_cast<size_t>(e.robot)];
        // Fore detector on port A bit 1, aft on bit 0; low within range.
        const uint8_t bit = e.detector == plant::Detector::Fore ? 0x02 : 0x01;
        const uint8_t lines = e.kind == plant::EventKind::EdgeEnter
                                  ? static_cast<uint8_t>(r.edgeLines & ~bit)
                                  : static_cast<uint8_t>(r.edgeLines | bit);
        r.setEdgeLines(t, lines);
        rec["detector"] = e.detector == plant::Detector::Fore ? "fore" : "aft";
        break;
      }
      case plant::EventKind::BallLaunch:
      case plant::EventKind::BallHit:
      case plant::EventKind::BallMiss:
        rec["gun"] = e.gun;
        if (e.other >= 0) rec["target"] = name(e.other);
        break;
      case plant::EventKind::Contact:
      case plant::EventKind::ReflexStart:
      case plant::EventKind::ReflexEnd:
        rec["bumper"] = e.bumper == plant::Bumper::Front ? "front" : "back";
        break;
      default:
        break;
    }
    trace_.add(t, std::move(rec));
  }
}

// Trace samples at fixed ticks, read from dense output once the plant has
// passed them and before any input discards that part of the trajectory.
void Match::sampleUpTo(Tick t) {
  if (!trace_.enabled()) return;
  const Tick limit = std::min(t, arena_.now());
  while (nextSample_ <= limit) {
    if (nextSample_ >= arena_.lastReinitTick()) {
      for (int i = 0; i < arena_.robotCount(); ++i) {
        const plant::RobotState s = arena_.state(i, nextSample_);
        const plant::EyeReadings eyes = arena_.eyeReadings(i, nextSample_);
        trace_.add(nextSample_, {{"type", "sample"},
                                 {"robot", name(i)},
                                 {"x_ft", s.pose.x_ft},
                                 {"y_ft", s.pose.y_ft},
                                 {"heading_deg", s.pose.heading_deg},
                                 {"left_fps", s.left_fps},
                                 {"right_fps", s.right_fps},
                                 {"eye_left", eyes.left},
                                 {"eye_right", eyes.right}});
      }
    }
    nextSample_ += config_.sampleInterval;
  }
}

MatchResult Match::run() {
  MatchResult result;
  bool over = false;
  while (!over) {
    ++rounds_;
    const Tick t = earliestClock();
    Tick horizon = std::min(queue_.nextTick(), t + kLookahead);
    plant::AdvanceResult step = arena_.advance(horizon);
    horizon = step.tick;
    for (auto& r : robots_) r->runTo(horizon);
    if (!portBWrites_.empty()) {
      applyPortB();
      // A re-initialisation discarded the plant's prediction: find it again.
      while (arena_.now() < horizon) {
        step = arena_.advance(horizon);
        if (step.tick < horizon) {
          sampleUpTo(step.tick);
          handlePlantEvents(step.tick, step.events);
        }
      }
    }
    sampleUpTo(horizon);
    handlePlantEvents(horizon, step.events);
    while (!queue_.empty() && queue_.nextTick() == horizon) {
      const auto entry = queue_.pop();
      switch (entry.payload.kind) {
        case QueuedEvent::Kind::SerialByte:
          sampleUpTo(horizon);
          robots_[static_cast<size_t>(entry.payload.robot)]->byteDone(horizon);
          break;
        case QueuedEvent::Kind::EndOfRound:
          over = true;
          break;
      }
    }
    if (config_.stopWhenAllExited && std::all_of(robots_.begin(), robots_.end(), [](const auto& r) {
          return r->result.exited || r->vm_.fault();
        })) {
      over = true;
    }
    if (over) {
      result.endTick = horizon;
      sampleUpTo(horizon);
    }
  }
  finish(result);
  return result;
}

void Match::finish(MatchResult& result) {
  result.rounds = rounds_;
  result.integrator = arena_.stats();
  for (auto& r : robots_) {
    RobotResult rr = r->result;
    rr.hits = arena_.hits(r->index);
    rr.shots = arena_.shots(r->index);
    rr.cycles = static_cast<uint64_t>(r->vm_.now());
    for (vm::Irq irq : {vm::Irq::Pio, vm::Irq::SerialTx})
      rr.interrupts.emplace(std::string(vm::irqName(irq)), 0);
    rr.finalPose = arena_.pose(r->index, std::min(result.endTick, arena_.now()));
    result.robots.push_back(std::move(rr));
  }
  if (result.robots.size() == 2) {
    const int a = result.robots[0].hits, b = result.robots[1].hits;
    if (a != b) {
      result.winner = a > b ? "A" : "B";
    } else {
      result.tieBrokenByCoin = true;
      result.winner = (coin_.next() >> 63) ? "B" : "A";
    }
  }
  result.trace = trace_.lines();
}

}  // namespace

uint64_t streamSeed(uint64_t seed, const std::string& purpose) {
  // FNV-1a of the purpose, mixed with the master seed through SplitMix64.
  uint64_t h = 1469598103934665603ull;
  for (char c : purpose) h = (h ^ static_cast<uint8_t>(c)) * 1099511628211ull;
  plant::SplitMix64 mix(seed ^ h);
  return mix.next();
}

MatchResult runMatch(const MatchConfig& config) {
  Match match(config);
  return match.run();
}

}  // namespace simbot::scheduler
