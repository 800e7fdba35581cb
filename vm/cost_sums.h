// The cycle model's sums, done at compile time: the Z180 timings of
// z180.def, the sum of a written sequence of them, and the tables of every
// opcode's and library call's sequence (opcodes.def, builtins.def) that
// makeCostTable resolves against the knobs (cost.h).
// Apart from cost.h so that only the VM's cost, disassembler and library
// files and the cost model's test evaluate them: a file that includes
// them spends about a second of compile time on the tables.
#pragma once
#include <array>
#include <cstdint>
#include <string_view>

#include "vm/bytecode.h"
#include "vm/cost.h"

namespace simbot::vm {

struct Z180Insn {
  std::string_view mnemonic;
  int tstates;  // the Z80180's
  int memCycles;
  int ioCycles;
  // Conditional branches (Z180_BRANCH): tstates/memCycles above are the
  // not-taken figures, these the taken ones.
  bool branch;
  int takenTstates;
  int takenMemCycles;
  // The Z8S180's T-states less the Z80180's (Z180_REVISED).
  int z8s180Delta;
};

inline constexpr Z180Insn kZ180[] = {
#define Z180_INSN(m, t, mc, io) {m, t, mc, io, false, t, mc, 0},
#define Z180_BRANCH(m, nt, nmc, tt, tmc) {m, nt, nmc, 0, true, tt, tmc, 0},
#define Z180_REVISED(m, t, ts, mc, io) {m, t, mc, io, false, t, mc, (ts) - (t)},
#include "vm/z180.def"
#undef Z180_REVISED
#undef Z180_BRANCH
#undef Z180_INSN
};

struct SeqCost {
  int tstates = 0;  // on the Z80180
  int memCycles = 0;
  int ioCycles = 0;
  int insns = 0;
  int branches = 0;     // conditional branches in the sequence (a loop's DJNZ is not one)
  int loops = 0;        // loop groups "{...}" in the sequence
  int z8s180Delta = 0;  // what the Z8S180 takes more (less: negative)
};

constexpr SeqCost operator-(SeqCost a, const SeqCost& b) {
  a.tstates -= b.tstates;
  a.memCycles -= b.memCycles;
  a.ioCycles -= b.ioCycles;
  a.insns -= b.insns;
  a.z8s180Delta -= b.z8s180Delta;
  return a;
}

// Branches. A sequence is the code as emitted; a conditional branch in it
// (JP cc,nn or JR cc,e) costs the Z180's taken or not-taken figure by the
// way it goes, and the instructions it jumps over when taken are written
// in brackets right after it: "LD rr,nn; JR cc,e; [INC rr]" runs INC HL
// only when JR falls through. `taken` has bit k set when the k-th branch
// of the sequence is taken; the VM picks the bits from the operands
// (vm.cpp) and charges the difference from the all-not-taken figure.
//
// Loops. "{BODY; DJNZ e}" is a loop closed by DJNZ: it runs `passes` times
// (at least once), the body each time, DJNZ taken passes - 1 times (9) and
// not taken once (7). It may sit inside a bracket group (the 16-bit
// shifts jump over it for a zero count); its DJNZ is not one of the
// sequence's branches. The VM supplies `passes` from the operands.
//
// Sum of a "MNEMONIC; MNEMONIC; ..." sequence along the path `taken`. An
// unknown mnemonic, a stray bracket or brace is a compile-time error (the
// throw is not a constant expression).
constexpr SeqCost sequenceCost(std::string_view seq, unsigned taken = 0, int passes = 1) {
  SeqCost total;
  bool skipping = false;      // inside a bracket group jumped over
  bool inGroup = false;       // inside a bracket group
  bool groupAllowed = false;  // the previous item was a branch
  bool inLoop = false;        // inside a loop group
  SeqCost body;               // one pass of the loop, DJNZ not included
  const Z180Insn* djnz = nullptr;
  while (!seq.empty()) {
    auto end = seq.find(';');
    auto item = seq.substr(0, end);
    while (!item.empty() && item.front() == ' ') item.remove_prefix(1);
    while (!item.empty() && item.back() == ' ') item.remove_suffix(1);
    if (!item.empty()) {
      bool closes = false;
      bool closesLoop = false;
      if (item.front() == '[') {
        if (!groupAllowed || inGroup) throw "a bracket group must follow a conditional branch";
        item.remove_prefix(1);
        inGroup = true;
      } else if (!inGroup) {
        skipping = false;
      }
      if (!item.empty() && item.front() == '{') {
        if (inLoop || total.loops > 0) throw "one loop group per sequence";
        item.remove_prefix(1);
        inLoop = true;
        body = SeqCost{};
        djnz = nullptr;
        ++total.loops;
      }
      if (!item.empty() && item.back() == ']') {
        if (!inGroup) throw "unbalanced bracket in cost sequence";
        item.remove_suffix(1);
        closes = true;
      }
      if (!item.empty() && item.back() == '}') {
        if (!inLoop) throw "unbalanced brace in cost sequence";
        item.remove_suffix(1);
        closesLoop = true;
      }
      groupAllowed = false;
      bool found = false;
      for (const auto& z : kZ180) {
        if (z.mnemonic != item) continue;
        found = true;
        const bool isDjnz = z.mnemonic == "DJNZ e";
        if (isDjnz != (inLoop && closesLoop)) throw "DJNZ closes a loop group, and only it";
        if (isDjnz) {
          djnz = &z;
        } else if (inLoop) {
          if (z.branch) throw "a branch inside a loop group is not supported";
          body.tstates += z.tstates;
          body.memCycles += z.memCycles;
          body.ioCycles += z.ioCycles;
          body.z8s180Delta += z.z8s180Delta;
          ++body.insns;
        } else if (skipping) {
          break;
        } else if (z.branch) {
          if (inGroup) throw "a branch inside a bracket group is not supported";
          const bool isTaken = (taken >> total.branches) & 1u;
          total.tstates += isTaken ? z.takenTstates : z.tstates;
          total.memCycles += isTaken ? z.takenMemCycles : z.memCycles;
          ++total.branches;
          groupAllowed = true;
          skipping = isTaken;  // applies to the bracket group that follows
          ++total.insns;
        } else {
          total.tstates += z.tstates;
          total.memCycles += z.memCycles;
          total.ioCycles += z.ioCycles;
          total.z8s180Delta += z.z8s180Delta;
          ++total.insns;
        }
        break;
      }
      if (!found) throw "unknown Z180 mnemonic in cost sequence";
      if (closesLoop) {
        inLoop = false;
        if (!skipping) {
          if (passes < 1) throw "a loop group runs at least once";
          // passes x body, DJNZ taken passes - 1 times, not taken once.
          total.tstates +=
              passes * body.tstates + (passes - 1) * djnz->takenTstates + djnz->tstates;
          total.memCycles +=
              passes * body.memCycles + (passes - 1) * djnz->takenMemCycles + djnz->memCycles;
          total.ioCycles += passes * body.ioCycles;
          total.z8s180Delta += passes * body.z8s180Delta;
          total.insns += passes * (body.insns + 1);
        }
      }
      if (closes) {
        if (inLoop) throw "a loop group must close inside its bracket group";
        inGroup = false;
        skipping = false;
      }
    }
    if (end == std::string_view::npos) break;
    seq.remove_prefix(end + 1);
  }
  if (inGroup) throw "unbalanced bracket in cost sequence";
  if (inLoop) throw "unbalanced brace in cost sequence";
  return total;
}

inline constexpr auto kOpPathCost = [] {
  std::array<std::array<SeqCost, kOpPaths>, kOpCount> a{};
  for (int i = 0; i < kOpCount; ++i) {
    for (unsigned p = 0; p < kOpPaths; ++p) a[i][p] = sequenceCost(kOpInfo[i].z180, p);
    if (a[i][0].branches > kMaxOpBranches) throw "an opcode with more than two branches";
  }
  return a;
}();

// All branches not taken: what the VM charges when an instruction starts.
inline constexpr auto kOpSeqCost = [] {
  std::array<SeqCost, kOpCount> a{};
  for (int i = 0; i < kOpCount; ++i) a[i] = kOpPathCost[i][0];
  return a;
}();

// Each pass of an opcode's loop after the first (body + DJNZ taken, less
// nothing: the first pass and the DJNZ that falls through are in
// kOpPathCost). Zero for an opcode without a loop.
inline constexpr auto kOpLoopPass = [] {
  std::array<SeqCost, kOpCount> a{};
  for (int i = 0; i < kOpCount; ++i)
    if (kOpPathCost[i][0].loops > 0)
      a[i] = sequenceCost(kOpInfo[i].z180, 0, 2) - sequenceCost(kOpInfo[i].z180, 0, 1);
  return a;
}();

// Library call sequences are charged whole when the call starts. Most must
// cost the same on every path (ser_*'s "JP PO; [EI]": 9 taken, 6 + 3 not
// taken); a routine whose one branch the VM decides from its argument when
// the call starts (abs: by the argument's sign, vm.cpp libPath) may take
// either. Checked here at compile time.
constexpr bool pathsCostTheSame(std::string_view seq) {
  const SeqCost first = sequenceCost(seq, 0);
  for (unsigned p = 1; p < (1u << first.branches); ++p) {
    const SeqCost other = sequenceCost(seq, p);
    if (other.tstates != first.tstates || other.memCycles != first.memCycles ||
        other.ioCycles != first.ioCycles)
      return false;
  }
  return true;
}

// The routines whose path the VM picks from the arguments (vm.cpp libPath).
constexpr bool libPathFromArguments(Lib id) { return id == Lib::ABS; }

// Paths through a library call: one branch at most where they differ.
inline constexpr int kLibPaths = 2;

inline constexpr auto kLibPathCost = [] {
  std::array<std::array<SeqCost, kLibPaths>, kLibCount> a{};
  for (int i = 0; i < kLibCount; ++i) {
    const std::string_view seq = kLibInfo[i].callSeq;
    if (sequenceCost(seq).loops > 0) throw "a library call sequence has no loop group (steps)";
    if (libPathFromArguments(static_cast<Lib>(i))) {
      if (sequenceCost(seq).branches != 1) throw "an argument-chosen path is one branch";
    } else if (!pathsCostTheSame(seq)) {
      throw "library call paths differ in cost";
    }
    for (unsigned p = 0; p < kLibPaths; ++p) a[i][p] = sequenceCost(seq, p);
  }
  return a;
}();

// Path 0 (every branch not taken).
inline constexpr auto kLibCallCost = [] {
  std::array<SeqCost, kLibCount> a{};
  for (int i = 0; i < kLibCount; ++i) a[i] = kLibPathCost[i][0];
  return a;
}();

inline constexpr auto kLibStepCost = [] {
  std::array<SeqCost, kLibCount> a{};
  for (int i = 0; i < kLibCount; ++i) a[i] = sequenceCost(kLibInfo[i].stepSeq);
  return a;
}();

// An inner loop closed by a conditional branch, its step sequence's last
// item ("...; OR A; JR NZ,e"): the branch is taken back for every unit but
// the last, which falls through (kLibStepCost); LDIR likewise repeats at
// its taken figure and ends at its not-taken one. Other loops (atoi's,
// closed by a plain JR) cost the same every pass.
constexpr bool stepLoopIsClosedByItsBranch(std::string_view seq) {
  const auto semicolon = seq.rfind(';');
  auto last = semicolon == std::string_view::npos ? seq : seq.substr(semicolon + 1);
  while (!last.empty() && last.front() == ' ') last.remove_prefix(1);
  return last == "JR cc,e" || last == "JP cc,nn" || last == "LDIR";
}
inline constexpr auto kLibStepLoopingCost = [] {
  std::array<SeqCost, kLibCount> a{};
  for (int i = 0; i < kLibCount; ++i) {
    const std::string_view seq = kLibInfo[i].stepSeq;
    const int branches = sequenceCost(seq).branches;
    a[i] = stepLoopIsClosedByItsBranch(seq) ? sequenceCost(seq, 1u << (branches - 1))
                                            : sequenceCost(seq);
  }
  return a;
}();

// A library call whose sequence saves the interrupt state and disables
// interrupts (the serial library's "LD A,I; PUSH AF; DI ... POP AF; JP PO;
// EI") is atomic: no instruction boundary inside it (DESIGN.md,
// "Interrupts").
inline constexpr auto kLibAtomic = [] {
  std::array<bool, kLibCount> a{};
  for (int i = 0; i < kLibCount; ++i)
    a[i] = kLibInfo[i].callSeq.find("LD A,I; PUSH rr; DI;") != std::string_view::npos;
  return a;
}();

// COPY's sequence up to its LDIR: the head that runs before the first byte.
inline constexpr SeqCost kCopyHeadCost = [] {
  const std::string_view seq = kOpInfo[static_cast<int>(Op::COPY)].z180;
  const auto ldir = seq.find("LDIR");
  if (ldir == std::string_view::npos) throw "COPY's sequence has an LDIR";
  return sequenceCost(seq.substr(0, ldir));
}();

// The RST 28h debug hook's body, run at every statement of a debug build
// (the RST itself is in the DBG opcode's sequence): PUSH AF; LD A,(nn);
// OR A; JR NZ,to_debugger (not taken: no debugger is attached); POP AF; RET.
inline constexpr std::string_view kDebugHookSeq = "PUSH rr; LD A,(nn); OR r; JR cc,e; POP rr; RET";
// What RET adds for a #class auto frame (the frame ENTER set up).
inline constexpr std::string_view kAutoFrameRetSeq = "POP IX";

// A named costatement that is STOPPED: COSTATE goes no further than its
// JP Z to the end (taken).
inline constexpr std::string_view kCostateStoppedSeq = "LD rr,nn; BIT b,(HL); JP cc,nn";

// The BIOS's periodic service on PRT0 (Dynamic C keeps TICK_TIMER, MS_TIMER
// and SEC_TIMER with it; DESIGN.md "Costatements"): acknowledge, save AF,
// HL, DE; read TCR then TMDR0L, which clears TIF0; TICK_TIMER += 1 (32 bits:
// ADD HL,DE then ADC HL,DE with DE = 0); the millisecond fraction += 125 in
// 7 bits and, when it carried into bit 7, MS_TIMER += 1 (so MS_TIMER =
// floor(TICK_TIMER * 125 / 128) = floor(TICK_TIMER * 1000 / 1024)); when
// TICK_TIMER's low 10 bits are 0, SEC_TIMER += 1; restore, EI, RETI.
// Branch 0 is taken when no millisecond is due, branch 1 when no second is.
inline constexpr std::string_view kTimerIsrSeq =
    "INTACK IM2; PUSH rr; PUSH rr; PUSH rr; IN0 r,(n); IN0 r,(n); "
    "LD HL,(nn); LD rr,nn; ADD HL,rr; LD (nn),HL; LD HL,(nn); DEC rr; ADC HL,rr; LD (nn),HL; "
    "LD A,(nn); ADD A,n; LD r,r; AND n; LD (nn),A; BIT b,r; JR cc,e; "
    "[LD HL,(nn); LD rr,nn; ADD HL,rr; LD (nn),HL; LD HL,(nn); DEC rr; ADC HL,rr; LD (nn),HL]; "
    "LD HL,(nn); LD r,r; AND n; OR r; JR cc,e; "
    "[LD HL,(nn); LD rr,nn; ADD HL,rr; LD (nn),HL; LD HL,(nn); DEC rr; ADC HL,rr; LD (nn),HL]; "
    "POP rr; POP rr; POP rr; EI; RETI";

}  // namespace simbot::vm
