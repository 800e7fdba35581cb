// Strings on their way into JSON, which must be UTF-8. Bytes a robot
// produced (console lines, motor frames) become one character per byte,
// U+0000..U+00FF, so that they read back exactly; any other text (a file
// name, a message) passes through when it is valid UTF-8 and is read as
// Latin-1 otherwise.
#pragma once
#include <nlohmann/json.hpp>
#include <string>

namespace simbot::sinks {

// `value` as JSON-safe UTF-8: bytes (robot output) or text (see above).
std::string jsonString(const std::string& value, bool bytes);
// The bytes a robot-output string was written from; throws
// std::invalid_argument for a character above U+00FF.
std::string bytesFromJsonString(const std::string& utf8);
// dump() that never throws on a string: invalid UTF-8 becomes U+FFFD.
std::string dumpJson(const nlohmann::json& json, int indent = -1);

}  // namespace simbot::sinks
