// config/text.h -- inside config/: what every loader of configuration text
// shares: reading a file, and a toml++ document's errors at their place.
#pragma once

#include <toml++/toml.h>

#include <cstdint>
#include <initializer_list>
#include <optional>
#include <string>
#include <string_view>

#include "config/config.h"

namespace simbot::config {

// A file's bytes (a regular file within files::kMaxConfigBytes);
// ConfigError "PATH:1:1: error: cannot read the file: REASON".
std::string readFile(const std::string& path);

// ConfigError at the start of `where` in `file`.
[[noreturn]] void failAt(const std::string& file, const toml::source_region& where,
                         const std::string& message);

// Every key of `table` must be one of `allowed`; otherwise ConfigError
// "unknown key 'K' in WHERE (expected one of: ...)" at the key.
void onlyKeys(const toml::table& table, const std::string& file, const std::string& where,
              std::initializer_list<const char*> allowed);

// A seed: a TOML integer >= 0, or a string of decimal digits up to
// 2^64 - 1 (TOML's integers stop at 2^63 - 1, and runs.csv prints seeds
// up to 2^64 - 1); nothing for anything else.
std::optional<std::uint64_t> seedValue(const toml::node& node);

// A time in a file: a number of seconds, or a string in
// timebase/written.h's grammar ("800ms", "9216t"); a whole number of ticks
// either way, checked against the one run-length limit when `runLength`.
// ConfigError "FILE:LINE:COL: error: 'NAME': ..." at the value otherwise.
scheduler::Tick timeValue(const toml::node& node, const std::string& file, const std::string& name,
                          bool runLength);

// checkTomlText, then toml++'s parse; its parse errors are ConfigErrors at
// their place.
toml::table parseToml(std::string_view text, const std::string& file);

}  // namespace simbot::config
