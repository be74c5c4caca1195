// Finding a calibration target's corners in an image (OpenCV), with point
// ids as TargetPoints (calibration_target.h) numbers them.
//
// - checkerboard: cv::findChessboardCornersSB with patternSize (cols,
//   rows), flags EXHAUSTIVE | ACCURACY, then ACCURACY alone, then
//   NORMALIZE_IMAGE | EXHAUSTIVE | ACCURACY until one finds it, each
//   corner then refined by cv::cornerSubPix on its own X-junction (half
//   window half its shortest edge to a neighbouring corner, clamped to
//   [2, 10] px, on the image smoothed by a 1 px Gaussian; SB alone puts
//   the corners of the pattern's border up to ~0.1 px outward, towards the
//   white margin): detector "chessboard-sb". Should it fail and chessboard_fallback is set, the
//   classic cv::findChessboardCorners (adaptive threshold, normalized
//   image) refined by cv::cornerSubPix: "chessboard-classic". The corners
//   are row-major over (cols, rows), but which physical corner is first is
//   ambiguous (a board looks the same turned by 180 degrees, and by 90 when
//   cols == rows): DetectTarget returns the CANONICAL order, the one among
//   those rotations of the grid whose corner 0 has the smallest x + y
//   (nearest the image's top-left).
// - aprilgrid: ArUco markers of DICT_APRILTAG_36h11 with a 2-bit border
//   (Kalibr's tags), corners refined by cv::cornerSubPix on the X-junctions
//   that Kalibr's corner squares make; tags with id >= cols * rows are
//   ignored; corner k of OpenCV's order (clockwise from the top-left of
//   OpenCV's marker image, which is the Kalibr tag turned by 180 degrees)
//   is Kalibr's corner k ^ 1, point 4 id + (k ^ 1). Detector "aprilgrid".
// - charuco: cv::aruco::detectMarkers, then
//   cv::aruco::interpolateCornersCharuco (local homographies, sub-pixel
//   refinement); the corner ids are the point ids. Detector "charuco".
//
// Pixels have their centers at integers (OpenCV's convention).
//
// Stereo pairs (DetectTargetPair): both images are searched in parallel.
// For a checkerboard the left image's corners are put in the canonical
// order, and the right image gets the ordering of its grid (any rotation,
// or a mirror image should the detector have returned one) whose layout
// about its centroid, scaled to unit RMS radius, best matches the left's:
// the two cameras of a rig look the same way. The pair's right observation
// is dropped (with a note) when the best candidate's mean squared mismatch
// is not below chessboard_pair_max_ratio times the runner-up's, or above
// chessboard_pair_max_mismatch: a missing view is better than a wrong
// pairing. The chessboard detector is never mixed within a pair: when SB
// misses either image and the fallback is on, the classic detector runs on
// both, and its results replace SB's only if it finds the board in more
// images than SB did.
//
// Nothing here throws: OpenCV's exceptions become "not found".
#ifndef RCM_CALIB_TARGET_DETECTOR_H_
#define RCM_CALIB_TARGET_DETECTOR_H_

#include <opencv2/core.hpp>
#include <optional>

#include "rcm/calib/calibration_target.h"
#include "rcm/calib/target_observation.h"
#include "rcm/util/status.h"

namespace rcm::calib {

struct TargetDetectorOptions {
  // Checkerboard: classic findChessboardCorners + cornerSubPix when SB
  // fails (on both images of a pair, never mixing detectors in a pair).
  // Off by default: on an image without a complete board the classic
  // detector searches for over a second (1.4 s on a 480x360 pair), and a
  // recording has many such frames; SB alone found the board in every
  // image of OpenCV's sample pairs and of the tests' renders.
  bool chessboard_fallback = false;
  // Fewest ChArUco corners (>= 4, the fewest a homography needs) and
  // aprilgrid tags (>= 1) that make a detection.
  int min_charuco_corners = 6;
  int min_aprilgrid_tags = 2;
  // Stereo checkerboard ordering: the best candidate's mismatch must be
  // below this fraction (in (0, 1)) of the runner-up's...
  double chessboard_pair_max_ratio = 0.2;
  // ...and below this mean squared distance (> 0) between the two layouts,
  // each centred and scaled to unit RMS radius (a true pair is ~0.001-0.05,
  // a 180-degree turn ~4).
  double chessboard_pair_max_mismatch = 0.5;
  // Threads DetectTargetPair uses: 2 searches both images at once, 1 one
  // after the other.
  int num_threads = 2;

  Status Check() const;
};

// The target's corners in `image` (8-bit gray, BGR or BGRA), nullopt when
// the target is not found (or the image is empty, tiny or of another
// type). CHECKs options.Check() and that `target` is valid.
std::optional<TargetObservation> DetectTarget(
    const cv::Mat& image, const CalibrationTarget& target,
    const TargetDetectorOptions& options = {});

// When view->note is empty, sets it to which of the pair's images lacks the
// target: "board found in neither image", "... in the left image only",
// "... in the right image only" (nothing when both have it).
void NoteMissingTargets(StereoView* view);

// Both images of a stereo pair (left = cam0), with consistent point ids;
// `note` says why a view is missing or was dropped. The names and
// timestamp are left empty for the caller.
StereoView DetectTargetPair(const cv::Mat& left, const cv::Mat& right,
                            const CalibrationTarget& target,
                            const TargetDetectorOptions& options = {});

}  // namespace rcm::calib

#endif  // RCM_CALIB_TARGET_DETECTOR_H_
