#include "rcm/util/heap_padding.h"

#include <gtest/gtest.h>

// AddressSanitizer's allocator (gcc defines __SANITIZE_ADDRESS__, clang
// has the feature).
#if defined(__SANITIZE_ADDRESS__)
#define RCM_TEST_ADDRESS_SANITIZER 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define RCM_TEST_ADDRESS_SANITIZER 1
#endif
#endif

namespace rcm::heap_padding_test {
namespace {

// glibc's allocator accepts the padding (Debian's C library). Under
// AddressSanitizer its own allocator replaces glibc's and refuses mallopt
// (returns 0), and without glibc it is a no-op; both say so.
TEST(HeapPadding, GlibcAcceptsIt) {
#if defined(__GLIBC__) && !defined(RCM_TEST_ADDRESS_SANITIZER)
  EXPECT_TRUE(PadHeapGrowth());
#else
  EXPECT_FALSE(PadHeapGrowth());
#endif
}

}  // namespace
}  // namespace rcm::heap_padding_test
