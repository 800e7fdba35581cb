// The programs and profiles a run is made of (play.h): compiling a program
// file or text, with its diagnostics as a UserError, and finding a profile
// by name or path.
#include <fmt/format.h>

#include <algorithm>
#include <filesystem>
#include <iostream>
#include <mutex>
#include <set>
#include <string>
#include <vector>

#include "compiler/compiler.h"
#include "config/config.h"
#include "runs/play.h"
#include "sinks/user_error.h"

namespace simbot::runs {

namespace {

vm::Image imageOrThrow(compiler::Result result) {
  if (!result.image) {
    std::vector<compiler::Diagnostic> all = result.warnings;
    all.insert(all.end(), result.errors.begin(), result.errors.end());
    std::stable_sort(all.begin(), all.end(), [](const auto& a, const auto& b) {
      return a.line != b.line ? a.line < b.line : a.column < b.column;
    });
    std::string text;
    for (const auto& d : all) text += d.format();
    throw sinks::UserError(text);
  }
  // Warnings go to stderr (stdout may be JSON), once per program per
  // process however many runs compile it (bench, tournament).
  static std::mutex mutex;
  static std::set<std::string> shown;
  if (!result.warnings.empty()) {
    std::lock_guard<std::mutex> lock(mutex);
    if (shown.insert(result.image->sourceName).second) {
      std::string all;
      for (const auto& d : result.warnings) all += d.format();
      std::cerr << all << std::flush;
    }
  }
  return std::move(*result.image);
}

}  // namespace

namespace {

std::mutex gOptionsMutex;
compiler::Options gOptions;

compiler::Options compileOptions() {
  std::lock_guard lock(gOptionsMutex);
  return gOptions;
}

}  // namespace

void setCompileOptions(const compiler::Options& options) {
  std::lock_guard lock(gOptionsMutex);
  gOptions = options;
}

void parseWarningOptions(const std::vector<std::string>& words, compiler::Options& options,
                         const std::string& command) {
  for (const std::string& w : words) {
    if (w == "-Werror") {
      options.werror = true;
    } else if (w.rfind("-Wno-", 0) == 0 && compiler::isWarningName(w.substr(5))) {
      options.disabledWarnings.insert(w.substr(5));
    } else {
      std::string names;
      for (const auto& info : compiler::warningList())
        names += (names.empty() ? "" : ", ") + std::string(info.name);
      throw sinks::UserError(
          fmt::format("simbot: {}: unknown option '{}' (warnings: {}; simbot {} --help lists the "
                      "options)\n",
                      command, w, names, command));
    }
  }
}

vm::Image compileProgramFile(const std::string& path) {
  if (!std::filesystem::exists(path))
    throw sinks::UserError(fmt::format("simbot: no such program '{}'\n", path));
  return imageOrThrow(compiler::compileFile(path, compileOptions()));
}

vm::Image compileProgramText(const std::string& source, const std::string& name) {
  return imageOrThrow(compiler::compile(source, name, compileOptions()));
}

config::Course loadNamedRules(const std::string& nameOrPath) {
  if (std::filesystem::exists(nameOrPath)) return config::loadRules(nameOrPath);
  const auto shipped = config::shippedRulesPath(nameOrPath);
  if (!shipped)
    throw sinks::UserError(fmt::format(
        "simbot: --rules: no rule set '{}' (a file, or one of rules/*.toml)\n", nameOrPath));
  return config::loadRules(*shipped);
}

config::Profile loadRunProfile(const std::string& profile, const std::string& rules) {
  config::Profile p = loadNamedProfile(profile);
  if (!rules.empty()) config::applyRules(loadNamedRules(rules), p);
  return p;
}

config::Profile loadNamedProfile(const std::string& nameOrPath) {
  if (std::filesystem::exists(nameOrPath)) return config::loadProfile(nameOrPath);
  const auto shipped = config::shippedProfilePath(nameOrPath);
  if (!shipped)
    throw sinks::UserError(
        fmt::format("simbot: no profile '{}' (a file, or one of profiles/*.toml)\n", nameOrPath));
  return config::loadProfile(*shipped);
}

}  // namespace simbot::runs
