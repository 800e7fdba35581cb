// inspect/tree.h -- internal: the syntax tree of a debugger expression and
// the parser that makes it (parse.cpp; the grammar is in inspect.h).
// Nothing outside inspect/ includes this header.
#pragma once
#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "compiler/arith.h"

namespace simbot::inspect {

using compiler::Arith;

// Limits beside what they limit: an expression is a line a person types.
inline constexpr size_t kMaxExpressionChars = 1000;
inline constexpr int kMaxNesting = 64;  // parentheses, unary operators, operands of ?:
inline constexpr int kMaxPointerStars = 8;

// A type name as a cast or sizeof spells it: type words or a struct or
// union tag, then stars. Resolved against the image's types when the
// expression is evaluated.
struct TypeName {
  bool isVoid = false;
  Arith arith = Arith::Int;  // when neither void nor a tag
  std::string tag;           // "struct pt", "union u"
  int pointers = 0;
  std::string text() const;  // as C spells it: "unsigned int", "struct pt *"
};

enum class Op : uint8_t {
  // unary
  Plus,
  Minus,
  Not,
  BitNot,
  Deref,
  Address,
  // binary, loosest last
  Mul,
  Div,
  Mod,
  Add,
  Sub,
  Slice,  // gdb's a@n
  Shl,
  Shr,
  Lt,
  Le,
  Gt,
  Ge,
  Eq,
  Ne,
  BitAnd,
  BitXor,
  BitOr,
  LogAnd,
  LogOr,
};
const char* spelling(Op op);

struct Node {
  enum class Kind : uint8_t {
    Name,         // name, or function::name
    Integer,      // a constant with its C type
    Real,         // a float constant
    Unary,        // op a
    Binary,       // a op b
    Conditional,  // a ? b : c
    Cast,         // (type) a
    SizeofType,   // sizeof (type)
    SizeofExpr,   // sizeof a
    Index,        // a[b]
    Member,       // a.name
    Arrow,        // a->name
  };
  Kind kind = Kind::Integer;
  int height = 1;  // of the tree below, this node included
  Op op = Op::Plus;
  Arith arith = Arith::Int;  // Integer
  int64_t integer = 0;
  float real = 0;
  std::string function;  // Name: FUNCTION::NAME
  std::string name;      // Name, Member, Arrow
  TypeName type;         // Cast, SizeofType
  std::unique_ptr<Node> a, b, c;
};

// Throws Error at the first token that does not fit the grammar.
std::unique_ptr<Node> parse(const std::string& text);
// The whole text as a type name (whatis int, ptype struct pt); none if it
// does not begin with a type word; Error if it begins so but is no type name.
std::optional<TypeName> parseTypeName(const std::string& text);

}  // namespace simbot::inspect
