#include "rcm/geometry/calibration_uncertainty.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

namespace rcm::calibration_uncertainty_test {
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

// The focal drift prior: s^2 g g^T on each lens, g = [fx, fy, 0, ...]; a
// camera with exact lenses gets that alone; 0 adds nothing.
TEST(CalibrationUncertainty, FocalDriftScalesBothFocalLengthsTogether) {
  Eigen::VectorXd left(8);
  left << 500.0, 502.0, 320.0, 240.0, 0.1, 0.0, 0.0, 0.0;
  Eigen::VectorXd right(4);
  right << 400.0, 400.0, 300.0, 200.0;
  CalibrationUncertainty uncertainty = CalibrationUncertainty::DriftPrior(0, 0);
  uncertainty.left_lens_covariance = Eigen::MatrixXd::Identity(8, 8);
  uncertainty.AddFocalDrift(0.0, left, right);
  EXPECT_EQ(uncertainty.left_lens_covariance, Eigen::MatrixXd::Identity(8, 8));
  EXPECT_EQ(uncertainty.right_lens_covariance.size(), 0);
  uncertainty.AddFocalDrift(0.003, left, right);
  EXPECT_NEAR(uncertainty.left_lens_covariance(0, 0), 1.0 + 2.25, 1e-12);
  EXPECT_NEAR(uncertainty.left_lens_covariance(0, 1), 0.003 * 0.003 * 500 * 502,
              1e-12);
  EXPECT_EQ(uncertainty.left_lens_covariance(2, 2), 1.0);
  EXPECT_EQ(uncertainty.left_lens_covariance(0, 2), 0.0);
  ASSERT_EQ(uncertainty.right_lens_covariance.rows(), 4);
  EXPECT_NEAR(uncertainty.right_lens_covariance(1, 1), 1.44, 1e-12);
  EXPECT_EQ(uncertainty.right_lens_covariance(2, 2), 0.0);
  // A perfectly correlated fx and fy: rank one, positive semi-definite.
  EXPECT_TRUE(uncertainty.Check(8, 4).ok())
      << uncertainty.Check(8, 4).message();
  EXPECT_EQ(CalibrationUncertainty::DescribeFocalDrift(0.003),
            "focal drift prior 0.3 %");
}

// The extrinsics' correlation with the lenses: JointCovariance places the
// blocks, and Check requires both lenses, the 6 x (p_l + p_r) shape and a
// positive semi-definite joint matrix.
TEST(CalibrationUncertainty, ExtrinsicsLensCorrelation) {
  Eigen::MatrixXd root(8, 8);
  for (int r = 0; r < 8; ++r) {
    for (int c = 0; c < 8; ++c) root(r, c) = std::sin(1.3 * r + 0.7 * c * c);
  }
  const Eigen::MatrixXd full = root * root.transpose();  // [w; dt; 1; 1]
  CalibrationUncertainty joint;
  joint.extrinsics_covariance = full.topLeftCorner<6, 6>();
  joint.left_lens_covariance = full.block(6, 6, 1, 1);
  joint.right_lens_covariance = full.block(7, 7, 1, 1);
  joint.extrinsics_lens_covariance = full.block(0, 6, 6, 2);
  // (The lens-lens block is zero in the joint matrix: a correlation
  // between the two lenses is not represented.)
  Eigen::MatrixXd expected = full;
  expected(6, 7) = expected(7, 6) = 0.0;
  EXPECT_EQ(joint.JointCovariance(), expected);
  joint.left_lens_covariance(0, 0) += 10.0;  // keeps it positive definite
  joint.right_lens_covariance(0, 0) += 10.0;
  EXPECT_TRUE(joint.Check(1, 1).ok()) << joint.Check(1, 1).message();

  CalibrationUncertainty bad = joint;
  bad.extrinsics_lens_covariance *= 1e3;
  EXPECT_THAT(bad.Check(1, 1).message(),
              HasSubstr("joint cam1_from_cam0 and lens covariance is not "
                        "positive semi-definite"));
  bad = joint;
  bad.extrinsics_lens_covariance.conservativeResize(6, 1);
  EXPECT_THAT(bad.Check(1, 1).message(), HasSubstr("is 6x1, not 6x2"));
  bad = joint;
  bad.right_lens_covariance.resize(0, 0);
  EXPECT_THAT(bad.Check(1, 1).message(), HasSubstr("needs both lens"));
}

// A fixed positive definite n x n matrix (entries of a sine table).
Eigen::MatrixXd FixedCovariance(int n, double shift) {
  Eigen::MatrixXd root(n, n);
  for (int r = 0; r < n; ++r) {
    for (int c = 0; c < n; ++c)
      root(r, c) = std::sin(shift + 1.3 * r + 0.7 * c * c);
  }
  return root * root.transpose() + 0.1 * Eigen::MatrixXd::Identity(n, n);
}

// The conditional covariance is the Schur complement Sigma_xx - Sigma_xq
// Sigma_qq^-1 Sigma_qx for an invertible Sigma_qq (to 1e-12 relative: the
// two differ only by rounding), ignores variables of zero variance, and is
// the marginal when x is uncorrelated with the rest.
TEST(CalibrationUncertainty, ConditionalCovarianceIsTheSchurComplement) {
  constexpr double kRounding = 1e-12;
  const Eigen::MatrixXd joint = FixedCovariance(7, 0.2);
  const Eigen::MatrixXd expected =
      joint.topLeftCorner(3, 3) - joint.topRightCorner(3, 4) *
                                      joint.bottomRightCorner(4, 4).inverse() *
                                      joint.bottomLeftCorner(4, 3);
  const Eigen::MatrixXd conditional = ConditionalCovariance(joint, 3);
  EXPECT_LT((conditional - expected).norm(), kRounding * joint.norm());
  EXPECT_EQ(conditional, conditional.transpose());

  // A variable of zero variance (an exact parameter) changes nothing.
  Eigen::MatrixXd padded = Eigen::MatrixXd::Zero(8, 8);
  padded.topLeftCorner(7, 7) = joint;
  EXPECT_LT((ConditionalCovariance(padded, 3) - expected).norm(),
            kRounding * joint.norm());

  Eigen::MatrixXd independent = joint;
  independent.topRightCorner(3, 4).setZero();
  independent.bottomLeftCorner(4, 3).setZero();
  EXPECT_EQ(ConditionalCovariance(independent, 3), joint.topLeftCorner(3, 3));
  EXPECT_EQ(ConditionalCovariance(joint, 7), joint);
}

// The rotation's prior: the marginal for a drift prior alone; for a rotation
// fitted through the lenses, w = K lenses + e, what e alone spreads (the
// lenses' share conditioned out, to rounding), however large K makes the
// marginal.
TEST(CalibrationUncertainty, RotationPriorIsTheRotationGivenTheRest) {
  const CalibrationUncertainty drift =
      CalibrationUncertainty::DriftPrior(1e-3, 1e-4);
  EXPECT_EQ(drift.RotationPriorCovariance(), drift.RotationCovariance());

  // Lenses of 2 parameters each, independent of the own error e of
  // [w; dt] (covariance E0); the rotation moves 0.01 rad per unit of lens.
  const Eigen::MatrixXd lens = FixedCovariance(4, 1.1);
  Eigen::Matrix<double, 6, 4> k = Eigen::Matrix<double, 6, 4>::Zero();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 4; ++c) k(r, c) = 0.01 * std::cos(r + 2.0 * c);
  }
  const Eigen::Matrix<double, 6, 6> own = 1e-8 * FixedCovariance(6, 0.4);
  CalibrationUncertainty fitted;
  fitted.extrinsics_covariance = own + k * lens * k.transpose();
  fitted.left_lens_covariance = lens.topLeftCorner(2, 2);
  fitted.right_lens_covariance = lens.bottomRightCorner(2, 2);
  fitted.lens_cross_covariance = lens.topRightCorner(2, 2);
  fitted.extrinsics_lens_covariance = k * lens;
  ASSERT_TRUE(fitted.Check(2, 2).ok()) << fitted.Check(2, 2).message();
  // Given the lenses and dt, w spreads as e does given e's dt.
  const Eigen::Matrix3d expected = ConditionalCovariance(own, 3);
  EXPECT_LT((fitted.RotationPriorCovariance() - expected).norm(),
            1e-9 * expected.norm());
  EXPECT_GT(fitted.RotationCovariance().trace(), 100.0 * expected.trace());
}

// The ports' parameters q join the joint covariance after the lenses, with
// their cross-covariance; a rotation fitted with the port tilts (w = K q +
// e) has the prior of e given the rest; sizes that do not fit are errors.
TEST(CalibrationUncertainty, PortsJoinTheJointCovariance) {
  const Eigen::MatrixXd q = 1e-4 * FixedCovariance(6, 0.7);
  Eigen::Matrix<double, 6, 6> k = Eigen::Matrix<double, 6, 6>::Zero();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 6; ++c) k(r, c) = 0.5 * std::sin(r + 1.5 * c);
  }
  const Eigen::Matrix<double, 6, 6> own = 1e-8 * FixedCovariance(6, 0.2);
  CalibrationUncertainty fitted;
  fitted.extrinsics_covariance = own + k * q * k.transpose();
  fitted.port_covariance = q;
  fitted.port_cross_covariance = k * q;
  ASSERT_TRUE(fitted.Check(4, 4).ok()) << fitted.Check(4, 4).message();
  const Eigen::MatrixXd joint = fitted.JointCovariance();
  ASSERT_EQ(joint.rows(), 12);
  EXPECT_EQ(joint.bottomRightCorner(6, 6), q);
  EXPECT_EQ(joint.topRightCorner(6, 6), k * q);
  const Eigen::Matrix3d expected = ConditionalCovariance(own, 3);
  EXPECT_LT((fitted.RotationPriorCovariance() - expected).norm(),
            1e-9 * expected.norm());
  EXPECT_FALSE(fitted.IsZero());

  CalibrationUncertainty bad = fitted;
  bad.port_covariance = q.topLeftCorner(5, 5);
  EXPECT_THAT(bad.Check(4, 4).message(), HasSubstr("port covariance is 5x5"));
  bad = fitted;
  bad.port_covariance.resize(0, 0);
  EXPECT_THAT(bad.Check(4, 4).message(),
              HasSubstr("needs the port covariance"));
  bad = fitted;
  bad.left_lens_covariance = Eigen::MatrixXd::Identity(4, 4);
  EXPECT_THAT(bad.Check(4, 4).message(),
              HasSubstr("port cross-covariance is 6x6, not 10x6"));
  bad = fitted;
  bad.port_cross_covariance *= 1e3;
  EXPECT_THAT(bad.Check(4, 4).message(), HasSubstr("not positive"));
}

}  // namespace
}  // namespace rcm::calibration_uncertainty_test
