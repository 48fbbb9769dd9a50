#include "fvs/util/parallel.h"

#include <gtest/gtest.h>

#include <atomic>
#include <stdexcept>
#include <vector>

namespace fvs {
namespace {

TEST(ParallelFor, VisitsEveryIndexOnce) {
  for (int threads : {1, 2, 3, 8}) {
    std::vector<std::atomic<int>> hits(1000);
    ParallelFor(
        0, 1000, [&](int64_t i) { hits[i]++; }, threads);
    for (auto& h : hits) EXPECT_EQ(h.load(), 1);
  }
}

TEST(ParallelFor, EmptyAndTinyRanges) {
  int calls = 0;
  ParallelFor(
      5, 5, [&](int64_t) { ++calls; }, 4);
  ParallelFor(
      5, 3, [&](int64_t) { ++calls; }, 4);
  EXPECT_EQ(calls, 0);
  std::atomic<int> n{0};
  ParallelFor(
      0, 1, [&](int64_t) { ++n; }, 8);
  EXPECT_EQ(n.load(), 1);
}

TEST(ParallelFor, RethrowsWorkerException) {
  EXPECT_THROW(ParallelFor(
                   0, 100,
                   [](int64_t i) {
                     if (i == 77) throw std::runtime_error("boom");
                   },
                   2),
               std::runtime_error);
}

TEST(ParallelFor, CallerChunkThrowsOnlyAfterTheWorkersFinish) {
  // The calling thread runs the first chunk; its exception must not leave the call
  // while a worker still uses the caller's stack.
  std::atomic<int> done{0};
  EXPECT_THROW(ParallelFor(
                   0, 100,
                   [&](int64_t i) {
                     if (i == 0) throw std::runtime_error("boom");
                     if (i >= 50) ++done;
                   },
                   2),
               std::runtime_error);
  EXPECT_EQ(done.load(), 50);
}

}  // namespace
}  // namespace fvs
