// Minimal data parallelism on std::thread: the machines we target have few cores, and the
// stages are coarse (rows of an image, views of a scene).
#pragma once

#include <cstdint>
#include <functional>

namespace fvs {

// Number of worker threads: FVS_NUM_THREADS if set (>0), else the hardware concurrency.
int DefaultNumThreads();

// Calls fn(i) for i in [begin, end) on up to num_threads threads (<= 0: default; the
// calling thread is one of them), in contiguous chunks. Exceptions thrown by fn are
// rethrown (the first one) after all threads have joined.
void ParallelFor(int64_t begin, int64_t end, const std::function<void(int64_t)>& fn,
                 int num_threads = 0);

// As ParallelFor, but hands each thread a [chunk_begin, chunk_end) range and its thread
// index.
void ParallelForRanges(int64_t begin, int64_t end,
                       const std::function<void(int64_t, int64_t, int)>& fn,
                       int num_threads = 0);

}  // namespace fvs
