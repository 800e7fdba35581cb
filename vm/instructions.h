// Every instruction's effect, written once: exec<Op::X> is what X does to
// the machine. The dispatch loop (vm.cpp) runs it as X's handler and as a
// piece of a superinstruction (superinstructions.def); the cycle-cost table
// (cost.h) has already charged X's not-taken path when it runs.
//
// An instruction works on the fast path's registers (Regs: the clock,
// instruction pointer, expression stack pointer and count, kept in locals of
// run()) and on the State. It returns true when the next boundary may be
// the fast one; false after it has saved the registers into the State
// (save()) and, where it faults, raised the fault there: the loop then goes
// to the slow boundary. A superinstruction runs its pieces through these
// same functions, so a piece that faults leaves the machine as it does
// alone. The instructions that always need the slow
// boundary (library calls, EI/DI, HALT, RETI, the costatement opcodes) save
// first and do their work on the State.
//
// Included by vm.cpp only.
#pragma once
#include "vm/state.h"

namespace simbot::vm {

#define SIMBOT_INSTRUCTION(name) \
  template <>                    \
  [[gnu::always_inline]] inline bool Vm::State::exec<Op::name>(Regs & r)

// ---- helpers shared by several instructions ---------------------------------

[[gnu::always_inline]] inline void Vm::State::save(const Regs& r) {
  now = r.clk;
  pc = static_cast<uint32_t>(r.ip);
  eval.sp = r.esp;
  stats.instructions = r.count;
}

[[gnu::always_inline]] inline bool Vm::State::fail(const Regs& r, const char* message) {
  save(r);
  raiseFault(message, r.pc());
  return false;
}

// checkAccess() inline: only a faulting access leaves the fast path.
[[gnu::always_inline]] inline bool Vm::State::access(const Regs& r, uint32_t address,
                                                     uint32_t bytes) {
  if (__builtin_expect(address >= kNullPageEnd && address + bytes <= kMemorySize, 1)) return true;
  save(r);
  checkAccess(address, bytes, r.pc());
  return false;
}

// The instruction's branches went the way `path` says (bit k: k-th branch
// taken): charge the difference from the not-taken figure.
template <Op O>
[[gnu::always_inline]] inline void Vm::State::branch(Regs& r, unsigned path) {
  r.charge(costs().branchDelta[static_cast<int>(O)][path]);
}

// A 16-bit comparison as the Z180 code does it: the result, and the path
// its branches take. Signed: the first branch (JP PO) is taken when the
// subtraction did not overflow (it jumps over the sign correction), the
// second when the result is 0. Unsigned: one branch, taken when the result
// is 0 (it jumps over INC HL).
template <Op C>
[[gnu::always_inline]] inline bool Vm::State::compare16(Regs& r) {
  const uint32_t b = r.pop(), a = r.top();
  bool result = false;
  unsigned path = 0;
  if constexpr (C == Op::LTW || C == Op::LEW || C == Op::GTW || C == Op::GEW) {
    // LTW and GEW compute a - b (HL = a); LEW and GTW b - a.
    constexpr bool kAFirst = C == Op::LTW || C == Op::GEW;
    const uint32_t hl = kAFirst ? a : b, de = kAFirst ? b : a;
    const int32_t diff = int32_t{asInt16(hl)} - int32_t{asInt16(de)};
    const bool overflow = diff < -32768 || diff > 32767;
    if constexpr (C == Op::LTW) result = asInt16(a) < asInt16(b);
    if constexpr (C == Op::LEW) result = asInt16(a) <= asInt16(b);
    if constexpr (C == Op::GTW) result = asInt16(a) > asInt16(b);
    if constexpr (C == Op::GEW) result = asInt16(a) >= asInt16(b);
    path = (overflow ? 0u : 1u) | (result ? 0u : 2u);
  } else {
    const uint32_t x = a & 0xFFFF, y = b & 0xFFFF;
    if constexpr (C == Op::EQW) result = x == y;
    if constexpr (C == Op::NEW) result = x != y;
    if constexpr (C == Op::LTUW) result = x < y;
    if constexpr (C == Op::LEUW) result = x <= y;
    if constexpr (C == Op::GTUW) result = x > y;
    if constexpr (C == Op::GEUW) result = x >= y;
    path = result ? 0u : 1u;
  }
  r.top() = result ? 1u : 0u;
  branch<C>(r, path);
  return true;
}

// A 16-bit shift by n: op[] is one pass; n = 0 takes the JR Z (path 1),
// n > 1 adds n - 1 further passes, run like a long instruction's tail (in
// steps of at most kMaxStepTstates, interruptible between them, as the
// Z180 is between the loop's instructions): the slow boundary.
template <Op O, class Shift>
[[gnu::always_inline]] inline bool Vm::State::shift16(Regs& r, Shift shifted) {
  const uint32_t n = r.pop() & 0xFF;
  r.top() = shifted(r.top(), n);
  if (n == 0) {
    branch<O>(r, 1u);
  } else if (n > 1) {
    const uint32_t more = (n - 1) * costs().loopPass[static_cast<int>(O)];
    if (r.profile) r.profile[r.opPc] += more;
    burn += more;
    burnPc = r.pc();
    r.limit = 0;
  }
  return true;
}

// Division and remainder: the divisor is popped, then checked.
template <class Divide>
[[gnu::always_inline]] inline bool Vm::State::divide(Regs& r, bool byZero, Divide quotient) {
  const uint32_t b = r.pop();
  if (byZero) return fail(r, "division by zero");
  r.top() = quotient(r.top(), b);
  return true;
}

// ---- constants and the expression stack --------------------------------------

SIMBOT_INSTRUCTION(PUSHW) {
  r.push(r.u16());
  return true;
}
SIMBOT_INSTRUCTION(PUSHL) {
  r.push(r.i32());
  return true;
}
SIMBOT_INSTRUCTION(PUSHF) {
  r.push(r.i32());
  return true;
}
SIMBOT_INSTRUCTION(POP) {
  --r.esp;
  return true;
}
SIMBOT_INSTRUCTION(DUP) {
  r.push(r.top());
  return true;
}
SIMBOT_INSTRUCTION(TUCK) {
  const uint32_t b = r.pop(), a = r.pop();
  r.push(b);
  r.push(a);
  r.push(b);
  return true;
}

// ---- globals and statics ------------------------------------------------------

SIMBOT_INSTRUCTION(LDGB) {
  r.push(r.rd8(r.u16()));
  return true;
}
SIMBOT_INSTRUCTION(LDGW) {
  r.push(r.rd16(r.u16()));
  return true;
}
SIMBOT_INSTRUCTION(LDGL) {
  r.push(r.rd32(r.u16()));
  return true;
}
SIMBOT_INSTRUCTION(STGB) {
  r.wr8(r.u16(), r.pop());
  return true;
}
SIMBOT_INSTRUCTION(STGW) {
  r.wr16(r.u16(), r.pop());
  return true;
}
SIMBOT_INSTRUCTION(STGL) {
  r.wr32(r.u16(), r.pop());
  return true;
}
SIMBOT_INSTRUCTION(INCGW) {
  r.wr16(r.u16(), r.rd16(r.u16()) + 1u);
  return true;
}
SIMBOT_INSTRUCTION(DECGW) {
  r.wr16(r.u16(), r.rd16(r.u16()) - 1u);
  return true;
}
SIMBOT_INSTRUCTION(INCGL) {
  r.wr32(r.u16(), r.rd32(r.u16()) + 1u);
  return true;
}

// ---- autos: checked, the frame pointer plus an offset may leave memory -----

template <int kBytes>
[[gnu::always_inline]] inline bool Vm::State::loadLocal(Regs& r) {
  const uint32_t a = mfp + r.u16();
  if (!access(r, a, kBytes)) return false;
  r.push(r.read<kBytes>(a));
  return true;
}
template <int kBytes>
[[gnu::always_inline]] inline bool Vm::State::storeLocal(Regs& r) {
  const uint32_t a = mfp + r.u16();
  const uint32_t v = r.pop();
  if (!access(r, a, kBytes)) return false;
  r.write<kBytes>(a, v);
  return true;
}
SIMBOT_INSTRUCTION(LDLB) { return loadLocal<1>(r); }
SIMBOT_INSTRUCTION(LDLW) { return loadLocal<2>(r); }
SIMBOT_INSTRUCTION(LDLL) { return loadLocal<4>(r); }
SIMBOT_INSTRUCTION(STLB) { return storeLocal<1>(r); }
SIMBOT_INSTRUCTION(STLW) { return storeLocal<2>(r); }
SIMBOT_INSTRUCTION(STLL) { return storeLocal<4>(r); }
SIMBOT_INSTRUCTION(LEAL) {
  r.push((mfp + r.u16()) & 0xFFFF);
  return true;
}

// ---- through a pointer --------------------------------------------------------

template <int kBytes>
[[gnu::always_inline]] inline bool Vm::State::loadIndirect(Regs& r) {
  const uint32_t a = r.top() & 0xFFFF;
  if (!access(r, a, kBytes)) return false;
  r.top() = r.read<kBytes>(a);
  return true;
}
// addr value -- ; or, keeping the value: addr value -- value
template <int kBytes, bool kKeep>
[[gnu::always_inline]] inline bool Vm::State::storeIndirect(Regs& r) {
  const uint32_t v = r.pop();
  const uint32_t a = (kKeep ? r.top() : r.pop()) & 0xFFFF;
  if (!access(r, a, kBytes)) return false;
  r.write<kBytes>(a, v);
  constexpr uint32_t kMask = kBytes == 1 ? 0xFFu : kBytes == 2 ? 0xFFFFu : 0xFFFFFFFFu;
  if (kKeep) r.top() = v & kMask;
  return true;
}
SIMBOT_INSTRUCTION(LDIB) { return loadIndirect<1>(r); }
SIMBOT_INSTRUCTION(LDIW) { return loadIndirect<2>(r); }
SIMBOT_INSTRUCTION(LDIL) { return loadIndirect<4>(r); }
SIMBOT_INSTRUCTION(STIB) { return storeIndirect<1, false>(r); }
SIMBOT_INSTRUCTION(STIW) { return storeIndirect<2, false>(r); }
SIMBOT_INSTRUCTION(STIL) { return storeIndirect<4, false>(r); }
SIMBOT_INSTRUCTION(STIBK) { return storeIndirect<1, true>(r); }
SIMBOT_INSTRUCTION(STIWK) { return storeIndirect<2, true>(r); }
SIMBOT_INSTRUCTION(STILK) { return storeIndirect<4, true>(r); }
SIMBOT_INSTRUCTION(COPY) {
  const uint32_t n = r.u16();
  const uint32_t src = r.pop() & 0xFFFF, dst = r.pop() & 0xFFFF;
  if (!access(r, src, n) || !access(r, dst, n)) return false;
  if (n == 0) return true;
  // The sequence up to LDIR has run (copyHead); then a byte a step at the
  // slow boundary, each after a boundary (State::copyStep): the total is
  // op[] + (n - 1) x ldirRepeat as the listing says, charged to the
  // profile here. Dispatch charged op[] (or its first kMaxStepTstates, the
  // rest in burn): take back what comes after the head.
  const Tick start = r.clk - (costs().op[static_cast<int>(Op::COPY)] - burn);
  burn = 0;
  r.clk = start + costs().copyHead;
  if (r.profile) r.profile[r.opPc] += (n - 1) * costs().ldirRepeat;
  copy = BlockCopy{dst, src, n};
  burnPc = r.pc();
  r.limit = 0;
  return true;
}

// ---- 16-bit arithmetic ----------------------------------------------------------

SIMBOT_INSTRUCTION(ADDW) {
  return r.binary([](uint32_t a, uint32_t b) { return (a + b) & 0xFFFF; });
}
SIMBOT_INSTRUCTION(SUBW) {
  return r.binary([](uint32_t a, uint32_t b) { return (a - b) & 0xFFFF; });
}
SIMBOT_INSTRUCTION(MULW) {
  return r.binary([](uint32_t a, uint32_t b) { return (a * b) & 0xFFFF; });
}
SIMBOT_INSTRUCTION(DIVW) {
  return divide(r, asInt16(r.top()) == 0,
                [](uint32_t a, uint32_t b) { return w(int32_t{asInt16(a)} / asInt16(b)); });
}
SIMBOT_INSTRUCTION(DIVUW) {
  return divide(r, (r.top() & 0xFFFF) == 0,
                [](uint32_t a, uint32_t b) { return (a & 0xFFFF) / (b & 0xFFFF); });
}
SIMBOT_INSTRUCTION(MODW) {
  return divide(r, asInt16(r.top()) == 0,
                [](uint32_t a, uint32_t b) { return w(int32_t{asInt16(a)} % asInt16(b)); });
}
SIMBOT_INSTRUCTION(MODUW) {
  return divide(r, (r.top() & 0xFFFF) == 0,
                [](uint32_t a, uint32_t b) { return (a & 0xFFFF) % (b & 0xFFFF); });
}
SIMBOT_INSTRUCTION(ANDW) {
  return r.binary([](uint32_t a, uint32_t b) { return a & b & 0xFFFF; });
}
SIMBOT_INSTRUCTION(ORW) {
  return r.binary([](uint32_t a, uint32_t b) { return (a | b) & 0xFFFF; });
}
SIMBOT_INSTRUCTION(XORW) {
  return r.binary([](uint32_t a, uint32_t b) { return (a ^ b) & 0xFFFF; });
}
// The 16-bit shifts loop once per bit (opcodes.def); 16 or more passes
// leave nothing (or the sign) behind.
SIMBOT_INSTRUCTION(SHLW) {
  return shift16<Op::SHLW>(r,
                           [](uint32_t a, uint32_t n) { return n >= 16 ? 0u : (a << n) & 0xFFFF; });
}
SIMBOT_INSTRUCTION(SHRW) {
  return shift16<Op::SHRW>(
      r, [](uint32_t a, uint32_t n) { return w(asInt16(a) >> std::min<uint32_t>(n, 15)); });
}
SIMBOT_INSTRUCTION(SHRUW) {
  return shift16<Op::SHRUW>(
      r, [](uint32_t a, uint32_t n) { return n >= 16 ? 0u : (a & 0xFFFF) >> n; });
}
SIMBOT_INSTRUCTION(NEGW) {
  r.top() = w(-static_cast<int32_t>(r.top()));
  return true;
}
SIMBOT_INSTRUCTION(NOTW) {
  r.top() = ~r.top() & 0xFFFF;
  return true;
}
SIMBOT_INSTRUCTION(LNOTW) {
  r.top() = (r.top() & 0xFFFF) == 0;
  branch<Op::LNOTW>(r, r.top() == 0 ? 1u : 0u);
  return true;
}
SIMBOT_INSTRUCTION(W2B) {
  r.top() &= 0xFF;
  return true;
}
SIMBOT_INSTRUCTION(SXB) {
  r.top() = static_cast<uint16_t>(static_cast<int8_t>(r.top() & 0xFF));
  return true;
}
SIMBOT_INSTRUCTION(EQW) { return compare16<Op::EQW>(r); }
SIMBOT_INSTRUCTION(NEW) { return compare16<Op::NEW>(r); }
SIMBOT_INSTRUCTION(LTW) { return compare16<Op::LTW>(r); }
SIMBOT_INSTRUCTION(LEW) { return compare16<Op::LEW>(r); }
SIMBOT_INSTRUCTION(GTW) { return compare16<Op::GTW>(r); }
SIMBOT_INSTRUCTION(GEW) { return compare16<Op::GEW>(r); }
SIMBOT_INSTRUCTION(LTUW) { return compare16<Op::LTUW>(r); }
SIMBOT_INSTRUCTION(LEUW) { return compare16<Op::LEUW>(r); }
SIMBOT_INSTRUCTION(GTUW) { return compare16<Op::GTUW>(r); }
SIMBOT_INSTRUCTION(GEUW) { return compare16<Op::GEUW>(r); }

// ---- 32-bit arithmetic ----------------------------------------------------------

inline int32_t asInt32(uint32_t v) { return static_cast<int32_t>(v); }

SIMBOT_INSTRUCTION(ADDL) {
  return r.binary([](uint32_t a, uint32_t b) { return a + b; });
}
SIMBOT_INSTRUCTION(SUBL) {
  return r.binary([](uint32_t a, uint32_t b) { return a - b; });
}
SIMBOT_INSTRUCTION(MULL) {
  return r.binary([](uint32_t a, uint32_t b) { return a * b; });
}
// INT32_MIN / -1 wraps (computed in 64 bits).
SIMBOT_INSTRUCTION(DIVL) {
  return divide(r, r.top() == 0, [](uint32_t a, uint32_t b) {
    return static_cast<uint32_t>(int64_t{asInt32(a)} / asInt32(b));
  });
}
SIMBOT_INSTRUCTION(DIVUL) {
  return divide(r, r.top() == 0, [](uint32_t a, uint32_t b) { return a / b; });
}
SIMBOT_INSTRUCTION(MODL) {
  return divide(r, r.top() == 0, [](uint32_t a, uint32_t b) {
    return static_cast<uint32_t>(int64_t{asInt32(a)} % asInt32(b));
  });
}
SIMBOT_INSTRUCTION(MODUL) {
  return divide(r, r.top() == 0, [](uint32_t a, uint32_t b) { return a % b; });
}
SIMBOT_INSTRUCTION(ANDL) {
  return r.binary([](uint32_t a, uint32_t b) { return a & b; });
}
SIMBOT_INSTRUCTION(ORL) {
  return r.binary([](uint32_t a, uint32_t b) { return a | b; });
}
SIMBOT_INSTRUCTION(XORL) {
  return r.binary([](uint32_t a, uint32_t b) { return a ^ b; });
}
SIMBOT_INSTRUCTION(SHLL) {
  return r.binary([](uint32_t a, uint32_t b) { return (b & 0xFF) >= 32 ? 0u : a << (b & 0xFF); });
}
SIMBOT_INSTRUCTION(SHRL) {
  return r.binary([](uint32_t a, uint32_t b) {
    return static_cast<uint32_t>(asInt32(a) >> std::min<uint32_t>(b & 0xFF, 31));
  });
}
SIMBOT_INSTRUCTION(SHRUL) {
  return r.binary([](uint32_t a, uint32_t b) { return (b & 0xFF) >= 32 ? 0u : a >> (b & 0xFF); });
}
SIMBOT_INSTRUCTION(NEGL) {
  r.top() = 0u - r.top();
  return true;
}
SIMBOT_INSTRUCTION(NOTL) {
  r.top() = ~r.top();
  return true;
}
SIMBOT_INSTRUCTION(TESTL) {
  r.top() = r.top() != 0;
  branch<Op::TESTL>(r, r.top() == 0 ? 1u : 0u);
  return true;
}
SIMBOT_INSTRUCTION(EQL) {
  return r.binary([](uint32_t a, uint32_t b) -> uint32_t { return a == b; });
}
SIMBOT_INSTRUCTION(NEL) {
  return r.binary([](uint32_t a, uint32_t b) -> uint32_t { return a != b; });
}
SIMBOT_INSTRUCTION(LTL) {
  return r.binary([](uint32_t a, uint32_t b) -> uint32_t { return asInt32(a) < asInt32(b); });
}
SIMBOT_INSTRUCTION(LEL) {
  return r.binary([](uint32_t a, uint32_t b) -> uint32_t { return asInt32(a) <= asInt32(b); });
}
SIMBOT_INSTRUCTION(GTL) {
  return r.binary([](uint32_t a, uint32_t b) -> uint32_t { return asInt32(a) > asInt32(b); });
}
SIMBOT_INSTRUCTION(GEL) {
  return r.binary([](uint32_t a, uint32_t b) -> uint32_t { return asInt32(a) >= asInt32(b); });
}
SIMBOT_INSTRUCTION(LTUL) {
  return r.binary([](uint32_t a, uint32_t b) -> uint32_t { return a < b; });
}
SIMBOT_INSTRUCTION(LEUL) {
  return r.binary([](uint32_t a, uint32_t b) -> uint32_t { return a <= b; });
}
SIMBOT_INSTRUCTION(GTUL) {
  return r.binary([](uint32_t a, uint32_t b) -> uint32_t { return a > b; });
}
SIMBOT_INSTRUCTION(GEUL) {
  return r.binary([](uint32_t a, uint32_t b) -> uint32_t { return a >= b; });
}

// ---- float ------------------------------------------------------------------------

template <class F>
[[gnu::always_inline]] inline auto onFloats(F f) {
  return [f](uint32_t a, uint32_t b) -> uint32_t { return f(asFloat(a), asFloat(b)); };
}
SIMBOT_INSTRUCTION(ADDF) {
  return r.binary(onFloats([](float a, float b) { return fromFloat(a + b); }));
}
SIMBOT_INSTRUCTION(SUBF) {
  return r.binary(onFloats([](float a, float b) { return fromFloat(a - b); }));
}
SIMBOT_INSTRUCTION(MULF) {
  return r.binary(onFloats([](float a, float b) { return fromFloat(a * b); }));
}
SIMBOT_INSTRUCTION(DIVF) {
  return divide(r, asFloat(r.top()) == 0.0f,
                onFloats([](float a, float b) { return fromFloat(a / b); }));
}
SIMBOT_INSTRUCTION(NEGF) {
  r.top() ^= 0x80000000u;
  return true;
}
SIMBOT_INSTRUCTION(TESTF) {
  r.top() = asFloat(r.top()) != 0.0f;
  return true;
}
SIMBOT_INSTRUCTION(EQF) {
  return r.binary(onFloats([](float a, float b) -> uint32_t { return a == b; }));
}
SIMBOT_INSTRUCTION(NEF) {
  return r.binary(onFloats([](float a, float b) -> uint32_t { return a != b; }));
}
SIMBOT_INSTRUCTION(LTF) {
  return r.binary(onFloats([](float a, float b) -> uint32_t { return a < b; }));
}
SIMBOT_INSTRUCTION(LEF) {
  return r.binary(onFloats([](float a, float b) -> uint32_t { return a <= b; }));
}
SIMBOT_INSTRUCTION(GTF) {
  return r.binary(onFloats([](float a, float b) -> uint32_t { return a > b; }));
}
SIMBOT_INSTRUCTION(GEF) {
  return r.binary(onFloats([](float a, float b) -> uint32_t { return a >= b; }));
}

// ---- conversions --------------------------------------------------------------------

template <class F>
[[gnu::always_inline]] inline bool Vm::State::unary(Regs& r, F f) {
  r.top() = f(r.top());
  return true;
}
SIMBOT_INSTRUCTION(W2L) {
  return unary(r, [](uint32_t v) { return static_cast<uint32_t>(int32_t{asInt16(v)}); });
}
SIMBOT_INSTRUCTION(UW2L) {
  return unary(r, [](uint32_t v) { return v & 0xFFFF; });
}
SIMBOT_INSTRUCTION(L2W) {
  return unary(r, [](uint32_t v) { return v & 0xFFFF; });
}
SIMBOT_INSTRUCTION(W2F) {
  return unary(r, [](uint32_t v) { return fromFloat(static_cast<float>(asInt16(v))); });
}
SIMBOT_INSTRUCTION(UW2F) {
  return unary(r, [](uint32_t v) { return fromFloat(static_cast<float>(v & 0xFFFF)); });
}
SIMBOT_INSTRUCTION(L2F) {
  return unary(r, [](uint32_t v) { return fromFloat(static_cast<float>(asInt32(v))); });
}
SIMBOT_INSTRUCTION(UL2F) {
  return unary(r, [](uint32_t v) { return fromFloat(static_cast<float>(v)); });
}
SIMBOT_INSTRUCTION(F2W) {
  return unary(r, [](uint32_t v) {
    return static_cast<uint32_t>(truncToRange(asFloat(v), -2147483648.0, 2147483647.0)) & 0xFFFF;
  });
}
SIMBOT_INSTRUCTION(F2L) {
  return unary(r, [](uint32_t v) {
    return static_cast<uint32_t>(truncToRange(asFloat(v), -2147483648.0, 2147483647.0));
  });
}
SIMBOT_INSTRUCTION(F2UL) {
  return unary(r, [](uint32_t v) {
    return static_cast<uint32_t>(truncToRange(asFloat(v), -2147483648.0, 4294967295.0));
  });
}

// ---- control flow -------------------------------------------------------------------

SIMBOT_INSTRUCTION(JMP) {
  r.ip = r.relTarget();
  return true;
}
template <bool kIfZero>
[[gnu::always_inline]] inline bool Vm::State::branchIf(Regs& r) {
  const bool taken = ((r.pop() & 0xFFFF) == 0) == kIfZero;
  branch<kIfZero ? Op::JZ : Op::JNZ>(r, taken ? 1u : 0u);
  if (taken) r.ip = r.relTarget();
  return true;
}
SIMBOT_INSTRUCTION(JZ) { return branchIf<true>(r); }
SIMBOT_INSTRUCTION(JNZ) { return branchIf<false>(r); }
// CALL and CALLI: the return address pushed on the robot's stack, then the
// jump.
[[gnu::always_inline]] inline bool Vm::State::callTo(Regs& r, uint32_t target) {
  if (msp < stackLimit + kReturnAddressBytes) return fail(r, "stack overflow");
  if (r.esp > kEvalSlots - kEvalHeadroom) return fail(r, "stack overflow (expression stack)");
  msp -= kReturnAddressBytes;
  r.wr16(msp, static_cast<uint32_t>(r.ip));
  calls.push_back(CallFrame{static_cast<uint32_t>(r.ip), msp});
  r.ip = target;
  return true;
}
SIMBOT_INSTRUCTION(CALL) { return callTo(r, r.u16()); }
SIMBOT_INSTRUCTION(CALLI) {
  const uint32_t target = r.pop() & 0xFFFF;
  const uint32_t argc = r.code[r.opPc + 1];
  const Image::Entry* entry = image().entryAt(target);
  if (!entry || entry->params != argc) {
    const Regs held = r;  // r's address stays in run(), so its fields stay in registers
    return badCallThrough(held, target, argc);
  }
  return callTo(r, target);
}
SIMBOT_INSTRUCTION(ENTER) {
  const uint32_t size = r.u16();
  if (msp < stackLimit + kSavedFpBytes + size) return fail(r, "stack overflow");
  msp -= kSavedFpBytes;
  r.wr16(msp, mfp);  // PUSH IX
  msp -= size;
  mfp = msp;
  return true;
}
// RET takes the return address from the robot's memory: at SP, or in a
// function whose ENTER made an auto frame (returnFrame), above the saved IX
// that the epilogue pops from just above the frame that IX points at.
// Where it leads anywhere but back to the call, divertedReturn decides.
SIMBOT_INSTRUCTION(RET) {
  if (calls.empty() || (!ints.empty() && static_cast<int>(calls.size()) <= ints.back().callDepth))
    return fail(r, "return with no caller");
  const CallFrame call = calls.back();
  calls.pop_back();
  const int32_t frame = program->returnFrame[r.opPc];
  const uint32_t fp = mfp;
  uint32_t readAt = msp;
  if (frame >= 0) {
    r.charge(static_cast<int32_t>(costs().autoFrameRet));  // LD SP,IX; POP IX
    const uint32_t savedFp = (fp + static_cast<uint32_t>(frame)) & 0xFFFF;
    mfp = r.rd16(savedFp);
    readAt = (savedFp + kSavedFpBytes) & 0xFFFF;
  }
  const uint32_t target = r.rd16(readAt);
  // SP wraps at 16 bits; kMemorySize is the empty stack.
  msp = (readAt + kReturnAddressBytes - 1) % kMemorySize + 1;
  if (__builtin_expect(target != call.retPc || readAt != call.saved, 0)) {
    Regs held = r;  // as in CALLI
    const bool runsOn = divertedReturn(held, call, target, readAt, frame, fp);
    r = held;
    return runsOn;
  }
  r.ip = target;
  return true;
}
SIMBOT_INSTRUCTION(DBG) {
  (void)r;
  return true;
}

// ---- the instructions that always end at the slow boundary ----------------------------

SIMBOT_INSTRUCTION(RETI) {
  save(r);
  if (ints.empty() || static_cast<int>(calls.size()) != ints.back().callDepth) {
    raiseFault("RETI outside an interrupt handler", r.pc());
    return false;
  }
  InterruptFrame& f = ints.back();
  if (f.evalSp != eval.sp && !diverted) {
    raiseFault("internal error: stack imbalance at RETI", r.pc());
    return false;
  }
  // The interrupted PC and IX come back from the acceptance frame in the
  // robot's memory, found where acceptance pushed it, as the epilogue's
  // balanced pops find it (after a diversion inside the handler the chip's
  // pops would start wherever SP was; simbot still uses the acceptance's
  // SP: docs/cycle-model.md).
  const uint32_t top = f.msp - kReturnAddressBytes;
  const uint32_t target = rd16(top);
  pc = f.retPc;
  msp = f.msp;
  mfp = rd16(f.msp - kInterruptFpOffset);
  halted = f.halted;
  burn = f.burn;
  burnPc = f.burnPc;
  copy = f.copy;
  lib = std::move(f.lib);
  const Irq irq = f.irq;
  const uint32_t expected = f.retPc;
  ints.pop_back();
  host().interruptReturned(now, irq);
  // The epilogue's EI: IFF1 is set when the RETI after it ends.
  if (costs().knobs.epilogueEi && !iff1) host().iffChanged(now, true);
  if (costs().knobs.epilogueEi) iff1 = iff2 = true;
  if (target != expected) {
    // A smashed frame: the robot goes where it leads, and what it was
    // doing at the interrupted point (a library call, a HALT) is dropped.
    const std::string problem = returnTargetProblem(target);
    if (!problem.empty()) {
      raiseFault(fmt::format("{} handler returned to 0x{:04X}, {}: the interrupted address "
                             "saved at 0x{:04X} (0x{:04X}) was overwritten",
                             irqName(irq), target, problem, top, expected),
                 r.pc());
      return false;
    }
    pc = target;
    halted = false;
    burn = 0;
    copy = BlockCopy{};
    lib = LibCall{};
    divert(r.pc(), target);
  }
  return false;
}
SIMBOT_INSTRUCTION(HALT) {
  save(r);
  pc = r.pc();  // stays on HALT; an interrupt returns here
  if (!halted) {
    flushConsole();
    haltedAt = now;
  }
  halted = true;
  return false;
}
SIMBOT_INSTRUCTION(LIB) {
  save(r);
  const int id = r.code[r.opPc + 1];
  const int argc = r.code[r.opPc + 2];
  if (id >= kLibCount || argc > kMaxLibArgs || argc > eval.sp)
    raiseFault("invalid library call", r.pc());
  else
    libCall(static_cast<Lib>(id), argc, r.pc());
  return false;
}
SIMBOT_INSTRUCTION(EI) {
  save(r);
  if (!iff1) host().iffChanged(now, true);
  iff1 = iff2 = true;
  eiShadow = true;
  return false;
}
SIMBOT_INSTRUCTION(DI) {
  save(r);
  if (iff1) host().iffChanged(now, false);
  iff1 = iff2 = false;
  return false;
}
SIMBOT_INSTRUCTION(COSTATE) {
  save(r);
  const uint32_t cd = r.u16();
  const uint32_t end = r.coTarget();
  if (!checkAccess(cd, kCoDataSize, r.pc())) return false;
  const uint8_t state = rd8(cd + kCoState);
  if (state & kCoStopped) {
    now += costs().costateStoppedDelta;
    if (r.profile) r.profile[r.opPc] += static_cast<uint64_t>(int64_t{costs().costateStoppedDelta});
    pc = end;
    return false;
  }
  wr8(cd + kCoState, state & ~kCoInit);
  const uint32_t resume = rd16(cd + kCoLastLoc);
  if (resume == 0) {
    // JR Z taken over JP (HL): the documented 84 T-states of a fresh entry.
    // (save(r) above copied the clock out of the registers: the delta goes
    // to `now`, which the boundary after this instruction runs on.)
    const int32_t d = costs().branchDelta[static_cast<int>(Op::COSTATE)][2];
    now += d;
    if (r.profile) r.profile[r.opPc] += static_cast<uint64_t>(int64_t{d});
  } else {
    if (coChecksum(resume, rd8(cd + kCoLastLocCbr)) != rd8(cd + kCoChkSum)) {
      raiseFault("costatement's resume address is corrupted (CoData checksum)", r.pc());
      return false;
    }
    if (!std::binary_search(image().resumePoints.begin(), image().resumePoints.end(),
                            static_cast<uint16_t>(resume))) {
      raiseFault(fmt::format("costatement resumes at 0x{:04x}, not a yield point", resume), r.pc());
      return false;
    }
    pc = resume;
  }
  costateEvent(cd, Bus::CostateEvent::Enter, pc);
  return false;
}
SIMBOT_INSTRUCTION(COYIELD) {
  save(r);
  const uint32_t cd = r.u16();
  if (!checkAccess(cd, kCoDataSize, r.pc())) return false;
  setResume(cd, r.coTarget());
  costateEvent(cd, Bus::CostateEvent::Yield, r.pc());
  return false;
}
// COEND (the end of a costatement's body) and CODONE (a waitfordone's end).
[[gnu::always_inline]] inline bool Vm::State::coEnd(Regs& r, bool done) {
  save(r);
  const uint32_t cd = r.u16();
  if (!checkAccess(cd, kCoDataSize, r.pc())) return false;
  costateEnd(cd, done);
  costateEvent(cd, Bus::CostateEvent::End, r.pc());
  return false;
}
SIMBOT_INSTRUCTION(COEND) { return coEnd(r, false); }
SIMBOT_INSTRUCTION(CODONE) { return coEnd(r, true); }

#undef SIMBOT_INSTRUCTION

}  // namespace simbot::vm
