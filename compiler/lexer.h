// Tokens and the lexer (internal to the compiler).
//
// The lexer is lazy: the preprocessor pulls one token at a time, so an error
// late in the file (an unterminated comment) cannot hide an earlier one, and
// the text inside a skipped #if group or after #asm is never lexed strictly.
// Numbers are kept as preprocessing numbers (their spelling); the parser gives
// them a value and a type, because #if needs the same spelling rules.
#pragma once
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "compiler/diagnostics.h"

namespace simbot::compiler {

enum class TokKind : unsigned char { Ident, Number, Char, String, Punct, Pragma, Eof };

// Names of the macros a token must not be expanded by (the "hide set" of
// Prosser's algorithm, as in chibicc); shared between copies, never mutated.
using HideSet = std::shared_ptr<const std::vector<std::string>>;

struct Token {
  TokKind kind = TokKind::Eof;
  std::string text;  // spelling; for Pragma the directive ("class auto")
  std::string str;   // String/Char: the bytes after escape processing
  Pos pos;
  bool bol = false;       // first token on its source line
  bool space = false;     // white space before it (for # stringizing)
  bool fromFile = false;  // lexed from the file, not made by an expansion
  HideSet hide;

  bool is(std::string_view s) const {
    return (kind == TokKind::Punct || kind == TokKind::Ident) && text == s;
  }
};

class Lexer {
 public:
  explicit Lexer(std::string_view src) : src_(src) {}
  // The next token. `lenient` (inside skipped #if groups): stray characters
  // and unterminated quotes are not errors; unterminated comments still are.
  Token next(bool lenient = false);

 private:
  char peekc(size_t k = 0) const { return pos_ + k < src_.size() ? src_[pos_ + k] : '\0'; }
  bool atEnd(size_t k = 0) const { return pos_ + k >= src_.size(); }
  void advance(size_t n = 1);
  bool skipSplice();
  void lexQuoted(Token& t, char quote, bool lenient);
  int lexEscape(bool lenient);

  std::string_view src_;
  size_t pos_ = 0;
  int line_ = 1;
  int col_ = 1;
  bool bol_ = true;
};

// The value of a preprocessing number, with what its spelling says about its
// type (the parser applies Dynamic C's typing rules). Throws on a malformed
// number or one too large for 32 bits.
struct NumberValue {
  bool isFloat = false;
  uint64_t value = 0;  // integers
  double fvalue = 0;   // floats
  bool decimal = true;
  bool suffixU = false;
  bool suffixL = false;
};
NumberValue parseNumber(const Token& t);

// Lex `text` as exactly one token (## pasting); nullopt if it is not one.
std::optional<Token> lexSingle(const std::string& text);

}  // namespace simbot::compiler
