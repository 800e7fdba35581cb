#include "batch/parallel.h"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <exception>
#include <iostream>
#include <mutex>
#include <system_error>
#include <thread>
#include <vector>

#include "sinks/user_error.h"

namespace simbot::batch {

int resolveThreads(int threads) {
  if (threads > 0) return threads;
  const unsigned hw = std::thread::hardware_concurrency();
  return hw == 0 ? 1 : static_cast<int>(hw);
}

double uniform(plant::RandomBits& bits, double lo, double hi) {
  return lo + (hi - lo) * plant::unit53(bits.next());
}

void parallelFor(size_t count, int threads, const std::function<void(size_t)>& job,
                 const std::string& label, bool progress, const std::atomic<bool>* stop) {
  // After a job throws (a table that cannot be written), no job starts.
  std::atomic<bool> failed{false};
  const auto stopped = [stop, &failed] { return failed.load() || (stop && stop->load()); };
  const auto start = std::chrono::steady_clock::now();
  const size_t workers =
      std::min<size_t>(static_cast<size_t>(resolveThreads(threads)), std::max<size_t>(count, 1));
  std::atomic<size_t> next{0}, done{0};
  size_t idle = 0;  // workers that took their last job (under `mutex`)
  std::vector<std::exception_ptr> errors(count);
  std::mutex mutex;
  std::condition_variable finished;
  // Workers wait until every one of them exists: a thread that cannot be
  // created then fails the batch before any job ran.
  bool gateOpen = false;
  auto work = [&] {
    {
      std::unique_lock lock(mutex);
      finished.wait(lock, [&] { return gateOpen; });
    }
    for (size_t i; !stopped() && (i = next.fetch_add(1)) < count;) {
      try {
        job(i);
      } catch (...) {
        errors[i] = std::current_exception();
        failed.store(true);
      }
      done.fetch_add(1);
      std::lock_guard lock(mutex);
      finished.notify_all();
    }
    std::lock_guard lock(mutex);
    ++idle;
    finished.notify_all();
  };
  std::vector<std::thread> pool;
  pool.reserve(workers);
  try {
    for (size_t w = 0; w < workers; ++w) pool.emplace_back(work);
  } catch (const std::exception& e) {
    // The system would not give us the threads asked for: the ones that
    // exist leave at once, and the batch says so in one line.
    failed.store(true);
    {
      std::lock_guard lock(mutex);
      gateOpen = true;
    }
    finished.notify_all();
    for (auto& th : pool) th.join();
    throw sinks::UserError(fmt::format(
        "simbot: {}: cannot start {} worker threads ({} started): {}; use --threads with fewer\n",
        label, workers, pool.size(),
        dynamic_cast<const std::system_error*>(&e)
            ? dynamic_cast<const std::system_error&>(e).code().message()
            : std::string(e.what())));
  }
  {
    std::lock_guard lock(mutex);
    gateOpen = true;
  }
  finished.notify_all();
  const bool tty = progress && isatty(STDERR_FILENO);
  auto elapsed = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  if (tty) {
    std::unique_lock lock(mutex);
    while (true) {
      const size_t d = done.load();
      constexpr size_t kWidth = 30;
      const size_t filled = count ? d * kWidth / count : kWidth;
      const double t = elapsed();
      const std::string eta =
          d > 0 && d < count
              ? fmt::format(", ETA {:.0f} s", t / static_cast<double>(d) * (count - d))
              : "";
      std::cerr << fmt::format("\r{} [{}{}] {}/{}  {:.0f} s{}   ", label, std::string(filled, '#'),
                               std::string(kWidth - filled, '.'), d, count, t, eta)
                << std::flush;
      if (d == count || idle == workers) break;
      finished.wait_for(lock, std::chrono::milliseconds(250));
    }
    std::cerr << '\n';
  }
  for (auto& th : pool) th.join();
  if (progress && !tty)
    std::cerr << fmt::format("{}: {}/{} done in {:.1f} s on {} threads\n", label, done.load(),
                             count, elapsed(), workers);
  for (auto& e : errors)
    if (e) std::rethrow_exception(e);
}

}  // namespace simbot::batch
