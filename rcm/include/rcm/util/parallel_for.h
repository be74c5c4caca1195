// Runs body(begin, end) over [0, count) split into contiguous chunks, one
// per thread (the calling thread takes the first). Small counts run on the
// calling thread alone, where starting threads would cost more than the
// work. Chunks are disjoint, so bodies that write only their own range
// need no locking.
#ifndef RCM_UTIL_PARALLEL_FOR_H_
#define RCM_UTIL_PARALLEL_FOR_H_

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <thread>
#include <vector>

namespace rcm {

template <typename Body>
void ParallelFor(int64_t count, int num_threads, int64_t min_per_thread,
                 const Body& body) {
  const int64_t max_threads =
      std::max<int64_t>(1, count / std::max<int64_t>(1, min_per_thread));
  const int threads =
      static_cast<int>(std::clamp<int64_t>(num_threads, 1, max_threads));
  if (threads == 1) {
    if (count > 0) body(int64_t{0}, count);
    return;
  }
  std::vector<std::thread> workers;
  workers.reserve(threads - 1);
  for (int t = 1; t < threads; ++t) {
    const int64_t begin = count * t / threads;
    const int64_t end = count * (t + 1) / threads;
    workers.emplace_back([&body, begin, end] { body(begin, end); });
  }
  body(int64_t{0}, count / threads);
  for (std::thread& worker : workers) worker.join();
}

// Runs body(begin, end) over [0, count) in chunks of `chunk` items that up
// to `num_threads` threads (the calling thread one of them) take in turn
// from a shared counter. Where ParallelFor's equal shares wait at the join
// for a thread the system runs late (the two cores shared with a decoder
// thread or another process), here the others take its chunks. For work
// whose items are independent; which thread runs a chunk varies from run
// to run, so a body must not depend on it.
template <typename Body>
void ParallelForChunks(int64_t count, int num_threads, int64_t chunk,
                       const Body& body) {
  chunk = std::max<int64_t>(1, chunk);
  const int64_t chunks = (std::max<int64_t>(0, count) + chunk - 1) / chunk;
  const int threads =
      static_cast<int>(std::clamp<int64_t>(num_threads, 1, chunks));
  std::atomic<int64_t> next{0};
  const auto work = [&] {
    for (int64_t c = next++; c < chunks; c = next++) {
      body(c * chunk, std::min(count, (c + 1) * chunk));
    }
  };
  if (threads <= 1) {
    work();
    return;
  }
  std::vector<std::thread> workers;
  workers.reserve(threads - 1);
  for (int t = 1; t < threads; ++t) workers.emplace_back(work);
  work();
  for (std::thread& worker : workers) worker.join();
}

}  // namespace rcm

#endif  // RCM_UTIL_PARALLEL_FOR_H_
