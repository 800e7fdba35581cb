// debug/'s one trim, shared by the console, the DAP server and its wire
// reader: each passes the blanks its input may carry around a word.
#pragma once
#include <string>
#include <string_view>

namespace simbot::debug {

inline std::string trim(std::string_view s, std::string_view blanks) {
  const auto a = s.find_first_not_of(blanks);
  if (a == std::string_view::npos) return "";
  const auto b = s.find_last_not_of(blanks);
  return std::string(s.substr(a, b - a + 1));
}

}  // namespace simbot::debug
