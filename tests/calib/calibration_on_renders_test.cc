// End to end on rendered images: targets drawn, rendered through a known
// rig (lens, extrinsics), detected, and calibrated. The issue's
// acceptance: focal lengths within 0.1 %, principal points within 0.5 px,
// baseline within 0.1 %. And the dome's (issue 33): boards rendered
// exactly through decentered domes under water, detected, and the
// decentering calibrated with the air lenses held, within 0.2 mm.
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include "calib/rendered_dome_dive.h"
#include "calib/synthetic_target_views.h"
#include "rcm/calib/dome_calibration.h"
#include "rcm/calib/stereo_calibration.h"
#include "rcm/calib/target_detector.h"
#include "rcm/calib/target_image.h"
#include "rcm/calib/target_renderer.h"
#include "support/projection_error.h"
#include "support/test_rigs.h"

namespace rcm::calib::calibration_on_renders_test {
namespace {

constexpr double kMaxFocalError = 1e-3;  // relative
constexpr double kMaxPrincipalPointErrorPx = 0.5;
constexpr double kMaxBaselineError = 1e-3;  // relative

// Renders `num_poses` views of `target` through `rig` (2 gray levels of
// noise, a 0.5 px blur: a sharp, well-exposed calibration image), detects
// the target, and calibrates with `model`.
StereoCalibration CalibrateOnRenders(const StereoRig& rig,
                                     const CalibrationTarget& target,
                                     LensModelId model, int num_poses,
                                     unsigned seed) {
  const TargetImage texture = DrawTargetImage(target, 4000.0);
  const TargetRenderer left =
      TargetRenderer::Create(rig.left(), texture).value();
  const TargetRenderer right =
      TargetRenderer::Create(rig.right(), texture).value();
  TargetRenderOptions render;
  render.noise_sigma = 2.0;
  render.blur_sigma_px = 0.5;
  const std::vector<Rigid3d> poses =
      test::BoardPoses(rig.left(), target, num_poses, seed, 0.5, 0.9, 30.0);
  std::vector<StereoView> views;
  int stereo = 0;
  for (size_t v = 0; v < poses.size(); ++v) {
    render.seed = 2 * v;
    const cv::Mat left_image = left.Render(poses[v], render);
    render.seed = 2 * v + 1;
    const cv::Mat right_image =
        right.Render(rig.right_from_left() * poses[v], render);
    views.push_back(DetectTargetPair(left_image, right_image, target));
    stereo += views.back().stereo() ? 1 : 0;
  }
  EXPECT_GE(stereo, num_poses / 2);
  StereoCalibrationOptions options;
  options.model = model;
  const Camera& l = rig.left();
  const Camera& r = rig.right();
  StereoCalibration calibration =
      CalibrateStereo(target, views, {l.width(), l.height()},
                      {r.width(), r.height()}, options)
          .value();
  return calibration;
}

void ExpectAccurate(const StereoCalibration& calibration,
                    const StereoRig& truth) {
  const Camera* estimates[2] = {&calibration.cam0.camera,
                                &calibration.cam1.camera};
  const Camera* truths[2] = {&truth.left(), &truth.right()};
  for (int c = 0; c < 2; ++c) {
    const Camera& e = *estimates[c];
    const Camera& t = *truths[c];
    std::printf("cam%d: fx %+.2e fy %+.2e (relative), cx %+.3f cy %+.3f px\n",
                c, e.fx() / t.fx() - 1.0, e.fy() / t.fy() - 1.0,
                e.cx() - t.cx(), e.cy() - t.cy());
    EXPECT_LT(std::abs(e.fx() / t.fx() - 1.0), kMaxFocalError) << "cam" << c;
    EXPECT_LT(std::abs(e.fy() / t.fy() - 1.0), kMaxFocalError) << "cam" << c;
    EXPECT_LT(std::abs(e.cx() - t.cx()), kMaxPrincipalPointErrorPx)
        << "cam" << c;
    EXPECT_LT(std::abs(e.cy() - t.cy()), kMaxPrincipalPointErrorPx)
        << "cam" << c;
  }
  const double baseline_error = calibration.baseline / truth.Baseline() - 1.0;
  std::printf("baseline %+.2e (relative), rms %.3f px, %d views, %d stereo\n",
              baseline_error, calibration.rms_px, calibration.num_views_used,
              calibration.num_stereo_views);
  EXPECT_LT(std::abs(baseline_error), kMaxBaselineError);
}

TEST(CalibrationOnRenders, ChessboardEquidistantDatasetRig) {
  const StereoRig rig = rcm::test::AlphasenseRealisticRig();
  const CalibrationTarget target = MakeCheckerboardTarget(9, 6, 0.04).value();
  ExpectAccurate(
      CalibrateOnRenders(rig, target, LensModelId::kEquidistant, 20, 3), rig);
}

// The EUCM (issue 21): a rig of two EUCM cameras, the dataset rig's
// extrinsics, calibrated from the basalt-style start (alpha = 0.5,
// beta = 1). Besides the acceptance, alpha and beta must come back
// within 0.01 of the truth (a few sigma of these renders, far below the
// distance of the start, 0.1), and the projection over the whole image,
// corners included where no board was seen, within 0.5 px.
//
// Not tested here, because it fails: the double sphere. Its image near
// the axis is f / (1 + xi) r, so f and xi trade against each other and
// only the off-axis shape separates them. On renders through
// test::DoubleSphereCamera (62 degrees at the corners) the calibration
// ended at xi = 0.49 and a focal 81 % high for the truth's xi = -0.18, at
// an RMS of 0.052 px; with f = 225 px (83 degrees at the corners) it ran
// to alpha = 1 (the bound) at an RMS of 1.8 px, and from a start at the
// equidistant lens of the same views, fitted by the double sphere, to
// xi = 0.49 and xi = 1 (the bound) at 0.116 px.
constexpr double kMaxUnifiedParameterError = 0.01;
constexpr double kMaxProjectionErrorPx = 0.5;

StereoRig UnifiedRig(LensModelId model) {
  const Camera left = model == LensModelId::kDoubleSphere
                          ? rcm::test::DoubleSphereCamera()
                          : rcm::test::EucmCamera();
  std::vector<double> distortion = left.Distortion();
  distortion[0] += 0.02;
  distortion[1] -= 0.03;
  const Camera right = Camera::Create(model, left.width(), left.height(),
                                      {left.fx() * 1.004, left.fy() * 1.003,
                                       left.cx() - 2.5, left.cy() + 1.5},
                                      distortion)
                           .value();
  return StereoRig::Create(
             left, right, rcm::test::AlphasenseRealisticRig().right_from_left())
      .value();
}

void ExpectUnifiedModelRecovered(LensModelId model) {
  const StereoRig rig = UnifiedRig(model);
  const CalibrationTarget target = MakeCheckerboardTarget(9, 6, 0.04).value();
  const StereoCalibration calibration =
      CalibrateOnRenders(rig, target, model, 20, 3);
  ExpectAccurate(calibration, rig);
  const CameraCalibration* estimates[2] = {&calibration.cam0,
                                           &calibration.cam1};
  const Camera* truths[2] = {&rig.left(), &rig.right()};
  for (int c = 0; c < 2; ++c) {
    const Camera& estimate = estimates[c]->camera;
    ASSERT_EQ(estimate.model(), model);
    const std::vector<double> e = estimate.Distortion();
    const std::vector<double> t = truths[c]->Distortion();
    const double projection_error =
        rcm::test::MaxProjectionErrorPx(estimate, *truths[c], 8.0);
    std::printf(
        "cam%d %s: [%.5f, %.5f] for [%.5f, %.5f] (sigma %.1e %.1e), "
        "projection within %.3f px\n",
        c, std::string(LensModelName(model)).c_str(), e[0], e[1], t[0], t[1],
        estimates[c]->sigma[4], estimates[c]->sigma[5], projection_error);
    for (int i = 0; i < 2; ++i) {
      EXPECT_NEAR(e[i], t[i], kMaxUnifiedParameterError)
          << "cam" << c << " coefficient " << i;
    }
    EXPECT_LT(projection_error, kMaxProjectionErrorPx) << "cam" << c;
  }
}

TEST(CalibrationOnRenders, ChessboardEucmRecoversTheTruth) {
  ExpectUnifiedModelRecovered(LensModelId::kEucm);
}

// Rendered dome dives (issue 33, calib/rendered_dome_dive.h): the 4-inch
// acrylic dome in water (n = 1.333, held at the truth), each camera
// decentered 1-3 mm laterally and 5-10 mm axially, a 9x6 chessboard of
// 40 mm squares at 0.4-1.4 m rendered through the dome with a 0.5 px blur
// and 2 gray levels of noise, detected, and calibrated with the true air
// lenses held, the board's bow estimated as on a real dive. Each component
// within 0.2 mm of the truth and within 3 of its reported sigmas
// (benchmarks/dome_monte_carlo.cc checks the sigmas over many dives).
constexpr double kMaxDomeDecenteringError = 2e-4;  // meters
constexpr double kMaxDomeDecenteringSigmas = 3.0;

// Renders `num_poses` views of the board through each camera's dome
// (cam0 = rig.left(); the right camera when `decentering` has two), detects
// them and calibrates the decentering; prints and checks it.
void ExpectDomeDiveRecovered(const StereoRig& rig,
                             const std::vector<Eigen::Vector3d>& decentering,
                             int num_poses, unsigned seed,
                             bool check_accuracy = true) {
  const int num_cameras = static_cast<int>(decentering.size());
  std::vector<DomePort> domes;
  for (const Eigen::Vector3d& c : decentering) {
    domes.push_back(rcm::test::AcrylicDome(c));
  }
  test::DomeDiveOptions dive_options;
  dive_options.num_poses = num_poses;
  dive_options.pose_seed = seed;
  const test::DomeDive dive = test::RenderDomeDive(rig, domes, dive_options);
  const StatusOr<DomeCalibration> result = test::CalibrateDomeDive(dive, rig);
  ASSERT_TRUE(result.ok()) << result.status().message();
  ASSERT_EQ(result->decentering.size(), decentering.size());
  std::printf(
      "%d camera(s), %d views used, %d corners detected, %d inliers, "
      "rms %.3f px, %s\n",
      num_cameras, result->num_views_used, dive.corners, result->num_inliers,
      result->rms_px, result->candidates[result->chosen].name.c_str());
  for (int c = 0; c < num_cameras; ++c) {
    const Eigen::Vector3d error = result->decentering[c] - decentering[c];
    const Eigen::Vector3d& sigma = result->decentering_sigma[c];
    std::printf(
        "cam%d decentering error (%+.3f, %+.3f, %+.3f) mm, sigma "
        "(%.3f, %.3f, %.3f) mm, rms %.3f px\n",
        c, 1e3 * error.x(), 1e3 * error.y(), 1e3 * error.z(), 1e3 * sigma.x(),
        1e3 * sigma.y(), 1e3 * sigma.z(), result->rms_px_per_camera[c]);
    if (!check_accuracy) continue;
    for (int i = 0; i < 3; ++i) {
      EXPECT_LT(std::abs(error[i]), kMaxDomeDecenteringError)
          << "cam" << c << " component " << i;
      EXPECT_LT(std::abs(error[i]), kMaxDomeDecenteringSigmas * sigma[i])
          << "cam" << c << " component " << i;
    }
  }
}

TEST(DomeCalibrationOnRenders, OneCameraDive) {
  ExpectDomeDiveRecovered(rcm::test::AlphasenseRealisticRig(),
                          {Eigen::Vector3d(0.002, -0.001, 0.007)}, 24, 5);
}

TEST(DomeCalibrationOnRenders, StereoDive) {
  ExpectDomeDiveRecovered(rcm::test::AlphasenseRealisticRig(),
                          {Eigen::Vector3d(0.002, -0.001, 0.007),
                           Eigen::Vector3d(-0.0015, 0.0025, 0.009)},
                          16, 7);
}

// The sanitizer pass's variant: the same chain on 4 views of one camera,
// run for its code (4 views say little of the decentering).
TEST(DomeCalibrationOnRenders, FourViewsRunEndToEnd) {
  ExpectDomeDiveRecovered(rcm::test::AlphasenseRealisticRig(),
                          {Eigen::Vector3d(0.001, 0.002, 0.005)}, 4, 9,
                          /*check_accuracy=*/false);
}

}  // namespace
}  // namespace rcm::calib::calibration_on_renders_test
