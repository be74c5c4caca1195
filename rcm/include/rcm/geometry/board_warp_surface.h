// BoardWarpSurface: the bow of a printed board over its target frame,
// mrcal's calobject_warp (rcm/calib/board_warp.h states the model and
// estimates it; rcm/sim/scene_board.h renders it): with (xr, yr) a point's
// position normalized over `extent` from `origin`,
//
//   z(x, y) = warp_x 4 xr (1 - xr) + warp_y 4 yr (1 - yr)     [m].
//
// In the core library so that the simulator's board and the calibration's
// model are one polynomial.
#ifndef RCM_GEOMETRY_BOARD_WARP_SURFACE_H_
#define RCM_GEOMETRY_BOARD_WARP_SURFACE_H_

#include <Eigen/Core>

namespace rcm {

// The warp's surface over the target frame: z(x, y) = warp . Basis(x, y).
struct BoardWarpSurface {
  Eigen::Vector2d origin = Eigen::Vector2d::Zero();  // (x_min, y_min) [m]
  Eigen::Vector2d extent = Eigen::Vector2d::Ones();  // (x_max - x_min, ...)
  Eigen::Vector2d warp = Eigen::Vector2d::Zero();    // (warp_x, warp_y) [m]

  // (4 xr (1 - xr), 4 yr (1 - yr)) of a point (x, y) of the target frame.
  Eigen::Vector2d Basis(double x, double y) const {
    const double xr = (x - origin.x()) / extent.x();
    const double yr = (y - origin.y()) / extent.y();
    return Eigen::Vector2d(4.0 * xr * (1.0 - xr), 4.0 * yr * (1.0 - yr));
  }
  // z(x, y) [m].
  double Height(double x, double y) const { return warp.dot(Basis(x, y)); }
  // (dz/dx, dz/dy).
  Eigen::Vector2d Slope(double x, double y) const {
    const double xr = (x - origin.x()) / extent.x();
    const double yr = (y - origin.y()) / extent.y();
    return Eigen::Vector2d(warp.x() * 4.0 * (1.0 - 2.0 * xr) / extent.x(),
                           warp.y() * 4.0 * (1.0 - 2.0 * yr) / extent.y());
  }
};

}  // namespace rcm

#endif  // RCM_GEOMETRY_BOARD_WARP_SURFACE_H_
