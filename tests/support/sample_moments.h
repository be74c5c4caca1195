// The mean and the sample standard deviation of a set of values, for the
// Monte Carlo tests that check that normalized errors (estimate - truth) /
// sigma are standard normal.
#ifndef RCM_TESTS_SUPPORT_SAMPLE_MOMENTS_H_
#define RCM_TESTS_SUPPORT_SAMPLE_MOMENTS_H_

#include <gtest/gtest.h>

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

// Success when the values' |mean| <= max_abs_mean and their standard
// deviation lies in [min_stddev, max_stddev]; the failure states both.
inline ::testing::AssertionResult LooksStandardNormal(
    const std::vector<double>& values, double max_abs_mean, double min_stddev,
    double max_stddev) {
  const SampleMoments moments = Moments(values);
  if (std::abs(moments.mean) <= max_abs_mean && moments.stddev >= min_stddev &&
      moments.stddev <= max_stddev) {
    return ::testing::AssertionSuccess();
  }
  return ::testing::AssertionFailure()
         << "mean " << moments.mean << " (|mean| <= " << max_abs_mean
         << " wanted), standard deviation " << moments.stddev << " (["
         << min_stddev << ", " << max_stddev << "] wanted) over "
         << values.size() << " values";
}

}  // namespace rcm::test

#endif  // RCM_TESTS_SUPPORT_SAMPLE_MOMENTS_H_
