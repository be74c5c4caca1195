// The printed pattern of a calibration target as an image (a texture for
// the renderer, or a file to print), consistent with TargetPoints
// (calibration_target.h): every target point is a true corner of the
// drawn pattern, on a pixel edge.
//
// Texture pixels have their centers at integers (OpenCV's convention), so
// pixel (col, row) covers [col - 0.5, col + 0.5] x [row - 0.5, row + 0.5]
// and pixel edges lie at half-integers. target_from_texture maps a texture
// position (col, row) to the target plane (x, y) [m]:
//
//   (x, y) = target_from_texture * (col, row, 1)
//
// The maps (s = metres per texture pixel, H = texture rows):
//
//   checkerboard  x = sx (col + 0.5 - 2 qx),  y = sy (row + 0.5 - 2 qy)
//                 (qx, qy pixels per square, sx = col_spacing / qx,
//                 sy = row_spacing / qy; y DOWN as printed, point 0 the
//                 top-left inner corner, the top-left square black)
//   aprilgrid     x = s (col + 0.5 - m),  y = s (H - 0.5 - row - m)
//                 (m = gap + tag pixels; Kalibr's frame has y UP, so rows
//                 are flipped: tag 0 is at the bottom left, tags upright)
//   charuco       x = s (col + 0.5 - q),  y = s (row + 0.5 - q)
//                 (q pixels per square; OpenCV's board frame, y DOWN as
//                 printed, the origin at the board's top-left outer corner)
//
// pixels_per_metre is only a request: it is rounded so that the basic cell
// is a whole number of texture pixels, and target_from_texture holds the
// scale actually used:
//
//   checkerboard  each square is round(spacing * ppm) >= 2 pixels along x
//                 and along y (separately): exact.
//   aprilgrid     each tag bit (tag_size / 10: 6 data bits and a 2-bit
//                 black border on each side) is b = round(tag_size * ppm /
//                 10) >= 1 pixels; b is increased (by at most a factor 4)
//                 until the gap tag_spacing * 10 b is a whole number of
//                 pixels, which makes every tag corner exact. When no such
//                 b exists (an irrational-looking spacing), each tag is
//                 placed at its pitch rounded to the nearest pixel, so its
//                 corners are within 0.5 texture pixels of TargetPoints.
//   charuco       each square is q = round(square_size * ppm) >= 4 pixels:
//                 the chessboard corners (the target points) are exact. The
//                 ArUco markers' cell edges are rounded to the nearest pixel
//                 edge (they only identify the squares).
//
// The pattern (0 black, 255 white) is surrounded by a white quiet zone:
// one square (checkerboard, charuco), or one tag beyond Kalibr's corner
// squares (aprilgrid, whose corner squares of edge tag_spacing * tag_size
// touch each tag diagonally at its four corners, as
// kalibr_create_target_pdf prints them).
#ifndef RCM_CALIB_TARGET_IMAGE_H_
#define RCM_CALIB_TARGET_IMAGE_H_

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "rcm/calib/calibration_target.h"

namespace rcm::calib {

struct TargetImage {
  // 8-bit gray (CV_8UC1): the printed pattern and its quiet zone.
  cv::Mat image;
  // Texture pixel (col, row), pixel centers at integers, to the target
  // plane (x, y) [m]; see the table above.
  Eigen::Matrix<double, 2, 3> target_from_texture =
      Eigen::Matrix<double, 2, 3>::Zero();
};

// Draws `target` (valid, as ParseCalibrationTarget returns it) at about
// `pixels_per_metre` (> 0, finite) texture pixels per metre. CHECKs that
// the texture stays below 2^28 pixels.
TargetImage DrawTargetImage(const CalibrationTarget& target,
                            double pixels_per_metre);

}  // namespace rcm::calib

#endif  // RCM_CALIB_TARGET_IMAGE_H_
