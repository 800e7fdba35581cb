// Diagnostic::format: the one place that knows the tool contract's error
// layout, "FILE:LINE:COL: error: MESSAGE", the source line, and a caret under
// column COL. Tabs before the column are copied so the caret lines up in any
// terminal whatever its tab width.
#include <fmt/format.h>

#include "compiler/compiler.h"

namespace simbot::compiler {

std::string Diagnostic::format() const {
  std::string out = fmt::format("{}:{}:{}: error: {}\n", file, line, column, message);
  out += sourceLine;
  out += '\n';
  for (int i = 0; i + 1 < column; ++i) {
    bool tab = i < static_cast<int>(sourceLine.size()) && sourceLine[i] == '\t';
    out += tab ? '\t' : ' ';
  }
  out += "^\n";
  return out;
}

}  // namespace simbot::compiler
