// Calibration targets (boards) for air stereo calibration, read from
// Kalibr's target YAML files (plus rcm's own ChArUco extension).
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
// ChArUco (OpenCV's board; Kalibr has none, the keys are rcm's):
//
//   target_type: 'charuco'
//   squaresX: 5              # chessboard squares along x, >= 2
//   squaresY: 7              # chessboard squares along y, >= 2
//   squareSize: 0.04         # edge of one square [m]
//   markerSize: 0.03         # edge of one ArUco marker [m], < squareSize
//   dictionary: 'DICT_6X6_250'   # optional, OpenCV's name; the default
//
// The dictionary is one of OpenCV's predefined ones (DICT_4X4_50 ...
// DICT_7X7_1000, DICT_ARUCO_ORIGINAL, DICT_APRILTAG_16h5 ... 36h11) and
// must hold the board's (squaresX * squaresY) / 2 markers (ids 0, 1, ...).
//
// Other keys are ignored. Integers must be written as integers ("6", not
// "6.0"); sizes are finite and positive; at most kMaxTargetCount corners
// (checkerboard), tags (aprilgrid) or squares (charuco) along a side.
// Unsupported types (Kalibr's circlegrid) are rejected.
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
//   tag 0 is at the bottom left, and every tag is printed upright (its
//   code's most significant bit at its upper left, kalibr_create_target_pdf
//   with rotation=2) with a 2-bit black border, so that its corners
//   k = 0..3 are its lower-left, lower-right, upper-right and upper-left
//   corners. (OpenCV's DICT_APRILTAG_36h11 marker image is this tag turned
//   by 180 degrees.)
//
// - charuco: the (squaresX - 1) x (squaresY - 1) inner chessboard corners,
//   row-major with OpenCV's ChArUco corner ids: corner (row r, col c) is
//   point r * (squaresX - 1) + c at ((c + 1) square, (r + 1) square, 0).
//   The frame is OpenCV 4.6's CharucoBoard frame (its chessboardCorners):
//   the origin is the outer corner of the board where the first square is,
//   x along the squaresX squares, y along the squaresY squares; seen from
//   the printed side x points right and y DOWN (as CharucoBoard::draw puts
//   it on an image), so z points into the board. The top-left square is
//   black; markers sit in the white squares, marker m in the m-th white
//   square in row-major order (y, then x), upright in that view.
#ifndef RCM_CALIB_CALIBRATION_TARGET_H_
#define RCM_CALIB_CALIBRATION_TARGET_H_

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "rcm/util/status.h"

namespace rcm::calib {

enum class TargetType { kCheckerboard, kAprilGrid, kCharuco };

// Largest accepted number of corners (checkerboard), tags (aprilgrid) or
// squares (charuco) along one side of a board: far above any printable
// board, and small enough that TargetPoints cannot exhaust memory.
inline constexpr int kMaxTargetCount = 1000;

// Accepted range of a target's lengths in meters and of tagSpacing (a
// ratio): far beyond any printable board either way, and narrow enough
// that neighbouring corners stay distinct in double precision.
inline constexpr double kMinTargetLength = 1e-6;
inline constexpr double kMaxTargetLength = 10.0;

// The ChArUco dictionary used when the YAML file names none.
inline constexpr char kDefaultCharucoDictionary[] = "DICT_6X6_250";

struct CalibrationTarget {
  TargetType type = TargetType::kCheckerboard;
  // Checkerboard: inner corners along x (targetCols) and y (targetRows),
  // each >= 2. Aprilgrid: tags along x (tagCols) and y (tagRows), each >= 1.
  // Charuco: chessboard squares along x (squaresX) and y (squaresY), each
  // >= 2.
  int cols = 0;
  int rows = 0;
  // Checkerboard only (0 otherwise): distance between neighbouring
  // corners along y (rowSpacingMeters) and along x (colSpacingMeters) [m].
  double row_spacing = 0.0;
  double col_spacing = 0.0;
  // Aprilgrid only (0 otherwise): tag edge [m] (tagSize) and the gap
  // between neighbouring tags as a fraction of tag_size (tagSpacing).
  double tag_size = 0.0;
  double tag_spacing = 0.0;
  // Charuco only (0 / empty otherwise): square edge (squareSize) and marker
  // edge (markerSize, < square_size) [m], and OpenCV's name of the ArUco
  // dictionary (e.g. "DICT_6X6_250").
  double square_size = 0.0;
  double marker_size = 0.0;
  std::string dictionary;
};

// Parses the text of a Kalibr target YAML file. Errors are one line,
// "SOURCE:LINE: what" (1-based line of the offending value) or
// "SOURCE: what" when no line applies (e.g. a missing key).
StatusOr<CalibrationTarget> ParseCalibrationTarget(
    const std::string& yaml_text, const std::string& source_name);

// Reads and parses the file at `path`; errors are prefixed with `path`.
StatusOr<CalibrationTarget> ReadCalibrationTarget(const std::string& path);

// Targets built from command-line values, checked as the YAML reader
// checks them; errors are one line naming the value, e.g. "checkerboard:
// rows must be between 2 and 1000 inner corners, got 1".
// Checkerboard of cols x rows INNER corners with square edge `square` [m].
StatusOr<CalibrationTarget> MakeCheckerboardTarget(int cols, int rows,
                                                   double square);
// Aprilgrid of cols x rows tags of edge `tag_size` [m], gaps of
// tag_spacing * tag_size.
StatusOr<CalibrationTarget> MakeAprilGridTarget(int cols, int rows,
                                                double tag_size,
                                                double tag_spacing);
// ChArUco board of squares_x x squares_y squares (edges `square` and
// `marker` [m]) with OpenCV's dictionary `dictionary` ("DICT_6X6_250").
StatusOr<CalibrationTarget> MakeCharucoTarget(int squares_x, int squares_y,
                                              double square, double marker,
                                              const std::string& dictionary);

// One line for logs and reports, e.g. "checkerboard 9x6 inner corners,
// 25 mm squares", "aprilgrid 6x6 tags, 88 mm tags, spacing 0.3",
// "charuco 5x7 squares, 40 mm squares, 30 mm markers, DICT_6X6_250".
std::string DescribeTarget(const CalibrationTarget& target);

// OpenCV's cv::aruco::PREDEFINED_DICTIONARY_NAME value of a dictionary
// name ("DICT_6X6_250") and its number of markers; nullopt for a name
// that is not one of OpenCV's predefined dictionaries.
struct ArucoDictionaryInfo {
  int opencv_id = 0;
  int num_markers = 0;
};
std::optional<ArucoDictionaryInfo> FindArucoDictionary(const std::string& name);

// Number of ArUco markers on a charuco board: (cols * rows) / 2, ids
// 0 .. that - 1.
int NumCharucoMarkers(const CalibrationTarget& target);

// Number of corners: cols * rows (checkerboard), 4 * cols * rows
// (aprilgrid), (cols - 1) * (rows - 1) (charuco). CHECKs that the counts
// are in the accepted range.
int NumTargetPoints(const CalibrationTarget& target);

// Corner positions in the target frame, in the order documented above.
// CHECKs that counts and sizes are in the accepted range (as every target
// that ParseCalibrationTarget returns is).
std::vector<Eigen::Vector3d> TargetPoints(const CalibrationTarget& target);

}  // namespace rcm::calib

#endif  // RCM_CALIB_CALIBRATION_TARGET_H_
