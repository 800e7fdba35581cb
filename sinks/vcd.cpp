// The VCD sink (see vcd.h). Records arrive in tick order; a record may also
// imply changes later on (a serial byte's bits, the end of a serial
// interrupt), which wait in a queue ordered by (tick, sequence). Changes at
// one tick are coalesced: only a signal's last value at a tick, and only if
// it differs from what was written, goes to the file.
#include "sinks/vcd.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstring>
#include <queue>
#include <type_traits>
#include <vector>

#include "plant/plant.h"
#include "sinks/user_error.h"
#include "timebase/tick.h"

namespace simbot::sinks {

namespace {

enum Wire : int {
  kTxd,
  kRs485,
  kEdgeFore,
  kEdgeAft,
  kPortB0,  // .. kPortB0 + 7
  kIff1 = kPortB0 + 8,
  kInPio,
  kInSerial,
  kLeftCmd,
  kRightCmd,
  kEyeLeft,
  kEyeRight,
  kConsole,
  kReset,  // held in reset (reset record to restart record; an injected one: one tick)
  kSignalsPerRobot
};

struct Signal {
  std::string name;
  bool real = false;
  std::string id;
  std::string written;  // value last written to the file
  std::string now;      // value at the current tick
};

struct RobotState {
  bool iff = true;  // Dynamic C's BIOS runs main with interrupts enabled
  int pioDepth = 0;
  int serialDepth = 0;
  std::int64_t consoleLines = 0;
  trace::Tick resetAt = -1;  // the latest reset record's tick
};

struct Later {
  trace::Tick tick;
  std::uint64_t seq;
  enum Kind : std::uint8_t { SetWire, SerialIsrEnd } kind;
  int robot;
  int signal;
  char value;
  friend bool operator>(const Later& a, const Later& b) {
    return a.tick != b.tick ? a.tick > b.tick : a.seq > b.seq;
  }
};

std::string idFor(int n) {
  std::string id;
  do {
    id.push_back(static_cast<char>('!' + n % 94));
    n /= 94;
  } while (n > 0);
  return id;
}

std::string realValue(std::int64_t v) { return fmt::format("r{}", v); }

}  // namespace

struct VcdSink::State {
  std::FILE* file = nullptr;
  bool headerDone = false;
  int robots = 0;
  std::array<std::array<std::string, 8>, 2> portBNames{};
  std::vector<Signal> signals;
  std::array<RobotState, 2> robot{};
  std::priority_queue<Later, std::vector<Later>, std::greater<>> later;
  std::uint64_t seq = 0;
  trace::Tick tick = 0;  // the tick whose changes are being gathered
  std::vector<int> touched;
  trace::Tick lastTick = 0;
  trace::Tick endTick = -1;  // the run's end, from its end record
  trace::Tick stamped = 0;   // the last time written to the file

  Signal& sig(int robotIndex, int wire) {
    return signals[static_cast<size_t>(robotIndex * kSignalsPerRobot + wire)];
  }
  void set(int robotIndex, int wire, std::string value) {
    const int index = robotIndex * kSignalsPerRobot + wire;
    Signal& s = signals[static_cast<size_t>(index)];
    if (s.now == value) return;
    s.now = std::move(value);
    touched.push_back(index);
  }
  void setIff(int r) {
    const RobotState& st = robot[static_cast<size_t>(r)];
    set(r, kIff1, st.iff && st.serialDepth == 0 ? "1" : "0");
  }
  // Writes the changes gathered at the current tick.
  void flushTick() {
    bool stampedNow = false;
    for (int index : touched) {
      Signal& s = signals[static_cast<size_t>(index)];
      if (s.now == s.written) continue;
      if (!stampedNow) {
        std::fprintf(file, "#%lld\n", static_cast<long long>(timebase::picosecondsFromTicks(tick)));
        stampedNow = true;
        stamped = tick;
      }
      s.written = s.now;
      if (s.real)
        std::fprintf(file, "%s %s\n", s.now.c_str(), s.id.c_str());
      else
        std::fprintf(file, "%s%s\n", s.now.c_str(), s.id.c_str());
    }
    touched.clear();
  }
  // Moves the clock to t: changes due before t are applied at their ticks.
  void advanceTo(trace::Tick t) {
    while (!later.empty() && later.top().tick < t) {
      const Later l = later.top();
      later.pop();
      at(l.tick);
      apply(l);
    }
    at(t);
  }
  void at(trace::Tick t) {
    if (t == tick) return;
    flushTick();
    tick = t;
  }
  void apply(const Later& l) {
    if (l.kind == Later::SetWire) {
      set(l.robot, l.signal, std::string(1, l.value));
    } else {
      RobotState& st = robot[static_cast<size_t>(l.robot)];
      if (st.serialDepth > 0) --st.serialDepth;
      set(l.robot, kInSerial, st.serialDepth > 0 ? "1" : "0");
      setIff(l.robot);
    }
  }
  // Changes at t that happen at the same tick as (and after) the record.
  void applyDue(trace::Tick t) {
    while (!later.empty() && later.top().tick <= t) {
      const Later l = later.top();
      later.pop();
      apply(l);
    }
  }
  void schedule(trace::Tick t, Later::Kind kind, int r, int signal = 0, char value = 0) {
    later.push(Later{t, seq++, kind, r, signal, value});
  }

  void declareSignals();
  void header();
  void record(const trace::Entry& e);
};

// Names of the signals other than port B's bits.
constexpr std::pair<int, const char*> kWireNames[] = {{kTxd, "txd"},
                                                      {kRs485, "rs485_enable"},
                                                      {kEdgeFore, "edge_fore"},
                                                      {kEdgeAft, "edge_aft"},
                                                      {kIff1, "iff1"},
                                                      {kInPio, "in_pio_a"},
                                                      {kInSerial, "in_serial_tx"},
                                                      {kLeftCmd, "left_cmd"},
                                                      {kRightCmd, "right_cmd"},
                                                      {kEyeLeft, "eye_left"},
                                                      {kEyeRight, "eye_right"},
                                                      {kConsole, "console_lines"},
                                                      {kReset, "reset"}};

// Every robot's signals, with their power-on values, then the header.
void VcdSink::State::declareSignals() {
  if (robots == 0) throw UserError("simbot: --vcd: the trace has no run record\n");
  signals.resize(static_cast<size_t>(robots * kSignalsPerRobot));
  int n = 0;
  for (int r = 0; r < robots; ++r) {
    for (const auto& [w, name] : kWireNames) sig(r, w).name = name;
    for (int bit = 0; bit < 8; ++bit) {
      const std::string& bound = portBNames[static_cast<size_t>(r)][static_cast<size_t>(bit)];
      sig(r, kPortB0 + bit).name = bound.empty() ? fmt::format("portb{}", bit) : bound;
    }
    for (int w = 0; w < kSignalsPerRobot; ++w) {
      Signal& s = sig(r, w);
      s.real = w >= kLeftCmd && w <= kConsole;
      s.id = idFor(n++);
      const bool high = w == kTxd || w == kEdgeFore || w == kEdgeAft || w == kIff1;
      s.written = s.now = s.real ? "r0" : high ? "1" : "0";
    }
  }
  header();
}

void VcdSink::State::header() {
  headerDone = true;
  const char* names[] = {"A", "B"};
  std::fprintf(
      file,
      "$version simbot $end\n"
      "$comment\n"
      "  simbot run: one tick of the 9.216 MHz clock is 1e12 / 9216000 = 108506.944... ps;\n"
      "  tick t is written at round(t * 1e12 / 9216000) ps (nearest picosecond, halves up).\n"
      "  Multi-bit values are real variables holding integers.\n"
      "$end\n"
      "$timescale 1ps $end\n");
  for (int r = 0; r < robots; ++r) {
    std::fprintf(file, "$scope module %s $end\n", names[r]);
    for (int w = 0; w < kSignalsPerRobot; ++w) {
      Signal& s = sig(r, w);
      std::fprintf(file, "$var %s %s %s_%s $end\n", s.real ? "real 64" : "wire 1", s.id.c_str(),
                   names[r], s.name.c_str());
    }
    std::fprintf(file, "$upscope $end\n");
  }
  std::fprintf(file, "$enddefinitions $end\n$dumpvars\n");
  for (Signal& s : signals) {
    if (s.real)
      std::fprintf(file, "%s %s\n", s.written.c_str(), s.id.c_str());
    else
      std::fprintf(file, "%s%s\n", s.written.c_str(), s.id.c_str());
  }
  std::fprintf(file, "$end\n");
}

void VcdSink::State::record(const trace::Entry& e) {
  namespace rec = trace::rec;
  if (std::holds_alternative<rec::End>(e.record)) endTick = e.t;
  const auto* run = std::get_if<rec::Run>(&e.record);
  if (run) {
    robots = static_cast<int>(std::clamp<std::int64_t>(run->robots, 1, 2));
    return;
  }
  if (const auto* setup = std::get_if<rec::RobotSetup>(&e.record)) {
    auto& names = portBNames[static_cast<size_t>(setup->robot & 1)];
    const std::pair<std::int64_t, const char*> bound[] = {
        {setup->gun1_motor_bit, "gun1_motor"},
        {setup->gun1_solenoid_bit, "gun1_solenoid"},
        {setup->gun2_motor_bit, "gun2_motor"},
        {setup->gun2_solenoid_bit, "gun2_solenoid"},
        {setup->disc_shooter_bit, "disc_shooter"}};
    for (const auto& [bit, name] : bound)
      if (bit >= 0 && bit < 8 && names[static_cast<size_t>(bit)].empty())
        names[static_cast<size_t>(bit)] = name;
    return;
  }
  // The set-up records at t = 0 before the first that moves a signal: the
  // disc launcher's bit gets its name; rules and obstacles move none.
  if (const auto* secondary = std::get_if<rec::Secondary>(&e.record)) {
    if (secondary->bit >= 0 && secondary->bit < 8)
      portBNames[static_cast<size_t>(secondary->robot & 1)][static_cast<size_t>(secondary->bit)] =
          "disc_launcher";
    return;
  }
  // A deployables table's bit: "deploy_" and its kind (deploy_block).
  if (const auto* table = std::get_if<rec::Deployables>(&e.record)) {
    if (table->bit >= 0 && table->bit < 8)
      portBNames[static_cast<size_t>(table->robot & 1)][static_cast<size_t>(table->bit)] =
          "deploy_" + table->kind;
    return;
  }
  if (std::holds_alternative<rec::Rules>(e.record) ||
      std::holds_alternative<rec::Obstacle>(e.record))
    return;
  if (!headerDone) declareSignals();
  advanceTo(e.t);
  applyDue(e.t);
  lastTick = std::max(lastTick, e.t);
  const int r = trace::robotOf(e.record);
  if (r < 0 || r >= robots) return;
  RobotState& st = robot[static_cast<size_t>(r)];
  std::visit(
      [&](const auto& x) {
        using R = std::remove_cvref_t<decltype(x)>;
        if constexpr (std::is_same_v<R, rec::SerialByte>) {
          const auto byte = static_cast<unsigned>(x.byte);
          set(r, kTxd, "0");  // start bit
          for (int bit = 0; bit < 8; ++bit)
            schedule(e.t + timebase::kTicksPerBit * (bit + 1), Later::SetWire, r, kTxd,
                     ((byte >> bit) & 1) ? '1' : '0');
          schedule(e.t + timebase::kTicksPerBit * 9, Later::SetWire, r, kTxd, '1');  // stop bit
        } else if constexpr (std::is_same_v<R, rec::SerialIsr>) {
          ++st.serialDepth;
          set(r, kInSerial, "1");
          setIff(r);
          schedule(x.end_t, Later::SerialIsrEnd, r);
        } else if constexpr (std::is_same_v<R, rec::Iff1>) {
          st.iff = x.enabled;
          setIff(r);
        } else if constexpr (std::is_same_v<R, rec::InterruptAccepted>) {
          if (x.source == "pio_a") {
            ++st.pioDepth;
            set(r, kInPio, "1");
          }
        } else if constexpr (std::is_same_v<R, rec::InterruptReturned>) {
          if (x.source == "pio_a" && st.pioDepth > 0 && --st.pioDepth == 0) set(r, kInPio, "0");
        } else if constexpr (std::is_same_v<R, rec::PortA>) {
          set(r, kEdgeFore, (x.value & 0x02) ? "1" : "0");
          set(r, kEdgeAft, (x.value & 0x01) ? "1" : "0");
        } else if constexpr (std::is_same_v<R, rec::PortB>) {
          for (int bit = 0; bit < 8; ++bit)
            set(r, kPortB0 + bit, ((x.value >> bit) & 1) ? "1" : "0");
        } else if constexpr (std::is_same_v<R, rec::Rs485>) {
          set(r, kRs485, x.value != 0 ? "1" : "0");
        } else if constexpr (std::is_same_v<R, rec::FrameLatched>) {
          if (const auto frame = plant::parseMotorFrame(x.bytes)) {
            const auto step = [](const plant::WheelCommand& c) {
              return static_cast<std::int64_t>(c.go ? (c.forward ? c.speed : -c.speed) : 0);
            };
            set(r, kLeftCmd, realValue(step(frame->left)));
            set(r, kRightCmd, realValue(step(frame->right)));
          }
        } else if constexpr (std::is_same_v<R, rec::AdRead>) {
          set(r, x.channel == 0 ? kEyeLeft : kEyeRight, realValue(x.value));
        } else if constexpr (std::is_same_v<R, rec::Console>) {
          set(r, kConsole, realValue(++st.consoleLines));
        } else if constexpr (std::is_same_v<R, rec::Reset>) {
          st.resetAt = e.t;
          set(r, kReset, "1");
        } else if constexpr (std::is_same_v<R, rec::Restart>) {
          // An injected reset restarts at its own tick: held one tick, so
          // that the pulse shows.
          if (e.t > st.resetAt)
            set(r, kReset, "0");
          else
            schedule(e.t + 1, Later::SetWire, r, kReset, '0');
        }
      },
      e.record);
}

VcdSink::VcdSink(const std::string& path) : path_(path), s_(new State) {
  try {
    file_ = out_.emplace(path).file();
  } catch (const files::Error& e) {
    delete s_;
    throw UserError(fmt::format("simbot: cannot write VCD '{}': {}\n", path, e.what()));
  }
  s_->file = file_;
}

VcdSink::~VcdSink() { delete s_; }

void VcdSink::write(const trace::Entry& entry) {
  s_->record(entry);
  if (std::ferror(file_))
    throw UserError(fmt::format("simbot: writing VCD '{}': {}\n", path_, std::strerror(errno)));
}

void VcdSink::close() {
  if (!file_) return;
  State& s = *s_;
  // The changes still queued (the last byte's bits, an interrupt's end)
  // up to the run's end, then its last tick, so that viewers show the
  // whole run and nothing after it.
  while (!s.later.empty() && (s.endTick < 0 || s.later.top().tick <= s.endTick)) {
    const Later l = s.later.top();
    s.later.pop();
    s.at(l.tick);
    s.apply(l);
    s.lastTick = std::max(s.lastTick, l.tick);
  }
  s.flushTick();
  if (s.headerDone && s.lastTick > s.stamped)
    std::fprintf(file_, "#%lld\n",
                 static_cast<long long>(timebase::picosecondsFromTicks(s.lastTick)));
  file_ = nullptr;
  try {
    out_->commit();
  } catch (const files::Error& e) {
    throw UserError(fmt::format("simbot: writing VCD '{}': {}\n", path_, e.what()));
  }
}

}  // namespace simbot::sinks
