// The per-pair stereo front end: from a raw stereo pair to the raw-pixel
// correspondences the estimators (rcm/estimation) take.
//
//   1. preprocess   gray, optional CLAHE            (image_preprocessing.h)
//   2. detect       keypoints + descriptors          (feature_detector.h)
//   3. match        descriptors within the refractive
//                   epipolar band of an n interval   (guided_matcher.h)
//   4. refine       right pixels to subpixel         (subpixel_refinement.h)
//                   (at most max_refined_matches of them)
//   5. verify       refined pairs still in the band  (locus_band.h)
//
// Stages 1-2 (and the band keys) run on the two images at once. Stages 1-2
// depend on the images and the options alone, not on the rig or n:
// StereoDetector runs them apart (a sequence detects the next pair while
// this one is matched and estimated, sequence_estimator.h), and Match takes
// their result. The band
// is the prior search range until an estimate exists; a caller that has
// one (n, sigma_n) passes RefractiveIndexInterval::Around(...) as the
// guide, which narrows the band to the locus of the current estimate plus
// the pixel tolerance. Most of the gain is fewer false candidates: between
// water and air the locus moves by ~1 px (median) over most of the image,
// inside the 2 px tolerance, so when the robot surfaces a guided frame
// still keeps most of its true matches and the estimators see the change.
// A guided frame that keeps fewer than reacquire_fraction of the matches
// the prior band last gave (a narrower tolerance, or a larger change of n)
// is matched again with the prior band, and the result says so
// (StereoMatches::reacquired).
#ifndef RCM_FRONTEND_STEREO_FRONT_END_H_
#define RCM_FRONTEND_STEREO_FRONT_END_H_

#include <cstdint>
#include <optional>
#include <vector>

#include "rcm/frontend/feature_detector.h"
#include "rcm/frontend/guided_matcher.h"
#include "rcm/frontend/image_preprocessing.h"
#include "rcm/frontend/locus_band.h"
#include "rcm/frontend/subpixel_refinement.h"
#include "rcm/geometry/stereo_correspondence.h"
#include "rcm/stereo/stereo_rig.h"
#include "rcm/util/status.h"

namespace rcm {

// The systematic error floor of this front end's matches, for the
// estimators' RefinementOptions::systematic_px (calibration_propagation.h):
// on rendered dives of the dataset rig and of a narrow-field rig, n and
// cam1's rotation fitted freely with the true rig read rotations up to
// 0.005 degrees off the truth (0.04 px at f = 500 px) where their noise
// sigma was 0.001 degree (lighting that differs between the two views,
// sub-pixel interpolation); 0.03 px per coefficient of the systematic
// field covers that.
inline constexpr double kFrontEndSystematicPx = 0.03;

// The guide of a sequence's next pair (Match's `guide`): the last pair's
// own estimate of n, widened to 6 sigma and at least +-0.01 (a few frames'
// drift of a real medium). `rcm estimate` on images and the live pipeline
// both guide with it.
RefractiveIndexInterval NextPairGuide(double n, double sigma_n);

struct StereoFrontEndOptions {
  ClaheOptions clahe;
  FeatureOptions features;
  LocusBandOptions band;
  GuidedMatchOptions matching;
  SubpixelOptions subpixel;
  // Where n may be before anything is known: air (1) to well past any
  // water (seawater 1.34, a port's glass would be 1.5).
  RefractiveIndexInterval search_range{1.0, 1.6};
  // A guided frame with fewer than this fraction of the matches of the last
  // frame matched with search_range is matched again with it; in [0, 1]
  // (0 never re-acquires).
  double reacquire_fraction = 0.5;
  // Descriptor matches refined (stages 4-5) and returned at most: every
  // k-th in the order they were matched, as SpreadSubset
  // (sequence_estimator.h) takes them; >= 0, 0 refines all. Refinement is
  // most of a pair's front end (~26 us per match of 720x540 on one core),
  // so a caller that uses only so many matches of a pair (the live
  // pipeline's window, SequenceEstimatorOptions::window_matches) refines
  // only those.
  int max_refined_matches = 0;
  // Threads; >= 1. 2 runs the two images' stages 1-2 at once.
  int num_threads = 2;

  Status Check() const;
};

// Milliseconds spent in each stage (wall clock).
struct FrontEndTimings {
  double preprocess_ms = 0.0;
  double detect_ms = 0.0;  // detection + descriptors + band keys
  double match_ms = 0.0;
  double refine_ms = 0.0;  // subpixel + verification
  double total_ms = 0.0;
};

struct StereoMatches {
  std::vector<StereoCorrespondence> matches;  // raw pixels
  // Per match, the index of its left keypoint in the detected pair's
  // features[0] (whose pixel is the match's left pixel): what a tracker
  // links across pairs by its descriptor (stereo_tracker.h).
  std::vector<int> left_keypoints_of_matches;
  int left_keypoints = 0;
  int right_keypoints = 0;
  int descriptor_matches = 0;    // after stage 3
  RefractiveIndexInterval band;  // the interval the matches were found in
  bool reacquired = false;       // a guided frame matched again (above)
  FrontEndTimings timings;
};

// Stages 1-2 of one stereo pair: each image preprocessed (gray, CLAHE) and
// its features.
struct DetectedStereoPair {
  cv::Mat gray[2];  // left, right
  Features features[2];
  double preprocess_ms = 0.0;  // wall clock, the slower image's
  double detect_ms = 0.0;
};

// Stages 1-2 of the front end, with their own detectors: one Detect at a
// time per object (OpenCV's detectors keep state), on any thread.
class StereoDetector {
 public:
  // Errors: options.Check().
  static StatusOr<StereoDetector> Create(const StereoFrontEndOptions& options);

  // The two images checked (CheckStereoImages), preprocessed and detected,
  // on up to `num_threads` threads (2: the two images at once); the
  // features do not depend on the threads.
  StatusOr<DetectedStereoPair> Detect(const cv::Mat& left, const cv::Mat& right,
                                      int num_threads);

 private:
  StereoDetector(const ClaheOptions& clahe, FeatureDetector left,
                 FeatureDetector right)
      : clahe_(clahe), left_(std::move(left)), right_(std::move(right)) {}

  ClaheOptions clahe_;
  FeatureDetector left_;
  FeatureDetector right_;
};

class StereoFrontEnd {
 public:
  // Errors: options.Check().
  static StatusOr<StereoFrontEnd> Create(const StereoRig& rig,
                                         const StereoFrontEndOptions& options);

  // Matches of one stereo pair, each with `frame` and `timestamp`. `guide`:
  // the interval of the current estimate of n, or nullopt for the prior
  // search range. Errors: CheckStereoImages, images whose size differs
  // from the rig's calibration, guide->Check().
  StatusOr<StereoMatches> Match(
      const cv::Mat& left, const cv::Mat& right, int64_t frame = 0,
      std::optional<double> timestamp = std::nullopt,
      const std::optional<RefractiveIndexInterval>& guide = std::nullopt);

  // Stages 3-5 of a pair detected by a StereoDetector with these options
  // (Match above is Detect, then this): the same matches. Errors: images
  // whose size differs from the rig's calibration, guide->Check().
  StatusOr<StereoMatches> Match(
      const DetectedStereoPair& detected, int64_t frame = 0,
      std::optional<double> timestamp = std::nullopt,
      const std::optional<RefractiveIndexInterval>& guide = std::nullopt);

  const StereoFrontEndOptions& options() const { return options_; }

 private:
  StereoFrontEnd(const StereoRig& rig, const StereoFrontEndOptions& options,
                 StereoDetector detector)
      : rig_(rig), options_(options), detector_(std::move(detector)) {}

  StereoRig rig_;
  StereoFrontEndOptions options_;
  StereoDetector detector_;
  // Matches of the last frame matched with the prior search range.
  int prior_band_matches_ = -1;
};

}  // namespace rcm

#endif  // RCM_FRONTEND_STEREO_FRONT_END_H_
