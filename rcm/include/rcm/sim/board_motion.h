// BoardMotion: how a diver holds a chessboard (scene_board.h) in front of
// the rig at the start of a dive, for an underwater target calibration:
// smooth, slow, at 0.6-2 m, tilted up to ~40 degrees, and kept in view of
// both cameras whenever possible. Poses are relative to cam0 (the diver
// swims with the robot).
//
// Each coordinate follows a sum of three sinusoids,
//   w(t) = sum_k a_k sin(2 pi t / T_k + phi_k),  a = (0.5, 0.3, 0.2),
// so |w| <= 1 and w is smooth (|dw/dt| <= 2 pi / T_min), with periods
// T_k uniform in a coordinate's range and phases phi_k uniform in
// [0, 2 pi), all drawn from the seed (SplitMix64). With e in [0, 1] the
// excursion (below):
//   distance  d = (min + max) / 2 + (max - min) / 2 w_d(t)    T 6-14 s
//   center    c = N(d) + e d (tan A w_x(t), 0.75 tan A w_y(t), 0)
//                                                             T 4-10 s
//   tilt      tau = e T (w_tx, w_ty) / max(1, |(w_tx, w_ty)|)  T 3-8 s
//   roll      rho = e R w_r(t)                                 T 5-12 s
// with A = max_off_axis_deg, T = max_tilt_deg, R = max_roll_deg and N(d)
// the neutral point at depth d (cam0's z): midway between the two
// cameras' optical axes (in air) where they cross the depth d, the middle
// of what both cameras see. The pose, cam0_from_target = (Q, t):
//   Q = AngleAxis(|tau|, (tau_x, tau_y, 0) / |tau|) Rz(rho),
//   t = c - Q center,
// center = SceneBoard::Center(): the board's inner corners are centered on
// c, its normal is |tau| from cam0's axis (about x by ~tau_x, about y by
// ~tau_y) and it is turned by rho about its normal. At e = 0 the board
// faces cam0 squarely, centered on the neutral line, printed side towards
// the rig, upright (target x along cam0's x, y down).
//
// Keeping it in view (PlanBoardFrames): per frame, the largest excursion
// e_max in [0, 1] (bisection) at which every point of the pattern's outline
// (SceneBoard::PatternOutline, so the whole chessboard and its border
// squares) is visible to both cameras with a margin of kBoardMarginPx (see
// BoardPointsVisible); then e = the largest sequence e <= e_max whose
// change between neighbouring frames is at most kMaxExcursionStep (two
// passes, forward and backward: e_f = min(e_max_f, e_{f-1} + step),
// e_f = min(e_f, e_{f+1} + step)), so that the board glides back into view
// rather than jumping. The distance is never changed: a board too large
// for the view at its distance (or poking through a wall) is recorded as
// not fully visible rather than moved.
#ifndef RCM_SIM_BOARD_MOTION_H_
#define RCM_SIM_BOARD_MOTION_H_

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include "rcm/camera/dome_port_geometry.h"
#include "rcm/camera/flat_port.h"
#include "rcm/geometry/rigid3d.h"
#include "rcm/sim/port_camera.h"
#include "rcm/sim/scene_board.h"
#include "rcm/sim/tank_scene.h"
#include "rcm/sim/trajectory.h"
#include "rcm/stereo/stereo_rig.h"
#include "rcm/util/status.h"

namespace rcm {

// Pixels between a board point and the image border for it to count as
// visible: a corner detector needs a few pixels around each corner.
inline constexpr double kBoardMarginPx = 3.0;
// Largest change of the excursion between neighbouring frames (a second at
// 20 Hz from the full excursion to none).
inline constexpr double kMaxExcursionStep = 0.05;

struct BoardMotionOptions {
  // Depth range of the board's center in cam0, meters, 0 < min <= max.
  double min_distance = 0.6;
  double max_distance = 2.0;
  // Largest angle between the board's normal and cam0's optical axis,
  // degrees, in [0, 70].
  double max_tilt_deg = 40.0;
  // Largest turn of the board about its normal, degrees, in [0, 45]: a
  // chessboard detector cannot tell a board turned by 180 degrees (90 for
  // a square one) and numbers the corners from the one nearest the image's
  // top-left (calib/target_detector.h), which is point 0 only while the
  // board is roughly upright.
  double max_roll_deg = 10.0;
  // Largest offset of the board's center from the neutral point, seen from
  // cam0, degrees (along x; 0.75 of it along y), in [0, 45].
  double max_off_axis_deg = 20.0;
  uint64_t seed = 1;  // periods and phases

  Status Check() const;
};

class BoardMotion {
 public:
  // Fails on invalid options or board.
  static StatusOr<BoardMotion> Create(const SceneBoard& board,
                                      const BoardMotionOptions& options,
                                      const Rigid3d& cam1_from_cam0);

  const SceneBoard& board() const { return board_; }
  const BoardMotionOptions& options() const { return options_; }

  // The pose at t seconds with the excursion e in [0, 1] (file comment).
  Rigid3d Cam0FromTarget(double t, double excursion = 1.0) const;
  // N(d): the neutral point at depth d, cam0 frame.
  Eigen::Vector3d NeutralPoint(double depth) const;

 private:
  // w(t) of one coordinate.
  struct Wave {
    std::array<double, 3> angular_rate{};  // 2 pi / T_k, 1/s
    std::array<double, 3> phase{};         // radians
    double operator()(double t) const;
  };
  enum Coordinate { kDistance, kX, kY, kTiltX, kTiltY, kRoll, kNumCoordinates };

  BoardMotion(const SceneBoard& board, const BoardMotionOptions& options)
      : board_(board), options_(options) {}

  SceneBoard board_;
  BoardMotionOptions options_;
  // Cam1's center and unit optical axis in cam0 (in air).
  Eigen::Vector3d cam1_center_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d cam1_axis_ = Eigen::Vector3d::UnitZ();
  std::array<Wave, kNumCoordinates> waves_;
};

// True when every point (target frame) of the board is seen by the camera:
// its exact pixel (PortCamera::ImageFromPoint, through the flat port or the
// dome) is in the image at least
// margin_px from the border, and the ray of that pixel (RayFromImage, moved
// to the world) meets the board's printed side first (IntersectScene)
// within 1e-6 m of the point, not the tank nor the board's back.
bool BoardPointsVisible(const PlacedBoard& board,
                        const std::vector<Eigen::Vector3d>& points_in_target,
                        const TankScene& tank, const PortCamera& camera,
                        const Rigid3d& world_from_camera, double margin_px);

// One frame of the board.
struct BoardFrame {
  Rigid3d cam0_from_target;
  double excursion = 1.0;  // the e of the pose, in [0, 1]
  // Per camera (left, right): every inner corner (SceneBoard::Corners) is
  // visible with kBoardMarginPx (BoardPointsVisible).
  std::array<bool, 2> fully_visible = {false, false};
};

// The board's frames over a sequence (file comment): `rig` is the rig that
// sees it (with its true extrinsics), `n_of_frame` the medium of each
// frame and `poses` cam0's pose in the tank (equal sizes); a camera with a
// dome sees through it instead of its flat port. Fails when a port or
// medium is invalid or the sizes differ.
StatusOr<std::vector<BoardFrame>> PlanBoardFrames(
    const BoardMotion& motion, const StereoRig& rig, const FlatPort& left_port,
    const FlatPort& right_port, const std::vector<double>& n_of_frame,
    const std::vector<TimedPose>& poses, const TankScene& tank,
    const std::optional<DomePort>& left_dome = std::nullopt,
    const std::optional<DomePort>& right_dome = std::nullopt);

}  // namespace rcm

#endif  // RCM_SIM_BOARD_MOTION_H_
