// Where the right match of a left keypoint can lie when n is known only to
// an interval: the band the refractive epipolar loci (locus.h) sweep for n
// in [n_min, n_max]. Guided matching (guided_matcher.h) compares a left
// keypoint's descriptor only with right keypoints in its band.
//
// Geometry. Take the rectified frame of the rig (stereo_rectification.h):
// origin at the left camera, x along the baseline to the right camera at
// (b, 0, 0). A keypoint's ray in the medium (refractive_model.h, eqs. 1-5),
// rotated into that frame, q = camera_from_rect^T (xb, yb, m(n, rb)), lies
// in the epipolar plane through the baseline at the angle
//
//   phi(n) = atan2(q_y, q_z)
//
// and points along that plane at u(n) = q_x / hypot(q_y, q_z), the
// cotangent of its angle from the baseline. Two rays meet at a point in
// front of both cameras, at distance rho from the baseline, iff
//
//   phi_l(n) = phi_r(n)   and   u_l(n) - u_r(n) = b / rho > 0.
//
// The first is the coplanarity of the two rays (the locus of the paper,
// Sec. III-C, for any calibrated rig, rectified or not); the second puts
// the point in front, no nearer than min_distance. With n in an interval,
// a pair is in the band when phi_l - phi_r changes sign between n_min and
// n_max or is within the tolerance at either end, and the disparity
// condition holds at one end or the other. (The difference is monotone in
// n on a rectified rig. Off rectified, where n barely moves the locus, it
// can return to zero inside the interval with one sign at both ends: the
// test then misses exact pairs by up to 0.3 px over [1, 1.6] and 0.005 px
// over n +- 0.05 on a rig 0.5 degrees off (locus_band_test.cc), well
// within the tolerance.)
//
// Tolerance: a pixel moves a ray by at most 1 / f radians in air (exactly
// 1 / f across an equidistant lens, less in the medium, where refraction
// narrows angles), so tolerance_px / f_min bounds the angle it subtends;
// along the plane du = (1 + u^2) dangle.
#ifndef RCM_FRONTEND_LOCUS_BAND_H_
#define RCM_FRONTEND_LOCUS_BAND_H_

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <opencv2/core.hpp>
#include <vector>

#include "rcm/stereo/stereo_rectification.h"
#include "rcm/stereo/stereo_rig.h"
#include "rcm/util/status.h"

namespace rcm {

// n somewhere in [min, max], within [1, 2].
struct RefractiveIndexInterval {
  double min = 1.0;
  double max = 1.6;

  // Errors: non-finite ends, min > max, an end outside [1, 2].
  Status Check() const;
  bool Contains(double n) const { return n >= min && n <= max; }
  double Width() const { return max - min; }

  // n +- max(sigmas * sigma_n, min_half_width), clipped to [1, 2].
  static RefractiveIndexInterval Around(double n, double sigma_n, double sigmas,
                                        double min_half_width);
};

// A keypoint's ray at both ends of the interval; `valid` is false when the
// lens cannot undistort the pixel.
struct LocusKey {
  double phi[2] = {0.0, 0.0};  // at n_min, n_max
  double u[2] = {0.0, 0.0};
  bool valid = false;
};

struct LocusBandOptions {
  // Half width of the band in pixels, on top of the interval's own width:
  // the keypoints' localization error; > 0. 2 px covers the corners of
  // 720 x 540 FAST keypoints and SIFT at its finer scales.
  double tolerance_px = 2.0;
  // Nearest point of the scene, meters from the baseline; > 0. Bounds the
  // disparity (b / rho): 0.2 m keeps the search to 0.55 for the 0.11 m
  // dataset rig.
  double min_distance = 0.2;

  Status Check() const;
};

class LocusBand {
 public:
  // Errors: options.Check(), interval.Check().
  static StatusOr<LocusBand> Create(const StereoRig& rig,
                                    const RefractiveIndexInterval& interval,
                                    const LocusBandOptions& options);

  // Keys of raw pixels of the left / right camera.
  std::vector<LocusKey> LeftKeys(
      const std::vector<cv::KeyPoint>& keypoints) const;
  std::vector<LocusKey> RightKeys(
      const std::vector<cv::KeyPoint>& keypoints) const;
  LocusKey LeftKey(const Eigen::Vector2d& pixel) const;
  LocusKey RightKey(const Eigen::Vector2d& pixel) const;

  // The band test of the header comment (inline: the matcher's inner loop).
  bool Contains(const LocusKey& left, const LocusKey& right) const {
    if (!left.valid || !right.valid) return false;
    const double d0 = left.phi[0] - right.phi[0];
    const double d1 = left.phi[1] - right.phi[1];
    const bool coplanar =
        (d0 <= 0.0) != (d1 <= 0.0) ||
        std::min(std::abs(d0), std::abs(d1)) <= angle_tolerance_;
    if (!coplanar) return false;
    const double u_tolerance = angle_tolerance_ * (1.0 + left.u[0] * left.u[0]);
    const double v0 = left.u[0] - right.u[0];
    const double v1 = left.u[1] - right.u[1];
    return std::max(v0, v1) >= -u_tolerance &&
           std::min(v0, v1) <= max_disparity_ + u_tolerance;
  }

  // The angular tolerance, radians (tolerance_px / f_min).
  double angle_tolerance() const { return angle_tolerance_; }
  const RefractiveIndexInterval& interval() const { return interval_; }

 private:
  LocusBand(const StereoRig& rig, const StereoRectification& rectification,
            const RefractiveIndexInterval& interval, double angle_tolerance,
            double max_disparity)
      : rig_(rig),
        rectification_(rectification),
        interval_(interval),
        angle_tolerance_(angle_tolerance),
        max_disparity_(max_disparity) {}
  LocusKey Key(const Camera& camera, const Eigen::Matrix3d& camera_from_rect,
               const Eigen::Vector2d& pixel) const;

  StereoRig rig_;
  StereoRectification rectification_;
  RefractiveIndexInterval interval_;
  double angle_tolerance_;
  double max_disparity_;  // b / min_distance
};

}  // namespace rcm

#endif  // RCM_FRONTEND_LOCUS_BAND_H_
