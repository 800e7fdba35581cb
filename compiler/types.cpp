// C types of Dynamic C on the Z180: char is 8-bit unsigned, short and int
// 16-bit, long 32-bit, float IEEE single, pointers 16-bit. Helpers to classify
// them and to spell them in symbols and messages; then the type rules of
// expressions the parser builds every typed node through (conversions,
// folding, operand checks, pointer arithmetic, assignment).
#include <optional>
#include <string>

#include "compiler/ast.h"
#include "compiler/parser_impl.h"

namespace simbot::compiler {

namespace {
Type makeBasic(TypeKind k, int size) {
  Type t;
  t.kind = k;
  t.size = size;
  return t;
}
Type gVoid = makeBasic(TypeKind::Void, 1);
Type gChar = makeBasic(TypeKind::Char, 1);
Type gSChar = makeBasic(TypeKind::SChar, 1);
Type gInt = makeBasic(TypeKind::Int, 2);
Type gUInt = makeBasic(TypeKind::UInt, 2);
Type gLong = makeBasic(TypeKind::Long, 4);
Type gULong = makeBasic(TypeKind::ULong, 4);
Type gFloat = makeBasic(TypeKind::Float, 4);
}  // namespace

Type* tyVoid() { return &gVoid; }
Type* tyChar() { return &gChar; }
Type* tySChar() { return &gSChar; }
Type* tyInt() { return &gInt; }
Type* tyUInt() { return &gUInt; }
Type* tyLong() { return &gLong; }
Type* tyULong() { return &gULong; }
Type* tyFloat() { return &gFloat; }

bool isInteger(const Type* t) {
  switch (t->kind) {
    case TypeKind::Char:
    case TypeKind::SChar:
    case TypeKind::Int:
    case TypeKind::UInt:
    case TypeKind::Long:
    case TypeKind::ULong:
      return true;
    default:
      return false;
  }
}
bool isArith(const Type* t) { return isInteger(t) || t->kind == TypeKind::Float; }
bool isPtrLike(const Type* t) { return t->kind == TypeKind::Ptr || t->kind == TypeKind::Array; }
bool isScalar(const Type* t) { return isArith(t) || isPtrLike(t); }
bool isStructLike(const Type* t) {
  return t->kind == TypeKind::Struct || t->kind == TypeKind::Union;
}
bool isUnsigned(const Type* t) {
  return t->kind == TypeKind::Char || t->kind == TypeKind::UInt || t->kind == TypeKind::ULong ||
         isPtrLike(t);
}

bool sameType(const Type* a, const Type* b) {
  if (a == b) return true;
  if (a->kind != b->kind) return false;
  switch (a->kind) {
    case TypeKind::Ptr:
      return sameType(a->base, b->base);
    case TypeKind::Array:
      return (a->arrayLen < 0 || b->arrayLen < 0 || a->arrayLen == b->arrayLen) &&
             sameType(a->base, b->base);
    case TypeKind::Struct:
    case TypeKind::Union:
      return false;  // distinct objects are distinct types
    case TypeKind::Func:
      if (!sameType(a->base, b->base)) return false;
      if (!a->hasProto || !b->hasProto) return true;
      if (a->params.size() != b->params.size()) return false;
      for (size_t i = 0; i < a->params.size(); ++i)
        if (!sameType(a->params[i].type, b->params[i].type)) return false;
      return true;
    default:
      return true;
  }
}

Slot slotOf(const Type* t) {
  switch (t->kind) {
    case TypeKind::Char:
    case TypeKind::SChar:
      return Slot::Byte;
    case TypeKind::Int:
    case TypeKind::UInt:
    case TypeKind::Ptr:
    case TypeKind::Array:
      return Slot::Word;
    case TypeKind::Long:
    case TypeKind::ULong:
      return Slot::Long;
    case TypeKind::Float:
      return Slot::Float;
    case TypeKind::Struct:
    case TypeKind::Union:
      return Slot::Struct;
    default:
      return Slot::None;
  }
}

std::string slotName(const Type* t) {
  switch (slotOf(t)) {
    case Slot::Byte:
    case Slot::Word:
      return "16-bit";
    case Slot::Long:
      return "32-bit";
    case Slot::Float:
      return "float";
    default:
      return typeName(t);
  }
}

std::string typeName(const Type* t) {
  switch (t->kind) {
    case TypeKind::Void:
      return "void";
    case TypeKind::Char:
      return "char";
    case TypeKind::SChar:
      return "signed char";
    case TypeKind::Int:
      return "int";
    case TypeKind::UInt:
      return "unsigned int";
    case TypeKind::Long:
      return "long";
    case TypeKind::ULong:
      return "unsigned long";
    case TypeKind::Float:
      return "float";
    case TypeKind::Ptr: {
      if (t->base->kind == TypeKind::Func) return typeName(t->base->base) + " (*)()";
      std::string b = typeName(t->base);
      return b + (b.back() == '*' ? "*" : " *");
    }
    case TypeKind::Array: {
      std::string dims;
      const Type* e = t;
      for (; e->kind == TypeKind::Array; e = e->base)
        dims += "[" + (e->arrayLen < 0 ? std::string() : std::to_string(e->arrayLen)) + "]";
      return typeName(e) + dims;
    }
    case TypeKind::Func:
      return typeName(t->base) + " ()";
    case TypeKind::Struct:
      return "struct " + (t->tag.empty() ? "<anonymous>" : t->tag);
    case TypeKind::Union:
      return "union " + (t->tag.empty() ? "<anonymous>" : t->tag);
  }
  return "?";
}

std::string typeCategory(const Type* t) {
  if (isPtrLike(t)) return "pointer";
  if (t->kind == TypeKind::Struct) return "struct";
  if (t->kind == TypeKind::Union) return "union";
  return typeName(t);
}

namespace detail {

// ===================================================================
// The type rules of expressions: conversions, constant folding, the
// checks of operands, pointer arithmetic, assignment. The parser builds
// every typed node through these.

Arith arithOf(const Type* t) {
  switch (t->kind) {
    case TypeKind::Char:
      return Arith::Char;
    case TypeKind::SChar:
      return Arith::SChar;
    case TypeKind::Int:
      return Arith::Int;
    case TypeKind::UInt:
      return Arith::UInt;
    case TypeKind::Long:
      return Arith::Long;
    case TypeKind::ULong:
      return Arith::ULong;
    default:
      return Arith::Float;
  }
}

Type* arithType(Arith a) {
  switch (a) {
    case Arith::Char:
      return tyChar();
    case Arith::SChar:
      return tySChar();
    case Arith::Int:
      return tyInt();
    case Arith::UInt:
      return tyUInt();
    case Arith::Long:
      return tyLong();
    case Arith::ULong:
      return tyULong();
    case Arith::Float:
      return tyFloat();
  }
  return tyInt();
}

int64_t wrapTo(int64_t v, const Type* t) {
  if (isInteger(t)) return wrapArith(v, arithOf(t));
  return wrapArith(v, Arith::UInt);  // pointers
}

Type* promote(Type* t) { return isInteger(t) ? arithType(promoteArith(arithOf(t))) : t; }

// The usual arithmetic conversions.
Type* commonType(Type* a, Type* b) { return arithType(commonArith(arithOf(a), arithOf(b))); }

const char* opSpelling(NodeKind k) {
  switch (k) {
    case NodeKind::Add:
      return "+";
    case NodeKind::Sub:
      return "-";
    case NodeKind::Mul:
      return "*";
    case NodeKind::Div:
      return "/";
    case NodeKind::Mod:
      return "%";
    case NodeKind::BitAnd:
      return "&";
    case NodeKind::BitOr:
      return "|";
    case NodeKind::BitXor:
      return "^";
    case NodeKind::Shl:
      return "<<";
    case NodeKind::Shr:
      return ">>";
    case NodeKind::Eq:
      return "==";
    case NodeKind::Ne:
      return "!=";
    case NodeKind::Lt:
      return "<";
    case NodeKind::Le:
      return "<=";
    case NodeKind::Gt:
      return ">";
    case NodeKind::Ge:
      return ">=";
    case NodeKind::LogAnd:
      return "&&";
    case NodeKind::LogOr:
      return "||";
    default:
      return "?";
  }
}

Node* Parser::value(Node* e) {
  if (e->type->kind == TypeKind::Void) fail(e->pos, "void value not ignored as it ought to be");
  return e;
}

Node* Parser::num(int64_t v, Type* ty, Pos pos) {
  Node* n = newNode(NodeKind::Num, pos, ty);
  n->ival = wrapTo(v, ty);
  return n;
}

Node* Parser::fnum(double v, Pos pos) {
  Node* n = newNode(NodeKind::FNum, pos, tyFloat());
  n->fval = static_cast<float>(v);
  return n;
}

// Conversion of `e` to `to`, folded when `e` is a constant.
Node* Parser::castTo(Node* e, Type* to, Pos pos) {
  Type* from = e->type;
  if (from == to || (from->kind == to->kind && from->kind != TypeKind::Array &&
                     from->kind != TypeKind::Ptr && !isStructLike(from)))
    return e;
  if (to->kind != TypeKind::Void) {
    if (e->kind == NodeKind::Num && (isInteger(to) || to->kind == TypeKind::Ptr))
      return num(e->ival, to, e->pos);
    if (e->kind == NodeKind::Num && to->kind == TypeKind::Float)
      return fnum(static_cast<double>(e->ival), e->pos);
    if (e->kind == NodeKind::FNum && isInteger(to))
      return num(floatToInteger(e->fval, arithOf(to)), to, e->pos);
  }
  Node* n = newNode(NodeKind::Cast, pos, to);
  n->lhs = e;
  n->depth = e->depth + 1;
  if (n->depth > kMaxTreeDepth) fail(pos, "expression too complex");
  return n;
}

Node* Parser::binary(NodeKind k, Node* l, Node* r, Pos pos, Type* ty) {
  if (Node* f = fold(k, l, r, pos, ty)) return f;
  Node* n = newNode(k, pos, ty);
  n->lhs = l;
  n->rhs = r;
  n->depth = std::max(l->depth, r->depth) + 1;
  if (n->depth > kMaxTreeDepth) fail(pos, "expression too complex");
  return n;
}

namespace {

// A comparison of two constants of the same (already converted) type,
// float or integer, as the robot's code compares them; none for an
// operator that is not a comparison.
template <class T>
std::optional<bool> compareConstants(NodeKind k, T a, T b) {
  switch (k) {
    case NodeKind::Eq:
      return a == b;
    case NodeKind::Ne:
      return a != b;
    case NodeKind::Lt:
      return a < b;
    case NodeKind::Le:
      return a <= b;
    case NodeKind::Gt:
      return a > b;
    case NodeKind::Ge:
      return a >= b;
    default:
      return std::nullopt;
  }
}

}  // namespace

// Constant folding, in the operands' (already converted) type.
Node* Parser::fold(NodeKind k, Node* l, Node* r, Pos pos, Type* ty) {
  if (!isConst(l) || !isConst(r)) return nullptr;
  if (k == NodeKind::LogAnd) return num(truthy(l) && truthy(r), tyInt(), pos);
  if (k == NodeKind::LogOr) return num(truthy(l) || truthy(r), tyInt(), pos);
  if (l->kind == NodeKind::FNum || r->kind == NodeKind::FNum) {
    if (l->kind != NodeKind::FNum || r->kind != NodeKind::FNum) return nullptr;
    float a = l->fval, b = r->fval;
    if (const auto c = compareConstants(k, a, b)) return num(*c, tyInt(), pos);
    switch (k) {
      case NodeKind::Add:
        return fnum(static_cast<float>(a + b), pos);
      case NodeKind::Sub:
        return fnum(static_cast<float>(a - b), pos);
      case NodeKind::Mul:
        return fnum(static_cast<float>(a * b), pos);
      case NodeKind::Div:
        if (b == 0) fail(pos, "division by zero in constant expression");
        return fnum(static_cast<float>(a / b), pos);
      default:
        return nullptr;
    }
  }
  int64_t a = l->ival, b = r->ival;
  if (const auto c = compareConstants(k, a, b)) return num(*c, tyInt(), pos);
  switch (k) {
    case NodeKind::Add:
      return num(a + b, ty, pos);
    case NodeKind::Sub:
      return num(a - b, ty, pos);
    case NodeKind::Mul:
      return num(static_cast<int64_t>(static_cast<uint64_t>(a) * static_cast<uint64_t>(b)), ty,
                 pos);
    case NodeKind::Div:
    case NodeKind::Mod:
      if (b == 0) fail(pos, "division by zero in constant expression");
      return num(
          k == NodeKind::Div ? divideArith(a, b, arithOf(ty)) : remainderArith(a, b, arithOf(ty)),
          ty, pos);
    case NodeKind::BitAnd:
      return num(a & b, ty, pos);
    case NodeKind::BitOr:
      return num(a | b, ty, pos);
    case NodeKind::BitXor:
      return num(a ^ b, ty, pos);
    case NodeKind::Shl:
      return num(shiftLeft(a, b, arithOf(ty)), ty, pos);
    case NodeKind::Shr:
      return num(shiftRight(a, b, arithOf(ty)), ty, pos);
    default:
      return nullptr;
  }
}

void Parser::badOperands(NodeKind k, Node* l, Node* r, Pos pos) {
  fail(pos, std::string("invalid operands to binary '") + opSpelling(k) + "' (" +
                typeCategory(l->type) + " and " + typeCategory(r->type) + ")");
}

// Arithmetic operators after the usual arithmetic conversions.
Node* Parser::arith(NodeKind k, Node* l, Node* r, Pos pos) {
  bool intOnly = k == NodeKind::Mod || k == NodeKind::BitAnd || k == NodeKind::BitOr ||
                 k == NodeKind::BitXor || k == NodeKind::Shl || k == NodeKind::Shr;
  if (!isArith(l->type) || !isArith(r->type) ||
      (intOnly && (!isInteger(l->type) || !isInteger(r->type))))
    badOperands(k, l, r, pos);
  if (k == NodeKind::Shl || k == NodeKind::Shr) {
    Type* t = promote(l->type);
    return binary(k, castTo(l, t, pos), castTo(r, tyInt(), pos), pos, t);
  }
  Type* t = commonType(l->type, r->type);
  return binary(k, castTo(l, t, pos), castTo(r, t, pos), pos, t);
}

// p + i, p - i: the index is scaled by the element size here.
Node* Parser::ptrOffset(NodeKind k, Node* p, Node* i, Pos pos) {
  Type* elem = p->type->base;
  if (elem->kind == TypeKind::Func) fail(pos, "arithmetic on a pointer to a function");
  if (isStructLike(elem) && !elem->complete)
    fail(pos, "arithmetic on a pointer to an incomplete type");
  int size = elem->kind == TypeKind::Void ? 1 : elem->size;
  Node* idx = castTo(i, tyInt(), pos);
  if (size != 1) idx = binary(NodeKind::Mul, idx, num(size, tyInt(), pos), pos, tyInt());
  Type* pt = p->type->kind == TypeKind::Ptr ? p->type : pointerTo(elem, pos);
  return binary(k, p, idx, pos, pt);
}

Node* Parser::newAdd(Node* l, Node* r, Pos pos) {
  value(l);
  value(r);
  if (isArith(l->type) && isArith(r->type)) return arith(NodeKind::Add, l, r, pos);
  if (isPtrLike(l->type) && isInteger(r->type)) return ptrOffset(NodeKind::Add, l, r, pos);
  if (isInteger(l->type) && isPtrLike(r->type)) return ptrOffset(NodeKind::Add, r, l, pos);
  badOperands(NodeKind::Add, l, r, pos);
}

Node* Parser::newSub(Node* l, Node* r, Pos pos) {
  value(l);
  value(r);
  if (isArith(l->type) && isArith(r->type)) return arith(NodeKind::Sub, l, r, pos);
  if (isPtrLike(l->type) && isInteger(r->type)) return ptrOffset(NodeKind::Sub, l, r, pos);
  if (isPtrLike(l->type) && isPtrLike(r->type)) {
    if (l->type->base->kind == TypeKind::Func || r->type->base->kind == TypeKind::Func)
      fail(pos, "arithmetic on a pointer to a function");
    int ls = l->type->base->kind == TypeKind::Void ? 1 : l->type->base->size;
    int rs = r->type->base->kind == TypeKind::Void ? 1 : r->type->base->size;
    if (ls != rs) badOperands(NodeKind::Sub, l, r, pos);
    Node* diff =
        binary(NodeKind::Sub, castTo(l, tyInt(), pos), castTo(r, tyInt(), pos), pos, tyInt());
    if (ls > 1) diff = binary(NodeKind::Div, diff, num(ls, tyInt(), pos), pos, tyInt());
    return diff;
  }
  badOperands(NodeKind::Sub, l, r, pos);
}

// An expression tested for truth: a scalar value. With `warnAssignment`,
// "if (x = 5)", an assignment as the whole condition, is warned about
// unless parenthesised as gcc's -Wparentheses accepts ("if ((c = next()))").
Node* Parser::condition(Node* e, bool warnAssignment) {
  value(e);
  if (warnAssignment && (e->kind == NodeKind::Assign || e->kind == NodeKind::OpAssign) &&
      !e->parenthesized)
    diags_.warn(e->pos, "parentheses",
                "assignment used as a condition; write '==' to compare, or put the assignment "
                "in parentheses");
  if (!isScalar(e->type)) fail(e->pos, "condition must have scalar type");
  return e;
}

// A comparison of an integer expression with a constant outside the range
// of the expression's type (ICEMAN's idiom "int i; for(i=0;i<50000;i++);":
// 50000 is a long, the int wraps at 32767, the loop never ends). Decided in
// the type the comparison is done in, and only when converting the
// expression to it keeps every value (an int compared as unsigned does not).
void Parser::checkTypeLimits(NodeKind k, const Node* l, const Node* r, Pos pos) {
  const bool constLeft = l->kind == NodeKind::Num;
  const Node* e = constLeft ? r : l;
  const Node* c = constLeft ? l : r;
  if (c->kind != NodeKind::Num || e->kind == NodeKind::Num || !isInteger(e->type) ||
      !isInteger(c->type))
    return;
  const auto range = [](const Type* t) -> std::pair<int64_t, int64_t> {
    switch (t->kind) {
      case TypeKind::Char:
        return {0, 0xFF};
      case TypeKind::SChar:
        return {-0x80, 0x7F};
      case TypeKind::Int:
        return {-0x8000, 0x7FFF};
      case TypeKind::UInt:
        return {0, 0xFFFF};
      case TypeKind::Long:
        return {-0x80000000LL, 0x7FFFFFFF};
      default:
        return {0, 0xFFFFFFFFLL};
    }
  };
  Type* common = commonType(promote(e->type), promote(c->type));
  auto [lo, hi] = range(e->type);
  auto [clo, chi] = range(common);
  if (lo < clo || hi > chi) return;  // the conversion changes some values
  const int64_t v = wrapTo(c->ival, common);
  // x OP v with x in [lo, hi]; a constant on the left mirrors the operator.
  NodeKind op = k;
  if (constLeft) {
    if (k == NodeKind::Lt) op = NodeKind::Gt;
    if (k == NodeKind::Gt) op = NodeKind::Lt;
    if (k == NodeKind::Le) op = NodeKind::Ge;
    if (k == NodeKind::Ge) op = NodeKind::Le;
  }
  int verdict = -1;  // -1 depends on x, 0 always false, 1 always true
  switch (op) {
    case NodeKind::Lt:
      verdict = hi < v ? 1 : lo >= v ? 0 : -1;
      break;
    case NodeKind::Le:
      verdict = hi <= v ? 1 : lo > v ? 0 : -1;
      break;
    case NodeKind::Gt:
      verdict = lo > v ? 1 : hi <= v ? 0 : -1;
      break;
    case NodeKind::Ge:
      verdict = lo >= v ? 1 : hi < v ? 0 : -1;
      break;
    case NodeKind::Eq:
      verdict = v < lo || v > hi ? 0 : -1;
      break;
    case NodeKind::Ne:
      verdict = v < lo || v > hi ? 1 : -1;
      break;
    default:
      break;
  }
  if (verdict < 0) return;
  diags_.warn(pos, "tautological-compare",
              fmt::format("comparison is always {}: a value of type '{}' lies in {}..{}",
                          verdict ? "true" : "false", typeName(e->type), lo, hi));
}

// Comparisons leave int 0/1; pointers compare unsigned.
Node* Parser::compare(NodeKind k, Node* l, Node* r, Pos pos) {
  value(l);
  value(r);
  if (isArith(l->type) && isArith(r->type)) {
    checkTypeLimits(k, l, r, pos);
    Type* t = commonType(l->type, r->type);
    return binary(k, castTo(l, t, pos), castTo(r, t, pos), pos, tyInt());
  }
  if ((isPtrLike(l->type) && (isPtrLike(r->type) || isInteger(r->type))) ||
      (isInteger(l->type) && isPtrLike(r->type))) {
    Type* pt = isPtrLike(l->type) ? l->type : r->type;
    if (pt->kind == TypeKind::Array) pt = pointerTo(pt->base, pos);
    return binary(k, castTo(l, pt, pos), castTo(r, pt, pos), pos, tyInt());
  }
  badOperands(k, l, r, pos);
}

Node* Parser::logical(NodeKind k, Node* l, Node* r, Pos pos) {
  value(l);
  value(r);
  if (!isScalar(l->type) || !isScalar(r->type)) badOperands(k, l, r, pos);
  return binary(k, l, r, pos, tyInt());
}

// The conversion as if by assignment (also arguments, returns, initialisers).
Node* Parser::assignConvert(Node* e, Type* ty, Pos pos, const std::string& context) {
  value(e);
  Type* from = e->type;
  if (isArith(ty) && isArith(from)) return castTo(e, ty, pos);
  if (ty->kind == TypeKind::Ptr && (isPtrLike(from) || isInteger(from))) {
    if (isInteger(from) && from->size == 4) e = castTo(e, tyUInt(), pos);
    return castTo(e, ty, pos);
  }
  if (isInteger(ty) && ty->size <= 2 && isPtrLike(from)) return castTo(e, ty, pos);
  if (isStructLike(ty) && from == ty) return e;
  std::string fromName =
      from->kind == TypeKind::Array ? typeName(from->base) + " *" : typeName(from);
  fail(pos, "incompatible types in " + context + " ('" + fromName + "' to '" + typeName(ty) + "')");
}

bool Parser::isLvalue(const Node* n) const {
  switch (n->kind) {
    case NodeKind::Var:
      return n->var->storage != Storage::Function;
    case NodeKind::Deref:
      return true;
    case NodeKind::Member:
      return isLvalue(n->lhs);
    default:
      return false;
  }
}

Node* Parser::newAssign(Node* l, Node* r, Pos pos) {
  if (!isLvalue(l) || l->type->kind == TypeKind::Array) fail(pos, "expression is not assignable");
  if (isStructLike(l->type) && !l->type->complete)
    incomplete(pos, l->type, "assignment to an incomplete type");
  Node* n = newNode(NodeKind::Assign, pos, l->type);
  n->lhs = l;
  n->rhs = assignConvert(r, l->type, pos, "assignment");
  n->depth = std::max(l->depth, n->rhs->depth) + 1;
  if (n->depth > kMaxTreeDepth) fail(pos, "expression too complex");
  return n;
}

Node* Parser::newOpAssign(NodeKind op, Node* l, Node* r, Pos pos) {
  if (!isLvalue(l) || l->type->kind == TypeKind::Array) fail(pos, "expression is not assignable");
  value(r);
  Node* n = newNode(NodeKind::OpAssign, pos, l->type);
  n->op = op;
  n->lhs = l;
  if ((op == NodeKind::Add || op == NodeKind::Sub) && l->type->kind == TypeKind::Ptr) {
    if (!isInteger(r->type)) badOperands(op, l, r, pos);
    Type* elem = l->type->base;
    if (elem->kind == TypeKind::Func) fail(pos, "arithmetic on a pointer to a function");
    int size = elem->kind == TypeKind::Void ? 1 : elem->size;
    Node* idx = castTo(r, tyInt(), pos);
    if (size != 1) idx = binary(NodeKind::Mul, idx, num(size, tyInt(), pos), pos, tyInt());
    n->rhs = idx;
    n->opType = l->type;
  } else {
    bool intOnly = op == NodeKind::Mod || op == NodeKind::BitAnd || op == NodeKind::BitOr ||
                   op == NodeKind::BitXor || op == NodeKind::Shl || op == NodeKind::Shr;
    if (!isArith(l->type) || !isArith(r->type) ||
        (intOnly && (!isInteger(l->type) || !isInteger(r->type))))
      badOperands(op, l, r, pos);
    if (op == NodeKind::Shl || op == NodeKind::Shr) {
      n->opType = promote(l->type);
      n->rhs = castTo(r, tyInt(), pos);
    } else {
      n->opType = commonType(l->type, r->type);
      n->rhs = castTo(r, n->opType, pos);
    }
  }
  n->depth = std::max(l->depth, n->rhs->depth) + 1;
  if (n->depth > kMaxTreeDepth) fail(pos, "expression too complex");
  return n;
}

Node* Parser::newIncDec(Node* e, int delta, bool prefix, Pos pos) {
  if (!isLvalue(e) || !isScalar(e->type) || e->type->kind == TypeKind::Array)
    fail(pos, "expression is not assignable");
  Node* n = newNode(NodeKind::IncDec, pos, e->type);
  n->lhs = e;
  n->prefix = prefix;
  if (e->type->kind == TypeKind::Ptr) {
    Type* elem = e->type->base;
    if (elem->kind == TypeKind::Func) fail(pos, "arithmetic on a pointer to a function");
    if (isStructLike(elem) && !elem->complete)
      fail(pos, "arithmetic on a pointer to an incomplete type");
    delta *= elem->kind == TypeKind::Void ? 1 : elem->size;
  }
  n->delta = delta;
  n->depth = e->depth + 1;
  return n;
}

Node* Parser::newDeref(Node* e, Pos pos) {
  value(e);
  if (!isPtrLike(e->type))
    fail(pos, "cannot dereference a non-pointer ('" + typeName(e->type) + "')");
  Type* base = e->type->base;
  if (base->kind == TypeKind::Func) {
    // *fp designates the function, which is converted straight back to its
    // address (C89 3.3.3.2, 3.2.2.1): (*fp)(x) calls fp. An rvalue, so
    // "*fp = g" is not an assignment to fp.
    Node* n = newNode(NodeKind::Cast, pos, e->type);
    n->lhs = e;
    n->depth = e->depth + 1;
    if (n->depth > kMaxTreeDepth) fail(pos, "expression too complex");
    return n;
  }
  if (base->kind == TypeKind::Void) fail(pos, "dereferencing a 'void *' pointer");
  Node* n = newNode(NodeKind::Deref, pos, base);
  n->lhs = e;
  n->depth = e->depth + 1;
  if (n->depth > kMaxTreeDepth) fail(pos, "expression too complex");
  return n;
}

Node* Parser::newAddr(Node* e, Pos pos) {
  if (e->kind == NodeKind::Var && e->var->isRegister)
    fail(pos, "cannot take the address of a register variable '" + e->var->name + "'");
  if (!isLvalue(e) && e->kind != NodeKind::Str) fail(pos, "cannot take the address of an rvalue");
  Node* n = newNode(NodeKind::Addr, pos, pointerTo(e->type, pos));
  n->lhs = e;
  n->depth = e->depth + 1;
  return n;
}

Node* Parser::member(Node* base, const Token& name, Pos pos) {
  Type* t = base->type;
  if (!isStructLike(t))
    fail(pos, "member reference base type '" + typeName(t) + "' is not a struct or union");
  if (!t->complete) incomplete(pos, t, "incomplete definition of type '" + typeName(t) + "'");
  if (name.kind != TokKind::Ident) fail(name.pos, "expected member name");
  for (const Member& m : t->members) {
    if (m.name == name.text) {
      Node* n = newNode(NodeKind::Member, name.pos, m.type);
      n->lhs = base;
      n->offset = m.offset;
      n->str = m.name;
      n->depth = base->depth + 1;
      return n;
    }
  }
  fail(name.pos, "no member named '" + name.text + "' in '" + typeName(t) + "'");
}

}  // namespace detail

}  // namespace simbot::compiler
