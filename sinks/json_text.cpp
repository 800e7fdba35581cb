#include "sinks/json_text.h"

#include <stdexcept>

namespace simbot::sinks {

namespace {

void appendUtf8(std::string& out, unsigned codePoint) {
  if (codePoint < 0x80) {
    out.push_back(static_cast<char>(codePoint));
  } else {
    out.push_back(static_cast<char>(0xC0 | (codePoint >> 6)));
    out.push_back(static_cast<char>(0x80 | (codePoint & 0x3F)));
  }
}

std::string latin1(const std::string& bytes) {
  std::string out;
  out.reserve(bytes.size());
  for (unsigned char c : bytes) appendUtf8(out, c);
  return out;
}

// Well-formed UTF-8 (RFC 3629: no overlong forms, no surrogates).
bool validUtf8(const std::string& s) {
  const auto byte = [&s](size_t i) { return static_cast<unsigned char>(s[i]); };
  size_t i = 0;
  while (i < s.size()) {
    const unsigned c = byte(i);
    if (c < 0x80) {
      ++i;
      continue;
    }
    size_t more = 0;
    unsigned lo = 0x80, hi = 0xBF;  // the range of the second byte
    if (c >= 0xC2 && c <= 0xDF) {
      more = 1;
    } else if (c >= 0xE0 && c <= 0xEF) {
      more = 2;
      if (c == 0xE0) lo = 0xA0;
      if (c == 0xED) hi = 0x9F;
    } else if (c >= 0xF0 && c <= 0xF4) {
      more = 3;
      if (c == 0xF0) lo = 0x90;
      if (c == 0xF4) hi = 0x8F;
    } else {
      return false;
    }
    if (s.size() - i <= more) return false;
    if (byte(i + 1) < lo || byte(i + 1) > hi) return false;
    for (size_t k = 2; k <= more; ++k)
      if ((byte(i + k) & 0xC0) != 0x80) return false;
    i += more + 1;
  }
  return true;
}

// The bytes a Bytes field was written from (code points U+0000..U+00FF).
std::string bytesFromUtf8Impl(const std::string& s) {
  std::string out;
  for (size_t i = 0; i < s.size(); ++i) {
    const auto c = static_cast<unsigned char>(s[i]);
    if (c < 0x80) {
      out.push_back(static_cast<char>(c));
    } else if ((c >> 5) == 6 && i + 1 < s.size()) {
      const unsigned cp = ((c & 0x1Fu) << 6) | (static_cast<unsigned char>(s[++i]) & 0x3Fu);
      if (cp > 0xFF) throw std::invalid_argument("a byte string holds a character above U+00FF");
      out.push_back(static_cast<char>(cp));
    } else {
      throw std::invalid_argument("a byte string holds a character above U+00FF");
    }
  }
  return out;
}

}  // namespace

std::string jsonString(const std::string& value, bool bytes) {
  return bytes || !validUtf8(value) ? latin1(value) : value;
}

std::string bytesFromJsonString(const std::string& utf8) { return bytesFromUtf8Impl(utf8); }

std::string dumpJson(const nlohmann::json& json, int indent) {
  return json.dump(indent, ' ', false, nlohmann::json::error_handler_t::replace);
}

}  // namespace simbot::sinks
