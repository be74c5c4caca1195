#include "rcm/calib/cross_validation.h"

#include <gtest/gtest.h>

#include <cmath>

namespace rcm::calib {
namespace {

// From enough replicates, the root mean square of the two sigmas (also
// when the jackknife's is the smaller); from few, the larger of the two.
TEST(CrossValidation, JackknifeNoiseSigmaIsTheMeanVariance) {
  EXPECT_DOUBLE_EQ(JackknifeNoiseSigma(2.0, 1.0, kMinJackknifeReplicates),
                   std::sqrt(2.5));
  EXPECT_DOUBLE_EQ(JackknifeNoiseSigma(2.0, 3.0, 10), std::sqrt(6.5));
  // Equal sigmas: that sigma.
  EXPECT_DOUBLE_EQ(JackknifeNoiseSigma(0.25, 0.25, 10), 0.25);
}

TEST(CrossValidation, JackknifeNoiseSigmaFromFewReplicatesNotBelowCovariance) {
  EXPECT_EQ(JackknifeNoiseSigma(2.0, 1.0, kMinJackknifeReplicates - 1), 2.0);
  EXPECT_EQ(JackknifeNoiseSigma(2.0, 3.0, kMinJackknifeReplicates - 1), 3.0);
  // No replicates, or a jackknife that failed: the covariance's.
  EXPECT_EQ(JackknifeNoiseSigma(2.0, 3.0, 1), 2.0);
  EXPECT_EQ(JackknifeNoiseSigma(2.0, std::nan(""), 10), 2.0);
  EXPECT_EQ(JackknifeNoiseSigma(2.0, INFINITY, 10), 2.0);
}

}  // namespace
}  // namespace rcm::calib
