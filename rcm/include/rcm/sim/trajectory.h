// A smooth camera trajectory through a TankScene, as an underwater robot
// would fly it: ground-truth poses of cam0 (the left camera) for image
// sequences.
//
// Path: an ellipse around the tank's center, its semi-axes the tank's half
// sizes minus wall_margin, flown at constant speed (arc length s = speed t,
// by a tabulated inverse of the ellipse's arc length), from a start angle
// and in a direction drawn from the seed. On it, with periods and phases
// drawn from the seed:
//   sway    a lateral offset  sway_amplitude sin(2 pi t / T_s + phi_s)
//   heave   a vertical offset heave_amplitude sin(...)
//   yaw     heading = path tangent + yaw_amplitude sin(...)
//   rock    pitch and roll wobbles of rock_amplitude
// The camera looks along the heading, `pitch` below the horizontal; its
// frame is x right, y down, z forward (docs/design.md, "Conventions"):
//   z = (cos p cos psi, cos p sin psi, -sin p),  x0 = (sin psi, -cos psi, 0),
//   y0 = z cross x0, then x, y rotated by the roll about z;
// world_from_cam0 has columns (x, y, z) and translation the camera center.
//
// A loop (loops = K >= 1): the frames fly exactly K laps of the ellipse, so
// that the last frame is where the first was, as a dive that returns to its
// start (the loop-closure gap of an odometry is its drift). The speed is
// then K * perimeter * frame_rate / (frames - 1), and each wobble's period
// is the dive's duration over the whole number of cycles nearest to its
// drawn period, so that every wobble closes too.
#ifndef RCM_SIM_TRAJECTORY_H_
#define RCM_SIM_TRAJECTORY_H_

#include <cstdint>
#include <vector>

#include "rcm/geometry/rigid3d.h"
#include "rcm/sim/tank_scene.h"
#include "rcm/util/status.h"

namespace rcm {

struct TrajectoryOptions {
  int frames = 200;          // >= 1; frame i is at t = i / frame_rate
  double frame_rate = 20.0;  // Hz, > 0 (the dataset's rate)
  double height = 1.2;       // meters, cam0 above the floor, > 0
  double speed = 0.3;        // meters per second along the path, in [0, 5]
  double pitch_deg = 16.0;   // camera axis below the horizontal, [-60, 80]
  // Distance of the ellipse from the walls, meters. wall_margin -
  // sway_amplitude must exceed 1 (cameras stay > 1 m from the walls).
  double wall_margin = 1.6;
  double sway_amplitude = 0.1;      // meters, >= 0
  double heave_amplitude = 0.05;    // meters, >= 0
  double yaw_amplitude_deg = 5.0;   // degrees, in [0, 45]
  double rock_amplitude_deg = 1.5;  // degrees of pitch and roll, [0, 20]
  // 0: an open path at `speed`. K >= 1: K closed laps (above; `speed` is
  // ignored), at most 100, with frames >= 2.
  int loops = 0;
  uint64_t seed = 1;  // start point, direction, periods and phases

  Status Check() const;
};

struct TimedPose {
  double t = 0.0;  // seconds, frame / frame_rate
  Rigid3d world_from_cam0;
};

// The trajectory's poses, one per frame. Fails when the options are
// invalid or do not fit the tank (the ellipse needs semi-axes of at least
// 0.25 m; the camera must stay 0.3 m below the surface and above the floor).
StatusOr<std::vector<TimedPose>> GenerateTrajectory(
    const TankScene& scene, const TrajectoryOptions& options);

}  // namespace rcm

#endif  // RCM_SIM_TRAJECTORY_H_
