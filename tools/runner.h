// Shared by simbot bench and simbot tournament: compiling, profiles, and
// running independent jobs on worker threads with a progress bar. Results
// are stored by job index, so they never depend on the completion order.
#pragma once
#include <atomic>
#include <cstdint>
#include <functional>
#include <optional>
#include <stdexcept>
#include <string>

#include "config/config.h"
#include "plant/plant.h"
#include "vm/image.h"

namespace simbot::tools {

// A user error: the message is printed as is, exit status 1.
struct ToolError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

vm::Image compileProgramFile(const std::string& path);
vm::Image compileProgramText(const std::string& source, const std::string& name);
// A profile by name (profiles/NAME.toml) or by path.
config::Profile loadNamedProfile(const std::string& nameOrPath);
// threads <= 0: the hardware concurrency (at least 1).
int resolveThreads(int threads);

// Runs job(0..count-1) on `threads` workers. With `progress`, draws a bar on
// stderr when it is a terminal, else prints one final line. Rethrows the
// first (lowest-index) exception a job threw, after all workers stopped.
// When `stop` becomes true no further job starts (those under way finish
// or give up on their own).
void parallelFor(size_t count, int threads, const std::function<void(size_t)>& job,
                 const std::string& label, bool progress, const std::atomic<bool>* stop = nullptr);

// A uniform double in [lo, hi) from 53 random bits (no std:: distribution).
double uniform(plant::RandomBits& bits, double lo, double hi);

}  // namespace simbot::tools
