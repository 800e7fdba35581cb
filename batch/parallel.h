// Private to batch/: running independent jobs (a bench's runs, a
// tournament's matches, a sweep's rows) on worker threads with a progress
// bar. Results are stored by job index, so they never depend on the
// completion order.
#pragma once
#include <atomic>
#include <cstddef>
#include <functional>
#include <string>

#include "plant/plant.h"

namespace simbot::batch {

// threads <= 0: the hardware concurrency (at least 1).
int resolveThreads(int threads);

// Runs job(0..count-1) on `threads` workers. With `progress`, draws a bar on
// stderr when it is a terminal, else prints one final line. After a job
// throws, no further job starts; the first (lowest-index) exception is
// rethrown after all workers stopped. Threads that cannot be created are a
// sinks::UserError.
// When `stop` becomes true no further job starts (those under way finish
// or give up on their own).
void parallelFor(size_t count, int threads, const std::function<void(size_t)>& job,
                 const std::string& label, bool progress, const std::atomic<bool>* stop = nullptr);

// A uniform double in [lo, hi) from 53 random bits (no std:: distribution).
double uniform(plant::RandomBits& bits, double lo, double hi);

}  // namespace simbot::batch
