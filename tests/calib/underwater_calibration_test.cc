#include "rcm/calib/underwater_calibration.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "calib/synthetic_target_views.h"
#include "rcm/camera/refractive_model.h"
#include "rcm/sim/reference_rigs.h"
#include "support/sample_moments.h"

namespace rcm::calib::underwater_calibration_test {
namespace {

using test::BoardPoses;
using test::NarrowRadTanRig;
using test::ObserveStereoUnderwater;

constexpr double kDegree = M_PI / 180.0;
// Seawater, as in the dive that motivated the refinement.
constexpr double kTrueN = 1.342;

// Noise-free corners: the solution is the truth up to the solver's
// convergence (parameter tolerance 1e-14 relative, board_bundle_
// adjustment.cc) and the flat port's solve (1e-15 relative): 1e-9 in n
// (dimensionless), radians and meters.
constexpr double kExactTolerance = 1e-9;

// 9x6 inner corners, 40 mm squares: 0.32 x 0.20 m of corners.
CalibrationTarget Checkerboard() {
  return MakeCheckerboardTarget(9, 6, 0.04).value();
}

// The housing drift of the dive: cam1 turned by 0.5 degrees about a skew
// axis (its largest component about y) and shifted by 0.3 mm.
const Eigen::Vector3d kDriftRotation =
    0.5 * kDegree * Eigen::Vector3d(0.3, -1.0, 0.2).normalized();
const Eigen::Vector3d kDriftTranslation(3e-4, -1e-4, 2e-4);

// 8 mm air gap + 6 mm acrylic, the thick housing of docs/thick_ports.md.
FlatPort ThickPort(double air_gap = 0.008) {
  FlatPort port;
  port.air_gap = air_gap;
  port.glass_thickness = 0.006;
  port.glass_index = 1.49;
  return port;
}

// A case: the air calibration, the rig as it truly is under water, and
// the views of the target through the true rig's ports.
struct Dive {
  StereoRig air;
  StereoRig truth;
  double n = kTrueN;
  std::vector<Rigid3d> poses;
  std::vector<StereoView> views;
};

// `rig` as the housings drifted.
StereoRig Drifted(const StereoRig& rig) {
  return rig.WithCam1Moved(kDriftRotation, kDriftTranslation).value();
}

Dive MakeDive(const StereoRig& air, const StereoRig& truth, double n,
              int num_views, double noise_px, unsigned seed) {
  Dive dive{air, truth, n, {}, {}};
  dive.poses = BoardPoses(truth.left(), Checkerboard(), num_views, /*seed=*/7,
                          0.45, 0.9, 35.0, n);
  dive.views = ObserveStereoUnderwater(truth, n, Checkerboard(), dive.poses,
                                       noise_px, seed);
  return dive;
}

// The Alphasense rig (air) drifted by kDrift (truth), thin ports.
Dive AlphasenseDive(int num_views = 16, double noise_px = 0.0,
                    unsigned seed = 1) {
  const StereoRig air = AlphasenseFrontUnrectifiedRig();
  return MakeDive(air, Drifted(air), kTrueN, num_views, noise_px, seed);
}

StatusOr<UnderwaterCalibration> Calibrate(
    const Dive& dive, UnderwaterCalibrationOptions options = {}) {
  const Camera& l = dive.air.left();
  const Camera& r = dive.air.right();
  return CalibrateUnderwater(Checkerboard(), dive.views,
                             {l.width(), l.height()}, {r.width(), r.height()},
                             dive.air, options);
}

// Options for the exact and Monte Carlo tests: no leave-out, no
// conventional fit (each tested once below).
UnderwaterCalibrationOptions Lean() {
  UnderwaterCalibrationOptions options;
  options.folds = 0;
  options.fit_conventional_model = false;
  return options;
}

// The lens parameters of `a` and `b` are the same bits.
bool SameBits(const Camera& a, const Camera& b) {
  return a.model() == b.model() && a.width() == b.width() &&
         a.height() == b.height() &&
         std::memcmp(a.params(), b.params(), sizeof(double) * 8) == 0;
}

double RotationError(const Rigid3d& a, const Rigid3d& b) {
  return Rigid3d{a.rotation * b.rotation.transpose(), Eigen::Vector3d::Zero()}
      .RotationAngle();
}

// n, the extrinsics, the estimated air gaps and port normals and every
// target pose are the truth; the lenses are the air calibration's,
// untouched; the residuals vanish.
void ExpectExact(const Dive& dive, const UnderwaterCalibration& result) {
  for (int c = 0; c < 2; ++c) {
    const PortEstimate& estimate = result.ports[c];
    if (!estimate.air_gap_estimated && !estimate.tilt_estimated) continue;
    ASSERT_TRUE(dive.truth.ports().has_value());
    ASSERT_TRUE(result.rig.ports().has_value());
    const FlatPort& truth =
        c == 0 ? dive.truth.ports()->left : dive.truth.ports()->right;
    const FlatPort& port =
        c == 0 ? result.rig.ports()->left : result.rig.ports()->right;
    EXPECT_EQ(port, estimate.port);
    EXPECT_NEAR(port.air_gap, truth.air_gap, kExactTolerance) << c;
    EXPECT_LT((port.normal - truth.normal).norm(), kExactTolerance) << c;
    EXPECT_EQ(port.glass_thickness, truth.glass_thickness) << c;
  }
  EXPECT_NEAR(result.n, dive.n, kExactTolerance);
  EXPECT_TRUE(SameBits(result.rig.left(), dive.air.left()));
  EXPECT_TRUE(SameBits(result.rig.right(), dive.air.right()));
  if (result.extrinsics_estimated) {
    EXPECT_LT(RotationError(result.rig.right_from_left(),
                            dive.truth.right_from_left()),
              kExactTolerance);
    EXPECT_LT((result.rig.right_from_left().translation -
               dive.truth.right_from_left().translation)
                  .norm(),
              kExactTolerance);
  }
  EXPECT_LT(result.rms_px, kExactTolerance);
  EXPECT_EQ(result.num_outliers, 0);
  for (size_t v = 0; v < dive.poses.size(); ++v) {
    if (!result.cam0_from_target[v]) continue;
    EXPECT_LT(RotationError(*result.cam0_from_target[v], dive.poses[v]),
              kExactTolerance);
    EXPECT_LT(
        (result.cam0_from_target[v]->translation - dive.poses[v].translation)
            .norm(),
        kExactTolerance);
  }
}

// Calibrates `dive` and expects the exact solution; nullopt (and a
// failure) when the calibration fails.
std::optional<UnderwaterCalibration> CalibrateExact(
    const Dive& dive, const UnderwaterCalibrationOptions& options) {
  StatusOr<UnderwaterCalibration> result = Calibrate(dive, options);
  EXPECT_TRUE(result.ok()) << result.status().message();
  if (!result.ok()) return std::nullopt;
  ExpectExact(dive, *result);
  return *std::move(result);
}

TEST(UnderwaterCalibration, ExactThinPortRecoversNAndDrift) {
  const Dive dive = AlphasenseDive();
  const std::optional<UnderwaterCalibration> result =
      CalibrateExact(dive, Lean());
  ASSERT_TRUE(result.has_value());
  EXPECT_EQ(result->num_views_used, 16);
  EXPECT_EQ(result->num_stereo_views, 16);
  EXPECT_TRUE(result->extrinsics_estimated);
  // The change from the air calibration is the drift, in the convention
  // of StereoRig::WithCam1Moved.
  const ExtrinsicChange& change = result->extrinsic_change;
  EXPECT_LT((change.rotation_deg - kDriftRotation / kDegree).norm(),
            kExactTolerance / kDegree);
  EXPECT_NEAR(change.angle_deg, 0.5, kExactTolerance / kDegree);
  EXPECT_LT((change.translation_mm - 1e3 * kDriftTranslation).norm(),
            1e3 * kExactTolerance);
  // No port block in, none out.
  EXPECT_FALSE(result->rig.ports().has_value());
  EXPECT_LT(result->initial_rms_px, 50.0);
}

TEST(UnderwaterCalibration, ExactBowedBoardRecoversWarp) {
  // The corners of a board bowed by 0.4 + 0.3 mm (board_warp.h) under
  // water: the warp is estimated jointly with n, the drift and the poses,
  // and every one of them is the truth (kExactTolerance, in meters for
  // the warp).
  const Eigen::Vector2d warp(4e-4, 3e-4);
  const StereoRig air = AlphasenseFrontUnrectifiedRig();
  Dive dive{air, Drifted(air), kTrueN, {}, {}};
  dive.poses = BoardPoses(dive.truth.left(), Checkerboard(), 16, /*seed=*/7,
                          0.45, 0.9, 35.0, kTrueN);
  dive.views = ObserveStereoUnderwater(dive.truth, kTrueN, Checkerboard(),
                                       dive.poses, 0.0, 1, warp);
  const std::optional<UnderwaterCalibration> result =
      CalibrateExact(dive, Lean());
  ASSERT_TRUE(result.has_value());
  EXPECT_TRUE(result->board_warp_estimated);
  EXPECT_LT((result->board_warp - warp).norm(), kExactTolerance);
  EXPECT_GT(result->board_warp_sigma.minCoeff(), 0.0);
  ASSERT_NE(result->covariance.Find("board_warp"), nullptr);
  // A flat-board fit of the same corners cannot reach them.
  UnderwaterCalibrationOptions flat = Lean();
  flat.estimate_board_warp = false;
  const StatusOr<UnderwaterCalibration> flat_result = Calibrate(dive, flat);
  ASSERT_TRUE(flat_result.ok()) << flat_result.status().message();
  EXPECT_FALSE(flat_result->board_warp_estimated);
  EXPECT_EQ(flat_result->covariance.Find("board_warp"), nullptr);
  EXPECT_GT(flat_result->rms_px, 1e-3);
  std::printf("bowed board under water: flat fit rms %.4f px, n %.6f\n",
              flat_result->rms_px, flat_result->n);
}

TEST(UnderwaterCalibration, ExactNarrowRadTanRig) {
  const StereoRig air = NarrowRadTanRig();
  const Dive dive = MakeDive(air, Drifted(air), kTrueN, 16, 0.0, 1);
  const std::optional<UnderwaterCalibration> result =
      CalibrateExact(dive, Lean());
  ASSERT_TRUE(result.has_value());
  EXPECT_EQ(result->num_stereo_views, 16);
}

TEST(UnderwaterCalibration, ExactThickPortKnownGap) {
  // The port block describes the housing exactly: n and the drift come out
  // exact through the thick-port model, the ports unchanged.
  const StereoRig air = AlphasenseFrontUnrectifiedRig()
                            .WithPorts(ThickPort(), ThickPort())
                            .value();
  const Dive dive = MakeDive(air, Drifted(air), kTrueN, 16, 0.0, 1);
  const std::optional<UnderwaterCalibration> result =
      CalibrateExact(dive, Lean());
  ASSERT_TRUE(result.has_value());
  ASSERT_TRUE(result->rig.ports().has_value());
  EXPECT_EQ(result->rig.ports()->left, ThickPort());
  EXPECT_EQ(result->rig.ports()->right, ThickPort());
  EXPECT_FALSE(result->ports[0].air_gap_estimated);
  EXPECT_EQ(result->covariance.Find("cam0 air_gap"), nullptr);
}

TEST(UnderwaterCalibration, ExactThickPortRecoversAirGap) {
  // The port block gives the glass and a 5 mm gap; the housing's gaps are
  // 8 and 9 mm. Both gaps, n and the drift are recovered.
  UnderwaterCalibrationOptions options = Lean();
  options.estimate_air_gap = true;
  for (const StereoRig& base :
       {AlphasenseFrontUnrectifiedRig(), NarrowRadTanRig()}) {
    const StereoRig air =
        base.WithPorts(ThickPort(0.005), ThickPort(0.005)).value();
    const StereoRig truth =
        Drifted(base.WithPorts(ThickPort(0.008), ThickPort(0.009)).value());
    const std::optional<UnderwaterCalibration> result =
        CalibrateExact(MakeDive(air, truth, kTrueN, 16, 0.0, 1), options);
    ASSERT_TRUE(result.has_value());
    EXPECT_TRUE(result->ports[0].air_gap_estimated);
    EXPECT_TRUE(result->ports[1].air_gap_estimated);
    EXPECT_NEAR(result->ports[1].port.air_gap, 0.009, kExactTolerance);
    // Named blocks: n, the extrinsics, the gaps, then the board's warp
    // (estimated by default).
    const UnderwaterCovariance& covariance = result->covariance;
    ASSERT_EQ(covariance.blocks.size(), 5u);
    EXPECT_EQ(covariance.blocks[0].name, "n");
    EXPECT_EQ(covariance.blocks[1].name, "cam1_from_cam0");
    EXPECT_EQ(covariance.blocks[2].name, "cam0 air_gap");
    EXPECT_EQ(covariance.blocks[3].name, "cam1 air_gap");
    EXPECT_EQ(covariance.blocks[3].offset, 8);
    EXPECT_EQ(covariance.blocks[4].name, "board_warp");
    EXPECT_EQ(covariance.matrix.rows(), 9 + 2);
  }
}

TEST(UnderwaterCalibration, ExactThinPortGapFromZero) {
  // No port block: estimate_air_gap starts from a thin port (d = 0, no
  // glass) and finds the 8 mm air gap of a housing without glass.
  const StereoRig air = AlphasenseFrontUnrectifiedRig();
  FlatPort gap_only;
  gap_only.air_gap = 0.008;
  const StereoRig truth = Drifted(air.WithPorts(gap_only, gap_only).value());
  UnderwaterCalibrationOptions options = Lean();
  options.estimate_air_gap = true;
  const std::optional<UnderwaterCalibration> result =
      CalibrateExact(MakeDive(air, truth, kTrueN, 16, 0.0, 1), options);
  ASSERT_TRUE(result.has_value());
  EXPECT_NEAR(result->rig.ports()->left.air_gap, 0.008, kExactTolerance);
}

TEST(UnderwaterCalibration, ExactTiltedPortRecoversTilt) {
  // Ports tilted by 1.5 and 1 degrees, 8 mm + 6 mm; the normals estimated
  // from the optical axis, with the gaps from 6 mm.
  const StereoRig air = AlphasenseFrontUnrectifiedRig()
                            .WithPorts(ThickPort(0.006), ThickPort(0.006))
                            .value();
  FlatPort left = ThickPort();
  left.normal = TiltedPortNormal(1.5 * kDegree, 0.4);
  FlatPort right = ThickPort();
  right.normal = TiltedPortNormal(1.0 * kDegree, 2.0);
  const StereoRig truth =
      Drifted(AlphasenseFrontUnrectifiedRig().WithPorts(left, right).value());
  UnderwaterCalibrationOptions options = Lean();
  options.estimate_air_gap = true;
  options.estimate_port_tilt = true;
  const std::optional<UnderwaterCalibration> result =
      CalibrateExact(MakeDive(air, truth, kTrueN, 20, 0.0, 1), options);
  ASSERT_TRUE(result.has_value());
  EXPECT_NEAR(result->ports[0].tilt_deg, 1.5, kExactTolerance / kDegree);
  EXPECT_TRUE(result->ports[1].tilt_estimated);
  ASSERT_NE(result->covariance.Find("cam1 port_tilt"), nullptr);
  EXPECT_EQ(result->covariance.Find("cam1 port_tilt")->size, 2);
  // n, the extrinsics, the gaps, the tilts and the board's warp.
  EXPECT_EQ(result->covariance.matrix.rows(), 1 + 6 + 2 + 4 + 2);
}

TEST(UnderwaterCalibration, ExactSingleCamera) {
  // The left camera only: n from one camera and the board; the extrinsics
  // are the air rig's and not estimated.
  Dive dive = AlphasenseDive();
  for (StereoView& view : dive.views) view.right.reset();
  const Camera& l = dive.air.left();
  const StatusOr<UnderwaterCalibration> result =
      CalibrateUnderwater(Checkerboard(), dive.views, {l.width(), l.height()},
                          {0, 0}, dive.air, Lean());
  ASSERT_TRUE(result.ok()) << result.status().message();
  ExpectExact(dive, *result);
  EXPECT_FALSE(result->extrinsics_estimated);
  EXPECT_EQ(result->rig.right_from_left().rotation,
            dive.air.right_from_left().rotation);
  EXPECT_EQ(result->rig.right_from_left().translation,
            dive.air.right_from_left().translation);
  EXPECT_EQ(result->num_stereo_views, 0);
  // n and the board's warp (estimated by default).
  EXPECT_EQ(result->covariance.blocks.size(), 2u);
  EXPECT_EQ(result->extrinsic_change.angle_deg, 0.0);
}

TEST(UnderwaterCalibration, ExactMixedSingleCameraAndStereoViews) {
  // Of 18 views, 4 show the target to the left camera only and 4 to the
  // right camera only (posed through the air extrinsics at the start).
  Dive dive = AlphasenseDive(18);
  for (int v = 0; v < 4; ++v) dive.views[v].right.reset();
  for (int v = 4; v < 8; ++v) dive.views[v].left.reset();
  const std::optional<UnderwaterCalibration> result =
      CalibrateExact(dive, Lean());
  ASSERT_TRUE(result.has_value());
  EXPECT_EQ(result->num_views_used, 18);
  EXPECT_EQ(result->num_stereo_views, 10);
  EXPECT_EQ(result->views[2].num_corners[1], 0);
  EXPECT_GT(result->views[2].num_corners[0], 0);
  EXPECT_GT(result->views[5].num_corners[1], 0);
}

TEST(UnderwaterCalibration, ConventionalModelCannotFitRefractionExactly) {
  // On exact corners the refractive model's residuals vanish; a
  // conventional model (the equidistant lens with its intrinsics free)
  // absorbs most of the refraction but not all: measured RMS 0.050 px on
  // the dataset rig (0.025 px on the narrow radtan rig), far above the
  // solver's floor (1e-9) and below the detection noise of real corners.
  const Dive dive = AlphasenseDive(20);
  UnderwaterCalibrationOptions options = Lean();
  options.fit_conventional_model = true;
  const std::optional<UnderwaterCalibration> result =
      CalibrateExact(dive, options);
  ASSERT_TRUE(result.has_value());
  ASSERT_TRUE(result->conventional.ok) << result->conventional.error;
  EXPECT_GT(result->conventional.rms_px, 0.02);
  EXPECT_LT(result->conventional.rms_px, 0.2);
  EXPECT_GT(result->conventional.num_parameters, result->num_parameters);
}

TEST(UnderwaterCalibration, ConvergesForAnyIndexAndLargeDrifts) {
  // From initial_n = 1.34 and the air extrinsics: true n across [1, 1.6]
  // (n = 1: the target in air, a valid answer at the bound) and drifts up
  // to 4 degrees (it converges to 20 degrees, measured; 4 is what a
  // housing may do).
  const StereoRig air = AlphasenseFrontUnrectifiedRig();
  for (const double n : {1.0, 1.1, 1.25, 1.45, 1.6}) {
    for (const double drift_deg : {0.5, 4.0}) {
      const Eigen::Vector3d rotation =
          drift_deg / 0.5 * kDriftRotation;  // the same axis
      const Dive dive = MakeDive(
          air, air.WithCam1Moved(rotation, 10.0 * kDriftTranslation).value(), n,
          12, 0.0, 1);
      const StatusOr<UnderwaterCalibration> result = Calibrate(dive, Lean());
      ASSERT_TRUE(result.ok()) << "n " << n << ", drift " << drift_deg
                               << " deg: " << result.status().message();
      EXPECT_NEAR(result->n, n, kExactTolerance)
          << "n " << n << ", drift " << drift_deg;
      EXPECT_LT(RotationError(result->rig.right_from_left(),
                              dive.truth.right_from_left()),
                kExactTolerance)
          << "n " << n << ", drift " << drift_deg;
    }
  }
}

// The Alphasense dive with noise: the estimates fall within their own
// sigmas (4 sigma: a 6e-5 two-sided chance per quantity when the sigmas are
// honest, which MonteCarloSigmaIsHonest checks), the noise estimate within
// 10 % of the truth (2m - p ~ 2000 degrees of freedom: relative sd 1.6 %),
// the leave-out sigma of n close to the covariance's (independent noise:
// the jackknife over 10 groups has a relative sd of ~1 / sqrt(2 * 9) =
// 0.24, so [0.4, 2] is a wide band; measured 1.2 for n, 1.0 for the
// drift angle), and the conventional fit reported.
TEST(UnderwaterCalibration, NoisyWithinReportedSigma) {
  constexpr double kNoisePx = 0.25;
  constexpr double kMaxSigmas = 4.0;
  const Dive dive = AlphasenseDive(20, kNoisePx, 11);
  std::vector<std::pair<int, int>> progress;
  const StatusOr<UnderwaterCalibration> result = CalibrateUnderwater(
      Checkerboard(), dive.views, {720, 540}, {720, 540}, dive.air, {},
      [&progress](int done, int total) { progress.emplace_back(done, total); });
  ASSERT_TRUE(result.ok()) << result.status().message();
  // The main fit, then each of the 10 leave-out replicates.
  ASSERT_EQ(progress.size(), 11u);
  EXPECT_EQ(progress.front(), std::make_pair(1, 11));
  EXPECT_EQ(progress.back(), std::make_pair(11, 11));
  EXPECT_LT(std::abs(result->n - kTrueN), kMaxSigmas * result->sigma_n);
  EXPECT_GT(result->sigma_n, 0.0);
  EXPECT_LT(result->sigma_n, 0.01);
  const ExtrinsicChange& change = result->extrinsic_change;
  for (int i = 0; i < 3; ++i) {
    EXPECT_LT(std::abs(change.rotation_deg[i] - kDriftRotation[i] / kDegree),
              kMaxSigmas * change.rotation_sigma_deg[i])
        << i;
    EXPECT_LT(std::abs(change.translation_mm[i] - 1e3 * kDriftTranslation[i]),
              kMaxSigmas * change.translation_sigma_mm[i])
        << i;
  }
  EXPECT_LT(std::abs(change.angle_deg - 0.5),
            kMaxSigmas * change.angle_sigma_deg);
  EXPECT_NEAR(result->pixel_sigma, kNoisePx, 0.1 * kNoisePx);
  EXPECT_EQ(result->num_outliers, 0);
  // The lenses are never touched, noise or not.
  EXPECT_TRUE(SameBits(result->rig.left(), dive.air.left()));
  EXPECT_TRUE(SameBits(result->rig.right(), dive.air.right()));
  // The covariance: sigma_n is its (n, n) entry; symmetric, positive.
  const UnderwaterCovariance& covariance = result->covariance;
  EXPECT_DOUBLE_EQ(std::sqrt(covariance.Block("n", "n")(0, 0)),
                   result->sigma_n);
  EXPECT_EQ(covariance.Block("cam1_from_cam0", "cam1_from_cam0"),
            result->extrinsics_covariance);
  EXPECT_LT((covariance.matrix - covariance.matrix.transpose()).norm(),
            1e-12 * covariance.matrix.norm());
  EXPECT_GT(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(covariance.matrix)
                .eigenvalues()
                .minCoeff(),
            0.0);
  // The leave-out sigmas.
  ASSERT_TRUE(result->leave_out.has_value());
  EXPECT_EQ(result->leave_out->folds, 10);
  EXPECT_EQ(result->leave_out->failed_folds, 0);
  ASSERT_TRUE(result->sigma_n_leave_out.has_value());
  EXPECT_GT(*result->sigma_n_leave_out, 0.4 * result->sigma_n);
  EXPECT_LT(*result->sigma_n_leave_out, 2.0 * result->sigma_n);
  ASSERT_TRUE(change.rotation_leave_out_sigma_deg.has_value());
  EXPECT_GT(change.rotation_leave_out_sigma_deg->norm(),
            0.4 * change.rotation_sigma_deg.norm());
  EXPECT_LT(change.rotation_leave_out_sigma_deg->norm(),
            2.0 * change.rotation_sigma_deg.norm());
  // The conventional fit of the same corners ran (its model error is
  // below this noise: ConventionalModelCannotFitRefractionExactly).
  ASSERT_TRUE(result->conventional.ok) << result->conventional.error;
  EXPECT_EQ(result->conventional.model, LensModelId::kEquidistant);
  EXPECT_GT(result->conventional.pixel_sigma, 0.9 * kNoisePx);
  // The per-view residuals are the noise.
  for (const UnderwaterViewResidual& view : result->views) {
    for (int c = 0; c < 2; ++c) {
      if (view.num_corners[c] > 0) {
        EXPECT_LT(view.rms_px[c], 3.0 * kNoisePx);
      }
    }
  }
}

// 100 noisy refinements (0.3 px, 10 views, seeds 1000-1099): the normalized
// errors (estimate - truth) / sigma of n and of the drift about its largest
// axis (y) have zero mean and unit standard deviation. With N = 100 the
// sample standard deviation of a unit normal has a standard error of
// 1 / sqrt(2N) = 0.07, so [0.7, 1.3] is a 4-sigma band; the mean's is
// 1 / sqrt(N) = 0.1, so |mean| < 0.4 is 4 sigma. Measured: sd 0.92 (n) and
// 0.88 (drift), means 0.11 and 0.10; with 400 trials sd 0.97 and 0.98,
// means 0.04 and 0.10.
TEST(UnderwaterCalibration, MonteCarloSigmaIsHonest) {
  constexpr int kTrials = 100;
  const int axis = 1;  // the drift's largest component
  ASSERT_GT(std::abs(kDriftRotation[axis]),
            kDriftRotation.cwiseAbs().maxCoeff() - 1e-15);
  // No outlier rounds: the corners have none, so the robust solves would
  // only lead to the same least-squares minimum at twice the cost.
  UnderwaterCalibrationOptions options = Lean();
  options.max_outlier_rounds = 0;
  std::vector<double> z[2];
  for (int trial = 0; trial < kTrials; ++trial) {
    const Dive dive = AlphasenseDive(10, 0.3, 1000 + trial);
    const StatusOr<UnderwaterCalibration> result = Calibrate(dive, options);
    ASSERT_TRUE(result.ok()) << result.status().message();
    z[0].push_back((result->n - kTrueN) / result->sigma_n);
    const ExtrinsicChange& change = result->extrinsic_change;
    z[1].push_back(
        (change.rotation_deg[axis] - kDriftRotation[axis] / kDegree) /
        change.rotation_sigma_deg[axis]);
  }
  const char* names[2] = {"n", "drift"};
  for (int i = 0; i < 2; ++i) {
    const rcm::test::SampleMoments moments = rcm::test::Moments(z[i]);
    EXPECT_LT(std::abs(moments.mean), 0.4) << names[i];
    EXPECT_GT(moments.stddev, 0.7) << names[i];
    EXPECT_LT(moments.stddev, 1.3) << names[i];
    std::printf("[ MEASURED ] z(%s): mean %.3f, sd %.3f\n", names[i],
                moments.mean, moments.stddev);
  }
}

TEST(UnderwaterCalibration, RejectsGrossOutliers) {
  // 0.2 px noise, and 3 % of the corners moved by 8-20 px (a detector
  // confusing corners). The outliers are found and n is as good as
  // without them: within 4 reported sigmas.
  constexpr double kNoisePx = 0.2;
  Dive dive = AlphasenseDive(18, kNoisePx, 3);
  const int num_moved = test::AddGrossOutliers(0.03, /*seed=*/5, &dive.views);
  ASSERT_GT(num_moved, 30);
  const StatusOr<UnderwaterCalibration> result = Calibrate(dive, Lean());
  ASSERT_TRUE(result.ok()) << result.status().message();
  EXPECT_EQ(result->num_outliers, num_moved);
  for (const CornerResidual& corner : result->corners) {
    if (!corner.inlier) {
      EXPECT_GT(corner.residual.norm(), 5.0);
    }
  }
  EXPECT_NEAR(result->pixel_sigma, kNoisePx, 0.1 * kNoisePx);
  EXPECT_LT(std::abs(result->n - kTrueN), 4.0 * result->sigma_n);
  // The rms over all corners counts the outliers, the inlier rms does not.
  EXPECT_GT(result->rms_px, 2.0 * result->inlier_rms_px);
}

// --- Bad input: one line each, never a number.

TEST(UnderwaterCalibration, NoViewWithTheTargetIsAnError) {
  Dive dive = AlphasenseDive(4);
  for (StereoView& view : dive.views) {
    view.left.reset();
    view.right.reset();
  }
  EXPECT_EQ(Calibrate(dive).status().message(),
            "no view shows the target with at least 6 corners (and a pose)");
  dive.views.clear();
  EXPECT_FALSE(Calibrate(dive).ok());
}

TEST(UnderwaterCalibration, TooFewViewsIsAnError) {
  const Dive dive = AlphasenseDive(2);
  EXPECT_EQ(Calibrate(dive).status().message(),
            "the target is seen with at least 6 corners (and a pose) in 2 "
            "view(s); at least 3 are needed");
}

TEST(UnderwaterCalibration, ViewsWithTooFewCornersAreNotUsed) {
  // Two of four views keep 5 corners, fewer than min_corners_per_view.
  Dive dive = AlphasenseDive(4);
  for (int v = 0; v < 2; ++v) {
    for (std::optional<TargetObservation>* side :
         {&dive.views[v].left, &dive.views[v].right}) {
      (*side)->point_ids.resize(5);
      (*side)->pixels.resize(5);
    }
  }
  EXPECT_EQ(Calibrate(dive).status().message(),
            "the target is seen with at least 6 corners (and a pose) in 2 "
            "view(s); at least 3 are needed");
}

TEST(UnderwaterCalibration, ImageSizeOtherThanTheAirCamerasIsAnError) {
  const Dive dive = AlphasenseDive(4);
  const StatusOr<UnderwaterCalibration> result = CalibrateUnderwater(
      Checkerboard(), dive.views, {720, 540}, {640, 480}, dive.air, Lean());
  EXPECT_EQ(result.status().message(),
            "cam1 images are 640x480 but the air calibration's cam1 is "
            "720x540: the air rig is not these cameras' (or the images were "
            "scaled)");
  // {0, 0} is refused for a camera that saw the target.
  EXPECT_FALSE(CalibrateUnderwater(Checkerboard(), dive.views, {720, 540},
                                   {0, 0}, dive.air, Lean())
                   .ok());
}

// Views of `rig` (no drift) through thin ports into a medium of any index,
// by the paper's closed form (the exact port takes n in [1, 2] only), with
// 0.2 px of noise.
Dive ThinPortDive(const StereoRig& rig, double n, int num_views) {
  const auto through = [n](const Camera& camera) -> test::PointProjection {
    return [&camera,
            n](const Eigen::Vector3d& p) -> std::optional<Eigen::Vector2d> {
      Eigen::Vector2d xb;
      if (!FlatPortRefraction::NormalizedFromPointInWater(n, p.data(), &xb.x(),
                                                          &xb.y())) {
        return std::nullopt;
      }
      return camera.ProjectNormalized(xb);
    };
  };
  Dive dive{rig, rig, n, {}, {}};
  dive.poses = BoardPoses(rig.left(), Checkerboard(), num_views, /*seed=*/7,
                          0.45, 0.9, 35.0, n);
  dive.views = test::ObserveStereoWith(
      rig.left(), through(rig.left()), rig.right(), through(rig.right()),
      rig.right_from_left(), Checkerboard(), dive.poses, 0.2, /*seed=*/1);
  return dive;
}

TEST(UnderwaterCalibration, NAtABoundIsAnError) {
  // A medium of index 2.3 runs into the bound 2. One of index 0.85 (as the
  // images of cameras whose air calibration has too long focal lengths
  // look) stops at the bound 1 with the data pulling it far below.
  const struct {
    double n;
    const char* message;
  } cases[] = {
      {2.3,
       "n = 2.0000 ends at the upper bound of [1, 2], which is not a "
       "physical answer: "},
      {0.85,
       "n ends at the lower bound 1 of [1, 2] and the corners pull it below "
       "by "},
  };
  for (const auto& c : cases) {
    const Dive dive = ThinPortDive(AlphasenseFrontUnrectifiedRig(), c.n, 8);
    const Status status = Calibrate(dive, Lean()).status();
    EXPECT_THAT(status.message(), ::testing::StartsWith(c.message))
        << "n " << c.n;
    // The refusal is recognized as such (the model selection refuses the
    // dive on it); other errors are not.
    EXPECT_TRUE(IsIndexOnBoundError(status)) << "n " << c.n;
  }
  EXPECT_FALSE(IsIndexOnBoundError(
      Status::Error("too few views: 2 views show the target to both cameras")));
  EXPECT_FALSE(IsIndexOnBoundError(Status::Ok()));
}

TEST(UnderwaterCalibration, AirIsAnAnswer) {
  // The target in air with noise: n = 1 is a valid estimate, at the bound
  // or just above it, within 3 sigma of the truth (the pull test passes).
  const Dive dive = ThinPortDive(AlphasenseFrontUnrectifiedRig(), 1.0, 12);
  const StatusOr<UnderwaterCalibration> result = Calibrate(dive, Lean());
  ASSERT_TRUE(result.ok()) << result.status().message();
  EXPECT_LT(result->n - 1.0, 4.0 * result->sigma_n);
}

TEST(UnderwaterCalibration, WrongAirCalibrationIsNoted) {
  // An air calibration whose focal lengths are 1.6 times too short: the
  // fit is poor and many corners are outliers; the notes say why.
  Dive dive = AlphasenseDive(8);
  const auto scaled = [](const Camera& c) {
    return Camera::Create(c.model(), c.width(), c.height(),
                          {c.fx() / 1.6, c.fy() / 1.6, c.cx(), c.cy()},
                          c.Distortion())
        .value();
  };
  dive.air =
      StereoRig::Create(scaled(dive.air.left()), scaled(dive.air.right()),
                        dive.air.right_from_left())
          .value();
  const StatusOr<UnderwaterCalibration> result = Calibrate(dive, Lean());
  ASSERT_TRUE(result.ok()) << result.status().message();
  EXPECT_GT(result->pixel_sigma, 1.0);
  bool noted = false;
  for (const std::string& note : result->notes) {
    noted |= note.find("of the corners are outliers") != std::string::npos;
  }
  EXPECT_TRUE(noted);
  EXPECT_TRUE(std::isfinite(result->rms_px));
}

TEST(UnderwaterCalibration, UnobservablePortIsDegenerate) {
  // In air (n = 1) a port without glass bends no ray: its gap and tilt do
  // not change a single residual, and the covariance says so.
  const StereoRig truth = AlphasenseFrontUnrectifiedRig();
  const Dive dive = MakeDive(truth, truth, 1.0, 8, 0.0, 1);
  UnderwaterCalibrationOptions options = Lean();
  options.estimate_air_gap = true;
  options.estimate_port_tilt = true;
  const std::string message = Calibrate(dive, options).status().message();
  EXPECT_THAT(message, ::testing::StartsWith(
                           "the underwater calibration is degenerate"));
}

TEST(UnderwaterCalibration, BadObservationsAreErrors) {
  const Dive dive = AlphasenseDive(4);
  Dive bad_id = dive;
  bad_id.views[2].left->point_ids[0] = 54;
  EXPECT_EQ(Calibrate(bad_id).status().message(),
            "view 2: point id 54 is not on the target");
  Dive nan_pixel = dive;
  nan_pixel.views[1].right->pixels[3].x() = std::nan("");
  EXPECT_EQ(Calibrate(nan_pixel).status().message(),
            "view 1: a corner pixel is not finite");
  Dive mismatched = dive;
  mismatched.views[0].left->pixels.pop_back();
  EXPECT_EQ(Calibrate(mismatched).status().message(),
            "view 0: point ids and pixels differ in number");
}

TEST(UnderwaterCalibrationOptions, Check) {
  EXPECT_TRUE(UnderwaterCalibrationOptions().Check().ok());
  const auto message = [](void (*change)(UnderwaterCalibrationOptions*)) {
    UnderwaterCalibrationOptions options;
    change(&options);
    return options.Check().message();
  };
  EXPECT_EQ(
      message([](UnderwaterCalibrationOptions* o) { o->initial_n = 2.5; }),
      "initial_n must be in [1, 2]");
  EXPECT_EQ(
      message([](UnderwaterCalibrationOptions* o) { o->initial_n = NAN; }),
      "initial_n must be in [1, 2]");
  EXPECT_EQ(message([](UnderwaterCalibrationOptions* o) { o->huber_px = 0; }),
            "huber_px must be positive and finite");
  EXPECT_EQ(
      message([](UnderwaterCalibrationOptions* o) { o->outlier_sigmas = NAN; }),
      "outlier_sigmas must be positive and finite");
  EXPECT_EQ(message([](UnderwaterCalibrationOptions* o) {
              o->min_outlier_threshold_px = -1;
            }),
            "min_outlier_threshold_px must be >= 0 and finite");
  EXPECT_EQ(message([](UnderwaterCalibrationOptions* o) {
              o->max_outlier_rounds = -1;
            }),
            "max_outlier_rounds must be >= 0");
  EXPECT_EQ(message([](UnderwaterCalibrationOptions* o) {
              o->max_num_iterations = 0;
            }),
            "max_num_iterations must be positive");
  EXPECT_EQ(message([](UnderwaterCalibrationOptions* o) {
              o->min_corners_per_view = 3;
            }),
            "min_corners_per_view must be at least 4");
  EXPECT_EQ(message([](UnderwaterCalibrationOptions* o) { o->folds = 1; }),
            "folds must be 0 (no leave-out) or at least 2");
  EXPECT_EQ(
      message([](UnderwaterCalibrationOptions* o) { o->num_threads = 0; }),
      "num_threads must be positive");
  // Reported by CalibrateUnderwater, not CHECKed.
  UnderwaterCalibrationOptions options;
  options.folds = -2;
  EXPECT_EQ(Calibrate(AlphasenseDive(3), options).status().message(),
            "folds must be 0 (no leave-out) or at least 2");
}

}  // namespace
}  // namespace rcm::calib::underwater_calibration_test
