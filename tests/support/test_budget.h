// How much work the slowest statistical and end-to-end tests do.
//
// The Release pass (build/) runs them in full and checks their statistics
// (Monte Carlo standard deviations, end-to-end accuracy). The sanitizer
// pass (build-sanitize/, scripts/test_sanitizers.sh) exists to catch
// memory errors and undefined behaviour on every code path; instrumented
// code runs 3-8x slower, so there these tests run a few trials or views
// only, enough to cover their code, and leave the statistics to Release.
#ifndef RCM_TESTS_SUPPORT_TEST_BUDGET_H_
#define RCM_TESTS_SUPPORT_TEST_BUDGET_H_

#include <algorithm>

namespace rcm::test {

#ifdef RCM_SANITIZER_BUILD
inline constexpr bool kSanitizerBuild = true;
#else
inline constexpr bool kSanitizerBuild = false;
#endif

// `release` trials in Release; a tenth (at least 3) under the sanitizers.
inline int Trials(int release) {
  return kSanitizerBuild ? std::max(3, release / 10) : release;
}

// Whether a test checks statistics of its trials (Release only).
inline bool ChecksStatistics() { return !kSanitizerBuild; }

}  // namespace rcm::test

#endif  // RCM_TESTS_SUPPORT_TEST_BUDGET_H_
