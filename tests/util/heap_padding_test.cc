#include "rcm/util/heap_padding.h"

#include <gtest/gtest.h>

namespace rcm::heap_padding_test {
namespace {

// glibc accepts the padding (Debian's C library; elsewhere it is a no-op
// that says so).
TEST(HeapPadding, GlibcAcceptsIt) {
#if defined(__GLIBC__)
  EXPECT_TRUE(PadHeapGrowth());
#else
  EXPECT_FALSE(PadHeapGrowth());
#endif
}

}  // namespace
}  // namespace rcm::heap_padding_test
