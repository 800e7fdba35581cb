// The Dynamic C compiler: source text in, Image out.
// Stages (one file each): preprocess.cpp, lexer.cpp, parser.cpp (builds the
// AST and checks types), codegen.cpp (emits bytecode), disasm lives in vm/.
#pragma once
#include <cstddef>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "vm/image.h"

namespace simbot::compiler {

enum class Severity { Error, Warning };

struct Diagnostic {
  std::string file;
  int line = 0;
  int column = 0;
  std::string message;
  std::string sourceLine;     // the offending line's text, without newline
  bool hasSourceLine = true;  // false: about the file as a whole (one line only)
  Severity severity = Severity::Error;
  // A warning's name (the NAME of -Wno-NAME); kept on a warning that
  // -Werror made an error. Empty for a plain error.
  std::string warning;
  // "FILE:LINE:COL: error: MESSAGE\nSOURCE LINE\n    ^\n"; a warning reads
  // "warning: MESSAGE [-WNAME]", one promoted by -Werror
  // "error: MESSAGE [-Werror=NAME]".
  std::string format() const;
};

// The warnings, by name (docs/language.md, "Warnings", says what each means).
struct WarningInfo {
  std::string_view name;
  std::string_view summary;
};
const std::vector<WarningInfo>& warningList();
bool isWarningName(std::string_view name);

struct Options {
  // Debug build: a DBG (RST 28h) at the start of every statement, except in
  // `nodebug` functions or after `#nodebug`. Dynamic C's default.
  bool debug = true;
  std::set<std::string> disabledWarnings;  // names from warningList()
  bool werror = false;                     // every warning is an error
};

struct Result {
  std::optional<vm::Image> image;
  std::vector<Diagnostic> errors;    // empty iff image is set; in source order
  std::vector<Diagnostic> warnings;  // in source order; not the disabled ones
};

// The largest program the compiler reads (ICEMAN is 10 KB): a bound, so
// that a file nobody meant as a program costs nothing.
inline constexpr std::size_t kMaxSourceBytes = 1 << 20;

// Compile `source` whose name (for messages and #include) is `fileName`.
Result compile(const std::string& source, const std::string& fileName, const Options& options = {});
// Read and compile a file; a missing or unreadable file is a Diagnostic.
Result compileFile(const std::string& path, const Options& options = {});

}  // namespace simbot::compiler
