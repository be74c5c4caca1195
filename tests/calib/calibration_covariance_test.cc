#include "rcm/calib/calibration_covariance.h"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <vector>

#include "rcm/geometry/calibration_uncertainty.h"
#include "support/test_rigs.h"

namespace rcm::calib::calibration_covariance_test {
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

// The fit's covariance of [n, w, t, cam0 air_gap, cam0 port_tilt, cam1
// port_tilt] (no cam1 air gap: not estimated), its blocks named as
// CalibrateUnderwater names them, and the held geometry's part `geometry`
// (11 x 11, the blocks after n).
UnderwaterCovariance FitCovariance(const Eigen::MatrixXd& geometry) {
  UnderwaterCovariance covariance;
  covariance.blocks = {{"n", 0, 1},
                       {"cam1_from_cam0", 1, 6},
                       {"cam0 air_gap", 7, 1},
                       {"cam0 port_tilt", 8, 2},
                       {"cam1 port_tilt", 10, 2}};
  covariance.matrix = Eigen::MatrixXd::Zero(12, 12);
  covariance.matrix(0, 0) = 1e-6;
  covariance.matrix.bottomRightCorner(11, 11) = geometry;
  return covariance;
}

// The whitened mean of the leave-out spread: J = C^1/2 diag(d) C^1/2 gives
// mean(d) (trace(C^-1 J) = sum d); a spread below the covariance widens
// nothing; no leave-out, nothing.
TEST(UnderwaterCalibrationCovariance, LeaveOutScaleIsTheWhitenedMeanSpread) {
  UnderwaterCalibration result(rcm::test::AlphasenseRealisticRig());
  const Eigen::MatrixXd geometry = FixedCovariance(11, 0.4, 1e-6);
  result.covariance = FitCovariance(geometry);
  EXPECT_EQ(GeometryLeaveOutScale(result), 1.0);
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(geometry);
  const Eigen::MatrixXd root = eigen.operatorSqrt();
  Eigen::VectorXd d(11);
  for (int i = 0; i < 11; ++i) d[i] = 1.0 + 0.5 * i;  // mean 3.5
  UnderwaterLeaveOut leave_out;
  leave_out.covariance = Eigen::MatrixXd::Zero(12, 12);
  leave_out.covariance(0, 0) = 100.0;  // n's spread is not the geometry's
  leave_out.covariance.bottomRightCorner(11, 11) = root * d.asDiagonal() * root;
  result.leave_out = leave_out;
  EXPECT_NEAR(GeometryLeaveOutScale(result), 3.5, 1e-9);
  result.leave_out->covariance.bottomRightCorner(11, 11) = 0.25 * geometry;
  EXPECT_EQ(GeometryLeaveOutScale(result), 1.0);
}

// An underwater calibration whose extrinsics and ports were fitted through
// air lenses of covariance L (the air rig's sidecar): a lens error moves
// the held geometry h = [w; dt; q] by K (X = K L, their lens share
// K L K^T), the water views measured h with covariance G0 given the lenses,
// and the leave-out spread is 2.25 G0 (s^2 = 2.25). The sidecar keeps X and
// the lens share as the fit has them and widens only G0, as one:
// Cov(h | lenses) = 2.25 G0 (to rounding), the response to the lenses K
// unchanged, the joint positive semi-definite, the ports in their block.
TEST(UnderwaterCalibrationCovariance, WidensOnlyWhatTheWaterViewsMeasured) {
  const StereoRig rig = rcm::test::AlphasenseRealisticRig();
  const int p = rig.left().num_params();
  ASSERT_EQ(rig.right().num_params(), p);
  CalibrationUncertainty air;
  air.left_lens_covariance = FixedCovariance(p, 0.3, 1.0);
  air.right_lens_covariance = FixedCovariance(p, 0.9, 1.0);
  const StereoRig air_rig = rig.WithCalibrationUncertainty(air).value();
  Eigen::MatrixXd lenses = Eigen::MatrixXd::Zero(2 * p, 2 * p);
  lenses.topLeftCorner(p, p) = air.left_lens_covariance;
  lenses.bottomRightCorner(p, p) = air.right_lens_covariance;
  // h's 12 rows; cam1's air gap (row 9) was not estimated.
  Eigen::MatrixXd k(12, 2 * p);
  for (int r = 0; r < 12; ++r) {
    for (int c = 0; c < 2 * p; ++c) {
      k(r, c) = r == 9 ? 0.0 : 1e-3 * std::cos(r + 0.5 * c);
    }
  }
  // G0 over the 11 estimated components, in h's 12 rows.
  const Eigen::MatrixXd estimated = FixedCovariance(11, 0.1, 1e-9);
  const std::vector<int> rows = {0, 1, 2, 3, 4, 5, 6, 7, 8, 10, 11};
  Eigen::MatrixXd own = Eigen::MatrixXd::Zero(12, 12);
  for (int r = 0; r < 11; ++r) {
    for (int c = 0; c < 11; ++c) own(rows[r], rows[c]) = estimated(r, c);
  }
  const Eigen::MatrixXd lens_share = k * lenses * k.transpose();

  UnderwaterCalibration result(rig);
  result.extrinsics_estimated = true;
  result.ports_estimated = true;
  result.extrinsic_change.covariance = own.topLeftCorner(6, 6);
  result.extrinsics_port_covariance = own.topRightCorner(6, 6);
  result.port_covariance = own.bottomRightCorner(6, 6);
  result.extrinsics_lens_covariance = (k * lenses).topRows(6);
  result.port_lens_covariance = (k * lenses).bottomRows(6);
  result.extrinsics_covariance_from_lenses = lens_share.topLeftCorner(6, 6);
  result.port_covariance_from_lenses = lens_share.bottomRows(6);
  // The fit's covariance in its own layout (the change's Jacobian taken as
  // the identity), and the replicates' spread 1.5 times its sigmas.
  result.covariance = FitCovariance(estimated);
  UnderwaterLeaveOut leave_out;
  leave_out.covariance = 2.25 * result.covariance.matrix;
  result.leave_out = leave_out;
  ASSERT_NEAR(GeometryLeaveOutScale(result), 2.25, 1e-9);

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
  written.port_covariance = file.port_covariance;
  written.port_cross_covariance = file.port_cross_covariance;
  ASSERT_TRUE(written.Check(p, p).ok()) << written.Check(p, p).message();
  // The joint in h's order: [w; dt; q; lenses].
  const Eigen::MatrixXd joint = written.JointCovariance();
  const int n = static_cast<int>(joint.rows());
  ASSERT_EQ(n, 12 + 2 * p);
  std::vector<int> order = {0, 1, 2, 3, 4, 5};
  for (int i = 0; i < 6; ++i) order.push_back(6 + 2 * p + i);
  for (int i = 0; i < 2 * p; ++i) order.push_back(6 + i);
  Eigen::MatrixXd reordered(n, n);
  for (int r = 0; r < n; ++r) {
    for (int c = 0; c < n; ++c) reordered(r, c) = joint(order[r], order[c]);
  }
  const Eigen::MatrixXd given_lenses = ConditionalCovariance(reordered, 12);
  const Eigen::MatrixXd expected = 2.25 * own;
  // Rounding: the lens share is ~1e3 times G0 in places, and the
  // conditional subtracts it back out.
  EXPECT_LT((given_lenses - expected).norm(), 1e-6 * expected.norm());
  // h's response to a lens error, X' L^-1, is the fit's K (scaling X with
  // h would make it another response with the same conditional).
  const Eigen::MatrixXd response =
      reordered.block(0, 12, 12, 2 * p) * lenses.inverse();
  EXPECT_LT((response - k).norm(), 1e-9 * k.norm());
}

}  // namespace
}  // namespace rcm::calib::calibration_covariance_test
