// Calibration targets (boards) for air stereo calibration, read from
// Kalibr's target YAML files.
//
// Checkerboard (counts are INNER corners, i.e. an 8x8-square board is 7x7):
//
//   target_type: 'checkerboard'
//   targetCols: 6            # inner corners along a row (x)
//   targetRows: 7            # inner corners along a column (y)
//   rowSpacingMeters: 0.06   # square size along y [m]
//   colSpacingMeters: 0.06   # square size along x [m]
//
// Aprilgrid (tag family 36h11, as printed by kalibr_create_target_pdf):
//
//   target_type: 'aprilgrid'
//   tagCols: 6               # tags along x
//   tagRows: 6               # tags along y
//   tagSize: 0.088           # edge of one tag, black border included [m]
//   tagSpacing: 0.3          # gap between tags divided by tagSize
//
// Other keys are ignored. Integers must be written as integers ("6", not
// "6.0"); sizes are finite and positive; at most kMaxTargetCount corners
// (checkerboard) or tags (aprilgrid) along a side. Unsupported types
// (Kalibr's circlegrid, ChArUco) are rejected.
//
// Target frame and point order (TargetPoints), all points on z = 0:
//
// - checkerboard: row-major over the inner corners; corner (row r, col c)
//   is point r * cols + c at (c * col_spacing, r * row_spacing, 0), so the
//   first inner corner is the origin, x runs along the columns and y along
//   the rows. This is the order of OpenCV's findChessboardCorners with
//   patternSize (cols, rows), which Kalibr uses. Kalibr's documentation
//   gives colSpacingMeters as the x spacing, as here; its code
//   (GridCalibrationTargetCheckerboard::createGridPoints) instead places
//   corner (r, c) at (rowSpacingMeters * r, colSpacingMeters * c), i.e. the
//   transposed board. Both are the same plane, so only the board pose
//   differs.
//
// - aprilgrid: 4 corners per tag, tags in id order; point 4 * id + k is
//   corner k of tag id, with id = j * tagCols + i for the tag in column i
//   (along x) and row j (along y). The tag's lower-left corner (the origin
//   for tag 0) is at (pitch * i, pitch * j, 0) with
//   pitch = tagSize * (1 + tagSpacing), and its corners k = 0..3 are that
//   corner plus (0, 0), (s, 0), (s, s), (0, s), s = tagSize: the order in
//   which the AprilTag detector used by Kalibr reports a tag's corners.
//   Positions are those of Kalibr's GridCalibrationTargetAprilgrid
//   (verified against its source), whose own point array is instead a
//   (2 tagRows) x (2 tagCols) row-major grid of the same corners: grid
//   index b, b + 1, b + 2 tagCols + 1, b + 2 tagCols for tag (i, j) with
//   b = 4 tagCols j + 2 i. Seen from the printed side with y pointing up,
//   tag 0 is at the bottom left.
#ifndef RCM_CALIB_CALIBRATION_TARGET_H_
#define RCM_CALIB_CALIBRATION_TARGET_H_

#include <Eigen/Core>
#include <string>
#include <vector>

#include "rcm/util/status.h"

namespace rcm::calib {

enum class TargetType { kCheckerboard, kAprilGrid };

// Largest accepted number of corners (checkerboard) or tags (aprilgrid)
// along one side of a board: far above any printable board, and small
// enough that TargetPoints cannot exhaust memory.
inline constexpr int kMaxTargetCount = 1000;

struct CalibrationTarget {
  TargetType type = TargetType::kCheckerboard;
  // Checkerboard: inner corners along x (targetCols) and y (targetRows),
  // each >= 2. Aprilgrid: tags along x (tagCols) and y (tagRows), each >= 1.
  int cols = 0;
  int rows = 0;
  // Checkerboard only (0 for an aprilgrid): distance between neighbouring
  // corners along y (rowSpacingMeters) and along x (colSpacingMeters) [m].
  double row_spacing = 0.0;
  double col_spacing = 0.0;
  // Aprilgrid only (0 for a checkerboard): tag edge [m] (tagSize) and the
  // gap between neighbouring tags as a fraction of tag_size (tagSpacing).
  double tag_size = 0.0;
  double tag_spacing = 0.0;
};

// Parses the text of a Kalibr target YAML file. Errors are one line,
// "SOURCE:LINE: what" (1-based line of the offending value) or
// "SOURCE: what" when no line applies (e.g. a missing key).
StatusOr<CalibrationTarget> ParseCalibrationTarget(
    const std::string& yaml_text, const std::string& source_name);

// Reads and parses the file at `path`; errors are prefixed with `path`.
StatusOr<CalibrationTarget> ReadCalibrationTarget(const std::string& path);

// Number of corners: cols * rows (checkerboard), 4 * cols * rows
// (aprilgrid). CHECKs that the counts are in the accepted range.
int NumTargetPoints(const CalibrationTarget& target);

// Corner positions in the target frame, in the order documented above.
// CHECKs that counts and sizes are in the accepted range (as every target
// that ParseCalibrationTarget returns is).
std::vector<Eigen::Vector3d> TargetPoints(const CalibrationTarget& target);

}  // namespace rcm::calib

#endif  // RCM_CALIB_CALIBRATION_TARGET_H_
