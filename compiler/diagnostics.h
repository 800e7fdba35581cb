// Internal error plumbing shared by every stage of the compiler.
//
// A stage that meets an error throws a CompileError carrying the position in
// the user's source. The parser catches it at the next statement or
// declaration boundary, records it in the Diagnostics collector and goes on
// (panic-mode recovery), so one compilation reports every error of a file,
// at most one per statement. Errors of the preprocessor and the lexer, and
// those the parser cannot step over (end of input, nesting limits), end the
// compilation: the token stream after them cannot be trusted.
// Positions are 1-based lines and byte columns of the ORIGINAL source text;
// tokens produced by a macro expansion carry the invocation's position.
#pragma once
#include <string>
#include <vector>

namespace simbot::compiler {

struct Pos {
  int line = 1;
  int col = 1;
  int len = 1;  // bytes of the token on its line (for "after this token")
};

struct CompileError {
  Pos pos;
  std::string message;
  // An error that only follows from an earlier one (a use of a name whose
  // declaration failed): it unwinds to the recovery point like any error but
  // is not reported.
  bool silent = false;
};

// Thrown once the compilation cannot go on; what ends it is already recorded.
struct StopCompiling {};

[[noreturn]] inline void fail(Pos pos, std::string message) {
  throw CompileError{pos, std::move(message)};
}

// The position just after a token, for "expected ';'" style errors.
inline Pos after(Pos p) { return Pos{p.line, p.col + p.len, 1}; }

// Errors reported before the compiler stops: past this many, the rest of a
// file is usually noise caused by the first ones (clang's default is 20).
inline constexpr int kMaxErrors = 50;

struct RawDiagnostic {
  Pos pos;
  std::string message;
  std::string warning;  // empty: an error; else the warning's name
};

class Diagnostics {
 public:
  // Records an error; throws StopCompiling once kMaxErrors are recorded.
  void error(Pos pos, std::string message);
  // Records an error and ends the compilation.
  [[noreturn]] void fatal(Pos pos, std::string message);
  void warn(Pos pos, const char* name, std::string message);
  int errorCount() const { return errors_; }
  const std::vector<RawDiagnostic>& all() const { return items_; }

 private:
  std::vector<RawDiagnostic> items_;
  int errors_ = 0;
};

}  // namespace simbot::compiler
