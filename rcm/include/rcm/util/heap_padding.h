// For executables, at the start of main: the C library's heap grows, and
// gives memory back to the system, in steps of kHeapPaddingBytes (16 MiB)
// instead of glibc's 128 KiB (mallopt M_TOP_PAD). A pair loop allocates and
// frees the same buffers again and again (images, keypoints, matches, the
// refinement's Ceres problems); with the default each round trip returned
// the top of the heap and faulted fresh zeroed pages in on the next pair,
// which the kernel's page-fault handling showed as ~16 % of an
// `rcm estimate` run's samples. Measured on 10 rendered 720x540 pairs
// (rcm estimate, 2026-12-05, three runs each): 0.90-1.02 s -> 0.66-0.76 s
// of wall time, system time 0.15-0.19 s -> 0.06-0.07 s, n the same to the
// last bit; BM_EndToEnd_RcmProcess 1.05 s -> 0.73 s. A live pair
// (BM_LivePipelinePair, which pads its heap as the node does) shows no
// change beyond its run-to-run spread (33-49 ms of CPU in water). The cost
// is at most 16 MiB kept per arena.
//
// The `rcm` executable and the ROS node call it; rcm's libraries never do
// (the allocator is the process's, not a library's), nor does the Python
// module (the interpreter is the user's process). A no-op without glibc.
#ifndef RCM_UTIL_HEAP_PADDING_H_
#define RCM_UTIL_HEAP_PADDING_H_

namespace rcm {

inline constexpr int kHeapPaddingBytes = 16 << 20;

// Sets the padding; false when the allocator refused it (AddressSanitizer's,
// which replaces glibc's, does) or the C library is not glibc.
bool PadHeapGrowth();

}  // namespace rcm

#endif  // RCM_UTIL_HEAP_PADDING_H_
