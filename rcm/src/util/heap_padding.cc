#include "rcm/util/heap_padding.h"

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace rcm {

bool PadHeapGrowth() {
#if defined(__GLIBC__)
  return mallopt(M_TOP_PAD, kHeapPaddingBytes) == 1;
#else
  return false;
#endif
}

}  // namespace rcm
