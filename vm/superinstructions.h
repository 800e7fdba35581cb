// The superinstructions' shapes (superinstructions.def) as data: the
// decoder matches them against the code (vm.cpp superinstructionAt), the
// dispatch loop has one handler per entry, generated from the same list,
// and the tests check each one against the pieces run one by one.
#pragma once
#include <algorithm>
#include <array>
#include <initializer_list>
#include <iterator>
#include <string_view>

#include "vm/bytecode.h"

namespace simbot::vm::detail {

inline constexpr int kMaxPieces = 16;

struct SuperShape {
  std::string_view name;
  std::array<Op, kMaxPieces> pieces;
  int n;
};

template <Op... Pieces>
constexpr SuperShape superShape(std::string_view name) {
  static_assert(sizeof...(Pieces) >= 2 && sizeof...(Pieces) <= kMaxPieces);
  return SuperShape{name, {Pieces...}, static_cast<int>(sizeof...(Pieces))};
}

inline constexpr SuperShape kSuperShapes[] = {
#define SUPER(name, ...)                   \
  [] {                                     \
    using enum Op;                         \
    return superShape<__VA_ARGS__>(#name); \
  }(),
#include "vm/superinstructions.def"
#undef SUPER
};
inline constexpr int kSuperCount = static_cast<int>(std::size(kSuperShapes));

// Their indices in kSuperShapes, by name (the handlers' spans).
enum SuperKind : int {
#define SUPER(name, ...) kSuper##name,
#include "vm/superinstructions.def"
#undef SUPER
};

// The entries by their first piece, each opcode's in the table's order
// (the decoder tries only those that can match at an address):
// kSuperByFirst.entry[begin[op] .. begin[op + 1]).
struct SuperIndex {
  std::array<int, kOpCount + 1> begin{};
  std::array<int, kSuperCount> entry{};
};
inline constexpr SuperIndex kSuperByFirst = [] {
  SuperIndex index;
  int next = 0;
  for (int op = 0; op < kOpCount; ++op) {
    index.begin[static_cast<size_t>(op)] = next;
    for (int i = 0; i < kSuperCount; ++i)
      if (static_cast<int>(kSuperShapes[i].pieces[0]) == op)
        index.entry[static_cast<size_t>(next++)] = i;
  }
  index.begin[kOpCount] = next;
  return index;
}();
static_assert(
    [] {
      // Every entry once, each opcode's in the table's order.
      for (int op = 0; op < kOpCount; ++op)
        for (int j = kSuperByFirst.begin[static_cast<size_t>(op)] + 1;
             j < kSuperByFirst.begin[static_cast<size_t>(op) + 1]; ++j)
          if (kSuperByFirst.entry[static_cast<size_t>(j)] <=
              kSuperByFirst.entry[static_cast<size_t>(j) - 1])
            return false;
      return kSuperByFirst.begin[kOpCount] == kSuperCount;
    }(),
    "the first-piece index holds every superinstruction once, in order");

// Where a piece leads (the next piece's address is decided at decode time,
// so a run may not go on after a piece whose successor depends on data).
constexpr bool endsRun(Op op) {
  switch (op) {
    case Op::JZ:
    case Op::JNZ:
    case Op::RET:
    case Op::RETI:
    case Op::HALT:
    case Op::LIB:
    case Op::EI:
    case Op::DI:
    case Op::COSTATE:
    case Op::COYIELD:
    case Op::COEND:
    case Op::CODONE:
      return true;
    default:
      return false;
  }
}
// The shifts leave their further passes to the slow boundary (their
// exec sets the limit to 0): only a last piece.
constexpr bool addsBurn(Op op) { return op == Op::SHLW || op == Op::SHRW || op == Op::SHRUW; }
// The instructions that always go to the slow boundary: never a piece.
// COPY too: its bytes are the slow boundary's steps, and it sets its own
// clock back from the whole figure dispatch charged to its set-up's end.
constexpr bool needsSlowBoundary(Op op) {
  return op == Op::RETI || op == Op::HALT || op == Op::LIB || op == Op::EI || op == Op::DI ||
         op == Op::COSTATE || op == Op::COYIELD || op == Op::COEND || op == Op::CODONE ||
         op == Op::COPY;
}

// What a run of pieces does to the expression stack, from opcodes.def:
// the most slots it takes from below its entry depth, the most it holds
// above it and where it ends. CALL leaves the stack as it is (its callee's
// prologue takes the arguments).
struct StackReach {
  int below = 0, above = 0, net = 0;
};
constexpr StackReach stackReach(std::initializer_list<Op> pieces) {
  StackReach r;
  for (const Op op : pieces) {
    const int pop = op == Op::CALL ? 0 : kOpInfo[static_cast<int>(op)].pop;
    const int push = op == Op::CALL ? 0 : kOpInfo[static_cast<int>(op)].push;
    if (pop < 0 || push < 0) throw "a piece whose stack effect depends on its operands";
    r.net -= pop;
    r.below = std::max(r.below, -r.net);
    r.net += push;
    r.above = std::max(r.above, r.net);
  }
  return r;
}

constexpr bool wellFormed(const SuperShape& s) {
  for (int k = 0; k < s.n; ++k) {
    if (needsSlowBoundary(s.pieces[k])) return false;
    if (k < s.n - 1 && (endsRun(s.pieces[k]) || addsBurn(s.pieces[k]))) return false;
  }
  return true;
}
static_assert(
    [] {
      for (const SuperShape& s : kSuperShapes)
        if (!wellFormed(s)) return false;
      return true;
    }(),
    "a superinstruction's pieces: no slow instruction, a branch, RET or shift only last");

}  // namespace simbot::vm::detail
