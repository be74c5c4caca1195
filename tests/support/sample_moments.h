// The mean and the sample standard deviation of a set of values, for the
// Monte Carlo tests that check that normalized errors (estimate - truth) /
// sigma are standard normal.
#ifndef RCM_TESTS_SUPPORT_SAMPLE_MOMENTS_H_
#define RCM_TESTS_SUPPORT_SAMPLE_MOMENTS_H_

#include <cmath>
#include <vector>

namespace rcm::test {

struct SampleMoments {
  double mean = 0.0;
  double stddev = 0.0;  // with the 1 / (N - 1) normalization
};

// Needs at least 2 values.
inline SampleMoments Moments(const std::vector<double>& values) {
  const double count = static_cast<double>(values.size());
  SampleMoments moments;
  for (const double x : values) moments.mean += x;
  moments.mean /= count;
  double variance = 0.0;
  for (const double x : values) {
    variance += (x - moments.mean) * (x - moments.mean);
  }
  moments.stddev = std::sqrt(variance / (count - 1.0));
  return moments;
}

}  // namespace rcm::test

#endif  // RCM_TESTS_SUPPORT_SAMPLE_MOMENTS_H_
