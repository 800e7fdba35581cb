// config/text.h -- inside config/: what every loader of configuration text
// shares: reading a file, and a toml++ document's errors at their place.
#pragma once

#include <toml++/toml.h>

#include <string>
#include <string_view>

#include "config/config.h"

namespace simbot::config {

// A file's bytes; ConfigError "PATH:1:1: error: cannot open file".
std::string readFile(const std::string& path);

// ConfigError at the start of `where` in `file`.
[[noreturn]] void failAt(const std::string& file, const toml::source_region& where,
                         const std::string& message);

// checkTomlText, then toml++'s parse; its parse errors are ConfigErrors at
// their place.
toml::table parseToml(std::string_view text, const std::string& file);

}  // namespace simbot::config
