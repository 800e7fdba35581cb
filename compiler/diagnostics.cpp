// Diagnostic::format: the one place that knows the tool contract's layout,
// "FILE:LINE:COL: error: MESSAGE" (or "warning: MESSAGE [-WNAME]"), the source
// line, and a caret under column COL. Tabs before the column are copied so
// the caret lines up in any terminal whatever its tab width. Long lines are
// cut around the column. Also the list of warning names and the collector.
#include "compiler/diagnostics.h"

#include <fmt/format.h>

#include <algorithm>
#include <string_view>

#include "compiler/compiler.h"

namespace simbot::compiler {

namespace {

// A diagnostic shows at most this much of its source line, around the
// column, and of its message: a 1 MB line must not become 1 MB of stderr.
constexpr size_t kShownLine = 160;
constexpr size_t kShownMessage = 300;

// Control characters would garble the terminal: shown as '?'.
std::string printable(std::string_view text) {
  std::string out(text);
  for (char& c : out)
    if ((static_cast<unsigned char>(c) < 0x20 && c != '\t') || c == 0x7f) c = '?';
  return out;
}

}  // namespace

const std::vector<WarningInfo>& warningList() {
  static const std::vector<WarningInfo> list = {
      {"tautological-compare",
       "a comparison always true or always false because of the operand's type range"},
      {"parentheses", "an assignment used as a condition"},
      {"unbound-handler", "an interrupt function that no #INT_VEC binds"},
      {"define-int-vec", "'#define INT_VEC', a vector binding mistyped as a macro"},
      {"uninitialized",
       "a variable read but never assigned (a local in its function, a global anywhere)"},
      {"unreachable-code", "a statement after return, break, continue or goto"},
      {"send-without-delay", "a serial send that can follow another with no delay between"},
      {"implicit-function-declaration", "a call to a function not yet declared"},
      {"unknown-pragma", "a #pragma simbot does not know (ignored, as C89 says)"},
      {"missing-member-name",
       "a struct or union member declaration with no declarator (\"int;\"): it declares "
       "nothing"},
  };
  return list;
}

bool isWarningName(std::string_view name) {
  for (const WarningInfo& w : warningList())
    if (w.name == name) return true;
  return false;
}

void Diagnostics::error(Pos pos, std::string message) {
  items_.push_back(RawDiagnostic{pos, std::move(message), {}});
  if (++errors_ >= kMaxErrors) {
    items_.push_back(
        RawDiagnostic{pos, fmt::format("too many errors ({}), stopping here", kMaxErrors), {}});
    ++errors_;
    throw StopCompiling{};
  }
}

void Diagnostics::fatal(Pos pos, std::string message) {
  error(pos, std::move(message));
  throw StopCompiling{};
}

void Diagnostics::warn(Pos pos, const char* name, std::string message) {
  items_.push_back(RawDiagnostic{pos, std::move(message), name});
}

std::string Diagnostic::format() const {
  std::string shownMessage =
      message.size() > kShownMessage ? message.substr(0, kShownMessage) + "..." : message;
  std::string tag;
  if (!warning.empty())
    tag = severity == Severity::Warning ? " [-W" + warning + "]" : " [-Werror=" + warning + "]";
  std::string out = fmt::format("{}:{}:{}: {}: {}{}\n", file, line, column,
                                severity == Severity::Warning ? "warning" : "error",
                                printable(shownMessage), tag);
  if (!hasSourceLine) return out;
  // The part of the line shown, and where the caret goes in it.
  const size_t col = column > 0 ? static_cast<size_t>(column - 1) : 0;
  size_t from = 0, to = sourceLine.size();
  if (to > kShownLine) {
    from = col > kShownLine / 2 ? std::min(col - kShownLine / 2, to - kShownLine) : 0;
    to = from + kShownLine;
  }
  const std::string before = from > 0 ? "..." : "";
  out += before + printable(std::string_view(sourceLine).substr(from, to - from));
  if (to < sourceLine.size()) out += "...";
  out += '\n';
  out += before.empty() ? "" : "   ";
  for (size_t i = from; i < col && i < from + (to - from) + 1; ++i)
    out += i < sourceLine.size() && sourceLine[i] == '\t' ? '\t' : ' ';
  out += "^\n";
  return out;
}

}  // namespace simbot::compiler
