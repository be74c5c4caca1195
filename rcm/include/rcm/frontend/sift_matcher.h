// A minimal stereo front end: SIFT keypoints in the left and right image of
// a pair, matched by descriptor, giving the raw pixel correspondences from
// which the estimators (rcm/estimation) recover n. Images come straight
// from the cameras: no rectification, no epipolar constraint (refraction
// bends the epipolar lines by an amount that depends on n, the unknown);
// the robust stage of the estimators rejects the remaining outliers.
//
// A left keypoint l with nearest right descriptors r1, r2 (L2 distances
// d1 <= d2) is matched to r1 when
//
//   d1 < ratio * d2                       (Lowe's ratio test)
//   and l is r1's nearest left descriptor (mutual check, optional)
//
// The ratio test drops keypoints whose descriptor has a near twin in the
// other image (repeated texture), the mutual check many-to-one matches.
#ifndef RCM_FRONTEND_SIFT_MATCHER_H_
#define RCM_FRONTEND_SIFT_MATCHER_H_

#include <cstdint>
#include <opencv2/core.hpp>
#include <optional>
#include <vector>

#include "rcm/geometry/stereo_correspondence.h"
#include "rcm/util/status.h"

namespace rcm {

struct SiftMatcherOptions {
  // Keypoints kept per image, the strongest (by SIFT's contrast score)
  // first; > 0.
  int max_features = 2000;
  // Lowe's ratio test; in (0, 1], 1 keeps every nearest neighbour. 0.8 is
  // Lowe's value: it drops 90 % of false matches and 5 % of true ones.
  double ratio = 0.8;
  // Keep only mutual nearest neighbours.
  bool cross_check = true;
  // Threads; >= 1. With 2 or more the two images are processed at once.
  int num_threads = 2;

  Status Check() const;
};

// Matches of one stereo pair, in raw pixels (pixel centers at integers),
// each with `frame` and `timestamp`; a keypoint pair found twice (SIFT
// gives one keypoint per dominant orientation) is reported once. Images:
// 8-bit, 1 (gray), 3 (BGR) or 4 (BGRA) channels, equal sizes. Errors:
// options.Check(), an empty image, a size mismatch, a depth other than
// 8 bit or an unsupported channel count.
StatusOr<std::vector<StereoCorrespondence>> MatchStereoPair(
    const cv::Mat& left, const cv::Mat& right,
    const SiftMatcherOptions& options = SiftMatcherOptions(), int64_t frame = 0,
    std::optional<double> timestamp = std::nullopt);

}  // namespace rcm

#endif  // RCM_FRONTEND_SIFT_MATCHER_H_
