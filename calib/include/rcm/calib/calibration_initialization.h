// Closed-form starting points for the stereo bundle adjustment
// (stereo_calibration.h), from OpenCV's calibration routines.
//
// Intrinsics (InitializeCamera), per camera from its target views:
//   1. OpenCV's closed form, cv::initCameraMatrix2D: Zhang's method (the
//      first step of cv::calibrateCamera), focal lengths from the
//      homographies' vanishing points with the principal point at the
//      image center, no distortion;
//   2. target poses from those intrinsics (InitializeTargetPose);
//   3. a single-camera bundle adjustment (Ceres, Huber loss at 1 px) of the
//      camera's lens parameters and its poses, from StartingDistortion:
//      zero distortion for the polynomial models (radtan, equidistant,
//      rational), and for the unified models the start basalt uses,
//      ds xi = 0, alpha = 0.5 and eucm alpha = 0.5, beta = 1 (the same
//      lens, (x, y) / (0.5 sqrt(r^2 + 1) + 0.5): a pinhole at the center,
//      whose focal length the closed form gives, with moderate barrel
//      distortion off axis). The double sphere is refined from six starts,
//      xi = -0.4 ... 0.6 at the same near-axis focal length f / (1 + xi),
//      and the lowest cost is kept: its f and xi trade along a long curved
//      valley in which a single start stopped far from the minimum. The ds
//      and eucm coefficients are kept in their ranges (DistortionBounds)
//      here and in the stereo adjustment.
// Step 3 is what cv::calibrateCamera / cv::fisheye::calibrate do after
// step 1, for our lens models and with a sparse solver: OpenCV's dense LM
// costs ~175 ms (calibrateCamera) and ~250 ms (fisheye::calibrate) on 18
// views of 54 corners, step 3 a few ms.
//
// Target poses (InitializeTargetPose): the corners are undistorted with the
// camera's own model (Camera::NormalizedFromImage), then cv::solvePnP on
// the normalized points (K = I) with IPPE, the planar-target solution,
// refined by LM. This works the same for every lens model.
//
// Extrinsics (MedianRigid): from the relative poses of the stereo views,
// the rotation that is the medoid under the angle metric and the
// component-wise median of the translations. Robust to a few bad views.
#ifndef RCM_CALIB_CALIBRATION_INITIALIZATION_H_
#define RCM_CALIB_CALIBRATION_INITIALIZATION_H_

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "rcm/calib/target_observation.h"
#include "rcm/camera/camera.h"
#include "rcm/geometry/rigid3d.h"
#include "rcm/util/status.h"

namespace rcm::calib {

// The distortion the single-camera adjustment starts from (see above).
std::vector<double> StartingDistortion(LensModelId model);

// The lens of one camera from the target's views in its images
// (observations of one camera; at least 3, each with >= 4 corners).
// `target_points` is TargetPoints(target). Fails when the closed form
// fails (e.g. every view nearly fronto-parallel) or fewer than 3 views can
// be posed.
StatusOr<Camera> InitializeCamera(
    LensModelId model, int width, int height,
    const std::vector<Eigen::Vector3d>& target_points,
    const std::vector<const TargetObservation*>& observations);

// camera_from_target of one view; nullopt when fewer than 4 corners
// undistort, PnP fails, or a corner ends up behind the camera.
std::optional<Rigid3d> InitializeTargetPose(
    const Camera& camera, const std::vector<Eigen::Vector3d>& target_points,
    const TargetObservation& observation);

// The same from the corners' rays, given as normalized points (the ray
// (x, y, 1) of a central camera): rays[k] belongs to corner k of the
// observation, nullopt to leave it out. What InitializeTargetPose does
// after undistortion, for cameras that are not a lens alone (the virtual
// pinhole of a refractive camera, underwater_calibration.h).
std::optional<Rigid3d> TargetPoseFromNormalized(
    const std::vector<Eigen::Vector3d>& target_points,
    const TargetObservation& observation,
    const std::vector<std::optional<Eigen::Vector2d>>& rays);

// The robust center of transforms (non-empty): medoid rotation, median
// translation.
Rigid3d MedianRigid(const std::vector<Rigid3d>& transforms);

// sqrt(mean |pi(camera, camera_from_target X) - u|^2) over the corners of
// the observations (nullptr poses are skipped); infinity when a corner
// does not project.
double ReprojectionRms(
    const Camera& camera, const std::vector<Eigen::Vector3d>& target_points,
    const std::vector<const TargetObservation*>& observations,
    const std::vector<std::optional<Rigid3d>>& poses);

}  // namespace rcm::calib

#endif  // RCM_CALIB_CALIBRATION_INITIALIZATION_H_
