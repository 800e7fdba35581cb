// The VM's internal state, shared by its parts: the dispatch loop and
// interrupt acceptance (vm.cpp), the library routines (library.cpp) and the
// fast-forward of delay loops (fast_forward.cpp). It is the machine's state
// only; what is decoded from the image is the Program (program.h), which
// it shares. Not part of the VM's interface (vm.h): nothing outside vm/
// includes it.
#pragma once
#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "vm/program.h"
#include "vm/superinstructions.h"
#include "vm/vm.h"

namespace simbot::vm {

namespace detail {

inline constexpr int kEvalSlots = 8192;
// A call needs this many free slots (its own expressions, in practice).
inline constexpr int kEvalHeadroom = 1024;
// No instruction or library step pushes more than two slots, so checking
// this much room at every boundary keeps any program (8,200 arguments, a
// deep nest of calls) from writing past the expression stack.
inline constexpr int kEvalGuard = 4;
static_assert(kEvalHeadroom > kMaxLibArgs + kEvalGuard,
              "a call's headroom must hold a library call's arguments");
inline constexpr int kMaxInterruptNesting = 16;
inline constexpr uint32_t kMaxStepTstates = 100;  // long library calls: boundary spacing
static_assert(Tick{kMaxStepTstates} <= kMaxRunOvershoot, "vm.h promises runs overshoot less");
// printf's largest field width and precision (assumption: Dynamic C's
// printf formatted each field into a buffer of this size).
inline constexpr long kMaxPrintfField = 127;
// Robot stack bytes: CALL pushes the return address, ENTER the caller's IX
// (the frame pointer) below it; acceptance pushes PC, AF, BC, DE, HL, IX,
// IY, so the interrupted PC is at the top and IX 12 bytes below the SP it
// interrupted.
inline constexpr uint32_t kReturnAddressBytes = 2;
inline constexpr uint32_t kSavedFpBytes = 2;
inline constexpr uint32_t kInterruptFrameBytes = 14;
inline constexpr uint32_t kInterruptFpOffset = 12;

// LibCall::mark before a routine's second phase has begun.
inline constexpr uint32_t kNoMark = 0xFFFFFFFFu;

struct LibCall {
  bool active = false;
  Lib id{};
  uint32_t pc = 0;  // address of the LIB instruction (for traces)
  int argc = 0;
  uint32_t args[kMaxLibArgs]{};
  uint32_t setup = 0;  // T-states of the call sequence still to run
  // The call sequence has run; its effect happens at the next boundary, so
  // that a bus access is always at a boundary that starts before the
  // horizon (the host never sees an access past the tick it ran us to).
  bool awaitingBegin = false;
  uint32_t index = 0;      // bytes processed (printf: characters sent)
  uint32_t remaining = 0;  // T-states still to burn (A/D, printf)
  uint32_t mark = 0;       // a routine's second phase: where it began
  uint32_t result = 0;
  std::string text;  // printf's formatted output
  bool operator==(const LibCall&) const = default;
};

// What the host remembers of a call, to check the return against and to
// name it in messages: the return address itself is in the robot's memory,
// and RET reads it there (a program that overwrites it returns where it
// leads).
struct CallFrame {
  uint32_t retPc;  // the address after the CALL
  uint32_t saved;  // where the CALL pushed it
  bool operator==(const CallFrame&) const = default;
};

// The first return that went where a smashed frame led, not back to its
// call: every later fault names it, since the host's record of the calls
// no longer matches what the robot runs.
struct Diversion {
  uint32_t at;      // the RET or RETI
  uint32_t target;  // where it went
  bool operator==(const Diversion&) const = default;
};

// A struct assignment's LDIR under way (COPY): one byte a step with an
// instruction boundary after each, as the Z180's LDIR is interruptible
// after every byte (it runs again with BC decremented), so a handler sees
// the copy as far as it has gone.
struct BlockCopy {
  uint32_t dst = 0;
  uint32_t src = 0;
  uint32_t left = 0;  // bytes still to copy; 0: none under way
  bool operator==(const BlockCopy&) const = default;
};

struct InterruptFrame {
  uint32_t retPc;
  Irq irq;
  uint32_t msp;  // SP before acceptance pushed the frame
  int evalSp;
  int callDepth;
  bool halted;
  uint32_t burn;
  uint32_t burnPc;
  BlockCopy copy;
  LibCall lib;
  bool operator==(const InterruptFrame&) const = default;
};

// The expression stack. A VM that runs holds all kEvalSlots slots (the
// fast path pushes through a pointer, checking the guard only at its
// boundaries); a copy holds only the slots in use, [0, sp) (nothing reads a
// slot at or above sp before writing it), and a VM takes the full size
// again before it runs (ready()).
class EvalStack {
 public:
  EvalStack() : slots_(kEvalSlots, 0) {}
  EvalStack(const EvalStack& other)
      : sp(other.sp), slots_(other.slots_.begin(), other.slots_.begin() + other.sp) {}
  EvalStack& operator=(const EvalStack& other) {
    if (this != &other) {
      sp = other.sp;
      slots_.assign(other.slots_.begin(), other.slots_.begin() + other.sp);
    }
    return *this;
  }
  bool operator==(const EvalStack& other) const {
    return sp == other.sp && std::equal(slots_.begin(), slots_.begin() + sp, other.slots_.begin());
  }
  void ready() {
    if (slots_.size() < static_cast<size_t>(kEvalSlots)) slots_.resize(kEvalSlots, 0);
  }
  uint32_t* data() { return slots_.data(); }
  uint32_t operator[](int i) const { return slots_[static_cast<size_t>(i)]; }
  void push(uint32_t v) { slots_[static_cast<size_t>(sp++)] = v; }
  uint32_t pop() { return slots_[static_cast<size_t>(--sp)]; }

  int sp = 0;  // the next free slot

 private:
  std::vector<uint32_t> slots_;
};

[[gnu::always_inline]] inline float asFloat(uint32_t bits) { return std::bit_cast<float>(bits); }
[[gnu::always_inline]] inline uint32_t fromFloat(float f) { return std::bit_cast<uint32_t>(f); }
[[gnu::always_inline]] inline int16_t asInt16(uint32_t v) {
  return static_cast<int16_t>(static_cast<uint16_t>(v));
}
static_assert(Tick{kPrtTicks} * kTimerHz == kTicksPerSecond,
              "PRT0's period must divide the clock into Dynamic C's 1,024 Hz tick");

// A little-endian 16-bit word at p (code operands, memory): one load on a
// little-endian host, where byte loads cost the dispatch loop instructions.
[[gnu::always_inline]] inline uint32_t le16(const uint8_t* p) {
  if constexpr (std::endian::native == std::endian::little) {
    uint16_t v;
    std::memcpy(&v, p, 2);
    return v;
  } else {
    return static_cast<uint32_t>(p[0] | (p[1] << 8));
  }
}
[[gnu::always_inline]] inline void setLe16(uint8_t* p, uint32_t v) {
  if constexpr (std::endian::native == std::endian::little) {
    const auto h = static_cast<uint16_t>(v);
    std::memcpy(p, &h, 2);
  } else {
    p[0] = static_cast<uint8_t>(v);
    p[1] = static_cast<uint8_t>(v >> 8);
  }
}
// A word of the 64 KiB memory m at a; its last byte's word wraps to 0.
[[gnu::always_inline]] inline uint32_t memRd16(const uint8_t* m, uint32_t a) {
  a &= 0xFFFF;
  if (__builtin_expect(a == 0xFFFF, 0)) return static_cast<uint32_t>(m[0xFFFF] | (m[0] << 8));
  return le16(m + a);
}
[[gnu::always_inline]] inline void memWr16(uint8_t* m, uint32_t a, uint32_t v) {
  a &= 0xFFFF;
  if (__builtin_expect(a == 0xFFFF, 0)) {
    m[0xFFFF] = static_cast<uint8_t>(v);
    m[0] = static_cast<uint8_t>(v >> 8);
  } else {
    setLe16(m + a, v);
  }
}

[[gnu::always_inline]] inline uint32_t w(int32_t v) { return static_cast<uint32_t>(v) & 0xFFFFu; }

inline int64_t truncToRange(float f, double lo, double hi) {
  if (std::isnan(f)) return 0;
  double t = std::trunc(static_cast<double>(f));
  return static_cast<int64_t>(std::clamp(t, lo, hi));
}

}  // namespace detail

// The VM's parts all work inside it.
using namespace detail;

// The fast path's registers (vm.cpp "Fast path"): locals of run(), which
// the compiler keeps in machine registers while ordinary instructions run
// (nothing takes their address: every function that works on them is
// inlined). The State's now, pc, sp and stats.instructions hold them only
// on the slow path (State::save). The helpers read operands from the
// padded code and memory through the pointers here.
struct Regs {
  Tick clk;        // the clock
  Tick limit;      // the first tick at which a boundary has anything to do, or 0
  uint64_t count;  // instructions run
  // The next instruction (the handler sets it past its own) and the one
  // being run: code addresses, as wide as a pointer so that an operand's
  // address folds into its load.
  size_t ip;
  size_t opPc;
  uint32_t pc() const { return static_cast<uint32_t>(opPc); }
  int esp;              // the expression stack's next free slot
  uint32_t* e;          // the expression stack
  uint8_t* m;           // memory
  const uint8_t* code;  // the padded code
  uint64_t* profile;    // cycles per code address, null unless profiling

  [[gnu::always_inline]] uint32_t& top() { return e[esp - 1]; }
  [[gnu::always_inline]] uint32_t pop() { return e[--esp]; }
  // A push past the guard makes the next boundary slow, where the guard
  // faults (no instruction pushes more than two slots, so the array's last
  // kEvalGuard slots are never passed).
  [[gnu::always_inline]] void push(uint32_t v) {
    e[esp++] = v;
    if (__builtin_expect(esp > kEvalSlots - kEvalGuard, 0)) limit = 0;
  }
  template <class F>
  [[gnu::always_inline]] bool binary(F f) {
    const uint32_t b = pop();
    top() = f(top(), b);
    return true;
  }
  // Operands, at offsets from the opcode that instructionSize() counts.
  [[gnu::always_inline]] uint32_t u16() const { return le16(code + opPc + 1); }
  [[gnu::always_inline]] uint32_t i32() const { return u16() | (le16(code + opPc + 3) << 16); }
  // A REL16 target, from the end of the instruction (ip).
  [[gnu::always_inline]] uint32_t relTarget() const {
    return static_cast<uint32_t>(ip) + static_cast<uint32_t>(static_cast<int16_t>(u16()));
  }
  // A CO-shape instruction's: its REL16 after the CoData address.
  [[gnu::always_inline]] uint32_t coTarget() const {
    return static_cast<uint32_t>(ip) +
           static_cast<uint32_t>(static_cast<int16_t>(le16(code + opPc + 3)));
  }
  [[gnu::always_inline]] void charge(int32_t delta) {
    clk += delta;
    if (profile) profile[opPc] += static_cast<uint64_t>(int64_t{delta});
  }
  [[gnu::always_inline]] uint32_t rd8(uint32_t a) const { return m[a & 0xFFFF]; }
  [[gnu::always_inline]] uint32_t rd16(uint32_t a) const { return memRd16(m, a); }
  [[gnu::always_inline]] uint32_t rd32(uint32_t a) const { return rd16(a) | (rd16(a + 2) << 16); }
  [[gnu::always_inline]] void wr8(uint32_t a, uint32_t v) {
    m[a & 0xFFFF] = static_cast<uint8_t>(v);
  }
  [[gnu::always_inline]] void wr16(uint32_t a, uint32_t v) { memWr16(m, a, v); }
  [[gnu::always_inline]] void wr32(uint32_t a, uint32_t v) {
    wr16(a, v);
    wr16(a + 2, v >> 16);
  }
  template <int kBytes>
  [[gnu::always_inline]] uint32_t read(uint32_t a) const {
    if constexpr (kBytes == 1) return rd8(a);
    if constexpr (kBytes == 2) return rd16(a);
    return rd32(a);
  }
  template <int kBytes>
  [[gnu::always_inline]] void write(uint32_t a, uint32_t v) {
    if constexpr (kBytes == 1) wr8(a, v);
    if constexpr (kBytes == 2) wr16(a, v);
    if constexpr (kBytes == 4) wr32(a, v);
  }
};

struct Vm::State {
  State(std::shared_ptr<const Program> p, Bus* b)
      : program(std::move(p)), dispatch(program->plain), bus(b) {}

  // The constant half, shared by every copy; and the dispatch the loop
  // runs: the program's, or this VM's with its breakpoints (shared by its
  // copies until they change: Vm::setBreakpoint).
  std::shared_ptr<const Program> program;
  std::shared_ptr<const Dispatch> dispatch;
  const CostTable& costs() const { return program->costs; }
  const Image& image() const { return *program->image; }
  static constexpr uint8_t kTrap = Program::kTrap;
  // The bus it talks to and the VM that holds it: not part of its value
  // (Vm's copy and assignment set them).
  Bus* bus;
  Vm* self = nullptr;
  // Every bus call goes through host(): whether one was made since the
  // continuation last answered (Continuation: the horizons a run takes
  // without asking hold only while none was).
  bool touchedHost = true;
  Bus& host() {
    touchedHost = true;
    return *bus;
  }

  std::vector<uint8_t> mem = std::vector<uint8_t>(kMemorySize, 0);
  EvalStack eval;
  std::vector<CallFrame> calls;
  std::vector<InterruptFrame> ints;
  uint32_t pc = 0;
  Tick now = 0;
  uint32_t msp = kMemorySize;  // robot stack pointer (grows down)
  uint32_t mfp = kMemorySize;  // auto frame pointer
  uint32_t stackLimit = kDataBase;
  bool iff1 = true;  // Dynamic C's BIOS runs main with interrupts enabled
  bool iff2 = true;
  bool eiShadow = false;
  bool halted = false;
  Tick haltedAt = 0;      // the end of the HALT that last halted it
  bool hostStop = false;  // Vm::stopAtNextBoundary, during a run
  // Set at the first diverted return: from then on the expression stack
  // need not match the code, so every boundary is slow and checks that the
  // next instruction has the slots it takes.
  std::optional<Diversion> diverted;
  std::array<bool, kIrqCount> pend{};
  std::array<uint8_t, kIrqCount> vec{};
  bool anyPending = false;
  std::optional<Fault> fault;
  LibCall lib;
  // T-states still to run of an opcode longer than kMaxStepTstates (a CALL
  // into a run-time routine): its effect is done, its time passes in steps
  // with an instruction boundary between them.
  uint32_t burn = 0;
  uint32_t burnPc = 0;  // the instruction whose tail (burn) or copy runs
  BlockCopy copy;
  // The instruction, library call or interrupt acceptance under way at the
  // current boundary (Vm::pc).
  uint32_t currentPc() const { return lib.active ? lib.pc : burn || copy.left ? burnPc : pc; }
  // The boundary's step of a copy under way: its next byte, then LDIR's
  // time for it (cost.h copyHead, ldirRepeat, copyLast).
  void copyStep() {
    wr8(copy.dst, rd8(copy.src));
    copy.dst = (copy.dst + 1) & 0xFFFF;
    copy.src = (copy.src + 1) & 0xFFFF;
    --copy.left;
    now += copy.left ? costs().ldirRepeat : costs().copyLast;
  }
  VmStats stats;
  // A piece k of an unchecked run faulted: take back the time and count
  // charged in advance for the pieces after it.
  void unwindSuperinstruction(int kind, int k);
  bool resumeAtBreakpoint = false;
  bool profiling = false;
  std::vector<uint64_t> profile;
  uint64_t serialIsrCycles = 0;
  // PRT0: the next tick at which it requests the timer interrupt
  // (kNoTimer when the service does not run).
  static constexpr Tick kNoTimer = INT64_MAX;
  Tick nextTimer = kNoTimer;
  uint64_t timerIsrCycles = 0;
  // The BIOS's counters when the program has no timer block of its own.
  uint32_t biosTicks = 0;
  uint8_t biosMsFraction = 0;
  bool costateEvents = false;
  // ---- fast-forward of delay loops (Program::loops) ----
  // Per loop, the cost of a pass in the constant-cost regime, once
  // measured (0 until then): every pass there costs the same.
  std::vector<Tick> loopPass = std::vector<Tick>(program->loops.size(), 0);
  // and the instructions a pass runs.
  std::vector<uint64_t> loopInstructions = std::vector<uint64_t>(program->loops.size(), 0);
  // The pass being measured: from one arrival at a loop's top to the next.
  struct Measure {
    int loop = -1;
    Tick start = 0;
    uint32_t counter = 0;
    uint64_t instructions = 0;
    uint64_t accepted = 0;
    std::array<uint64_t, Program::kMaxLoopBytes> profile{};
    bool operator==(const Measure&) const = default;
  } measure;
  uint64_t acceptances = 0;  // interrupts accepted so far (a pass with one is no measure)
  bool fastForward(Tick until);
  bool applyPasses(size_t loop, uint32_t& v, Tick until, bool measured);
  Tick quietUntil() const;
  std::string consoleLine;
  // The machine at power-on at tick `start` (the constructor's and a
  // reset's): memory as the image initialises it, the program at its entry.
  void powerOn(Tick start);
  // Room to run: the expression stack's full size and the stacks' deepest
  // nesting, so that no push on the hot path allocates (a copy holds what
  // is in use only).
  void ready();
  [[gnu::noinline, gnu::cold]] void prepare();
  // The run's counters (stats, profile, interrupt service cycles): they
  // carry on over a reset.
  void copyCounters(const State& from);
  bool operator==(const State&) const = default;

  // ---- faults and memory ----
  void raiseFault(std::string message, uint32_t atPc) {
    if (fault) return;
    if (diverted) {
      const Symbol* f = image().functionAt(diverted->at);
      message += fmt::format(" (after the return at 0x{:04X}{} went to 0x{:04X}, off its call)",
                             diverted->at, f ? fmt::format(" in '{}'", f->name) : std::string(),
                             diverted->target);
    }
    fault = Fault{std::move(message), now, image().lineAt(atPc), atPc};
  }
  // Checks a pointer access of `size` bytes; false (and a fault) if invalid.
  bool checkAccess(uint32_t address, uint32_t size, uint32_t atPc) {
    if (address < kNullPageEnd) {
      raiseFault(fmt::format("null pointer access at 0x{:04x}", address), atPc);
      return false;
    }
    if (address + size > kMemorySize) {
      raiseFault(fmt::format("access outside memory at 0x{:04x} ({} bytes)", address, size), atPc);
      return false;
    }
    return true;
  }
  uint8_t rd8(uint32_t a) const { return mem[a & 0xFFFF]; }
  uint16_t rd16(uint32_t a) const { return static_cast<uint16_t>(memRd16(mem.data(), a)); }
  uint32_t rd32(uint32_t a) const { return rd16(a) | (static_cast<uint32_t>(rd16(a + 2)) << 16); }
  void wr8(uint32_t a, uint32_t v) { mem[a & 0xFFFF] = static_cast<uint8_t>(v); }
  void wr16(uint32_t a, uint32_t v) { memWr16(mem.data(), a, v); }
  void wr32(uint32_t a, uint32_t v) {
    wr16(a, v);
    wr16(a + 2, v >> 16);
  }

  // ---- console ----
  void emitConsole(std::string_view text) {
    for (char c : text) {
      if (c == '\n') {
        host().console(now, consoleLine);
        consoleLine.clear();
      } else {
        consoleLine.push_back(c);
      }
    }
  }
  void flushConsole() {
    if (!consoleLine.empty()) {
      host().console(now, consoleLine);
      consoleLine.clear();
    }
  }

  // ---- interrupts ----
  void updatePending() {
    anyPending = std::any_of(pend.begin(), pend.end(), [](bool p) { return p; });
  }
  // Accepts the highest-priority pending request at the current boundary.
  void accept();
  // PRT0 reached nextTimer: raise its request (one flag: a tick that comes
  // while the last one is still pending is lost) and schedule the next.
  void timerTick() {
    pend[static_cast<int>(Irq::Timer)] = true;
    anyPending = true;
    nextTimer += static_cast<Tick>((now - nextTimer) / kPrtTicks + 1) * kPrtTicks;
  }
  void timerService(uint32_t interruptedPc);
  // ---- costatements ----
  void costateEvent(uint32_t coData, Bus::CostateEvent kind, uint32_t atPc) {
    if (costateEvents)
      host().costate(now, static_cast<uint16_t>(coData), kind, image().lineAt(atPc));
  }
  // CoData's ChkSum: the XOR of the resume address's three bytes.
  static uint8_t coChecksum(uint32_t resume, uint8_t cbr) {
    return static_cast<uint8_t>((resume & 0xFF) ^ ((resume >> 8) & 0xFF) ^ cbr);
  }
  // lastlocADDR := resume (0: from the top), with its CBR (0) and checksum.
  void setResume(uint32_t coData, uint32_t resume) {
    wr16(coData + kCoLastLoc, resume);
    wr8(coData + kCoLastLocCbr, 0);
    wr8(coData + kCoChkSum, coChecksum(resume, 0));
  }
  void costateEnd(uint32_t coData, bool done) {
    setResume(coData, 0);
    if (done) wr8(coData + kCoState, kCoStopped | kCoInit);
  }
  bool delayDone(uint32_t coData, int32_t interval, uint32_t timerAddress, uint32_t instructionPc);
  // ---- library ----
  void libCall(Lib id, int argc, uint32_t instructionPc);
  void libBegin();
  void libStep();
  void libFinish(bool pushResult);
  std::string formatPrintf(uint32_t instructionPc, int formatArg);
  uint32_t printfCharTstates() const;
  uint32_t printfToLineEnd() const;
  void printfSent();

  template <bool kProfile>
  Stop run(Tick until, Continuation* more);
  Tick nextHorizon(Continuation& more, Tick reached);
  bool takeHorizon(Regs& r, Tick& until, Continuation* more);
  // ---- instructions (instructions.h) and superinstructions (vm.cpp) ----
  template <Op O>
  bool exec(Regs& r);
  template <Op O>
  bool step(Regs& r);
  template <int kKind, Op First, Op... Rest>
  bool superinstruction(Regs& r, const Program& prog);
  template <int kKind, int kPiece, Op O>
  bool uncheckedPiece(Regs& r);
  template <int kKind, Op First, Op... Rest, size_t... kPieces>
  bool unchecked(Regs& r, const Program& prog, std::index_sequence<kPieces...>);
  void save(const Regs& r);
  void burnTail(Regs& r);
  bool fail(const Regs& r, const char* message);
  bool badCallThrough(const Regs& r, uint32_t target, uint32_t argc);
  bool divertedReturn(Regs& r, const CallFrame& call, uint32_t target, uint32_t readAt,
                      int32_t frame, uint32_t fp);
  void divert(uint32_t at, uint32_t target);
  // Where a smashed return address may lead: instruction starts, but not
  // the reset address.
  std::string returnTargetProblem(uint32_t target) const;
  bool callTo(Regs& r, uint32_t target);
  bool access(const Regs& r, uint32_t address, uint32_t bytes);
  template <Op O>
  void branch(Regs& r, unsigned path);
  template <Op C>
  bool compare16(Regs& r);
  template <Op O, class Shift>
  bool shift16(Regs& r, Shift shifted);
  template <class Divide>
  bool divide(Regs& r, bool byZero, Divide quotient);
  template <class F>
  bool unary(Regs& r, F f);
  template <int kBytes>
  bool loadLocal(Regs& r);
  template <int kBytes>
  bool storeLocal(Regs& r);
  template <int kBytes>
  bool loadIndirect(Regs& r);
  template <int kBytes, bool kKeep>
  bool storeIndirect(Regs& r);
  template <bool kIfZero>
  bool branchIf(Regs& r);
  bool coEnd(Regs& r, bool done);
};

}  // namespace simbot::vm
