// Descriptor matching restricted to the refractive epipolar band
// (locus_band.h): a left keypoint is compared only with the right
// keypoints whose rays can meet its ray for some n of the interval, in
// front of both cameras. The geometry removes most false candidates before
// any descriptor is compared, so the ratio test decides among a handful of
// candidates instead of the whole image, and the cost is
// O(keypoints x candidates) rather than O(keypoints^2).
//
// A left keypoint l with band candidates at descriptor distances
// d1 <= d2 <= ... is matched to the nearest, r1, when
//
//   d1 < ratio * d2             (Lowe's ratio test; passes with one candidate)
//   d1 <= max_hamming_distance  (binary descriptors only)
//   l is r1's nearest among the left keypoints whose band holds r1
//                               (cross-check, optional)
//
// Candidates come from right keypoints sorted by the mean of their two
// plane angles: a pair in the band has |c_l - c_r| <= h_l + h_r + tol
// (c the mean, h the half-difference of phi at the two ends of the
// interval), so each left keypoint scans a window of that sorted list.
// The window is narrow for the interval of a current estimate and widens
// toward the image borders for a wide prior interval, where the planes of
// refraction turn fastest with n.
#ifndef RCM_FRONTEND_GUIDED_MATCHER_H_
#define RCM_FRONTEND_GUIDED_MATCHER_H_

#include <vector>

#include "rcm/frontend/feature_detector.h"
#include "rcm/frontend/locus_band.h"
#include "rcm/util/status.h"

namespace rcm {

struct GuidedMatchOptions {
  // Lowe's ratio test among the band's candidates; in (0, 1]. 0.8 is
  // Lowe's value.
  double ratio = 0.8;
  // Keep only mutual best matches.
  bool cross_check = true;
  // Binary descriptors farther apart than this many bits (of 256 for ORB)
  // are not matched, whatever the ratio; in [0, 256]. 64 keeps ORB's true
  // matches of a stereo pair (typically < 40 bits apart).
  int max_hamming_distance = 64;
  // Threads; >= 1.
  int num_threads = 2;

  Status Check() const;
};

struct KeypointMatch {
  int left = 0;   // index into the left features
  int right = 0;  // index into the right features
  float distance = 0.0f;  // descriptor distance (bits, or L2)
};

// Matches in left keypoint order. `left_keys` / `right_keys` are the
// band's keys of the features' keypoints (LocusBand::LeftKeys / RightKeys);
// the two Features use one descriptor type. `options` must pass Check().
std::vector<KeypointMatch> MatchInLocusBand(
    const Features& left, const std::vector<LocusKey>& left_keys,
    const Features& right, const std::vector<LocusKey>& right_keys,
    const LocusBand& band, const GuidedMatchOptions& options);

}  // namespace rcm

#endif  // RCM_FRONTEND_GUIDED_MATCHER_H_
