// The board's flatness: a printed target is not a plane. Model (mrcal's
// calobject_warp = [x2, y2], mrcal.c, so that the numbers compare): a
// target point at (x, y, 0) of the target frame (calibration_target.h)
// lies at
//
//   z = warp_x * 4 xr (1 - xr) + warp_y * 4 yr (1 - yr)     [m]
//
// with (xr, yr) = ((x - x_min) / (x_max - x_min), (y - y_min) / (y_max -
// y_min)) its position normalized over the extent of the target's points
// (TargetPoints). For a checkerboard of W x H inner corners, corner
// (col i, row j) has xr = i / (W - 1), yr = j / (H - 1): mrcal's formula
// exactly. For aprilgrid and charuco targets (not one row/col grid) the
// same formula with (xr, yr) the point's normalized position over the
// extent of all the target's corners. warp_x + warp_y is the bowl at the
// centre (xr = yr = 1/2); z > 0 bows the centre along +z of the target
// frame (away from a camera that sees the board's front with z pointing
// away from it).
//
// Outside the corners' extent (a texture's margin) the same polynomial
// continues (negative z beyond the corners for a positive warp).
#ifndef RCM_CALIB_BOARD_WARP_H_
#define RCM_CALIB_BOARD_WARP_H_

#include <Eigen/Core>
#include <vector>

#include "rcm/calib/calibration_target.h"
#include "rcm/geometry/board_warp_surface.h"

namespace rcm::calib {

// The surface of `target` (its points' extent) bowed by `warp` [m].
BoardWarpSurface BoardWarpSurfaceOf(const CalibrationTarget& target,
                                    const Eigen::Vector2d& warp);

// Per point of TargetPoints(target): its basis (4 xr (1 - xr),
// 4 yr (1 - yr)).
std::vector<Eigen::Vector2d> BoardWarpBasis(const CalibrationTarget& target);

// TargetPoints(target) with z from the warp [m].
std::vector<Eigen::Vector3d> WarpedTargetPoints(const CalibrationTarget& target,
                                                const Eigen::Vector2d& warp);

}  // namespace rcm::calib

#endif  // RCM_CALIB_BOARD_WARP_H_
