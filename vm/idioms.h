// Semantic superinstructions (idioms): runs of 3-5 ordinary instructions
// that the fast path executes as one dispatch, with no expression-stack
// traffic for their intermediates. Chosen from the most frequent n-grams
// counted over the reference, shipped, test and benchmark programs
// (docs/cycle-model.md, "Dispatch"). The list is shared by the decoder (idioms.cpp: which idiom
// starts at an address, and what its pieces cost) and the handlers
// (vm.cpp, one label per idiom, in the same order).
#pragma once
#include <cstdint>
#include <iterator>

#include "vm/bytecode.h"

namespace simbot::vm::detail {

// Compare-and-branch: LOAD x; PUSHW k; CMP; BR t, for every 16-bit
// comparison, a global or auto LOAD and JZ or JNZ.
// clang-format off
#define SIMBOT_IDIOM_COMPARES(X, load, br)                              \
  X(load, LTW, br) X(load, LEW, br) X(load, GTW, br) X(load, GEW, br)   \
  X(load, EQW, br) X(load, NEW, br) X(load, LTUW, br) X(load, LEUW, br) \
  X(load, GTUW, br) X(load, GEUW, br)
#define SIMBOT_IDIOMS_CB(X)                                                    \
  SIMBOT_IDIOM_COMPARES(X, LDGW, JZ) SIMBOT_IDIOM_COMPARES(X, LDGW, JNZ)       \
  SIMBOT_IDIOM_COMPARES(X, LDLW, JZ) SIMBOT_IDIOM_COMPARES(X, LDLW, JNZ)
// Load-op-store on globals: LDGW a; SRC b; OP; STGW c (c = a OP b), alone
// (BS) and closing a loop (BSJ: then JMP).
#define SIMBOT_IDIOMS_BS(X) X(LDGW, ADDW) X(LDGW, SUBW) X(PUSHW, ADDW) X(PUSHW, SUBW)
// An operand and an immediate: LOAD x; PUSHW k; OP (pushes x OP k), alone
// (LK) and as a call's last argument (LKC: then CALL f).
#define SIMBOT_IDIOMS_LK(X) \
  X(LDLW, ADDW) X(LDLW, SUBW) X(LDGW, ADDW) X(LDGW, SUBW)

// An expression's end stored: PUSHW k; OP; STGW a (a = top OP k).
#define SIMBOT_IDIOMS_KS(X) X(ADDW) X(SUBW)

// Every idiom as X(name, first piece), in the order of kIdiomShapes.
#define SIMBOT_IDIOM_LIST(X)                                                   \
  X(StoreByte, PUSHW) X(ByteJZ, PUSHW) X(ByteJNZ, PUSHW) X(Byte, PUSHW)       \
  SIMBOT_IDIOMS_CB(X##_CB) SIMBOT_IDIOMS_BS(X##_BSJ) SIMBOT_IDIOMS_BS(X##_BS) \
  SIMBOT_IDIOMS_LK(X##_LKC) SIMBOT_IDIOMS_LK(X##_LK) X(MulAdd, LDGW)          \
  X(Mul, LDGW) SIMBOT_IDIOMS_KS(X##_KS) X(StoreConst, PUSHW) X(LoadRet, LDLW)
// clang-format on

// Every idiom as SIMBOT_IDIOM_NAMED(name, first piece), in the same order,
// each family's name spelled out (CB_LDGW_LTW_JZ, BSJ_LDGW_ADDW, ...): the
// enum below, the handlers' label tables and the DBG entries in vm.cpp
// define SIMBOT_IDIOM_NAMED and expand SIMBOT_IDIOM_NAMES.
#define SIMBOT_IDIOM_N(name, first) SIMBOT_IDIOM_NAMED(name, first)
#define SIMBOT_IDIOM_N_CB(l, c, b) SIMBOT_IDIOM_NAMED(CB_##l##_##c##_##b, l)
#define SIMBOT_IDIOM_N_BSJ(s, o) SIMBOT_IDIOM_NAMED(BSJ_##s##_##o, LDGW)
#define SIMBOT_IDIOM_N_BS(s, o) SIMBOT_IDIOM_NAMED(BS_##s##_##o, LDGW)
#define SIMBOT_IDIOM_N_LKC(l, o) SIMBOT_IDIOM_NAMED(LKC_##l##_##o, l)
#define SIMBOT_IDIOM_N_LK(l, o) SIMBOT_IDIOM_NAMED(LK_##l##_##o, l)
#define SIMBOT_IDIOM_N_KS(o) SIMBOT_IDIOM_NAMED(KS_##o, PUSHW)
#define SIMBOT_IDIOM_NAMES SIMBOT_IDIOM_LIST(SIMBOT_IDIOM_N)

// Every idiom's pieces, longest first where one idiom is a prefix of
// another (the decoder takes the first that matches).
#define SIMBOT_IDIOM_CB_SHAPE(l, c, b) {{Op::l, Op::PUSHW, Op::c, Op::b}, 4},
#define SIMBOT_IDIOM_BSJ_SHAPE(s, o) {{Op::LDGW, Op::s, Op::o, Op::STGW, Op::JMP}, 5},
#define SIMBOT_IDIOM_BS_SHAPE(s, o) {{Op::LDGW, Op::s, Op::o, Op::STGW}, 4},
#define SIMBOT_IDIOM_LKC_SHAPE(l, o) {{Op::l, Op::PUSHW, Op::o, Op::CALL}, 4},
#define SIMBOT_IDIOM_LK_SHAPE(l, o) {{Op::l, Op::PUSHW, Op::o}, 3},
#define SIMBOT_IDIOM_KS_SHAPE(o) {{Op::PUSHW, Op::o, Op::STGW}, 3},
// clang-format off
#define SIMBOT_IDIOM_SHAPES                                                      \
  {{Op::PUSHW, Op::LDGW, Op::ADDW, Op::PUSHW, Op::STIB}, 5},                     \
  {{Op::PUSHW, Op::LDGW, Op::ADDW, Op::LDIB, Op::JZ}, 5},                        \
  {{Op::PUSHW, Op::LDGW, Op::ADDW, Op::LDIB, Op::JNZ}, 5},                       \
  {{Op::PUSHW, Op::LDGW, Op::ADDW, Op::LDIB}, 4},                                \
  SIMBOT_IDIOMS_CB(SIMBOT_IDIOM_CB_SHAPE)                                        \
  SIMBOT_IDIOMS_BS(SIMBOT_IDIOM_BSJ_SHAPE)                                       \
  SIMBOT_IDIOMS_BS(SIMBOT_IDIOM_BS_SHAPE)                                        \
  SIMBOT_IDIOMS_LK(SIMBOT_IDIOM_LKC_SHAPE)                                       \
  SIMBOT_IDIOMS_LK(SIMBOT_IDIOM_LK_SHAPE)                                        \
  {{Op::LDGW, Op::LDGW, Op::MULW, Op::ADDW}, 4},                                 \
  {{Op::LDGW, Op::LDGW, Op::MULW}, 3},                                           \
  SIMBOT_IDIOMS_KS(SIMBOT_IDIOM_KS_SHAPE)                                        \
  {{Op::PUSHW, Op::STGW}, 2},                                                    \
  {{Op::LDLW, Op::RET}, 2}
// clang-format on

// Joins: a loop's closing piece (INCGW a; JMP t, or a BSJ idiom) whose JMP
// goes to a compare-and-branch that exits the loop (CB with JZ) runs that
// compare-and-branch in the same dispatch (vm.cpp "Joins"). Every pair of a
// closer and a target, closers in this order: IJ (INCGW; JMP), then the
// BSJ idioms.
// clang-format off
#define SIMBOT_JOIN_COMPARES(X, C, l)                                   \
  X(C, l, LTW) X(C, l, LEW) X(C, l, GTW) X(C, l, GEW) X(C, l, EQW)     \
  X(C, l, NEW) X(C, l, LTUW) X(C, l, LEUW) X(C, l, GTUW) X(C, l, GEUW)
#define SIMBOT_JOIN_TARGETS(X, C) SIMBOT_JOIN_COMPARES(X, C, LDGW) SIMBOT_JOIN_COMPARES(X, C, LDLW)
#define SIMBOT_JOINS(X)                                                         \
  SIMBOT_JOIN_TARGETS(X, IJ) SIMBOT_JOIN_TARGETS(X, BSJ_LDGW_ADDW)              \
  SIMBOT_JOIN_TARGETS(X, BSJ_LDGW_SUBW) SIMBOT_JOIN_TARGETS(X, BSJ_PUSHW_ADDW)  \
  SIMBOT_JOIN_TARGETS(X, BSJ_PUSHW_SUBW)
// clang-format on

struct IdiomShape {
  Op pieces[5];
  int n;
};

inline constexpr IdiomShape kIdiomShapes[] = {SIMBOT_IDIOM_SHAPES};
inline constexpr int kIdiomCount = static_cast<int>(std::size(kIdiomShapes));

// Their indices, in the same order (the handlers' names in vm.cpp).
enum IdiomKind : int {
#define SIMBOT_IDIOM_NAMED(name, first) kIdiom##name,
  SIMBOT_IDIOM_NAMES
#undef SIMBOT_IDIOM_NAMED
      kIdiomEnd
};
static_assert(kIdiomEnd == kIdiomCount, "one kind per shape");

// The joins' indices: closer c with target t is c * kJoinTargetCount + t.
enum JoinKind : int {
#define SIMBOT_JOIN_KIND(C, l, c) kJoin_##C##_##l##_##c,
  SIMBOT_JOINS(SIMBOT_JOIN_KIND)
#undef SIMBOT_JOIN_KIND
      kJoinEnd
};
// The targets, as idioms.
inline constexpr int kJoinTargets[] = {
#define SIMBOT_JOIN_TARGET(C, l, c) kIdiomCB_##l##_##c##_JZ,
    SIMBOT_JOIN_TARGETS(SIMBOT_JOIN_TARGET, IJ)
#undef SIMBOT_JOIN_TARGET
};
inline constexpr int kJoinTargetCount = static_cast<int>(std::size(kJoinTargets));
// The closers that are idioms (the first closer, IJ, is not one).
inline constexpr int kJoinClosers[] = {-1, kIdiomBSJ_LDGW_ADDW, kIdiomBSJ_LDGW_SUBW,
                                       kIdiomBSJ_PUSHW_ADDW, kIdiomBSJ_PUSHW_SUBW};
inline constexpr int kJoinCloserCount = static_cast<int>(std::size(kJoinClosers));
static_assert(kJoinEnd == kJoinCloserCount * kJoinTargetCount, "one join per closer and target");

// The farthest an entry that fuses pieces can be before the last of them
// (DBG, then PUSHW base; LDGW i; ADDW; PUSHW v; STIB or LDGW a; LDGW b;
// ADDW; STGW c; JMP t): a breakpoint set at an address re-decodes the
// entries this far before it.
inline constexpr uint32_t kMaxIdiomReach = 11;

// An idiom's pieces' costs, from the cost table: `span`, the most its
// pieces but the first and the last can take (each at its slowest
// branch path), and `base`, what its pieces but the first cost with every
// branch not taken (the handler adds the paths' deltas).
// `path`: a compare-and-branch's whole cost by its compare's path p and
// its branch (taken t), at [p * 2 + t].
struct IdiomCost {
  uint32_t span = 0;
  uint32_t base = 0;
  uint32_t path[8]{};
  bool operator==(const IdiomCost&) const = default;
};

}  // namespace simbot::vm::detail
