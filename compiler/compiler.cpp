// The driver: source text through the preprocessor, parser, the warnings'
// analyses and the code generator to an Image and its warnings, or every
// error found as Diagnostics. Nothing escapes
// compile(): compile errors, resource exhaustion and internal faults all come
// back as a Diagnostic.
#include "compiler/compiler.h"

#include <fmt/format.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <new>
#include <sstream>

#include "compiler/ast.h"
#include "compiler/preprocess.h"

namespace simbot::compiler {

namespace {

// CRLF and a lone CR (classic Mac OS files) end a line as LF does; the rest
// of the compiler sees LF only, so line numbers are right in all three.
std::string normalizeNewlines(const std::string& source) {
  std::string out;
  out.reserve(source.size());
  for (size_t i = 0; i < source.size(); ++i) {
    if (source[i] != '\r') {
      out.push_back(source[i]);
    } else {
      out.push_back('\n');
      if (i + 1 < source.size() && source[i + 1] == '\n') ++i;
    }
  }
  return out;
}

std::vector<std::string> splitLines(const std::string& source) {
  std::vector<std::string> lines;
  size_t start = 0;
  for (;;) {
    size_t end = source.find('\n', start);
    std::string line =
        source.substr(start, end == std::string::npos ? std::string::npos : end - start);
    if (!line.empty() && line.back() == '\r') line.pop_back();
    lines.push_back(std::move(line));
    if (end == std::string::npos) break;
    start = end + 1;
  }
  if (!lines.empty() && lines.back().empty() && !source.empty() && source.back() == '\n')
    lines.pop_back();
  return lines;
}

Diagnostic makeDiagnostic(const std::string& fileName, const std::vector<std::string>& lines,
                          Pos pos, std::string message) {
  Diagnostic d;
  d.file = fileName;
  d.line = pos.line < 1 ? 1 : pos.line;
  d.column = pos.col < 1 ? 1 : pos.col;
  d.message = std::move(message);
  d.hasSourceLine = d.line >= 1 && static_cast<size_t>(d.line) <= lines.size();
  if (d.hasSourceLine) d.sourceLine = lines[d.line - 1];
  return d;
}

}  // namespace

Result compile(const std::string& rawSource, const std::string& fileName, const Options& options) {
  Result result;
  if (rawSource.size() > kMaxSourceBytes) {
    result.errors.push_back(
        makeDiagnostic(fileName, {}, Pos{1, 1},
                       fmt::format("the program is {} bytes, more than a program may have ({})",
                                   rawSource.size(), kMaxSourceBytes)));
    return result;
  }
  // A UTF-8 byte order mark (editors on Windows write one) is not part of
  // the program: dropped, so line 1's columns are what the editor shows.
  constexpr std::string_view kByteOrderMark = "\xEF\xBB\xBF";
  const std::string source = normalizeNewlines(
      std::string_view(rawSource).substr(0, 3) == kByteOrderMark ? rawSource.substr(3) : rawSource);
  std::vector<std::string> lines = splitLines(source);
  Diagnostics diags;
  std::optional<vm::Image> image;
  // Internal faults end the compilation with what was found so far.
  const auto record = [&](Pos pos, std::string message) {
    try {
      diags.error(pos, std::move(message));
    } catch (const StopCompiling&) {
    }
  };
  try {
    Preprocessor pp(source, fileName, diags);
    Program prog;
    parse(pp, options, prog, diags);
    if (diags.errorCount() == 0) {
      analyze(prog, diags);
      image = generate(prog);
      image->sourceName = fileName;
      image->sourceLines = lines;
    }
  } catch (const StopCompiling&) {
  } catch (const CompileError& e) {  // code generation's limits
    record(e.pos, e.message);
  } catch (const std::bad_alloc&) {
    record(Pos{}, "out of memory");
  } catch (const std::exception& e) {
    record(Pos{}, std::string("internal compiler error: ") + e.what());
  } catch (...) {
    record(Pos{}, "internal compiler error");
  }

  // Source order, whichever stage found them (a stable sort keeps a
  // statement's error before a later note about the same place).
  std::vector<RawDiagnostic> all = diags.all();
  std::stable_sort(all.begin(), all.end(), [](const RawDiagnostic& a, const RawDiagnostic& b) {
    return a.pos.line != b.pos.line ? a.pos.line < b.pos.line : a.pos.col < b.pos.col;
  });
  for (const RawDiagnostic& r : all) {
    if (!r.warning.empty() && options.disabledWarnings.count(r.warning)) continue;
    Diagnostic d = makeDiagnostic(fileName, lines, r.pos, r.message);
    d.warning = r.warning;
    if (!r.warning.empty() && !options.werror) {
      d.severity = Severity::Warning;
      result.warnings.push_back(std::move(d));
    } else {
      result.errors.push_back(std::move(d));
    }
  }
  if (result.errors.empty()) result.image = std::move(image);
  return result;
}

Result compileFile(const std::string& path, const Options& options) {
  const auto cannot = [&path](const std::string& why) {
    Result r;
    Diagnostic d;
    d.file = path;
    d.line = 1;
    d.column = 1;
    d.message = "cannot read file: " + why;
    d.hasSourceLine = false;
    r.errors.push_back(d);
    return r;
  };
  // Looked at before it is opened: opening a FIFO would wait for a writer.
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (ec || !std::filesystem::exists(status)) return cannot("no such file");
  if (std::filesystem::is_directory(status)) return cannot("it is a directory");
  if (!std::filesystem::is_regular_file(status)) return cannot("not a regular file");
  const auto size = std::filesystem::file_size(path, ec);
  if (!ec && size > kMaxSourceBytes)
    return cannot(
        fmt::format("{} bytes is more than a program may have ({})", size, kMaxSourceBytes));
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  if (in) text << in.rdbuf();
  if (!in || in.bad()) return cannot("read error");
  return compile(text.str(), path, options);
}

}  // namespace simbot::compiler
