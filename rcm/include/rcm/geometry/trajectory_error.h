// TrajectoryError: how far an estimated trajectory is from the truth, as
// odometry is scored (the paper's Table I; the TUM RGB-D benchmark's
// absolute trajectory error, Sturm et al. 2012).
//
// Poses are world_from_cam of the same frames, each trajectory in its own
// world frame. The estimate is first moved onto the truth by the rigid
// transform (R, t) that minimizes the squared position errors (Umeyama
// 1991, without scale: a stereo rig's scale is its baseline's, and an
// error of it is an error of the odometry), then
//
//   ATE       = sqrt(1/F sum_f |c_f - (R c^_f + t)|^2)       (metres)
//   end drift = |d^ - d|,  d = R_0^T (c_{F-1} - c_0)         (metres)
//
// c_f the truth's centres, c^_f the estimate's, and d the last centre seen
// from the first camera (R_0 its rotation in the world), for each
// trajectory in its own frame: no alignment enters the end drift. On a
// dive that returns to its start (trajectory.h's loops), d = 0 and the end
// drift is the loop-closure gap, the odometry's accumulated drift.
#ifndef RCM_GEOMETRY_TRAJECTORY_ERROR_H_
#define RCM_GEOMETRY_TRAJECTORY_ERROR_H_

#include <vector>

#include "rcm/geometry/rigid3d.h"
#include "rcm/util/status.h"

namespace rcm {

struct TrajectoryError {
  int frames = 0;
  double ate_m = 0.0;        // above
  double end_drift_m = 0.0;  // above; the loop-closure gap of a loop
  // The truth's path length sum_f |c_f - c_{f-1}|, and |d|.
  double path_length_m = 0.0;
  double true_end_distance_m = 0.0;
  // The largest rotation error after the alignment, degrees:
  // max_f angle(R_f^T R R^_f).
  double max_rotation_error_deg = 0.0;
};

// Errors (one line): different lengths, fewer than 2 poses, a non-finite
// pose.
StatusOr<TrajectoryError> CompareTrajectories(
    const std::vector<Rigid3d>& estimated_world_from_cam,
    const std::vector<Rigid3d>& true_world_from_cam);

}  // namespace rcm

#endif  // RCM_GEOMETRY_TRAJECTORY_ERROR_H_
