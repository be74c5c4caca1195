#include "rcm/estimation/sequence_bundle_adjustment.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <random>
#include <vector>

#include "rcm/camera/refractive_camera.h"
#include "rcm/estimation/estimate_refractive_index.h"
#include "rcm/geometry/calibration_uncertainty.h"
#include "support/test_budget.h"
#include "support/test_rigs.h"

namespace rcm {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDeg = kPi / 180.0;

// Noise-free data and a converged Ceres solve: the unknowns agree with the
// truth to rounding amplified by the problem's conditioning (n's
// sensitivity is ~1e3 px per unit, a pose's ~1e3 px per metre).
constexpr double kExactTolerance = 1e-9;

// cam1's turn since the calibration in the tests: 0.5 degrees about a skew
// axis (the drift).
Eigen::Vector3d TrueTurn() {
  return 0.5 * kDeg * Eigen::Vector3d(0.3, 1.0, 0.2).normalized();
}

struct Dive {
  StereoTracks tracks;
  std::vector<Rigid3d> cam0_from_world;  // truth
  std::vector<Eigen::Vector3d> landmarks;
};

// A rig moving through a field of landmarks 1.5-8 m ahead: `frames`
// keyframes on a gently curving path (0.12 m apart, turning up to ~8
// degrees), every landmark projected exactly through `truth`'s refractive
// cameras at index n, plus Gaussian noise of `sigma_px`.
// How the synthetic rig moves: the curving path above; still; straight
// ahead along its optical axis; over a plane 3 m ahead, parallel to it.
enum class Path { kCurving, kStatic, kAlongAxis, kOverPlane };

Dive MakeDive(const StereoRig& truth, double n, int frames, int landmarks,
              double sigma_px, uint64_t seed, Path path = Path::kCurving) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::normal_distribution<double> noise(0.0, 1.0);
  Dive dive;
  for (int l = 0; l < landmarks; ++l) {
    const double z = path == Path::kOverPlane ? 3.0 : 1.5 + 6.5 * unit(rng);
    dive.landmarks.emplace_back((unit(rng) - 0.5) * 1.6 * z + 0.06 * frames,
                                (unit(rng) - 0.5) * 1.2 * z, z);
  }
  for (int f = 0; f < frames; ++f) {
    const double s = static_cast<double>(f);
    Eigen::Matrix3d world_from_cam0_rotation =
        (Eigen::AngleAxisd(0.04 * std::sin(0.5 * s), Eigen::Vector3d::UnitX()) *
         Eigen::AngleAxisd(0.14 * std::sin(0.3 * s), Eigen::Vector3d::UnitY()) *
         Eigen::AngleAxisd(0.03 * s / frames, Eigen::Vector3d::UnitZ()))
            .toRotationMatrix();
    Eigen::Vector3d position(0.12 * s, 0.05 * std::sin(0.7 * s), 0.04 * s);
    // The degenerate paths turn by less than a degree.
    const Eigen::Matrix3d wobble =
        Eigen::AngleAxisd(0.01 * std::sin(s), Eigen::Vector3d::UnitY())
            .toRotationMatrix();
    switch (path) {
      case Path::kCurving:
        break;
      case Path::kStatic:
        world_from_cam0_rotation = wobble;
        position = Eigen::Vector3d(0.001 * std::sin(s), 0.0, 0.0);
        break;
      case Path::kAlongAxis:
        world_from_cam0_rotation = wobble;
        position = Eigen::Vector3d(0.0, 0.0, 0.1 * s);
        break;
      case Path::kOverPlane:
        world_from_cam0_rotation = wobble;
        position = Eigen::Vector3d(0.12 * s, 0.03 * s, 0.0);
        break;
    }
    dive.cam0_from_world.push_back(
        Rigid3d{world_from_cam0_rotation, position}.Inverse());
  }
  // The exact port when the rig has one (ImageFromPointInWater is exact at
  // every depth; the reference depth only shapes the bearings).
  const auto camera_of = [&](const Camera& camera, bool left_camera) {
    if (!truth.ports()) return RefractiveCamera::Create(camera, n).value();
    const FlatPort& port =
        left_camera ? truth.ports()->left : truth.ports()->right;
    return RefractiveCamera::CreateWithPort(camera, n, port, 2.0).value();
  };
  const RefractiveCamera left = camera_of(truth.left(), true);
  const RefractiveCamera right = camera_of(truth.right(), false);
  dive.tracks.num_frames = frames;
  dive.tracks.num_landmarks = landmarks;
  for (int f = 0; f < frames; ++f) {
    for (int l = 0; l < landmarks; ++l) {
      const Eigen::Vector3d p0 = dive.cam0_from_world[f] * dive.landmarks[l];
      const Eigen::Vector3d p1 = truth.right_from_left() * p0;
      for (int c = 0; c < 2; ++c) {
        const RefractiveCamera& camera = c == 0 ? left : right;
        const std::optional<Eigen::Vector2d> pixel =
            camera.ImageFromPointInWater(c == 0 ? p0 : p1);
        if (!pixel || !camera.camera().InImage(*pixel)) continue;
        StereoTrackObservation observation;
        observation.frame = f;
        observation.camera = c;
        observation.landmark = l;
        observation.pixel =
            *pixel + sigma_px * Eigen::Vector2d(noise(rng), noise(rng));
        dive.tracks.observations.push_back(observation);
      }
    }
  }
  return dive;
}

// The camchain the user holds (cam1 as calibrated in air) and the rig as
// it is in the dive (cam1 turned since).
StereoRig Calibration() { return test::AlphasenseRealisticRig(); }
StereoRig TurnedTruth() {
  return Calibration().WithCam1Moved(TrueTurn()).value();
}

// The bundle of `rig` with `options` over `tracks`.
StatusOr<SequenceBundleResult> Bundle(const StereoRig& rig,
                                      const SequenceBundleOptions& options,
                                      const StereoTracks& tracks) {
  return SequenceBundleAdjustment::Create(rig, options).value().Solve(tracks);
}

double RotationError(const Rigid3d& a, const Rigid3d& b) {
  return Eigen::AngleAxisd(a.rotation.transpose() * b.rotation).angle();
}

TEST(SequenceBundleAdjustment, NoiseFreeRecoversNTurnAndEveryPose) {
  const double n = 1.34;
  const Dive dive = MakeDive(TurnedTruth(), n, 8, 300, 0.0, 1);
  SequenceBundleOptions options;
  options.initial_n = 1.333;  // water's tabulated index, not the truth
  const SequenceBundleAdjustment bundle =
      SequenceBundleAdjustment::Create(Calibration(), options).value();
  const StatusOr<SequenceBundleResult> result = bundle.Solve(dive.tracks);
  ASSERT_TRUE(result.ok()) << result.status().message();
  EXPECT_NEAR(result->n, n, kExactTolerance);
  EXPECT_LT((result->state.cam1_rotation - TrueTurn()).norm(), kExactTolerance);
  ASSERT_EQ(result->state.cam0_from_world.size(), 8u);
  for (int f = 0; f < 8; ++f) {
    EXPECT_LT(RotationError(result->state.cam0_from_world[f],
                            dive.cam0_from_world[f]),
              kExactTolerance)
        << "keyframe " << f;
    EXPECT_LT((result->state.cam0_from_world[f].translation -
               dive.cam0_from_world[f].translation)
                  .norm(),
              kExactTolerance)
        << "keyframe " << f;
  }
  int compared = 0;
  for (size_t l = 0; l < dive.landmarks.size(); ++l) {
    if (!result->state.landmarks[l].allFinite()) continue;
    EXPECT_LT((result->state.landmarks[l] - dive.landmarks[l]).norm(), 1e-8)
        << "landmark " << l;
    ++compared;
  }
  EXPECT_EQ(compared, result->num_landmarks);
  EXPECT_GT(result->num_landmarks, 200);
  // Every observation of a placed landmark is an inlier.
  int64_t placed = 0;
  for (const StereoTrackObservation& o : dive.tracks.observations) {
    placed += result->state.landmarks[o.landmark].allFinite() ? 1 : 0;
  }
  EXPECT_EQ(result->num_inliers, placed);
  // Motion separates n from the turn: the epipolar estimate's correlation
  // on this rig is 0.97 (docs/design.md).
  EXPECT_LT(result->correlation_n_rotation, 0.9);
}

// Lenses that changed since the calibration (+0.4 % and -0.2 %), under
// the calibration's focal drift prior of 0.3 %: the bundle estimates each
// camera's focal scale with n and the turn. Noise-free tracks weigh the
// prior by the pixel noise they show (none), so every unknown comes back
// to the 1e-9 of the other noise-free tests; with the focal lengths held
// instead, n is off by the lens change's pull (measured 7.8e-3, the
// focal prior then only propagated: sigma_n 6.8e-3).
TEST(SequenceBundleAdjustment, NoiseFreeLensChangeRecoveredWithTheFocalScales) {
  const double n = 1.34;
  const StereoRig truth = TurnedTruth().WithFocalScaled(0.004, -0.002).value();
  const Dive dive = MakeDive(truth, n, 8, 300, 0.0, 1);
  CalibrationUncertainty uncertainty =
      CalibrationUncertainty::DriftPrior(0.0, 0.0);
  const StereoRig calibration = Calibration();
  uncertainty.AddFocalDrift(
      0.003,
      Eigen::Map<const Eigen::VectorXd>(calibration.left().params(),
                                        calibration.left().num_params()),
      Eigen::Map<const Eigen::VectorXd>(calibration.right().params(),
                                        calibration.right().num_params()));
  const StereoRig held =
      calibration.WithCalibrationUncertainty(uncertainty).value();
  SequenceBundleOptions options;
  const StatusOr<SequenceBundleResult> result =
      Bundle(held, options, dive.tracks);
  ASSERT_TRUE(result.ok()) << result.status().message();
  EXPECT_TRUE(result->focal_scales_estimated);
  EXPECT_NEAR(result->n, n, kExactTolerance);
  EXPECT_LT((result->state.cam1_rotation - TrueTurn()).norm(), kExactTolerance);
  EXPECT_NEAR(result->state.focal_scales[0], 0.004, kExactTolerance);
  EXPECT_NEAR(result->state.focal_scales[1], -0.002, kExactTolerance);
  for (int f = 0; f < 8; ++f) {
    EXPECT_LT((result->state.cam0_from_world[f].translation -
               dive.cam0_from_world[f].translation)
                  .norm(),
              kExactTolerance)
        << "keyframe " << f;
  }
  options.self_calibrate_focal = false;
  const StatusOr<SequenceBundleResult> held_lenses =
      Bundle(held, options, dive.tracks);
  ASSERT_TRUE(held_lenses.ok()) << held_lenses.status().message();
  EXPECT_FALSE(held_lenses->focal_scales_estimated);
  EXPECT_EQ(held_lenses->state.focal_scales, Eigen::Vector2d::Zero());
  EXPECT_GT(std::abs(held_lenses->n - n), 1e-3);
}

TEST(SequenceBundleAdjustment, TranslationDirectionRecoveredWhenFree) {
  const double n = 1.34;
  const Eigen::Vector3d dt(0.0, 0.0006, -0.0008);  // metres, cam1 frame
  const StereoRig calibration = Calibration();
  const StereoRig truth = calibration.WithCam1Moved(TrueTurn(), dt).value();
  // The bundle holds the calibration's baseline length: the truth's
  // translation rescaled to it, so that the data are exact.
  const Eigen::Vector3d t_truth = truth.right_from_left().translation;
  const double b = calibration.Baseline();
  const StereoRig exact =
      StereoRig::Create(truth.left(), truth.right(),
                        Rigid3d{truth.right_from_left().rotation,
                                t_truth * (b / t_truth.norm())})
          .value();
  const Dive dive = MakeDive(exact, n, 8, 300, 0.0, 2);
  SequenceBundleOptions options;
  options.refine_translation_direction = true;
  const SequenceBundleAdjustment bundle =
      SequenceBundleAdjustment::Create(calibration, options).value();
  const StatusOr<SequenceBundleResult> result = bundle.Solve(dive.tracks);
  ASSERT_TRUE(result.ok()) << result.status().message();
  EXPECT_NEAR(result->n, n, kExactTolerance);
  EXPECT_LT((result->state.cam1_rotation - TrueTurn()).norm(), kExactTolerance);
  // u = exp(-[w]x) t' / b.
  const Eigen::Vector3d direction =
      Eigen::AngleAxisd(TrueTurn().norm(), TrueTurn().normalized())
          .toRotationMatrix()
          .transpose() *
      exact.right_from_left().translation / b;
  EXPECT_LT((result->state.cam1_direction - direction).norm(), kExactTolerance);
}

// A thick port (air gap, glass, a tilted normal): the bundle projects
// through the exact port (flat_port_projection.h), which the initializer
// only approximates (a central camera at 2 m).
TEST(SequenceBundleAdjustment, NoiseFreeThroughThickPorts) {
  const double n = 1.34;
  FlatPort port;
  port.air_gap = 0.008;
  port.glass_thickness = 0.01;
  port.normal = Eigen::Vector3d(0.02, -0.01, 1.0).normalized();
  const StereoRig calibration = Calibration().WithPorts(port, port).value();
  const StereoRig truth = calibration.WithCam1Moved(TrueTurn()).value();
  const Dive dive = MakeDive(truth, n, 8, 300, 0.0, 7);
  const StatusOr<SequenceBundleResult> result =
      Bundle(calibration, SequenceBundleOptions(), dive.tracks);
  ASSERT_TRUE(result.ok()) << result.status().message();
  EXPECT_NEAR(result->n, n, kExactTolerance);
  EXPECT_LT((result->state.cam1_rotation - TrueTurn()).norm(), kExactTolerance);
  for (int f = 0; f < 8; ++f) {
    EXPECT_LT((result->state.cam0_from_world[f].translation -
               dive.cam0_from_world[f].translation)
                  .norm(),
              kExactTolerance)
        << "keyframe " << f;
  }
}

// A port whose air gap the calibration knows to 1 mm (an underwater
// calibration's port covariance): sigma_n_calibration is n's linear
// response to the gap moved by +-1 mm, which re-solving the bundle with the
// gap moved confirms: the same central difference to 1 % (the re-solve's
// third-order remainder; measured 0.04 %).
TEST(SequenceBundleAdjustment, PortUncertaintyCarriedIntoSigma) {
  const double n = 1.34;
  FlatPort port;
  port.air_gap = 0.008;
  port.glass_thickness = 0.01;
  const StereoRig calibration = Calibration().WithPorts(port, port).value();
  const Dive dive = MakeDive(calibration.WithCam1Moved(TrueTurn()).value(), n,
                             8, 300, 0.0, 7);
  CalibrationUncertainty uncertainty =
      CalibrationUncertainty::DriftPrior(0.0, 0.0);
  uncertainty.port_covariance = Eigen::MatrixXd::Zero(6, 6);
  uncertainty.port_covariance(0, 0) = 1e-6;  // the left air gap: 1 mm
  const StereoRig uncertain =
      calibration.WithCalibrationUncertainty(uncertainty).value();
  const SequenceBundleOptions options;
  const StatusOr<SequenceBundleResult> result =
      Bundle(uncertain, options, dive.tracks);
  ASSERT_TRUE(result.ok()) << result.status().message();
  EXPECT_NEAR(result->n, n, kExactTolerance);
  EXPECT_EQ(result->propagation_directions, 1);
  // n re-solved with the left gap 1 mm wider and 1 mm narrower: the
  // response curves (+1.000e-3 and -1.293e-3), and the propagation's
  // central difference is their mean slope.
  double moved_n[2];
  for (int sign = 0; sign < 2; ++sign) {
    FlatPort moved_port = port;
    moved_port.air_gap += sign == 0 ? 0.001 : -0.001;
    const StatusOr<SequenceBundleResult> moved = Bundle(
        calibration.WithPorts(moved_port, port).value(), options, dive.tracks);
    ASSERT_TRUE(moved.ok()) << moved.status().message();
    moved_n[sign] = moved->n;
  }
  const double dn = 0.5 * std::abs(moved_n[0] - moved_n[1]);
  EXPECT_GT(dn, 1e-4);  // the gap matters
  EXPECT_NEAR(result->sigma_n_calibration, dn, 0.01 * dn) << "re-solved " << dn;
}

// 0.5 px of pixel noise: n within 4 of its reported noise sigma (a 6e-5
// chance for an honest sigma), and the estimated pixel noise within 5 % of
// the truth (~60k residuals: its relative standard error is ~0.3 %, the
// bias of the dropped outliers of a Gaussian beyond 2 px is nil).
TEST(SequenceBundleAdjustment, NoisyWithinItsSigma) {
  const double n = 1.34;
  const double sigma_px = 0.5;
  const Dive dive = MakeDive(TurnedTruth(), n, 10, 400, sigma_px, 3);
  const SequenceBundleAdjustment bundle =
      SequenceBundleAdjustment::Create(Calibration(), SequenceBundleOptions())
          .value();
  const StatusOr<SequenceBundleResult> result = bundle.Solve(dive.tracks);
  ASSERT_TRUE(result.ok()) << result.status().message();
  EXPECT_GT(result->sigma_n_noise, 0.0);
  EXPECT_LT(std::abs(result->n - n), 4.0 * result->sigma_n_noise)
      << "n " << result->n << " +- " << result->sigma_n_noise;
  EXPECT_NEAR(result->pixel_sigma, sigma_px, 0.05 * sigma_px);
  const double turn_error = (result->state.cam1_rotation - TrueTurn()).norm();
  EXPECT_LT(turn_error, 4.0 * std::sqrt(result->rotation_covariance.trace()));
  // No calibration uncertainty on the test rig: the noise is the total.
  EXPECT_EQ(result->propagation_directions, 0);
  EXPECT_DOUBLE_EQ(result->sigma_n, result->sigma_n_noise);
}

// The default drift prior and focal drift (what a camchain without a
// sidecar gets): the bundle estimates the turn, so the rotation's share
// vanishes from sigma_n_calibration, while the translation and the lenses
// stay in it.
TEST(SequenceBundleAdjustment, CalibrationUncertaintyCarriedIntoSigma) {
  const double n = 1.34;
  CalibrationUncertainty uncertainty =
      CalibrationUncertainty::DefaultDriftPrior();
  const StereoRig calibration = Calibration();
  const int p_l = calibration.left().num_params();
  const int p_r = calibration.right().num_params();
  uncertainty.AddFocalDrift(
      0.003,
      Eigen::Map<const Eigen::VectorXd>(calibration.left().params(), p_l),
      Eigen::Map<const Eigen::VectorXd>(calibration.right().params(), p_r));
  const StereoRig uncertain =
      calibration.WithCalibrationUncertainty(uncertainty).value();
  const Dive dive = MakeDive(TurnedTruth(), n, 6, 250, 0.0, 4);
  SequenceBundleOptions options;
  const SequenceBundleAdjustment bundle =
      SequenceBundleAdjustment::Create(uncertain, options).value();
  const StatusOr<SequenceBundleResult> result = bundle.Solve(dive.tracks);
  ASSERT_TRUE(result.ok()) << result.status().message();
  EXPECT_NEAR(result->n, n, kExactTolerance);
  EXPECT_GT(result->propagation_directions, 0);
  EXPECT_GT(result->sigma_n_calibration, 0.0);
  EXPECT_TRUE(std::isfinite(result->sigma_n_calibration));
  EXPECT_NEAR(result->sigma_n,
              std::hypot(result->sigma_n_noise, result->sigma_n_calibration),
              1e-15);

  // The same with only a rotation uncertain: the bundle absorbs it. What
  // remains is the linear response's third-order remainder of a 0.1
  // degree move (measured 2e-7), where a held turn of 0.1 degree moves an
  // epipolar n by 0.01-0.04 (docs/design.md).
  const StereoRig turned_only =
      calibration
          .WithCalibrationUncertainty(
              CalibrationUncertainty::DriftPrior(0.1 * kDeg, 0.0))
          .value();
  const StatusOr<SequenceBundleResult> absorbed =
      Bundle(turned_only, options, dive.tracks);
  ASSERT_TRUE(absorbed.ok()) << absorbed.status().message();
  EXPECT_EQ(absorbed->propagation_directions, 3);
  EXPECT_LT(absorbed->sigma_n_calibration, 1e-6);
}

// The z-scores of n over Monte Carlo trials on `rig`: 4 keyframes of
// `landmarks` landmarks, 0.3 px of noise, cam1 turned by 0-1 degree about a
// random axis since `calibration` (the drifts), n in [1.33, 1.35]; and,
// with `focal_change`, each camera's focal lengths changed by a relative
// N(0, focal_change^2) since it (a lens that changed), which the
// calibration's focal drift prior of the same size says it may have.
std::vector<double> ZScores(const StereoRig& calibration, int trials,
                            double focal_change, uint64_t seed,
                            int landmarks = 200, double field_px = 0.0,
                            double noise_px = 0.3) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::normal_distribution<double> normal(0.0, 1.0);
  StereoRig held = calibration;
  if (focal_change > 0.0) {
    CalibrationUncertainty uncertainty =
        CalibrationUncertainty::DriftPrior(0.0, 0.0);
    const int p_l = calibration.left().num_params();
    const int p_r = calibration.right().num_params();
    uncertainty.AddFocalDrift(
        focal_change,
        Eigen::Map<const Eigen::VectorXd>(calibration.left().params(), p_l),
        Eigen::Map<const Eigen::VectorXd>(calibration.right().params(), p_r));
    held = calibration.WithCalibrationUncertainty(uncertainty).value();
  }
  SequenceBundleOptions options;
  options.systematic_px = field_px;
  const SequenceBundleAdjustment bundle =
      SequenceBundleAdjustment::Create(held, options).value();
  std::vector<double> z;
  for (int t = 0; t < trials; ++t) {
    const Eigen::Vector3d axis =
        Eigen::Vector3d(normal(rng), normal(rng), normal(rng)).normalized();
    const double degrees = unit(rng);
    StereoRig truth = calibration.WithCam1Moved(degrees * kDeg * axis).value();
    if (focal_change > 0.0) {
      truth = truth
                  .WithFocalScaled(focal_change * normal(rng),
                                   focal_change * normal(rng))
                  .value();
    }
    const double n = 1.33 + 0.02 * unit(rng);
    Dive dive = MakeDive(truth, n, 4, landmarks, noise_px, seed * 1000 + t);
    if (field_px > 0.0) {
      // A smooth field over each camera's image, on u and on v, its 6
      // coefficients of each drawn from N(0, field_px^2) (the header's
      // systematic floor).
      double c[2][2][6];
      for (auto& camera : c) {
        for (auto& coordinate : camera) {
          for (double& coefficient : coordinate) {
            coefficient = field_px * normal(rng);
          }
        }
      }
      for (StereoTrackObservation& o : dive.tracks.observations) {
        const Camera& camera = o.camera == 0 ? truth.left() : truth.right();
        const double x = 2.0 * o.pixel.x() / camera.width() - 1.0;
        const double y = 2.0 * o.pixel.y() / camera.height() - 1.0;
        const double phi[6] = {1.0, x, y, x * x, x * y, y * y};
        for (int j = 0; j < 2; ++j) {
          for (int k = 0; k < 6; ++k) o.pixel[j] += c[o.camera][j][k] * phi[k];
        }
      }
    }
    const StatusOr<SequenceBundleResult> result = bundle.Solve(dive.tracks);
    if (!result.ok()) {
      ADD_FAILURE() << "trial " << t << ": " << result.status().message();
      continue;
    }
    z.push_back((result->n - n) / result->sigma_n);
  }
  return z;
}

double StandardDeviation(const std::vector<double>& values) {
  double mean = 0.0;
  for (double v : values) mean += v;
  mean /= static_cast<double>(values.size());
  double sum = 0.0;
  for (double v : values) sum += (v - mean) * (v - mean);
  return std::sqrt(sum / static_cast<double>(values.size() - 1));
}

// sigma_n is honest: the z-scores' standard deviation in [0.8, 1.3] over
// 50 trials (its standard error at 50 trials is ~10 %, so an honest sigma
// falls outside with a chance of ~1 %; the sanitizer build runs 5 trials
// and checks nothing but that they run).
TEST(SequenceBundleAdjustment, SigmaHonestUnderPixelNoiseAndDrift) {
  for (const StereoRig& rig :
       {test::AlphasenseRealisticRig(), test::NarrowRadtanRig()}) {
    const std::vector<double> z = ZScores(rig, test::Trials(50), 0.0, 21);
    if (!test::ChecksStatistics()) continue;
    ASSERT_EQ(z.size(), 50u);
    const double sd = StandardDeviation(z);
    EXPECT_GT(sd, 0.8);
    EXPECT_LT(sd, 1.3);
  }
}

// Under a lens that changed since the calibration (each camera's focal
// lengths by 0.3 % rms, the default focal drift prior): the bundle
// estimates each focal scale under that prior, what the prior leaves joins
// sigma_n_calibration, and sigma_n stays honest (measured z sd 0.95 on the
// paper's rig and 0.98 on the narrow one; 0.99 and 1.02 with the prior
// only propagated).
TEST(SequenceBundleAdjustment, SigmaHonestUnderALensChange) {
  // Fewer landmarks in the field than the drift's test, as many as keep
  // the narrow rig's keyframes linked (it sees a third of the wide rig's).
  for (const auto& [rig, landmarks] :
       {std::pair<StereoRig, int>{test::AlphasenseRealisticRig(), 100},
        {test::NarrowRadtanRig(), 200}}) {
    const std::vector<double> z =
        ZScores(rig, test::Trials(50), 0.003, 22, landmarks);
    if (!test::ChecksStatistics()) continue;
    ASSERT_EQ(z.size(), 50u);
    const double sd = StandardDeviation(z);
    EXPECT_GT(sd, 0.8);
    EXPECT_LT(sd, 1.3);
  }
}

// Under a matcher's smooth systematic error (each camera's field on u and
// on v, 0.03 px per coefficient, the front end's floor), on top of 0.05 px
// of noise (rendered tracks show 0.07 px): sigma_n carries it
// (sigma_n_systematic) and stays honest: z sd 1.10 on the paper's rig and
// 0.96 on the narrow one; with the floor off, 2.31 and 1.49.
TEST(SequenceBundleAdjustment, SigmaHonestUnderASystematicField) {
  for (const StereoRig& rig :
       {test::AlphasenseRealisticRig(), test::NarrowRadtanRig()}) {
    const std::vector<double> z =
        ZScores(rig, test::Trials(50), 0.0, 23, 200, 0.03, 0.05);
    if (!test::ChecksStatistics()) continue;
    ASSERT_EQ(z.size(), 50u);
    const double sd = StandardDeviation(z);
    EXPECT_GT(sd, 0.8);
    EXPECT_LT(sd, 1.3);
  }
}

// The engine's bundle over the last keyframes only (bundle_window): the
// trajectory is the window's, in its first keyframe's frame, stamped with
// the window's frames; noise-free, n to 1e-9 as over the whole dive.
TEST(EstimateRefractiveIndexFromTracks, WindowAdjustsTheLastKeyframes) {
  const double n = 1.34;
  const Dive dive = MakeDive(TurnedTruth(), n, 8, 300, 0.0, 1);
  std::vector<KeyframeStamp> stamps;
  for (int k = 0; k < 8; ++k) stamps.push_back({10 + k, 0.25 * k});
  EstimationOptions options;
  options.estimator = EstimatorKind::kBundle;
  options.bundle_window = 5;
  const StatusOr<RefractiveIndexEstimate> estimate =
      EstimateRefractiveIndexFromTracks(Calibration(), dive.tracks, stamps,
                                        options);
  ASSERT_TRUE(estimate.ok()) << estimate.status().message();
  EXPECT_NEAR(estimate->n, n, kExactTolerance);
  ASSERT_TRUE(estimate->bundle.has_value());
  EXPECT_EQ(estimate->bundle->frames_used, 5);
  ASSERT_EQ(estimate->bundle->trajectory.size(), 5u);
  EXPECT_EQ(estimate->bundle->trajectory.front().frame, 13);
  EXPECT_EQ(estimate->bundle->trajectory.back().timestamp, 0.25 * 7);
  // Pose k of the window is keyframe 3 + k seen from keyframe 3.
  for (int k = 0; k < 5; ++k) {
    const Rigid3d truth =
        dive.cam0_from_world[3] * dive.cam0_from_world[3 + k].Inverse();
    EXPECT_LT((estimate->bundle->trajectory[k].world_from_cam0.translation -
               truth.translation)
                  .norm(),
              kExactTolerance)
        << "window keyframe " << k;
  }
  options.bundle_window = 1;
  EXPECT_EQ(EstimateRefractiveIndexFromTracks(Calibration(), dive.tracks,
                                              stamps, options)
                .status()
                .message(),
            "bundle window = 1 keyframes must be 0 (every keyframe) or >= 2");
}

TEST(SequenceBundleAdjustment, SolvedFromTheTruthStaysThere) {
  // The functor's residual at the truth is the RefractiveCamera's pixel
  // minus the observed one (zero), for both cameras.
  const double n = 1.36;
  const StereoRig rig = Calibration();
  const Dive dive = MakeDive(rig, n, 2, 50, 0.0, 5);
  SequenceBundleState truth;
  truth.n = n;
  truth.cam1_direction = rig.right_from_left().translation.normalized();
  truth.cam0_from_world = dive.cam0_from_world;
  truth.landmarks = dive.landmarks;
  // Solving from the truth stays there: every residual is zero.
  SequenceBundleOptions options;
  options.propagate_calibration = false;
  const StatusOr<SequenceBundleResult> result =
      SequenceBundleAdjustment::Create(rig, options)
          .value()
          .Solve(dive.tracks, truth);
  ASSERT_TRUE(result.ok()) << result.status().message();
  EXPECT_NEAR(result->n, n, 1e-12);
  EXPECT_LT(result->state.cam1_rotation.norm(), 1e-12);
}

// Motion that does not help: one line that names it, no number. With
// allow_degenerate_motion the noise-free bundle still solves exactly (the
// refusal is about what an error of the model could hide, not arithmetic).
TEST(SequenceBundleAdjustment, StaticRigRefusedInOneLine) {
  const Dive dive =
      MakeDive(TurnedTruth(), 1.34, 6, 300, 0.0, 8, Path::kStatic);
  const StatusOr<SequenceBundleResult> result =
      Bundle(Calibration(), SequenceBundleOptions(), dive.tracks);
  ASSERT_FALSE(result.ok());
  EXPECT_EQ(result.status().message().rfind("the rig does not move: ", 0), 0u)
      << result.status().message();
  EXPECT_NE(result.status().message().find("use the epipolar estimate"),
            std::string::npos);
  EXPECT_EQ(result.status().message().find('\n'), std::string::npos);
  SequenceBundleOptions options;
  options.allow_degenerate_motion = true;
  const StatusOr<SequenceBundleResult> anyway =
      Bundle(Calibration(), options, dive.tracks);
  ASSERT_TRUE(anyway.ok()) << anyway.status().message();
  EXPECT_EQ(anyway->motion.kind, BundleMotion::kStatic);
  EXPECT_NEAR(anyway->n, 1.34, kExactTolerance);
}

TEST(SequenceBundleAdjustment, AlongTheAxisRefusedInOneLine) {
  const Dive dive =
      MakeDive(TurnedTruth(), 1.34, 6, 300, 0.0, 9, Path::kAlongAxis);
  const StatusOr<SequenceBundleResult> result =
      Bundle(Calibration(), SequenceBundleOptions(), dive.tracks);
  ASSERT_FALSE(result.ok());
  EXPECT_EQ(result.status().message().rfind(
                "the rig moves only along its optical axis", 0),
            0u)
      << result.status().message();
}

TEST(SequenceBundleAdjustment, OnePlaneFromOneDistanceRefusedInOneLine) {
  const Dive dive =
      MakeDive(TurnedTruth(), 1.34, 6, 300, 0.0, 10, Path::kOverPlane);
  const StatusOr<SequenceBundleResult> result =
      Bundle(Calibration(), SequenceBundleOptions(), dive.tracks);
  ASSERT_FALSE(result.ok());
  EXPECT_EQ(result.status().message().rfind(
                "the rig sees one plane from one distance", 0),
            0u)
      << result.status().message();
}

TEST(BundleMotion, CurvingPathIsMoving) {
  const Dive dive = MakeDive(TurnedTruth(), 1.34, 8, 300, 0.0, 1);
  SequenceBundleState truth;
  truth.cam0_from_world = dive.cam0_from_world;
  truth.landmarks = dive.landmarks;
  const BundleMotionSummary summary =
      ClassifyBundleMotion(truth, SequenceBundleOptions());
  EXPECT_EQ(summary.kind, BundleMotion::kMoving);
  EXPECT_GT(summary.rotation_span_deg, 2.0);
  EXPECT_EQ(summary.Describe().rfind("the rig moves ", 0), 0u);
}

TEST(SequenceBundleAdjustment, BadTracksRefusedInOneLine) {
  const SequenceBundleAdjustment bundle =
      SequenceBundleAdjustment::Create(Calibration(), SequenceBundleOptions())
          .value();
  StereoTracks tracks;
  tracks.num_frames = 2;
  tracks.num_landmarks = 1;
  tracks.observations.push_back({0, 0, 3, Eigen::Vector2d(10, 10)});
  StatusOr<SequenceBundleResult> result = bundle.Solve(tracks);
  ASSERT_FALSE(result.ok());
  EXPECT_EQ(result.status().message(), "observation 0 names landmark 3 of 1");
  tracks.observations = {{0, 2, 0, Eigen::Vector2d(10, 10)}};
  EXPECT_FALSE(bundle.Solve(tracks).ok());
  tracks.observations = {{5, 0, 0, Eigen::Vector2d(10, 10)}};
  EXPECT_FALSE(bundle.Solve(tracks).ok());
  tracks.observations = {{0, 0, 0, Eigen::Vector2d(NAN, 10)}};
  EXPECT_FALSE(bundle.Solve(tracks).ok());
  tracks.num_frames = 1;
  tracks.observations = {{0, 0, 0, Eigen::Vector2d(10, 10)}};
  EXPECT_FALSE(bundle.Solve(tracks).ok());
}

TEST(SequenceBundleAdjustment, BrokenTrackChainRefused) {
  // Keyframe 2 shares no landmark with keyframes 0-1.
  Dive first = MakeDive(Calibration(), 1.34, 2, 100, 0.0, 6);
  StereoTracks tracks = first.tracks;
  tracks.num_frames = 3;
  tracks.num_landmarks = 200;
  for (const StereoTrackObservation& o : first.tracks.observations) {
    if (o.frame != 0) continue;
    StereoTrackObservation moved = o;
    moved.frame = 2;
    moved.landmark += 100;
    tracks.observations.push_back(moved);
  }
  const StatusOr<SequenceBundleResult> result =
      Bundle(Calibration(), SequenceBundleOptions(), tracks);
  ASSERT_FALSE(result.ok());
  EXPECT_NE(result.status().message().find("keyframe 2 sees 0 landmarks"),
            std::string::npos)
      << result.status().message();
}

TEST(SequenceBundleOptions, CheckNamesTheField) {
  SequenceBundleOptions options;
  EXPECT_TRUE(options.Check().ok());
  options.initial_n = 0.9;
  EXPECT_EQ(options.Check().message(), "initial n = 0.9 is outside [1, 2]");
  options = SequenceBundleOptions();
  options.min_shared_landmarks = 3;
  EXPECT_FALSE(options.Check().ok());
  options = SequenceBundleOptions();
  options.num_threads = 0;
  EXPECT_FALSE(options.Check().ok());
  options = SequenceBundleOptions();
  options.loss_scale_px = -1.0;
  EXPECT_FALSE(options.Check().ok());
}

}  // namespace
}  // namespace rcm
