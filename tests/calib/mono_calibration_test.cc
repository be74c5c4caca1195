#include "rcm/calib/mono_calibration.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "calib/synthetic_target_views.h"
#include "rcm/calib/board_warp.h"
#include "rcm/calib/calibration_covariance.h"
#include "rcm/calib/calibration_report.h"
#include "rcm/calib/cross_validation.h"
#include "rcm/calib/projection_uncertainty.h"
#include "support/sample_moments.h"
#include "support/test_rigs.h"

namespace rcm::calib::mono_calibration_test {
namespace {

// 9x6 inner corners, 40 mm squares: 0.32 x 0.20 m of corners.
CalibrationTarget Checkerboard() {
  return MakeCheckerboardTarget(9, 6, 0.04).value();
}

ImageSize SizeOf(const Camera& camera) {
  return {camera.width(), camera.height()};
}

// One camera's views of the board (bowed by `board_warp` [m]) at `poses`,
// with Gaussian pixel noise of `noise_px` per axis.
std::vector<StereoView> Observe(
    const Camera& camera, const std::vector<Rigid3d>& poses, double noise_px,
    unsigned seed,
    const Eigen::Vector2d& board_warp = Eigen::Vector2d::Zero()) {
  std::mt19937 rng(seed);
  const std::vector<Eigen::Vector3d> points =
      WarpedTargetPoints(Checkerboard(), board_warp);
  std::vector<std::optional<TargetObservation>> observations;
  for (const Rigid3d& pose : poses) {
    observations.push_back(test::ObserveTargetWith(
        camera, test::InAir(camera), pose, points, noise_px, &rng));
  }
  return MonoViews(observations);
}

// Views of the flat board at `num_views` poses of BoardPoses(pose_seed).
std::vector<StereoView> NoisyViews(const Camera& truth, int num_views,
                                   unsigned pose_seed, double noise_px,
                                   unsigned noise_seed) {
  return Observe(truth,
                 test::BoardPoses(truth, Checkerboard(), num_views, pose_seed),
                 noise_px, noise_seed);
}

StatusOr<StereoCalibration> Calibrate(const Camera& truth,
                                      const std::vector<StereoView>& views,
                                      StereoCalibrationOptions options = {}) {
  options.model = truth.model();
  return CalibrateMono(Checkerboard(), views, SizeOf(truth), options);
}

// Noise-free corners: the solution is the truth up to the solver's
// convergence (its parameter tolerance, 1e-14 relative: 5e-12 px of a
// 500 px focal length). 1e-9 in pixels (focal lengths, principal points),
// in the dimensionless coefficients and in metres (poses, the warp).
constexpr double kExactTolerance = 1e-9;

void ExpectExactRecovery(const Camera& truth,
                         const Eigen::Vector2d& board_warp) {
  const std::vector<Rigid3d> poses =
      test::BoardPoses(truth, Checkerboard(), 18, /*seed=*/7);
  const StatusOr<StereoCalibration> calibration =
      Calibrate(truth, Observe(truth, poses, 0.0, 1, board_warp));
  ASSERT_TRUE(calibration.ok()) << calibration.status().message();
  EXPECT_EQ(calibration->num_cameras, 1);
  for (int i = 0; i < truth.num_params(); ++i) {
    EXPECT_NEAR(calibration->cam0.camera.params()[i], truth.params()[i],
                kExactTolerance)
        << "parameter " << i;
  }
  EXPECT_LT((calibration->board_warp - board_warp).cwiseAbs().maxCoeff(),
            kExactTolerance);
  EXPECT_LT(calibration->rms_px, kExactTolerance);
  EXPECT_EQ(calibration->num_outliers, 0);
  EXPECT_EQ(calibration->num_views_used, 18);
  EXPECT_EQ(calibration->num_stereo_views, 0);
  // Each board pose, rotation and translation (metres).
  for (size_t v = 0; v < poses.size(); ++v) {
    const std::optional<Rigid3d>& pose = calibration->cam0_from_target[v];
    ASSERT_TRUE(pose.has_value()) << "view " << v;
    EXPECT_LT((pose->ToMatrix() - poses[v].ToMatrix()).cwiseAbs().maxCoeff(),
              kExactTolerance)
        << "view " << v;
  }
  // Every corner is cam0's; p = lens + 6 per view + the warp.
  for (const CornerResidual& corner : calibration->corners) {
    EXPECT_EQ(corner.camera, 0);
  }
  EXPECT_EQ(calibration->num_parameters, truth.num_params() + 6 * 18 + 2);
}

TEST(MonoCalibration, NoiseFreeRecoversLens) {
  // A radtan lens and a board bowed by 0.4 mm along x and -0.2 mm along y.
  ExpectExactRecovery(rcm::test::EurocRadtanCamera(),
                      Eigen::Vector2d(4e-4, -2e-4));
}

TEST(MonoCalibration, NoiseFreeRecoversWideEquidistantLens) {
  ExpectExactRecovery(rcm::test::AlphasenseRealisticRig().left(),
                      Eigen::Vector2d::Zero());
}

TEST(MonoCalibration, NoisyWithinTheNoisesBound) {
  // 0.2 px of Gaussian noise per axis, 18 views. The tolerance of each of
  // fx, fy, cx, cy follows from the noise: the first-order standard
  // deviation of the least-squares estimate is kNoisePx sqrt([(J^T J)^-1]_ii)
  // = sigma_i kNoisePx / pixel_sigma (sigma_i the reported one, which uses
  // the estimated noise pixel_sigma instead of kNoisePx); each estimate
  // lies within 4 of those (a 6e-5 two-sided chance per quantity). The
  // noise estimate sqrt(SSR / (2m - p)) is within 10 % of kNoisePx: with
  // 2m - p ~ 1800 degrees of freedom its relative standard deviation is
  // 1 / sqrt(2 * 1800) = 1.7 %. The RMS over all corners is
  // sqrt(2 kNoisePx^2 (2m - p) / 2m) ~ sqrt(2) kNoisePx, within 10 % too.
  constexpr double kNoisePx = 0.2;
  constexpr double kMaxSigmas = 4.0;
  const Camera truth = rcm::test::EurocRadtanCamera();
  const StatusOr<StereoCalibration> calibration =
      Calibrate(truth, NoisyViews(truth, 18, 7, kNoisePx, 11));
  ASSERT_TRUE(calibration.ok()) << calibration.status().message();
  EXPECT_NEAR(calibration->pixel_sigma, kNoisePx, 0.1 * kNoisePx);
  EXPECT_NEAR(calibration->rms_px, std::sqrt(2.0) * kNoisePx, 0.1 * kNoisePx);
  EXPECT_EQ(calibration->num_outliers, 0);
  const CameraCalibration& estimate = calibration->cam0;
  for (int i = 0; i < 4; ++i) {
    const double sigma =
        estimate.sigma[i] * kNoisePx / calibration->pixel_sigma;
    EXPECT_GT(sigma, 0.0);
    EXPECT_NEAR(estimate.camera.params()[i], truth.params()[i],
                kMaxSigmas * sigma)
        << "parameter " << i;
  }
  // The initialization's RMS is at least the solution's.
  EXPECT_GE(calibration->initial_rms_px, calibration->rms_px);
}

TEST(MonoCalibration, MonteCarloSigmaIsHonest) {
  // 100 noisy calibrations from 10 views at 0.3 px: the normalized errors
  // z = (estimate - truth) / sigma of fx, fy, cx, cy should have zero mean
  // and unit standard deviation. With N = 100 the sample standard
  // deviation of a unit normal has a standard error of 1 / sqrt(2N) = 0.07,
  // so [0.8, 1.3] is 2.8 standard errors below 1 and 4.2 above; the
  // mean's standard error is 1 / sqrt(N) = 0.1, so |mean| < 0.35 is 3.5 of
  // them. Fixed seeds: the draw is the same each run. About 2 s in
  // Release; the Release pass alone runs it (scripts/test_passes.sh).
  constexpr int kTrials = 100;
  constexpr double kNoisePx = 0.3;
  const Camera truth = rcm::test::EurocRadtanCamera();
  StereoCalibrationOptions options;
  options.num_threads = 1;
  std::vector<std::vector<double>> z(4);
  for (int trial = 0; trial < kTrials; ++trial) {
    const StatusOr<StereoCalibration> calibration = Calibrate(
        truth, NoisyViews(truth, 10, 3, kNoisePx, 2000 + trial), options);
    ASSERT_TRUE(calibration.ok()) << calibration.status().message();
    for (int i = 0; i < 4; ++i) {
      z[i].push_back(
          (calibration->cam0.camera.params()[i] - truth.params()[i]) /
          calibration->cam0.sigma[i]);
    }
  }
  const char* names[4] = {"fx", "fy", "cx", "cy"};
  for (int i = 0; i < 4; ++i) {
    EXPECT_TRUE(rcm::test::LooksStandardNormal(z[i], 0.35, 0.8, 1.3))
        << names[i];
  }
}

TEST(MonoCalibration, ReportLeaveOutUncertaintyAndSidecarCoverCam0Only) {
  const Camera truth = rcm::test::EurocRadtanCamera();
  const ImageSize size = SizeOf(truth);
  const std::vector<StereoView> views = NoisyViews(truth, 12, 7, 0.2, 5);
  StereoCalibrationOptions options;
  options.model = truth.model();
  const StatusOr<StereoCalibration> calibration =
      CalibrateMono(Checkerboard(), views, size, options);
  ASSERT_TRUE(calibration.ok()) << calibration.status().message();

  // The full covariance: the lens, 6 per view and the warp, no cam1 and no
  // extrinsics.
  const FullCovariance& full = calibration->full_covariance;
  EXPECT_EQ(full.size(), truth.num_params() + 6 * 12 + 2);
  EXPECT_EQ(full.lens_offset[0], 0);
  EXPECT_EQ(full.lens_offset[1], -1);
  EXPECT_EQ(full.extrinsics_offset, -1);
  const Eigen::Vector2d center(size.width / 2.0, size.height / 2.0);
  const double uncertainty =
      MeanFramesProjectionUncertainty(*calibration, 0, center);
  EXPECT_GT(uncertainty, 0.0);
  EXPECT_LT(uncertainty, 1.0);

  const CalibrationReport report =
      SummarizeCalibration(*calibration, views, size, size);
  EXPECT_EQ(report.num_cameras, 1);
  EXPECT_EQ(report.cameras[0].corners,
            static_cast<int>(calibration->corners.size()));
  EXPECT_EQ(report.cameras[1].corners, 0);
  EXPECT_GT(report.cameras[0].projection_uncertainty_median_px, 0.0);
  for (const std::string& warning : report.warnings) {
    EXPECT_EQ(warning.find("both cameras"), std::string::npos) << warning;
    EXPECT_EQ(warning.find("cam1"), std::string::npos) << warning;
  }
  // A one-camera per_view.csv row: cam1's corners 0 and its RMS nan.
  EXPECT_NE(FormatPerViewCsv(report).find(",0,0,0,"), std::string::npos);

  CrossValidationOptions folds;
  folds.folds = 3;
  const StatusOr<CrossValidation> cross_validation = CrossValidateStereo(
      Checkerboard(), views, size, size, *calibration, options, folds);
  ASSERT_TRUE(cross_validation.ok()) << cross_validation.status().message();
  std::vector<std::string> names;
  for (const ParameterSpread& p : cross_validation->parameters) {
    names.push_back(p.name);
  }
  EXPECT_EQ(names, (std::vector<std::string>{"cam0 fx", "cam0 fy", "cam0 cx",
                                             "cam0 cy", "board bowl"}));

  const CalibrationCovarianceFile sidecar =
      AirCalibrationCovariance(*calibration, *cross_validation);
  ASSERT_EQ(sidecar.cameras.size(), 1u);
  EXPECT_EQ(sidecar.cameras[0].intrinsics_covariance.rows(),
            truth.num_params());
  EXPECT_FALSE(sidecar.cameras[0].from_previous_covariance.has_value());
}

TEST(MonoCalibration, RightObservationIsAnError) {
  const Camera truth = rcm::test::EurocRadtanCamera();
  std::vector<StereoView> views = NoisyViews(truth, 6, 7, 0.0, 1);
  views[2].right = views[2].left;
  const StatusOr<StereoCalibration> calibration = Calibrate(truth, views);
  ASSERT_FALSE(calibration.ok());
  EXPECT_EQ(calibration.status().message(),
            "view 2 has a right observation: a one-camera calibration takes "
            "the left observations only (CalibrateStereo calibrates a pair)");
}

TEST(MonoCalibration, TooFewViewsIsAnError) {
  const Camera truth = rcm::test::EurocRadtanCamera();
  const StatusOr<StereoCalibration> calibration =
      Calibrate(truth, NoisyViews(truth, 2, 7, 0.0, 1));
  ASSERT_FALSE(calibration.ok());
  EXPECT_EQ(calibration.status().message(),
            "cam0 sees the target with at least 6 corners in 2 view(s); at "
            "least 3 are needed");
}

TEST(MonoCalibration, BadOptionsAndSizeAreErrors) {
  const Camera truth = rcm::test::EurocRadtanCamera();
  const std::vector<StereoView> views = NoisyViews(truth, 6, 7, 0.0, 1);
  StereoCalibrationOptions options;
  options.huber_px = -1.0;
  const StatusOr<StereoCalibration> bad_options =
      CalibrateMono(Checkerboard(), views, SizeOf(truth), options);
  ASSERT_FALSE(bad_options.ok());
  EXPECT_NE(bad_options.status().message().find("huber_px"), std::string::npos);
  const StatusOr<StereoCalibration> bad_size =
      CalibrateMono(Checkerboard(), views, {0, 480});
  ASSERT_FALSE(bad_size.ok());
  EXPECT_NE(bad_size.status().message().find("cam0"), std::string::npos)
      << bad_size.status().message();
}

}  // namespace
}  // namespace rcm::calib::mono_calibration_test
