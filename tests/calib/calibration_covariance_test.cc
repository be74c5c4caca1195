#include "rcm/calib/calibration_covariance.h"

#include <gtest/gtest.h>

#include <cmath>

#include "rcm/geometry/calibration_uncertainty.h"
#include "support/test_rigs.h"

namespace rcm::calib {
namespace {

// A fixed positive definite n x n matrix (entries of a sine table), scaled.
Eigen::MatrixXd FixedCovariance(int n, double shift, double scale) {
  Eigen::MatrixXd root(n, n);
  for (int r = 0; r < n; ++r) {
    for (int c = 0; c < n; ++c) root(r, c) = std::sin(shift + 1.3 * r + c * c);
  }
  return scale *
         (root * root.transpose() + 0.1 * Eigen::MatrixXd::Identity(n, n));
}

// An underwater calibration whose extrinsics were fitted through air lenses
// of covariance L (the air rig's sidecar): a lens error moves them by K
// (X = K L, their lens share K L K^T), the water views measured them with
// covariance E0 given the lenses, and the leave-out spread is twice that
// about y and 1.5 times along z. The sidecar keeps X and the lens share as
// the fit has them and widens only E0, per component:
// Cov([w; dt] | lenses) = S E0 S (to rounding), the response to the lenses
// K unchanged, the joint positive semi-definite.
TEST(UnderwaterCalibrationCovariance, WidensOnlyWhatTheWaterViewsMeasured) {
  const StereoRig rig = test::AlphasenseRealisticRig();
  const int p = rig.left().num_params();
  ASSERT_EQ(rig.right().num_params(), p);
  CalibrationUncertainty air;
  air.left_lens_covariance = FixedCovariance(p, 0.3, 1.0);
  air.right_lens_covariance = FixedCovariance(p, 0.9, 1.0);
  const StereoRig air_rig = rig.WithCalibrationUncertainty(air).value();
  Eigen::MatrixXd lenses = Eigen::MatrixXd::Zero(2 * p, 2 * p);
  lenses.topLeftCorner(p, p) = air.left_lens_covariance;
  lenses.bottomRightCorner(p, p) = air.right_lens_covariance;
  Eigen::MatrixXd k(6, 2 * p);
  for (int r = 0; r < 6; ++r) {
    for (int c = 0; c < 2 * p; ++c) k(r, c) = 1e-3 * std::cos(r + 0.5 * c);
  }
  const Eigen::Matrix<double, 6, 6> own = FixedCovariance(6, 0.1, 1e-9);

  UnderwaterCalibration result(rig);
  result.extrinsics_estimated = true;
  result.extrinsic_change.covariance = own;
  result.extrinsics_lens_covariance = k * lenses;
  result.extrinsics_covariance_from_lenses = k * lenses * k.transpose();
  Eigen::Matrix<double, 6, 1> sigma = own.diagonal().cwiseSqrt();
  result.extrinsic_change.rotation_sigma_deg = sigma.head<3>() * 180.0 / M_PI;
  result.extrinsic_change.translation_sigma_mm = sigma.tail<3>() * 1e3;
  Eigen::Matrix<double, 6, 1> scales;
  scales << 1.0, 2.0, 1.0, 1.0, 1.0, 1.5;
  result.extrinsic_change.rotation_leave_out_sigma_deg =
      Eigen::Vector3d(scales.head<3>().cwiseProduct(
          result.extrinsic_change.rotation_sigma_deg));
  result.extrinsic_change.translation_leave_out_sigma_mm =
      Eigen::Vector3d(scales.tail<3>().cwiseProduct(
          result.extrinsic_change.translation_sigma_mm));
  // A leave-out spread below the covariance's widens nothing.
  (*result.extrinsic_change.translation_leave_out_sigma_mm)[0] *= 0.5;
  EXPECT_LT((ExtrinsicsLeaveOutScales(result.extrinsic_change) - scales)
                .cwiseAbs()
                .maxCoeff(),
            1e-12);

  const CalibrationCovarianceFile file =
      UnderwaterCalibrationCovariance(result, air_rig);
  ASSERT_EQ(file.cameras.size(), 2u);
  EXPECT_EQ(file.medium, "water");
  EXPECT_EQ(file.cameras[1].from_previous_intrinsics_covariance,
            result.extrinsics_lens_covariance);
  CalibrationUncertainty written;
  ASSERT_TRUE(file.cameras[1].from_previous_covariance.has_value());
  written.extrinsics_covariance = *file.cameras[1].from_previous_covariance;
  written.left_lens_covariance = file.cameras[0].intrinsics_covariance;
  written.right_lens_covariance = file.cameras[1].intrinsics_covariance;
  written.extrinsics_lens_covariance =
      file.cameras[1].from_previous_intrinsics_covariance;
  ASSERT_TRUE(written.Check(p, p).ok()) << written.Check(p, p).message();
  const Eigen::MatrixXd given_lenses =
      ConditionalCovariance(written.JointCovariance(), 6);
  const Eigen::DiagonalMatrix<double, 6> s(scales);
  const Eigen::Matrix<double, 6, 6> expected = s * own * s;
  // Rounding: the lens share is ~1e3 times E0 in places, and the
  // conditional subtracts it back out.
  EXPECT_LT((given_lenses - expected).norm(), 1e-6 * expected.norm());
  // The extrinsics' response to a lens error, X' L^-1, is the fit's K
  // (scaling X with the extrinsics, the sidecar before, made it S K: the
  // same conditional, another response).
  const Eigen::MatrixXd response =
      file.cameras[1].from_previous_intrinsics_covariance * lenses.inverse();
  EXPECT_LT((response - k).norm(), 1e-9 * k.norm());
}

}  // namespace
}  // namespace rcm::calib
