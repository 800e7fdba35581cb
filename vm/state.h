// The VM's internal state, shared by its parts: the dispatch loop and
// interrupt acceptance (vm.cpp), the library routines (library.cpp) and the
// fast-forward of delay loops (fast_forward.cpp). Not part of the VM's
// interface (vm.h): nothing outside vm/ includes it.
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
  State(const Image& img, Bus& b, const CostTable& c) : image(&img), bus(&b), costs(c) {}

  // Pointers, not references, so that a State is a value: a copy of a VM
  // is a copy of its State pointed at the copy's bus.
  const Image* image;
  Bus* bus;
  CostTable costs;
  std::vector<uint8_t> mem = std::vector<uint8_t>(kMemorySize, 0);
  std::vector<uint32_t> eval = std::vector<uint32_t>(kEvalSlots, 0);
  int sp = 0;  // eval stack: next free slot
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
  bool hostStop = false;  // Vm::stopAtNextBoundary, during a run
  // Set at the first diverted return: from then on the expression stack
  // need not match the code, so every boundary is slow and checks that the
  // next instruction has the slots it takes.
  std::optional<Diversion> diverted;
  std::array<bool, kIrqCount> pend{};
  std::array<uint8_t, kIrqCount> vec{};
  bool anyPending = false;
  std::array<int32_t, 256> handlerFor{};
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
    now += copy.left ? costs.ldirRepeat : costs.copyLast;
  }
  VmStats stats;
  // The dispatch copy of the code (vm.cpp "Fast path"): per code address
  // the opcode the fast path runs there, or kTrap where the slow path must
  // look first (an invalid opcode, an instruction that runs past the end of
  // the code or jumps outside it, a fast-forward loop top, a breakpoint),
  // kCodePad kTrap bytes past the end.
  // `padded` is the code with kCodePad zero bytes after it, for operands.
  static constexpr uint8_t kTrap = kOpCount;
  static constexpr uint32_t kCodePad = 8;
  std::vector<uint8_t> dispatch;
  std::vector<uint8_t> baseDispatch;  // without breakpoints
  std::vector<uint8_t> padded;
  void decode();
  // `dispatch` as run<kProfile> reads it: per code address the handler's
  // label, the opcode's cost and size (0 for kTrap) and the opcode, built
  // at the first run of each (the labels are known only inside run()).
  struct Fast {
    const void* label;
    uint32_t cost;
    uint8_t op;
    bool operator==(const Fast&) const = default;
  };
  std::array<std::vector<Fast>, 2> fast;
  std::array<const void* const*, 2> fastLabels{};
  // The superinstructions' labels (superinstructions.def), set by
  // run<false>: its entry for a superinstruction's first piece jumps there.
  const void* const* superLabels = nullptr;
  // The superinstruction whose pieces start at `address` (each where the
  // one before leads, all ordinary and none a trap in `dispatch`), or -1.
  int superinstructionAt(uint32_t address) const;
  // Per superinstruction, the most ticks its inner boundaries can lie after
  // its first piece's dispatch (every piece at its slowest path), under
  // this VM's cost table: when they all lie before the limit, nothing can
  // happen at them (vm.cpp State::superinstruction).
  std::array<uint32_t, kSuperCount> superSpan{};
  // Per superinstruction and piece k, what the pieces after k cost on their
  // not-taken paths ([0]: all but the first).
  std::array<std::array<uint32_t, kMaxPieces>, kSuperCount> superAfter{};
  void setSuperSpans();
  // A piece k of an unchecked run faulted: take back the time and count
  // charged in advance for the pieces after it.
  void unwindSuperinstruction(int kind, int k);
  // The handler that starts an instruction longer than kMaxStepTstates on
  // the fast path.
  std::array<const void*, 2> longLabels{};
  void setFast(int k, uint32_t address);
  // A REL16 instruction's target, from its start (in the padded code).
  int64_t relTargetAt(uint32_t address) const;
  std::vector<uint8_t> breakpoints;  // one flag per code byte
  bool anyBreakpoint = false;
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
  // ---- fast-forward of delay loops ----
  struct Loop {
    uint32_t top, exit, counter;
    uint32_t limit;
    bool wide;       // a long counter
    bool isSigned;   // LTW, LEW, LTL, LEL
    bool inclusive;  // <=
    // A breakpoint inside turns fast-forward off (kept by setBreakpoint, so
    // that no arrival scans the loop's bytes).
    bool breakpointInside = false;
    // The cost of a pass in the constant-cost regime, once measured (0
    // until then): every pass there costs the same.
    Tick pass = 0;
    bool operator==(const Loop&) const = default;
  };
  std::vector<Loop> loops;
  std::vector<int16_t> loopAtTop;  // per code byte: index into loops, or -1
  // The pass being measured: from one arrival at a loop's top to the next.
  static constexpr uint32_t kMaxLoopBytes = 32;
  struct Measure {
    int loop = -1;
    Tick start = 0;
    uint32_t counter = 0;
    uint64_t instructions = 0;
    uint64_t accepted = 0;
    std::array<uint64_t, kMaxLoopBytes> profile{};
    bool operator==(const Measure&) const = default;
  } measure;
  uint64_t acceptances = 0;  // interrupts accepted so far (a pass with one is no measure)
  void findLoops();
  bool fastForward(Tick until);
  Tick quietUntil() const;
  std::string consoleLine;
  Vm* self = nullptr;
  // The machine at power-on at tick `start` (the constructor's and a
  // reset's): image, bus and costs as they are.
  void powerOn(Tick start);
  // Points a copied State at its VM and that VM's bus.
  void attach(Vm* vm, Bus& to);
  void reserveStacks();
  // The run's counters (stats, profile, interrupt service cycles): they
  // carry on over a reset.
  void copyCounters(const State& from);
  bool operator==(const State&) const = default;

  // ---- faults and memory ----
  void raiseFault(std::string message, uint32_t atPc) {
    if (fault) return;
    if (diverted) {
      const Symbol* f = image->functionAt(diverted->at);
      message += fmt::format(" (after the return at 0x{:04X}{} went to 0x{:04X}, off its call)",
                             diverted->at, f ? fmt::format(" in '{}'", f->name) : std::string(),
                             diverted->target);
    }
    fault = Fault{std::move(message), now, image->lineAt(atPc), atPc};
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
        bus->console(now, consoleLine);
        consoleLine.clear();
      } else {
        consoleLine.push_back(c);
      }
    }
  }
  void flushConsole() {
    if (!consoleLine.empty()) {
      bus->console(now, consoleLine);
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
    if (costateEvents) bus->costate(now, static_cast<uint16_t>(coData), kind, image->lineAt(atPc));
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
  Stop run(Tick until);
  // ---- instructions (instructions.h) and superinstructions (vm.cpp) ----
  template <Op O>
  bool exec(Regs& r);
  template <Op O>
  bool step(Regs& r);
  template <Op O>
  bool piece(Regs& r);
  template <int kKind, Op First, Op... Rest>
  bool superinstruction(Regs& r);
  template <int kKind, int kPiece, Op O>
  bool uncheckedPiece(Regs& r);
  template <int kKind, Op First, Op... Rest, size_t... kPieces>
  bool unchecked(Regs& r, std::index_sequence<kPieces...>);
  void save(const Regs& r);
  void burnTail(Regs& r);
  bool fail(const Regs& r, const char* message);
  bool badCallThrough(const Regs& r, uint32_t target, uint32_t argc);
  bool divertedReturn(Regs& r, const CallFrame& call, uint32_t target, uint32_t readAt,
                      int32_t frame, uint32_t fp);
  void divert(uint32_t at, uint32_t target);
  // Where a smashed return address may lead: instruction starts, but not
  // the reset address.
  std::vector<uint8_t> instructionStart;
  std::string returnTargetProblem(uint32_t target) const;
  // Per RET, the auto frame it releases, or -1 (Image::returnFrames).
  std::vector<int32_t> returnFrame;
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
