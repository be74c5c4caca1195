#include "rcm/geometry/calibration_uncertainty.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

namespace rcm {
namespace {

using ::testing::HasSubstr;

TEST(CalibrationUncertainty, DriftPriorAndChecks) {
  const CalibrationUncertainty prior =
      CalibrationUncertainty::DriftPrior(0.002, 3e-4);
  EXPECT_EQ(prior.extrinsics_covariance.diagonal().head<3>(),
            Eigen::Vector3d::Constant(4e-6));
  EXPECT_NEAR(prior.extrinsics_covariance(4, 4), 9e-8, 1e-22);
  EXPECT_FALSE(prior.IsZero());
  EXPECT_TRUE(CalibrationUncertainty().IsZero());
  EXPECT_TRUE(prior.Check(8, 8).ok());
  CalibrationUncertainty bad = prior;
  bad.extrinsics_covariance(0, 1) = 1.0;
  EXPECT_THAT(bad.Check(8, 8).message(), HasSubstr("not symmetric"));
  bad = prior;
  bad.extrinsics_covariance(2, 2) = -1.0;
  EXPECT_THAT(bad.Check(8, 8).message(),
              HasSubstr("not positive semi-definite"));
  bad = prior;
  bad.right_lens_covariance = Eigen::MatrixXd::Identity(4, 4);
  EXPECT_THAT(bad.Check(8, 8).message(),
              HasSubstr("right lens covariance is 4x4, the camera has 8"));
  bad.right_lens_covariance(0, 0) = NAN;
  EXPECT_THAT(bad.Check(8, 4).message(), HasSubstr("not finite"));
}

}  // namespace
}  // namespace rcm
