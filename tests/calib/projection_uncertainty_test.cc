// mrcal's mean-frames projection uncertainty (projection_uncertainty.h):
// the Jacobian by autodiff against central differences, q(b*) = q0, and a
// Monte Carlo check that the predicted spread is the spread of re-solved
// calibrations.
#include "rcm/calib/projection_uncertainty.h"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <cstdio>
#include <vector>

#include "calib/synthetic_target_views.h"
#include "rcm/calib/calibration_report.h"
#include "rcm/calib/stereo_calibration.h"
#include "support/test_rigs.h"

namespace rcm::calib::projection_uncertainty_test {
namespace {

using test::BoardPoses;
using test::ObserveStereo;

CalibrationTarget Checkerboard() {
  return MakeCheckerboardTarget(9, 6, 0.04).value();
}

const Eigen::Vector2d kWarp(4e-4, 3e-4);

// EuRoC's radtan lens twice on a 0.11 m, 0.5-degree rig (752x480).
StereoRig RadTanRig() { return rcm::test::EurocRadtanTwinRig(); }

StereoCalibration CalibrateViews(const StereoRig& rig,
                                 const std::vector<StereoView>& views) {
  StereoCalibrationOptions options;
  options.model = rig.left().model();
  return CalibrateStereo(Checkerboard(), views,
                         {rig.left().width(), rig.left().height()},
                         {rig.right().width(), rig.right().height()}, options)
      .value();
}

StereoCalibration NoisyCalibration(const StereoRig& rig, int num_views,
                                   double noise_px, unsigned seed) {
  const std::vector<Rigid3d> poses =
      BoardPoses(rig.left(), Checkerboard(), num_views, /*seed=*/7);
  return CalibrateViews(
      rig, ObserveStereo(rig, Checkerboard(), poses, noise_px, seed, kWarp));
}

TEST(MeanFramesProjection, JacobianMatchesCentralDifferences) {
  // Autodiff against central differences of q(b) over every parameter.
  // The step 1e-6 (of px, rad, m) leaves a truncation error of order
  // h^2 |q'''| ~ 1e-12 * (f / depth^3 ~ 1e3) and a rounding error of
  // 1e-16 * 500 px / 1e-6 ~ 5e-8: 1e-6 relative to the largest entry is
  // far above both.
  const StereoRig rig = RadTanRig();
  const StereoCalibration calibration = NoisyCalibration(rig, 12, 0.2, 3);
  ASSERT_GT(calibration.full_covariance.size(), 0);
  EXPECT_EQ(calibration.full_covariance.size(),
            calibration.full_parameters.size());
  EXPECT_EQ(calibration.full_covariance.size(), calibration.num_parameters);
  constexpr double kStep = 1e-6;
  for (int camera = 0; camera < 2; ++camera) {
    for (double distance : {kInfiniteDistance, 1.0}) {
      for (const Eigen::Vector2d& pixel :
           {Eigen::Vector2d(376.0, 240.0), Eigen::Vector2d(60.0, 50.0)}) {
        const std::optional<MeanFramesPoint> point =
            MeanFramesPointOf(calibration, camera, pixel, distance);
        ASSERT_TRUE(point.has_value());
        // q(b*) is the pixel itself.
        const std::optional<Eigen::Vector2d> q0 = MeanFramesPixel(
            calibration, *point, calibration.full_parameters);
        ASSERT_TRUE(q0.has_value());
        EXPECT_LT((*q0 - pixel).norm(), 1e-6);
        const Eigen::MatrixXd autodiff =
            MeanFramesJacobian(calibration, *point).value();
        Eigen::MatrixXd numeric(2, autodiff.cols());
        for (int k = 0; k < autodiff.cols(); ++k) {
          Eigen::VectorXd plus = calibration.full_parameters;
          Eigen::VectorXd minus = plus;
          plus[k] += kStep;
          minus[k] -= kStep;
          numeric.col(k) = (MeanFramesPixel(calibration, *point, plus).value() -
                            MeanFramesPixel(calibration, *point, minus).value()) /
                           (2.0 * kStep);
        }
        const double scale = autodiff.cwiseAbs().maxCoeff();
        EXPECT_LT((autodiff - numeric).cwiseAbs().maxCoeff(), 1e-6 * scale)
            << "cam" << camera << " distance " << distance;
        // At infinity the translations drop out.
        if (std::isinf(distance)) {
          for (size_t v = 0; v < point->pose_offset.size(); ++v) {
            const double translation =
                autodiff.block<2, 3>(0, point->pose_offset[v] + 3)
                    .cwiseAbs()
                    .maxCoeff();
            EXPECT_EQ(translation, 0.0);
          }
        }
      }
    }
  }
  // The warp does not enter q (its correlations enter through Var(b)).
  const FullCovariance& layout = calibration.full_covariance;
  ASSERT_GE(layout.warp_offset, 0);
  const MeanFramesPoint point =
      MeanFramesPointOf(calibration, 1, {100.0, 400.0}, 1.0).value();
  const double warp_column = MeanFramesJacobian(calibration, point)
                                  ->block<2, 2>(0, layout.warp_offset)
                                  .cwiseAbs()
                                  .maxCoeff();
  EXPECT_EQ(warp_column, 0.0);
  EXPECT_TRUE(std::isnan(
      MeanFramesProjectionUncertainty(calibration, 0, {376.0, 240.0}, -1.0)));
}

TEST(MeanFramesProjection, InTheReport) {
  // The report's statistics and map of the mean-frames figure: finite,
  // ordered, at the distance asked for.
  const StereoRig rig = RadTanRig();
  const StereoCalibration calibration = NoisyCalibration(rig, 12, 0.2, 3);
  std::vector<StereoView> views(calibration.cam0_from_target.size());
  const ImageSize size{rig.left().width(), rig.left().height()};
  CalibrationReportOptions options;
  const CalibrationReport at_infinity =
      SummarizeCalibration(calibration, views, size, size, options);
  options.uncertainty_distance_m = 1.0;
  const CalibrationReport at_1m =
      SummarizeCalibration(calibration, views, size, size, options);
  for (int c = 0; c < 2; ++c) {
    const CalibrationReport::CameraStats& s = at_infinity.cameras[c];
    std::printf("cam%d: mean-frames median %.4f p95 %.4f max %.4f px at "
                "infinity, median %.4f px at 1 m; intrinsics only median "
                "%.4f px\n",
                c, s.projection_uncertainty_median_px,
                s.projection_uncertainty_p95_px,
                s.projection_uncertainty_max_px,
                at_1m.cameras[c].projection_uncertainty_median_px,
                s.intrinsics_only_uncertainty_median_px);
    EXPECT_GT(s.projection_uncertainty_median_px, 0.0);
    EXPECT_LE(s.projection_uncertainty_median_px,
              s.projection_uncertainty_p95_px);
    EXPECT_LE(s.projection_uncertainty_p95_px, s.projection_uncertainty_max_px);
    EXPECT_NE(s.projection_uncertainty_median_px,
              at_1m.cameras[c].projection_uncertainty_median_px);
    // The same sample as the function's at the image centre's cell.
    EXPECT_TRUE(std::isfinite(s.projection_uncertainty_max_px));
  }
  const cv::Mat map = DrawMeanFramesUncertainty(calibration, 1, 1.0, 0.0,
                                                "cam1");
  EXPECT_EQ(map.type(), CV_8UC3);
  EXPECT_GE(map.cols, size.width);
  options.uncertainty_distance_m = 0.0;
  EXPECT_FALSE(options.Check().ok());
  EXPECT_EQ(DistanceName(kInfiniteDistance), "infinity");
}

// Worst-direction standard deviation of a sample of pixels.
double SampleWorstSigma(const std::vector<Eigen::Vector2d>& samples) {
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (const Eigen::Vector2d& q : samples) mean += q;
  mean /= static_cast<double>(samples.size());
  Eigen::Matrix2d covariance = Eigen::Matrix2d::Zero();
  for (const Eigen::Vector2d& q : samples) {
    covariance += (q - mean) * (q - mean).transpose();
  }
  covariance /= static_cast<double>(samples.size() - 1);
  return WorstDirectionSigma(covariance);
}

TEST(MeanFramesProjection, MonteCarloSpreadIsThePredictedOne) {
  // A known rig and 10 board poses (a bowed board, the warp estimated;
  // the radtan rig: with the equidistant Alphasense rig and this few views
  // some draws make the solve fail from OpenCV's start);
  // exact corners re-noised with 0.3 px, re-solved 100 times (fixed
  // seeds). For a few pixels, q_trial = q(b_trial) with the points p_i
  // fixed at the noise-free solution b* (= the truth): mrcal's own Monte
  // Carlo. The worst-direction standard deviation of q_trial against the
  // predicted sqrt(lambda_max(J Var(b) J^T)), averaged over the trials'
  // own predictions (each with its own sigma estimate): the ratio in
  // [0.8, 1.25]. With N = 100 the sample standard deviation has a
  // relative standard error of 1 / sqrt(2 (N - 1)) = 0.07, so the band is
  // ~3 standard errors (and the largest eigenvalue of a 2x2 sample
  // covariance is biased up by a few %).
  constexpr int kTrials = 100;
  constexpr int kViews = 10;
  constexpr double kNoisePx = 0.3;
  const StereoRig rig = RadTanRig();
  const std::vector<Rigid3d> poses =
      BoardPoses(rig.left(), Checkerboard(), kViews, /*seed=*/7);
  const StereoCalibration reference = CalibrateViews(
      rig, ObserveStereo(rig, Checkerboard(), poses, 0.0, 1, kWarp));
  ASSERT_EQ(reference.num_views_used, kViews);
  struct Probe {
    int camera;
    Eigen::Vector2d pixel;
    double distance;
  };
  const std::vector<Probe> probes = {
      {0, {376.0, 240.0}, kInfiniteDistance},
      {0, {40.0, 40.0}, kInfiniteDistance},
      {1, {710.0, 440.0}, kInfiniteDistance},
      {0, {376.0, 240.0}, 1.0},
      {0, {40.0, 40.0}, 1.0},
      {1, {710.0, 440.0}, 1.0}};
  std::vector<MeanFramesPoint> points;
  for (const Probe& probe : probes) {
    points.push_back(
        MeanFramesPointOf(reference, probe.camera, probe.pixel, probe.distance)
            .value());
  }
  std::vector<std::vector<Eigen::Vector2d>> samples(probes.size());
  std::vector<double> predicted(probes.size(), 0.0);
  for (int trial = 0; trial < kTrials; ++trial) {
    const StereoCalibration c = CalibrateViews(
        rig,
        ObserveStereo(rig, Checkerboard(), poses, kNoisePx, 100 + trial, kWarp));
    ASSERT_EQ(c.full_parameters.size(), reference.full_parameters.size());
    for (size_t p = 0; p < probes.size(); ++p) {
      samples[p].push_back(
          MeanFramesPixel(reference, points[p], c.full_parameters).value());
      const double sigma = MeanFramesProjectionUncertainty(
          c, probes[p].camera, probes[p].pixel, probes[p].distance);
      predicted[p] += sigma * sigma / kTrials;
    }
  }
  for (size_t p = 0; p < probes.size(); ++p) {
    const double observed = SampleWorstSigma(samples[p]);
    const double expected = std::sqrt(predicted[p]);
    const double ratio = observed / expected;
    std::printf("cam%d (%.0f, %.0f) at %s: observed %.4f px, predicted %.4f "
                "px, ratio %.3f\n",
                probes[p].camera, probes[p].pixel.x(), probes[p].pixel.y(),
                DistanceName(probes[p].distance).c_str(), observed, expected,
                ratio);
    EXPECT_GT(ratio, 0.8) << p;
    EXPECT_LT(ratio, 1.25) << p;
  }
}

}  // namespace
}  // namespace rcm::calib::projection_uncertainty_test
