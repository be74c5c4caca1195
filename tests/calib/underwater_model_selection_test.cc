#include "rcm/calib/underwater_model_selection.h"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include "calib/synthetic_target_views.h"
#include "rcm/calib/calibration_covariance.h"
#include "rcm/estimation/batch_refinement.h"
#include "rcm/io/calibration_covariance_file.h"
#include "rcm/sim/reference_rigs.h"
#include "rcm/sim/stereo_sampler.h"
#include "support/sample_moments.h"
#include "support/test_budget.h"

namespace rcm::calib::underwater_model_selection_test {
namespace {

using test::BoardPoses;
using test::ObserveStereoUnderwater;

constexpr double kDegree = M_PI / 180.0;
constexpr double kTrueN = 1.340;
// Noise-free corners: every candidate that contains the truth reaches it
// to the solver's convergence (underwater_calibration_test.cc).
constexpr double kExactTolerance = 1e-9;

CalibrationTarget Checkerboard() {
  return MakeCheckerboardTarget(9, 6, 0.04).value();
}

// The air rig and the rig as it is in the water: cam1 turned 0.5 degrees,
// the ports as given.
struct Dive {
  StereoRig air;
  StereoRig truth;
  std::vector<StereoView> views;
};

StereoRig Drifted(const StereoRig& rig) {
  return rig
      .WithCam1Moved(
          0.5 * kDegree * Eigen::Vector3d(0.3, -1.0, 0.2).normalized(),
          Eigen::Vector3d(3e-4, -1e-4, 2e-4))
      .value();
}

// `num_views` views of the dataset rig's dive, the board bowed by `warp`
// [m], through `port` on both cameras (thin by default).
Dive MakeDive(int num_views, double noise_px, unsigned seed,
              const Eigen::Vector2d& warp, const FlatPort& port = FlatPort(),
              double min_depth = 0.45, double max_depth = 0.9,
              double max_tilt_deg = 35.0) {
  const StereoRig air = AlphasenseFrontUnrectifiedRig();
  Dive dive{air, Drifted(air).WithPorts(port, port).value(), {}};
  const std::vector<Rigid3d> poses =
      BoardPoses(dive.truth.left(), Checkerboard(), num_views, /*seed=*/7,
                 min_depth, max_depth, max_tilt_deg, kTrueN);
  dive.views = ObserveStereoUnderwater(dive.truth, kTrueN, Checkerboard(),
                                       poses, noise_px, seed, warp);
  return dive;
}

UnderwaterModelSelectionOptions Options(int folds) {
  UnderwaterModelSelectionOptions options;
  options.fit.folds = folds;
  options.fit.fit_conventional_model = false;
  return options;
}

StatusOr<UnderwaterModelSelection> Select(
    const Dive& dive, const UnderwaterModelSelectionOptions& options) {
  return SelectUnderwaterModel(Checkerboard(), dive.views, {720, 540},
                               {720, 540}, dive.air, options);
}

int CandidateIndex(const UnderwaterModelSelection& selection,
                   const UnderwaterCandidateModel& model) {
  for (size_t k = 0; k < selection.candidates.size(); ++k) {
    if (selection.candidates[k].model == model) return static_cast<int>(k);
  }
  return -1;
}

TEST(UnderwaterCandidates, SimplestFirstAndRestrictedByTheFlags) {
  const std::vector<UnderwaterCandidateModel> all =
      UnderwaterCandidates(false, false, false);
  ASSERT_EQ(all.size(), 8u);
  EXPECT_EQ(all[0].Name(), "flat board, thin ports");
  for (size_t k = 1; k < all.size(); ++k) {
    EXPECT_LE(all[k - 1].ExtraParameters(), all[k].ExtraParameters());
  }
  EXPECT_EQ(all.back().Name(), "bowed board, air gaps and tilted ports");
  EXPECT_EQ(UnderwaterCandidates(true, false, false).size(), 4u);
  const std::vector<UnderwaterCandidateModel> one =
      UnderwaterCandidates(true, false, false, /*thin_port=*/true);
  ASSERT_EQ(one.size(), 1u);
  EXPECT_EQ(one[0].Name(), "flat board, thin ports");
  const std::vector<UnderwaterCandidateModel> gaps =
      UnderwaterCandidates(false, true, false);
  ASSERT_EQ(gaps.size(), 2u);
  EXPECT_EQ(gaps[0].Name(), "flat board, air gaps");
  EXPECT_EQ(gaps[1].Name(), "bowed board, air gaps");
  EXPECT_EQ(UnderwaterCandidates(true, true, true)[0].Name(),
            "flat board, air gaps and tilted ports");
}

TEST(UnderwaterModelSelectionOptions, Check) {
  EXPECT_TRUE(UnderwaterModelSelectionOptions().Check().ok());
  UnderwaterModelSelectionOptions options;
  options.candidates.clear();
  EXPECT_NE(options.Check().message().find("empty"), std::string::npos);
  options = UnderwaterModelSelectionOptions();
  options.candidates.push_back(options.candidates[0]);
  EXPECT_NE(options.Check().message().find("twice"), std::string::npos);
  options = UnderwaterModelSelectionOptions();
  options.evidence_sigmas = 0.0;
  EXPECT_NE(options.Check().message().find("evidence_sigmas"),
            std::string::npos);
  options = UnderwaterModelSelectionOptions();
  options.max_sigma_n = -1.0;
  EXPECT_NE(options.Check().message().find("max_sigma_n"), std::string::npos);
  options = UnderwaterModelSelectionOptions();
  options.fit.folds = 1;
  EXPECT_NE(options.Check().message().find("folds"), std::string::npos);
}

// A board bowed by 1.5 mm at its centre, thin ports, no noise: the flat
// board's candidates cannot reach the corners and are ruled out; the bowed
// board's thin-port candidate is chosen and is the truth, as are the
// richer bowed candidates (they contain it), so no model spread remains.
TEST(UnderwaterModelSelection, ExactBowedBoardChoosesTheBow) {
  const Dive dive = MakeDive(16, 0.0, 1, Eigen::Vector2d(8e-4, 7e-4));
  const StatusOr<UnderwaterModelSelection> selection = Select(dive, Options(4));
  ASSERT_TRUE(selection.ok()) << selection.status().message();
  ASSERT_EQ(selection->candidates.size(), 8u);
  EXPECT_EQ(selection->num_evidence_views, 16);
  // (Which bowed candidate is chosen is rounding: they all reach the
  // corners to 1e-13 px.)
  EXPECT_TRUE(selection->candidates[selection->chosen].model.board_warp);
  EXPECT_NEAR(selection->n, kTrueN, kExactTolerance);
  EXPECT_LT(selection->sigma_n_model, kExactTolerance);
  for (const UnderwaterCandidate& candidate : selection->candidates) {
    ASSERT_TRUE(candidate.fit.has_value()) << candidate.error;
    std::printf("[ MEASURED ] %-36s n %.9f held-out %.2e px evidence %.3g\n",
                candidate.model.Name().c_str(), candidate.fit->n,
                candidate.held_out_rms_px, candidate.evidence);
    if (!candidate.model.board_warp) {
      EXPECT_FALSE(candidate.plausible) << candidate.model.Name();
      EXPECT_GT(candidate.held_out_rms_px, 1e-3) << candidate.model.Name();
    } else {
      EXPECT_NEAR(candidate.fit->n, kTrueN, kExactTolerance)
          << candidate.model.Name();
    }
  }
  EXPECT_DOUBLE_EQ(selection->sigma_n, std::hypot(selection->sigma_n_noise,
                                                  selection->sigma_n_lenses,
                                                  selection->sigma_n_model));
}

// A flat board behind 6 mm acrylic with an 8 mm air gap, described to the
// fit as a port block with the glass and no gap: the thin-port candidates
// cannot reach the corners; the air-gap candidates are the truth.
TEST(UnderwaterModelSelection, ExactAirGapChoosesAGap) {
  FlatPort housing;
  housing.air_gap = 0.008;
  housing.glass_thickness = 0.006;
  housing.glass_index = 1.49;
  Dive dive = MakeDive(16, 0.0, 1, Eigen::Vector2d::Zero(), housing);
  FlatPort described = housing;
  described.air_gap = 0.0;
  dive.air = dive.air.WithPorts(described, described).value();
  UnderwaterModelSelectionOptions options = Options(4);
  options.candidates = UnderwaterCandidates(/*flat_board=*/true, false, false);
  const StatusOr<UnderwaterModelSelection> selection = Select(dive, options);
  ASSERT_TRUE(selection.ok()) << selection.status().message();
  const UnderwaterCandidate& chosen = selection->candidates[selection->chosen];
  // (The gap-and-tilt candidate reaches the corners too: either is the
  // truth, and which wins is rounding.)
  EXPECT_TRUE(chosen.model.air_gap) << chosen.model.Name();
  EXPECT_NEAR(selection->n, kTrueN, kExactTolerance);
  EXPECT_NEAR(chosen.fit->ports[0].port.air_gap, 0.008, kExactTolerance);
  const int thin = CandidateIndex(*selection, {false, false, false});
  ASSERT_GE(thin, 0);
  EXPECT_FALSE(selection->candidates[thin].plausible);
}

// Without folds there is no held-out error: every candidate that fits is
// plausible, the simplest is chosen, and sigma_n_model covers the spread
// of the others (the flat board's n is biased by the bow here).
TEST(UnderwaterModelSelection, WithoutFoldsEveryCandidateIsPlausible) {
  const Dive dive = MakeDive(12, 0.0, 1, Eigen::Vector2d(8e-4, 7e-4));
  UnderwaterModelSelectionOptions options = Options(0);
  options.candidates = UnderwaterCandidates(false, false, false, true);
  const StatusOr<UnderwaterModelSelection> selection = Select(dive, options);
  ASSERT_TRUE(selection.ok()) << selection.status().message();
  ASSERT_EQ(selection->candidates.size(), 2u);
  EXPECT_EQ(selection->num_evidence_views, 0);
  for (const UnderwaterCandidate& candidate : selection->candidates) {
    EXPECT_TRUE(candidate.plausible);
    EXPECT_TRUE(std::isnan(candidate.evidence));
  }
  EXPECT_EQ(selection->chosen, 0);
  const double flat_n = selection->candidates[0].fit->n;
  const double bowed_n = selection->candidates[1].fit->n;
  EXPECT_NEAR(bowed_n, kTrueN, kExactTolerance);
  EXPECT_GT(std::abs(flat_n - kTrueN), 1e-4);
  // The model spread: without evidence both weigh 1, so its square is
  // half the squared difference less what the two fits' noise sigmas make
  // of it (here the flat fit's, which is its model error).
  const double difference = flat_n - bowed_n;
  const double noise =
      std::abs(std::pow(selection->candidates[0].sigma_n_noise, 2) -
               std::pow(selection->candidates[1].sigma_n_noise, 2));
  EXPECT_NEAR(selection->sigma_n_model,
              std::sqrt(0.5 * (difference * difference - noise)), 1e-12);
  EXPECT_GT(selection->sigma_n_model, 0.5 * std::abs(difference));
}

// The rig `air` with each camera's lens moved by root * z, z a draw of
// independent unit normals from `normal` and `rng` (root: a factor of the
// lens covariance, L L^T).
StereoRig DrawnLenses(const StereoRig& air, const Eigen::MatrixXd& root,
                      std::mt19937* rng,
                      std::normal_distribution<double>* normal) {
  Camera cameras[2] = {air.left(), air.right()};
  for (Camera& camera : cameras) {
    Eigen::VectorXd unit(camera.num_params());
    for (int i = 0; i < unit.size(); ++i) unit[i] = (*normal)(*rng);
    const Eigen::VectorXd delta = root * unit;
    std::vector<double> params(camera.params(),
                               camera.params() + camera.num_params());
    for (int i = 0; i < unit.size(); ++i) params[i] += delta[i];
    camera = Camera::Create(camera.model(), camera.width(), camera.height(),
                            {params[0], params[1], params[2], params[3]},
                            {params.begin() + 4, params.end()})
                 .value();
  }
  return StereoRig::Create(cameras[0], cameras[1], air.right_from_left())
      .value();
}

// The air lenses' covariance reaches n through the refits: first order, so
// a covariance 4 times larger doubles sigma_n_lenses; and it matches the
// spread of n over air rigs drawn from that covariance (noise-free corners
// of the true rig, 40 draws: the sample sd's relative standard error is
// 1 / sqrt(2 * 40) = 0.11, so [0.65, 1.35] is 3 of them).
TEST(UnderwaterCalibration, LensCovarianceReachesN) {
  const Dive dive = MakeDive(12, 0.0, 1, Eigen::Vector2d::Zero());
  // A lens covariance of the size an air calibration of 30 views gives:
  // 0.3 px on the focal lengths and principal point, 1e-3 on k1, k2, 1e-4
  // on the rest, with a correlation between fx and fy.
  const auto with_covariance = [&](double scale) {
    CalibrationUncertainty uncertainty;
    const int size = dive.air.left().num_params();
    Eigen::MatrixXd covariance = Eigen::MatrixXd::Zero(size, size);
    for (int i = 0; i < size; ++i) {
      const double sigma = i < 4 ? 0.3 : (i < 6 ? 1e-3 : 1e-4);
      covariance(i, i) = scale * sigma * sigma;
    }
    covariance(0, 1) = covariance(1, 0) = 0.8 * covariance(0, 0);
    uncertainty.left_lens_covariance = covariance;
    uncertainty.right_lens_covariance = covariance;
    return dive.air.WithCalibrationUncertainty(uncertainty).value();
  };
  UnderwaterCalibrationOptions options;
  options.folds = 0;
  options.fit_conventional_model = false;
  const ImageSize size{720, 540};
  const StatusOr<UnderwaterCalibration> one = CalibrateUnderwater(
      Checkerboard(), dive.views, size, size, with_covariance(1.0), options);
  const StatusOr<UnderwaterCalibration> four = CalibrateUnderwater(
      Checkerboard(), dive.views, size, size, with_covariance(4.0), options);
  ASSERT_TRUE(one.ok()) << one.status().message();
  ASSERT_TRUE(four.ok()) << four.status().message();
  ASSERT_TRUE(one->sigma_n_lenses.has_value());
  ASSERT_TRUE(four->sigma_n_lenses.has_value());
  EXPECT_GT(*one->sigma_n_lenses, 1e-4);
  // First order: within 2 % (the refits' curvature).
  EXPECT_NEAR(*four->sigma_n_lenses / *one->sigma_n_lenses, 2.0, 0.04);
  // None without a covariance, or when turned off.
  EXPECT_FALSE(CalibrateUnderwater(Checkerboard(), dive.views, size, size,
                                   dive.air, options)
                   ->sigma_n_lenses.has_value());

  const StereoRig air = with_covariance(1.0);
  const CalibrationUncertainty& uncertainty = *air.calibration_uncertainty();
  const Eigen::LLT<Eigen::MatrixXd> factor(uncertainty.left_lens_covariance);
  const Eigen::MatrixXd root = factor.matrixL();
  std::mt19937 rng(5);
  std::normal_distribution<double> normal;
  UnderwaterCalibrationOptions lean = options;
  lean.propagate_lens_covariance = false;
  lean.max_outlier_rounds = 0;
  const int kDraws = rcm::test::Trials(40);
  std::vector<double> n;
  for (int draw = 0; draw < kDraws; ++draw) {
    const StereoRig drawn = DrawnLenses(dive.air, root, &rng, &normal);
    const StatusOr<UnderwaterCalibration> result = CalibrateUnderwater(
        Checkerboard(), dive.views, size, size, drawn, lean);
    ASSERT_TRUE(result.ok()) << result.status().message();
    n.push_back(result->n);
  }
  const double sd = rcm::test::Moments(n).stddev;
  std::printf("[ MEASURED ] sigma_n_lenses %.6f, sd of n over %d draws %.6f\n",
              *one->sigma_n_lenses, kDraws, sd);
  if (!rcm::test::ChecksStatistics()) return;
  EXPECT_GT(sd / *one->sigma_n_lenses, 0.65);
  EXPECT_LT(sd / *one->sigma_n_lenses, 1.35);
}

// What the covariance sidecar of an underwater calibration does for a
// target-free estimate with its camchain. Air rigs are drawn from the air
// lenses' covariance (as above); each is calibrated under water on the
// dive's noise-free corners, so that its extrinsics are fitted through its
// wrong lenses; then n is estimated target-free (batch refinement, cam1's
// rotation self-calibrated under the sidecar's prior) on correspondences
// of the true rig in the water with that camchain and the joint covariance
// the calibration reports (extrinsics_lens_covariance: of the nominal air
// rig's fit, as the draws' differ from it to second order). The scene is
// the one where the correlation matters: near-constant depth (0.9-1.2 m,
// a board or a wall ahead), where n and cam1's rotation are nearly
// collinear and the rotation's prior, i.e. the calibration, decides; 4
// frames of 200 with 0.05 px of noise drawn anew for each draw.
// z = (n - truth) / sigma_n over 40 draws: its root mean square (the truth
// is known: z has mean 0) within [0.65, 1.35] (3 standard errors of a
// sample sd, above). Without the correlation the lenses' error is counted
// as if the extrinsics did not move with it: sigma_n too large, the RMS
// below 0.7 of it (measured 1.06 with, 0.49 without). The rotation's prior
// is its covariance given the lenses (RotationPriorCovariance): mean
// sigma_n 0.0138; with the marginal, degrees wide as the lenses turn the
// fitted rotation, it was 0.081 (RMS 0.93): as honest and 6x wider.
TEST(UnderwaterCalibration, LensCorrelationKeepsTargetFreeSigmaHonest) {
  const Dive dive = MakeDive(12, 0.0, 1, Eigen::Vector2d::Zero());
  CalibrationUncertainty air_uncertainty;
  const int size = dive.air.left().num_params();
  Eigen::MatrixXd lens = Eigen::MatrixXd::Zero(size, size);
  for (int i = 0; i < size; ++i) {
    const double sigma = i < 4 ? 0.5 : (i < 6 ? 2e-3 : 2e-4);
    lens(i, i) = sigma * sigma;
  }
  lens(0, 1) = lens(1, 0) = 0.8 * lens(0, 0);
  air_uncertainty.left_lens_covariance = lens;
  air_uncertainty.right_lens_covariance = lens;
  const StereoRig air =
      dive.air.WithCalibrationUncertainty(air_uncertainty).value();
  UnderwaterCalibrationOptions options;
  options.folds = 0;
  options.fit_conventional_model = false;
  const ImageSize image{720, 540};
  const StatusOr<UnderwaterCalibration> nominal = CalibrateUnderwater(
      Checkerboard(), dive.views, image, image, air, options);
  ASSERT_TRUE(nominal.ok()) << nominal.status().message();
  ASSERT_EQ(nominal->extrinsics_lens_covariance.rows(), 6);
  ASSERT_EQ(nominal->extrinsics_lens_covariance.cols(), 2 * size);
  // The sidecar's uncertainty (calibrate_underwater.cc): the fit's
  // extrinsics covariance plus the lenses' share, the air lenses', and
  // their correlation; and the same without the correlation.
  CalibrationUncertainty joint = air_uncertainty;
  joint.extrinsics_covariance = nominal->extrinsic_change.covariance +
                                nominal->extrinsics_covariance_from_lenses;
  joint.extrinsics_lens_covariance = nominal->extrinsics_lens_covariance;
  ASSERT_TRUE(joint.Check(size, size).ok())
      << joint.Check(size, size).message();
  CalibrationUncertainty independent = joint;
  independent.extrinsics_lens_covariance.resize(0, 0);

  StereoSamplerOptions sampler;
  sampler.n = kTrueN;
  sampler.min_depth = 0.9;
  sampler.max_depth = 1.2;
  sampler.num_frames = 4;
  sampler.per_frame = 200;
  sampler.seed = 11;
  const std::vector<StereoCorrespondence> exact =
      SampleStereoCorrespondences(dive.truth, sampler).value();

  const Eigen::LLT<Eigen::MatrixXd> factor(lens);
  const Eigen::MatrixXd root = factor.matrixL();
  std::mt19937 rng(21);
  std::normal_distribution<double> normal;
  UnderwaterCalibrationOptions lean = options;
  lean.propagate_lens_covariance = false;
  lean.max_outlier_rounds = 0;
  const int kDraws = rcm::test::Trials(40);
  std::vector<double> z;
  std::vector<double> z_independent;
  double sigma_sum = 0.0;
  for (int draw = 0; draw < kDraws; ++draw) {
    const StereoRig drawn = DrawnLenses(dive.air, root, &rng, &normal);
    const StatusOr<UnderwaterCalibration> water = CalibrateUnderwater(
        Checkerboard(), dive.views, image, image, drawn, lean);
    ASSERT_TRUE(water.ok()) << water.status().message();
    std::vector<StereoCorrespondence> data = exact;
    AddPixelNoise(0.05, 100 + draw, &data);
    for (const bool correlated : {true, false}) {
      const StatusOr<RefinementSummary> estimate = RefineRefractiveIndex(
          water->rig
              .WithCalibrationUncertainty(correlated ? joint : independent)
              .value(),
          data, RefinementOptions());
      ASSERT_TRUE(estimate.ok()) << estimate.status().message();
      (correlated ? z : z_independent)
          .push_back((estimate->n - kTrueN) / estimate->sigma_n);
      if (correlated) sigma_sum += estimate->sigma_n;
    }
  }
  const auto rms = [](const std::vector<double>& values) {
    double sum = 0.0;
    for (const double x : values) sum += x * x;
    return std::sqrt(sum / static_cast<double>(values.size()));
  };
  const double sd = rms(z);
  const double sd_independent = rms(z_independent);
  std::printf(
      "[ MEASURED ] target-free z over %d draws: rms %.3f with the "
      "lens correlation (mean sigma_n %.5f), %.3f without\n",
      kDraws, sd, sigma_sum / kDraws, sd_independent);
  if (!rcm::test::ChecksStatistics()) return;
  EXPECT_GT(sd, 0.65);
  EXPECT_LT(sd, 1.35);
  EXPECT_LT(sd_independent, 0.7 * sd);
}

// The ports in the sidecar. An underwater calibration that estimates the
// ports' air gaps and tilts (8 mm behind no glass, tilted 1.5 degrees;
// 12 views at 0.45-0.9 m, 0.3 px of corner noise drawn anew for each dive)
// fits them with the extrinsics: the gap trades against the translation
// along the axis, the tilts against cam1's rotation. A target-free estimate
// with its camchain (batch refinement, thick ports, cam1's rotation
// self-calibrated) on 4 frames of 200 matches of the true rig at 0.5-3 m,
// out of the board's depths, with 0.05 px of noise, holds the geometry the
// calibration fitted, with the sidecar it wrote
// (UnderwaterCalibrationCovariance, read as a file is): the ports' columns
// and their correlation with the extrinsics carry the fit's error, and
// z = (n - truth) / sigma_n has RMS in [0.65, 1.35] over 40 dives (3
// standard errors, as above; measured 0.905, mean sigma_n 0.0015). Without
// the ports (the sidecar before them) the ports are taken as exact, the
// rotation's prior is its covariance given the translation alone, and
// sigma_n misses the tilts' error: RMS 1.84 (mean sigma_n 0.0010), outside
// the band.
TEST(UnderwaterCalibration, PortsInTheSidecarKeepTargetFreeSigmaHonest) {
  FlatPort port;
  port.air_gap = 0.008;
  port.normal = TiltedPortNormal(1.5 * kDegree, 0.7);
  UnderwaterCalibrationOptions options;
  options.estimate_air_gap = true;
  options.estimate_port_tilt = true;
  options.estimate_board_warp = false;
  options.folds = 0;
  options.fit_conventional_model = false;
  options.max_outlier_rounds = 0;
  const ImageSize image{720, 540};
  const Dive geometry = MakeDive(12, 0.0, 1, Eigen::Vector2d::Zero(), port);
  StereoSamplerOptions sampler;
  sampler.n = kTrueN;
  sampler.min_depth = 0.5;
  sampler.max_depth = 3.0;
  sampler.num_frames = 4;
  sampler.per_frame = 200;
  sampler.seed = 11;
  const std::vector<StereoCorrespondence> exact =
      SampleFlatPortCorrespondences(geometry.truth, port, port, sampler)
          .value();
  const int kDraws = rcm::test::Trials(40);
  std::vector<double> z;
  std::vector<double> z_without;
  double sigma_sum = 0.0;
  double sigma_without_sum = 0.0;
  for (int draw = 0; draw < kDraws; ++draw) {
    const Dive dive =
        MakeDive(12, 0.3, 200 + draw, Eigen::Vector2d::Zero(), port);
    const StatusOr<UnderwaterCalibration> water = CalibrateUnderwater(
        Checkerboard(), dive.views, image, image, dive.air, options);
    ASSERT_TRUE(water.ok()) << water.status().message();
    ASSERT_TRUE(water->ports_estimated);
    const CalibrationCovarianceFile file =
        ParseCalibrationCovariance(
            FormatCalibrationCovariance(
                UnderwaterCalibrationCovariance(*water, dive.air)),
            "sidecar")
            .value();
    const Eigen::VectorXd left = Eigen::VectorXd::Map(
        water->rig.left().params(), water->rig.left().num_params());
    const Eigen::VectorXd right = Eigen::VectorXd::Map(
        water->rig.right().params(), water->rig.right().num_params());
    const CalibrationUncertainty sidecar =
        PairCalibrationUncertainty(file, 0, 1, "sidecar", left, right).value();
    ASSERT_EQ(sidecar.port_covariance.rows(), 6);
    CalibrationUncertainty without = sidecar;
    without.port_covariance.resize(0, 0);
    without.port_cross_covariance.resize(0, 0);
    std::vector<StereoCorrespondence> data = exact;
    AddPixelNoise(0.05, 100 + draw, &data);
    for (const bool ports : {true, false}) {
      const StatusOr<RefinementSummary> estimate = RefineRefractiveIndex(
          water->rig.WithCalibrationUncertainty(ports ? sidecar : without)
              .value(),
          data, RefinementOptions());
      ASSERT_TRUE(estimate.ok()) << estimate.status().message();
      (ports ? z : z_without)
          .push_back((estimate->n - kTrueN) / estimate->sigma_n);
      (ports ? sigma_sum : sigma_without_sum) += estimate->sigma_n;
    }
  }
  const auto rms = [](const std::vector<double>& values) {
    double sum = 0.0;
    for (const double x : values) sum += x * x;
    return std::sqrt(sum / static_cast<double>(values.size()));
  };
  std::printf(
      "[ MEASURED ] target-free z over %d dives: rms %.3f with the ports "
      "(mean sigma_n %.5f), %.3f without (%.5f)\n",
      kDraws, rms(z), sigma_sum / kDraws, rms(z_without),
      sigma_without_sum / kDraws);
  if (!rcm::test::ChecksStatistics()) return;
  EXPECT_GT(rms(z), 0.65);
  EXPECT_LT(rms(z), 1.35);
  EXPECT_GT(rms(z_without), 1.35);
}

}  // namespace
}  // namespace rcm::calib::underwater_model_selection_test

namespace rcm::calib::underwater_model_selection_test {
namespace {

// The errors a real dive has that one fixed model leaves out, drawn per
// dive within the ranges of real housings and boards: the board bowed by
// 0.5-3 mm at its centre (either way, split at random between x and y),
// an air gap of 2-10 mm behind 6 mm of acrylic that the air camchain
// describes as glass only, ports tilted by 0.5-3 degrees in any direction.
struct ModelError {
  const char* name;
  bool bow = false;
  bool air_gap = false;
  bool tilt = false;
};

// Monte Carlo (fixed seeds): n's z-score (n - truth) / sigma_n of the
// selection over noisy dives (0.3 px, 16 views, the default 10 folds and
// all eight candidates), each with its own draw of the model error, under
// each error alone and all three mixed. Each dive fits 8 models 11 times
// (4-9 s on 2 cores). The acceptance run is 100 dives per error
// (RCM_MONTE_CARLO_TRIALS=100): the sample sd of a unit normal then has a
// standard error of 1 / sqrt(2 * 100) = 0.07, and each error's sd must lie
// in [0.8, 1.3] (3 of them below 1, 4 above; measured in
// docs/calibrate.md). CI runs kCiTrialsPerError dives of each error (the
// first dives of that run: 25 s of CI's 2 cores each) and checks their
// pooled sd: 24 dives, standard error 1 / sqrt(48) = 0.14, in [0.7, 1.35]
// (2.1 and 2.4 standard errors: a sigma off by 40 % either way fails);
// each error's own sd, of 6 dives, only within [0.25, 2]: the sample sd
// of 6 unit normals is below 0.29 or above 1.83 with probability 0.005
// each (chi-square, 5 degrees of freedom), so the band catches a sigma
// off by a factor of 2-4, not less (the bowed board's 6 dives read 0.34).
// Under the sanitizers one dive of the mixed error covers the code.
constexpr int kMonteCarloViews = 16;
constexpr int kCiTrialsPerError = 6;

int MonteCarloTrials() {
  if (const char* text = std::getenv("RCM_MONTE_CARLO_TRIALS")) {
    return std::max(1, std::atoi(text));
  }
  return rcm::test::kSanitizerBuild ? 1 : kCiTrialsPerError;
}

// The z-scores of `trials` dives under `error`; prints their moments.
std::vector<double> ZScoresUnderModelError(const ModelError& error,
                                           int trials) {
  std::vector<double> z;
  int chose_truth = 0;
  for (int trial = 0; trial < trials; ++trial) {
    std::mt19937 rng(3000 + trial);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    Eigen::Vector2d warp = Eigen::Vector2d::Zero();
    if (error.bow) {
      const double bowl =
          (0.5e-3 + 2.5e-3 * unit(rng)) * (unit(rng) < 0.5 ? -1.0 : 1.0);
      const double share = unit(rng);
      warp = bowl * Eigen::Vector2d(share, 1.0 - share);
    }
    FlatPort housing;
    housing.glass_thickness = 0.006;
    housing.glass_index = 1.49;
    housing.air_gap = error.air_gap ? 0.002 + 0.008 * unit(rng) : 0.0;
    if (error.tilt) {
      const double tilt = (0.5 + 2.5 * unit(rng)) * kDegree;
      const double azimuth = 2.0 * M_PI * unit(rng);
      housing.normal =
          Eigen::Vector3d(std::sin(tilt) * std::cos(azimuth),
                          std::sin(tilt) * std::sin(azimuth), std::cos(tilt));
    }
    Dive dive = MakeDive(kMonteCarloViews, 0.3, 2000 + trial, warp, housing);
    FlatPort described = housing;
    described.air_gap = 0.0;
    described.normal = Eigen::Vector3d::UnitZ();
    dive.air = dive.air.WithPorts(described, described).value();
    UnderwaterModelSelectionOptions options = Options(10);
    options.fit.max_outlier_rounds = 0;
    const StatusOr<UnderwaterModelSelection> selection = Select(dive, options);
    EXPECT_TRUE(selection.ok()) << selection.status().message();
    if (!selection.ok()) continue;
    z.push_back((selection->n - kTrueN) / selection->sigma_n);
    if (trial == 0) {
      // The first dive's candidates, as docs/calibrate.md shows them.
      std::printf(
          "[ MEASURED ] %s, dive 0: n %.5f +- %.5f (noise %.5f, "
          "model %.5f), truth %.3f\n",
          error.name, selection->n, selection->sigma_n,
          selection->sigma_n_noise, selection->sigma_n_model, kTrueN);
      for (size_t k = 0; k < selection->candidates.size(); ++k) {
        const UnderwaterCandidate& c = selection->candidates[k];
        if (!c.fit) {
          std::printf("[ MEASURED ]     %s: %s\n", c.model.Name().c_str(),
                      c.error.c_str());
          continue;
        }
        std::printf(
            "[ MEASURED ]   %s %-38s n %.5f +- %.5f rms %.4f px "
            "held-out %.4f px evidence %.1f%s\n",
            static_cast<int>(k) == selection->chosen ? "*" : " ",
            c.model.Name().c_str(), c.fit->n, c.sigma_n_noise, c.fit->rms_px,
            c.held_out_rms_px, c.evidence, c.plausible ? "" : " x");
      }
    }
    const UnderwaterCandidateModel& chosen =
        selection->candidates[selection->chosen].model;
    chose_truth += chosen.board_warp == error.bow &&
                   chosen.air_gap == error.air_gap &&
                   chosen.port_tilt == error.tilt;
  }
  const rcm::test::SampleMoments moments = rcm::test::Moments(z);
  std::printf(
      "[ MEASURED ] %s: z of n mean %.3f, sd %.3f; the true model "
      "chosen in %d of %d\n",
      error.name, moments.mean, moments.stddev, chose_truth, trials);
  return z;
}

TEST(UnderwaterModelSelection, MonteCarloHonestUnderEachModelError) {
  const int trials = MonteCarloTrials();
  const bool acceptance = trials >= 100;
  const std::vector<ModelError> errors =
      rcm::test::kSanitizerBuild && trials == 1
          ? std::vector<ModelError>{{"bow, air gap and tilt", true, true, true}}
          : std::vector<ModelError>{
                {"bowed board", true, false, false},
                {"air gap", false, true, false},
                {"tilted port", false, false, true},
                {"bow, air gap and tilt", true, true, true}};
  std::vector<double> pooled;
  for (const ModelError& error : errors) {
    const std::vector<double> z = ZScoresUnderModelError(error, trials);
    pooled.insert(pooled.end(), z.begin(), z.end());
    if (!rcm::test::ChecksStatistics() || z.size() < 2) continue;
    const double sd = rcm::test::Moments(z).stddev;
    EXPECT_GT(sd, acceptance ? 0.8 : 0.25) << error.name;
    EXPECT_LT(sd, acceptance ? 1.3 : 2.0) << error.name;
  }
  const rcm::test::SampleMoments moments = rcm::test::Moments(pooled);
  std::printf(
      "[ MEASURED ] every error: z of n mean %.3f, sd %.3f over %zu "
      "dives\n",
      moments.mean, moments.stddev, pooled.size());
  if (!rcm::test::ChecksStatistics() || pooled.size() < 2) return;
  EXPECT_GT(moments.stddev, 0.7);
  EXPECT_LT(moments.stddev, 1.35);
}

}  // namespace
}  // namespace rcm::calib::underwater_model_selection_test
