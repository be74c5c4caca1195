// StereoTracker: landmarks tracked over the keyframes of a stereo sequence
// (geometry/stereo_tracks.h), for the sequence bundle adjustment
// (estimation/sequence_bundle_adjustment.h).
//
// Each keyframe brings its stereo matches (StereoFrontEnd::Match: left and
// right within the refractive epipolar band) and the left image's features.
// Each match's left keypoint is linked to a match of the previous keyframe
// by its descriptor:
//
//   1. candidates   the previous keyframe's matched left keypoints within
//                   max_motion_px of it (the rig moves little between
//                   keyframes)
//   2. ratio        the nearest descriptor, when it is nearer than `ratio`
//                   times the second nearest (Lowe)
//   3. unique       a previous keypoint claimed twice goes to the nearer
//   4. subpixel     the link's left pixel is refined by aligning the
//                   previous keyframe's patch at the landmark's pixel
//                   (subpixel_refinement.h), then its right pixel against
//                   the refined left one: every observation of a landmark
//                   is the same point of the scene, not the detector's
//                   keypoint of each image (ORB's keypoints of pyramid
//                   level L sit 0.5 (1.2^L - 1) px up and left of the
//                   point they describe: OpenCV scales the level's
//                   coordinates without its half-pixel shift, which biased
//                   n by 4 sigma on a rendered dive). A link whose patch
//                   does not align is dropped.
//   5. rigid        the links agree with one motion of the left camera:
//                   an essential matrix of their bearings in the water at
//                   n (OpenCV's RANSAC, epipolar_threshold_px at the left
//                   focal length); the others are dropped. The water's
//                   camera is central (refractive_model.h), so its bearings
//                   obey the pinhole's epipolar geometry exactly at the
//                   true n and within a fraction of a pixel near it.
//
// A linked match continues its landmark (at its refined pixels); any other
// starts a new one. Every match adds two observations (left and right) of
// its landmark.
#ifndef RCM_FRONTEND_STEREO_TRACKER_H_
#define RCM_FRONTEND_STEREO_TRACKER_H_

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <optional>
#include <vector>

#include "rcm/camera/refractive_camera.h"
#include "rcm/frontend/feature_detector.h"
#include "rcm/frontend/stereo_front_end.h"
#include "rcm/frontend/subpixel_refinement.h"
#include "rcm/geometry/stereo_tracks.h"
#include "rcm/stereo/stereo_rig.h"
#include "rcm/util/status.h"

namespace rcm {

struct StereoTrackerOptions {
  // How far a keypoint may move between consecutive keyframes, pixels.
  double max_motion_px = 120.0;
  // Lowe's ratio of the nearest to the second nearest descriptor distance.
  double ratio = 0.8;
  // The rigid check's RANSAC threshold, pixels at the left focal length.
  double epipolar_threshold_px = 2.0;
  // The index the bearings of the rigid check are taken at (the front
  // end's guide, or water's 1.333: near is enough).
  double n = 1.333;
  // The alignment of step 4 (the front end's).
  SubpixelOptions subpixel;

  // Errors name the field: "tracker ratio = 1.5 must be in (0, 1]".
  Status Check() const;
};

class StereoTracker {
 public:
  // Errors: options.Check().
  static StatusOr<StereoTracker> Create(const StereoRig& rig,
                                        const StereoTrackerOptions& options);

  // Adds the next keyframe: its detected pair (StereoDetector::Detect)
  // and its stereo matches (StereoFrontEnd::Match of that pair, whose
  // left_keypoints_of_matches index its left features). Returns how many
  // of its matches continue a landmark of the previous keyframe. Errors:
  // matches without their keypoint indices, an index out of range, images
  // of another size than the previous keyframe's.
  StatusOr<int> AddKeyframe(const DetectedStereoPair& detected,
                            const StereoMatches& matches);

  const StereoTracks& tracks() const { return tracks_; }
  int num_keyframes() const { return tracks_.num_frames; }

 private:
  StereoTracker(const StereoRig& rig, const StereoTrackerOptions& options,
                RefractiveCamera left)
      : rig_(rig), options_(options), left_(std::move(left)) {}

  StereoRig rig_;
  StereoTrackerOptions options_;
  RefractiveCamera left_;
  StereoTracks tracks_;
  // The previous keyframe: its left image, its matches' left descriptors
  // (rows), left pixels (refined where linked) and landmarks.
  cv::Mat previous_left_;
  cv::Mat previous_descriptors_;
  int previous_norm_ = cv::NORM_HAMMING;
  std::vector<Eigen::Vector2d> previous_pixels_;
  std::vector<int> previous_landmarks_;
};

}  // namespace rcm

#endif  // RCM_FRONTEND_STEREO_TRACKER_H_
