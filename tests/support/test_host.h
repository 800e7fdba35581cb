// A host for VM tests: a Bus with fixed eye readings, a simple serial port
// model (one transmit interrupt per byte after the first, 9,600 ticks apart,
// the service routine fetching from robot memory and decrementing *cc) and
// requests scheduled at exact ticks. The product's serial link and devices
// live in plant/ and scheduler/; this is only enough to drive the VM.
#pragma once
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "compiler/compiler.h"
#include "timebase/tick.h"
#include "vm/vm.h"

namespace simbot::testkit {

using vm::Irq;
using vm::Tick;

using timebase::kTicksPerChar;

struct Access {
  Tick tick;
  uint16_t port;
  uint8_t value;
};

struct Event {
  Tick tick;
  Irq irq;
  uint32_t pc;  // interrupted pc (accepted) or 0 (returned)
  bool accepted;
};

class TestHost : public vm::Bus {
 public:
  int eye[2] = {16, 16};
  uint8_t pioA = 0xFF;
  std::vector<std::string> consoleLines;
  std::vector<Tick> consoleTicks;  // each line's tick
  std::vector<Access> outs;
  std::vector<Tick> sends;
  std::vector<Event> events;
  std::vector<std::string> sentBytes;  // bytes fetched per send
  uint8_t pioVector = vm::kVecPIOA;

  // A request at `tick`; from inside a bus call the run stops at the next
  // boundary so that runUntil raises it on time.
  void schedule(Tick tick, Irq irq) {
    scheduled_.emplace(tick, irq);
    if (running_) running_->stopAtNextBoundary();
  }

  void out(Tick t, uint16_t port, uint8_t value) override { outs.push_back({t, port, value}); }
  uint8_t in(Tick, uint16_t port) override { return port == vm::kPortPIODA ? pioA : 0xFF; }
  int adSample(Tick, int channel) override { return eye[channel & 1]; }
  void serialSend(Tick t, uint16_t buf, uint16_t cc) override {
    sends.push_back(t);
    buf_ = buf;
    cc_ = cc;
    next_ = 1;
    sentBytes.emplace_back();
    // The library put buf[0] in the shift register; the data register is
    // empty at once, so the first transmit interrupt is requested at T0.
    schedule(t, Irq::SerialTx);
  }
  void serialTxService(Tick t, vm::Vm& v) override {
    const uint8_t cc = v.read8(cc_);
    if (cc <= 1) return;  // nothing left: the library disables the interrupt
    sentBytes.back().push_back(static_cast<char>(v.read8(static_cast<uint16_t>(buf_ + next_))));
    v.write8(cc_, static_cast<uint8_t>(cc - 1));
    ++next_;
    // The byte just loaded moves to the shift register when the previous
    // one has gone; then the data register is empty again.
    schedule(sends.back() + kTicksPerChar * (next_ - 1), Irq::SerialTx);
    (void)t;
  }
  void console(Tick t, std::string_view line) override {
    consoleLines.emplace_back(line);
    consoleTicks.push_back(t);
  }
  void interruptAccepted(Tick t, Irq irq, uint32_t pc) override {
    events.push_back({t, irq, pc, true});
  }
  void interruptReturned(Tick t, Irq irq) override { events.push_back({t, irq, 0, false}); }

  // Runs the VM to `end`, raising scheduled requests at their exact ticks.
  vm::Stop runUntil(vm::Vm& v, Tick end) {
    for (;;) {
      Tick horizon = end;
      if (!scheduled_.empty()) horizon = std::min(horizon, scheduled_.begin()->first);
      running_ = &v;
      const vm::Stop stop = v.run(horizon);
      running_ = nullptr;
      if (stop == vm::Stop::Fault || stop == vm::Stop::Breakpoint) return stop;
      while (!scheduled_.empty() && scheduled_.begin()->first <= v.now()) {
        const Irq irq = scheduled_.begin()->second;
        v.request(irq, irq == Irq::Pio ? pioVector : 0);
        scheduled_.erase(scheduled_.begin());
      }
      if (v.now() >= end && (scheduled_.empty() || scheduled_.begin()->first > v.now()))
        return stop;
      const bool requestPending =
          v.pending(Irq::Pio) || v.pending(Irq::SerialTx) || v.pending(Irq::Timer);
      if (stop == vm::Stop::Halted && scheduled_.empty() && !requestPending) return stop;
    }
  }

 private:
  std::multimap<Tick, Irq> scheduled_;
  vm::Vm* running_ = nullptr;  // the VM in run() (for schedule())
  uint16_t buf_ = 0, cc_ = 0;
  uint32_t next_ = 1;
};

// The calibrated cycle table, built once for all tests of a binary.
inline const vm::CostTable& calibratedCosts() {
  static const vm::CostTable table = vm::makeCostTable(vm::calibratedKnobs());
  return table;
}
// One opcode's T-states in that table.
inline uint32_t calibratedCost(vm::Op op) { return calibratedCosts().op[static_cast<int>(op)]; }

// Compiles a program or fails the test with the diagnostic.
inline vm::Image compileOrDie(const std::string& source, const std::string& name = "test.dc") {
  auto r = compiler::compile(source, name);
  if (!r.image)
    throw std::runtime_error(r.errors.empty() ? "compile failed" : r.errors[0].format());
  return std::move(*r.image);
}

// Compiles a program file or fails the test with the diagnostic.
inline vm::Image compileFileOrDie(const std::string& path) {
  auto r = compiler::compileFile(path);
  if (!r.image)
    throw std::runtime_error(r.errors.empty() ? "compile failed" : r.errors[0].format());
  return std::move(*r.image);
}

inline const vm::Symbol& symbol(const vm::Image& img, const std::string& name) {
  for (const auto& s : img.symbols)
    if (s.name == name) return s;
  throw std::runtime_error("no symbol " + name);
}

}  // namespace simbot::testkit
