// config/text.cpp -- what every configuration loader shares: the error's
// FILE:LINE:COL format, reading a file, and the check of TOML text that
// keeps toml++ 3.3.0 away from input it mishandles (config.h).
#include "config/text.h"

#include <fmt/format.h>

#include <charconv>
#include <cstdint>
#include <cstdio>

#include "files/files.h"
#include "timebase/written.h"

namespace simbot::config {

ConfigError::ConfigError(const std::string& file, int line, int column, const std::string& message)
    : std::runtime_error(fmt::format("{}:{}:{}: error: {}", file, line < 1 ? 1 : line,
                                     column < 1 ? 1 : column, message)) {}

std::string readFile(const std::string& path) {
  try {
    return files::readInput(path, files::kMaxConfigBytes);
  } catch (const files::Error& e) {
    throw ConfigError(path, 1, 1, fmt::format("cannot read the file: {}", e.what()));
  }
}

std::optional<std::uint64_t> seedValue(const toml::node& node) {
  if (node.is_integer()) {
    const int64_t v = *node.value<int64_t>();
    if (v < 0) return std::nullopt;
    return static_cast<std::uint64_t>(v);
  }
  if (!node.is_string()) return std::nullopt;
  const std::string text = *node.value<std::string>();
  std::uint64_t v = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), v);
  if (text.empty() || error != std::errc() || end != text.data() + text.size() ||
      text.find_first_not_of("0123456789") != std::string::npos)
    return std::nullopt;
  return v;
}

void failAt(const std::string& file, const toml::source_region& where, const std::string& message) {
  throw ConfigError(file, static_cast<int>(where.begin.line), static_cast<int>(where.begin.column),
                    message);
}

void onlyKeys(const toml::table& table, const std::string& file, const std::string& where,
              std::initializer_list<const char*> allowed) {
  for (auto&& [key, value] : table) {
    bool known = false;
    std::string list;
    for (const char* a : allowed) {
      known = known || key.str() == a;
      list += list.empty() ? a : std::string(", ") + a;
    }
    if (!known)
      failAt(file, key.source(),
             fmt::format("unknown key '{}' in {} (expected one of: {})", key.str(), where, list));
  }
}

scheduler::Tick timeValue(const toml::node& node, const std::string& file, const std::string& name,
                          bool runLength) {
  std::string written;  // as the user wrote it, for the messages
  scheduler::Tick ticks = 0;
  try {
    if (const auto* s = node.as_string()) {
      written = s->get();
      ticks = timebase::parseTime(written, timebase::BareNumber::Seconds);
    } else if (const auto* i = node.as_integer()) {
      written = std::to_string(i->get());
      ticks = timebase::parseTime(written, timebase::BareNumber::Seconds);
    } else if (const auto* f = node.as_floating_point()) {
      written = fmt::format("{}", f->get());
      ticks = timebase::parseSeconds(f->get());
    } else {
      failAt(file, node.source(),
             fmt::format("'{}' must be a time: a number of seconds, or a string such as \"800ms\"",
                         name));
    }
    return runLength ? timebase::checkRunLength(ticks, written) : ticks;
  } catch (const timebase::TimeError& e) {
    failAt(file, node.source(), fmt::format("'{}': {}", name, e.what()));
  }
}

toml::table parseToml(std::string_view text, const std::string& file) {
  checkTomlText(text, file);
  try {
    return toml::parse(text, file);
  } catch (const toml::parse_error& e) {
    failAt(file, e.source(), std::string(e.description()));
  }
}

void checkTomlText(std::string_view text, const std::string& sourceName) {
  int line = 1, column = 1;
  const auto fail = [&](const std::string& msg) {
    throw ConfigError(sourceName, line, column, msg);
  };
  enum class In : std::uint8_t { Code, Comment, Basic, Literal, MultiBasic, MultiLiteral };
  In in = In::Code;
  bool escaped = false;  // the character after a backslash in a basic string
  const auto at = [&](std::size_t i) { return i < text.size() ? text[i] : '\0'; };
  const auto starts = [&](std::size_t i, std::string_view s) {
    return text.substr(i, s.size()) == s;
  };
  for (std::size_t i = 0; i < text.size();) {
    const auto c = static_cast<unsigned char>(text[i]);
    // A UTF-8 sequence: its length, checked strictly (no overlongs, no surrogates).
    std::size_t len = 1;
    if (c >= 0x80) {
      unsigned lo = 0x80, hi = 0xBF;
      if (c >= 0xC2 && c <= 0xDF) {
        len = 2;
      } else if (c >= 0xE0 && c <= 0xEF) {
        len = 3;
        if (c == 0xE0) lo = 0xA0;
        if (c == 0xED) hi = 0x9F;
      } else if (c >= 0xF0 && c <= 0xF4) {
        len = 4;
        if (c == 0xF0) lo = 0x90;
        if (c == 0xF4) hi = 0x8F;
      } else {
        fail(fmt::format("the file is not valid UTF-8 (byte 0x{:02x})", c));
      }
      for (std::size_t k = 1; k < len; ++k) {
        const auto b = static_cast<unsigned char>(at(i + k));
        if (k == 1 ? (b < lo || b > hi) : (b & 0xC0) != 0x80)
          fail(fmt::format("the file is not valid UTF-8 (byte 0x{:02x})", c));
      }
      if (in == In::Code)
        fail("a non-ASCII character outside a string or comment (TOML allows none there)");
    }
    std::size_t next = i + len;
    switch (in) {
      case In::Code:
        if (c == '#') in = In::Comment;
        if (c == '"') in = starts(i, "\"\"\"") ? In::MultiBasic : In::Basic;
        if (c == '\'') in = starts(i, "'''") ? In::MultiLiteral : In::Literal;
        if (in == In::MultiBasic || in == In::MultiLiteral) next = i + 3;
        break;
      case In::Comment:
        if (c == '\n') in = In::Code;
        break;
      case In::Basic:
        if (escaped)
          escaped = false;
        else if (c == '\\')
          escaped = true;
        else if (c == '"' || c == '\n')
          in = In::Code;
        break;
      case In::Literal:
        if (c == '\'' || c == '\n') in = In::Code;
        break;
      case In::MultiBasic:
        if (escaped) {
          escaped = false;
        } else if (c == '\\') {
          // A line-ending backslash: what follows the blank space after it
          // must be ASCII.
          std::size_t k = i + 1;
          while (at(k) == ' ' || at(k) == '\t') ++k;
          if (at(k) == '\r' || at(k) == '\n') {
            while (at(k) == ' ' || at(k) == '\t' || at(k) == '\r' || at(k) == '\n') ++k;
            if (static_cast<unsigned char>(at(k)) >= 0x80)
              fail(
                  "a line-ending backslash in a multi-line string is followed by a non-ASCII "
                  "character, which toml++ 3.3.0 cannot parse safely: put the character on "
                  "the backslash's line");
          }
          escaped = true;
        } else if (starts(i, "\"\"\"")) {
          in = In::Code;
          next = i + 3;
        }
        break;
      case In::MultiLiteral:
        if (starts(i, "'''")) {
          in = In::Code;
          next = i + 3;
        }
        break;
    }
    for (; i < next && i < text.size(); ++i) {
      if (text[i] == '\n') {
        ++line;
        column = 1;
      } else if ((static_cast<unsigned char>(text[i]) & 0xC0) != 0x80) {
        ++column;  // columns count characters, as toml++'s do
      }
    }
  }
}

}  // namespace simbot::config
