// libFuzzer target: the compiler on any bytes. Every input must come back
// as an image or as diagnostics (each one line of FILE:LINE:COL and a
// bounded excerpt): never a crash, a hang or an unbounded allocation.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "compiler/compiler.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string source(reinterpret_cast<const char*>(data), size);
  const simbot::compiler::Result r = simbot::compiler::compile(source, "fuzz.dc");
  if (!r.image && r.errors.empty()) std::abort();  // a failure must say why
  for (const auto& e : r.errors)
    if (e.format().size() > 2048) std::abort();  // diagnostics are bounded
  return 0;
}
