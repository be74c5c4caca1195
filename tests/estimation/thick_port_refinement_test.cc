#include "rcm/estimation/thick_port_refinement.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "rcm/estimation/batch_refinement.h"
#include "rcm/sim/stereo_sampler.h"
#include "support/reader_inputs.h"
#include "support/test_rigs.h"

namespace rcm::thick_port_refinement_test {
namespace {

FlatPort Port(double air_gap, double glass_thickness) {
  FlatPort port;
  port.air_gap = air_gap;
  port.glass_thickness = glass_thickness;
  port.glass_index = 1.49;
  return port;
}

// Correspondences through the exact port (the simulator's ray tracer),
// scene depths 0.6-6 m, with Gaussian pixel noise on all four coordinates.
std::vector<StereoCorrespondence> Matches(const StereoRig& rig,
                                          const FlatPort& port, double n,
                                          double noise_px, uint64_t seed,
                                          int count = 300) {
  StereoSamplerOptions options;
  options.n = n;
  options.per_frame = count;
  options.seed = seed;
  std::vector<StereoCorrespondence> matches =
      SampleFlatPortCorrespondences(rig, port, port, options).value();
  if (noise_px > 0.0) AddPixelNoise(noise_px, seed + 1000, &matches);
  return matches;
}

// Noise-free data through the true port give n to 1e-9 (the solver's
// tolerance; the templated back-trace agrees with the tracer to 1e-12)
// over the range of housings, where the thin-port estimate is
// biased by up to -0.05.
TEST(ThickPortRefinement, ExactOverGapsAndGlass) {
  const StereoRig rig = test::AlphasenseRealisticRig();
  constexpr double kN = 1.335;
  for (const double gap : {0.0, 0.01, 0.03}) {
    for (const double glass : {0.0, 0.005, 0.01}) {
      const FlatPort port = Port(gap, glass);
      const std::vector<StereoCorrespondence> matches =
          Matches(rig, port, kN, 0.0, 3);
      const StatusOr<ThickPortRefinementSummary> thick =
          RefineRefractiveIndexThickPort(rig, port, port, matches,
                                         ThickPortRefinementOptions());
      ASSERT_TRUE(thick.ok()) << thick.status().message();
      EXPECT_NEAR(thick->refinement.n, kN, 1e-9)
          << "gap " << gap << " glass " << glass;
      EXPECT_EQ(thick->refinement.inliers.size(), matches.size());
    }
  }
}

// Noise-free data and a wrong gap in the rig file: estimating the gap
// with n recovers both.
TEST(ThickPortRefinement, ExactJointAirGap) {
  const StereoRig rig = test::AlphasenseRealisticRig();
  const FlatPort truth = Port(0.008, 0.006);
  const std::vector<StereoCorrespondence> matches =
      Matches(rig, truth, 1.335, 0.0, 4);
  ThickPortRefinementOptions options;
  options.estimate_air_gap = true;
  const FlatPort guess = Port(0.004, 0.006);
  const StatusOr<ThickPortRefinementSummary> result =
      RefineRefractiveIndexThickPort(rig, guess, guess, matches, options);
  ASSERT_TRUE(result.ok()) << result.status().message();
  ASSERT_TRUE(result->air_gap.has_value());
  EXPECT_NEAR(result->refinement.n, 1.335, 1e-9);
  EXPECT_NEAR(result->air_gap->left_air_gap, 0.008, 1e-9);
  EXPECT_NEAR(result->air_gap->right_air_gap, 0.008, 1e-9);
}

// Acceptance (issue 8): with 0.3 px noise the estimate with the true port
// has an RMS error within 1.5x the Cramer-Rao bound over 12 trials per
// housing, for gaps of 0, 10 and 30 mm with glass of 0, 5 and 10 mm and
// the 8 mm + 6 mm (the RMS of 12 unbiased trials exceeds 1.5x its
// expectation with probability ~1e-3 per housing), while the thin-port
// estimate is biased by several bounds. Dataset rig, true n = 1.335, 300
// matches per trial.
TEST(ThickPortRefinement,
     WithinOneAndAHalfCramerRaoBoundsWhereThinPortIsBiased) {
  const StereoRig rig = test::AlphasenseRealisticRig();
  constexpr double kN = 1.335;
  constexpr double kNoisePx = 0.3;
  constexpr int kTrials = 12;
  std::vector<std::pair<double, double>> housings = {{0.008, 0.006}};
  for (const double gap : {0.0, 0.01, 0.03}) {
    for (const double glass : {0.0, 0.005, 0.01}) {
      housings.emplace_back(gap, glass);
    }
  }
  for (const auto& [gap, glass] : housings) {
    const FlatPort port = Port(gap, glass);
    double squared_error = 0.0;
    double crlb = 0.0;
    double thin_error = 0.0;
    for (int trial = 0; trial < kTrials; ++trial) {
      const std::vector<StereoCorrespondence> matches =
          Matches(rig, port, kN, kNoisePx, 100 + trial);
      const StatusOr<ThickPortRefinementSummary> thick =
          RefineRefractiveIndexThickPort(rig, port, port, matches,
                                         ThickPortRefinementOptions());
      ASSERT_TRUE(thick.ok()) << thick.status().message();
      const double error = thick->refinement.n - kN;
      squared_error += error * error / kTrials;
      crlb += thick->refinement.crlb / kTrials;
      const StatusOr<RefinementSummary> thin =
          RefineRefractiveIndex(rig, matches, RefinementOptions());
      ASSERT_TRUE(thin.ok()) << thin.status().message();
      thin_error += (thin->n - kN) / kTrials;
    }
    const double rmse = std::sqrt(squared_error);
    std::printf(
        "gap %2.0f mm, glass %2.0f mm: thick-port RMSE %.2e (CRLB %.2e, "
        "ratio %.2f); thin-port mean error %+.4f\n",
        gap * 1e3, glass * 1e3, rmse, crlb, rmse / crlb, thin_error);
    EXPECT_LT(rmse, 1.5 * crlb);
    // The thin-port mean over 12 trials has a standard deviation of about
    // crlb / sqrt(12) = 0.3 crlb, so a bias beyond 3 bounds is ten of its
    // standard deviations: a bias, not noise.
    if (gap >= 0.008) {  // below, the bias is within a few bounds
      EXPECT_GT(std::abs(thin_error), 3.0 * crlb);
    }
  }
}

// The joint air gap: over 30 seeds (0.3 px, 500 matches, gap started 3 mm
// off) the z-scores (estimate - truth) / sigma of n and of the gap. The
// reported sigmas are conservative, not optimistic: measured standard
// deviations of the z-scores are 0.77 (n) and 0.66 (gap) over 40 seeds,
// because the information on the gap changes with the gap itself (the
// sigma of the gap ranges 1.4-3.4 mm between seeds), so the covariance
// evaluated at a noisy estimate overstates the spread. The test holds the
// z-scores' sd within [0.5, 1.3] (never optimistic beyond sampling: its
// sampling sd is 1/sqrt(60) = 0.13) and |mean| < 0.6 (3.3 sd of a mean of
// 30). n and the gap are strongly correlated (the bias table of
// docs/thin_port_bias.md: a gap reads as a smaller n), which the reported
// correlation shows.
TEST(ThickPortRefinement, MonteCarloJointAirGapSigmaIsHonest) {
  const StereoRig rig = test::AlphasenseRealisticRig();
  const FlatPort truth = Port(0.008, 0.006);
  const FlatPort guess = Port(0.005, 0.006);
  ThickPortRefinementOptions options;
  options.estimate_air_gap = true;
  constexpr int kTrials = 30;
  std::vector<double> z_n;
  std::vector<double> z_gap;
  double correlation = 0.0;
  for (int trial = 0; trial < kTrials; ++trial) {
    const StatusOr<ThickPortRefinementSummary> result =
        RefineRefractiveIndexThickPort(
            rig, guess, guess,
            Matches(rig, truth, 1.335, 0.3, 300 + trial, 500), options);
    ASSERT_TRUE(result.ok()) << result.status().message();
    z_n.push_back((result->refinement.n - 1.335) / result->refinement.sigma_n);
    z_gap.push_back((result->air_gap->left_air_gap - 0.008) /
                    result->air_gap->sigma);
    correlation += result->air_gap->correlation_with_n / kTrials;
    // Estimating the gap costs precision: sigma_n above the bound with the
    // gap known.
    EXPECT_GT(result->refinement.sigma_n, result->refinement.crlb);
  }
  for (const std::vector<double>* z : {&z_n, &z_gap}) {
    double mean = 0.0;
    for (const double v : *z) mean += v / kTrials;
    double variance = 0.0;
    for (const double v : *z)
      variance += (v - mean) * (v - mean) / (kTrials - 1);
    EXPECT_GT(std::sqrt(variance), 0.5);
    EXPECT_LT(std::sqrt(variance), 1.3);
    EXPECT_LT(std::abs(mean), 0.6);
  }
  std::printf("mean correlation of n with the air gap: %.3f\n", correlation);
  EXPECT_GT(std::abs(correlation), 0.5);
}

TEST(ThickPortRefinement, RejectsRotationCorrectionAndBadPorts) {
  const StereoRig rig = test::AlphasenseRealisticRig();
  const std::vector<StereoCorrespondence> matches =
      Matches(rig, Port(0.008, 0.006), 1.335, 0.0, 5, 50);
  ThickPortRefinementOptions options;
  options.base.refine_rotation = true;
  EXPECT_NE(test::ErrorMessage(RefineRefractiveIndexThickPort(
                                   rig, Port(0.008, 0.006), Port(0.008, 0.006),
                                   matches, options))
                .find("rotation correction"),
            std::string::npos);
  EXPECT_NE(test::ErrorMessage(RefineRefractiveIndexThickPort(
                                   rig, Port(-0.001, 0.0), Port(0.0, 0.0),
                                   matches, ThickPortRefinementOptions()))
                .find("left camera: port air_gap"),
            std::string::npos);
  EXPECT_NE(test::ErrorMessage(RefineRefractiveIndexThickPort(
                                   rig, Port(0.0, 0.0), Port(0.0, 0.0),
                                   std::vector<StereoCorrespondence>(
                                       matches.begin(), matches.begin() + 5),
                                   ThickPortRefinementOptions()))
                .find("too few correspondences"),
            std::string::npos);
}

}  // namespace
}  // namespace rcm::thick_port_refinement_test

namespace rcm::thick_port_refinement_test {
namespace {

// A rig that carries thick ports (from a camchain's port blocks) is refined
// with the thick-port model by the estimator of record.
TEST(ThickPortRefinement, RigWithPortsSelectsTheThickModel) {
  const FlatPort port = Port(0.008, 0.006);
  const StereoRig rig =
      test::AlphasenseRealisticRig().WithPorts(port, port).value();
  ASSERT_TRUE(rig.HasThickPort());
  const std::vector<StereoCorrespondence> matches =
      Matches(rig, port, 1.335, 0.0, 21);
  const StatusOr<RefinementSummary> summary =
      RefineRefractiveIndex(rig, matches, RefinementOptions());
  ASSERT_TRUE(summary.ok()) << summary.status().message();
  EXPECT_NEAR(summary->n, 1.335, 1e-9);
  RefinementOptions rotation;
  rotation.refine_rotation = true;
  EXPECT_NE(test::ErrorMessage(RefineRefractiveIndex(rig, matches, rotation))
                .find("not available with a thick port"),
            std::string::npos);
}

// Thin ports in the rig file change nothing: the paper's model, bit for
// bit.
TEST(ThickPortRefinement, ThinPortsGiveTheThinPortResultExactly) {
  const StereoRig plain = test::AlphasenseRealisticRig();
  const StereoRig with_thin = plain.WithPorts(FlatPort(), FlatPort()).value();
  EXPECT_FALSE(with_thin.HasThickPort());
  const std::vector<StereoCorrespondence> matches =
      Matches(plain, FlatPort(), 1.335, 0.5, 22);
  const StatusOr<RefinementSummary> a =
      RefineRefractiveIndex(plain, matches, RefinementOptions());
  const StatusOr<RefinementSummary> b =
      RefineRefractiveIndex(with_thin, matches, RefinementOptions());
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_EQ(a->n, b->n);
  EXPECT_EQ(a->sigma_n, b->sigma_n);
  EXPECT_EQ(a->inliers, b->inliers);
}

// A port tilted by (x, y) degrees (N_x / N_z = tan x, N_y / N_z = tan y),
// no gap or glass: the thick-port model all the same (the rays no longer
// meet in the camera center).
FlatPort TiltedPort(double x_deg, double y_deg) {
  FlatPort port;
  port.normal = Eigen::Vector3d(std::tan(x_deg * M_PI / 180.0),
                                std::tan(y_deg * M_PI / 180.0), 1.0)
                    .normalized();
  return port;
}

// Tilted ports (as an underwater calibration of a hand-built housing found
// them: 3.9 and 2.0 degrees) and cam1 turned since that calibration; the
// rig read with the default drift prior. cam1's rotation is
// self-calibrated under the prior, as for the thin port: noise-free data
// give n and the turn to 1e-9, where the rotation held at the stale
// calibration gives an n that is off.
TEST(ThickPortRefinement, TiltedPortsSelfCalibrateTheRotationExactly) {
  const FlatPort left = TiltedPort(3.9, 0.6);
  const FlatPort right = TiltedPort(1.4, 1.4);
  const StereoRig nominal =
      test::AlphasenseRealisticRig().WithPorts(left, right).value();
  ASSERT_TRUE(nominal.HasThickPort());
  const Eigen::Vector3d turn = Eigen::Vector3d(0.05, 0.12, -0.03) * M_PI / 180;
  const StereoRig truth = nominal.WithCam1Moved(turn).value();
  StereoSamplerOptions sampling;
  sampling.n = 1.335;
  sampling.num_frames = 4;
  sampling.per_frame = 100;
  sampling.seed = 31;
  const std::vector<StereoCorrespondence> matches =
      SampleFlatPortCorrespondences(truth, left, right, sampling).value();
  const StereoRig calibrated =
      nominal
          .WithCalibrationUncertainty(
              CalibrationUncertainty::DefaultDriftPrior())
          .value();
  const StatusOr<RefinementSummary> summary =
      RefineRefractiveIndex(calibrated, matches, RefinementOptions());
  ASSERT_TRUE(summary.ok()) << summary.status().message();
  EXPECT_NEAR(summary->n, 1.335, 1e-9);
  ASSERT_TRUE(summary->rotation.has_value());
  EXPECT_TRUE(summary->rotation->with_prior);
  EXPECT_LT((summary->rotation->angle_axis - turn).norm(), 1e-9);
  EXPECT_LT(summary->sigma_px, 1e-9);
  // Held: n absorbs the turn.
  RefinementOptions held;
  held.self_calibrate_rotation = false;
  const StatusOr<RefinementSummary> stale =
      RefineRefractiveIndex(calibrated, matches, held);
  ASSERT_TRUE(stale.ok()) << stale.status().message();
  EXPECT_FALSE(stale->rotation.has_value());
  EXPECT_GT(std::abs(stale->n - 1.335), 1e-3);
}

TEST(StereoRigPorts, WithPortsRejectsInvalidPorts) {
  const StereoRig rig = test::AlphasenseRealisticRig();
  EXPECT_EQ(test::ErrorMessage(rig.WithPorts(Port(0.0, 0.0), Port(0.9, 0.0))),
            "right port: port air_gap = 0.9 m is outside [0, 0.5]");
  EXPECT_FALSE(rig.ports().has_value());
}

}  // namespace
}  // namespace rcm::thick_port_refinement_test
