#include "rcm/calib/stereo_calibration.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "calib/synthetic_target_views.h"
#include "support/sample_moments.h"
#include "support/projection_error.h"
#include "support/test_rigs.h"

namespace rcm::calib::stereo_calibration_test {
namespace {

using test::BoardPoses;
using test::ObserveStereo;

// 9x6 inner corners, 40 mm squares: 0.32 x 0.20 m of corners.
CalibrationTarget Checkerboard() {
  CalibrationTarget target;
  target.type = TargetType::kCheckerboard;
  target.cols = 9;
  target.rows = 6;
  target.row_spacing = 0.04;
  target.col_spacing = 0.04;
  return target;
}

// Two radtan cameras (EuRoC's lens, the second with its own intrinsics) on
// a 0.11 m, 0.5-degree rig.
StereoRig RadTanRig() {
  const Camera left = rcm::test::EurocRadtanCamera();
  std::vector<double> distortion = left.Distortion();
  distortion[0] *= 0.9;
  distortion[3] = -1e-4;
  const Camera right =
      Camera::Create(LensModelId::kRadTan, left.width(), left.height(),
                     {left.fx() * 1.01, left.fy() * 1.012, left.cx() - 4.0,
                      left.cy() + 3.0},
                     distortion)
          .value();
  Rigid3d right_from_left;
  right_from_left.rotation =
      Eigen::AngleAxisd(0.5 * M_PI / 180.0,
                        Eigen::Vector3d(0.2, 1.0, 0.1).normalized())
          .toRotationMatrix();
  right_from_left.translation = Eigen::Vector3d(-0.11, 0.001, 0.002);
  return StereoRig::Create(left, right, right_from_left).value();
}

struct Truth {
  StereoRig rig;
  LensModelId model;
};

Truth RadTanTruth() { return {RadTanRig(), LensModelId::kRadTan}; }
Truth EquidistantTruth() {
  return {rcm::test::AlphasenseRealisticRig(), LensModelId::kEquidistant};
}

StatusOr<StereoCalibration> Calibrate(const Truth& truth,
                                      const std::vector<StereoView>& views,
                                      StereoCalibrationOptions options = {}) {
  options.model = truth.model;
  const Camera& l = truth.rig.left();
  const Camera& r = truth.rig.right();
  return CalibrateStereo(Checkerboard(), views, {l.width(), l.height()},
                         {r.width(), r.height()}, options);
}

// Largest |estimate - truth| over the parameters of a camera.
double MaxParamError(const Camera& estimate, const Camera& truth) {
  double error = 0.0;
  for (int i = 0; i < truth.num_params(); ++i) {
    error = std::max(error, std::abs(estimate.params()[i] - truth.params()[i]));
  }
  return error;
}

// Noise-free corners: the solution is the truth up to the solver's
// convergence. 1e-9 in pixels (focal lengths, principal points) and in the
// dimensionless coefficients; in metres and radians for the extrinsics.
constexpr double kExactTolerance = 1e-9;

void ExpectExactRecovery(const Truth& truth) {
  const std::vector<Rigid3d> poses =
      BoardPoses(truth.rig.left(), Checkerboard(), 18, /*seed=*/7);
  const std::vector<StereoView> views =
      ObserveStereo(truth.rig, Checkerboard(), poses, 0.0, 1);
  const StatusOr<StereoCalibration> calibration = Calibrate(truth, views);
  ASSERT_TRUE(calibration.ok()) << calibration.status().message();
  EXPECT_LT(MaxParamError(calibration->cam0.camera, truth.rig.left()),
            kExactTolerance);
  EXPECT_LT(MaxParamError(calibration->cam1.camera, truth.rig.right()),
            kExactTolerance);
  const Rigid3d& estimate = calibration->cam1_from_cam0;
  EXPECT_LT(
      (estimate.translation - truth.rig.right_from_left().translation).norm(),
      kExactTolerance);
  EXPECT_LT((estimate.rotation - truth.rig.right_from_left().rotation)
                .cwiseAbs()
                .maxCoeff(),
            kExactTolerance);
  EXPECT_LT(calibration->rms_px, kExactTolerance);
  EXPECT_EQ(calibration->num_outliers, 0);
  EXPECT_EQ(calibration->num_views_used, 18);
  for (size_t v = 0; v < poses.size(); ++v) {
    ASSERT_TRUE(calibration->cam0_from_target[v].has_value());
    EXPECT_LT(
        (calibration->cam0_from_target[v]->translation - poses[v].translation)
            .norm(),
        kExactTolerance);
  }
}

TEST(StereoCalibration, ExactRadTan) { ExpectExactRecovery(RadTanTruth()); }

TEST(StereoCalibration, ExactEquidistantWideLens) {
  ExpectExactRecovery(EquidistantTruth());
}

// A rig of two cameras of `left`'s model: the second with intrinsics and
// coefficients of its own, on RadTanRig()'s extrinsics.
Truth TwinTruth(const Camera& left) {
  std::vector<double> distortion = left.Distortion();
  for (size_t i = 0; i < distortion.size(); ++i) {
    distortion[i] *= i % 2 == 0 ? 0.97 : 1.02;
  }
  const Camera right =
      Camera::Create(left.model(), left.width(), left.height(),
                     {left.fx() * 1.004, left.fy() * 1.003, left.cx() - 2.5,
                      left.cy() + 1.5},
                     distortion)
          .value();
  return {StereoRig::Create(left, right, RadTanRig().right_from_left()).value(),
          left.model()};
}

StatusOr<StereoCalibration> CalibrateExact(const Truth& truth) {
  return Calibrate(truth, ObserveStereo(truth.rig, Checkerboard(),
                                        BoardPoses(truth.rig.left(),
                                                   Checkerboard(), 18,
                                                   /*seed=*/7),
                                        0.0, 1));
}

// The rational model's eight coefficients are not identifiable one by one
// from a lens's image (numerator and denominator trade against each other:
// on noise-free corners they come back within 2e-5 of the truth at an RMS
// of 4e-11 px), but the lens is: its projection over the whole image, where
// no corner was seen included, is the truth's within 1e-6 px, and every
// other parameter within 1e-9.
TEST(StereoCalibration, ExactRationalProjectsAsTheTruth) {
  constexpr double kMaxProjectionPx = 1e-6;
  const Truth truth = TwinTruth(rcm::test::RationalCamera());
  const StatusOr<StereoCalibration> calibration = CalibrateExact(truth);
  ASSERT_TRUE(calibration.ok()) << calibration.status().message();
  EXPECT_LT(calibration->rms_px, kExactTolerance);
  const Camera* estimates[2] = {&calibration->cam0.camera,
                                &calibration->cam1.camera};
  const Camera* truths[2] = {&truth.rig.left(), &truth.rig.right()};
  for (int c = 0; c < 2; ++c) {
    EXPECT_LT(rcm::test::MaxProjectionErrorPx(*estimates[c], *truths[c], 4.0),
              kMaxProjectionPx)
        << "cam" << c;
  }
  EXPECT_LT((calibration->cam1_from_cam0.translation -
             truth.rig.right_from_left().translation)
                .norm(),
            kExactTolerance);
}

TEST(StereoCalibration, ExactEucm) {
  ExpectExactRecovery(TwinTruth(rcm::test::EucmCamera()));
}

// The double sphere (truth xi = -0.18, the corners ~75 degrees off axis)
// from 18 views with 0.2 px of noise: near the axis its image is
// f / (1 + xi) r, so f and xi trade along a long, curved valley of the cost
// that only the off-axis shape closes, and these views do not close it:
// the fits end 140-220 px (45-75 %) high in f and 0.4-0.6 high in xi at
// the noise's RMS (4 seeds; noise-free, cam0 ends 0.46 px from the truth,
// cam1 200 px). What the data cannot support must show in the sigma: each
// camera's reported sigma of f is more than 5 % of f (39-72 px, 9-14 %;
// a radtan lens's is ~0.05 % here), not a precise-looking number. The tighter bound, the estimate within 5
// of its sigmas (2.6-4.0 seen: the valley is curved, so the linearized
// sigma is somewhat small), is checked too.
TEST(StereoCalibration, NoisyDoubleSphereReportsItsFocalLengthUncertain) {
  constexpr double kNoisePx = 0.2;
  constexpr double kMinRelativeSigma = 0.05;
  constexpr double kMaxSigmas = 5.0;
  const Truth truth = TwinTruth(rcm::test::DoubleSphereCamera());
  const StatusOr<StereoCalibration> calibration = Calibrate(
      truth, ObserveStereo(truth.rig, Checkerboard(),
                           BoardPoses(truth.rig.left(), Checkerboard(), 18,
                                      /*seed=*/7),
                           kNoisePx, 1));
  ASSERT_TRUE(calibration.ok()) << calibration.status().message();
  const CameraCalibration* estimates[2] = {&calibration->cam0,
                                           &calibration->cam1};
  const Camera* truths[2] = {&truth.rig.left(), &truth.rig.right()};
  for (int c = 0; c < 2; ++c) {
    const double f = estimates[c]->camera.fx();
    const double sigma = estimates[c]->sigma[0];
    std::printf("cam%d: f %.1f for %.1f, sigma %.1f\n", c, f, truths[c]->fx(),
                sigma);
    EXPECT_GT(sigma, kMinRelativeSigma * f) << "cam" << c;
    EXPECT_LT(std::abs(f - truths[c]->fx()), kMaxSigmas * sigma)
        << "cam" << c;
  }
}

// A ds fit of an equidistant lens that sees 89.5 degrees off axis: the fit
// runs alpha to 1, the end of the model's range. That is an error naming
// the coefficient, never a camera (nor a camchain) with a covariance taken
// at an active bound.
TEST(StereoCalibration, DoubleSpherePinnedAtItsBoundIsAnError) {
  Truth truth = EquidistantTruth();
  const std::vector<StereoView> views = ObserveStereo(
      truth.rig, Checkerboard(),
      BoardPoses(truth.rig.left(), Checkerboard(), 18, /*seed=*/7), 0.0, 1);
  truth.model = LensModelId::kDoubleSphere;
  const StatusOr<StereoCalibration> calibration = Calibrate(truth, views);
  ASSERT_FALSE(calibration.ok());
  EXPECT_THAT(calibration.status().message(),
              testing::MatchesRegex("the calibration failed: cam[01]'s ds "
                                    "(xi|alpha) ended at [-0-9.e]+, the end "
                                    "of its range, so the model does not fit "
                                    "these views \\(try --model eucm or "
                                    "equidistant, or views that reach the "
                                    "image corners\\)"));
}

// Normalized errors (estimate - truth) / reported sigma of the quantities
// the acceptance criteria name, for one noisy calibration.
struct NormalizedErrors {
  double fx0, cx0, fy1, cy1, baseline;
};

NormalizedErrors CalibrateNoisy(const Truth& truth, double noise_px,
                                unsigned seed, StereoCalibration* out,
                                int num_views = 18) {
  const std::vector<Rigid3d> poses =
      BoardPoses(truth.rig.left(), Checkerboard(), num_views, /*seed=*/7);
  const std::vector<StereoView> views =
      ObserveStereo(truth.rig, Checkerboard(), poses, noise_px, seed);
  StereoCalibration calibration = Calibrate(truth, views).value();
  const CameraCalibration& c0 = calibration.cam0;
  const CameraCalibration& c1 = calibration.cam1;
  NormalizedErrors errors;
  errors.fx0 = (c0.camera.fx() - truth.rig.left().fx()) / c0.sigma[0];
  errors.cx0 = (c0.camera.cx() - truth.rig.left().cx()) / c0.sigma[2];
  errors.fy1 = (c1.camera.fy() - truth.rig.right().fy()) / c1.sigma[1];
  errors.cy1 = (c1.camera.cy() - truth.rig.right().cy()) / c1.sigma[3];
  errors.baseline = (calibration.baseline - truth.rig.Baseline()) /
                    calibration.baseline_sigma;
  if (out != nullptr) *out = calibration;
  return errors;
}

TEST(StereoCalibration, NoisyWithinReportedSigma) {
  // 0.2 px of Gaussian noise per axis. Each estimate is within 4 of its
  // own reported standard deviations (a 6e-5 two-sided chance per
  // quantity if the sigmas are honest, which MonteCarloSigmaIsHonest
  // checks), and the noise estimate sqrt(SSR / (2m - p)) is within 10 %
  // of the truth: with 2m - p ~ 1700 degrees of freedom its relative
  // standard deviation is 1 / sqrt(2 * 1700) = 1.7 %.
  constexpr double kNoisePx = 0.2;
  constexpr double kMaxSigmas = 4.0;
  for (const Truth& truth : {RadTanTruth(), EquidistantTruth()}) {
    StereoCalibration calibration(truth.rig.left(), truth.rig.right());
    const NormalizedErrors e =
        CalibrateNoisy(truth, kNoisePx, /*seed=*/11, &calibration);
    EXPECT_LT(std::abs(e.fx0), kMaxSigmas);
    EXPECT_LT(std::abs(e.cx0), kMaxSigmas);
    EXPECT_LT(std::abs(e.fy1), kMaxSigmas);
    EXPECT_LT(std::abs(e.cy1), kMaxSigmas);
    EXPECT_LT(std::abs(e.baseline), kMaxSigmas);
    EXPECT_NEAR(calibration.pixel_sigma, kNoisePx, 0.1 * kNoisePx);
    EXPECT_EQ(calibration.num_outliers, 0);
    // The rms over all corners is the noise less the fitted fraction:
    // sqrt(2 sigma^2 (2m - p) / 2m) ~ sqrt(2) sigma.
    EXPECT_NEAR(calibration.rms_px, std::sqrt(2.0) * kNoisePx, 0.1 * kNoisePx);
    // Sigmas are small and positive: ~0.1 px on focal lengths here.
    EXPECT_GT(calibration.cam0.sigma[0], 0.0);
    EXPECT_LT(calibration.cam0.sigma[0], 1.0);
    EXPECT_GT(calibration.baseline_sigma, 0.0);
  }
}

TEST(StereoCalibration, MonteCarloSigmaIsHonest) {
  // 60 noisy calibrations of the radtan rig from 10 views: the normalized
  // errors (estimate - truth) / sigma should have zero mean and unit
  // standard deviation. With N = 60 the sample standard deviation of a
  // unit normal has a standard error of 1 / sqrt(2N) = 0.09, so [0.7, 1.3]
  // is a 3.3-sigma band; the mean's standard error is 1 / sqrt(N) = 0.13,
  // so |mean| < 0.45 is 3.5 sigma.
  constexpr int kTrials = 60;
  const Truth truth = RadTanTruth();
  std::vector<std::vector<double>> samples(5);
  for (int trial = 0; trial < kTrials; ++trial) {
    const NormalizedErrors e =
        CalibrateNoisy(truth, 0.3, /*seed=*/1000 + trial, nullptr, 10);
    const double values[5] = {e.fx0, e.cx0, e.fy1, e.cy1, e.baseline};
    for (int i = 0; i < 5; ++i) samples[i].push_back(values[i]);
  }
  const char* names[5] = {"fx0", "cx0", "fy1", "cy1", "baseline"};
  for (int i = 0; i < 5; ++i) {
    const rcm::test::SampleMoments z = rcm::test::Moments(samples[i]);
    EXPECT_LT(std::abs(z.mean), 0.45) << names[i];
    EXPECT_GT(z.stddev, 0.7) << names[i];
    EXPECT_LT(z.stddev, 1.3) << names[i];
  }
}

TEST(StereoCalibration, RejectsGrossOutliers) {
  // 0.2 px noise, and 3 % of the corners moved by 8-20 px (a detector
  // confusing corners). The outliers are found and the result is as good
  // as without them: within 4 reported sigmas.
  constexpr double kNoisePx = 0.2;
  const Truth truth = RadTanTruth();
  const std::vector<Rigid3d> poses =
      BoardPoses(truth.rig.left(), Checkerboard(), 18, /*seed=*/7);
  std::vector<StereoView> views =
      ObserveStereo(truth.rig, Checkerboard(), poses, kNoisePx, 3);
  const int num_moved = test::AddGrossOutliers(0.03, /*seed=*/5, &views);
  ASSERT_GT(num_moved, 30);
  const StereoCalibration calibration = Calibrate(truth, views).value();
  EXPECT_EQ(calibration.num_outliers, num_moved);
  for (const CornerResidual& corner : calibration.corners) {
    if (!corner.inlier) {
      EXPECT_GT(corner.residual.norm(), 5.0);
    }
  }
  EXPECT_NEAR(calibration.pixel_sigma, kNoisePx, 0.1 * kNoisePx);
  EXPECT_LT(std::abs(calibration.cam0.camera.fx() - truth.rig.left().fx()),
            4.0 * calibration.cam0.sigma[0]);
  EXPECT_LT(std::abs(calibration.baseline - truth.rig.Baseline()),
            4.0 * calibration.baseline_sigma);
  // The rms over all corners counts the outliers, the inlier rms does not.
  EXPECT_GT(calibration.rms_px, 2.0 * calibration.inlier_rms_px);
}

TEST(StereoCalibration, UsesSingleCameraViews) {
  // Six of 18 views show the target to the left camera only: they pose the
  // board from cam0 alone and still count for cam0's intrinsics.
  const Truth truth = RadTanTruth();
  const std::vector<Rigid3d> poses =
      BoardPoses(truth.rig.left(), Checkerboard(), 18, /*seed=*/7);
  std::vector<StereoView> views =
      ObserveStereo(truth.rig, Checkerboard(), poses, 0.0, 1);
  for (int v = 0; v < 6; ++v) views[v].right.reset();
  StereoCalibration with = Calibrate(truth, views).value();
  EXPECT_EQ(with.num_views_used, 18);
  EXPECT_EQ(with.num_stereo_views, 12);
  EXPECT_LT(MaxParamError(with.cam0.camera, truth.rig.left()), kExactTolerance);
  EXPECT_LT(MaxParamError(with.cam1.camera, truth.rig.right()),
            kExactTolerance);
  StereoCalibrationOptions stereo_only;
  stereo_only.use_single_camera_views = false;
  StereoCalibration without = Calibrate(truth, views, stereo_only).value();
  EXPECT_EQ(without.num_views_used, 12);
  EXPECT_FALSE(without.cam0_from_target[0].has_value());
}

TEST(StereoCalibration, NoStereoViewIsAnError) {
  const Truth truth = RadTanTruth();
  const std::vector<Rigid3d> poses =
      BoardPoses(truth.rig.left(), Checkerboard(), 8, /*seed=*/7);
  std::vector<StereoView> views =
      ObserveStereo(truth.rig, Checkerboard(), poses, 0.0, 1);
  for (int v = 0; v < 8; ++v)
    (v % 2 == 0 ? views[v].left : views[v].right).reset();
  const StatusOr<StereoCalibration> calibration = Calibrate(truth, views);
  ASSERT_FALSE(calibration.ok());
  EXPECT_NE(calibration.status().message().find("both images"),
            std::string::npos)
      << calibration.status().message();
}

TEST(StereoCalibration, TooFewViewsIsAnError) {
  const Truth truth = RadTanTruth();
  const std::vector<StereoView> views = ObserveStereo(
      truth.rig, Checkerboard(),
      BoardPoses(truth.rig.left(), Checkerboard(), 2, /*seed=*/7), 0.0, 1);
  const StatusOr<StereoCalibration> calibration = Calibrate(truth, views);
  ASSERT_FALSE(calibration.ok());
  EXPECT_EQ(calibration.status().message(),
            "cam0 sees the target with at least 6 corners in 2 view(s); at "
            "least 3 are needed");
  EXPECT_FALSE(Calibrate(truth, {}).ok());
}

TEST(StereoCalibration, BadObservationsAreErrors) {
  const Truth truth = RadTanTruth();
  std::vector<StereoView> views = ObserveStereo(
      truth.rig, Checkerboard(),
      BoardPoses(truth.rig.left(), Checkerboard(), 6, /*seed=*/7), 0.0, 1);
  std::vector<StereoView> bad_id = views;
  bad_id[2].left->point_ids[0] = 54;
  EXPECT_EQ(Calibrate(truth, bad_id).status().message(),
            "view 2: point id 54 is not on the target");
  std::vector<StereoView> nan_pixel = views;
  nan_pixel[1].right->pixels[3].x() = std::nan("");
  EXPECT_EQ(Calibrate(truth, nan_pixel).status().message(),
            "view 1: a corner pixel is not finite");
  std::vector<StereoView> mismatched = views;
  mismatched[0].left->pixels.pop_back();
  EXPECT_FALSE(Calibrate(truth, mismatched).ok());
}

TEST(StereoCalibrationOptions, Check) {
  EXPECT_TRUE(StereoCalibrationOptions().Check().ok());
  StereoCalibrationOptions options;
  options.huber_px = 0.0;
  EXPECT_FALSE(options.Check().ok());
  options = {};
  options.outlier_sigmas = std::nan("");
  EXPECT_FALSE(options.Check().ok());
  options = {};
  options.min_corners_per_view = 3;
  EXPECT_FALSE(options.Check().ok());
  options = {};
  options.num_threads = 0;
  EXPECT_FALSE(options.Check().ok());
  options = {};
  options.max_outlier_rounds = -1;
  EXPECT_FALSE(options.Check().ok());
  // Invalid options are reported by CalibrateStereo, not CHECKed.
  options = {};
  options.huber_px = -1.0;
  const Truth truth = RadTanTruth();
  EXPECT_EQ(Calibrate(truth, {}, options).status().message(),
            "huber_px must be positive and finite");
}

}  // namespace
}  // namespace rcm::calib::stereo_calibration_test
