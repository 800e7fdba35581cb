// The preprocessor (internal): a token stream with directives executed and
// macros expanded. The parser pulls tokens one at a time with next().
//
// Dynamic C directives that change code generation rather than text
// (#class auto/static, #nodebug/#debug) come out as Pragma tokens in stream
// order, so the parser applies them exactly where they stood. #INT_VEC
// bindings are collected for the end of compilation, when their handler
// names can be resolved.
#pragma once
#include <algorithm>
#include <map>
#include <string>
#include <string_view>
#include <tuple>
#include <unordered_map>
#include <vector>

#include "compiler/diagnostics.h"
#include "compiler/lexer.h"

namespace simbot::compiler {

struct IntVecDirective {
  Pos pos;           // the '#'
  int vector = -1;   // IM2 vector byte
  std::string name;  // handler name
  Pos namePos;
};

class Preprocessor {
 public:
  // Warnings of directives (define-int-vec) go to `diags`; errors are thrown.
  Preprocessor(std::string_view src, std::string fileName, Diagnostics& diags);
  // The next token after preprocessing; Eof (repeatedly) at the end.
  Token next();
  const std::vector<IntVecDirective>& intVecs() const { return intVecs_; }
  // Whether a #use or #include has named `library` (lower case, as
  // "math.lib") so far.
  bool uses(std::string_view library) const {
    return std::find(used_.begin(), used_.end(), library) != used_.end();
  }

 private:
  struct Macro {
    bool funcLike = false;
    bool variadic = false;
    std::vector<std::string> params;
    std::vector<Token> body;
  };
  struct Cond {
    Pos pos;
    bool included = false;  // some branch has been taken
    bool inElse = false;
  };

  Token raw(bool lenient = false);
  void unget(Token t) { pending_.push_back(std::move(t)); }
  std::vector<Token> readLine(bool lenient = false);
  void skipLine() { readLine(true); }
  void directive(const Token& hash);
  void skipGroup();
  void define(const Token& nameTok, const std::vector<Token>& line);
  bool evalIf(const Token& dirTok, std::vector<Token> line);
  std::string libraryName(const Token& dirTok, const std::vector<Token>& line);
  void intVec(const Token& hash, const std::vector<Token>& line);
  bool expand(const Token& t);
  std::vector<Token> expandList(std::vector<Token> toks, const Token& at);
  std::vector<Token> substitute(const Macro& m, const std::vector<std::vector<Token>>& args,
                                const Token& at);
  void pushExpansion(std::vector<Token> toks, const HideSet& hs, const Token& at);
  HideSet hideUnion(const HideSet& a, const HideSet& b, Pos at);
  HideSet hideIntersection(const HideSet& a, const HideSet& b, Pos at);
  HideSet hideAdd(const HideSet& a, const std::string& name, Pos at);
  HideSet hideMade(char op, const HideSet& a, const HideSet& b, std::vector<std::string> names,
                   Pos at);

  Lexer lex_;
  std::string fileName_;
  Diagnostics& diags_;
  std::vector<Token> pending_;  // pushed-back or expanded tokens, back() first
  bool noLexer_ = false;        // expanding an isolated token list
  std::unordered_map<std::string, Macro> macros_;
  std::vector<Cond> conds_;
  std::vector<IntVecDirective> intVecs_;
  std::vector<std::string> used_;  // libraries named by #use / #include
  int expandDepth_ = 0;
  long expandedTokens_ = 0;
  // The tokens of a macro invocation in the file, expanded in full before
  // the first is handed on; next() returns them from ready_[readyAt_].
  std::vector<Token> ready_;
  size_t readyAt_ = 0;
  // Every hide set made, by the operation ('|', '&') and the sets it was
  // made of, so that the same operation gives the same shared set; the
  // entries hold their operands, so an address is never reused as a key.
  struct HideMemo {
    HideSet a, b, made;
  };
  std::map<std::tuple<char, const void*, const void*>, HideMemo> hideMemo_;
  std::unordered_map<std::string, HideSet> hideSingles_;  // {name}, one per macro name
  long hideNames_ = 0;  // names held by the sets made (and a charge per set)
};

}  // namespace simbot::compiler
