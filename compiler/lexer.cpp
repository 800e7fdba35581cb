// The lexer: bytes of the source in, tokens with their original line and
// column out. It knows C's token shapes (identifiers, preprocessing numbers,
// character constants and strings with escapes, punctuators) and skips white
// space, comments and backslash-newline splices. Anything else is an
// "invalid character" at its exact position; an unterminated comment, string
// or character constant is reported at its start.
#include "compiler/lexer.h"

#include <array>
#include <cctype>
#include <cstdlib>

namespace simbot::compiler {

namespace {

bool isIdentStart(char c) { return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_'; }
bool isIdentChar(char c) { return isIdentStart(c) || (c >= '0' && c <= '9'); }
bool isDigit(char c) { return c >= '0' && c <= '9'; }
int hexValue(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

// Longest first, so that ">>=" wins over ">>" and ">".
constexpr std::array<std::string_view, 48> kPuncts = {
    "<<=", ">>=", "...", "->", "++", "--", "<<", ">>", "<=", ">=", "==", "!=",
    "&&",  "||",  "+=",  "-=", "*=", "/=", "%=", "&=", "|=", "^=", "##", "+",
    "-",   "*",   "/",   "%",  "&",  "|",  "^",  "~",  "!",  "=",  "<",  ">",
    "?",   ":",   ";",   ",",  ".",  "(",  ")",  "[",  "]",  "{",  "}",  "#"};

}  // namespace

void Lexer::advance(size_t n) {
  for (size_t i = 0; i < n && pos_ < src_.size(); ++i) {
    if (src_[pos_] == '\n') {
      ++line_;
      col_ = 1;
    } else {
      ++col_;
    }
    ++pos_;
  }
}

// A backslash at the end of a line joins it to the next (C's line splice).
bool Lexer::skipSplice() {
  if (peekc() != '\\') return false;
  if (peekc(1) == '\n') {
    advance(2);
    return true;
  }
  if (peekc(1) == '\r' && peekc(2) == '\n') {
    advance(3);
    return true;
  }
  return false;
}

// One escape sequence after the backslash (already consumed); its byte value.
int Lexer::lexEscape(bool lenient) {
  Pos at{line_, col_ - 1, 1};
  char c = peekc();
  if (atEnd()) return '\\';
  if (c >= '0' && c <= '7') {
    int v = 0;
    for (int i = 0; i < 3 && peekc() >= '0' && peekc() <= '7'; ++i) {
      v = v * 8 + (peekc() - '0');
      advance();
    }
    if (v > 0xFF && !lenient) fail(at, "octal escape sequence out of range");
    return v & 0xFF;
  }
  if (c == 'x') {
    advance();
    if (hexValue(peekc()) < 0) {
      if (!lenient) fail(at, "\\x used with no following hex digits");
      return 0;
    }
    int v = 0;
    bool overflow = false;
    while (!atEnd() && hexValue(peekc()) >= 0) {
      v = v * 16 + hexValue(peekc());
      if (v > 0xFF) overflow = true;
      v &= 0xFFF;
      advance();
    }
    if (overflow && !lenient) fail(at, "hex escape sequence out of range");
    return v & 0xFF;
  }
  advance();
  switch (c) {
    case 'n':
      return '\n';
    case 't':
      return '\t';
    case 'r':
      return '\r';
    case 'a':
      return 7;
    case 'b':
      return 8;
    case 'f':
      return 12;
    case 'v':
      return 11;
    case 'e':
      return 27;
    default:
      return static_cast<unsigned char>(c);  // \\ \' \" \? and unknown
  }
}

// A string literal or character constant: the opening quote is current.
void Lexer::lexQuoted(Token& t, char quote, bool lenient) {
  size_t start = pos_;
  Pos at = t.pos;
  advance();
  for (;;) {
    if (skipSplice()) continue;
    char c = peekc();
    if (atEnd() || c == '\n') {
      if (!lenient)
        fail(at, quote == '"' ? "unterminated string literal" : "unterminated character constant");
      break;
    }
    if (c == quote) {
      advance();
      break;
    }
    if (c == '\\') {
      advance();
      t.str += static_cast<char>(lexEscape(lenient));
      continue;
    }
    t.str += c;
    advance();
  }
  t.text = std::string(src_.substr(start, pos_ - start));
}

Token Lexer::next(bool lenient) {
  bool space = false;
  for (;;) {
    if (atEnd()) break;
    char c = peekc();
    if (c == '\n') {
      advance();
      bol_ = true;
      space = false;
      continue;
    }
    if (c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v') {
      advance();
      space = true;
      continue;
    }
    if (skipSplice()) {
      space = true;
      continue;
    }
    if (c == '/' && peekc(1) == '/') {
      while (!atEnd() && peekc() != '\n') advance();
      space = true;
      continue;
    }
    if (c == '/' && peekc(1) == '*') {
      Pos at{line_, col_, 2};
      size_t end = src_.find("*/", pos_ + 2);
      if (end == std::string_view::npos) fail(at, "unterminated comment");
      advance(end + 2 - pos_);
      space = true;
      continue;
    }
    break;
  }

  Token t;
  t.pos = Pos{line_, col_, 1};
  t.bol = bol_;
  t.space = space;
  t.fromFile = true;
  bol_ = false;
  if (atEnd()) {
    t.kind = TokKind::Eof;
    return t;
  }
  size_t start = pos_;
  char c = peekc();

  if (isDigit(c) || (c == '.' && isDigit(peekc(1)))) {
    // A preprocessing number: digits, letters, '.', and a sign after e/E/p/P.
    t.kind = TokKind::Number;
    for (;;) {
      char d = peekc();
      if ((d == 'e' || d == 'E' || d == 'p' || d == 'P') && (peekc(1) == '+' || peekc(1) == '-')) {
        advance(2);
      } else if (!atEnd() && (isIdentChar(d) || d == '.')) {
        advance();
      } else {
        break;
      }
    }
  } else if (isIdentStart(c)) {
    t.kind = TokKind::Ident;
    while (!atEnd() && isIdentChar(peekc())) advance();
  } else if (c == '"' || c == '\'') {
    t.kind = c == '"' ? TokKind::String : TokKind::Char;
    lexQuoted(t, c, lenient);
    t.pos.len = t.pos.line == line_ ? static_cast<int>(pos_ - start) : 1;
    return t;
  } else {
    t.kind = TokKind::Punct;
    bool found = false;
    for (std::string_view p : kPuncts) {
      if (src_.substr(pos_, p.size()) == p) {
        advance(p.size());
        found = true;
        break;
      }
    }
    if (!found) {
      if (!lenient) fail(t.pos, "invalid character");
      advance();  // junk token, only seen by a skipped group
    }
  }
  t.text = std::string(src_.substr(start, pos_ - start));
  t.pos.len = static_cast<int>(pos_ - start);
  return t;
}

std::optional<Token> lexSingle(const std::string& text) {
  try {
    Lexer lex(text);
    Token t = lex.next();
    if (t.kind == TokKind::Eof || t.space) return std::nullopt;
    Token rest = lex.next();
    if (rest.kind != TokKind::Eof || rest.space) return std::nullopt;
    return t;
  } catch (const CompileError&) {
    return std::nullopt;
  }
}

}  // namespace simbot::compiler

namespace simbot::compiler {

NumberValue parseNumber(const Token& t) {
  const std::string& s = t.text;
  NumberValue v;
  bool hex = s.size() > 1 && s[0] == '0' && (s[1] == 'x' || s[1] == 'X');
  bool isFloat = !hex && (s.find('.') != std::string::npos || s.find('e') != std::string::npos ||
                          s.find('E') != std::string::npos);
  if (isFloat) {
    // digits [. digits] [e [+-] digits] [f F l L]
    size_t i = 0;
    while (i < s.size() && isDigit(s[i])) ++i;
    if (i < s.size() && s[i] == '.') {
      ++i;
      while (i < s.size() && isDigit(s[i])) ++i;
    }
    if (i < s.size() && (s[i] == 'e' || s[i] == 'E')) {
      size_t e = i + 1;
      if (e < s.size() && (s[e] == '+' || s[e] == '-')) ++e;
      if (e >= s.size() || !isDigit(s[e])) fail(t.pos, "exponent has no digits");
      while (e < s.size() && isDigit(s[e])) ++e;
      i = e;
    }
    std::string mant = s.substr(0, i);
    std::string suffix = s.substr(i);
    if (!(suffix.empty() || suffix == "f" || suffix == "F" || suffix == "l" || suffix == "L"))
      fail(t.pos, "invalid suffix '" + suffix + "' on floating constant");
    v.isFloat = true;
    v.fvalue = std::strtod(mant.c_str(), nullptr);
    if (!(v.fvalue <= 3.4028234663852886e38)) fail(t.pos, "floating constant is too large");
    return v;
  }
  size_t i = 0;
  int base = 10;
  if (hex) {
    base = 16;
    i = 2;
    v.decimal = false;
  } else if (s.size() > 1 && s[0] == '0') {
    base = 8;
    i = 1;
    v.decimal = false;
  }
  size_t digitsStart = i;
  uint64_t value = 0;
  bool tooLarge = false;
  for (; i < s.size(); ++i) {
    int d = hexValue(s[i]);
    if (d < 0 || (base == 10 && d > 9) || (base == 8 && d > 9)) break;
    if (base == 8 && d > 7)
      fail(t.pos, std::string("invalid digit '") + s[i] + "' in octal constant");
    value = value * base + d;
    if (value > 0xFFFFFFFFull) {
      tooLarge = true;
      value = 0xFFFFFFFFull + 1;
    }
  }
  if (hex && i == digitsStart) fail(t.pos, "invalid integer constant '" + s + "'");
  std::string suffix = s.substr(i);
  for (char c : suffix) {
    if ((c == 'u' || c == 'U') && !v.suffixU) {
      v.suffixU = true;
    } else if ((c == 'l' || c == 'L') && !v.suffixL) {
      v.suffixL = true;
    } else if (c == 'l' || c == 'L') {
      fail(t.pos, "long long is not supported");
    } else {
      fail(t.pos, "invalid suffix '" + suffix + "' on integer constant");
    }
  }
  if (tooLarge) fail(t.pos, "integer constant is too large");
  v.value = value;
  return v;
}

}  // namespace simbot::compiler
