// Helpers shared by the fuzz targets: doubles drawn from libFuzzer's bytes
// (FuzzedDataProvider, shipped with clang), a check that aborts, so that a
// violated property is a finding like a crash, and the property every
// reader's error message has.
#ifndef RCM_FUZZ_FUZZ_INPUT_H_
#define RCM_FUZZ_FUZZ_INPUT_H_

#include <fuzzer/FuzzedDataProvider.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

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

// A reader's error: one nonempty line that starts with the name of the
// source it read (the file's path in the rcm executable).
inline void CheckErrorMessage(const std::string& message, const char* source) {
  FuzzCheck(!message.empty(), "empty error message");
  FuzzCheck(message.find('\n') == std::string::npos,
            "error message of more than one line");
  FuzzCheck(message.rfind(source, 0) == 0,
            "error message without the source name");
}

inline bool AllFinite(const double* values, int count) {
  for (int i = 0; i < count; ++i) {
    if (!std::isfinite(values[i])) return false;
  }
  return true;
}

}  // namespace rcm::fuzz

#endif  // RCM_FUZZ_FUZZ_INPUT_H_
