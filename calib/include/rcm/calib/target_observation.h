// What a board detector saw: the target corners found in one image, and
// the stereo views a calibration is made from.
#ifndef RCM_CALIB_TARGET_OBSERVATION_H_
#define RCM_CALIB_TARGET_OBSERVATION_H_

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

namespace rcm::calib {

// Corners of a target seen in one image. point_ids[k] indexes
// TargetPoints(target) (calibration_target.h) and pixels[k] is where that
// corner was found, in pixels with pixel centers at integers (OpenCV's
// convention). Ids are distinct; the order is the detector's.
struct TargetObservation {
  std::vector<int> point_ids;
  std::vector<Eigen::Vector2d> pixels;
  // The detector that found the corners, e.g. "chessboard-sb".
  std::string detector;

  int size() const { return static_cast<int>(point_ids.size()); }
};

// One stereo pair of calibration images: the board as seen by cam0 (left)
// and cam1 (right), each nullopt when that image does not show it.
struct StereoView {
  std::string left_name;
  std::string right_name;
  double timestamp = 0.0;
  std::optional<TargetObservation> left;
  std::optional<TargetObservation> right;
  // Why a camera's target is missing or was dropped (e.g. "board found in
  // the left image only"); empty when both were found and kept.
  std::string note;

  bool stereo() const { return left.has_value() && right.has_value(); }
};

}  // namespace rcm::calib

#endif  // RCM_CALIB_TARGET_OBSERVATION_H_
