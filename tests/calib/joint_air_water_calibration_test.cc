// The joint calibration of air and water (CalibrateUnderwater with
// AirTargetViews): the lenses from both media, n, both media's extrinsics
// and every pose in one bundle adjustment.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <vector>

#include "calib/synthetic_target_views.h"
#include "rcm/calib/underwater_calibration.h"
#include "support/sample_moments.h"

namespace rcm::calib::joint_air_water_calibration_test {
namespace {

using test::BoardPoses;
using test::NarrowRadTanRig;
using test::ObserveStereo;
using test::ObserveStereoUnderwater;

constexpr double kDegree = M_PI / 180.0;
constexpr double kTrueN = 1.342;
// Noise-free corners: the truth up to the solver's convergence (1e-14
// relative parameter tolerance) and the flat port's solve: 1e-9 in n,
// radians and meters; the lens parameters are ~500 px (focal lengths,
// principal point) and ~0.1 (distortion): 1e-9 relative is 1e-6 px.
constexpr double kExact = 1e-9;
constexpr double kExactLensPx = 1e-6;

CalibrationTarget Checkerboard() {
  return MakeCheckerboardTarget(9, 6, 0.04).value();
}

// `camera` with its focal lengths scaled by 1 + `scale`, its principal
// point moved by `shift` px and k1 by `dk1`: an air calibration that is
// off by a few of its sigmas.
Camera Moved(const Camera& camera, double scale, double shift, double dk1) {
  std::vector<double> params(camera.params(),
                             camera.params() + camera.num_params());
  params[0] *= 1.0 + scale;
  params[1] *= 1.0 + scale;
  params[2] += shift;
  params[3] -= shift;
  params[4] += dk1;
  return camera.WithParams(params.data()).value();
}

// The rig in air (truth), the rig under water (cam1 turned 0.5 degrees
// since), and an air calibration whose lenses are off (the start).
struct Rigs {
  StereoRig air = NarrowRadTanRig();
  StereoRig water =
      air.WithCam1Moved(
             0.5 * kDegree * Eigen::Vector3d(0.3, -1.0, 0.2).normalized(),
             Eigen::Vector3d(3e-4, -1e-4, 2e-4))
          .value();
  StereoRig start = StereoRig::Create(Moved(air.left(), 0.004, 1.5, 0.004),
                                      Moved(air.right(), -0.003, -2.0, -0.003),
                                      air.right_from_left())
                        .value();
};

struct Case {
  Rigs rigs;
  std::vector<Rigid3d> water_poses;
  std::vector<StereoView> water_views;
  AirTargetViews air;
};

// 16 views under water and 16 in air, noise `noise_px` in both, a board
// bowed by `warp` in both.
Case MakeCase(double noise_px, unsigned seed,
              const Eigen::Vector2d& warp = Eigen::Vector2d::Zero()) {
  Case c;
  c.water_poses = BoardPoses(c.rigs.water.left(), Checkerboard(), 16,
                             /*seed=*/7, 0.45, 0.9, 35.0, kTrueN);
  c.water_views = ObserveStereoUnderwater(c.rigs.water, kTrueN, Checkerboard(),
                                          c.water_poses, noise_px, seed, warp);
  const std::vector<Rigid3d> air_poses =
      BoardPoses(c.rigs.air.left(), Checkerboard(), 16, /*seed=*/11);
  c.air.target = Checkerboard();
  c.air.views = ObserveStereo(c.rigs.air, Checkerboard(), air_poses, noise_px,
                              seed + 1000, warp);
  c.air.cam0_size = {640, 480};
  c.air.cam1_size = {640, 480};
  return c;
}

UnderwaterCalibrationOptions Lean() {
  UnderwaterCalibrationOptions options;
  options.folds = 0;
  options.fit_conventional_model = false;
  return options;
}

StatusOr<UnderwaterCalibration> Calibrate(
    const Case& c, const UnderwaterCalibrationOptions& options = Lean()) {
  return CalibrateUnderwater(Checkerboard(), c.water_views, {640, 480},
                             {640, 480}, c.rigs.start, options, nullptr,
                             &c.air);
}

double RotationError(const Rigid3d& a, const Rigid3d& b) {
  return Rigid3d{a.rotation * b.rotation.transpose(), Eigen::Vector3d::Zero()}
      .RotationAngle();
}

void ExpectSameLens(const Camera& estimate, const Camera& truth) {
  for (int i = 0; i < truth.num_params(); ++i) {
    EXPECT_NEAR(estimate.params()[i], truth.params()[i],
                i < 4 ? kExactLensPx : kExact)
        << "param " << i;
  }
}

TEST(JointAirWaterCalibration, ExactRecoversLensesNAndBothExtrinsics) {
  const Case c = MakeCase(0.0, 1);
  const StatusOr<UnderwaterCalibration> result = Calibrate(c);
  ASSERT_TRUE(result.ok()) << result.status().message();
  EXPECT_TRUE(result->lenses_estimated);
  EXPECT_NEAR(result->n, kTrueN, kExact);
  ExpectSameLens(result->rig.left(), c.rigs.air.left());
  ExpectSameLens(result->rig.right(), c.rigs.air.right());
  EXPECT_LT(RotationError(result->rig.right_from_left(),
                          c.rigs.water.right_from_left()),
            kExact);
  EXPECT_LT((result->rig.right_from_left().translation -
             c.rigs.water.right_from_left().translation)
                .norm(),
            kExact);
  EXPECT_LT(
      RotationError(result->air_cam1_from_cam0, c.rigs.air.right_from_left()),
      kExact);
  EXPECT_LT((result->air_cam1_from_cam0.translation -
             c.rigs.air.right_from_left().translation)
                .norm(),
            kExact);
  for (size_t v = 0; v < c.water_poses.size(); ++v) {
    ASSERT_TRUE(result->cam0_from_target[v].has_value());
    EXPECT_LT(RotationError(*result->cam0_from_target[v], c.water_poses[v]),
              kExact);
  }
  EXPECT_LT(result->rms_px, kExact);
  EXPECT_LT(result->air_rms_px, kExact);
  EXPECT_EQ(result->num_air_views_used, 16);
  EXPECT_EQ(result->num_views_used, 16);
}

TEST(JointAirWaterCalibration, ExactSameBowedBoardInBothMedia) {
  // One board bowed by 0.6 + 0.4 mm, shown in air and under water: one
  // warp for both, the truth.
  const Eigen::Vector2d warp(6e-4, 4e-4);
  Case c = MakeCase(0.0, 1, warp);
  c.air.same_board = true;
  const StatusOr<UnderwaterCalibration> result = Calibrate(c);
  ASSERT_TRUE(result.ok()) << result.status().message();
  EXPECT_NEAR(result->n, kTrueN, kExact);
  EXPECT_LT((result->board_warp - warp).norm(), kExact);
  EXPECT_EQ(result->air_board_warp, result->board_warp);
  ExpectSameLens(result->rig.left(), c.rigs.air.left());
  // Without --same-board each medium has its warp, both the truth.
  c.air.same_board = false;
  const StatusOr<UnderwaterCalibration> separate = Calibrate(c);
  ASSERT_TRUE(separate.ok()) << separate.status().message();
  EXPECT_LT((separate->board_warp - warp).norm(), kExact);
  EXPECT_LT((separate->air_board_warp - warp).norm(), kExact);
  // The shared warp uses both media's corners: its sigma is smaller.
  const StatusOr<UnderwaterCalibration> noisy_shared = [&] {
    Case n = MakeCase(0.3, 5, warp);
    n.air.same_board = true;
    return Calibrate(n);
  }();
  const StatusOr<UnderwaterCalibration> noisy_separate =
      Calibrate(MakeCase(0.3, 5, warp));
  ASSERT_TRUE(noisy_shared.ok() && noisy_separate.ok());
  EXPECT_LT(noisy_shared->board_warp_sigma.x(),
            noisy_separate->board_warp_sigma.x());
}

TEST(JointAirWaterCalibration, LensShareSplitsTheJointVariance) {
  // sigma_n^2 + sigma_n_lenses^2 is the joint covariance's C_nn, the
  // lenses' blocks are the covariance's, and the extrinsics' correlation
  // with the lenses is J C_{[w; t], L} (header).
  const Case c = MakeCase(0.3, 3);
  const StatusOr<UnderwaterCalibration> result = Calibrate(c);
  ASSERT_TRUE(result.ok()) << result.status().message();
  ASSERT_TRUE(result->sigma_n_lenses.has_value());
  const double c_nn = result->covariance.Block("n", "n")(0, 0);
  EXPECT_NEAR(result->sigma_n * result->sigma_n +
                  *result->sigma_n_lenses * *result->sigma_n_lenses,
              c_nn, 1e-12 * c_nn);
  EXPECT_GT(*result->sigma_n_lenses, 0.0);
  for (int k = 0; k < 2; ++k) {
    const Eigen::MatrixXd& lens = result->lens_covariance[k];
    ASSERT_EQ(lens.rows(), 8);
    EXPECT_GT(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(lens)
                  .eigenvalues()
                  .minCoeff(),
              0.0);
  }
  ASSERT_EQ(result->extrinsics_lens_covariance.rows(), 6);
  ASSERT_EQ(result->extrinsics_lens_covariance.cols(), 16);
  EXPECT_EQ(result->extrinsics_covariance_from_lenses,
            (Eigen::Matrix<double, 6, 6>::Zero()));
  // The lenses' joint block, and the calibration uncertainty a target-free
  // estimate reads from the sidecar is positive semi-definite and holds
  // the joint covariance's blocks.
  ASSERT_EQ(result->lens_cross_covariance.rows(), 8);
  ASSERT_EQ(result->lens_cross_covariance.cols(), 8);
  EXPECT_EQ(result->lens_cross_covariance,
            result->covariance.Block("cam0 lens", "cam1 lens"));
  CalibrationUncertainty sidecar;
  sidecar.extrinsics_covariance = result->extrinsic_change.covariance;
  sidecar.left_lens_covariance = result->lens_covariance[0];
  sidecar.right_lens_covariance = result->lens_covariance[1];
  sidecar.extrinsics_lens_covariance = result->extrinsics_lens_covariance;
  sidecar.lens_cross_covariance = result->lens_cross_covariance;
  EXPECT_TRUE(sidecar.Check(8, 8).ok()) << sidecar.Check(8, 8).message();
  std::printf(
      "joint: sigma_n %.6f (noise %.6f, lenses %.6f), sigma_fx0 %.3f px\n",
      std::sqrt(c_nn), result->sigma_n, *result->sigma_n_lenses,
      std::sqrt(result->lens_covariance[0](0, 0)));
}

TEST(JointAirWaterCalibration, MonteCarloSigmaIsHonest) {
  // 100 dives of 16 + 16 views at 0.3 px, fixed seeds: the z-scores of n
  // (total sigma: noise and lenses) and of each camera's fx and cx against
  // the joint covariance. For 100 standard normal draws the sample sd is
  // within 1 +- 0.071 (1 / sqrt(2 (N - 1))); the band [0.8, 1.3] (the
  // issue's) is about 3 of those. Measured: sd 0.86 (n), 1.04 (fx, cx).
  constexpr int kTrials = 100;
  std::vector<double> z_n;
  std::vector<double> z_lens;
  for (int t = 0; t < kTrials; ++t) {
    const Case c = MakeCase(0.3, 100 + t);
    const StatusOr<UnderwaterCalibration> result = Calibrate(c);
    ASSERT_TRUE(result.ok()) << result.status().message();
    const double sigma = std::hypot(result->sigma_n, *result->sigma_n_lenses);
    z_n.push_back((result->n - kTrueN) / sigma);
    const Camera* truth[2] = {&c.rigs.air.left(), &c.rigs.air.right()};
    const Camera* estimate[2] = {&result->rig.left(), &result->rig.right()};
    for (int k = 0; k < 2; ++k) {
      for (int i : {0, 2}) {
        z_lens.push_back((estimate[k]->params()[i] - truth[k]->params()[i]) /
                         std::sqrt(result->lens_covariance[k](i, i)));
      }
    }
  }
  const rcm::test::SampleMoments n = rcm::test::Moments(z_n);
  const rcm::test::SampleMoments lens = rcm::test::Moments(z_lens);
  std::printf(
      "joint Monte Carlo: z(n) mean %.3f sd %.3f; z(fx, cx) mean %.3f "
      "sd %.3f\n",
      n.mean, n.stddev, lens.mean, lens.stddev);
  EXPECT_GT(n.stddev, 0.8);
  EXPECT_LT(n.stddev, 1.3);
  EXPECT_LT(std::abs(n.mean), 3.0 / std::sqrt(kTrials));
  EXPECT_GT(lens.stddev, 0.8);
  EXPECT_LT(lens.stddev, 1.3);
}

TEST(JointAirWaterCalibration, AirImageSizeOtherThanTheRigsIsAnError) {
  Case c = MakeCase(0.0, 1);
  c.air.cam1_size = {320, 240};
  const StatusOr<UnderwaterCalibration> result = Calibrate(c);
  ASSERT_FALSE(result.ok());
  EXPECT_NE(result.status().message().find("cam1 air images are 320x240"),
            std::string::npos)
      << result.status().message();
}

TEST(JointAirWaterCalibration, SameBoardWithAnotherTargetIsAnError) {
  Case c = MakeCase(0.0, 1);
  c.air.same_board = true;
  c.air.target = MakeCheckerboardTarget(9, 6, 0.025).value();
  const StatusOr<UnderwaterCalibration> result = Calibrate(c);
  ASSERT_FALSE(result.ok());
  EXPECT_NE(result.status().message().find("is not the water board"),
            std::string::npos)
      << result.status().message();
}

TEST(JointAirWaterCalibration, NoAirViewIsAnError) {
  Case c = MakeCase(0.0, 1);
  for (StereoView& view : c.air.views) {
    view.left.reset();
    view.right.reset();
  }
  const StatusOr<UnderwaterCalibration> result = Calibrate(c);
  ASSERT_FALSE(result.ok());
  EXPECT_NE(result.status().message().find("no air view"), std::string::npos)
      << result.status().message();
}

}  // namespace
}  // namespace rcm::calib::joint_air_water_calibration_test
