// The VM's dispatch loop: one handler per opcode, generated from
// opcodes.def, each running the instruction's effect (instructions.h), and
// one per superinstruction (superinstructions.def), running its pieces'
// effects one after the other. Handlers jump to each other through labels
// as values (a GNU extension GCC and Clang have: "computed goto").
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

#include "vm/instructions.h"
#include "vm/state.h"
#include "vm/superinstructions.h"

// Computed goto (labels as values) is a GNU extension used on purpose.
#pragma GCC diagnostic ignored "-Wpedantic"

#include <fmt/format.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <optional>
#include <stdexcept>

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
  const uint32_t interruptedPc = currentPc();
  if (irq == Irq::Timer) {
    timerService(interruptedPc);
    return;
  }
  if (irq == Irq::SerialTx) {
    // The serial library's own ISR: short and atomic, leaves IFF1 set.
    host().interruptAccepted(now, irq, interruptedPc);
    now += costs().serialIsr;
    serialIsrCycles += costs().serialIsr;
    host().serialTxService(now, *self);
    host().interruptReturned(now, irq);
    return;
  }
  const int32_t handler = program->handlerFor[vec[i]];
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
  ints.push_back(InterruptFrame{pc, irq, msp, eval.sp, static_cast<int>(calls.size()), halted, burn,
                                burnPc, copy, std::move(lib)});
  // The frame's PC and IX, as the handler's prologue pushed them (the other
  // registers' slots keep what they held: the VM has no AF, BC, DE, HL, IY).
  wr16(msp - kReturnAddressBytes, pc);
  wr16(msp - kInterruptFpOffset, mfp);
  lib = LibCall{};
  burn = 0;
  copy = BlockCopy{};
  resumeAtBreakpoint = false;
  msp -= kInterruptFrameBytes;
  halted = false;
  iff1 = iff2 = false;
  host().interruptAccepted(now, irq, interruptedPc);
  host().iffChanged(now, false);
  now += costs().interruptAccept;
  if (profiling) profile[handler] += costs().interruptAccept;
  pc = static_cast<uint32_t>(handler);
}

// The BIOS timer service (cost_sums.h kTimerIsrSeq): atomic, like the serial
// library's ISR: interrupts stay disabled inside it and its EI; RETI leaves
// IFF1 set as it was at acceptance.
void Vm::State::timerService(uint32_t interruptedPc) {
  host().interruptAccepted(now, Irq::Timer, interruptedPc);
  const TimerBlock& tb = image().timer;
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
  const uint32_t cost = costs().timerIsr[(msDue ? 0u : 1u) | (secDue ? 0u : 2u)];
  now += cost;
  timerIsrCycles += cost;
  host().interruptReturned(now, Irq::Timer);
}

// ---- dispatch ---------------------------------------------------------------
//
// Fast path. The clock, pc, eval-stack pointer and instruction count live in
// the registers (Regs r, locals of run()) while ordinary instructions run;
// the State's members (now, pc, sp, stats.instructions) hold them only on
// the slow path. An ordinary instruction ends with NEXT: one compare of the
// clock against r.limit, the load of the next address's entry from `fast`
// (its handler's label and cost) and a jump to the handler. r.limit is
// min(until, nextTimer), the first tick at which the boundary has anything
// to do, or 0 (a trap) while anything rarer is due:
//  - a fault, a bus access (Io), a library call, HALT, EI/DI, RETI, the
//    costatement opcodes: their handlers save the registers and go to the
//    slow boundary themselves (their exec returns false);
//  - a pending request with IFF1 set (only the slow path changes IFF1, the
//    pending flags or the EI shadow while run() runs: the host raises
//    requests between calls), the time of a long instruction still to burn,
//    the eval stack past its guard, and every boundary after a diverted
//    return (divertedReturn): limit = 0, so the next boundary is slow;
//  - an address whose `dispatch` byte is kTrap (decode(): invalid opcodes,
//    instructions past the end of the code or jumping outside it,
//    fast-forward loop tops, breakpoints): the kTrap handler sends it to
//    the slow boundary, which runs the instruction from the code itself and
//    sets limit = 0 for the boundary after it.
// An instruction longer than kMaxStepTstates charges the first
// kMaxStepTstates, leaves the rest in `burn` and runs its handler with
// limit = 0 (L_Long_); its NEXT then runs the tail's steps at `slowNext`,
// each after the same compare against the real limit (nothing else can be
// due inside a pure stack operation's tail), and leaves for the slow
// boundary at the first step where something is.
// The slow boundary (`boundary:`) is the one every instruction used to take:
// the same tests in the same order, so every tick, count and trace is what
// it was. Any pc the fast path can reach indexes `fast` safely: jumps and
// calls out of the code are kTrap at decode, and a return address is at
// most kCodePad - 1 past its end.

// A call through a pointer that the chip would have made into the weeds: to
// no function's first instruction, or with a count of arguments the
// function's prologue does not pop (its stack would come back unbalanced).
bool Vm::State::badCallThrough(const Regs& r, uint32_t target, uint32_t argc) {
  save(r);
  std::string message;
  if (target == 0) {
    message = "call through a null function pointer";
  } else if (const Image::Entry* entry = image().entryAt(target)) {
    const Symbol* f = image().functionAt(target);
    message = fmt::format("call through a pointer to '{}' with {} argument{}; it takes {}",
                          f ? f->name : "?", argc, argc == 1 ? "" : "s", entry->params);
  } else {
    const Symbol* f = image().functionAt(target);
    message = fmt::format(
        "call through a pointer to 0x{:04X}, which is not the start of a function", target);
    if (f && target < f->address + f->size) message += fmt::format(" (it is inside '{}')", f->name);
  }
  raiseFault(std::move(message), r.pc());
  return false;
}

// Why a return cannot go to `target`, or "" when it can: an instruction's
// first byte, where the chip would simply run on, except the reset address
// (the chip would start its BIOS again, which simbot does not model).
std::string Vm::State::returnTargetProblem(uint32_t target) const {
  const std::vector<uint8_t>& instructionStart = program->instructionStart;
  if (target >= instructionStart.size()) return "outside the code";
  if (target == image().entry) return "the reset address";
  if (!instructionStart[target]) {
    const Symbol* f = image().functionAt(target);
    return f ? fmt::format("inside an instruction of '{}'", f->name)
             : std::string("inside an instruction");
  }
  return "";
}

// The robot leaves its call path at `at` for `target`: every boundary is
// slow from here on (see "Fast path").
void Vm::State::divert(uint32_t at, uint32_t target) {
  if (!diverted) diverted = Diversion{at, target};
}

// A RET that read a return address other than its call's, or read it
// elsewhere (its IX was not its frame's): a local array overrun or a wild
// pointer wrote over the frame. The robot goes where the address leads, as
// the chip would, if that is an instruction; otherwise it faults, naming
// the function, where the word was read and what the call had saved.
bool Vm::State::divertedReturn(Regs& r, const CallFrame& call, uint32_t target, uint32_t readAt,
                               int32_t frame, uint32_t fp) {
  const Symbol* callee = image().functionAt(r.pc());
  const Symbol* caller = image().functionAt(call.retPc);
  const std::string name = callee ? fmt::format("'{}'", callee->name) : std::string("a function");
  // IX was not the frame's (a saved IX that a callee restored had been
  // overwritten): the saved IX and return address were read elsewhere.
  const std::string wrongFp =
      frame >= 0 && readAt != call.saved
          ? fmt::format(
                " (its frame pointer IX was 0x{:04X}, not its frame's 0x{:04X}: a saved "
                "IX on the stack was overwritten)",
                fp, (call.saved - kSavedFpBytes - static_cast<uint32_t>(frame)) & 0xFFFF)
          : std::string();
  const uint32_t savedFp = (readAt - kSavedFpBytes) & 0xFFFF;
  std::string message;
  if (frame >= 0 && savedFp < kNullPageEnd) {
    message =
        fmt::format("{} read its saved IX at 0x{:04X}, in the null page{}", name, savedFp, wrongFp);
  } else if (readAt < kNullPageEnd) {
    message = fmt::format("{} read its return address at 0x{:04X}, in the null page{}", name,
                          readAt, wrongFp);
  } else if (const std::string problem = returnTargetProblem(target); !problem.empty()) {
    message = readAt != call.saved
                  ? fmt::format(
                        "{} returned to 0x{:04X}, {}: it read its return address at "
                        "0x{:04X}, not at 0x{:04X} where its call saved it{}",
                        name, target, problem, readAt, call.saved, wrongFp)
                  : fmt::format(
                        "{} returned to 0x{:04X}, {}: its return address at 0x{:04X} "
                        "(0x{:04X}, in '{}') was overwritten",
                        name, target, problem, readAt, call.retPc, caller ? caller->name : "?");
  } else {
    // It runs on. The calls whose return addresses SP has now passed will
    // never return: drop them, so that the host's record stays bounded.
    const size_t floor = ints.empty() ? 0 : static_cast<size_t>(ints.back().callDepth);
    while (calls.size() > floor && calls.back().saved < msp) calls.pop_back();
    divert(r.pc(), target);
    r.ip = target;
    r.limit = 0;
    return true;
  }
  save(r);
  raiseFault(std::move(message), r.pc());
  return false;
}

// One instruction's handler: past the instruction, then its effect.
template <Op O>
[[gnu::always_inline]] inline bool Vm::State::step(Regs& r) {
  r.ip = r.opPc + static_cast<uint32_t>(instructionSize(O));
  return exec<O>(r);
}

void Vm::State::unwindSuperinstruction(int kind, int k) {
  const uint32_t later = program->superAfter[kind][k];
  now -= later;
  if (fault) fault->tick -= later;
  stats.instructions -= static_cast<uint64_t>(kSuperShapes[kind].n - 1 - k);
}

// The run's next horizon from its continuation: taken without asking
// where the continuation says it may (Continuation::cap), else asked.
Tick Vm::State::nextHorizon(Continuation& more, Tick reached) {
  if (more.mayTakeUnasked(reached, now, touchedHost) && quietUntil() == now)
    return more.takeUnasked(now);
  touchedHost = false;
  return more.nextHorizon(reached);
}

// A long instruction's tail on the fast path: its steps while they start
// before the limit (nothing else can be due inside it).
[[gnu::always_inline]] inline void Vm::State::burnTail(Regs& r) {
  while (burn && r.clk < r.limit) {
    const uint32_t s = std::min(kMaxStepTstates, burn);
    r.clk += s;
    burn -= s;
  }
}

// The horizon reached on the fast path (r.clk >= r.limit), taken there
// where the slow boundary would only take the next one unasked
// (nextHorizon): the limit is the horizon, not 0 (something rare is due,
// a shift's or a copy's steps among them) or PRT0's tick; no copy is
// left; and with no delay loop under measure, quietUntil() is the clock
// (a long instruction's steps may be left: L_Long_'s tail, where the
// boundaries between them are boundaries like any other). True when the
// run goes on on the fast path.
[[gnu::always_inline]] inline bool Vm::State::takeHorizon(Regs& r, Tick& until,
                                                          Continuation* more) {
  if (!more || r.limit != until || r.clk >= nextTimer || copy.left || measure.loop >= 0 ||
      !more->mayTakeUnasked(until, r.clk, touchedHost))
    return false;
  until = more->takeUnasked(r.clk);
  r.limit = std::min(until, nextTimer);
  return r.clk < r.limit;
}

// An unchecked run's piece (State::superinstruction): charged and counted
// in advance with the pieces after it, which a fault takes back.
template <int kKind, int kPiece, Op O>
[[gnu::always_inline]] inline bool Vm::State::uncheckedPiece(Regs& r) {
  if (kPiece > 0) r.opPc = r.ip;
  if (__builtin_expect(step<O>(r), 1)) return true;
  unwindSuperinstruction(kKind, kPiece);
  return false;
}

// The pieces work on a copy of the stack's top in a local array (its
// slots at constant places, so the compiler keeps them in registers), which
// is copied back when they end: the slots they took from below their entry
// and those they leave. Every check that reads the stack's depth inside
// (the guard, CALL's headroom) passes: superinstruction() checked the
// deepest they can reach.
template <int kKind, Op First, Op... Rest, size_t... kPieces>
[[gnu::always_inline]] inline bool Vm::State::unchecked(Regs& r, const Program& prog,
                                                        std::index_sequence<kPieces...>) {
  constexpr StackReach kReach = stackReach({First, Rest...});
  uint32_t window[kReach.below + kReach.above + 1];
  uint32_t* const stack = r.e;
  const int entry = r.esp;
  uint32_t* const base = stack + entry - kReach.below;
  for (int k = 0; k < kReach.below; ++k) window[k] = base[k];
  r.e = window;
  r.esp = kReach.below;
  r.clk += prog.superAfter[kKind][0];
  r.count += sizeof...(Rest);
  const bool ran = uncheckedPiece<kKind, 0, First>(r) &&
                   (uncheckedPiece<kKind, static_cast<int>(kPieces) + 1, Rest>(r) && ...);
  if (__builtin_expect(ran, 1)) {
    for (int k = 0; k < kReach.below + kReach.net; ++k) base[k] = window[k];
  } else {  // a fault: as it stands, with the depth it saved
    for (int k = 0; k < kReach.below + kReach.above; ++k) base[k] = window[k];
    eval.sp = entry - kReach.below + r.esp;
  }
  r.e = stack;
  r.esp = entry - kReach.below + r.esp;
  return ran;
}

// The first piece has been dispatched (charged and counted) as usual. When
// every inner boundary lies before the limit even at the pieces' slowest
// paths (superSpan), nothing can happen at them; when the expression stack
// also has room for the most the pieces hold above a call's headroom, no
// check on its depth inside can fail: the pieces run unchecked, their time
// and count charged at once, on a copy of the stack's top (unchecked()).
// Otherwise the first piece runs alone, and the ones after it are
// dispatched from the table one by one, each after NEXT's test, as they
// are unfused (a long one as L_Long_). `prog` is run()'s: read through
// the `program` member, the pointer is loaded again after every store to
// the robot's memory (bytes, which may alias it), 1 % of the host's
// instructions (cachegrind, the Lua comparison programs).
template <int kKind, Op First, Op... Rest>
[[gnu::always_inline]] inline bool Vm::State::superinstruction(Regs& r, const Program& prog) {
  constexpr StackReach kReach = stackReach({First, Rest...});
  if (__builtin_expect(r.clk + prog.superSpan[kKind] < r.limit &&
                           r.esp <= kEvalSlots - kEvalHeadroom - kReach.above,
                       1))
    return unchecked<kKind, First, Rest...>(r, prog, std::make_index_sequence<sizeof...(Rest)>{});
  return step<First>(r);
}

template <bool kProfile>
Stop Vm::State::run(Tick until, Continuation* more) {
  if (fault) return Stop::Fault;
  // The host may have acted since the last run ended (at a breakpoint, a
  // host stop): the first horizon of this one is asked.
  touchedHost = true;
  static const void* const kLabels[] = {
#define OP(name, shape, pop, push, seq) &&L_##name,
#include "vm/opcodes.def"
#undef OP
      &&L_Trap_,  // kTrap
  };
  static const void* const kSuperLabels[] = {
#define SUPER(name, ...) &&S_##name,
#include "vm/superinstructions.def"
#undef SUPER
  };
  const Program& prog = *program;
  const Fast* const fd =
      dispatch->fast(kProfile ? 1 : 0, prog,
                     // The profiling run never fuses: its profile is per
                     // instruction.
                     Labels{kLabels, &&L_Long_, kProfile ? nullptr : kSuperLabels});
  const uint8_t* const code = prog.padded.data();
  const auto codeSize = static_cast<uint32_t>(prog.image->code.size());
  const int16_t* const loopTop =
      prog.costs.knobs.fastForward && !prog.loopAtTop.empty() ? prog.loopAtTop.data() : nullptr;
  const uint8_t* const ops = dispatch->ops().data();
  ready();
  // The fast path's registers, from the machine at a boundary.
  const auto registers = [&](Tick limit) {
    return Regs{
        now,     limit,       stats.instructions, pc,   pc,
        eval.sp, eval.data(), mem.data(),         code, kProfile ? profile.data() : nullptr};
  };
  Regs r = registers(0);
  Tick longLimit = -1;  // L_Long_: the limit its instruction's tail runs to
  uint8_t op = 0;
  hostStop = false;

#define NEXT                                   \
  if (__builtin_expect(r.clk >= r.limit, 0)) { \
    goto slowNext;                             \
  }                                            \
  DISPATCH_NEXT
#define DISPATCH_NEXT                               \
  {                                                 \
    const Fast& d = fd[r.ip];                       \
    r.opPc = r.ip;                                  \
    r.clk += d.cost;                                \
    if constexpr (kProfile) {                       \
      if (d.op != kTrap) profile[r.opPc] += d.cost; \
    }                                               \
    ++r.count;                                      \
    goto* d.label;                                  \
  }

boundary:
  if (fault) return Stop::Fault;
  if (eval.sp > kEvalSlots - kEvalGuard) {
    raiseFault("expression stack overflow (too many arguments or values pending)", pc);
    goto boundary;
  }
  if (hostStop) {
    hostStop = false;
    return Stop::Host;
  }
  if (now >= nextTimer) timerTick();
  if (now >= until) {
    // Going on from here is what a new run() would do: its entry checks
    // (fault, stack guard, stop, PRT0) are the ones above.
    if (!more || halted) return halted ? Stop::Halted : Stop::Horizon;
    until = nextHorizon(*more, until);
    if (now >= until) return Stop::Horizon;
  }
  if (lib.awaitingBegin) {  // the end of a library call's sequence: no boundary
    // (for an atomic call this also keeps interrupts out until its effect)
    libBegin();
    goto boundary;
  }
  if (anyPending && iff1 && !eiShadow) {
    accept();
    goto boundary;
  }
  if (copy.left) {
    copyStep();
    eiShadow = false;
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
  if (dispatch->anyBreakpoint() && dispatch->breakpointAt(pc) && !resumeAtBreakpoint) {
    resumeAtBreakpoint = true;
    return Stop::Breakpoint;
  }
  if (loopTop && loopTop[pc] >= 0 && fastForward(until)) {
    // Passes ran: a breakpoint the robot resumed from is behind it (a
    // measured pass applied at the first arrival after one must not
    // leave the flag for the landing).
    resumeAtBreakpoint = false;
    goto boundary;
  }
  resumeAtBreakpoint = false;
  // An ordinary instruction (the table's, not a trap) runs on the fast
  // path, as after NEXT: a long one's tail, a superinstruction and the
  // limit are then the fast path's, and the checks below pass.
  if (ops[pc] != kTrap && !diverted) {
    eiShadow = false;
    r = registers(anyPending && iff1 ? 0 : std::min(until, nextTimer));
    DISPATCH_NEXT;
  }
  op = code[pc];
  if (op >= kOpCount) {
    raiseFault(fmt::format("invalid opcode {}", op), pc);
    goto boundary;
  }
  if (diverted && eval.sp < slotsTaken(static_cast<Op>(op), code + pc)) {
    raiseFault("expression stack underflow", pc);
    goto boundary;
  }
  if (costs().op[op] <= kMaxStepTstates) {
    now += costs().op[op];
  } else {
    now += kMaxStepTstates;
    burn = costs().op[op] - kMaxStepTstates;
    burnPc = pc;
  }
  if constexpr (kProfile) profile[pc] += costs().op[op];
  ++stats.instructions;
  eiShadow = false;
  // The boundary after this instruction is slow too when anything rare is
  // due there (see "Fast path").
  r = registers(ops[pc] == kTrap || burn || (anyPending && iff1) || diverted
                    ? 0
                    : std::min(until, nextTimer));
  goto* kLabels[op];

  // One handler per opcode, and one per superinstruction.
#define OP(name, shape, pop, push, seq)       \
  L_##name : if (step<Op::name>(r)) { NEXT; } \
  goto boundary;
#include "vm/opcodes.def"
#undef OP
  // The profiling run never fuses (its table has no superinstruction's
  // label): its copies of these handlers are left empty, which halves
  // their compile time.
#define SUPER(name, ...)                                        \
  S_##name : if constexpr (!kProfile) {                         \
    using enum Op;                                              \
    if (superinstruction<kSuper##name, __VA_ARGS__>(r, prog)) { \
      NEXT;                                                     \
    }                                                           \
  }                                                             \
  goto boundary;
#include "vm/superinstructions.def"
#undef SUPER

slowNext:
  if (longLimit >= 0) {  // the tail of a long instruction (L_Long_)
    r.limit = longLimit;
    longLimit = -1;
    burnTail(r);
    // A horizon reached between its steps is taken there as at any
    // boundary (most of histogram.dc's are reached inside a division).
    while (burn && takeHorizon(r, until, more)) burnTail(r);
    if (!burn && !copy.left && r.clk < r.limit) DISPATCH_NEXT;
  }
  if (takeHorizon(r, until, more)) DISPATCH_NEXT;
  save(r);
  goto boundary;

L_Long_ : {
  op = fd[r.opPc].op;
  const uint32_t rest = costs().op[op] - kMaxStepTstates;
  if constexpr (kProfile) profile[r.opPc] += rest;
  burn = rest;
  burnPc = r.pc();
  longLimit = r.limit;
  r.limit = 0;
  goto* kLabels[op];
}

L_Trap_ : {  // the slow boundary looks first (see "Fast path")
  --r.count;
  r.ip = r.opPc;
  save(r);
  goto boundary;
}
#undef NEXT
#undef DISPATCH_NEXT
}

// ---- public interface ---------------------------------------------------

Vm::Vm(const Image& image, Bus& bus, const CostTable& costs, Tick start)
    : s_(std::make_unique<State>(std::make_shared<const Program>(image, costs), &bus)),
      clock_(&s_->now),
      fault_(&s_->fault) {
  s_->self = this;
  s_->costateEvents = bus.wantCostateEvents();
  s_->powerOn(start);
}

void Vm::State::powerOn(Tick start) {
  std::copy(image().data.begin(), image().data.end(), mem.begin() + kDataBase);
  stackLimit = kDataBase + static_cast<uint32_t>(image().data.size());
  pc = image().entry;
  now = start;
  const TimerService service = costs().knobs.timerService;
  if (service == TimerService::Always || (service == TimerService::Auto && image().timer.used()))
    nextTimer = start + kPrtTicks;
}

Vm::Vm(const Vm& other)
    : s_(std::make_unique<State>(*other.s_)), clock_(&s_->now), fault_(&s_->fault) {
  s_->bus = nullptr;
  s_->self = this;
}

Vm::Vm(const Vm& other, Bus& bus) : Vm(other) { attach(bus); }

Vm& Vm::operator=(const Vm& other) {
  if (this != &other) {
    Bus* const bus = s_->bus;
    *s_ = *other.s_;
    s_->bus = bus;
    s_->self = this;
    if (bus) s_->costateEvents = bus->wantCostateEvents();
  }
  return *this;
}

void Vm::attach(Bus& bus) {
  s_->bus = &bus;
  s_->costateEvents = bus.wantCostateEvents();
}

// Every run's first call: the tests inline, the work (after a copy, which
// keeps no capacity) out of line.
void Vm::State::ready() {
  if (__builtin_expect(!bus || calls.capacity() < kMemorySize / kReturnAddressBytes ||
                           ints.capacity() < static_cast<size_t>(kMaxInterruptNesting),
                       0))
    prepare();
  eval.ready();
}

void Vm::State::prepare() {
  if (!bus) throw std::logic_error("a copied VM runs only once attached to a bus (Vm::attach)");
  calls.reserve(kMemorySize / kReturnAddressBytes);
  ints.reserve(kMaxInterruptNesting);
}

void Vm::State::copyCounters(const State& from) {
  stats = from.stats;
  profile = from.profile;
  serialIsrCycles = from.serialIsrCycles;
  timerIsrCycles = from.timerIsrCycles;
}

Vm::~Vm() = default;

void Vm::restore(const Vm& snapshot) { *this = snapshot; }

void Vm::reset(Tick t) {
  const State& old = *s_;
  State fresh(old.program, old.bus);
  // The breakpoints stay, and the bus's wishes.
  fresh.dispatch = old.dispatch;
  fresh.self = this;
  fresh.costateEvents = old.costateEvents;
  fresh.powerOn(t);
  fresh.profiling = old.profiling;
  fresh.copyCounters(old);
  *s_ = std::move(fresh);
}

namespace {

// A copy of `mine` for comparing with `other`: what is not the machine's
// state taken from `other`. The bus it talks to, and the program when it
// is the same image decoded for the same costs by another VM (with the
// same breakpoints, the same dispatch).
Vm::State comparable(const Vm::State& mine, const Vm::State& other) {
  Vm::State copy = mine;
  copy.bus = other.bus;
  copy.self = other.self;
  copy.costateEvents = other.costateEvents;
  copy.touchedHost = other.touchedHost;
  if (copy.program->image == other.program->image && copy.program->costs == other.program->costs)
    copy.program = other.program;
  if (copy.program == other.program &&
      copy.dispatch->breakpoints() == other.dispatch->breakpoints())
    copy.dispatch = other.dispatch;
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

bool Vm::sameProgramState(const Vm& other) const {
  State mine = comparable(*s_, *other.s_);
  mine.copyCounters(*other.s_);
  mine.measure = other.s_->measure;
  mine.loopPass = other.s_->loopPass;
  mine.loopInstructions = other.s_->loopInstructions;
  mine.resumeAtBreakpoint = other.s_->resumeAtBreakpoint;
  return mine == *other.s_;
}

bool Vm::sharesProgram(const Vm& other) const { return s_->program == other.s_->program; }

void Vm::fillMemory(const std::function<uint64_t()>& next) {
  State& s = *s_;
  const auto& init = s.image().initialised;
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

Stop Vm::run(Tick until, Continuation* more) {
  return s_->profiling ? s_->run<true>(until, more) : s_->run<false>(until, more);
}

void Vm::request(Irq irq, uint8_t vector) {
  const int i = static_cast<int>(irq);
  s_->pend[i] = true;
  s_->vec[i] = vector;
  s_->anyPending = true;
}

void Vm::stopAtNextBoundary() { s_->hostStop = true; }

void Vm::cancelRequest(Irq irq) {
  s_->pend[static_cast<int>(irq)] = false;
  s_->updatePending();
}

bool Vm::pending(Irq irq) const { return s_->pend[static_cast<int>(irq)]; }
bool Vm::halted() const { return s_->halted; }
Tick Vm::haltedSince() const { return s_->haltedAt; }
bool Vm::interruptsEnabled() const { return s_->iff1; }
uint32_t Vm::pc() const { return s_->currentPc(); }
int Vm::line() const { return s_->image().lineAt(pc()); }
int Vm::interruptDepth() const { return static_cast<int>(s_->ints.size()); }
int Vm::callDepth() const { return static_cast<int>(s_->calls.size()); }
uint32_t Vm::libraryCallPc() const { return s_->lib.pc; }

std::vector<Vm::Frame> Vm::frames() const {
  const auto& calls = s_->calls;
  const auto& ints = s_->ints;
  std::vector<Frame> out;
  out.reserve(calls.size() + ints.size());
  // A handler accepted with d calls under way comes after call d - 1: the
  // calls it makes are calls[d..].
  size_t k = 0;
  auto handlersAt = [&](size_t depth) {
    for (; k < ints.size() && static_cast<size_t>(ints[k].callDepth) <= depth; ++k)
      // The instruction it interrupted: a library call, a long
      // instruction's tail or a block copy under way, else the next one.
      out.push_back({ints[k].lib.active                  ? ints[k].lib.pc
                     : ints[k].burn || ints[k].copy.left ? ints[k].burnPc
                                                         : ints[k].retPc,
                     true});
  };
  for (size_t i = 0; i < calls.size(); ++i) {
    handlersAt(i);
    out.push_back({calls[i].retPc - 1, false});
  }
  handlersAt(SIZE_MAX);
  return out;
}
std::vector<Vm::Activation> Vm::activations() const {
  const State& s = *s_;
  const Image& img = s.image();
  // A function has a frame once its first instruction, an ENTER, has run.
  auto entered = [&](uint32_t at) {
    const Symbol* f = img.functionAt(at);
    return f && f->address < img.code.size() &&
           img.code[f->address] == static_cast<uint8_t>(Op::ENTER) && at != f->address;
  };
  const std::vector<Frame> outer = frames();
  std::vector<Activation> out;
  out.reserve(outer.size() + 1);
  uint32_t fp = s.mfp;
  size_t call = s.calls.size(), handler = s.ints.size();
  uint32_t at = s.currentPc();
  bool inHandler = !s.ints.empty() && s.ints.back().callDepth == static_cast<int>(s.calls.size());
  for (size_t k = outer.size() + 1; k-- > 0;) {
    const bool framed = entered(at);
    out.push_back({at, fp, framed, inHandler});
    if (k == 0) break;
    const Frame& f = outer[k - 1];
    if (f.interrupted) {
      // Acceptance saved the interrupted code's IX below its PC.
      --handler;
      fp = s.rd16(static_cast<uint16_t>(s.ints[handler].msp - kInterruptFpOffset));
    } else {
      --call;
      if (framed) fp = s.rd16(static_cast<uint16_t>(s.calls[call].saved - kSavedFpBytes));
    }
    at = f.at;
    inHandler = handler > 0 && s.ints[handler - 1].callDepth == static_cast<int>(call);
  }
  return out;
}
int Vm::evalDepth() const { return s_->eval.sp; }
bool Vm::inLibraryCall() const { return s_->lib.active; }
bool Vm::effectPending() const { return s_->lib.awaitingBegin && !s_->fault; }

void Vm::settle() {
  State& s = *s_;
  if (!effectPending()) return;
  s.ready();
  // What run() does at the boundary before the effect (the timer's tick
  // was taken when run() stopped here).
  if (s.now >= s.nextTimer) s.timerTick();
  s.libBegin();
}
uint32_t Vm::evalSlot(int fromTop) const {
  const int i = s_->eval.sp - 1 - fromTop;
  return i >= 0 && i < kEvalSlots ? s_->eval[i] : 0;
}
uint8_t Vm::read8(uint16_t a) const { return s_->rd8(a); }
void Vm::write8(uint16_t a, uint8_t v) { s_->wr8(a, v); }
uint16_t Vm::read16(uint16_t a) const { return s_->rd16(a); }
uint32_t Vm::read32(uint16_t a) const { return s_->rd32(a); }
const VmStats& Vm::stats() const { return s_->stats; }
const Image& Vm::image() const { return s_->image(); }
const CostTable& Vm::costs() const { return s_->costs(); }

void Vm::setBreakpoint(uint32_t codeAddress, bool enabled) {
  State& s = *s_;
  if (codeAddress > s.image().code.size() || s.dispatch->breakpointAt(codeAddress) == enabled)
    return;
  // A superinstruction's pieces may lie anywhere (a JMP's or CALL's
  // target): the new dispatch decodes every entry again.
  s.dispatch = s.dispatch->withBreakpoint(*s.program, codeAddress, enabled);
}

int Vm::superinstructionAt(uint32_t codeAddress) const {
  return codeAddress < s_->dispatch->ops().size()
             ? s_->dispatch->superinstructionAt(*s_->program, codeAddress)
             : -1;
}

void Vm::enableProfile() {
  s_->profiling = true;
  s_->profile.assign(s_->image().code.size() + 1, 0);
}
const std::vector<uint64_t>& Vm::profile() const { return s_->profile; }
uint64_t Vm::serialIsrCycles() const { return s_->serialIsrCycles; }
uint64_t Vm::timerIsrCycles() const { return s_->timerIsrCycles; }

}  // namespace simbot::vm
