#include "rcm/util/parallel_for.h"

#include <gtest/gtest.h>

#include <atomic>
#include <cstdint>
#include <vector>

namespace rcm::parallel_for_test {
namespace {

// Every index is run exactly once, in chunks of the size asked for (the
// last one shorter), whatever the threads, and nothing for no items.
TEST(ParallelForChunks, RunsEveryIndexOnceInChunks) {
  for (const int64_t count : {0, 1, 7, 64, 1000, 1001}) {
    for (const int64_t chunk : {1, 16, 5000}) {
      for (const int threads : {1, 2, 3}) {
        std::vector<std::atomic<int>> runs(static_cast<size_t>(count));
        std::atomic<int64_t> calls{0};
        std::atomic<bool> bad_range{false};
        ParallelForChunks(
            count, threads, chunk, [&](int64_t begin, int64_t end) {
              ++calls;
              if (begin % chunk != 0 || end <= begin || end - begin > chunk ||
                  (end - begin < chunk && end != count)) {
                bad_range = true;
              }
              for (int64_t i = begin; i < end; ++i) ++runs[i];
            });
        for (int64_t i = 0; i < count; ++i) {
          EXPECT_EQ(runs[i].load(), 1) << "index " << i << " of " << count;
        }
        EXPECT_EQ(calls.load(), (count + chunk - 1) / chunk);
        EXPECT_FALSE(bad_range.load()) << count << " items, chunk " << chunk
                                       << ", " << threads << " threads";
      }
    }
  }
}

}  // namespace
}  // namespace rcm::parallel_for_test
