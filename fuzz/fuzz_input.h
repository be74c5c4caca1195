// Helpers shared by the fuzz targets: doubles drawn from libFuzzer's bytes
// (FuzzedDataProvider, shipped with clang), and a check that aborts, so that
// a violated property is a finding like a crash.
#ifndef RCM_FUZZ_FUZZ_INPUT_H_
#define RCM_FUZZ_FUZZ_INPUT_H_

#include <fuzzer/FuzzedDataProvider.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>

namespace rcm::fuzz {

// Any double: the raw bit pattern of 8 bytes (NaN, inf, subnormals, -0
// included) half of the time, otherwise a value in [low, high], where the
// interesting branches of the model are. libFuzzer mutates the bytes, so
// both kinds of value are explored.
inline double ConsumeDouble(FuzzedDataProvider& data, double low,
                            double high) {
  if (data.ConsumeBool()) {
    uint64_t bits = data.ConsumeIntegral<uint64_t>();
    double value;
    std::memcpy(&value, &bits, sizeof(value));
    return value;
  }
  return data.ConsumeFloatingPointInRange(low, high);
}

// Aborts with `what` when `condition` is false: a property of the code under
// test that the fuzzer found violated.
inline void FuzzCheck(bool condition, const char* what) {
  if (!condition) {
    std::fprintf(stderr, "fuzz property violated: %s\n", what);
    std::abort();
  }
}

inline bool AllFinite(const double* values, int count) {
  for (int i = 0; i < count; ++i) {
    if (!std::isfinite(values[i])) return false;
  }
  return true;
}

}  // namespace rcm::fuzz

#endif  // RCM_FUZZ_FUZZ_INPUT_H_
