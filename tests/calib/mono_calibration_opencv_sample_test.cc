// The left images of the stereo chessboard sample that Debian's opencv-doc
// package ships (left01.jpg ... left14.jpg, 13 images, 640x480, 9x6 inner
// corners; scripts/setup.sh installs it): real images, calibrated as one
// camera by rcm and by cv::calibrateCamera on the same corners.
#include <gtest/gtest.h>

#include <cstdio>
#include <opencv2/imgcodecs.hpp>
#include <optional>
#include <string>
#include <vector>

#include "calib/opencv_calibrate_camera.h"
#include "rcm/calib/calibration_target.h"
#include "rcm/calib/mono_calibration.h"
#include "rcm/calib/target_detector.h"

namespace rcm::calib::mono_calibration_opencv_sample_test {
namespace {

constexpr char kDataDir[] = "/usr/share/doc/opencv-doc/examples/data/";
// The sample's numbering skips 10.
constexpr int kImageNumbers[] = {1, 2, 3, 4, 5, 6, 7, 8, 9, 11, 12, 13, 14};
constexpr int kWidth = 640;
constexpr int kHeight = 480;

CalibrationTarget SampleBoard() {
  // The square size of the printed board is not published; 25 mm scales
  // the translations only, never the RMS or the intrinsics.
  return MakeCheckerboardTarget(9, 6, 0.025).value();
}

TEST(MonoCalibrationOpenCvSample, LeftImagesEqualCalibrateCamera) {
  std::vector<std::optional<TargetObservation>> observations;
  for (const int number : kImageNumbers) {
    char name[32];
    std::snprintf(name, sizeof(name), "left%02d.jpg", number);
    const std::string path = std::string(kDataDir) + name;
    const cv::Mat image = cv::imread(path, cv::IMREAD_GRAYSCALE);
    ASSERT_FALSE(image.empty())
        << "cannot read " << path << ": install opencv-doc (scripts/setup.sh)";
    observations.push_back(DetectTarget(image, SampleBoard()));
    ASSERT_TRUE(observations.back().has_value()) << path;
  }
  const std::vector<StereoView> views = MonoViews(observations);

  // A flat board (OpenCV's model) and radtan (OpenCV's with k3 = 0).
  StereoCalibrationOptions options;
  options.model = LensModelId::kRadTan;
  options.estimate_board_warp = false;
  const StatusOr<StereoCalibration> rcm =
      CalibrateMono(SampleBoard(), views, {kWidth, kHeight}, options);
  ASSERT_TRUE(rcm.ok()) << rcm.status().message();
  const test::OpenCvCamera opencv =
      test::OpenCvCalibrateCamera(SampleBoard(), views, kWidth, kHeight);

  // The same corners (no outlier dropped), the same model and the same
  // cost: the same minimum. The bounds: 0.01 px in the RMS, 0.1 px
  // in each intrinsic; the solvers stop at tolerances far below (measured:
  // see the printout). The coefficients within 1e-4: at 0.1 px of the
  // intrinsics the coefficients move by ~1e-4 (k1 at the image corner,
  // r^2 ~ 0.6, is ~60 px per unit at f = 530 px), so this asks as much
  // of them.
  constexpr double kRmsTolerancePx = 0.01;
  constexpr double kIntrinsicsTolerancePx = 0.1;
  constexpr double kDistortionTolerance = 1e-4;
  EXPECT_EQ(rcm->num_outliers, 0);
  EXPECT_EQ(rcm->num_views_used, 13);
  const Camera& camera = rcm->cam0.camera;
  std::printf(
      "rcm:    rms %.6f px  fx %.4f fy %.4f cx %.4f cy %.4f  k1 %.6f k2 %.6f "
      "p1 %.6f p2 %.6f\n",
      rcm->rms_px, camera.fx(), camera.fy(), camera.cx(), camera.cy(),
      camera.Distortion()[0], camera.Distortion()[1], camera.Distortion()[2],
      camera.Distortion()[3]);
  std::printf(
      "OpenCV: rms %.6f px  fx %.4f fy %.4f cx %.4f cy %.4f  k1 %.6f k2 %.6f "
      "p1 %.6f p2 %.6f\n",
      opencv.rms_px, opencv.fx, opencv.fy, opencv.cx, opencv.cy,
      opencv.distortion[0], opencv.distortion[1], opencv.distortion[2],
      opencv.distortion[3]);
  EXPECT_NEAR(rcm->rms_px, opencv.rms_px, kRmsTolerancePx);
  EXPECT_NEAR(camera.fx(), opencv.fx, kIntrinsicsTolerancePx);
  EXPECT_NEAR(camera.fy(), opencv.fy, kIntrinsicsTolerancePx);
  EXPECT_NEAR(camera.cx(), opencv.cx, kIntrinsicsTolerancePx);
  EXPECT_NEAR(camera.cy(), opencv.cy, kIntrinsicsTolerancePx);
  for (int i = 0; i < 4; ++i) {
    EXPECT_NEAR(camera.Distortion()[i], opencv.distortion[i],
                kDistortionTolerance)
        << "coefficient " << i;
  }
  // And it says how well it knows them: sigma of each intrinsic positive
  // and below 2 px on 13 views.
  for (int i = 0; i < 4; ++i) {
    EXPECT_GT(rcm->cam0.sigma[i], 0.0);
    EXPECT_LT(rcm->cam0.sigma[i], 2.0);
  }
}

}  // namespace
}  // namespace rcm::calib::mono_calibration_opencv_sample_test
