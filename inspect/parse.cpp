// inspect/parse.cpp -- the lexer and the recursive-descent parser of
// debugger expressions (the grammar is in inspect.h; each rule is above
// its function). Constants take their C types here, by Dynamic C's rules
// (compiler/arith.h); everything that needs the program waits for
// evaluation.
#include <fmt/format.h>

#include <cctype>
#include <cmath>
#include <cstring>
#include <vector>

#include "inspect/inspect.h"
#include "inspect/tree.h"

namespace simbot::inspect {

namespace {

// A tree taller than this is refused: evaluating and freeing it recurse.
constexpr int kMaxTreeHeight = 256;

struct Token {
  enum class Kind { Name, Integer, Real, Op, End } kind;
  std::string text;
  size_t at = 0;
  Arith arith = Arith::Int;  // Integer
  int64_t integer = 0;
  float real = 0;
};

bool isDigit(char c) { return c >= '0' && c <= '9'; }
bool isNameChar(char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; }

class Lexer {
 public:
  explicit Lexer(const std::string& s) : s_(s) {}

  std::vector<Token> run() {
    std::vector<Token> out;
    while (i_ < s_.size()) {
      const char c = s_[i_];
      if (std::isspace(static_cast<unsigned char>(c))) {
        ++i_;
        continue;
      }
      const size_t start = i_;
      if (std::isalpha(static_cast<unsigned char>(c)) || c == '_') {
        while (i_ < s_.size() && isNameChar(s_[i_])) ++i_;
        out.push_back({Token::Kind::Name, s_.substr(start, i_ - start), start});
      } else if (isDigit(c) || (c == '.' && i_ + 1 < s_.size() && isDigit(s_[i_ + 1]))) {
        out.push_back(number());
      } else if (c == '\'') {
        out.push_back(character());
      } else {
        out.push_back(punctuator());
      }
    }
    out.push_back({Token::Kind::End, "", s_.size()});
    return out;
  }

 private:
  [[noreturn]] void fail(size_t at, const std::string& what) const {
    throw Error(fmt::format("{} at column {} of '{}'", what, at + 1, s_));
  }

  // A pp-number as C's lexer takes it, then its value and type.
  Token number() {
    const size_t start = i_;
    const bool hexDigits = s_.compare(i_, 2, "0x") == 0 || s_.compare(i_, 2, "0X") == 0;
    while (i_ < s_.size()) {
      const char c = s_[i_];
      const bool sign =
          (c == '+' || c == '-') && !hexDigits && (s_[i_ - 1] == 'e' || s_[i_ - 1] == 'E');
      if (!isNameChar(c) && c != '.' && !sign) break;
      ++i_;
    }
    const std::string text = s_.substr(start, i_ - start);
    Token t{Token::Kind::Integer, text, start};
    const bool hex = text.size() > 1 && text[0] == '0' && (text[1] == 'x' || text[1] == 'X');
    if (!hex && text.find_first_of(".eE") != std::string::npos) {
      // digits [. digits] [e [+-] digits] [f F l L]
      size_t k = 0;
      while (k < text.size() && isDigit(text[k])) ++k;
      if (k < text.size() && text[k] == '.') {
        ++k;
        while (k < text.size() && isDigit(text[k])) ++k;
      }
      if (k < text.size() && (text[k] == 'e' || text[k] == 'E')) {
        size_t e = k + 1;
        if (e < text.size() && (text[e] == '+' || text[e] == '-')) ++e;
        if (e >= text.size() || !isDigit(text[e])) fail(start, "exponent has no digits");
        while (e < text.size() && isDigit(text[e])) ++e;
        k = e;
      }
      const std::string suffix = text.substr(k);
      if (!(suffix.empty() || suffix == "f" || suffix == "F" || suffix == "l" || suffix == "L"))
        fail(start, fmt::format("invalid suffix '{}' on floating constant", suffix));
      const double d = std::strtod(text.substr(0, k).c_str(), nullptr);
      if (!(d <= 3.4028234663852886e38)) fail(start, "floating constant is too large");
      t.kind = Token::Kind::Real;
      t.real = static_cast<float>(d);
      return t;
    }
    int base = 10;
    size_t k = 0;
    if (hex) {
      base = 16;
      k = 2;
    } else if (text.size() > 1 && text[0] == '0') {
      base = 8;
      k = 1;
    }
    const size_t digits = k;
    uint64_t value = 0;
    bool tooLarge = false;
    for (; k < text.size(); ++k) {
      const char c = static_cast<char>(std::tolower(static_cast<unsigned char>(text[k])));
      int d = -1;
      if (isDigit(c)) d = c - '0';
      if (base == 16 && c >= 'a' && c <= 'f') d = c - 'a' + 10;
      if (d < 0) break;
      if (base == 8 && d > 7) fail(start, fmt::format("invalid digit '{}' in octal constant", c));
      value = value * static_cast<uint64_t>(base) + static_cast<uint64_t>(d);
      if (value > 0xFFFFFFFFull) {
        tooLarge = true;
        value = 0x100000000ull;  // keeps the sum from overflowing
      }
    }
    if (hex && k == digits) fail(start, fmt::format("invalid integer constant '{}'", text));
    bool u = false, l = false;
    for (size_t j = k; j < text.size(); ++j) {
      const char c = text[j];
      if ((c == 'u' || c == 'U') && !u)
        u = true;
      else if ((c == 'l' || c == 'L') && !l)
        l = true;
      else
        fail(start, fmt::format("invalid suffix '{}' on integer constant", text.substr(k)));
    }
    // The robot's constants are at most 32 bits: a larger one is refused,
    // not wrapped (buf[9223372036854775807] means what it says).
    if (tooLarge)
      fail(start, fmt::format("integer constant '{}' is too large (at most 0xFFFFFFFF)", text));
    t.arith = compiler::constantArith(value, base == 10, u, l);
    t.integer = compiler::wrapArith(static_cast<int64_t>(value), t.arith);
    return t;
  }

  // 'c', '\n', '\x41', '\101': an int, the unsigned char's value.
  Token character() {
    const size_t start = i_++;
    if (i_ >= s_.size() || s_[i_] == '\'') fail(start, "empty character constant");
    int value = static_cast<unsigned char>(s_[i_++]);
    if (value == '\\') {
      if (i_ >= s_.size()) fail(start, "unterminated character constant");
      const char e = s_[i_++];
      if (e == 'x') {
        int digits = 0;
        value = 0;
        for (; digits < 2 && i_ < s_.size() && std::isxdigit(static_cast<unsigned char>(s_[i_]));
             ++digits) {
          const char h = static_cast<char>(std::tolower(static_cast<unsigned char>(s_[i_++])));
          value = value * 16 + (isDigit(h) ? h - '0' : h - 'a' + 10);
        }
        if (!digits) fail(start, "\\x used with no following hex digits");
      } else if (e >= '0' && e <= '7') {
        value = e - '0';
        for (int digits = 1; digits < 3 && i_ < s_.size() && s_[i_] >= '0' && s_[i_] <= '7';
             ++digits)
          value = value * 8 + (s_[i_++] - '0');
        value &= 0xFF;
      } else {
        value = simpleEscape(e);
        if (value < 0) fail(start, fmt::format("unknown escape sequence '\\{}'", e));
      }
    }
    if (i_ >= s_.size() || s_[i_] != '\'') fail(start, "a character constant holds one character");
    ++i_;
    Token t{Token::Kind::Integer, s_.substr(start, i_ - start), start};
    t.integer = value;
    return t;
  }

  static int simpleEscape(char e) {
    switch (e) {
      case 'n':
        return '\n';
      case 't':
        return '\t';
      case 'r':
        return '\r';
      case 'a':
        return '\a';
      case 'b':
        return '\b';
      case 'f':
        return '\f';
      case 'v':
        return '\v';
      case '\\':
      case '\'':
      case '"':
      case '?':
        return e;
      default:
        return -1;
    }
  }

  Token punctuator() {
    static const char* const kOps[] = {"::", "->", "<<", ">>", "<=", ">=", "==", "!=", "&&", "||",
                                       "[",  "]",  "(",  ")",  ".",  "*",  "&",  "-",  "+",  "/",
                                       "%",  "!",  "~",  "<",  ">",  "@",  "^",  "|",  "?",  ":"};
    for (const char* op : kOps) {
      const size_t n = std::strlen(op);
      if (s_.compare(i_, n, op) == 0) {
        Token t{Token::Kind::Op, op, i_};
        i_ += n;
        return t;
      }
    }
    const auto c = static_cast<unsigned char>(s_[i_]);
    if (c >= 0x20 && c < 0x7F) fail(i_, fmt::format("unexpected '{}'", static_cast<char>(c)));
    fail(i_, fmt::format("unexpected byte 0x{:02X}", c));
  }

  const std::string& s_;
  size_t i_ = 0;
};

bool isTypeWord(const std::string& w) {
  static const char* const kWords[] = {"void",  "char",   "short",   "int",      "long",
                                       "float", "double", "signed",  "unsigned", "struct",
                                       "union", "const",  "volatile"};
  for (const char* k : kWords)
    if (w == k) return true;
  return false;
}

using NodePtr = std::unique_ptr<Node>;

class Parser {
 public:
  explicit Parser(const std::string& text) : text_(text), tokens_(Lexer(text).run()) {}

  NodePtr parse() {
    NodePtr n = expr();
    if (cur().kind != Token::Kind::End) fail("unexpected '" + cur().text + "'");
    return n;
  }

  std::optional<TypeName> parseTypeName() {
    if (cur().kind != Token::Kind::Name || !isTypeWord(cur().text)) return std::nullopt;
    TypeName t = typeName();
    if (cur().kind != Token::Kind::End) fail("unexpected '" + cur().text + "'");
    return t;
  }

 private:
  const Token& cur() const { return tokens_[i_]; }
  const Token& peek(size_t k) const { return tokens_[std::min(i_ + k, tokens_.size() - 1)]; }
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
  // A depth counter, not the C++ stack, bounds the recursion.
  struct Depth {
    Parser& p;
    explicit Depth(Parser& parser) : p(parser) {
      if (++p.depth_ > kMaxNesting) p.fail("expression nested too deeply");
    }
    ~Depth() { --p.depth_; }
  };

  // Every node is made here, and its height checked.
  NodePtr make(Node::Kind kind, NodePtr a = nullptr, NodePtr b = nullptr, NodePtr c = nullptr) {
    int h = 0;
    for (const NodePtr* child : {&a, &b, &c})
      if (*child) h = std::max(h, (*child)->height);
    if (h + 1 > kMaxTreeHeight) fail("expression nested too deeply");
    auto n = std::make_unique<Node>();
    n->kind = kind;
    n->height = h + 1;
    n->a = std::move(a);
    n->b = std::move(b);
    n->c = std::move(c);
    return n;
  }
  NodePtr binary(Op op, NodePtr a, NodePtr b) {
    NodePtr n = make(Node::Kind::Binary, std::move(a), std::move(b));
    n->op = op;
    return n;
  }

  // expr := cond
  NodePtr expr() { return conditional(); }

  // cond := logor ("?" expr ":" cond)?
  NodePtr conditional() {
    NodePtr c = binaryLevel(0);
    if (!accept("?")) return c;
    const Depth depth(*this);
    NodePtr a = expr();
    expect(":");
    NodePtr b = conditional();
    return make(Node::Kind::Conditional, std::move(c), std::move(a), std::move(b));
  }

  // The binary operators, loosest first; all associate to the left:
  //   logor      := logand ("||" logand)*
  //   logand     := bitor ("&&" bitor)*
  //   bitor      := bitxor ("|" bitxor)*
  //   bitxor     := bitand ("^" bitand)*
  //   bitand     := equality ("&" equality)*
  //   equality   := relational (("==" | "!=") relational)*
  //   relational := shift (("<" | "<=" | ">" | ">=") shift)*
  //   shift      := slice (("<<" | ">>") slice)*
  //   slice      := additive ("@" additive)*
  //   additive   := term (("+" | "-") term)*
  //   term       := cast (("*" | "/" | "%") cast)*
  struct Level {
    const char* spellings[4];
    Op ops[4];
  };
  static constexpr Level kLevels[] = {
      {{"||"}, {Op::LogOr}},
      {{"&&"}, {Op::LogAnd}},
      {{"|"}, {Op::BitOr}},
      {{"^"}, {Op::BitXor}},
      {{"&"}, {Op::BitAnd}},
      {{"==", "!="}, {Op::Eq, Op::Ne}},
      {{"<", "<=", ">", ">="}, {Op::Lt, Op::Le, Op::Gt, Op::Ge}},
      {{"<<", ">>"}, {Op::Shl, Op::Shr}},
      {{"@"}, {Op::Slice}},
      {{"+", "-"}, {Op::Add, Op::Sub}},
      {{"*", "/", "%"}, {Op::Mul, Op::Div, Op::Mod}},
  };
  static constexpr size_t kLevelCount = sizeof kLevels / sizeof kLevels[0];

  NodePtr binaryLevel(size_t level) {
    if (level == kLevelCount) return cast();
    NodePtr n = binaryLevel(level + 1);
    for (;;) {
      const Level& l = kLevels[level];
      bool matched = false;
      for (size_t k = 0; k < 4 && l.spellings[k]; ++k) {
        if (accept(l.spellings[k])) {
          n = binary(l.ops[k], std::move(n), binaryLevel(level + 1));
          matched = true;
          break;
        }
      }
      if (!matched) return n;
    }
  }

  // cast := "(" type-name ")" cast | unary
  NodePtr cast() {
    if (isOp("(") && peek(1).kind == Token::Kind::Name && isTypeWord(peek(1).text)) {
      const Depth depth(*this);
      ++i_;
      TypeName t = typeName();
      expect(")");
      NodePtr n = make(Node::Kind::Cast, cast());
      n->type = std::move(t);
      return n;
    }
    return unary();
  }

  // unary := ("+" | "-" | "!" | "~" | "*" | "&") cast
  //        | "sizeof" "(" type-name ")" | "sizeof" unary | postfix
  NodePtr unary() {
    static const std::pair<const char*, Op> kPrefix[] = {{"+", Op::Plus},  {"-", Op::Minus},
                                                         {"!", Op::Not},   {"~", Op::BitNot},
                                                         {"*", Op::Deref}, {"&", Op::Address}};
    for (const auto& [spelling, op] : kPrefix) {
      if (accept(spelling)) {
        const Depth depth(*this);
        NodePtr n = make(Node::Kind::Unary, cast());
        n->op = op;
        return n;
      }
    }
    if (cur().kind == Token::Kind::Name && cur().text == "sizeof") {
      const Depth depth(*this);
      ++i_;
      if (isOp("(") && peek(1).kind == Token::Kind::Name && isTypeWord(peek(1).text)) {
        ++i_;
        NodePtr n = make(Node::Kind::SizeofType);
        n->type = typeName();
        expect(")");
        return n;
      }
      return make(Node::Kind::SizeofExpr, unary());
    }
    return postfix();
  }

  // type-name := type-word+ "*"*     (or "struct" TAG, "union" TAG, then "*"*)
  TypeName typeName() {
    TypeName t;
    int counter = 0;
    for (;;) {
      if (cur().kind != Token::Kind::Name || !isTypeWord(cur().text)) break;
      const std::string w = cur().text;
      ++i_;
      namespace tw = compiler::typeword;
      if (w == "const" || w == "volatile") continue;
      if (w == "struct" || w == "union") {
        if (counter) fail("invalid combination of type specifiers");
        if (cur().kind != Token::Kind::Name) fail(fmt::format("expected a tag after '{}'", w));
        t.tag = w + " " + cur().text;
        ++i_;
        counter += tw::kOther;
        continue;
      }
      if (counter & tw::kOther) fail("invalid combination of type specifiers");
      if (w == "long" && (counter & tw::kLong)) fail("long long is not supported");
      if (w == "void") counter += tw::kVoid;
      if (w == "char") counter += tw::kChar;
      if (w == "short") counter += tw::kShort;
      if (w == "int") counter += tw::kInt;
      if (w == "long") counter += tw::kLong;
      if (w == "float") counter += tw::kFloat;
      if (w == "double") counter += tw::kDouble;
      if (w == "signed") counter |= tw::kSigned;
      if (w == "unsigned") counter |= tw::kUnsigned;
      if (counter != tw::kVoid && !compiler::typeWordsArith(counter))
        fail("invalid combination of type specifiers");
    }
    if (counter == compiler::typeword::kVoid)
      t.isVoid = true;
    else if (t.tag.empty())
      t.arith = *compiler::typeWordsArith(counter);
    while (accept("*")) {
      if (++t.pointers > kMaxPointerStars) fail("too many '*' in a type name");
    }
    if (isOp("[") || isOp("("))
      fail("array and function types are not supported in a type name here");
    return t;
  }

  // postfix := primary ("[" expr "]" | "." NAME | "->" NAME)*
  NodePtr postfix() {
    NodePtr n = primary();
    for (;;) {
      if (accept("[")) {
        const Depth depth(*this);
        NodePtr index = expr();
        expect("]");
        n = make(Node::Kind::Index, std::move(n), std::move(index));
      } else if (isOp(".") || isOp("->")) {
        const bool arrow = isOp("->");
        ++i_;
        if (cur().kind != Token::Kind::Name) fail("expected a member name");
        n = make(arrow ? Node::Kind::Arrow : Node::Kind::Member, std::move(n));
        n->name = cur().text;
        ++i_;
      } else {
        return n;
      }
    }
  }

  // primary := NAME | FUNCTION "::" NAME | NUMBER | CHAR | "(" expr ")"
  NodePtr primary() {
    const Token t = cur();
    if (t.kind == Token::Kind::Integer || t.kind == Token::Kind::Real) {
      ++i_;
      NodePtr n = make(t.kind == Token::Kind::Integer ? Node::Kind::Integer : Node::Kind::Real);
      n->arith = t.kind == Token::Kind::Integer ? t.arith : Arith::Float;
      n->integer = t.integer;
      n->real = t.real;
      return n;
    }
    if (t.kind == Token::Kind::Name) {
      if (t.text == "sizeof" || isTypeWord(t.text))
        fail(fmt::format("unexpected type word '{}'", t.text));
      ++i_;
      NodePtr n = make(Node::Kind::Name);
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
      const Depth depth(*this);
      NodePtr n = expr();
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

}  // namespace

const char* spelling(Op op) {
  switch (op) {
    case Op::Plus:
    case Op::Add:
      return "+";
    case Op::Minus:
    case Op::Sub:
      return "-";
    case Op::Not:
      return "!";
    case Op::BitNot:
      return "~";
    case Op::Deref:
    case Op::Mul:
      return "*";
    case Op::Address:
    case Op::BitAnd:
      return "&";
    case Op::Div:
      return "/";
    case Op::Mod:
      return "%";
    case Op::Slice:
      return "@";
    case Op::Shl:
      return "<<";
    case Op::Shr:
      return ">>";
    case Op::Lt:
      return "<";
    case Op::Le:
      return "<=";
    case Op::Gt:
      return ">";
    case Op::Ge:
      return ">=";
    case Op::Eq:
      return "==";
    case Op::Ne:
      return "!=";
    case Op::BitXor:
      return "^";
    case Op::BitOr:
      return "|";
    case Op::LogAnd:
      return "&&";
    case Op::LogOr:
      return "||";
  }
  return "?";
}

std::string TypeName::text() const {
  std::string base;
  if (isVoid) {
    base = "void";
  } else if (!tag.empty()) {
    base = tag;
  } else {
    static const char* const kNames[] = {"char", "signed char",   "int",  "unsigned int",
                                         "long", "unsigned long", "float"};
    base = kNames[static_cast<int>(arith)];
  }
  if (pointers) base += " " + std::string(static_cast<size_t>(pointers), '*');
  return base;
}

namespace {
void checkLength(const std::string& text) {
  if (text.size() > kMaxExpressionChars)
    throw Error(fmt::format("an expression of {} characters (at most {})", text.size(),
                            kMaxExpressionChars));
}
}  // namespace

std::unique_ptr<Node> parse(const std::string& text) {
  checkLength(text);
  return Parser(text).parse();
}

std::optional<TypeName> parseTypeName(const std::string& text) {
  checkLength(text);
  return Parser(text).parseTypeName();
}

}  // namespace simbot::inspect
