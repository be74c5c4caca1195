// cv::calibrateCamera on the corners of one camera's views, for the tests
// that hold rcm's one-camera calibration (mono_calibration.h) to OpenCV's:
// the radtan model with k3 fixed to 0 (rcm's four coefficients), run to
// convergence (200 iterations, relative change 1e-12).
#ifndef RCM_TESTS_CALIB_OPENCV_CALIBRATE_CAMERA_H_
#define RCM_TESTS_CALIB_OPENCV_CALIBRATE_CAMERA_H_

#include <array>
#include <opencv2/calib3d.hpp>
#include <vector>

#include "rcm/calib/calibration_target.h"
#include "rcm/calib/target_observation.h"

namespace rcm::calib::test {

struct OpenCvCamera {
  double rms_px = 0.0;  // cv::calibrateCamera's: sqrt(mean |e|^2)
  double fx = 0.0, fy = 0.0, cx = 0.0, cy = 0.0;
  std::array<double, 4> distortion{};  // k1, k2, p1, p2
};

// Over the left observations of `views` (views without one are skipped).
inline OpenCvCamera OpenCvCalibrateCamera(const CalibrationTarget& target,
                                          const std::vector<StereoView>& views,
                                          int width, int height) {
  const std::vector<Eigen::Vector3d> points = TargetPoints(target);
  std::vector<std::vector<cv::Point3f>> object;
  std::vector<std::vector<cv::Point2f>> image;
  for (const StereoView& view : views) {
    if (!view.left) continue;
    object.emplace_back();
    image.emplace_back();
    for (int k = 0; k < view.left->size(); ++k) {
      const Eigen::Vector3d& x = points[view.left->point_ids[k]];
      object.back().emplace_back(x.x(), x.y(), x.z());
      image.back().emplace_back(view.left->pixels[k].x(),
                                view.left->pixels[k].y());
    }
  }
  cv::Mat k;
  cv::Mat d;
  std::vector<cv::Mat> rvecs;
  std::vector<cv::Mat> tvecs;
  OpenCvCamera camera;
  camera.rms_px = cv::calibrateCamera(
      object, image, cv::Size(width, height), k, d, rvecs, tvecs,
      cv::CALIB_FIX_K3,
      cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 200,
                       1e-12));
  camera.fx = k.at<double>(0, 0);
  camera.fy = k.at<double>(1, 1);
  camera.cx = k.at<double>(0, 2);
  camera.cy = k.at<double>(1, 2);
  for (int i = 0; i < 4; ++i) camera.distortion[i] = d.at<double>(i);
  return camera;
}

}  // namespace rcm::calib::test

#endif  // RCM_TESTS_CALIB_OPENCV_CALIBRATE_CAMERA_H_
