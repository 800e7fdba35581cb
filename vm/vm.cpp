// The VM's dispatch loop. One set of handlers (the CASE blocks below) builds
// as a switch or, with GCC/Clang, as computed goto (SIMBOT_COMPUTED_GOTO).
//
// Each step of the loop is an instruction boundary: first the horizon test,
// then interrupt acceptance, then one bytecode instruction or one step of a
// long library call. An instruction's cost is charged when it starts and its
// effects (bus accesses included) happen at its end tick.
//
// Faults (documented in docs/cycle-model.md): division by zero (Dynamic C's run-time
// error handler stops the program), access to the null page 0x0000-0x00FF
// (an assumption: on the target that is the vector area, so a stray pointer
// would corrupt it silently; simbot stops the robot instead), a multi-byte
// access past 0xFFFF, the auto/return stack growing into the data area
// ("stack overflow"), an interrupt through a vector with no #INT_VEC handler.
// A fault stops only that robot; the host carries on.
#include "vm/vm.h"

#include "vm/state.h"

// Computed goto (labels as values) is a GNU extension used on purpose.
#pragma GCC diagnostic ignored "-Wpedantic"

#include <fmt/format.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <optional>

#ifndef SIMBOT_COMPUTED_GOTO
#if defined(__GNUC__)
#define SIMBOT_COMPUTED_GOTO 1
#else
#define SIMBOT_COMPUTED_GOTO 0
#endif
#endif

namespace simbot::vm {

std::string_view irqName(Irq irq) {
  switch (irq) {
    case Irq::Pio:
      return "pio_a";
    case Irq::Timer:
      return "timer";
    case Irq::SerialTx:
      return "serial_tx";
  }
  return "?";
}

void Vm::State::accept() {
  ++acceptances;
  int i = 0;
  while (!pend[i]) ++i;
  const Irq irq = static_cast<Irq>(i);
  pend[i] = false;
  updatePending();
  ++stats.interrupts[i];
  const uint32_t interruptedPc = lib.active ? lib.pc : burn ? burnPc : pc;
  if (irq == Irq::Timer) {
    timerService(interruptedPc);
    return;
  }
  if (irq == Irq::SerialTx) {
    // The serial library's own ISR: short and atomic, leaves IFF1 set.
    bus->interruptAccepted(now, irq, interruptedPc);
    now += costs.serialIsr;
    serialIsrCycles += costs.serialIsr;
    bus->serialTxService(now, *self);
    bus->interruptReturned(now, irq);
    busTouched = true;
    return;
  }
  const int32_t handler = handlerFor[vec[i]];
  if (handler < 0) {
    raiseFault(fmt::format("{} interrupt through vector 0x{:02x}, which no #INT_VEC binds",
                           irqName(irq), vec[i]),
               interruptedPc);
    return;
  }
  if (static_cast<int>(ints.size()) >= kMaxInterruptNesting) {
    raiseFault("interrupts nested too deeply", interruptedPc);
    return;
  }
  if (msp < stackLimit + kInterruptFrameBytes) {
    raiseFault("stack overflow (interrupt frame)", interruptedPc);
    return;
  }
  ints.push_back(InterruptFrame{pc, irq, msp, mfp, sp, static_cast<int>(calls.size()), halted, burn,
                                std::move(lib)});
  lib = LibCall{};
  burn = 0;
  resumeAtBreakpoint = false;
  msp -= kInterruptFrameBytes;
  halted = false;
  iff1 = iff2 = false;
  bus->interruptAccepted(now, irq, interruptedPc);
  bus->iffChanged(now, false);
  now += costs.interruptAccept;
  if (profiling) profile[handler] += costs.interruptAccept;
  pc = static_cast<uint32_t>(handler);
}

// The BIOS timer service (cost.h kTimerIsrSeq): atomic, like the serial
// library's ISR: interrupts stay disabled inside it and its EI; RETI leaves
// IFF1 set as it was at acceptance.
void Vm::State::timerService(uint32_t interruptedPc) {
  bus->interruptAccepted(now, Irq::Timer, interruptedPc);
  const TimerBlock& tb = image->timer;
  const uint32_t ticks = (tb.used() ? rd32(tb.tick) : biosTicks) + 1;
  const uint32_t fraction = (tb.used() ? rd8(tb.msFraction) : biosMsFraction) + kMsFractionStep;
  const bool msDue = fraction >= kMsFractionOne;
  const bool secDue = (ticks & (kTimerHz - 1)) == 0;
  const uint8_t newFraction = static_cast<uint8_t>(fraction % kMsFractionOne);
  if (tb.used()) {
    wr32(tb.tick, ticks);
    wr8(tb.msFraction, newFraction);
    if (msDue) wr32(tb.ms, rd32(tb.ms) + 1);
    if (secDue) wr32(tb.sec, rd32(tb.sec) + 1);
  } else {
    biosTicks = ticks;
    biosMsFraction = newFraction;
  }
  const uint32_t cost = costs.timerIsr[(msDue ? 0u : 1u) | (secDue ? 0u : 2u)];
  now += cost;
  timerIsrCycles += cost;
  bus->interruptReturned(now, Irq::Timer);
}

// ---- dispatch ---------------------------------------------------------------
//
// Fast path. The clock, pc, eval-stack pointer and instruction count live in
// locals (clk, ip, esp, count) while ordinary instructions run; the State's
// members (now, pc, sp, stats.instructions) hold them only on the slow path.
// An ordinary instruction ends with NEXT: one compare of the clock against
// `limit`, the load of the next opcode from `dispatch` and a jump to its
// handler. limit is min(until, nextTimer), the first tick at which the
// boundary has anything to do, or 0 (a trap) while anything rarer is due:
//  - a fault, a bus access (Io), a library call, HALT, EI/DI, RETI, the
//    costatement opcodes: their handlers go to the slow boundary themselves;
//  - a pending request with IFF1 set (only the slow path changes IFF1, the
//    pending flags or the EI shadow while run() runs: the host raises
//    requests between calls), the time of a long instruction still to burn,
//    the eval stack past its guard: limit = 0, so the next boundary is slow;
//  - an address whose `dispatch` byte is kTrap (decode(): invalid opcodes,
//    instructions past the end of the code or jumping outside it,
//    fast-forward loop tops, breakpoints): the kTrap handler sends it to
//    the slow boundary, which runs the instruction from the code itself and
//    sets limit = 0 for the boundary after it.
// An instruction longer than kMaxStepTstates (L_Long_) charges the first
// kMaxStepTstates, leaves the rest in `burn` and runs its handler with
// limit = 0; its NEXT then runs the tail's steps at `slowNext`, each after
// the same compare against the real limit (nothing else can be due inside
// a pure stack operation's tail), and leaves for the slow boundary at the
// first step where something is.
// The slow boundary (`boundary:`) is the one every instruction used to take:
// the same tests in the same order, so every tick, count and trace is what
// it was. Any pc the fast path can reach indexes `dispatch` safely: jumps
// and calls out of the code are kTrap at decode, and a return address is at
// most kCodePad - 1 past its end.

void Vm::State::decode() {
  const auto& code = image->code;
  const auto size = static_cast<uint32_t>(code.size());
  padded = code;
  padded.resize(size + kCodePad, 0);
  baseDispatch.assign(size + kCodePad, kTrap);
  auto rel = [&](uint32_t a) {  // a REL16 instruction's target, from its start
    return int64_t{a} + 3 + static_cast<int16_t>(padded[a + 1] | (padded[a + 2] << 8));
  };
  for (uint32_t a = 0; a < size; ++a) {
    const uint8_t b = code[a];
    if (b >= kOpCount) continue;
    const Op op = static_cast<Op>(b);
    if (a + static_cast<uint32_t>(instructionSize(op)) > size) continue;
    if ((op == Op::JMP || op == Op::JZ || op == Op::JNZ) && (rel(a) < 0 || rel(a) >= size))
      continue;
    if (op == Op::CALL && static_cast<uint32_t>(padded[a + 1] | (padded[a + 2] << 8)) >= size)
      continue;
    baseDispatch[a] = b;
  }
  if (costs.knobs.fastForward)
    for (const Loop& loop : loops) baseDispatch[loop.top] = kTrap;
  dispatch = baseDispatch;
}

// Superinstructions: pairs (first, second) chosen from the most frequent
// adjacent opcodes counted over the reference, shipped, test and benchmark
// programs (docs/cycle-model.md, "Dispatch"); the first half never touches the bus or
// charges a branch-dependent tail, and no half is longer than
// kMaxStepTstates. The entry of a first half followed by its second (both
// ordinary: no trap, no breakpoint on the second) jumps to a handler that
// runs the first, then the boundary between them (the same compare against
// `limit`: a horizon, PRT0 tick or trap there stops exactly there, with
// the same count and clock), then charges the second and jumps straight to
// its handler. A first half that faults leaves as it does alone (FAULT,
// CHECK_ACCESS). Each half is counted and costs what it costs alone; what
// is saved is the second's table load and indirect jump. The profiling run
// does not fuse.
// clang-format off
#define SIMBOT_FUSED_PAIRS(X)                                                         \
  X(PUSHW, LTW) X(LTW, JZ) X(LDGW, LDGW) X(LDGW, PUSHW) X(LDGW, ADDW) X(ADDW, PUSHW)  \
  X(ADDW, STGW) X(INCGW, JMP) X(DBG, PUSHW) X(DBG, LDLW) X(DBG, LDGW) X(PUSHW, PUSHW) \
  X(PUSHW, LDGW) X(PUSHW, SUBW) X(PUSHW, ADDW) X(STGW, DBG) X(STGW, LDGW) X(POP, DBG) \
  X(LDLW, PUSHW) X(LDLW, RET) X(STLW, DBG) X(ENTER, STLW) X(SUBW, CALL) X(ADDW, RET)  \
  X(STGW, INCGW)
// clang-format on

namespace {
struct FusedPair {
  Op first, second;
};
constexpr FusedPair kFusedPairs[] = {
#define SIMBOT_PAIR(a, b) {Op::a, Op::b},
    SIMBOT_FUSED_PAIRS(SIMBOT_PAIR)
#undef SIMBOT_PAIR
};
int fusedIndex(uint8_t first, uint8_t second) {
  for (size_t i = 0; i < std::size(kFusedPairs); ++i)
    if (static_cast<uint8_t>(kFusedPairs[i].first) == first &&
        static_cast<uint8_t>(kFusedPairs[i].second) == second)
      return static_cast<int>(i);
  return -1;
}

// A 16-bit comparison as the Z180 code does it, for the compare handlers
// (COMPARE16 in run()) and the compare-and-branch idioms alike: the result,
// and the path its branches take. Signed: the first branch (JP PO) is taken
// when the subtraction did not overflow (it jumps over the sign
// correction), the second when the result is 0. Unsigned: one branch,
// taken when the result is 0 (it jumps over INC HL).
template <Op C>
bool compare16(uint32_t a, uint32_t b, unsigned& path) {
  if constexpr (C == Op::LTW || C == Op::LEW || C == Op::GTW || C == Op::GEW) {
    // LTW and GEW compute a - b (HL = a); LEW and GTW b - a.
    constexpr bool kAFirst = C == Op::LTW || C == Op::GEW;
    const uint32_t hl = kAFirst ? a : b, de = kAFirst ? b : a;
    const int32_t diff = int32_t{asInt16(hl)} - int32_t{asInt16(de)};
    const bool overflow = diff < -32768 || diff > 32767;
    bool r = false;
    if constexpr (C == Op::LTW) r = asInt16(a) < asInt16(b);
    if constexpr (C == Op::LEW) r = asInt16(a) <= asInt16(b);
    if constexpr (C == Op::GTW) r = asInt16(a) > asInt16(b);
    if constexpr (C == Op::GEW) r = asInt16(a) >= asInt16(b);
    path = (overflow ? 0u : 1u) | (r ? 0u : 2u);
    return r;
  } else {
    const uint32_t x = a & 0xFFFF, y = b & 0xFFFF;
    bool r = false;
    if constexpr (C == Op::EQW) r = x == y;
    if constexpr (C == Op::NEW) r = x != y;
    if constexpr (C == Op::LTUW) r = x < y;
    if constexpr (C == Op::LEUW) r = x <= y;
    if constexpr (C == Op::GTUW) r = x > y;
    if constexpr (C == Op::GEUW) r = x >= y;
    path = r ? 0u : 1u;
    return r;
  }
}
}  // namespace

void Vm::State::setFast(int k, uint32_t address) {
  uint8_t o = dispatch[address];
  const bool isLong = o != kTrap && costs.op[o] > kMaxStepTstates;
  if (isLong && !longLabels[k]) o = kTrap;
  const bool trap = o == kTrap;
  const auto size = trap ? uint8_t{0} : static_cast<uint8_t>(instructionSize(static_cast<Op>(o)));
  const void* label = isLong && !trap ? longLabels[k] : fastLabels[k][o];
  if (k == 0 && fusedLabels && !trap && !isLong && address + size < dispatch.size()) {
    const uint8_t next = dispatch[address + size];
    const int f = fusedIndex(o, next);
    // A pair would run its second half unfused: an idiom there is worth more.
    if (f >= 0 && costs.op[next] <= kMaxStepTstates &&
        !(idiomLabels && idiomAt(address + size) >= 0))
      label = fusedLabels[f];
  }
  if (k == 0 && idiomLabels && !trap && !isLong) {
    const int here = idiomAt(address);
    int i = here;
    if (i >= 0)
      label = idiomLabels[i];
    else if (o == static_cast<uint8_t>(Op::DBG) && (i = idiomAt(address + 1)) >= 0)
      label = dbgIdiomLabels[i];
    const int j = joinAt(address, here);
    if (j >= 0) {
      label = joinLabels[j];
      if (std::find(joinEntries.begin(), joinEntries.end(), address) == joinEntries.end())
        joinEntries.push_back(address);
    }
  }
  const uint32_t cost = trap ? 0u : isLong ? kMaxStepTstates : costs.op[o];
  fast[k][address] = Fast{label, cost, o, size};
}

template <bool kProfile>
Stop Vm::State::run(Tick until) {
  if (fault) return Stop::Fault;
  const uint8_t* const code = padded.data();
  const uint8_t* const xop = dispatch.data();
  const uint32_t codeSize = static_cast<uint32_t>(image->code.size());
  const uint32_t* const opCost = costs.op.data();
  const int16_t* const loopTop =
      costs.knobs.fastForward && !loopAtTop.empty() ? loopAtTop.data() : nullptr;
  uint32_t* const e = eval.data();
#if SIMBOT_COMPUTED_GOTO
  // The idioms' memory, in a register: a byte store through `mem` would
  // make the compiler reload its data pointer.
  uint8_t* const m = mem.data();
#endif
  busTouched = false;

#if SIMBOT_COMPUTED_GOTO
  static const void* const kLabels[] = {
#define OP(name, shape, pop, push, seq) &&L_##name,
#include "vm/opcodes.def"
#undef OP
      &&L_Trap_,  // kTrap
  };
// An ordinary handler sets ip past its instruction and op itself (NEXT
// leaves ip at opPc and op unset): constants, and two loads fewer per fast
// dispatch.
#define CASE(name)                                                         \
  L_##name : ip = opPc + static_cast<uint32_t>(instructionSize(Op::name)); \
  op = static_cast<uint8_t>(Op::name);
#define NEXT_IP
#define NEXT_OP
#define DISPATCH() goto* kLabels[op]
#define FAST_DISPATCH(d) goto* d.label
#else
#define CASE(name) case Op::name:
#define NEXT_IP ip += d.size;
#define NEXT_OP op = d.op;
#define DISPATCH() goto dispatchOp
#define FAST_DISPATCH(d) goto dispatchOp
  static const void* const kLabels[kOpCount + 1] = {};  // Fast::label unused
#endif
  constexpr int kRun = kProfile ? 1 : 0;
  if (fast[kRun].empty()) {
    fastLabels[kRun] = kLabels;
#if SIMBOT_COMPUTED_GOTO
    static const void* const kFused[] = {
#define SIMBOT_PAIR(a, b) &&F_##a##_##b,
        SIMBOT_FUSED_PAIRS(SIMBOT_PAIR)
#undef SIMBOT_PAIR
    };
    if (!kProfile) fusedLabels = kFused;
      // In the order of kIdiomShapes (idioms.h): the idioms, and DBG followed
      // by each (the DBG that starts most statements).
#define SIMBOT_IDIOM_NAMED(name, first) &&I_##name,
    static const void* const kIdioms[] = {SIMBOT_IDIOM_NAMES};
#undef SIMBOT_IDIOM_NAMED
#define SIMBOT_IDIOM_NAMED(name, first) &&D_##name,
    static const void* const kDbgIdioms[] = {SIMBOT_IDIOM_NAMES};
#undef SIMBOT_IDIOM_NAMED
    static_assert(std::size(kDbgIdioms) == kIdiomCount);
    static_assert(std::size(kIdioms) == kIdiomCount);
#define SIMBOT_JOIN_LABEL(C, l, c) &&J_##C##_##l##_##c,
    static const void* const kJoins[] = {SIMBOT_JOINS(SIMBOT_JOIN_LABEL)};
#undef SIMBOT_JOIN_LABEL
    static_assert(std::size(kJoins) == kJoinEnd);
    if (!kProfile) {
      setIdiomCosts();
      idiomLabels = kIdioms;
      dbgIdiomLabels = kDbgIdioms;
      joinLabels = kJoins;
    }
    longLabels[kRun] = &&L_Long_;
#endif
    fast[kRun].resize(dispatch.size());
    for (uint32_t a = 0; a < dispatch.size(); ++a) setFast(kRun, a);
  }
  const Fast* const fd = fast[kRun].data();
  Tick clk = now;
  uint32_t ip = pc;
  int esp = sp;
  uint64_t count = stats.instructions;
  Tick limit = 0;
  Tick longLimit = -1;  // L_Long_: the limit its instruction's tail runs to
#define SAVE() (now = clk, pc = ip, sp = esp, stats.instructions = count)
#define LOAD() (clk = now, ip = pc, esp = sp, count = stats.instructions)
#define NEXT                               \
  if (__builtin_expect(clk >= limit, 0)) { \
    goto slowNext;                         \
  }                                        \
  DISPATCH_NEXT
#define DISPATCH_NEXT                             \
  {                                               \
    const Fast& d = fd[ip];                       \
    opPc = ip;                                    \
    NEXT_OP                                       \
    clk += d.cost;                                \
    if constexpr (kProfile) {                     \
      if (d.op != kTrap) profile[opPc] += d.cost; \
    }                                             \
    ++count;                                      \
    NEXT_IP                                       \
    FAST_DISPATCH(d);                             \
  }
  // The slow boundary after a handler that has saved its state (SAVE()).
#define SLOW goto boundary
#define FAULT(message)         \
  {                            \
    SAVE();                    \
    raiseFault(message, opPc); \
    SLOW;                      \
  }

  // checkAccess() inline: only a faulting access leaves the fast path.
#define CHECK_ACCESS(address, bytes)                                                        \
  if (__builtin_expect((address) < kNullPageEnd || (address) + (bytes) > kMemorySize, 0)) { \
    SAVE();                                                                                 \
    checkAccess(address, bytes, opPc);                                                      \
    SLOW;                                                                                   \
  }

  uint32_t opPc = 0;
  uint8_t op = 0;
  // The operands of the instruction at opPc: an address, not a variable, so
  // that no register holds it (the compiler folds it into the loads).
#define operand (code + opPc + 1)
boundary:
  if (fault) return Stop::Fault;
  if (sp > kEvalSlots - kEvalGuard) {
    raiseFault("expression stack overflow (too many arguments or values pending)", pc);
    goto boundary;
  }
  if (busTouched) {
    busTouched = false;
    return Stop::Io;
  }
  if (now >= nextTimer) timerTick();
  if (now >= until) return halted ? Stop::Halted : Stop::Horizon;
  if (lib.awaitingBegin) {  // the end of a library call's sequence: no boundary
    // (for an atomic call this also keeps interrupts out until its effect)
    libBegin();
    goto boundary;
  }
  if (anyPending && iff1 && !eiShadow) {
    accept();
    goto boundary;
  }
  if (burn) {
    const uint32_t step = std::min(kMaxStepTstates, burn);
    now += step;
    burn -= step;
    eiShadow = false;
    goto boundary;
  }
  if (lib.active) {
    eiShadow = false;
    libStep();
    goto boundary;
  }
  if (halted) {
    // HALT: idle until the horizon, the next interrupt request from the
    // host, or PRT0's next tick.
    if (nextTimer < until) {
      now = nextTimer;
      goto boundary;
    }
    now = until;
    return Stop::Halted;
  }
  if (pc >= codeSize) {
    raiseFault(fmt::format("jump outside the program (0x{:04x})", pc), pc);
    goto boundary;
  }
  if (anyBreakpoint && breakpoints[pc] && !resumeAtBreakpoint) {
    resumeAtBreakpoint = true;
    return Stop::Breakpoint;
  }
  if (loopTop && loopTop[pc] >= 0 && fastForward(until)) goto boundary;
  resumeAtBreakpoint = false;
  opPc = pc;
  op = code[pc];
  if (op >= kOpCount) {
    raiseFault(fmt::format("invalid opcode {}", op), pc);
    goto boundary;
  }
  if (opCost[op] <= kMaxStepTstates) {
    now += opCost[op];
  } else {
    now += kMaxStepTstates;
    burn = opCost[op] - kMaxStepTstates;
    burnPc = opPc;
  }
  if constexpr (kProfile) profile[opPc] += opCost[op];
  ++stats.instructions;
  eiShadow = false;
  // The boundary after this instruction is slow too when anything rare is
  // due there (see "Fast path").
  limit = xop[opPc] == kTrap || burn || (anyPending && iff1) ? 0 : std::min(until, nextTimer);
  LOAD();
  ip += static_cast<uint32_t>(instructionSize(static_cast<Op>(op)));
  DISPATCH();
  // Operands, read from the padded code.
#define U16() le16(operand)
#define I32()                                              \
  (static_cast<uint32_t>(operand[0] | (operand[1] << 8)) | \
   (static_cast<uint32_t>(operand[2]) << 16) | (static_cast<uint32_t>(operand[3]) << 24))
  // A CO-shape instruction's target: its REL16 after the CoData address,
  // from the end of the instruction (pc is already past it; its handlers
  // have saved their state).
#define CO_TARGET()                                \
  static_cast<uint32_t>(static_cast<int32_t>(pc) + \
                        static_cast<int16_t>(operand[2] | (operand[3] << 8)))
#define TOP e[esp - 1]
#define POPV e[--esp]
  // A push past the eval stack's guard makes the next boundary slow, where
  // the guard faults as it always did (no instruction pushes more than two
  // slots, so the array's last kEvalGuard slots are never passed).
#define PUSHV(v)                                                       \
  {                                                                    \
    e[esp++] = (v);                                                    \
    if (__builtin_expect(esp > kEvalSlots - kEvalGuard, 0)) limit = 0; \
  }
#define BINARY(expr)         \
  {                          \
    const uint32_t b = POPV; \
    const uint32_t a = TOP;  \
    TOP = (expr);            \
  }                          \
  NEXT
  // The instruction's branches went the way `path` says (bit k: k-th
  // branch taken): charge the difference from the not-taken figure.
#define BRANCH_COST(path)                                                       \
  {                                                                             \
    const int32_t d = costs.branchDelta[op][(path)];                            \
    clk += d;                                                                   \
    if constexpr (kProfile) profile[opPc] += static_cast<uint64_t>(int64_t{d}); \
  }
  // A 16-bit comparison that materialises 0/1: the result, and the path its
  // branches take, from compare16, the one statement of the compare
  // semantics (the idioms' too).
#define COMPARE16_BODY(c)                           \
  {                                                 \
    const uint32_t b = POPV;                        \
    unsigned path = 0;                              \
    TOP = compare16<Op::c>(TOP, b, path) ? 1u : 0u; \
    BRANCH_COST(path);                              \
  }
#define COMPARE16(c) \
  COMPARE16_BODY(c)  \
  NEXT
  // A shift by n: op[] is one pass; n = 0 takes the JR Z (path 1), n > 1
  // adds n - 1 further passes, run like a long instruction's tail (in
  // steps of at most kMaxStepTstates, interruptible between them, as
  // the Z180 is between the loop's instructions): the slow boundary.
#define SHIFT(expr)                                       \
  {                                                       \
    const uint32_t n = POPV & 0xFF;                       \
    const uint32_t a = TOP;                               \
    TOP = (expr);                                         \
    if (n == 0) {                                         \
      BRANCH_COST(1u);                                    \
    } else if (n > 1) {                                   \
      const uint32_t more = (n - 1) * costs.loopPass[op]; \
      if constexpr (kProfile) profile[opPc] += more;      \
      burn += more;                                       \
      burnPc = opPc;                                      \
      limit = 0;                                          \
    }                                                     \
  }                                                       \
  NEXT
#if SIMBOT_COMPUTED_GOTO
  // Superinstructions (SIMBOT_FUSED_PAIRS): the first half's body, the
  // boundary between the halves, then the second half as NEXT would
  // dispatch it, its opcode known.
#define FIRST_PUSHW PUSHV(U16())
#define FIRST_LDGW PUSHV(rd16(U16()))
#define FIRST_STGW wr16(U16(), POPV)
#define FIRST_POP --esp
#define FIRST_DBG
#define FIRST_INCGW wr16(U16(), rd16(U16()) + 1u)
#define FIRST_ADDW            \
  {                           \
    const uint32_t b = POPV;  \
    TOP = (TOP + b) & 0xFFFF; \
  }
#define FIRST_LTW COMPARE16_BODY(LTW)
#define FIRST_SUBW            \
  {                           \
    const uint32_t b = POPV;  \
    TOP = (TOP - b) & 0xFFFF; \
  }
#define FIRST_LDLW                  \
  {                                 \
    const uint32_t a = mfp + U16(); \
    CHECK_ACCESS(a, 2);             \
    PUSHV(rd16(a));                 \
  }
#define FIRST_STLW                  \
  {                                 \
    const uint32_t a = mfp + U16(); \
    const uint32_t v = POPV;        \
    CHECK_ACCESS(a, 2);             \
    wr16(a, v);                     \
  }
#define FIRST_ENTER                                                                  \
  {                                                                                  \
    const uint32_t size = U16();                                                     \
    if (msp < stackLimit + size) FAULT("stack overflow");                            \
    msp -= size;                                                                     \
    mfp = msp;                                                                       \
    if (static_cast<int>(calls.size()) > (ints.empty() ? 0 : ints.back().callDepth)) \
      calls.back().autoFrame = true;                                                 \
  }
#define NEXT_TO(second)                                     \
  if (__builtin_expect(clk >= limit, 0)) {                  \
    SAVE();                                                 \
    goto boundary;                                          \
  }                                                         \
  opPc = ip;                                                \
  op = static_cast<uint8_t>(Op::second);                    \
  clk += opCost[op];                                        \
  if constexpr (kProfile) profile[opPc] += opCost[op];      \
  ++count;                                                  \
  ip += static_cast<uint32_t>(instructionSize(Op::second)); \
  goto L_##second;
#define SIMBOT_PAIR(a, b)                                      \
  F_##a##_##b : {                                              \
    ip = opPc + static_cast<uint32_t>(instructionSize(Op::a)); \
    op = static_cast<uint8_t>(Op::a);                          \
    FIRST_##a;                                                 \
    NEXT_TO(b)                                                 \
  }
  SIMBOT_FUSED_PAIRS(SIMBOT_PAIR)
#undef SIMBOT_PAIR
#undef NEXT_TO
#undef FIRST_PUSHW
#undef FIRST_LDGW
#undef FIRST_STGW
#undef FIRST_POP
#undef FIRST_DBG
#undef FIRST_INCGW
#undef FIRST_ADDW
#undef FIRST_LTW
#undef FIRST_SUBW
#undef FIRST_LDLW
#undef FIRST_STLW
#undef FIRST_ENTER

  // Idioms (idioms.h): the first piece has been dispatched (charged and
  // counted) as usual. If the boundaries inside the idiom all come before
  // `limit` even at the pieces' slowest paths, and its pushes stay inside
  // the expression stack's guard, nothing can happen at them (see "Fast
  // path"), so the idiom does the pieces' work at once, charges their
  // actual costs and counts them; otherwise, and where a piece would
  // fault, the first piece runs alone and the rest are dispatched one by
  // one. Operands are read at their offsets from the first's.
// As rd16, rd8, wr16 and wr8, on m.
#define M_RD8(a) static_cast<uint32_t>(m[(a)&0xFFFF])
// Words: the decoder takes no idiom or join whose global is at 0xFFFF (its
// word wraps), and an auto's address is checked below 0xFFFF.
#define M_RD16(a) le16(m + (a))
#define M_WR8(a, v) (m[(a)&0xFFFF] = static_cast<uint8_t>(v))
#define M_WR16(a, v) setLe16(m + (a), (v))
#define OPND16(off) le16(operand + (off))
#define IDIOM_ENTER(kind, first, peak)                                                       \
  const IdiomCost& ic = idiomCosts[kind];                                                    \
  if (__builtin_expect(clk + ic.span >= limit || esp > kEvalSlots - kEvalGuard - (peak), 0)) \
    goto L_##first;
#define IDIOM_LOAD_LDGW(x) const uint32_t x = M_RD16(OPND16(0));
#define IDIOM_LOAD_LDLW(x)                                                                         \
  const uint32_t x##Address = mfp + OPND16(0);                                                     \
  if (__builtin_expect(x##Address < kNullPageEnd || x##Address + 2 > kMemorySize, 0)) goto L_LDLW; \
  const uint32_t x = M_RD16(x##Address);
#define IDIOM_SRC_LDGW(v) M_RD16(v)
#define IDIOM_SRC_PUSHW(v) (v)
#define IDIOM_OP_ADDW(x, y) (((x) + (y)) & 0xFFFF)
#define IDIOM_OP_SUBW(x, y) (((x) - (y)) & 0xFFFF)
#define IDIOM_TARGET(ip, off) \
  static_cast<uint32_t>(static_cast<int32_t>(ip) + static_cast<int16_t>(OPND16(off)))
  // PUSHW base; LDGW i; ADDW; ...: the byte at base + i.
#define IDIOM_BYTE_ADDRESS(first)                              \
  const uint32_t a = (OPND16(0) + M_RD16(OPND16(3))) & 0xFFFF; \
  if (__builtin_expect(a < kNullPageEnd || a + 1 > kMemorySize, 0)) goto L_##first;
I_StoreByte : {  // PUSHW base; LDGW i; ADDW; PUSHW v; STIB
  IDIOM_ENTER(kIdiomStoreByte, PUSHW, 2)
  IDIOM_BYTE_ADDRESS(PUSHW)
  M_WR8(a, OPND16(7));
  clk += ic.base;
  count += 4;
  ip = opPc + 11;
}
  NEXT;
I_Byte : {  // PUSHW base; LDGW i; ADDW; LDIB
  IDIOM_ENTER(kIdiomByte, PUSHW, 2)
  IDIOM_BYTE_ADDRESS(PUSHW)
  e[esp++] = M_RD8(a);
  clk += ic.base;
  count += 3;
  ip = opPc + 8;
}
  NEXT;
#define IDIOM_BYTE_BRANCH(name, br, takenIf)                                           \
  I_##name : { /* PUSHW base; LDGW i; ADDW; LDIB; br t */                              \
    IDIOM_ENTER(kIdiom##name, PUSHW, 2)                                                \
    IDIOM_BYTE_ADDRESS(PUSHW)                                                          \
    const uint32_t v = M_RD8(a);                                                       \
    const bool taken = (takenIf);                                                      \
    clk += Tick{ic.base} + costs.branchDelta[static_cast<int>(Op::br)][taken ? 1 : 0]; \
    count += 4;                                                                        \
    ip = taken ? IDIOM_TARGET(opPc + 11, 8) : opPc + 11;                               \
  }                                                                                    \
  NEXT;
  IDIOM_BYTE_BRANCH(ByteJZ, JZ, v == 0)
  IDIOM_BYTE_BRANCH(ByteJNZ, JNZ, v != 0)
  // A compare-and-branch's pieces but the first, that piece dispatched.
#define IDIOM_CB_BODY(l, c, b)                                  \
  {                                                             \
    const IdiomCost& cb = idiomCosts[kIdiomCB_##l##_##c##_##b]; \
    IDIOM_LOAD_##l(x) unsigned path = 0;                        \
    const bool r = compare16<Op::c>(x, OPND16(3), path);        \
    const bool taken = Op::b == Op::JZ ? !r : r;                \
    clk += cb.path[path * 2 + (taken ? 1 : 0)];                 \
    count += 3;                                                 \
    ip = taken ? IDIOM_TARGET(opPc + 10, 7) : opPc + 10;        \
  }
#define SIMBOT_IDIOM(l, c, b)       \
  I_CB_##l##_##c##_##b              \
      : {/* l x; PUSHW k; c; b t */ \
         IDIOM_ENTER(kIdiomCB_##l##_##c##_##b, l, 2) IDIOM_CB_BODY(l, c, b)} NEXT;
  SIMBOT_IDIOMS_CB(SIMBOT_IDIOM)
#undef SIMBOT_IDIOM
  // LDGW a; s b; o; STGW c: c = a o b (the BS and BSJ idioms, the joins'
  // BSJ closers).
#define IDIOM_LOAD_OP_STORE(s, o)                \
  {                                              \
    const uint32_t x = M_RD16(OPND16(0));        \
    const uint32_t y = IDIOM_SRC_##s(OPND16(3)); \
    M_WR16(OPND16(7), IDIOM_OP_##o(x, y));       \
  }
#define SIMBOT_IDIOM(s, o)                        \
  I_BS_##s##_##o : { /* LDGW a; s b; o; STGW c */ \
    IDIOM_ENTER(kIdiomBS_##s##_##o, LDGW, 2)      \
    IDIOM_LOAD_OP_STORE(s, o)                     \
    clk += ic.base;                               \
    count += 3;                                   \
    ip = opPc + 10;                               \
  }                                               \
  NEXT;
  SIMBOT_IDIOMS_BS(SIMBOT_IDIOM)
#undef SIMBOT_IDIOM
#define SIMBOT_IDIOM(l, o)                                   \
  I_LK_##l##_##o : { /* l x; PUSHW k; o */                   \
    IDIOM_ENTER(kIdiomLK_##l##_##o, l, 2)                    \
    IDIOM_LOAD_##l(x) e[esp++] = IDIOM_OP_##o(x, OPND16(3)); \
    clk += ic.base;                                          \
    count += 2;                                              \
    ip = opPc + 7;                                           \
  }                                                          \
  NEXT;
  SIMBOT_IDIOMS_LK(SIMBOT_IDIOM)
#undef SIMBOT_IDIOM
#define SIMBOT_IDIOM(s, o)                                \
  I_BSJ_##s##_##o : { /* LDGW a; s b; o; STGW c; JMP t */ \
    IDIOM_ENTER(kIdiomBSJ_##s##_##o, LDGW, 2)             \
    IDIOM_LOAD_OP_STORE(s, o)                             \
    clk += ic.base;                                       \
    count += 4;                                           \
    ip = IDIOM_TARGET(opPc + 13, 10);                     \
  }                                                       \
  NEXT;
  SIMBOT_IDIOMS_BS(SIMBOT_IDIOM)
#undef SIMBOT_IDIOM
  // CALL's own faults (stack overflow, no headroom) leave it to run alone.
#define SIMBOT_IDIOM(l, o)                                                  \
  I_LKC_##l##_##o : { /* l x; PUSHW k; o; CALL f */                         \
    IDIOM_ENTER(kIdiomLKC_##l##_##o, l, 2)                                  \
    IDIOM_LOAD_##l(x) if (msp < stackLimit + kCallFrameBytes ||             \
                          esp + 1 > kEvalSlots - kEvalHeadroom) goto L_##l; \
    e[esp++] = IDIOM_OP_##o(x, OPND16(3));                                  \
    calls.push_back(CallFrame{opPc + 10, msp, mfp, false});                 \
    msp -= kCallFrameBytes;                                                 \
    clk += ic.base;                                                         \
    count += 3;                                                             \
    ip = OPND16(7);                                                         \
  }                                                                         \
  NEXT;
  SIMBOT_IDIOMS_LK(SIMBOT_IDIOM)
#undef SIMBOT_IDIOM
// A long MULW inside: its steps' boundaries are all inside the span.
I_MulAdd : { /* LDGW a; LDGW b; MULW; ADDW */
  IDIOM_ENTER(kIdiomMulAdd, LDGW, 2)
  const uint32_t p = (M_RD16(OPND16(0)) * M_RD16(OPND16(3))) & 0xFFFF;
  e[esp - 1] = (e[esp - 1] + p) & 0xFFFF;
  clk += ic.base;
  count += 3;
  ip = opPc + 8;
}
  NEXT;
I_Mul : { /* LDGW a; LDGW b; MULW */
  IDIOM_ENTER(kIdiomMul, LDGW, 2)
  e[esp++] = (M_RD16(OPND16(0)) * M_RD16(OPND16(3))) & 0xFFFF;
  clk += ic.base;
  count += 2;
  ip = opPc + 7;
}
  NEXT;
#define SIMBOT_IDIOM(o)                            \
  I_KS_##o : { /* PUSHW k; o; STGW a */            \
    IDIOM_ENTER(kIdiomKS_##o, PUSHW, 1)            \
    const uint32_t v = e[--esp];                   \
    M_WR16(OPND16(4), IDIOM_OP_##o(v, OPND16(0))); \
    clk += ic.base;                                \
    count += 2;                                    \
    ip = opPc + 7;                                 \
  }                                                \
  NEXT;
  SIMBOT_IDIOMS_KS(SIMBOT_IDIOM)
#undef SIMBOT_IDIOM
I_StoreConst : { /* PUSHW k; STGW a */
  IDIOM_ENTER(kIdiomStoreConst, PUSHW, 1)
  M_WR16(OPND16(3), OPND16(0));
  clk += ic.base;
  count += 1;
  ip = opPc + 6;
}
  NEXT;
I_LoadRet : { /* LDLW x; RET: RET's fault leaves it to run alone */
  IDIOM_ENTER(kIdiomLoadRet, LDLW, 1)
  IDIOM_LOAD_LDLW(x)
  if (__builtin_expect(calls.empty() || (!ints.empty() &&
                                         static_cast<int>(calls.size()) <= ints.back().callDepth),
                       0))
    goto L_LDLW;
  e[esp++] = x;
  const CallFrame f = calls.back();
  calls.pop_back();
  clk += ic.base;
  if (f.autoFrame) clk += costs.autoFrameRet;  // as RET: POP IX
  count += 1;
  ip = f.retPc;
  msp = f.msp;
  mfp = f.mfp;
}
  NEXT;
  // Joins (idioms.h): a loop's closer, its JMP, then the compare-and-branch
  // at the JMP's target, in one dispatch. The closer's first piece has been
  // dispatched as usual. If all the boundaries up to the target's last
  // piece come before `limit` at their slowest paths (joinSpans) and the
  // pushes stay inside the guard, nothing can happen at them; otherwise
  // the closer runs as it does alone (its idiom, or the INCGW; JMP pair),
  // and the target is dispatched after it. A target that would fault
  // leaves from its first piece, as its idiom does.
#define JOIN_CLOSE_IJ(t)                     \
  M_WR16(OPND16(0), M_RD16(OPND16(0)) + 1u); \
  clk += opCost[static_cast<int>(Op::JMP)];  \
  count += 1;                                \
  t = IDIOM_TARGET(opPc + 6, 3);
#define JOIN_ALONE_IJ F_INCGW_JMP
#define JOIN_CLOSE_BSJ(s, o, t)                  \
  {                                              \
    IDIOM_LOAD_OP_STORE(s, o)                    \
    clk += idiomCosts[kIdiomBSJ_##s##_##o].base; \
    count += 4;                                  \
    t = IDIOM_TARGET(opPc + 13, 10);             \
  }
#define JOIN_CLOSE_BSJ_LDGW_ADDW(t) JOIN_CLOSE_BSJ(LDGW, ADDW, t)
#define JOIN_CLOSE_BSJ_LDGW_SUBW(t) JOIN_CLOSE_BSJ(LDGW, SUBW, t)
#define JOIN_CLOSE_BSJ_PUSHW_ADDW(t) JOIN_CLOSE_BSJ(PUSHW, ADDW, t)
#define JOIN_CLOSE_BSJ_PUSHW_SUBW(t) JOIN_CLOSE_BSJ(PUSHW, SUBW, t)
#define JOIN_ALONE_BSJ_LDGW_ADDW I_BSJ_LDGW_ADDW
#define JOIN_ALONE_BSJ_LDGW_SUBW I_BSJ_LDGW_SUBW
#define JOIN_ALONE_BSJ_PUSHW_ADDW I_BSJ_PUSHW_ADDW
#define JOIN_ALONE_BSJ_PUSHW_SUBW I_BSJ_PUSHW_SUBW
#define SIMBOT_JOIN(C, l, c)                                                                      \
  J_##C##_##l##_##c : {                                                                           \
    if (__builtin_expect(                                                                         \
            clk + joinSpans[kJoin_##C##_##l##_##c] >= limit || esp > kEvalSlots - kEvalGuard - 2, \
            0))                                                                                   \
      goto JOIN_ALONE_##C;                                                                        \
    uint32_t t;                                                                                   \
    JOIN_CLOSE_##C(t) /* the target's first piece, as NEXT dispatches it */                       \
        opPc = t;                                                                                 \
    clk += opCost[static_cast<int>(Op::l)];                                                       \
    ++count;                                                                                      \
    ip = t + static_cast<uint32_t>(instructionSize(Op::l));                                       \
    IDIOM_CB_BODY(l, c, JZ)                                                                       \
  }                                                                                               \
  NEXT;
  SIMBOT_JOINS(SIMBOT_JOIN)
#undef SIMBOT_JOIN
#undef JOIN_CLOSE_IJ
#undef JOIN_ALONE_IJ
#undef JOIN_CLOSE_BSJ
#undef JOIN_CLOSE_BSJ_LDGW_ADDW
#undef JOIN_CLOSE_BSJ_LDGW_SUBW
#undef JOIN_CLOSE_BSJ_PUSHW_ADDW
#undef JOIN_CLOSE_BSJ_PUSHW_SUBW
#undef JOIN_ALONE_BSJ_LDGW_ADDW
#undef JOIN_ALONE_BSJ_LDGW_SUBW
#undef JOIN_ALONE_BSJ_PUSHW_ADDW
#undef JOIN_ALONE_BSJ_PUSHW_SUBW
#undef IDIOM_CB_BODY
#undef IDIOM_LOAD_OP_STORE
  // DBG, then the idiom after it: the boundary between them, then the
  // idiom's first piece charged as NEXT would, without the table load.
#define DBG_THEN(name, first)                                \
  D_##name : {                                               \
    ip = opPc + 1; /* past DBG */                            \
    if (__builtin_expect(clk >= limit, 0)) {                 \
      SAVE();                                                \
      goto boundary;                                         \
    }                                                        \
    opPc = ip;                                               \
    clk += opCost[static_cast<int>(Op::first)];              \
    ++count;                                                 \
    ip += static_cast<uint32_t>(instructionSize(Op::first)); \
    goto I_##name;                                           \
  }
#define SIMBOT_IDIOM_NAMED(name, first) DBG_THEN(name, first)
  SIMBOT_IDIOM_NAMES
#undef SIMBOT_IDIOM_NAMED
#undef DBG_THEN
#undef M_RD8
#undef M_RD16
#undef M_WR8
#undef M_WR16
#undef OPND16
#undef IDIOM_ENTER
#undef IDIOM_LOAD_LDGW
#undef IDIOM_LOAD_LDLW
#undef IDIOM_SRC_LDGW
#undef IDIOM_SRC_PUSHW
#undef IDIOM_OP_ADDW
#undef IDIOM_OP_SUBW
#undef IDIOM_TARGET
#undef IDIOM_BYTE_ADDRESS
#undef IDIOM_BYTE_BRANCH
#endif
slowNext:
  if (longLimit >= 0) {  // the tail of a long instruction (L_Long_)
    limit = longLimit;
    longLimit = -1;
    while (burn && clk < limit) {
      const uint32_t step = std::min(kMaxStepTstates, burn);
      clk += step;
      burn -= step;
    }
    if (!burn && clk < limit) DISPATCH_NEXT;
  }
  SAVE();
  SLOW;
#if SIMBOT_COMPUTED_GOTO
L_Long_ : {
  op = fd[opPc].op;
  const uint32_t rest = opCost[op] - kMaxStepTstates;
  if constexpr (kProfile) profile[opPc] += rest;
  burn = rest;
  burnPc = opPc;
  longLimit = limit;
  limit = 0;
  DISPATCH();
}
#endif
#if !SIMBOT_COMPUTED_GOTO
dispatchOp:
  switch (static_cast<Op>(op)) {
    case Op::Count_:
#else
L_Trap_ :
#endif
    {  // the slow boundary looks first (see "Fast path")
      --count;
      ip = opPc;
      SAVE();
      SLOW;
    }
      CASE(PUSHW) PUSHV(U16());
      NEXT;
      CASE(PUSHL) PUSHV(I32());
      NEXT;
      CASE(PUSHF) PUSHV(I32());
      NEXT;
      CASE(POP)-- esp;
      NEXT;
      CASE(DUP) {
        const uint32_t v = TOP;
        PUSHV(v);
      }
      NEXT;
      CASE(TUCK) {
        const uint32_t b = POPV, a = POPV;
        PUSHV(b);
        PUSHV(a);
        PUSHV(b);
      }
      NEXT;
      CASE(LDGB) PUSHV(rd8(U16()));
      NEXT;
      CASE(LDGW) PUSHV(rd16(U16()));
      NEXT;
      CASE(LDGL) PUSHV(rd32(U16()));
      NEXT;
      CASE(STGB) wr8(U16(), POPV);
      NEXT;
      CASE(STGW) wr16(U16(), POPV);
      NEXT;
      CASE(STGL) wr32(U16(), POPV);
      NEXT;
      CASE(INCGW) {
        const uint32_t a = U16();
        wr16(a, rd16(a) + 1u);
      }
      NEXT;
      CASE(DECGW) {
        const uint32_t a = U16();
        wr16(a, rd16(a) - 1u);
      }
      NEXT;
      CASE(INCGL) {
        const uint32_t a = U16();
        wr32(a, rd32(a) + 1u);
      }
      NEXT;
      // One shape per addressing mode; the width picks rd/wr and the mask.
#define LOAD_LOCAL(bytes, read)     \
  {                                 \
    const uint32_t a = mfp + U16(); \
    CHECK_ACCESS(a, bytes);         \
    PUSHV(read(a));                 \
  }                                 \
  NEXT
#define STORE_LOCAL(bytes, write)   \
  {                                 \
    const uint32_t a = mfp + U16(); \
    const uint32_t v = POPV;        \
    CHECK_ACCESS(a, bytes);         \
    write(a, v);                    \
  }                                 \
  NEXT
#define LOAD_INDIRECT(bytes, read)   \
  {                                  \
    const uint32_t a = TOP & 0xFFFF; \
    CHECK_ACCESS(a, bytes);          \
    TOP = read(a);                   \
  }                                  \
  NEXT
      // addr value -- ; or, keeping the value: addr value -- value
#define STORE_INDIRECT(bytes, write, mask, keep)     \
  {                                                  \
    const uint32_t v = POPV;                         \
    const uint32_t a = (keep ? TOP : POPV) & 0xFFFF; \
    CHECK_ACCESS(a, bytes);                          \
    write(a, v);                                     \
    if (keep) TOP = v & (mask);                      \
  }                                                  \
  NEXT
      CASE(LDLB) LOAD_LOCAL(1, rd8);
      CASE(LDLW) LOAD_LOCAL(2, rd16);
      CASE(LDLL) LOAD_LOCAL(4, rd32);
      CASE(STLB) STORE_LOCAL(1, wr8);
      CASE(STLW) STORE_LOCAL(2, wr16);
      CASE(STLL) STORE_LOCAL(4, wr32);
      CASE(LEAL) PUSHV((mfp + U16()) & 0xFFFF);
      NEXT;
      CASE(LDIB) LOAD_INDIRECT(1, rd8);
      CASE(LDIW) LOAD_INDIRECT(2, rd16);
      CASE(LDIL) LOAD_INDIRECT(4, rd32);
      CASE(STIB) STORE_INDIRECT(1, wr8, 0xFFu, false);
      CASE(STIW) STORE_INDIRECT(2, wr16, 0xFFFFu, false);
      CASE(STIL) STORE_INDIRECT(4, wr32, 0xFFFFFFFFu, false);
      CASE(STIBK) STORE_INDIRECT(1, wr8, 0xFFu, true);
      CASE(STIWK) STORE_INDIRECT(2, wr16, 0xFFFFu, true);
      CASE(STILK) STORE_INDIRECT(4, wr32, 0xFFFFFFFFu, true);
#undef LOAD_LOCAL
#undef STORE_LOCAL
#undef LOAD_INDIRECT
#undef STORE_INDIRECT
      CASE(COPY) {
        const uint32_t n = U16();
        const uint32_t src = POPV & 0xFFFF, dst = POPV & 0xFFFF;
        CHECK_ACCESS(src, n);
        CHECK_ACCESS(dst, n);
        std::memmove(&mem[dst], &mem[src], n);
      }
      NEXT;

      CASE(ADDW) BINARY((a + b) & 0xFFFF);
      CASE(SUBW) BINARY((a - b) & 0xFFFF);
      CASE(MULW) BINARY((a * b) & 0xFFFF);
      CASE(DIVW) {
        const int32_t b = asInt16(POPV), a = asInt16(TOP);
        if (b == 0) {
          FAULT("division by zero");
        }
        TOP = w(a / b);
      }
      NEXT;
      CASE(DIVUW) {
        const uint32_t b = POPV & 0xFFFF, a = TOP & 0xFFFF;
        if (b == 0) {
          FAULT("division by zero");
        }
        TOP = a / b;
      }
      NEXT;
      CASE(MODW) {
        const int32_t b = asInt16(POPV), a = asInt16(TOP);
        if (b == 0) {
          FAULT("division by zero");
        }
        TOP = w(a % b);
      }
      NEXT;
      CASE(MODUW) {
        const uint32_t b = POPV & 0xFFFF, a = TOP & 0xFFFF;
        if (b == 0) {
          FAULT("division by zero");
        }
        TOP = a % b;
      }
      NEXT;
      CASE(ANDW) BINARY(a & b & 0xFFFF);
      CASE(ORW) BINARY((a | b) & 0xFFFF);
      CASE(XORW) BINARY((a ^ b) & 0xFFFF);
      // The 16-bit shifts loop once per bit (opcodes.def): the count's low
      // byte n is the number of passes (n = 0 takes JR Z over the loop);
      // 16 or more passes leave nothing (or the sign) behind.
      CASE(SHLW) SHIFT((n >= 16 ? 0u : (a << n) & 0xFFFF));
      CASE(SHRW) SHIFT(w(asInt16(a) >> std::min<uint32_t>(n, 15)));
      CASE(SHRUW) SHIFT((n >= 16 ? 0u : (a & 0xFFFF) >> n));
      CASE(NEGW) TOP = w(-static_cast<int32_t>(TOP));
      NEXT;
      CASE(NOTW) TOP = ~TOP & 0xFFFF;
      NEXT;
      CASE(LNOTW) {
        TOP = (TOP & 0xFFFF) == 0;
        BRANCH_COST(TOP == 0 ? 1u : 0u);
      }
      NEXT;
      CASE(W2B) TOP &= 0xFF;
      NEXT;
      CASE(EQW) COMPARE16(EQW);
      CASE(NEW) COMPARE16(NEW);
      CASE(LTW) COMPARE16(LTW);
      CASE(LEW) COMPARE16(LEW);
      CASE(GTW) COMPARE16(GTW);
      CASE(GEW) COMPARE16(GEW);
      CASE(LTUW) COMPARE16(LTUW);
      CASE(LEUW) COMPARE16(LEUW);
      CASE(GTUW) COMPARE16(GTUW);
      CASE(GEUW) COMPARE16(GEUW);

      CASE(ADDL) BINARY(a + b);
      CASE(SUBL) BINARY(a - b);
      CASE(MULL) BINARY(a * b);
      CASE(DIVL) {
        const int64_t b = static_cast<int32_t>(POPV), a = static_cast<int32_t>(TOP);
        if (b == 0) {
          FAULT("division by zero");
        }
        TOP = static_cast<uint32_t>(a / b);  // INT32_MIN / -1 wraps
      }
      NEXT;
      CASE(DIVUL) {
        const uint32_t b = POPV, a = TOP;
        if (b == 0) {
          FAULT("division by zero");
        }
        TOP = a / b;
      }
      NEXT;
      CASE(MODL) {
        const int64_t b = static_cast<int32_t>(POPV), a = static_cast<int32_t>(TOP);
        if (b == 0) {
          FAULT("division by zero");
        }
        TOP = static_cast<uint32_t>(a % b);
      }
      NEXT;
      CASE(MODUL) {
        const uint32_t b = POPV, a = TOP;
        if (b == 0) {
          FAULT("division by zero");
        }
        TOP = a % b;
      }
      NEXT;
      CASE(ANDL) BINARY(a & b);
      CASE(ORL) BINARY(a | b);
      CASE(XORL) BINARY(a ^ b);
      CASE(SHLL) BINARY((b & 0xFF) >= 32 ? 0u : a << (b & 0xFF));
      CASE(SHRL)
      BINARY(static_cast<uint32_t>(static_cast<int32_t>(a) >> std::min<uint32_t>(b & 0xFF, 31)));
      CASE(SHRUL) BINARY((b & 0xFF) >= 32 ? 0u : a >> (b & 0xFF));
      CASE(NEGL) TOP = 0u - TOP;
      NEXT;
      CASE(NOTL) TOP = ~TOP;
      NEXT;
      CASE(TESTL) {
        TOP = TOP != 0;
        BRANCH_COST(TOP == 0 ? 1u : 0u);
      }
      NEXT;
      CASE(EQL) BINARY(a == b);
      CASE(NEL) BINARY(a != b);
      CASE(LTL) BINARY(static_cast<int32_t>(a) < static_cast<int32_t>(b));
      CASE(LEL) BINARY(static_cast<int32_t>(a) <= static_cast<int32_t>(b));
      CASE(GTL) BINARY(static_cast<int32_t>(a) > static_cast<int32_t>(b));
      CASE(GEL) BINARY(static_cast<int32_t>(a) >= static_cast<int32_t>(b));
      CASE(LTUL) BINARY(a < b);
      CASE(LEUL) BINARY(a <= b);
      CASE(GTUL) BINARY(a > b);
      CASE(GEUL) BINARY(a >= b);

      CASE(ADDF) BINARY(fromFloat(asFloat(a) + asFloat(b)));
      CASE(SUBF) BINARY(fromFloat(asFloat(a) - asFloat(b)));
      CASE(MULF) BINARY(fromFloat(asFloat(a) * asFloat(b)));
      CASE(DIVF) {
        const float b = asFloat(POPV), a = asFloat(TOP);
        if (b == 0.0f) {
          FAULT("division by zero");
        }
        TOP = fromFloat(a / b);
      }
      NEXT;
      CASE(NEGF) TOP ^= 0x80000000u;
      NEXT;
      CASE(TESTF) TOP = asFloat(TOP) != 0.0f;
      NEXT;
      CASE(EQF) BINARY(asFloat(a) == asFloat(b));
      CASE(NEF) BINARY(asFloat(a) != asFloat(b));
      CASE(LTF) BINARY(asFloat(a) < asFloat(b));
      CASE(LEF) BINARY(asFloat(a) <= asFloat(b));
      CASE(GTF) BINARY(asFloat(a) > asFloat(b));
      CASE(GEF) BINARY(asFloat(a) >= asFloat(b));

      CASE(W2L) TOP = static_cast<uint32_t>(static_cast<int32_t>(asInt16(TOP)));
      NEXT;
      CASE(UW2L) TOP &= 0xFFFF;
      NEXT;
      CASE(L2W) TOP &= 0xFFFF;
      NEXT;
      CASE(W2F) TOP = fromFloat(static_cast<float>(asInt16(TOP)));
      NEXT;
      CASE(UW2F) TOP = fromFloat(static_cast<float>(TOP & 0xFFFF));
      NEXT;
      CASE(L2F) TOP = fromFloat(static_cast<float>(static_cast<int32_t>(TOP)));
      NEXT;
      CASE(UL2F) TOP = fromFloat(static_cast<float>(TOP));
      NEXT;
      CASE(F2W)
      TOP = static_cast<uint32_t>(truncToRange(asFloat(TOP), -2147483648.0, 2147483647.0)) & 0xFFFF;
      NEXT;
      CASE(F2L)
      TOP = static_cast<uint32_t>(truncToRange(asFloat(TOP), -2147483648.0, 2147483647.0));
      NEXT;
      CASE(F2UL)
      TOP = static_cast<uint32_t>(truncToRange(asFloat(TOP), -2147483648.0, 4294967295.0));
      NEXT;

      CASE(JMP) ip = static_cast<uint32_t>(static_cast<int32_t>(ip) + static_cast<int16_t>(U16()));
      NEXT;
      CASE(JZ) {
        const uint32_t target =
            static_cast<uint32_t>(static_cast<int32_t>(ip) + static_cast<int16_t>(U16()));
        const bool taken = (POPV & 0xFFFF) == 0;
        BRANCH_COST(taken ? 1u : 0u);
        if (taken) ip = target;
      }
      NEXT;
      CASE(JNZ) {
        const uint32_t target =
            static_cast<uint32_t>(static_cast<int32_t>(ip) + static_cast<int16_t>(U16()));
        const bool taken = (POPV & 0xFFFF) != 0;
        BRANCH_COST(taken ? 1u : 0u);
        if (taken) ip = target;
      }
      NEXT;
      CASE(CALL) {
        if (msp < stackLimit + kCallFrameBytes) {
          FAULT("stack overflow");
        }
        if (esp > kEvalSlots - kEvalHeadroom) {
          FAULT("stack overflow (expression stack)");
        }
        calls.push_back(CallFrame{ip, msp, mfp, false});
        msp -= kCallFrameBytes;
        ip = U16();
      }
      NEXT;
      CASE(ENTER) {
        const uint32_t size = U16();
        if (msp < stackLimit + size) {
          FAULT("stack overflow");
        }
        msp -= size;
        mfp = msp;
        // The frame now holds the caller's IX (ENTER's PUSH IX): its RET
        // pops it. (ENTER in main or in a handler has no CallFrame of its
        // own; a handler's RETI restores IX anyway.)
        if (static_cast<int>(calls.size()) > (ints.empty() ? 0 : ints.back().callDepth))
          calls.back().autoFrame = true;
      }
      NEXT;
      CASE(RET) {
        if (calls.empty() ||
            (!ints.empty() && static_cast<int>(calls.size()) <= ints.back().callDepth)) {
          FAULT("return with no caller");
        }
        const CallFrame f = calls.back();
        calls.pop_back();
        if (f.autoFrame) {  // POP IX: only #class auto frames set IX up
          clk += costs.autoFrameRet;
          if constexpr (kProfile) profile[opPc] += costs.autoFrameRet;
        }
        ip = f.retPc;
        msp = f.msp;
        mfp = f.mfp;
      }
      NEXT;
      CASE(RETI) {
        SAVE();
        if (ints.empty() || static_cast<int>(calls.size()) != ints.back().callDepth) {
          raiseFault("RETI outside an interrupt handler", opPc);
          SLOW;
        }
        InterruptFrame& f = ints.back();
        if (f.evalSp != sp) {
          raiseFault("internal error: stack imbalance at RETI", opPc);
          SLOW;
        }
        pc = f.retPc;
        msp = f.msp;
        mfp = f.mfp;
        halted = f.halted;
        burn = f.burn;
        lib = std::move(f.lib);
        const Irq irq = f.irq;
        ints.pop_back();
        bus->interruptReturned(now, irq);
        // The epilogue's EI: IFF1 is set when the RETI after it ends.
        if (costs.knobs.epilogueEi && !iff1) bus->iffChanged(now, true);
        if (costs.knobs.epilogueEi) iff1 = iff2 = true;
        busTouched = true;
      }
      SLOW;
      CASE(HALT) {
        SAVE();
        pc = opPc;  // stays on HALT; an interrupt returns here
        if (!halted) flushConsole();
        halted = true;
      }
      SLOW;
      CASE(LIB) {
        SAVE();
        const int id = operand[0];
        const int argc = operand[1];
        if (id >= kLibCount || argc > kMaxLibArgs || argc > sp) {
          raiseFault("invalid library call", opPc);
          SLOW;
        }
        libCall(static_cast<Lib>(id), argc, opPc);
      }
      SLOW;
      CASE(EI) {
        SAVE();
        if (!iff1) bus->iffChanged(now, true);
        iff1 = iff2 = true;
        eiShadow = true;
      }
      SLOW;
      CASE(DI) {
        SAVE();
        if (iff1) bus->iffChanged(now, false);
        iff1 = iff2 = false;
      }
      SLOW;
      CASE(DBG) NEXT;
      CASE(COSTATE) {
        SAVE();
        const uint32_t cd = U16();
        const uint32_t end = CO_TARGET();
        if (!checkAccess(cd, kCoDataSize, opPc)) SLOW;
        const uint8_t state = rd8(cd + kCoState);
        if (state & kCoStopped) {
          now += costs.costateStoppedDelta;
          if constexpr (kProfile)
            profile[opPc] += static_cast<uint64_t>(int64_t{costs.costateStoppedDelta});
          pc = end;
          SLOW;
        }
        wr8(cd + kCoState, state & ~kCoInit);
        const uint32_t resume = rd16(cd + kCoLastLoc);
        if (resume == 0) {
          BRANCH_COST(2u);  // JR Z taken over JP (HL)
        } else {
          if (coChecksum(resume, rd8(cd + kCoLastLocCbr)) != rd8(cd + kCoChkSum)) {
            raiseFault("costatement's resume address is corrupted (CoData checksum)", opPc);
            SLOW;
          }
          if (!std::binary_search(image->resumePoints.begin(), image->resumePoints.end(),
                                  static_cast<uint16_t>(resume))) {
            raiseFault(fmt::format("costatement resumes at 0x{:04x}, not a yield point", resume),
                       opPc);
            SLOW;
          }
          pc = resume;
        }
        costateEvent(cd, Bus::CostateEvent::Enter, pc);
      }
      SLOW;
      CASE(COYIELD) {
        SAVE();
        const uint32_t cd = U16();
        if (!checkAccess(cd, kCoDataSize, opPc)) SLOW;
        setResume(cd, CO_TARGET());
        costateEvent(cd, Bus::CostateEvent::Yield, opPc);
      }
      SLOW;
      CASE(COEND)
      goto coEnd;  // past CODONE's op
      CASE(CODONE)
    coEnd : {
      SAVE();
      const uint32_t cd = U16();
      if (!checkAccess(cd, kCoDataSize, opPc)) SLOW;
      costateEnd(cd, op == static_cast<uint8_t>(Op::CODONE));
      costateEvent(cd, Bus::CostateEvent::End, opPc);
    }
      SLOW;
#if !SIMBOT_COMPUTED_GOTO
  }
#endif
  __builtin_unreachable();  // every handler ends in NEXT or SLOW
#undef TOP
#undef POPV
#undef PUSHV
#undef BINARY
#undef BRANCH_COST
#undef SHIFT
#undef COMPARE16
#undef COMPARE16_BODY
#undef U16
#undef I32
#undef CO_TARGET
}
#undef CASE
#undef NEXT_IP
#undef NEXT_OP
#undef operand
#undef DISPATCH
#undef FAST_DISPATCH
#undef NEXT
#undef DISPATCH_NEXT
#undef SLOW
#undef FAULT
#undef CHECK_ACCESS
#undef SAVE
#undef LOAD

// ---- public interface ---------------------------------------------------

Vm::Vm(const Image& image, Bus& bus, const CostTable& costs, Tick start)
    : s_(std::make_unique<State>(image, bus, costs)) {
  s_->self = this;
  s_->powerOn(start);
}

void Vm::State::powerOn(Tick start) {
  std::copy(image->data.begin(), image->data.end(), mem.begin() + kDataBase);
  stackLimit = kDataBase + static_cast<uint32_t>(image->data.size());
  pc = image->entry;
  now = start;
  handlerFor.fill(-1);
  for (const auto& v : image->vectors) handlerFor[v.vector] = v.handler;
  reserveStacks();
  const TimerService service = costs.knobs.timerService;
  if (service == TimerService::Always || (service == TimerService::Auto && image->timer.used()))
    nextTimer = start + kPrtTicks;
  costateEvents = bus->wantCostateEvents();
  findLoops();
  decode();
}

Vm::Vm(const Vm& other, Bus& bus) : s_(std::make_unique<State>(*other.s_)) {
  s_->attach(this, bus);
}

void Vm::State::attach(Vm* vm, Bus& to) {
  self = vm;
  bus = &to;
  costateEvents = to.wantCostateEvents();
  // A copied vector keeps its size, not its room.
  reserveStacks();
}

// Room for the deepest nesting, so that no push on the hot path allocates.
void Vm::State::reserveStacks() {
  calls.reserve(kMemorySize / kCallFrameBytes);
  ints.reserve(kMaxInterruptNesting);
}

void Vm::State::copyCounters(const State& from) {
  stats = from.stats;
  profile = from.profile;
  serialIsrCycles = from.serialIsrCycles;
  timerIsrCycles = from.timerIsrCycles;
}

Vm::~Vm() = default;

void Vm::restore(const Vm& snapshot) {
  Bus& bus = *s_->bus;
  *s_ = *snapshot.s_;
  s_->attach(this, bus);
}

void Vm::reset(Tick t) {
  const State& old = *s_;
  auto fresh = std::make_unique<State>(*old.image, *old.bus, old.costs);
  fresh->self = this;
  fresh->powerOn(t);
  fresh->profiling = old.profiling;
  fresh->copyCounters(old);
  const std::vector<uint8_t> breakpoints = old.breakpoints;
  s_ = std::move(fresh);
  for (uint32_t a = 0; a < breakpoints.size(); ++a)
    if (breakpoints[a]) setBreakpoint(a);
}

namespace {

// A copy of `mine` for comparing with `other`: what is not the machine's
// state taken from `other`. The bus it talks to, and the caches a run
// builds from the image, the breakpoints and run()'s labels (the fast
// path's tables, built at the first run of each kind: a VM that has not
// run yet is the same machine as one that has run nothing).
Vm::State comparable(const Vm::State& mine, const Vm::State& other) {
  Vm::State copy = mine;
  copy.bus = other.bus;
  copy.self = other.self;
  copy.costateEvents = other.costateEvents;
  copy.fast = other.fast;
  copy.fastLabels = other.fastLabels;
  copy.fusedLabels = other.fusedLabels;
  copy.idiomLabels = other.idiomLabels;
  copy.dbgIdiomLabels = other.dbgIdiomLabels;
  copy.joinLabels = other.joinLabels;
  copy.longLabels = other.longLabels;
  copy.joinEntries = other.joinEntries;
  copy.idiomCosts = other.idiomCosts;
  return copy;
}

}  // namespace

bool Vm::operator==(const Vm& other) const { return comparable(*s_, *other.s_) == *other.s_; }

bool Vm::sameMachine(const Vm& other) const {
  State mine = comparable(*s_, *other.s_);
  mine.copyCounters(*other.s_);
  // A delay loop's measured pass keeps the counters at its start.
  mine.measure.instructions = other.s_->measure.instructions;
  mine.measure.profile = other.s_->measure.profile;
  return mine == *other.s_;
}

void Vm::fillMemory(const std::function<uint64_t()>& next) {
  State& s = *s_;
  const auto& init = s.image->initialised;
  uint64_t bits = 0;
  int left = 0;
  for (uint32_t a = kDataBase; a < kMemorySize; ++a) {
    if (left == 0) {
      bits = next();
      left = 8;
    }
    const auto byte = static_cast<uint8_t>(bits);
    bits >>= 8;
    --left;
    const uint32_t i = a - kDataBase;
    if (i >= init.size() || !init[i]) s.mem[a] = byte;
  }
}

Stop Vm::run(Tick until) { return s_->profiling ? s_->run<true>(until) : s_->run<false>(until); }

void Vm::request(Irq irq, uint8_t vector) {
  const int i = static_cast<int>(irq);
  s_->pend[i] = true;
  s_->vec[i] = vector;
  s_->anyPending = true;
}

void Vm::cancelRequest(Irq irq) {
  s_->pend[static_cast<int>(irq)] = false;
  s_->updatePending();
}

bool Vm::pending(Irq irq) const { return s_->pend[static_cast<int>(irq)]; }
Tick Vm::now() const { return s_->now; }
Tick Vm::quietUntil() const { return s_->quietUntil(); }
bool Vm::halted() const { return s_->halted; }
const Fault* Vm::fault() const { return s_->fault ? &*s_->fault : nullptr; }
bool Vm::interruptsEnabled() const { return s_->iff1; }
uint32_t Vm::pc() const { return s_->lib.active ? s_->lib.pc : s_->burn ? s_->burnPc : s_->pc; }
int Vm::line() const { return s_->image->lineAt(pc()); }
int Vm::interruptDepth() const { return static_cast<int>(s_->ints.size()); }
uint8_t Vm::read8(uint16_t a) const { return s_->rd8(a); }
void Vm::write8(uint16_t a, uint8_t v) { s_->wr8(a, v); }
uint16_t Vm::read16(uint16_t a) const { return s_->rd16(a); }
uint32_t Vm::read32(uint16_t a) const { return s_->rd32(a); }
const VmStats& Vm::stats() const { return s_->stats; }
const Image& Vm::image() const { return *s_->image; }

void Vm::setBreakpoint(uint32_t codeAddress, bool enabled) {
  State& s = *s_;
  if (s.breakpoints.empty()) s.breakpoints.assign(s.image->code.size() + 1, 0);
  if (codeAddress < s.breakpoints.size()) {
    s.breakpoints[codeAddress] = enabled ? 1 : 0;
    s.dispatch[codeAddress] = enabled ? State::kTrap : s.baseDispatch[codeAddress];
    // The entries that may fuse into this address: those just before it
    // (an idiom's last piece starts at most kMaxIdiomReach after them).
    const uint32_t from = codeAddress >= kMaxIdiomReach ? codeAddress - kMaxIdiomReach : 0;
    for (int k = 0; k < 2; ++k)
      if (!s.fast[k].empty())
        for (uint32_t a = from; a <= codeAddress; ++a) s.setFast(k, a);
    // And the joins, whose target may be anywhere (a copy: setFast adds).
    if (!s.fast[0].empty())
      for (const uint32_t a : std::vector<uint32_t>(s.joinEntries)) s.setFast(0, a);
  }
  s.anyBreakpoint =
      std::any_of(s.breakpoints.begin(), s.breakpoints.end(), [](uint8_t b) { return b != 0; });
  for (State::Loop& loop : s.loops)
    loop.breakpointInside =
        std::any_of(s.breakpoints.begin() + loop.top, s.breakpoints.begin() + loop.exit,
                    [](uint8_t b) { return b != 0; });
}

void Vm::enableProfile() {
  s_->profiling = true;
  s_->profile.assign(s_->image->code.size() + 1, 0);
}
const std::vector<uint64_t>& Vm::profile() const { return s_->profile; }
uint64_t Vm::serialIsrCycles() const { return s_->serialIsrCycles; }
uint64_t Vm::timerIsrCycles() const { return s_->timerIsrCycles; }

}  // namespace simbot::vm
