// A stereo correspondence: the same scene point seen in the left and right
// image of one frame.
#ifndef RCM_GEOMETRY_STEREO_CORRESPONDENCE_H_
#define RCM_GEOMETRY_STEREO_CORRESPONDENCE_H_

#include <Eigen/Core>
#include <cstdint>
#include <optional>

namespace rcm {

// In raw (lens-distorted) pixels, as matched in the images.
struct StereoCorrespondence {
  int64_t frame = 0;                // frame index; 0 when the source has one
  std::optional<double> timestamp;  // seconds, when the source has one
  Eigen::Vector2d left_pixel = Eigen::Vector2d::Zero();
  Eigen::Vector2d right_pixel = Eigen::Vector2d::Zero();
};

// In lens-undistorted normalized coordinates (z = 1 plane) of each camera:
// the (x_bar, y_bar) of the paper, each divided by its own camera's focal.
struct NormalizedCorrespondence {
  Eigen::Vector2d left = Eigen::Vector2d::Zero();
  Eigen::Vector2d right = Eigen::Vector2d::Zero();
};

}  // namespace rcm

#endif  // RCM_GEOMETRY_STEREO_CORRESPONDENCE_H_
