// inspect/eval.cpp -- evaluating a debugger expression's tree against a
// Scope, as the robot's code would compute it: C89's conversions with
// Dynamic C's sizes (compiler/arith.h, the rules the compiler types its
// code by), pointer arithmetic in 16-bit addresses, the VM's shifts and
// divisions. Memory is read through the VM and never written.
//
// An operand C does not evaluate (sizeof's, the arm of ?: not taken, the
// right of && or || once the left decides) is still typed, with its
// values unknown (Value::known), so it is checked but cannot fail by its
// values: `n ? 100 / n : 0` with n 0 is 0.
#include <fmt/format.h>

#include "inspect/inspect.h"
#include "inspect/names.h"
#include "inspect/tree.h"
#include "inspect/types.h"

namespace simbot::inspect {

using vm::TypeInfo;

namespace {

Value anyValue() {
  Value v;
  v.anyType = true;
  v.known = false;
  return v;
}

bool isZero(const Scope& s, const Value& rv) {
  if (!rv.known || classOf(s, rv) != Class::Arithmetic) return false;
  return arithOfValue(s, rv) == Arith::Float ? rv.real == 0 : rv.integer == 0;
}

bool isInteger(const Scope& s, const Value& rv) {
  return classOf(s, rv) == Class::Arithmetic && arithOfValue(s, rv) != Arith::Float;
}

bool isScalar(Class c) { return c == Class::Arithmetic || c == Class::Pointer || c == Class::Any; }

// An arithmetic value converted to another arithmetic type.
Value convert(const Scope& s, const Value& rv, Arith to) {
  const Arith from = arithOfValue(s, rv);
  Value out = to == Arith::Float ? floatValue(s.image(), 0) : integerValue(s.image(), to, 0);
  if (!rv.known) return unknownOf(out);
  if (to == Arith::Float)
    out.real = from == Arith::Float ? rv.real : static_cast<float>(rv.integer);
  else
    out.integer = from == Arith::Float ? compiler::floatToInteger(rv.real, to)
                                       : compiler::wrapArith(rv.integer, to);
  return out;
}

// The size of what a pointer points at, for its arithmetic (void's is 1,
// as the compiler takes it).
int64_t elementSize(const Scope& s, int32_t pointee) {
  const TypeInfo& t = typeOf(s.image(), pointee);
  if (t.kind == TypeInfo::Kind::Function) throw Error("arithmetic on a pointer to a function");
  if (t.kind == TypeInfo::Kind::Void) return 1;
  if (t.size == 0)
    throw Error(fmt::format("arithmetic on a pointer to an incomplete '{}'", t.name));
  return t.size;
}

// The object a pointer value points at.
Value target(const Scope& s, const Value& pointer, const char* op) {
  const TypeInfo& t = typeOf(s.image(), pointer.pointee);
  if (t.kind == TypeInfo::Kind::Void)
    throw Error(fmt::format("'{}' of a void pointer (cast it to a type first)", op));
  if (t.kind == TypeInfo::Kind::Function)
    throw Error(fmt::format("'{}' of a function pointer", op));
  Value v;
  v.type = pointer.pointee;
  v.inMemory = true;
  v.address = static_cast<uint16_t>(pointer.integer);
  v.known = pointer.known;
  return v;
}

Value member(const Scope& s, const Value& v, const std::string& name, const char* op) {
  if (v.anyType) return v;
  if (!v.inMemory || v.count > 0)
    throw Error(fmt::format("'{}{}' of a {}, not a struct or union", op, name, category(s, v)));
  const TypeInfo& t = typeOf(s.image(), v.type);
  if (t.kind != TypeInfo::Kind::Struct && t.kind != TypeInfo::Kind::Union)
    throw Error(fmt::format("'{}{}' of a {}, not a struct or union", op, name, t.name));
  for (const TypeInfo::Field& f : t.fields) {
    if (f.name != name) continue;
    Value m;
    m.type = f.type;
    m.inMemory = true;
    m.address = static_cast<uint16_t>(v.address + f.offset);
    m.known = v.known;
    return m;
  }
  throw Error(fmt::format("{} has no member '{}'", t.name, name));
}

class Evaluator {
 public:
  // `typed`: false in check(), where names have no type.
  Evaluator(const Scope& s, bool typed) : s_(s), image_(s.image()), typed_(typed) {}

  Value eval(const Node& n, bool typesOnly) {
    switch (n.kind) {
      case Node::Kind::Name:
        if (!typed_) return anyName(n);
        return objectOf(s_, lookUp(s_, n.function, n.name), typesOnly);
      case Node::Kind::Integer:
        return known(integerValue(image_, n.arith, n.integer), typesOnly);
      case Node::Kind::Real:
        return known(floatValue(image_, n.real), typesOnly);
      case Node::Kind::Unary:
        return unary(n, typesOnly);
      case Node::Kind::Binary:
        if (n.op == Op::LogAnd || n.op == Op::LogOr) return logical(n, typesOnly);
        if (n.op == Op::Slice) return slice(n, typesOnly);
        return binary(n.op, rv(*n.a, typesOnly), rv(*n.b, typesOnly));
      case Node::Kind::Conditional:
        return conditional(n, typesOnly);
      case Node::Kind::Cast:
        return cast(n.type, rv(*n.a, typesOnly));
      case Node::Kind::SizeofType:
        return known(sizeofType(n.type), typesOnly);
      case Node::Kind::SizeofExpr:
        return known(sizeofValue(eval(*n.a, true)), typesOnly);
      case Node::Kind::Index:
        return index(rv(*n.a, typesOnly), rv(*n.b, typesOnly));
      case Node::Kind::Member:
        return member(s_, eval(*n.a, typesOnly), n.name, ".");
      case Node::Kind::Arrow: {
        const Value p = rv(*n.a, typesOnly);
        if (p.anyType) return p;
        if (classOf(s_, p) != Class::Pointer)
          throw Error(fmt::format("'->{}' of a {}, not a pointer", n.name, category(s_, p)));
        return member(s_, target(s_, p, "->"), n.name, "->");
      }
    }
    throw Error("bad expression");
  }

 private:
  static Value known(Value v, bool typesOnly) { return typesOnly ? unknownOf(v) : v; }

  // check(): a name with no frame to look it up from. Every variable it
  // could mean (the global, a static, auto or parameter of any function;
  // FUNCTION::NAME's) has one type: an object of it, value unknown; else
  // the type too is unknown.
  Value anyName(const Node& n) const {
    int32_t type = -1;
    for (const vm::Symbol& sym : image_.symbols) {
      if (sym.typeId < 0 || sym.kind == vm::Symbol::Kind::Function ||
          sym.kind == vm::Symbol::Kind::Handler)
        continue;
      const auto dot = sym.name.find('.');
      const bool means = n.function.empty()
                             ? (dot == std::string::npos
                                    ? sym.name == n.name
                                    : sym.name.compare(dot + 1, std::string::npos, n.name) == 0)
                             : sym.name == n.function + "." + n.name;
      if (!means) continue;
      if (type >= 0 && !sameType(image_, type, sym.typeId)) return anyValue();
      type = sym.typeId;
    }
    if (type < 0) return anyValue();
    Value v;
    v.type = type;
    v.inMemory = true;
    v.known = false;
    return v;
  }
  Value rv(const Node& n, bool typesOnly) { return rvalue(s_, eval(n, typesOnly)); }

  [[noreturn]] void badOperands(Op op, const Value& a, const Value& b) const {
    throw Error(fmt::format("invalid operands to '{}' ({} and {})", spelling(op), category(s_, a),
                            category(s_, b)));
  }

  // ("+" | "-" | "!" | "~" | "*" | "&") operand
  Value unary(const Node& n, bool typesOnly) {
    if (n.op == Op::Address) {
      const Value v = eval(*n.a, typesOnly);
      if (v.anyType) return v;
      if (!v.inMemory) throw Error("'&' of a value that is not in memory");
      if (v.count > 0) throw Error("'&' of an '@' slice");
      Value out = addressValue(v.type, v.address);
      return v.known ? out : unknownOf(out);
    }
    const Value v = rv(*n.a, typesOnly);
    const Class c = classOf(s_, v);
    if (c == Class::Any) return v;
    if (n.op == Op::Deref) {
      if (c != Class::Pointer)
        throw Error(fmt::format("'*' of a {}, not a pointer", category(s_, v)));
      return target(s_, v, "*");
    }
    if (n.op == Op::Not) {
      if (!isScalar(c)) throw Error(fmt::format("'!' of a {}", category(s_, v)));
      return v.known ? integerValue(image_, Arith::Int, !truthOf(v))
                     : unknownOf(integerValue(image_, Arith::Int, 0));
    }
    if (c != Class::Arithmetic || (n.op == Op::BitNot && !isInteger(s_, v)))
      throw Error(fmt::format("'{}' of a {}", spelling(n.op), category(s_, v)));
    const Arith t = compiler::promoteArith(arithOfValue(s_, v));
    Value x = convert(s_, v, t);
    if (!x.known || n.op == Op::Plus) return x;
    if (t == Arith::Float) {
      x.real = -x.real;
      return x;
    }
    x.integer = compiler::wrapArith(n.op == Op::Minus ? -x.integer : ~x.integer, t);
    return x;
  }

  bool truthOf(const Value& rv) const {
    if (classOf(s_, rv) == Class::Arithmetic && arithOfValue(s_, rv) == Arith::Float)
      return rv.real != 0;
    return rv.integer != 0;
  }

  Value binary(Op op, const Value& a, const Value& b) {
    const Class ca = classOf(s_, a), cb = classOf(s_, b);
    // A division by a constant zero fails whatever it divides.
    if ((op == Op::Div || op == Op::Mod) && isZero(s_, b)) throw Error("division by zero");
    if (ca == Class::Any || cb == Class::Any) return anyValue();
    if (ca == Class::Pointer || cb == Class::Pointer) return pointerArithmetic(op, a, b);
    if (ca != Class::Arithmetic || cb != Class::Arithmetic) badOperands(op, a, b);
    const Arith ta = arithOfValue(s_, a), tb = arithOfValue(s_, b);
    const bool integerOnly = op == Op::Mod || op == Op::BitAnd || op == Op::BitOr ||
                             op == Op::BitXor || op == Op::Shl || op == Op::Shr;
    if (integerOnly && (ta == Arith::Float || tb == Arith::Float)) badOperands(op, a, b);
    if (op == Op::Shl || op == Op::Shr) {
      // The left operand promoted; the count an int (compiler/types.cpp).
      const Arith t = compiler::promoteArith(ta);
      Value x = convert(s_, a, t);
      const Value n = convert(s_, b, Arith::Int);
      if (!x.known || !n.known) return unknownOf(x);
      x.integer = op == Op::Shl ? compiler::shiftLeft(x.integer, n.integer, t)
                                : compiler::shiftRight(x.integer, n.integer, t);
      return x;
    }
    const Arith t = compiler::commonArith(ta, tb);
    const Value x = convert(s_, a, t), y = convert(s_, b, t);
    const bool comparison = op == Op::Lt || op == Op::Le || op == Op::Gt || op == Op::Ge ||
                            op == Op::Eq || op == Op::Ne;
    if (!x.known || !y.known)
      return unknownOf(comparison ? integerValue(image_, Arith::Int, 0) : x);
    if (comparison) {
      const bool r =
          t == Arith::Float ? compare(op, x.real, y.real) : compare(op, x.integer, y.integer);
      return integerValue(image_, Arith::Int, r);
    }
    if (t == Arith::Float) {
      Value out = x;
      switch (op) {
        case Op::Add:
          out.real = x.real + y.real;
          break;
        case Op::Sub:
          out.real = x.real - y.real;
          break;
        case Op::Mul:
          out.real = x.real * y.real;
          break;
        default:  // Div (a zero divisor failed above)
          out.real = x.real / y.real;
          break;
      }
      return out;
    }
    // Both 32 bits at most: the int64 arithmetic cannot overflow (a product
    // is taken unsigned, as its low 32 bits are all that is kept).
    const int64_t p = x.integer, q = y.integer;
    int64_t r = 0;
    switch (op) {
      case Op::Add:
        r = p + q;
        break;
      case Op::Sub:
        r = p - q;
        break;
      case Op::Mul:
        r = static_cast<int64_t>(static_cast<uint64_t>(p) * static_cast<uint64_t>(q));
        break;
      case Op::Div:
        r = compiler::divideArith(p, q, t);
        break;
      case Op::Mod:
        r = compiler::remainderArith(p, q, t);
        break;
      case Op::BitAnd:
        r = p & q;
        break;
      case Op::BitOr:
        r = p | q;
        break;
      case Op::BitXor:
        r = p ^ q;
        break;
      default:
        badOperands(op, a, b);
    }
    return integerValue(image_, t, r);
  }

  template <class T>
  static bool compare(Op op, T x, T y) {
    switch (op) {
      case Op::Lt:
        return x < y;
      case Op::Le:
        return x <= y;
      case Op::Gt:
        return x > y;
      case Op::Ge:
        return x >= y;
      case Op::Eq:
        return x == y;
      default:
        return x != y;
    }
  }

  // p + i, i + p, p - i, p - q, and comparisons with a pointer, in the
  // robot's 16-bit addresses: the index is an int, scaled in an int
  // (compiler/types.cpp ptrOffset), the sum wraps at 64 KiB.
  Value pointerArithmetic(Op op, const Value& a, const Value& b) {
    const Class ca = classOf(s_, a), cb = classOf(s_, b);
    const bool known = a.known && b.known;
    if (op == Op::Add || (op == Op::Sub && cb != Class::Pointer)) {
      const bool pointerFirst = ca == Class::Pointer;
      const Value& p = pointerFirst ? a : b;
      const Value& i = pointerFirst ? b : a;
      if (!isInteger(s_, i) || (op == Op::Sub && !pointerFirst)) badOperands(op, a, b);
      const int64_t size = elementSize(s_, p.pointee);
      const int64_t index = compiler::wrapArith(i.integer, Arith::Int);
      const int64_t offset = compiler::wrapArith(index * size, Arith::Int);
      Value out = addressValue(p.pointee, op == Op::Add ? p.integer + offset : p.integer - offset);
      return known ? out : unknownOf(out);
    }
    if (op == Op::Sub) {  // p - q: the elements between them, an int
      const int64_t size = elementSize(s_, a.pointee);
      if (ca != Class::Pointer || size != elementSize(s_, b.pointee)) badOperands(op, a, b);
      const int64_t bytes = compiler::wrapArith(a.integer - b.integer, Arith::Int);
      const Value out =
          integerValue(image_, Arith::Int, compiler::divideArith(bytes, size, Arith::Int));
      return known ? out : unknownOf(out);
    }
    const bool comparison = op == Op::Lt || op == Op::Le || op == Op::Gt || op == Op::Ge ||
                            op == Op::Eq || op == Op::Ne;
    // A pointer compares with a pointer or an integer (made an address), unsigned.
    if (!comparison || (ca != Class::Pointer && !isInteger(s_, a)) ||
        (cb != Class::Pointer && !isInteger(s_, b)))
      badOperands(op, a, b);
    if (!known) return unknownOf(integerValue(image_, Arith::Int, 0));
    const auto address = [](const Value& v) { return static_cast<uint64_t>(v.integer) & 0xFFFF; };
    return integerValue(image_, Arith::Int, compare(op, address(a), address(b)));
  }

  // "&&" and "||": the right operand only if the left does not decide.
  Value logical(const Node& n, bool typesOnly) {
    const Value l = rv(*n.a, typesOnly);
    if (!isScalar(classOf(s_, l)))
      throw Error(fmt::format("'{}' of a {}", spelling(n.op), category(s_, l)));
    const bool decided = l.known && truthOf(l) == (n.op == Op::LogOr);
    const Value r = rv(*n.b, typesOnly || !l.known || decided);
    if (!isScalar(classOf(s_, r)))
      throw Error(fmt::format("'{}' of a {}", spelling(n.op), category(s_, r)));
    if (decided) return integerValue(image_, Arith::Int, n.op == Op::LogOr);
    if (!l.known || !r.known) return unknownOf(integerValue(image_, Arith::Int, 0));
    return integerValue(image_, Arith::Int, truthOf(r));
  }

  // cond ? a : b, of the type C gives it (the arms' common type).
  Value conditional(const Node& n, bool typesOnly) {
    const Value c = rv(*n.a, typesOnly);
    if (!isScalar(classOf(s_, c)))
      throw Error(fmt::format("the condition of '?:' is a {}", category(s_, c)));
    const bool decided = c.known && !c.anyType;
    const bool first = decided && truthOf(c);
    const Value a = rv(*n.b, typesOnly || !decided || !first);
    const Value b = rv(*n.c, typesOnly || !decided || first);
    const Class ca = classOf(s_, a), cb = classOf(s_, b);
    const Value& chosen = first ? a : b;
    if (ca == Class::Any || cb == Class::Any) return anyValue();
    Value out;
    if (ca == Class::Arithmetic && cb == Class::Arithmetic) {
      out = convert(s_, chosen, compiler::commonArith(arithOfValue(s_, a), arithOfValue(s_, b)));
    } else if ((ca == Class::Pointer && (cb == Class::Pointer || isInteger(s_, b))) ||
               (cb == Class::Pointer && isInteger(s_, a))) {
      out = addressValue(ca == Class::Pointer ? a.pointee : b.pointee, chosen.integer);
      out.known = chosen.known;
    } else if (ca == Class::Aggregate && cb == Class::Aggregate && a.count == 0 && b.count == 0 &&
               sameType(image_, a.type, b.type)) {
      out = chosen;
    } else {
      throw Error(
          fmt::format("type mismatch in '?:' ({} and {})", category(s_, a), category(s_, b)));
    }
    return decided ? out : unknownOf(out);
  }

  // (type-name) operand, as the compiler converts (gen_expr.cpp convert):
  // a long made an address keeps its low 16 bits, as an unsigned int does.
  Value cast(const TypeName& name, const Value& v) {
    const Resolved to = resolve(image_, name);
    const Class c = classOf(s_, v);
    if (c == Class::Any) return v;
    const std::string target = name.text();
    if (c == Class::Aggregate)
      throw Error(fmt::format("cannot cast a {} to '{}'", category(s_, v), target));
    if (to.pointee >= 0) {
      if (c == Class::Arithmetic && arithOfValue(s_, v) == Arith::Float)
        throw Error(fmt::format("cannot cast a float to '{}'", target));
      Value out = addressValue(to.pointee, v.integer);
      return v.known ? out : unknownOf(out);
    }
    const std::optional<Arith> a = arithOf(image_, to.type);
    if (!a) throw Error(fmt::format("cannot cast to '{}'", target));
    if (c == Class::Pointer) {
      if (*a == Arith::Float) throw Error("cannot cast a pointer to 'float'");
      Value out = integerValue(image_, *a, v.integer);
      return v.known ? out : unknownOf(out);
    }
    return convert(s_, v, *a);
  }

  Value sizeofType(const TypeName& name) {
    const Resolved r = resolve(image_, name);
    if (r.pointee >= 0) return integerValue(image_, Arith::UInt, 2);
    const TypeInfo& t = typeOf(image_, r.type);
    if (t.kind == TypeInfo::Kind::Void || t.size == 0)
      throw Error(fmt::format("sizeof of the incomplete type '{}'", name.text()));
    return integerValue(image_, Arith::UInt, t.size);
  }

  // The size of an operand's type (it was not evaluated: its value is unknown).
  Value sizeofValue(const Value& v) {
    if (v.anyType) return unknownOf(integerValue(image_, Arith::UInt, 0));
    if (!v.inMemory && v.type < 0) return integerValue(image_, Arith::UInt, 2);  // an address
    const TypeInfo& t = typeOf(image_, v.type);
    if (v.count > 0)
      return integerValue(image_, Arith::UInt, static_cast<int64_t>(t.size) * v.count);
    if (t.size == 0) throw Error(fmt::format("sizeof of the incomplete type '{}'", t.name));
    return integerValue(image_, Arith::UInt, t.size);
  }

  // a[i] (or i[a]): *(a + i).
  Value index(const Value& a, const Value& b) {
    const Class ca = classOf(s_, a), cb = classOf(s_, b);
    if (ca == Class::Any || cb == Class::Any) return anyValue();
    if (ca != Class::Pointer && cb != Class::Pointer)
      throw Error(fmt::format("a {} cannot be indexed (not an array or a pointer)",
                              category(s_, ca == Class::Arithmetic ? a : b)));
    if (!isInteger(s_, ca == Class::Pointer ? b : a))
      throw Error(fmt::format("an index must be an integer, not a {}",
                              category(s_, ca == Class::Pointer ? b : a)));
    return target(s_, pointerArithmetic(Op::Add, a, b), "[]");
  }

  // gdb's a@n: n elements from the object a, n counted now even in an
  // operand that is not evaluated (sizeof buf[0]@4 is 4).
  Value slice(const Node& n, bool typesOnly) {
    Value v = eval(*n.a, typesOnly);
    const Value count = rv(*n.b, false);
    if (count.known && isInteger(s_, count) && count.integer < 1)
      throw Error(fmt::format("the count after '@' must be at least 1, not {}", count.integer));
    if (v.anyType || classOf(s_, count) == Class::Any) return anyValue();
    if (!v.inMemory) throw Error("'@' needs an object in memory on its left");
    if (v.count > 0) throw Error("'@' of an '@' slice");
    if (!isInteger(s_, count))
      throw Error(
          fmt::format("the count after '@' must be an integer, not a {}", category(s_, count)));
    const int64_t size = std::max<int64_t>(typeOf(image_, v.type).size, 1);
    if (!count.known) return anyValue();  // check(): the count is a name's
    if (count.integer < 1 || count.integer * size > 0x10000)
      throw Error(fmt::format("the count after '@' must be 1 to {} (64 KiB of {}), not {}",
                              0x10000 / size, typeOf(image_, v.type).name, count.integer));
    v.count = static_cast<int>(count.integer);
    return v;
  }

  const Scope& s_;
  const vm::Image& image_;
  bool typed_;
};

}  // namespace

// ---- interface --------------------------------------------------------------

Expression::Expression(const std::string& text) : text_(text), root_(parse(text)) {}
Expression::~Expression() = default;
Expression::Expression(Expression&&) noexcept = default;
Expression& Expression::operator=(Expression&&) noexcept = default;

Value Expression::evaluate(const Scope& scope) const {
  if (!scope.vm || scope.activations.empty()) throw Error("the robot has no state to read");
  return Evaluator(scope, true).eval(*root_, false);
}

void check(const vm::Image& image, const Expression& expression) {
  const Scope scope(image);
  Evaluator(scope, false).eval(expression.root(), false);
}

std::vector<std::pair<std::string, std::string>> Expression::names() const {
  std::vector<std::pair<std::string, std::string>> out;
  std::vector<const Node*> todo{root_.get()};
  while (!todo.empty()) {
    const Node* n = todo.back();
    todo.pop_back();
    if (!n) continue;
    if (n->kind == Node::Kind::Name) out.emplace_back(n->function, n->name);
    todo.push_back(n->a.get());
    todo.push_back(n->b.get());
    todo.push_back(n->c.get());
  }
  return out;
}

bool scalar(const Scope& scope, const Value& value, int64_t& integer, double& real, bool& isFloat) {
  if (value.inMemory) {
    const TypeInfo& t = typeOf(scope.image(), value.type);
    if (value.count > 0 || (t.kind != TypeInfo::Kind::Scalar && t.kind != TypeInfo::Kind::Pointer))
      return false;
  }
  const Value v = rvalue(scope, value);
  const Class c = classOf(scope, v);
  if (c != Class::Arithmetic && c != Class::Pointer) return false;
  isFloat = c == Class::Arithmetic && arithOfValue(scope, v) == Arith::Float;
  integer = v.integer;
  real = v.real;
  return true;
}

bool truth(const Scope& scope, const Value& value) {
  int64_t i = 0;
  double r = 0;
  bool f = false;
  if (!scalar(scope, value, i, r, f)) throw Error("a condition must be a number");
  return f ? r != 0 : i != 0;
}

}  // namespace simbot::inspect
