#include "fvs/util/parallel.h"

#include <algorithm>
#include <cstdlib>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

#include "fvs/util/cancel.h"

namespace fvs {

int DefaultNumThreads() {
  if (const char* env = std::getenv("FVS_NUM_THREADS")) {
    const int n = std::atoi(env);
    if (n > 0) return n;
  }
  const unsigned hw = std::thread::hardware_concurrency();
  return hw > 0 ? static_cast<int>(hw) : 1;
}

void ParallelForRanges(int64_t begin, int64_t end,
                       const std::function<void(int64_t, int64_t, int)>& fn,
                       int num_threads) {
  if (end <= begin) return;
  // A cancellable caller (util/cancel.h) hands its flag to the threads started here, so
  // that the ParallelFor calls nested in fn see it too.
  const std::atomic<bool>* cancel = CurrentCancelFlag();
  ThrowIfCancelled(cancel);
  if (num_threads <= 0) num_threads = DefaultNumThreads();
  const int64_t n = end - begin;
  const int threads = static_cast<int>(std::min<int64_t>(num_threads, n));
  if (threads <= 1) {
    fn(begin, end, 0);
    return;
  }
  std::exception_ptr first_error;
  std::mutex mutex;
  auto run = [&](int t) {
    const CancelScope scope(cancel);
    try {
      fn(begin + n * t / threads, begin + n * (t + 1) / threads, t);
    } catch (...) {
      std::lock_guard<std::mutex> lock(mutex);
      if (!first_error) first_error = std::current_exception();
    }
  };
  // The calling thread takes the first chunk itself: one thread start fewer per call
  // (callers such as the rasteriser make several calls per frame).
  std::vector<std::thread> workers;
  workers.reserve(threads - 1);
  for (int t = 1; t < threads; ++t) workers.emplace_back(run, t);
  run(0);
  for (auto& w : workers) w.join();
  if (first_error) std::rethrow_exception(first_error);
  ThrowIfCancelled(cancel);
}

void ParallelFor(int64_t begin, int64_t end, const std::function<void(int64_t)>& fn,
                 int num_threads) {
  ParallelForRanges(
      begin, end,
      [&fn](int64_t b, int64_t e, int) {
        const std::atomic<bool>* cancel = CurrentCancelFlag();
        for (int64_t i = b; i < e; ++i) {
          ThrowIfCancelled(cancel);
          fn(i);
        }
      },
      num_threads);
}

}  // namespace fvs
