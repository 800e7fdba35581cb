// compiler/parse_expr.cpp -- the parser's expressions (parser_impl.h): one
// function per precedence level down to the binary operators, which a
// table drives, then casts, unary and postfix operators, primaries and
// calls.
#include "compiler/parser_impl.h"

namespace simbot::compiler::detail {

// expr = assign ("," assign)*
Node* Parser::expr() {
  Node* n = assign();
  while (is(",")) {
    Pos pos = cur().pos;
    advance();
    Node* r = assign();
    Node* c = newNode(NodeKind::Comma, pos, r->type);
    c->lhs = n;
    c->rhs = r;
    c->depth = std::max(n->depth, r->depth) + 1;
    if (c->depth > kMaxTreeDepth) fail(pos, "expression too complex");
    n = c;
  }
  return n;
}

// assign = conditional (assign-op assign)?
// assign-op = "=" | "+=" | "-=" | "*=" | "/=" | "%=" | "&=" | "|=" | "^=" | "<<=" | ">>="
Node* Parser::assign() {
  Node* l = conditional();
  const Token& t = cur();
  if (t.kind != TokKind::Punct) return l;
  Pos pos = t.pos;
  static const std::pair<std::string_view, NodeKind> ops[] = {
      {"+=", NodeKind::Add},   {"-=", NodeKind::Sub},    {"*=", NodeKind::Mul},
      {"/=", NodeKind::Div},   {"%=", NodeKind::Mod},    {"&=", NodeKind::BitAnd},
      {"|=", NodeKind::BitOr}, {"^=", NodeKind::BitXor}, {"<<=", NodeKind::Shl},
      {">>=", NodeKind::Shr}};
  if (t.text == "=") {
    advance();
    DepthGuard guard(*this);
    return newAssign(l, assign(), pos);
  }
  for (auto [s, k] : ops) {
    if (t.text == s) {
      advance();
      DepthGuard guard(*this);
      return newOpAssign(k, l, assign(), pos);
    }
  }
  return l;
}

// The binary operators, loosest first; all associate to the left. The
// grammar this table stands for, one rule per level:
//   log-or         = log-and ("||" log-and)*
//   log-and        = bit-or ("&&" bit-or)*
//   bit-or         = bit-xor ("|" bit-xor)*
//   bit-xor        = bit-and ("^" bit-and)*
//   bit-and        = equality ("&" equality)*
//   equality       = relational (("==" | "!=") relational)*
//   relational     = shift (("<" | "<=" | ">" | ">=") shift)*
//   shift          = additive (("<<" | ">>") additive)*
//   additive       = multiplicative (("+" | "-") multiplicative)*
//   multiplicative = cast (("*" | "/" | "%") cast)*
namespace {

struct BinaryOperator {
  std::string_view spelling;
  NodeKind kind;
  int precedence;  // 1 binds loosest
};
constexpr BinaryOperator kBinaryOperators[] = {
    {"||", NodeKind::LogOr, 1}, {"&&", NodeKind::LogAnd, 2}, {"|", NodeKind::BitOr, 3},
    {"^", NodeKind::BitXor, 4}, {"&", NodeKind::BitAnd, 5},  {"==", NodeKind::Eq, 6},
    {"!=", NodeKind::Ne, 6},    {"<", NodeKind::Lt, 7},      {"<=", NodeKind::Le, 7},
    {">", NodeKind::Gt, 7},     {">=", NodeKind::Ge, 7},     {"<<", NodeKind::Shl, 8},
    {">>", NodeKind::Shr, 8},   {"+", NodeKind::Add, 9},     {"-", NodeKind::Sub, 9},
    {"*", NodeKind::Mul, 10},   {"/", NodeKind::Div, 10},    {"%", NodeKind::Mod, 10}};
constexpr int kLoosestBinary = 1;

}  // namespace

// conditional = binary ("?" expr ":" conditional)?
Node* Parser::conditional() {
  Node* c = binaryExpr(kLoosestBinary);
  if (!is("?")) return c;
  Pos pos = cur().pos;
  advance();
  DepthGuard guard(*this);
  c = condition(c);
  Node* a = expr();
  expect(":");
  Node* b = conditional();
  Type* t;
  if (isArith(a->type) && isArith(b->type)) {
    t = commonType(a->type, b->type);
    a = castTo(a, t, pos);
    b = castTo(b, t, pos);
  } else if (isPtrLike(a->type) && (isPtrLike(b->type) || b->kind == NodeKind::Num)) {
    t = a->type->kind == TypeKind::Array ? pointerTo(a->type->base, pos) : a->type;
    a = castTo(a, t, pos);
    b = castTo(b, t, pos);
  } else if (isPtrLike(b->type) && a->kind == NodeKind::Num) {
    t = b->type->kind == TypeKind::Array ? pointerTo(b->type->base, pos) : b->type;
    a = castTo(a, t, pos);
    b = castTo(b, t, pos);
  } else if (a->type->kind == TypeKind::Void && b->type->kind == TypeKind::Void) {
    t = tyVoid();
  } else if (isStructLike(a->type) && a->type == b->type) {
    t = a->type;
  } else {
    fail(pos, "type mismatch in conditional expression ('" + typeName(a->type) + "' and '" +
                  typeName(b->type) + "')");
  }
  if (isConst(c)) return truthy(c) ? a : b;
  Node* n = newNode(NodeKind::Cond, pos, t);
  n->cond = c;
  n->lhs = a;
  n->rhs = b;
  n->depth = std::max({c->depth, a->depth, b->depth}) + 1;
  if (n->depth > kMaxTreeDepth) fail(pos, "expression too complex");
  return n;
}

// binary = cast (binary-operator cast)*, grouped by the table's precedences
// (precedence climbing): the operands of an operator of precedence p bind
// tighter than p.
Node* Parser::binaryExpr(int minPrecedence) {
  Node* n = cast();
  for (;;) {
    const BinaryOperator* op = nullptr;
    if (cur().kind == TokKind::Punct)
      for (const BinaryOperator& o : kBinaryOperators)
        if (cur().text == o.spelling) op = &o;
    if (!op || op->precedence < minPrecedence) return n;
    const Pos pos = cur().pos;
    advance();
    Node* r = binaryExpr(op->precedence + 1);
    switch (op->kind) {
      case NodeKind::LogOr:
      case NodeKind::LogAnd:
        n = logical(op->kind, n, r, pos);
        break;
      case NodeKind::Eq:
      case NodeKind::Ne:
      case NodeKind::Lt:
      case NodeKind::Le:
      case NodeKind::Gt:
      case NodeKind::Ge:
        n = compare(op->kind, n, r, pos);
        break;
      case NodeKind::Add:
        n = newAdd(n, r, pos);
        break;
      case NodeKind::Sub:
        n = newSub(n, r, pos);
        break;
      default:  // | ^ & << >> * / %
        n = arith(op->kind, value(n), value(r), pos);
        break;
    }
  }
}

// cast = "(" type-name ")" cast | unary
Node* Parser::cast() {
  if (is("(") && isDeclStart(peek(1))) {
    DepthGuard guard(*this);
    Pos pos = cur().pos;
    advance();
    Type* t = abstractTypeName();
    expect(")");
    if (is("{")) fail(cur().pos, "compound literals are not supported");
    Node* e = cast();
    if (t->kind == TypeKind::Void) {
      Node* n = newNode(NodeKind::Cast, pos, tyVoid());
      n->lhs = e;
      n->depth = e->depth + 1;
      return n;
    }
    value(e);
    if (!isScalar(t)) fail(pos, "cannot cast to '" + typeName(t) + "'");
    if (!isScalar(e->type))
      fail(pos, "cannot cast '" + typeName(e->type) + "' to '" + typeName(t) + "'");
    if ((t->kind == TypeKind::Float && isPtrLike(e->type)) ||
        (isPtrLike(t) && e->type->kind == TypeKind::Float))
      fail(pos, "cannot cast between a pointer and a float");
    if (t->kind == TypeKind::Array) fail(pos, "cannot cast to an array type");
    if (t->kind == TypeKind::Ptr && isInteger(e->type) && e->type->size == 4)
      e = castTo(e, tyUInt(), pos);
    Node* c = castTo(e, t, pos);
    if (c == e && e->type != t) {  // same kind, different pointer type: retype
      c = newNode(NodeKind::Cast, pos, t);
      c->lhs = e;
      c->depth = e->depth + 1;
    }
    return c;
  }
  return unary();
}

// unary = ("+" | "-" | "!" | "~" | "*" | "&") cast
//       | ("++" | "--") unary
//       | "sizeof" "(" type-name ")" | "sizeof" unary
//       | postfix
Node* Parser::unary() {
  const Token& t = cur();
  Pos pos = t.pos;
  static const std::unordered_set<std::string_view> prefixOps = {"+", "-",  "!",  "~",     "*",
                                                                 "&", "++", "--", "sizeof"};
  if (!(t.kind == TokKind::Punct || t.kind == TokKind::Ident) || !prefixOps.count(t.text))
    return postfix();
  DepthGuard guard(*this);
  if (accept("+")) {
    Node* e = value(cast());
    if (!isArith(e->type))
      fail(pos, "invalid argument type '" + typeName(e->type) + "' to unary '+'");
    return castTo(e, promote(e->type), pos);
  }
  if (accept("-")) {
    Node* e = value(cast());
    if (!isArith(e->type))
      fail(pos, "invalid argument type '" + typeName(e->type) + "' to unary '-'");
    Type* ty = promote(e->type);
    e = castTo(e, ty, pos);
    if (e->kind == NodeKind::Num) return num(-e->ival, ty, pos);
    if (e->kind == NodeKind::FNum) return fnum(-e->fval, pos);
    Node* n = newNode(NodeKind::Neg, pos, ty);
    n->lhs = e;
    n->depth = e->depth + 1;
    return n;
  }
  if (accept("!")) {
    Node* e = value(cast());
    if (!isScalar(e->type))
      fail(pos, "invalid argument type '" + typeName(e->type) + "' to unary '!'");
    if (isConst(e)) return num(!truthy(e), tyInt(), pos);
    Node* n = newNode(NodeKind::Not, pos, tyInt());
    n->lhs = e;
    n->depth = e->depth + 1;
    return n;
  }
  if (accept("~")) {
    Node* e = value(cast());
    if (!isInteger(e->type))
      fail(pos, "invalid argument type '" + typeName(e->type) + "' to unary '~'");
    Type* ty = promote(e->type);
    e = castTo(e, ty, pos);
    if (e->kind == NodeKind::Num) return num(~e->ival, ty, pos);
    Node* n = newNode(NodeKind::BitNot, pos, ty);
    n->lhs = e;
    n->depth = e->depth + 1;
    return n;
  }
  if (accept("*")) return newDeref(cast(), pos);
  if (accept("&")) {
    Node* e = cast();
    if (e->kind == NodeKind::FuncRef) return e;  // &f is f's address, as f is
    return newAddr(e, pos);
  }
  if (accept("++")) return newIncDec(unary(), 1, true, pos);
  if (accept("--")) return newIncDec(unary(), -1, true, pos);
  if (accept("sizeof")) {
    Type* ty;
    if (is("(") && isDeclStart(peek(1))) {
      advance();
      ty = abstractTypeName();
      expect(")");
    } else {
      ty = unary()->type;
    }
    if (ty->kind == TypeKind::Void || ty->kind == TypeKind::Func ||
        (isStructLike(ty) && !ty->complete) || (ty->kind == TypeKind::Array && ty->arrayLen < 0))
      incomplete(pos, ty,
                 "invalid application of 'sizeof' to an incomplete type '" + typeName(ty) + "'");
    return num(ty->size, tyUInt(), pos);
  }
  return postfix();
}

// postfix = primary ("[" expr "]" | "." ident | "->" ident | "++" | "--")*
Node* Parser::postfix() {
  Node* n = primary();
  for (;;) {
    const Token& t = cur();
    Pos pos = t.pos;
    if (t.is("[")) {
      DepthGuard guard(*this);
      advance();
      Node* idx = expr();
      expect("]");
      value(n);
      value(idx);
      if (!(isPtrLike(n->type) && isInteger(idx->type)) &&
          !(isInteger(n->type) && isPtrLike(idx->type)))
        fail(pos, isPtrLike(n->type) ? "array subscript is not an integer"
                                     : "subscripted value is not an array or pointer");
      n = newDeref(newAdd(n, idx, pos), pos);
    } else if (t.is(".")) {
      advance();
      Token name = cur();
      advance();
      n = member(n, name, pos);
    } else if (t.is("->")) {
      advance();
      Token name = cur();
      advance();
      if (!isPtrLike(n->type) || !isStructLike(n->type->base))
        fail(pos, "member reference type '" + typeName(n->type) + "' is not a pointer to a struct");
      n = member(newDeref(n, pos), name, pos);
    } else if (t.is("++")) {
      advance();
      n = newIncDec(n, 1, false, pos);
    } else if (t.is("--")) {
      advance();
      n = newIncDec(n, -1, false, pos);
    } else if (t.is("(")) {
      // (f)(x), (*f)(x), (&f)(x): a direct call; anything else of
      // pointer-to-function type is called through.
      Node* target = n;
      while (target->kind == NodeKind::Cast && target->type == target->lhs->type)
        target = target->lhs;
      if (target->kind == NodeKind::FuncRef) {
        Token nameTok = t;
        nameTok.text = target->callee->name;
        nameTok.pos = n->pos;
        n = funcall(nameTok, target->callee);
      } else {
        value(n);
        if (n->type->kind != TypeKind::Ptr || n->type->base->kind != TypeKind::Func)
          fail(pos, "called object of type '" + typeName(n->type) + "' is not a function");
        n = callThrough(n, pos);
      }
    } else {
      return n;
    }
  }
}

// primary = "(" expr ")" | ident | ident "(" args ")" | number | char | string+
Node* Parser::primary() {
  const Token& t = cur();
  Pos pos = t.pos;
  switch (t.kind) {
    case TokKind::Punct:
      if (t.is("(")) {
        DepthGuard guard(*this);
        advance();
        Node* e = expr();
        expect(")");
        e->parenthesized = true;
        return e;
      }
      fail(pos, "expected expression");
    case TokKind::Eof:
      fail(after(prevPos_), "expected expression at end of input");
    case TokKind::Number: {
      NumberValue v = parseNumber(t);
      advance();
      if (v.isFloat) return fnum(v.fvalue, pos);
      const uint64_t x = v.value;
      Type* ty = arithType(constantArith(x, v.decimal, v.suffixU, v.suffixL));
      return num(static_cast<int64_t>(x), ty, pos);
    }
    case TokKind::Char: {
      if (t.str.empty()) fail(pos, "empty character constant");
      if (t.str.size() > 1) fail(pos, "multi-character character constant");
      int v = static_cast<unsigned char>(t.str[0]);
      advance();
      return num(v, tyInt(), pos);
    }
    case TokKind::String: {
      std::string s;
      while (cur().kind == TokKind::String) {
        s += cur().str;
        advance();
      }
      if (s.size() >= 0xFFFF) fail(pos, "string literal is too long");
      Node* n = newNode(NodeKind::Str, pos, arrayOf(tyChar(), static_cast<int>(s.size()) + 1, pos));
      n->str = std::move(s);
      return n;
    }
    case TokKind::Ident:
      break;
    default:
      fail(pos, "expected expression");
  }
  if (t.is("wfd") || t.is("waitfordone")) notSupported(t);
  if (isKeyword(t)) {
    if (isDeclStart(t)) fail(pos, "unexpected type name '" + t.text + "'");
    fail(pos, "expected expression before '" + t.text + "'");
  }
  Token nameTok = t;
  advance();
  ScopeEntry* e = findVar(nameTok.text);
  if (e) {
    if (e->typeDef) fail(pos, "unexpected type name '" + nameTok.text + "'");
    if (e->isConst) return num(e->value, tyInt(), pos);
    Obj* o = e->var;
    if (o->storage == Storage::Function)
      return is("(") ? funcall(nameTok, o->fn) : funcRef(o->fn, pos);
    Node* n = newNode(NodeKind::Var, pos, o->type);
    n->var = o;
    if (is("(") && !(o->type->kind == TypeKind::Ptr && o->type->base->kind == TypeKind::Func))
      fail(cur().pos, "called object '" + nameTok.text + "' is not a function");
    if (o->biosTimer) useTimer();
    return n;
  }
  if (is("(")) {
    if (nameTok.text == "EI" || nameTok.text == "DI") {
      advance();
      if (!is(")"))
        fail(cur().pos, "too many arguments to function '" + nameTok.text + "' (expected 0)");
      advance();
      Node* n = newNode(NodeKind::Intrinsic, pos, tyVoid());
      n->lib = nameTok.text == "EI" ? 0 : 1;
      return n;
    }
    if (const int lib = library(nameTok.text); lib >= 0) return libcall(nameTok, lib);
    // K&R: an undeclared function is "int f()".
    Declarator d;
    d.name = nameTok.text;
    d.pos = pos;
    d.hasName = true;
    d.type = newType(TypeKind::Func, 1);
    d.type->base = tyInt();
    Function* f = declareFunction(d, VarAttr{});
    f->implicit = true;
    if (!poisoned_.count(nameTok.text))
      diags_.warn(pos, "implicit-function-declaration",
                  "implicit declaration of function '" + nameTok.text + "' (taken as 'int " +
                      nameTok.text + "()'; declare it before this call)");
    return funcall(nameTok, f);
  }
  if (library(nameTok.text) >= 0)
    fail(pos, "library routine '" + nameTok.text +
                  "' has no address in simbot (it is built into the VM); call it from a "
                  "function of your own and take that one's address");
  undeclared(pos, nameTok.text, "undeclared identifier '" + nameTok.text + "'");
}

// funcall = ident "(" (assign ("," assign)*)? ")"
Node* Parser::funcall(const Token& nameTok, Function* f) {
  Pos pos = nameTok.pos;
  if (f->isHandler) fail(pos, "cannot call interrupt function '" + f->name + "'");
  DepthGuard guard(*this);
  Node* n = newNode(NodeKind::Call, pos, f->type->base);
  n->callee = f;
  callArguments(n);
  Type* ft = f->type;
  if (ft->hasProto) {
    checkCallAgainstDefinition(f, n, false);  // counts; arguments are converted below
  }
  convertArguments(n, ft, "'" + f->name + "'");
  if (!ft->hasProto) f->uncheckedCalls.push_back(n);
  if (!f->called) {
    f->called = true;
    f->firstCall = pos;
  }
  return n;
}

// call-through = postfix "(" (assign ("," assign)*)? ")"   (postfix: a
// pointer to a function). The callee is known only at run time: the VM
// checks that the address is a function's first instruction and that it
// takes as many arguments as were passed (a fault of the robot if not).
Node* Parser::callThrough(Node* fp, Pos pos) {
  DepthGuard guard(*this);
  Type* ft = fp->type->base;
  Node* n = newNode(NodeKind::Call, pos, ft->base);
  n->lhs = fp;
  n->depth = fp->depth + 1;
  callArguments(n);
  if (ft->hasProto && n->list.size() != ft->params.size())
    fail(pos, fmt::format("too {} arguments in a call through '{}' (expected {}, got {})",
                          n->list.size() > ft->params.size() ? "many" : "few", typeName(fp->type),
                          ft->params.size(), n->list.size()));
  if (n->list.size() > kMaxParameters)
    fail(pos, fmt::format("too many arguments (at most {})", kMaxParameters));
  convertArguments(n, ft, "the call through '" + typeName(fp->type) + "'");
  if (n->depth > kMaxTreeDepth) fail(pos, "expression too complex");
  return n;
}

// A function designator not called: its address (C89 3.2.2.1).
Node* Parser::funcRef(Function* f, Pos pos) {
  if (f->isHandler)
    fail(pos, "cannot take the address of interrupt function '" + f->name +
                  "' (it returns with RETI; bind it to a vector with #INT_VEC)");
  Node* n = newNode(NodeKind::FuncRef, pos, pointerTo(f->type, pos));
  n->callee = f;
  if (!f->addressTaken) {  // an interrupt function defined later is refused there
    f->addressTaken = true;
    f->addressPos = pos;
  }
  if (!f->called) {  // it must be defined, as a called one must
    f->called = true;
    f->firstCall = pos;
  }
  return n;
}

// "(" (assign ("," assign)*)? ")" into n->list, with each one's position.
void Parser::callArguments(Node* n) {
  advance();  // "("
  if (accept(")")) return;
  for (;;) {
    n->argPos.push_back(cur().pos);
    n->list.push_back(assign());
    if (accept(")")) return;
    if (cur().kind == TokKind::Eof) fail(after(prevPos_), "expected ')' at end of input");
    expect(",");
  }
}

// Each argument as if assigned to its parameter (a prototype), or with the
// default promotions (none).
void Parser::convertArguments(Node* n, Type* ft, const std::string& to) {
  for (size_t i = 0; i < n->list.size(); ++i) {
    Node* a = value(n->list[i]);
    if (ft->hasProto) {
      n->list[i] = assignConvert(a, ft->params[i].type, n->argPos[i],
                                 "argument " + std::to_string(i + 1) + " to " + to);
    } else {
      if (isStructLike(a->type)) fail(n->argPos[i], "passing a struct by value is not supported");
      if (a->type->kind == TypeKind::Array)
        a = castTo(a, pointerTo(a->type->base, n->argPos[i]), n->argPos[i]);
      n->list[i] = castTo(a, promote(a->type), n->argPos[i]);
    }
    n->depth = std::max(n->depth, n->list[i]->depth + 1);
  }
}

// libcall = builtin-name "(" (assign ("," assign)*)? ")"
// Arguments are converted to the routine's type letters (builtins.def).
Node* Parser::libcall(const Token& nameTok, int lib) {
  const vm::LibInfo& info = vm::kLibInfo[lib];
  Pos pos = nameTok.pos;
  DepthGuard guard(*this);
  advance();  // "("
  std::vector<Node*> args;
  std::vector<Pos> argPos;
  if (!accept(")")) {
    for (;;) {
      argPos.push_back(cur().pos);
      args.push_back(assign());
      if (accept(")")) break;
      if (cur().kind == TokKind::Eof) fail(after(prevPos_), "expected ')' at end of input");
      expect(",");
    }
  }
  std::string_view letters = info.args;
  bool variadic = !letters.empty() && letters.back() == '.';
  if (variadic) letters.remove_suffix(1);
  std::string name(info.name);
  // Dynamic C's firsttime functions take the enclosing costatement's CoData
  // as a hidden first argument.
  const bool firsttime = lib == static_cast<int>(vm::Lib::DELAYMS) ||
                         lib == static_cast<int>(vm::Lib::DELAYSEC) ||
                         lib == static_cast<int>(vm::Lib::DELAYTICKS);
  Node* hidden = nullptr;
  if (firsttime) {
    if (costates_.empty())
      fail(pos, "'" + name + "' is used inside a costatement, as in 'waitfor(" + name + "(...));'");
    Node* cd = newNode(NodeKind::Var, pos, coDataType_);
    cd->var = costates_.back()->var;
    hidden = newAddr(cd, pos);
    letters.remove_prefix(1);
    useTimer();
  }
  if (args.size() > letters.size() && !variadic)
    fail(pos, "too many arguments to function '" + name + "' (expected " +
                  std::to_string(letters.size()) + ", got " + std::to_string(args.size()) + ")");
  if (args.size() < letters.size())
    fail(pos, "too few arguments to function '" + name + "' (expected " +
                  std::string(variadic ? "at least " : "") + std::to_string(letters.size()) +
                  ", got " + std::to_string(args.size()) + ")");
  Node* n = newNode(NodeKind::LibCall, pos);
  n->lib = lib;
  if (hidden) {
    n->list.push_back(hidden);
    n->argPos.push_back(pos);
  }
  for (size_t i = 0; i < args.size(); ++i) {
    Node* a = value(args[i]);
    Pos ap = argPos[i];
    std::string what = "argument " + std::to_string(i + 1) + " to '" + name + "'";
    const char letter = i < letters.size() ? letters[i] : '.';
    auto bad = [&]() {
      fail(ap, "incompatible type for " + what + " ('" + typeName(a->type) + "')");
    };
    switch (letter) {
      case 'i':
        if (!isScalar(a->type)) bad();
        a = assignConvert(a, tyInt(), ap, what);
        break;
      case 'u':
        if (!isScalar(a->type)) bad();
        a = assignConvert(a, tyUInt(), ap, what);
        break;
      case 'c':
        if (!isArith(a->type)) bad();
        a = castTo(castTo(a, tyChar(), ap), tyInt(), ap);
        break;
      case 'l':
        if (!isArith(a->type)) bad();
        a = castTo(a, tyLong(), ap);
        break;
      case 'f':
        if (!isArith(a->type)) bad();
        a = castTo(a, tyFloat(), ap);
        break;
      case 'p':
        if (!(isPtrLike(a->type) || (isInteger(a->type) && a->type->size <= 2))) bad();
        if (a->type->kind == TypeKind::Array) a = castTo(a, pointerTo(a->type->base, ap), ap);
        break;
      default:  // variadic extras: promoted
        if (isStructLike(a->type)) bad();
        if (a->type->kind == TypeKind::Array) a = castTo(a, pointerTo(a->type->base, ap), ap);
        a = castTo(a, promote(a->type), ap);
        break;
    }
    n->list.push_back(a);
    n->argPos.push_back(ap);
    n->depth = std::max(n->depth, a->depth + 1);
  }
  switch (info.result) {
    case 'v':
      n->type = tyVoid();
      break;
    case 'i':
      n->type = tyInt();
      break;
    case 'u':
      n->type = tyUInt();
      break;
    case 'c':
      n->type = tyChar();
      break;
    case 'l':
      n->type = tyLong();
      break;
    case 'f':
      n->type = tyFloat();
      break;
    default:
      n->type = pointerTo(tyChar(), pos);
      break;
  }
  return n;
}

// const-expr = conditional, which must fold to an integer constant
int64_t Parser::constExpr(Type** type) {
  Pos pos = cur().pos;
  Node* n = conditional();
  if (n->kind != NodeKind::Num) fail(pos, "expression is not an integer constant");
  if (type) *type = n->type;
  return n->ival;
}

}  // namespace simbot::compiler::detail
