// SplitMix64 (Steele, Lea and Flood, 2014): a fast, stateless 64-bit mixer.
// The simulator derives every random stream from it (seeds of its parts,
// texture draws, per-pixel sensor noise keyed by (seed, frame, camera,
// pixel)), so results do not depend on the order in which threads run.
#ifndef RCM_UTIL_SPLITMIX64_H_
#define RCM_UTIL_SPLITMIX64_H_

#include <cmath>
#include <cstdint>

namespace rcm {

// The SplitMix64 output for state x: the golden-ratio increment, then the
// two xor-shift-multiply rounds and a final xor-shift.
constexpr uint64_t SplitMix64(uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

// The key of item `index` (a frame) of the stream `salt` under `seed`:
// hashes of key + k then give the item's draws, which do not depend on how
// many items were drawn before it.
constexpr uint64_t IndexKey(uint64_t seed, uint64_t salt, uint64_t index) {
  return SplitMix64(seed ^ salt) + 0x9E3779B97F4A7C15ull * index;
}

// A standard normal draw from one 64-bit hash (e.g. SplitMix64 of a seed
// and a pixel index): Box-Muller on its two 32-bit halves, so that a noise
// image depends on the seed and the pixel only, not on thread scheduling.
inline double GaussianFromHash(uint64_t hash) {
  const double u1 = (static_cast<double>(hash >> 32) + 0.5) * 0x1.0p-32;
  const double u2 = static_cast<double>(hash & 0xFFFFFFFFull) * 0x1.0p-32;
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
}

}  // namespace rcm

#endif  // RCM_UTIL_SPLITMIX64_H_
