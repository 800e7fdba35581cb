// inspect/inspect.cpp -- expressions over a stopped robot's memory
// (inspect.h has the grammar). A recursive-descent parser makes a small
// tree once; evaluation walks it against a Scope each time the debugger
// stops, reading memory through the VM and never writing it.
#include "inspect/inspect.h"

#include <fmt/format.h>

#include <algorithm>
#include <bit>
#include <cctype>
#include <cmath>
#include <cstring>

namespace simbot::inspect {

using vm::Symbol;
using vm::TypeInfo;

// ---- scope ------------------------------------------------------------------

Scope::Scope(const vm::Vm& v, int selected) : vm(v), activations(v.activations()) {
  frame = std::clamp(selected, 0, static_cast<int>(activations.size()) - 1);
}

const Symbol* Scope::function() const {
  return image().functionAt(activations[static_cast<size_t>(frame)].pc);
}

int Scope::line() const { return image().lineAt(activations[static_cast<size_t>(frame)].pc); }

// ---- tree -------------------------------------------------------------------

struct Expression::Node {
  enum class Kind { Name, Integer, Real, Unary, Binary, Index, Member, Arrow, Slice };
  Kind kind = Kind::Integer;
  std::string op;        // Unary, Binary
  std::string function;  // Name: FUNCTION::NAME
  std::string name;      // Name, Member, Arrow
  int64_t integer = 0;
  double real = 0;
  std::unique_ptr<Node> a, b;
};

namespace {

using Node = Expression::Node;
using NodePtr = std::unique_ptr<Node>;

NodePtr newNode(Node::Kind kind) {
  auto n = std::make_unique<Node>();
  n->kind = kind;
  return n;
}

// Limits beside what they limit: an expression is a line a person types.
constexpr size_t kMaxExpressionChars = 1000;
constexpr int kMaxNesting = 64;
constexpr int kMaxShownElements = 200;  // longer arrays end in "..."
constexpr int kMaxStringChars = 80;     // a char pointer's string

struct Token {
  enum class Kind { Name, Integer, Real, Op, End } kind;
  std::string text;
  int64_t integer = 0;
  double real = 0;
  size_t at = 0;
};

std::vector<Token> lex(const std::string& s) {
  std::vector<Token> out;
  size_t i = 0;
  auto fail = [&](size_t at, const std::string& what) {
    throw Error(fmt::format("{} at column {} of '{}'", what, at + 1, s));
  };
  while (i < s.size()) {
    const unsigned char c = static_cast<unsigned char>(s[i]);
    if (std::isspace(c)) {
      ++i;
      continue;
    }
    const size_t start = i;
    if (std::isalpha(c) || c == '_') {
      while (i < s.size() && (std::isalnum(static_cast<unsigned char>(s[i])) || s[i] == '_')) ++i;
      out.push_back({Token::Kind::Name, s.substr(start, i - start), 0, 0, start});
    } else if (std::isdigit(c) || (c == '.' && i + 1 < s.size() &&
                                   std::isdigit(static_cast<unsigned char>(s[i + 1])))) {
      while (i < s.size() && (std::isalnum(static_cast<unsigned char>(s[i])) || s[i] == '.')) ++i;
      const std::string text = s.substr(start, i - start);
      Token t{Token::Kind::Integer, text, 0, 0, start};
      const bool hex = text.size() > 1 && text[0] == '0' && (text[1] == 'x' || text[1] == 'X');
      char* end = nullptr;
      if (!hex && (text.find('.') != std::string::npos || text.find('e') != std::string::npos)) {
        t.kind = Token::Kind::Real;
        t.real = std::strtod(text.c_str(), &end);
      } else {
        t.integer = static_cast<int64_t>(std::strtoull(text.c_str(), &end, 0));
      }
      if (!end || *end != '\0') fail(start, "bad number '" + text + "'");
      out.push_back(t);
    } else if (c == '\'') {
      if (i + 2 < s.size() && s[i + 2] == '\'') {
        out.push_back(
            {Token::Kind::Integer, s.substr(i, 3), static_cast<unsigned char>(s[i + 1]), 0, start});
        i += 3;
      } else {
        fail(start, "bad character constant");
      }
    } else {
      static const char* const kOps[] = {"::", "->", "==", "!=", "<=", ">=", "&&", "||",
                                         "[",  "]",  "(",  ")",  ".",  "*",  "&",  "-",
                                         "+",  "/",  "%",  "!",  "<",  ">",  "@"};
      bool found = false;
      for (const char* op : kOps) {
        const size_t n = std::strlen(op);
        if (s.compare(i, n, op) == 0) {
          out.push_back({Token::Kind::Op, op, 0, 0, start});
          i += n;
          found = true;
          break;
        }
      }
      if (!found) fail(start, fmt::format("unexpected '{}'", s[i]));
    }
  }
  out.push_back({Token::Kind::End, "", 0, 0, s.size()});
  return out;
}

class Parser {
 public:
  Parser(const std::string& text) : text_(text), tokens_(lex(text)) {}

  NodePtr parse() {
    NodePtr n = orExpr();
    if (cur().kind != Token::Kind::End) fail("unexpected '" + cur().text + "'");
    return n;
  }

 private:
  const Token& cur() const { return tokens_[i_]; }
  bool isOp(const char* op) const { return cur().kind == Token::Kind::Op && cur().text == op; }
  bool accept(const char* op) {
    if (!isOp(op)) return false;
    ++i_;
    return true;
  }
  [[noreturn]] void fail(const std::string& what) const {
    throw Error(fmt::format("{} at column {} of '{}'", what, cur().at + 1, text_));
  }
  void expect(const char* op) {
    if (!accept(op)) fail(fmt::format("expected '{}'", op));
  }
  struct Depth {
    Parser& p;
    explicit Depth(Parser& parser) : p(parser) {
      if (++p.depth_ > kMaxNesting) p.fail("expression nested too deeply");
    }
    ~Depth() { --p.depth_; }
  };

  static NodePtr binary(std::string op, NodePtr a, NodePtr b) {
    auto n = newNode(Node::Kind::Binary);
    n->op = std::move(op);
    n->a = std::move(a);
    n->b = std::move(b);
    return n;
  }

  // or := and ("||" and)*
  NodePtr orExpr() {
    NodePtr n = andExpr();
    while (accept("||")) n = binary("||", std::move(n), andExpr());
    return n;
  }
  // and := cmp ("&&" cmp)*
  NodePtr andExpr() {
    NodePtr n = compare();
    while (accept("&&")) n = binary("&&", std::move(n), compare());
    return n;
  }
  // cmp := sum (("=="|"!="|"<"|"<="|">"|">=") sum)?
  NodePtr compare() {
    NodePtr n = sum();
    for (const char* op : {"==", "!=", "<=", ">=", "<", ">"})
      if (accept(op)) return binary(op, std::move(n), sum());
    return n;
  }
  // sum := term (("+"|"-") term)*
  NodePtr sum() {
    NodePtr n = term();
    for (;;) {
      if (accept("+"))
        n = binary("+", std::move(n), term());
      else if (accept("-"))
        n = binary("-", std::move(n), term());
      else
        return n;
    }
  }
  // term := unary (("*"|"/"|"%") unary)*
  NodePtr term() {
    NodePtr n = unary();
    for (;;) {
      if (accept("*"))
        n = binary("*", std::move(n), unary());
      else if (accept("/"))
        n = binary("/", std::move(n), unary());
      else if (accept("%"))
        n = binary("%", std::move(n), unary());
      else
        return n;
    }
  }
  // unary := ("-"|"!"|"*"|"&") unary | slice
  NodePtr unary() {
    const Depth depth(*this);
    for (const char* op : {"-", "!", "*", "&"}) {
      if (accept(op)) {
        auto n = newNode(Node::Kind::Unary);
        n->op = op;
        n->a = unary();
        return n;
      }
    }
    return slice();
  }
  // slice := postfix ("@" unary)?
  NodePtr slice() {
    NodePtr n = postfix();
    if (accept("@")) {
      auto s = newNode(Node::Kind::Slice);
      s->a = std::move(n);
      s->b = unary();
      return s;
    }
    return n;
  }
  // postfix := primary ("[" expr "]" | "." NAME | "->" NAME)*
  NodePtr postfix() {
    NodePtr n = primary();
    for (;;) {
      if (accept("[")) {
        auto x = newNode(Node::Kind::Index);
        x->a = std::move(n);
        x->b = orExpr();
        expect("]");
        n = std::move(x);
      } else if (isOp(".") || isOp("->")) {
        const bool arrow = isOp("->");
        ++i_;
        if (cur().kind != Token::Kind::Name) fail("expected a member name");
        auto m = newNode(arrow ? Node::Kind::Arrow : Node::Kind::Member);
        m->a = std::move(n);
        m->name = cur().text;
        ++i_;
        n = std::move(m);
      } else {
        return n;
      }
    }
  }
  // primary := NAME | FUNCTION "::" NAME | NUMBER | CHAR | "(" expr ")"
  NodePtr primary() {
    const Depth depth(*this);
    const Token t = cur();
    if (t.kind == Token::Kind::Integer || t.kind == Token::Kind::Real) {
      ++i_;
      auto n = newNode(t.kind == Token::Kind::Integer ? Node::Kind::Integer : Node::Kind::Real);
      n->integer = t.integer;
      n->real = t.real;
      return n;
    }
    if (t.kind == Token::Kind::Name) {
      ++i_;
      auto n = newNode(Node::Kind::Name);
      n->name = t.text;
      if (accept("::")) {
        if (cur().kind != Token::Kind::Name) fail("expected a name after '::'");
        n->function = t.text;
        n->name = cur().text;
        ++i_;
      }
      return n;
    }
    if (accept("(")) {
      NodePtr n = orExpr();
      expect(")");
      return n;
    }
    if (t.kind == Token::Kind::End) fail("expected a name or a number");
    fail("unexpected '" + t.text + "'");
  }

  std::string text_;
  std::vector<Token> tokens_;
  size_t i_ = 0;
  int depth_ = 0;
};

// ---- reading memory ---------------------------------------------------------

const TypeInfo& typeOf(const Scope& s, int32_t type) {
  const auto& types = s.image().types;
  if (type < 0 || static_cast<size_t>(type) >= types.size()) throw Error("a value without a type");
  return types[static_cast<size_t>(type)];
}

bool isScalarType(const TypeInfo& t) {
  return t.kind == TypeInfo::Kind::Scalar || t.kind == TypeInfo::Kind::Pointer;
}

// A scalar object's value: integers sign- or zero-extended, floats as double.
void load(const Scope& s, const TypeInfo& t, uint16_t a, int64_t& integer, double& real,
          bool& isFloat) {
  using V = Symbol::Value;
  isFloat = false;
  switch (t.scalar) {
    case V::Char:
      integer = s.vm.read8(a);
      return;
    case V::SChar:
      integer = static_cast<int8_t>(s.vm.read8(a));
      return;
    case V::Int:
      integer = static_cast<int16_t>(s.vm.read16(a));
      return;
    case V::UInt:
    case V::Pointer:
      integer = s.vm.read16(a);
      return;
    case V::Long:
      integer = static_cast<int32_t>(s.vm.read32(a));
      return;
    case V::ULong:
      integer = s.vm.read32(a);
      return;
    case V::Float:
      isFloat = true;
      real = std::bit_cast<float>(s.vm.read32(a));
      return;
    default:
      throw Error("not a number: " + t.name);
  }
}

// The symbol NAME means from the selected frame (C's rules), or FUNCTION::NAME.
struct Found {
  const Symbol* symbol = nullptr;
  int frame = -1;  // autos: the activation whose frame holds it
};

Found lookUp(const Scope& s, const std::string& function, const std::string& name) {
  const vm::Image& img = s.image();
  auto local = [&](const std::string& fn, int frame, int line) -> Found {
    const std::string qualified = fn + "." + name;
    const Symbol* best = nullptr;
    for (const Symbol& sym : img.symbols) {
      if (sym.name != qualified) continue;
      // Statics and a static function's parameters have addresses.
      if (sym.kind == Symbol::Kind::Static || sym.kind == Symbol::Kind::Param) {
        if (!best) best = &sym;
        continue;
      }
      if (sym.kind != Symbol::Kind::Auto || frame < 0) continue;
      const bool inScope =
          sym.parameter || (line >= sym.line && (sym.scopeEnd == 0 || line <= sym.scopeEnd));
      if (inScope && (!best || best->kind != Symbol::Kind::Auto || sym.line > best->line))
        best = &sym;
    }
    return best ? Found{best, best->kind == Symbol::Kind::Auto ? frame : -1} : Found{};
  };
  if (!function.empty()) {
    // The innermost activation of that function holds its autos.
    for (size_t f = 0; f < s.activations.size(); ++f) {
      const Symbol* fn = img.functionAt(s.activations[f].pc);
      if (fn && fn->name == function) {
        const Found found = local(function, static_cast<int>(f), img.lineAt(s.activations[f].pc));
        if (found.symbol) return found;
      }
    }
    const Found found = local(function, -1, 0);
    if (found.symbol) return found;
    throw Error(
        fmt::format("no variable '{}' in '{}' (or it is an auto of a function that is "
                    "not on the stack)",
                    name, function));
  }
  if (const Symbol* fn = s.function()) {
    const Found found = local(fn->name, s.frame, s.line());
    if (found.symbol) return found;
  }
  for (const Symbol& sym : img.symbols)
    if (sym.kind == Symbol::Kind::Global && sym.name == name) return Found{&sym, -1};
  for (const Symbol& sym : img.symbols)
    if ((sym.kind == Symbol::Kind::Function || sym.kind == Symbol::Kind::Handler) &&
        sym.name == name)
      throw Error(fmt::format("'{}' is a function, not a variable", name));
  const Symbol* fn = s.function();
  throw Error(fmt::format("no variable '{}' in scope{}", name,
                          fn ? fmt::format(" at line {} of {}()", s.line(), fn->name) : ""));
}

Value objectOf(const Scope& s, const Found& found) {
  const Symbol& sym = *found.symbol;
  Value v;
  v.type = sym.typeId;
  v.inMemory = true;
  if (sym.kind == Symbol::Kind::Auto) {
    const vm::Vm::Activation& act = s.activations[static_cast<size_t>(found.frame)];
    if (!act.framed)
      throw Error(
          fmt::format("'{}' has no frame yet (its function's first instruction, ENTER, "
                      "has not run)",
                      sym.name));
    v.address = static_cast<uint16_t>(act.fp + sym.address);
    v.frame = found.frame;
  } else {
    v.address = static_cast<uint16_t>(sym.address);
  }
  return v;
}

bool numberOf(const Scope& s, const Value& v, int64_t& integer, double& real, bool& isFloat) {
  if (v.type < 0) {
    integer = v.integer;
    real = v.real;
    isFloat = v.isFloat;
    return true;
  }
  const TypeInfo& t = typeOf(s, v.type);
  if (v.count > 0) return false;
  if (t.kind == TypeInfo::Kind::Array) {
    integer = v.address;  // an array is its address
    isFloat = false;
    return true;
  }
  if (!isScalarType(t)) return false;
  load(s, t, v.address, integer, real, isFloat);
  return true;
}

Value number(int64_t i) {
  Value v;
  v.integer = i;
  return v;
}
Value realNumber(double d) {
  Value v;
  v.isFloat = true;
  v.real = d;
  return v;
}

Value eval(const Scope& s, const Node& n);

int64_t integerOf(const Scope& s, const Node& n, const char* what) {
  const Value v = eval(s, n);
  int64_t i = 0;
  double r = 0;
  bool f = false;
  if (!numberOf(s, v, i, r, f) || f) throw Error(fmt::format("{} must be an integer", what));
  return i;
}

// The element type and address of an array or pointer value.
void elements(const Scope& s, const Value& v, int32_t& element, uint16_t& base) {
  if (v.type < 0 && v.pointee >= 0) {
    element = v.pointee;
    base = static_cast<uint16_t>(v.integer);
    return;
  }
  if (v.type < 0) throw Error("a number cannot be indexed or dereferenced");
  const TypeInfo& t = typeOf(s, v.type);
  if (t.kind == TypeInfo::Kind::Array) {
    element = t.base;
    base = v.address;
  } else if (t.kind == TypeInfo::Kind::Pointer) {
    element = t.base;
    base = s.vm.read16(v.address);
  } else {
    throw Error(fmt::format("a {} cannot be indexed or dereferenced", t.name));
  }
  if (element < 0 || typeOf(s, element).kind == TypeInfo::Kind::Void)
    throw Error("a void pointer cannot be dereferenced");
  if (typeOf(s, element).kind == TypeInfo::Kind::Function)
    throw Error("a function pointer cannot be dereferenced here");
}

Value member(const Scope& s, Value v, const std::string& name) {
  const TypeInfo& t = typeOf(s, v.type);
  if (t.kind != TypeInfo::Kind::Struct && t.kind != TypeInfo::Kind::Union)
    throw Error(fmt::format("'.{}' of a {}, not a struct or union", name, t.name));
  for (const TypeInfo::Field& f : t.fields) {
    if (f.name != name) continue;
    Value m;
    m.type = f.type;
    m.inMemory = true;
    m.address = static_cast<uint16_t>(v.address + f.offset);
    return m;
  }
  throw Error(fmt::format("{} has no member '{}'", t.name, name));
}

// The type an address points at: a pointer object's target, an array's
// element, an &x's; -1 for anything else.
int32_t pointeeOf(const Scope& s, const Value& v) {
  if (v.type < 0) return v.pointee;
  if (v.count > 0) return -1;
  const TypeInfo& t = typeOf(s, v.type);
  if (t.kind != TypeInfo::Kind::Pointer && t.kind != TypeInfo::Kind::Array) return -1;
  if (t.base < 0) return -1;
  const TypeInfo& target = typeOf(s, t.base);
  return target.kind == TypeInfo::Kind::Void || target.kind == TypeInfo::Kind::Function ? -1
                                                                                        : t.base;
}

Value arith(const std::string& op, const Scope& s, const Value& a, const Value& b) {
  // Address arithmetic, as C scales it: p + n, n + p, p - n.
  if (op == "-" && pointeeOf(s, a) >= 0 && pointeeOf(s, b) >= 0) {
    // p - q: the elements between them.
    int64_t ia = 0, ib = 0;
    double r = 0;
    bool f = false;
    numberOf(s, a, ia, r, f);
    numberOf(s, b, ib, r, f);
    const int64_t size = std::max<int64_t>(1, typeOf(s, pointeeOf(s, a)).size);
    return number((ia - ib) / size);
  }
  if (op == "+" || op == "-") {
    const int32_t pa = pointeeOf(s, a), pb = op == "+" ? pointeeOf(s, b) : -1;
    if ((pa >= 0) != (pb >= 0)) {
      const Value& address = pa >= 0 ? a : b;
      const Value& offset = pa >= 0 ? b : a;
      int64_t base = 0, n = 0;
      double r = 0;
      bool f = false;
      if (!numberOf(s, address, base, r, f) || !numberOf(s, offset, n, r, f) || f)
        throw Error(fmt::format("'{}' of an address needs an integer", op));
      const int32_t target = pa >= 0 ? pa : pb;
      const int64_t size = typeOf(s, target).size;
      Value out = number(static_cast<uint16_t>(base + (op == "+" ? n : -n) * size));
      out.pointee = target;
      return out;
    }
  }
  int64_t ia = 0, ib = 0;
  double ra = 0, rb = 0;
  bool fa = false, fb = false;
  if (!numberOf(s, a, ia, ra, fa) || !numberOf(s, b, ib, rb, fb))
    throw Error(fmt::format("'{}' needs numbers", op));
  if (fa || fb) {
    const double x = fa ? ra : static_cast<double>(ia), y = fb ? rb : static_cast<double>(ib);
    if (op == "+") return realNumber(x + y);
    if (op == "-") return realNumber(x - y);
    if (op == "*") return realNumber(x * y);
    if (op == "/") return realNumber(x / y);
    if (op == "==") return number(x == y);
    if (op == "!=") return number(x != y);
    if (op == "<") return number(x < y);
    if (op == "<=") return number(x <= y);
    if (op == ">") return number(x > y);
    if (op == ">=") return number(x >= y);
    throw Error(fmt::format("'{}' needs integers", op));
  }
  if ((op == "/" || op == "%") && ib == 0) throw Error("division by zero");
  // Wrapping, as the robot's arithmetic would.
  const auto ua = static_cast<uint64_t>(ia), ub = static_cast<uint64_t>(ib);
  if (op == "+") return number(static_cast<int64_t>(ua + ub));
  if (op == "-") return number(static_cast<int64_t>(ua - ub));
  if (op == "*") return number(static_cast<int64_t>(ua * ub));
  if (op == "/") return number(ib == -1 ? static_cast<int64_t>(0 - ua) : ia / ib);
  if (op == "%") return number(ib == -1 ? 0 : ia % ib);
  if (op == "==") return number(ia == ib);
  if (op == "!=") return number(ia != ib);
  if (op == "<") return number(ia < ib);
  if (op == "<=") return number(ia <= ib);
  if (op == ">") return number(ia > ib);
  return number(ia >= ib);
}

Value eval(const Scope& s, const Node& n) {
  switch (n.kind) {
    case Node::Kind::Name:
      return objectOf(s, lookUp(s, n.function, n.name));
    case Node::Kind::Integer:
      return number(n.integer);
    case Node::Kind::Real:
      return realNumber(n.real);
    case Node::Kind::Unary: {
      const Value a = eval(s, *n.a);
      if (n.op == "*") {
        Value v;
        uint16_t base = 0;
        elements(s, a, v.type, base);
        v.inMemory = true;
        v.address = base;
        return v;
      }
      if (n.op == "&") {
        if (!a.inMemory) throw Error("'&' of a value that is not in memory");
        Value address = number(a.address);
        address.pointee = a.type;
        return address;
      }
      int64_t i = 0;
      double r = 0;
      bool f = false;
      if (!numberOf(s, a, i, r, f)) throw Error(fmt::format("'{}' needs a number", n.op));
      if (n.op == "!") return number(f ? r == 0 : i == 0);
      return f ? realNumber(-r) : number(static_cast<int64_t>(0 - static_cast<uint64_t>(i)));
    }
    case Node::Kind::Binary: {
      if (n.op == "&&" || n.op == "||") {
        const bool a = truth(s, eval(s, *n.a));
        if (n.op == "&&" ? !a : a) return number(a);
        return number(truth(s, eval(s, *n.b)));
      }
      return arith(n.op, s, eval(s, *n.a), eval(s, *n.b));
    }
    case Node::Kind::Index: {
      const Value a = eval(s, *n.a);
      const int64_t i = integerOf(s, *n.b, "an index");
      Value v;
      uint16_t base = 0;
      elements(s, a, v.type, base);
      v.inMemory = true;
      v.address = static_cast<uint16_t>(base + i * typeOf(s, v.type).size);
      return v;
    }
    case Node::Kind::Member:
      return member(s, eval(s, *n.a), n.name);
    case Node::Kind::Arrow: {
      const Value a = eval(s, *n.a);
      Value target;
      uint16_t base = 0;
      elements(s, a, target.type, base);
      target.inMemory = true;
      target.address = base;
      return member(s, target, n.name);
    }
    case Node::Kind::Slice: {
      Value v = eval(s, *n.a);
      if (!v.inMemory) throw Error("'@' needs an object in memory on its left");
      const int64_t count = integerOf(s, *n.b, "the count after '@'");
      if (count < 1 || count > 0x10000) throw Error("the count after '@' must be 1 to 65536");
      v.count = static_cast<int>(count);
      return v;
    }
  }
  throw Error("bad expression");
}

std::string charText(int64_t c) {
  if (c == '\'' || c == '\\') return fmt::format("'\\{}'", static_cast<char>(c));
  if (c >= 0x20 && c < 0x7F) return fmt::format("'{}'", static_cast<char>(c));
  if (c == 0) return "'\\0'";
  return fmt::format("'\\x{:02x}'", static_cast<uint8_t>(c));
}

std::string quoted(const Scope& s, uint16_t a, int limit, bool& ended) {
  std::string out = "\"";
  ended = false;
  for (int k = 0; k < limit; ++k) {
    const uint8_t c = s.vm.read8(static_cast<uint16_t>(a + k));
    if (c == 0) {
      ended = true;
      break;
    }
    if (c == '"' || c == '\\')
      out += fmt::format("\\{}", static_cast<char>(c));
    else if (c >= 0x20 && c < 0x7F)
      out += static_cast<char>(c);
    else
      out += fmt::format("\\x{:02x}", c);
  }
  return out + "\"";
}

std::string formatNumber(const Value& v) {
  if (v.pointee >= 0) return fmt::format("0x{:04X}", static_cast<uint16_t>(v.integer));
  return v.isFloat ? fmt::format("{}", v.real) : fmt::format("{}", v.integer);
}

std::string formatObject(const Scope& s, int32_t type, uint16_t a, int count);

std::string formatScalar(const Scope& s, const TypeInfo& t, uint16_t a) {
  int64_t i = 0;
  double r = 0;
  bool f = false;
  load(s, t, a, i, r, f);
  if (f) return fmt::format("{}", static_cast<float>(r));
  if (t.kind == TypeInfo::Kind::Pointer) {
    std::string out = fmt::format("0x{:04X}", i);
    const int32_t target = t.base;
    if (target >= 0) {
      const TypeInfo& pt = typeOf(s, target);
      if (pt.kind == TypeInfo::Kind::Function) {
        if (const Symbol* fn = s.image().functionAt(static_cast<uint32_t>(i));
            fn && fn->address == static_cast<uint32_t>(i))
          out += fmt::format(" <{}>", fn->name);
      } else if (pt.kind == TypeInfo::Kind::Scalar &&
                 (pt.scalar == Symbol::Value::Char || pt.scalar == Symbol::Value::SChar) &&
                 i >= vm::kNullPageEnd) {
        bool ended = false;
        out += " " + quoted(s, static_cast<uint16_t>(i), kMaxStringChars, ended);
        if (!ended) out += "...";
      }
    }
    return out;
  }
  if (t.scalar == Symbol::Value::Char || t.scalar == Symbol::Value::SChar)
    return fmt::format("{} {}", i, charText(i));
  return fmt::format("{}", i);
}

std::string formatElements(const Scope& s, int32_t element, uint16_t a, int count) {
  const TypeInfo& e = typeOf(s, element);
  std::string out;
  if (e.kind == TypeInfo::Kind::Scalar &&
      (e.scalar == Symbol::Value::Char || e.scalar == Symbol::Value::SChar)) {
    // A char array: its string (to the first NUL inside it) and every byte.
    bool ended = false;
    out = quoted(s, a, count, ended);
    if (!ended) out += " (no NUL)";
    out += " {";
    for (int k = 0; k < count && k < kMaxShownElements; ++k)
      out += fmt::format("{}0x{:02X}", k ? " " : "", s.vm.read8(static_cast<uint16_t>(a + k)));
    return out + (count > kMaxShownElements ? " ...}" : "}");
  }
  out = "{";
  for (int k = 0; k < count && k < kMaxShownElements; ++k)
    out += (k ? ", " : "") + formatObject(s, element, static_cast<uint16_t>(a + k * e.size), 0);
  return out + (count > kMaxShownElements ? ", ...}" : "}");
}

std::string formatObject(const Scope& s, int32_t type, uint16_t a, int count) {
  if (count > 0) return formatElements(s, type, a, count);
  const TypeInfo& t = typeOf(s, type);
  switch (t.kind) {
    case TypeInfo::Kind::Scalar:
    case TypeInfo::Kind::Pointer:
      return formatScalar(s, t, a);
    case TypeInfo::Kind::Array:
      if (t.count == 0) return fmt::format("0x{:04X} (an array of unknown length)", a);
      return formatElements(s, t.base, a, t.count);
    case TypeInfo::Kind::Struct:
    case TypeInfo::Kind::Union: {
      std::string out = "{";
      for (size_t k = 0; k < t.fields.size(); ++k)
        out += fmt::format(
            "{}{} = {}", k ? ", " : "", t.fields[k].name,
            formatObject(s, t.fields[k].type, static_cast<uint16_t>(a + t.fields[k].offset), 0));
      return out + "}";
    }
    default:
      return "(" + t.name + ")";
  }
}

}  // namespace

// ---- interface --------------------------------------------------------------

Expression::Expression(const std::string& text) : text_(text) {
  if (text.size() > kMaxExpressionChars)
    throw Error(fmt::format("an expression of {} characters (at most {})", text.size(),
                            kMaxExpressionChars));
  root_ = Parser(text).parse();
}
Expression::~Expression() = default;
Expression::Expression(Expression&&) noexcept = default;
Expression& Expression::operator=(Expression&&) noexcept = default;

Value Expression::evaluate(const Scope& scope) const {
  if (scope.activations.empty()) throw Error("the robot has no state to read");
  return eval(scope, *root_);
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
  }
  return out;
}

bool namesExist(const vm::Image& image, const Expression& expression) {
  for (const auto& [function, name] : expression.names()) {
    bool found = false;
    for (const Symbol& s : image.symbols) {
      if (s.typeId < 0) continue;
      const auto dot = s.name.find('.');
      if (function.empty())
        found |= (s.kind == Symbol::Kind::Global && s.name == name) ||
                 (dot != std::string::npos && s.name.substr(dot + 1) == name);
      else
        found |= s.name == function + "." + name;
    }
    if (!found) return false;
  }
  return true;
}

std::string format(const Scope& scope, const Value& value) {
  if (value.type < 0) return formatNumber(value);
  return formatObject(scope, value.type, value.address, value.count);
}

std::string typeName(const Scope& scope, const Value& value) {
  if (value.type < 0 && value.pointee >= 0) {
    const std::string target = typeOf(scope, value.pointee).name;
    return target + (target.back() == '*' ? "*" : " *");
  }
  if (value.type < 0) return value.isFloat ? "double" : "long";
  const std::string name = typeOf(scope, value.type).name;
  return value.count > 0 ? fmt::format("{}[{}]", name, value.count) : name;
}

bool scalar(const Scope& scope, const Value& value, int64_t& integer, double& real, bool& isFloat) {
  if (value.type >= 0 && value.count == 0 &&
      typeOf(scope, value.type).kind == TypeInfo::Kind::Array)
    return false;
  return numberOf(scope, value, integer, real, isFloat);
}

bool truth(const Scope& scope, const Value& value) {
  int64_t i = 0;
  double r = 0;
  bool f = false;
  if (!numberOf(scope, value, i, r, f)) throw Error("a condition must be a number");
  return f ? r != 0 : i != 0;
}

std::vector<uint8_t> bytes(const Scope& scope, const Value& value) {
  std::vector<uint8_t> out;
  if (!value.inMemory) return out;
  const uint32_t size = value.count > 0
                            ? typeOf(scope, value.type).size * static_cast<uint32_t>(value.count)
                            : typeOf(scope, value.type).size;
  out.reserve(size);
  for (uint32_t k = 0; k < size; ++k)
    out.push_back(scope.vm.read8(static_cast<uint16_t>(value.address + k)));
  return out;
}

std::vector<Child> children(const Scope& scope, const Value& value) {
  std::vector<Child> out;
  if (value.type < 0) return out;
  const TypeInfo& t = typeOf(scope, value.type);
  auto elementsFrom = [&](int32_t element, uint16_t a, int count) {
    const uint32_t size = typeOf(scope, element).size;
    for (int k = 0; k < count && k < kMaxShownElements; ++k) {
      Value v;
      v.type = element;
      v.inMemory = true;
      v.address = static_cast<uint16_t>(a + k * size);
      out.push_back({fmt::format("[{}]", k), v});
    }
  };
  if (value.count > 0) {
    elementsFrom(value.type, value.address, value.count);
  } else if (t.kind == TypeInfo::Kind::Array) {
    elementsFrom(t.base, value.address, t.count);
  } else if (t.kind == TypeInfo::Kind::Struct || t.kind == TypeInfo::Kind::Union) {
    for (const TypeInfo::Field& f : t.fields) {
      Value v;
      v.type = f.type;
      v.inMemory = true;
      v.address = static_cast<uint16_t>(value.address + f.offset);
      out.push_back({"." + f.name, v});
    }
  } else if (t.kind == TypeInfo::Kind::Pointer && t.base >= 0) {
    const TypeInfo& target = typeOf(scope, t.base);
    const uint16_t p = scope.vm.read16(value.address);
    if (p >= vm::kNullPageEnd && target.kind != TypeInfo::Kind::Void &&
        target.kind != TypeInfo::Kind::Function) {
      Value v;
      v.type = t.base;
      v.inMemory = true;
      v.address = p;
      out.push_back({"*", v});
    }
  }
  return out;
}

bool hasChildren(const Scope& scope, const Value& value) {
  if (value.type < 0) return false;
  if (value.count > 0) return true;
  const TypeInfo& t = typeOf(scope, value.type);
  if (t.kind == TypeInfo::Kind::Array || t.kind == TypeInfo::Kind::Struct ||
      t.kind == TypeInfo::Kind::Union)
    return true;
  if (t.kind == TypeInfo::Kind::Pointer && t.base >= 0) {
    const TypeInfo& target = typeOf(scope, t.base);
    return target.kind != TypeInfo::Kind::Void && target.kind != TypeInfo::Kind::Function;
  }
  return false;
}

std::vector<Variable> locals(const Scope& scope) {
  std::vector<Variable> out;
  const Symbol* fn = scope.function();
  if (!fn) return out;
  const std::string prefix = fn->name + ".";
  std::vector<std::string> names;
  for (const Symbol& sym : scope.image().symbols)
    if (sym.name.rfind(prefix, 0) == 0 && sym.typeId >= 0 &&
        std::find(names.begin(), names.end(), sym.name.substr(prefix.size())) == names.end())
      names.push_back(sym.name.substr(prefix.size()));
  for (const std::string& name : names) {
    try {
      const Found found = lookUp(scope, "", name);
      if (found.symbol && found.symbol->name == prefix + name)
        out.push_back({name, objectOf(scope, found)});
    } catch (const Error&) {
      // Not in scope at this line, or no frame yet: not shown.
    }
  }
  return out;
}

std::vector<Variable> globals(const Scope& scope) {
  std::vector<Variable> out;
  for (const Symbol& sym : scope.image().symbols) {
    if (sym.kind != Symbol::Kind::Global || sym.typeId < 0) continue;
    Value v;
    v.type = sym.typeId;
    v.inMemory = true;
    v.address = static_cast<uint16_t>(sym.address);
    out.push_back({sym.name, v});
  }
  return out;
}

}  // namespace simbot::inspect
