// Internal error plumbing shared by every stage of the compiler.
//
// The compiler reports the first error only (the tool contract), so each
// stage simply throws a CompileError carrying the position in the user's
// source; compile() catches it and turns it into the public Diagnostic.
// Positions are 1-based lines and byte columns of the ORIGINAL source text;
// tokens produced by a macro expansion carry the invocation's position.
#pragma once
#include <string>

namespace simbot::compiler {

struct Pos {
  int line = 1;
  int col = 1;
  int len = 1;  // bytes of the token on its line (for "after this token")
};

struct CompileError {
  Pos pos;
  std::string message;
};

[[noreturn]] inline void fail(Pos pos, std::string message) {
  throw CompileError{pos, std::move(message)};
}

// The position just after a token, for "expected ';'" style errors.
inline Pos after(Pos p) { return Pos{p.line, p.col + p.len, 1}; }

}  // namespace simbot::compiler
