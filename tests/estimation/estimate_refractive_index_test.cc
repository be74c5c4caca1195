#include "rcm/estimation/estimate_refractive_index.h"

#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "rcm/estimation/batch_refinement.h"
#include "rcm/estimation/estimate_json.h"
#include "rcm/estimation/estimate_warnings.h"
#include "rcm/io/stereo_rig_file.h"
#include "support/test_rigs.h"

namespace rcm::estimate_refractive_index_test {
namespace {

// Exact data: residuals below 1e-12 px at the true n
// (sampson_coplanarity_error_test.cc); the bar for noise-free data.
constexpr double kExactTolerance = 1e-9;
// The same function on the same matches: only the threads' order of
// summation may differ (Ceres' residual evaluation on two threads).
constexpr double kSameRunTolerance = 1e-12;
constexpr double kWaterN = 1.34;

EstimationOptions Options(EstimatorKind kind) {
  EstimationOptions options;
  options.estimator = kind;
  options.window.window_frames = 3;
  return options;
}

TEST(EstimateRefractiveIndex, RefineIsTheBatchRefinement) {
  const StereoRig rig = test::AlphasenseRealisticRig();
  const std::vector<StereoCorrespondence> matches =
      test::ExactSequence(rig, kWaterN, 3, 200, 7);
  const StatusOr<RefractiveIndexEstimate> estimate = EstimateRefractiveIndex(
      rig, SplitFrames(matches), Options(EstimatorKind::kRefine));
  ASSERT_TRUE(estimate.ok()) << estimate.status().message();
  const RefinementSummary summary =
      RefineRefractiveIndex(rig, matches, RefinementOptions()).value();
  EXPECT_NEAR(estimate->n, summary.n, kSameRunTolerance);
  EXPECT_NEAR(estimate->n, kWaterN, kExactTolerance);
  EXPECT_NEAR(estimate->sigma_n, summary.sigma_n, kSameRunTolerance);
  EXPECT_EQ(estimate->inliers, static_cast<int64_t>(summary.inliers.size()));
  EXPECT_EQ(estimate->correspondences, 600);
  EXPECT_EQ(estimate->frames, 3);
  EXPECT_EQ(estimate->estimator, "refine");
  EXPECT_EQ(estimate->port, "thin");
  EXPECT_TRUE(estimate->per_frame.empty());  // not asked for
  EXPECT_TRUE(estimate->warnings.empty());
}

TEST(EstimateRefractiveIndex, EveryEstimatorExactOnNoiseFreeFrames) {
  // The ideal rectified rig, where the closed form (eq. 14) is exact too.
  const StereoRig rig = test::AlphasenseIdealRig();
  const std::vector<FrameMatches> frames =
      SplitFrames(test::ExactSequence(rig, kWaterN, 4, 150, 11));
  for (const EstimatorKind kind :
       {EstimatorKind::kRefine, EstimatorKind::kOnline, EstimatorKind::kWindow,
        EstimatorKind::kClosedForm}) {
    EstimationOptions options = Options(kind);
    options.per_frame_estimates = true;
    const StatusOr<RefractiveIndexEstimate> estimate =
        EstimateRefractiveIndex(rig, frames, options);
    ASSERT_TRUE(estimate.ok())
        << EstimatorName(kind) << ": " << estimate.status().message();
    EXPECT_EQ(estimate->estimator, EstimatorName(kind));
    EXPECT_NEAR(estimate->n, kWaterN, kExactTolerance) << EstimatorName(kind);
    ASSERT_EQ(estimate->per_frame.size(), frames.size()) << EstimatorName(kind);
    for (const FrameEstimateRow& row : estimate->per_frame) {
      EXPECT_NEAR(row.n, kWaterN, kExactTolerance) << EstimatorName(kind);
    }
    EXPECT_FALSE(estimate->method.empty());
  }
}

TEST(EstimateRefractiveIndex, EstimatorNamesRoundTrip) {
  for (const EstimatorKind kind :
       {EstimatorKind::kRefine, EstimatorKind::kOnline, EstimatorKind::kWindow,
        EstimatorKind::kClosedForm, EstimatorKind::kBundle}) {
    EXPECT_EQ(EstimatorFromName(EstimatorName(kind)), kind);
  }
  EXPECT_FALSE(EstimatorFromName("kalman").has_value());
}

// The bundle needs tracks (images), not matches: one line that says so.
TEST(EstimateRefractiveIndex, BundleOnMatchesRefusedInOneLine) {
  const StatusOr<RefractiveIndexEstimate> estimate = EstimateRefractiveIndex(
      test::AlphasenseIdealRig(),
      SplitFrames(test::ExactMatches(test::AlphasenseIdealRig(), 1.333, 200)),
      Options(EstimatorKind::kBundle));
  ASSERT_FALSE(estimate.ok());
  EXPECT_EQ(
      estimate.status().message().rfind(
          "the bundle estimator needs landmarks tracked over keyframes", 0),
      0u);
}

TEST(EstimateRefractiveIndex, RefineOnlyOptionsRefusedElsewhere) {
  EstimationOptions options = Options(EstimatorKind::kWindow);
  options.refinement.refine_rotation = true;
  EXPECT_FALSE(options.Check().ok());
  options = Options(EstimatorKind::kOnline);
  options.estimate_air_gap = true;
  EXPECT_FALSE(options.Check().ok());
  options = Options(EstimatorKind::kRefine);
  options.estimate_air_gap = true;
  EXPECT_TRUE(options.Check().ok());
  options.refinement.refine_rotation = true;
  EXPECT_FALSE(options.Check().ok());
}

TEST(EstimateRefractiveIndex, ClosedFormOffARectifiedRigSaysSo) {
  const StereoRig rig = test::AlphasenseRealisticRig();
  const StatusOr<RefractiveIndexEstimate> estimate = EstimateRefractiveIndex(
      rig, SplitFrames(test::ExactSequence(rig, kWaterN, 2, 200, 3)),
      Options(EstimatorKind::kClosedForm));
  ASSERT_TRUE(estimate.ok()) << estimate.status().message();
  ASSERT_EQ(estimate->warnings.size(), 1u);
  EXPECT_NE(estimate->warnings[0].find("from a rectified pair"),
            std::string::npos);
}

TEST(EstimateWarnings, StaleCalibrationIsNamed) {
  // The rig as `rcm` reads a camchain without a sidecar (0.1 deg of drift
  // prior per axis); the matches of the same rig with cam1 turned by 1
  // degree: 10 prior sigmas, far beyond the 3 of kStaleRotationSigmas.
  const StereoRig rig = WithDefaultCalibrationUncertainty(
                            test::AlphasenseRealisticRig(), RigFileOptions())
                            .value();
  const StereoRig turned =
      rig.WithCam1Moved(Eigen::Vector3d(0.0, M_PI / 180.0, 0.0)).value();
  const auto stale = [](const RefractiveIndexEstimate& e) {
    for (const std::string& warning : e.warnings) {
      if (warning.find("the calibration is stale") != std::string::npos) {
        return true;
      }
    }
    return false;
  };
  const RefractiveIndexEstimate fresh =
      EstimateRefractiveIndex(
          rig, SplitFrames(test::ExactSequence(rig, kWaterN, 3, 200, 5)),
          Options(EstimatorKind::kRefine))
          .value();
  EXPECT_FALSE(stale(fresh));
  const RefractiveIndexEstimate moved =
      EstimateRefractiveIndex(
          rig, SplitFrames(test::ExactSequence(turned, kWaterN, 3, 200, 5)),
          Options(EstimatorKind::kRefine))
          .value();
  ASSERT_TRUE(moved.rotation.has_value());
  EXPECT_TRUE(stale(moved)) << moved.warnings.size() << " warnings";
  EXPECT_EQ(EstimateWarnings(moved), moved.warnings);
}

TEST(EstimateJson, KeysAreTheFieldsAndMeanTheSame) {
  const StereoRig rig = WithDefaultCalibrationUncertainty(
                            test::AlphasenseRealisticRig(), RigFileOptions())
                            .value();
  const RefractiveIndexEstimate estimate =
      EstimateRefractiveIndex(
          rig, SplitFrames(test::ExactSequence(rig, kWaterN, 3, 200, 9)),
          Options(EstimatorKind::kRefine))
          .value();
  const nlohmann::json json = nlohmann::json::parse(EstimateJson(estimate));
  // Numbers round-trip exactly (17 significant digits).
  EXPECT_EQ(json.at("n").get<double>(), estimate.n);
  EXPECT_EQ(json.at("sigma_n").get<double>(), estimate.sigma_n);
  EXPECT_EQ(json.at("sigma_n_noise").get<double>(), estimate.sigma_n_noise);
  EXPECT_EQ(json.at("sigma_n_calibration").get<double>(),
            estimate.sigma_n_calibration);
  EXPECT_EQ(json.at("inliers").get<int64_t>(), estimate.inliers);
  EXPECT_EQ(json.at("frames").get<int64_t>(), 3);
  EXPECT_EQ(json.at("estimator"), "refine");
  ASSERT_TRUE(estimate.rotation.has_value());
  for (int i = 0; i < 3; ++i) {
    EXPECT_DOUBLE_EQ(json.at("rotation").at("angle_axis_deg")[i].get<double>(),
                     estimate.rotation->angle_axis[i] * 180.0 / M_PI);
  }
  ASSERT_TRUE(estimate.calibration.has_value());
  EXPECT_EQ(json.at("calibration").at("rotation"),
            RotationModeName(estimate.calibration->mode));
  EXPECT_DOUBLE_EQ(
      json.at("calibration").at("prior_sigma_deg")[0].get<double>(),
      0.1);  // the default drift prior
  EXPECT_TRUE(json.at("warnings").is_array());
  // The window's keys belong to the window estimator only.
  EXPECT_FALSE(json.contains("switches"));
  EXPECT_TRUE(json.contains("n_seed"));
}

TEST(EstimateJson, NaNIsNull) {
  RefractiveIndexEstimate estimate;
  estimate.estimator = "closed-form";
  estimate.n = 1.33;
  const nlohmann::json json = nlohmann::json::parse(EstimateJson(estimate, -1));
  EXPECT_TRUE(json.at("sigma_n_noise").is_null());
  EXPECT_TRUE(json.at("calibration").is_null());
  EXPECT_EQ(json.at("n").get<double>(), 1.33);
}

TEST(EstimatePerFrameCsv, OneRowPerFrame) {
  RefractiveIndexEstimate estimate;
  estimate.per_frame.push_back({4, 0.5, 1.33, 0.01, false});
  estimate.per_frame.push_back({5, std::nullopt, NAN, NAN, true});
  EXPECT_EQ(EstimatePerFrameCsv(estimate),
            "frame,t,n,sigma_n,switch\n4,0.5,1.3300000000000001,"
            "0.01,0\n5,,,,1\n");
}

}  // namespace
}  // namespace rcm::estimate_refractive_index_test
