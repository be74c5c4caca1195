// SceneBoard: a printed chessboard calibration target as an object of the
// simulated pool, as a diver holds it in front of the rig (an underwater
// target calibration, docs/design.md, "Rigs that drift").
//
// Target frame: EXACTLY that of rcm::calib's checkerboard
// (calib/calibration_target.h TargetPoints, calib/target_image.h), so that
// a truth pose cam0_from_target compares directly with what rcm::calib
// estimates from detections (the core library cannot depend on rcm::calib;
// a test checks the two agree bit for bit):
//
//   - the board is the plane z = 0; inner corner (row r, col c), r in
//     [0, rows), c in [0, cols), is point r * cols + c at
//     (c * square, r * square, 0): point 0 is the top-left inner corner,
//     x runs along a row of `cols` corners, y down as printed;
//   - z = x cross y points INTO the board: the printed side faces -z;
//   - the pattern is (cols + 1) x (rows + 1) squares covering
//     [-square, cols square] x [-square, rows square]; the square
//     [i, i + 1) x [j, j + 1) (in units of `square`) is black when i + j
//     is even, so the top-left square ([-1, 0) x [-1, 0)) is black;
//   - a white margin of one square surrounds the pattern: the printed area
//     is [-2 square, (cols + 1) square] x [-2 square, (rows + 1) square].
//     Beyond it there is no board (rays go on to the tank). The back of
//     the board is unprinted (white).
//
// Anti-aliased albedo (FilteredAlbedo): the mean albedo over an
// axis-aligned box [x - hx, x + hx] x [y - hy, y + hy]. With the square
// wave q(u) = +1 on [2k, 2k + 1) square and -1 on [2k + 1, 2k + 2)
// square, the black squares of the pattern are
//   black(x, y) = (I_x(x) I_y(y) + q(x) I_x(x) q(y) I_y(y)) / 2,
// I_x, I_y the indicators of the pattern's extent along each axis: a sum
// of two separable products, so its box mean is
//   B = (F[I_x] F[I_y] + F[q I_x] F[q I_y]) / 2,
// each F a 1-D box mean, in closed form from the antiderivative of q, the
// triangle wave P(u) = r for r = u mod 2 square < square, 2 square - r
// otherwise:
//   F[I](x)   = |[x - h, x + h] cap [u0, u1]| / 2h
//   F[q I](x) = (P(min(x + h, u1)) - P(max(x - h, u0))) / 2h.
// albedo = black B + white (1 - B). Exact for the box, with h -> 0 the
// point value; a point-symmetric filter keeps each corner where it is.
//
// A bowed board (`warp`): a hand-held board is not a plane. Its printed
// side is the surface z = h(x, y) of the target frame, mrcal's
// calobject_warp as rcm::calib's board_warp.h has it (the numbers compare):
//
//   h(x, y) = warp_x 4 xr (1 - xr) + warp_y 4 yr (1 - yr),
//   (xr, yr) = (x / ((cols - 1) square), y / ((rows - 1) square)),
//
// the corners' extent normalized (beyond it, in the margin, the same
// polynomial). warp_x + warp_y is the bowl at the centre; z > 0 bows the
// centre away from a camera that sees the printed side. The corners and
// the outline then lie on the surface; a ray meets it (Intersect) by
// Newton's method on the distance t along the ray from the plane's hit,
//
//   f(t) = o_z + t v_z - h(o_x + t v_x, o_y + t v_y),
//   f'(t) = v_z - grad h . (v_x, v_y),
//
// to a step below 1e-12 m (a few iterations: the slope of millimetres of
// bow over decimetres is ~0.01); a ray whose iteration does not settle (a
// ray grazing the board) misses it. The hit's normal is the surface's.
//
// A sample's box (Shade): a ray of unit direction v (target frame) whose
// sample is f meters wide across the ray (its angular footprint times the
// distance) covers on the board an ellipse-like patch of width f across
// v's projection onto the plane and f / cos along it, cos = |v_z| (at
// least 1/64). Its axis-aligned extent, u = (v_x, v_y) / |(v_x, v_y)|:
//   2 hx = sqrt(f^2 / cos^2 u_x^2 + f^2 u_y^2),
//   2 hy = sqrt(f^2 / cos^2 u_y^2 + f^2 u_x^2).
#ifndef RCM_SIM_SCENE_BOARD_H_
#define RCM_SIM_SCENE_BOARD_H_

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "rcm/geometry/board_warp_surface.h"
#include "rcm/geometry/rigid3d.h"
#include "rcm/util/status.h"

namespace rcm {

struct BoardHit;

struct SceneBoard {
  // Inner corners along x (a row) and along y (a column), each in [2, 100].
  int cols = 9;
  int rows = 6;
  double square = 0.03;  // meters, edge of a square, in [0.005, 0.5]
  // Albedo of the printed black and white, 0 <= black < white <= 1 (matte
  // print on a white board).
  double black_albedo = 0.05;
  double white_albedo = 0.85;
  // The bow (warp_x, warp_y), meters, each |.| <= kMaxWarp (file comment);
  // zero: a flat board.
  static constexpr double kMaxWarp = 0.05;
  Eigen::Vector2d warp = Eigen::Vector2d::Zero();

  Status Check() const;
  // The bow as a surface over the corners' extent (board_warp_surface.h),
  // and its height h(x, y) and gradient (file comment).
  BoardWarpSurface WarpSurface() const;
  double Height(double x, double y) const;
  Eigen::Vector2d Slope(double x, double y) const;

  // The inner corners in the target frame, point r * cols + c at
  // (c square, r square, h): calib::TargetPoints' order and values (with
  // the warp, calib::WarpedTargetPoints').
  std::vector<Eigen::Vector3d> Corners() const;
  // The corners of the pattern's squares along its outline: the
  // (cols + 2) x (rows + 2) lattice of square corners that bound the
  // pattern, the points of its border only, clockwise from the top-left
  // (-square, -square), on the surface.
  std::vector<Eigen::Vector3d> PatternOutline() const;

  // The printed area (pattern and margin) in the target plane.
  double MinX() const { return -2.0 * square; }
  double MaxX() const { return (cols + 1) * square; }
  double MinY() const { return -2.0 * square; }
  double MaxY() const { return (rows + 1) * square; }
  bool InPrintedArea(double x, double y) const {
    return x >= MinX() && x <= MaxX() && y >= MinY() && y <= MaxY();
  }
  // The center of the inner corners, ((cols - 1) square, (rows - 1)
  // square, 0) / 2.
  Eigen::Vector3d Center() const;

  // The printed side's albedo at (x, y) (target frame, meters) averaged
  // over the box of half-widths (hx, hy) >= 0 (see the file comment).
  double FilteredAlbedo(double x, double y, double hx, double hy) const;
  // The albedo a ray sees at a hit (BoardHit below) when its sample is
  // `footprint` meters wide across the ray (file comment): the printed
  // side's FilteredAlbedo over the sample's box, the back's white.
  double Shade(const BoardHit& hit, double footprint) const;
};

// Where a ray meets a placed board, inside its printed area.
struct BoardHit {
  double distance = 0.0;  // meters along the ray from its origin, > 0
  Eigen::Vector3d point = Eigen::Vector3d::Zero();  // world
  // Unit normal of the side that was hit, pointing towards the ray's
  // origin (world).
  Eigen::Vector3d normal = -Eigen::Vector3d::UnitZ();
  Eigen::Vector2d point_in_target = Eigen::Vector2d::Zero();  // (x, y), m
  // The ray's unit direction in the target frame.
  Eigen::Vector3d direction_in_target = Eigen::Vector3d::UnitZ();
  bool printed_side = true;  // the ray came from z < 0 (the printed face)
};

// A board at a pose in the world (one frame's).
class PlacedBoard {
 public:
  PlacedBoard(const SceneBoard& board, const Rigid3d& world_from_target)
      : board_(board),
        world_from_target_(world_from_target),
        target_from_world_(world_from_target.Inverse()) {}

  const SceneBoard& board() const { return board_; }
  const Rigid3d& world_from_target() const { return world_from_target_; }

  // The first (only) point where the ray from `origin_in_world` along
  // `unit_direction_in_world` crosses the board's printed area, at a
  // distance > 0; nullopt when it misses it or runs parallel to it.
  // Plane z = 0 of the target frame: with o, v the origin and direction
  // in that frame, t = -o_z / v_z; a bowed board's surface from there
  // (file comment).
  std::optional<BoardHit> Intersect(
      const Eigen::Vector3d& origin_in_world,
      const Eigen::Vector3d& unit_direction_in_world) const;

 private:
  SceneBoard board_;
  Rigid3d world_from_target_;
  Rigid3d target_from_world_;
};

}  // namespace rcm

#endif  // RCM_SIM_SCENE_BOARD_H_
