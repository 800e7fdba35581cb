// The cycle-counted VM: runs one robot's Image against an I/O bus that the
// host implements. It knows nothing of robots; it sees port reads and writes,
// A/D samples, the serial library's hooks and interrupt requests.
//
// Time is the robot's clock in ticks of 9.216 MHz (one Z180 T-state). Every
// instruction and library step adds its cost from the CostTable.
//
// Interrupts (DESIGN.md "Interrupts"): a request made at tick c is accepted
// at the first instruction boundary b >= c at which IFF1 is set (never
// inside the instruction after EI: the EI shadow). Acceptance clears
// IFF1/IFF2, pushes the interrupted state and charges the acceptance cost;
// the handler's first instruction starts at b + that cost. RETI restores,
// and the compiler's epilogue sets IFF1 again unless the knob drops it.
// Pending requests are taken in the Z180's fixed priority order: the PIO
// (INT0), then PRT0 (the timer), then the ASCI (serial transmit). Long
// library calls run as steps of <= 100 T-states with a boundary between
// steps, their inner loops one unit (a byte) a step, and a struct
// assignment one byte a step, as the Z180's LDIR; a handler accepted there
// resumes the call or the copy when it returns. The
// serial library's calls are atomic (cost_sums.h kLibAtomic): no boundary inside
// them, and IFF1 after them is what it was before.
//
// The timer: when the program uses the timer library (Image::timer) or the
// knob says always, PRT0 requests Irq::Timer every kPrtTicks from the VM's
// power-on (or reset) tick (9.216 MHz / 20 / 450 = 1,024 Hz). The BIOS
// service runs atomically at acceptance like the serial library's ISR, costs
// CostTable::timerIsr and advances TICK_TIMER, MS_TIMER and SEC_TIMER in
// robot memory. A request not yet accepted when the next tick comes is the
// same request (PRT0's TIF0 is one flag): that tick is lost, as on the chip.
#pragma once
#include <algorithm>
#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "timebase/tick.h"
#include "vm/cost.h"
#include "vm/image.h"

namespace simbot::vm {

// The clock is defined once, in timebase/tick.h.
using timebase::kTicksPerSecond;
using timebase::Tick;

// Interrupt sources in the Z180's priority order (0 = highest): INT0 (the
// PIO), PRT0 (the timer), ASCI (the serial port).
enum class Irq : uint8_t { Pio = 0, Timer = 1, SerialTx = 2 };
inline constexpr int kIrqCount = 3;
// The most a run ends after its `until` (Vm::run): an instruction, or a
// step of a long one, is at most this long; but not after an atomic
// library call (the serial library's DI ... restore sequences), charged
// whole with no boundary inside (185 ticks past, measured).
inline constexpr Tick kMaxRunOvershoot = 100;
std::string_view irqName(Irq irq);  // "pio_a", "timer", "serial_tx"

class Vm;

// A host that knows, when a run reaches its horizon, where the next one
// would be with nothing happening in between (the scheduler's next
// sub-round of a robot that runs alone): the run goes on to it at once,
// exactly as a new run() from there would.
class Continuation {
 public:
  // `horizon`: where the host keeps the run's horizon, which nextHorizon
  // moves and so does the VM when it takes one without asking.
  explicit Continuation(Tick& runHorizon) : horizon(runHorizon) {}
  Tick& horizon;

  // Called at the boundary where the run reached `reached` (the VM's
  // now() and quietUntil() are its own there): the next horizon, or one
  // at or before now() to end the run.
  virtual Tick nextHorizon(Tick reached) = 0;

  // The horizons the run takes without asking: while the VM has made no
  // bus call since nextHorizon last answered (nothing the host holds has
  // changed, since nothing else runs meanwhile), reaches a horizon before
  // `cap` and is not quiet past its clock, the next one is
  // min(cap, now() + step), which nextHorizon would have given. A host
  // sets them in nextHorizon; the first horizon of every run() always
  // asks (the host may have acted between runs, after a breakpoint).
  // (Each one taken so is a return to the host's loop saved:
  // bench/programs/histogram.dc's 548,000 horizons cost it 9 % of its CPU
  // time.)
  Tick cap = INT64_MIN;
  Tick step = 0;
  // And only up to `unaskedUpTo`, the latest next horizon the host gives
  // as the rule above says (where a later one, not the cap, would change
  // its answer: another robot that would stop sitting sub-rounds out).
  Tick unaskedUpTo = INT64_MAX;
  uint64_t taken = 0;  // horizons taken without asking
  // Whether the horizon `reached` may be left behind without asking at a
  // boundary at `clock`, the VM having made no bus call since the last
  // answer (`touchedHost`).
  bool mayTakeUnasked(Tick reached, Tick clock, bool touchedHost) const {
    return !touchedHost && reached < cap && unaskedAfter(clock) <= unaskedUpTo;
  }
  // The next horizon taken without asking at a boundary at `clock`.
  Tick takeUnasked(Tick clock) {
    ++taken;
    horizon = unaskedAfter(clock);
    return horizon;
  }
  // The horizon the rule above gives after a boundary at `clock`.
  Tick unaskedAfter(Tick clock) const { return std::min(cap, clock + step); }

 protected:
  ~Continuation() = default;
};

// What the host provides. Every call carries the exact tick of the access.
class Bus {
 public:
  virtual ~Bus() = default;
  virtual void out(Tick t, uint16_t port, uint8_t value) = 0;
  virtual uint8_t in(Tick t, uint16_t port) = 0;
  // ad_rd8(channel): the value it returns, sampled at t, the start of the
  // conversion.
  virtual int adSample(Tick t, int channel) = 0;
  virtual void hvEnable(Tick) {}
  virtual void serialInit(Tick, int /*mode*/, int /*baudDivisor*/) {}
  // ser_send_z1 returned at t (T0) having pointed the library at buf/cc.
  virtual void serialSend(Tick, uint16_t /*buf*/, uint16_t /*ccAddress*/) {}
  // The serial library's transmit interrupt service, running at t (after
  // acceptance); it reads the next byte from robot memory through vm.
  virtual void serialTxService(Tick, Vm&) {}
  virtual void console(Tick, std::string_view /*line*/) {}
  // Notifications for traces and device logic (PIO "under service").
  virtual void interruptAccepted(Tick, Irq, uint32_t /*interruptedPc*/) {}
  virtual void interruptReturned(Tick, Irq) {}
  // IFF1 changed at t: EI, DI, a handler's acceptance or its RETI (the
  // serial library's own interrupt leaves IFF1 as it was).
  virtual void iffChanged(Tick, bool /*iff1*/) {}
  // A costatement (its CoData at `coData`) was entered, yielded (a yield,
  // or a waitfor whose expression was false) or ended (its closing brace or
  // abort), at t; `line` is the source line it resumes at, yields at or ends
  // at. Called only after wantCostateEvents() answered true.
  enum class CostateEvent : uint8_t { Enter, Yield, End };
  virtual bool wantCostateEvents() const { return false; }
  virtual void costate(Tick, uint16_t /*coData*/, CostateEvent, int /*line*/) {}
};

struct Fault {
  std::string message;
  Tick tick = 0;
  int line = 0;
  uint32_t pc = 0;  // the faulting instruction's address
  bool operator==(const Fault&) const = default;
};

enum class Stop : uint8_t {
  Horizon,     // reached `until`: the next instruction starts at or after it
  Halted,      // main returned (interrupts still run on later calls)
  Host,        // a bus call asked for a stop (stopAtNextBoundary)
  Fault,       // the robot faulted; it never runs again
  Breakpoint,  // the next instruction is at a breakpoint; run() again to go on
};

struct VmStats {
  uint64_t instructions = 0;  // bytecode instructions and library steps
  // Of those, the ones fast-forward applied without dispatching them.
  uint64_t fastForwarded = 0;
  std::array<uint64_t, kIrqCount> interrupts{};
  bool operator==(const VmStats&) const = default;
};

class Vm {
 public:
  // Powered on at tick `start` of the host's clock: the program at its
  // entry, memory as the image initialises it, PRT0's first tick at
  // start + kPrtTicks.
  // The image and the costs are decoded once (the program: code, cost
  // table, decode tables), and shared read-only by every copy.
  Vm(const Image& image, Bus& bus, const CostTable& costs, Tick start = 0);
  ~Vm();
  // A VM is a value apart from the program it runs and the bus it talks
  // to: a copy holds all of the other's state (memory, registers, stacks,
  // pending requests, clock, breakpoints, counters), shares its program,
  // and talks to no bus until attach() (it runs only then). Copied into
  // another VM, or restored from a copy, it goes on byte for byte as the
  // original would. A copy holds only the expression stack's slots in use.
  Vm(const Vm& other);
  // A copy that talks to `bus`.
  Vm(const Vm& other, Bus& bus);
  // This VM takes `other`'s state and keeps talking to its own bus.
  Vm& operator=(const Vm& other);
  void restore(const Vm& snapshot);
  void attach(Bus& bus);
  // The same program (the same decode tables, not a copy of them).
  bool sharesProgram(const Vm& other) const;
  // The controller's reset at `t` (a reload): the machine as a VM powered
  // on at t; its breakpoints, its profile switch and its counters (stats,
  // profile, interrupt service cycles) carry on over the whole run.
  void reset(Tick t);
  // Same state: every part of the machine and the counters, for the same
  // image (by address); the bus it talks to and the caches a run builds
  // aside. sameMachine leaves the counters out.
  bool operator==(const Vm& other) const;
  bool sameMachine(const Vm& other) const;
  // sameMachine less what fast-forward learns as it runs (a delay loop's
  // measured pass, a measurement under way) and whether the VM stopped at
  // its breakpoint last: a state reached by another path (a debugger's
  // replay from a snapshot) has the same memory, registers, stacks,
  // requests and clock, and goes on the same.
  bool sameProgramState(const Vm& other) const;

  // Executes every instruction that starts before `until` (so it stops
  // less than kMaxRunOvershoot ticks after it but after an atomic library
  // call: no other step of an instruction is longer). A bus access
  // does not end the run: what the host does on one (a port B write, a
  // send) takes effect in the plant or the queue at the end of the host's
  // round, not inside it, so stopping there bought nothing (160,000 of
  // the 412,000 runs of the 180-s ICEMAN vs fig92 match did).
  // With `more`, the run goes on past `until` as long as it gives a later
  // horizon (not while halted: a halted robot's run ends at its horizon).
  Stop run(Tick until, Continuation* more = nullptr);
  // From inside a bus call: end the run at the next instruction boundary
  // (Stop::Host), for a host that must look at what the call did before
  // the VM goes on, such as a test host with no lookahead of its own.
  void stopAtNextBoundary();

  // A tick before which this VM, left alone, neither touches the bus nor
  // accepts an interrupt: now() in general; later while it runs a delay
  // loop that fast-forward has measured (the arrival at its top where the
  // compare fails, or PRT0's next tick if sooner). A request the host
  // raises makes it now() again.
  Tick quietUntil() const;

  // Raise a request now (at now()); it stays pending until accepted. For
  // vectored sources the vector byte selects the #INT_VEC handler.
  void request(Irq irq, uint8_t vector = 0);
  void cancelRequest(Irq irq);
  bool pending(Irq irq) const;

  Tick now() const { return *clock_; }
  bool halted() const;
  // While halted: the tick its HALT ended (it idles from there).
  Tick haltedSince() const;
  const Fault* fault() const { return *fault_ ? &**fault_ : nullptr; }  // null unless faulted
  bool interruptsEnabled() const;
  // The instruction, library call or interrupt acceptance under way at the
  // current boundary: a long library call's own address while it runs.
  uint32_t pc() const;
  int line() const;            // source line of pc()
  int interruptDepth() const;  // handlers in service (nested ones count)
  int callDepth() const;       // calls not yet returned from
  // The calls and handlers the program is inside, outermost first, for
  // trace records and messages (it allocates: not for the hot path). A
  // call not yet returned from gives an address inside its CALL (its
  // return address less one: the line table covers every byte); a handler
  // in service, the instruction it interrupted (`interrupted`), where it
  // nests among the calls. The current instruction is not among them.
  struct Frame {
    uint32_t at;
    bool interrupted;
  };
  std::vector<Frame> frames() const;
  // The same calls and handlers as a debugger walks them, innermost first,
  // the current instruction's function first: where each one is (pc(), or
  // the CALL it made, or the instruction its handler interrupted) and its
  // frame pointer IX (its autos are at fp + their offset), valid once its
  // function's ENTER has run (`framed`; a function without one has none).
  // `handler`: the activation is an interrupt handler's.
  struct Activation {
    uint32_t pc;
    uint32_t fp;
    bool framed;
    bool handler;
  };
  std::vector<Activation> activations() const;
  // The expression stack's depth in slots, and its top slots (for a
  // debugger's `info registers`).
  int evalDepth() const;
  // A library call is under way (its steps have boundaries between them).
  bool inLibraryCall() const;
  // A library call's effect (what it does to the bus, the serial library,
  // memory) is due now: run() stopped at the call's last tick, where the
  // host's events of that tick come first. settle() makes it happen, as the
  // next run() would before anything else; the robot then stands at the
  // instruction boundary after the call (a debugger's step ends there).
  bool effectPending() const;
  void settle();
  uint32_t evalSlot(int fromTop) const;

  // The LIB instruction of the latest library call: during a routine's
  // bus access (Bus::serialSend, ...) the call that made it, which pc() is
  // no longer once the routine's effect has begun.
  uint32_t libraryCallPc() const;

  // Power-on RAM from a random stream (a profile option, DESIGN.md): every
  // byte from kDataBase up that the image does not initialise is replaced,
  // eight bytes per call of `next`, in address order. After power-on or
  // reset(), before the next run().
  void fillMemory(const std::function<uint64_t()>& next);

  // Robot memory, for the host (serial ISR, tests, watches).
  uint8_t read8(uint16_t address) const;
  void write8(uint16_t address, uint8_t value);
  uint16_t read16(uint16_t address) const;
  uint32_t read32(uint16_t address) const;

  const VmStats& stats() const;
  const Image& image() const;
  const CostTable& costs() const;  // what it charges (its profile's revision and knobs)

  // Stop before executing the instruction at `codeAddress` (used for
  // program-point injection and for tests). The next run() executes it.
  // Breakpoints are kept across reset().
  void setBreakpoint(uint32_t codeAddress, bool enabled = true);
  // The superinstruction (vm/superinstructions.def, by its index there) the
  // fast path runs from `codeAddress` when not profiling, or -1: for tests.
  int superinstructionAt(uint32_t codeAddress) const;

  // Profile: cycles charged at each code address (instruction start), when
  // enabled before running. Interrupt acceptance is charged to the handler's
  // first instruction; serial ISR time to `serialIsrCycles`.
  void enableProfile();
  const std::vector<uint64_t>& profile() const;
  uint64_t serialIsrCycles() const;
  uint64_t timerIsrCycles() const;  // the BIOS timer service's time

  struct State;

 private:
  std::unique_ptr<State> s_;
  // The State's clock and fault, read inline (the round loop asks at every
  // sub-round): s_ lives as long as this VM.
  const Tick* clock_;
  const std::optional<Fault>* fault_;
};

// Disassembly of an image, interleaving source lines (vm/disasm.cpp).
std::string disassemble(const Image& image);
// The instruction at `codeAddress` as one line of that listing: address,
// name, operands and T-states (the debugger's stepi).
std::string disassembleAt(const Image& image, uint32_t codeAddress);
// The same with the T-states of `costs` (a robot's own table: its CPU
// revision).
std::string disassembleAt(const Image& image, uint32_t codeAddress, const CostTable& costs);

}  // namespace simbot::vm
