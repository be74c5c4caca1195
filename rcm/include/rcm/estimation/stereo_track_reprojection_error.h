// Cost functor of the sequence bundle adjustment
// (sequence_bundle_adjustment.h): the pixel at which one camera of the
// stereo rig, at one keyframe's pose, images a landmark through its flat
// port into water of index n, minus the pixel the landmark was tracked at.
// Written as Ceres' examples/snavely_reprojection_error.h: const members,
// a templated operator(), a static Create().
//
// Parameter blocks (raw arrays):
//   n                 [n]                          the medium's index
//   cam0_from_world   [qw, qx, qy, qz, tx, ty, tz] the keyframe's left
//                                                  camera pose (Hamilton
//                                                  quaternion, Ceres'
//                                                  order; metres)
//   landmark          [X, Y, Z]                    world point, metres
//   focal_scales      [e0, e1]                     each camera's focal
//                                                  lengths' change since
//                                                  the calibration: fx, fy
//                                                  of camera c scaled by
//                                                  1 + e_c
//   cam1_rotation     [w0, w1, w2]                 cam1's turn since the
//                                                  calibration (rad)
//   cam1_direction    [u0, u1, u2]                 unit direction of
//                                                  cam1_from_cam0's
//                                                  translation before the
//                                                  turn (cam1 frame)
//
// With (R, t) the calibration's cam1_from_cam0 and b = |t| its baseline
// (held: it gives the metric scale), the point in each camera is
//
//   p0 = R(q) X + t_f
//   p1 = exp([w]x) (R p0 + b u)
//
// which is StereoRig::WithCam1Moved's (exp([w]x) R, exp([w]x) t + dt) with
// exp([w]x) t + dt = b exp([w]x) u: at u = t / b, dt = 0. The residual is
//
//   r = pi(lens_c, port_c(n, p_c)) - u_observed       (pixels)
//
// with port_c the normalized point in air of a point in the medium: the
// paper's closed form for a thin port (refractive_model.h,
// (xb, yb) = n (X, Y) / sqrt(Z^2 - (n^2 - 1)(X^2 + Y^2))), the exact flat
// port for a thick one (flat_port_projection.h), and pi the air lens model
// (lens_models.h). The lenses and the ports are constants of the functor
// (the air calibration), so the Jets carry only the bundle's unknowns. A
// point the port cannot image (behind the camera, past the critical angle)
// makes the residual undefined: operator() returns false and Ceres rejects
// the step.
#ifndef RCM_ESTIMATION_STEREO_TRACK_REPROJECTION_ERROR_H_
#define RCM_ESTIMATION_STEREO_TRACK_REPROJECTION_ERROR_H_

#include <ceres/autodiff_cost_function.h>
#include <ceres/rotation.h>

#include <Eigen/Core>
#include <array>

#include "rcm/camera/flat_port_geometry.h"
#include "rcm/camera/flat_port_projection.h"
#include "rcm/camera/lens_models.h"
#include "rcm/camera/refractive_model.h"

namespace rcm {

// What one camera's residual holds fixed: its air lens (lens_models.h
// order) and its port.
struct TrackCameraConstants {
  std::array<double, kMaxLensParams> lens{};
  // The paper's thin port: the closed form; otherwise the exact port below.
  bool thin_port = true;
  double air_gap = 0.0;          // metres
  double glass_thickness = 0.0;  // metres
  double glass_index = 1.49;
  std::array<double, 3> normal{0.0, 0.0, 1.0};  // unit, camera frame
};

namespace track_internal {

// pi(lens, port(n, P)) - pixel for a point P in the camera frame; false
// where the port cannot image P.
template <typename LensModel, typename T>
bool ProjectThroughPort(const TrackCameraConstants& constants, const T& n,
                        const T& focal_scale, const T point[3],
                        const Eigen::Vector2d& pixel, T* residuals) {
  T normalized[2];
  if (constants.thin_port) {
    if (!FlatPortRefraction::NormalizedFromPointInWater(
            n, point, &normalized[0], &normalized[1])) {
      return false;
    }
  } else {
    const T normal[3] = {T(constants.normal[0]), T(constants.normal[1]),
                         T(constants.normal[2])};
    if (!FlatPortProjection::NormalizedFromPoint(
            n, T(constants.air_gap), T(constants.glass_thickness),
            T(constants.glass_index), normal, point, normalized)) {
      return false;
    }
  }
  T lens[LensModel::kNumParams];
  for (int i = 0; i < LensModel::kNumParams; ++i) {
    lens[i] = T(constants.lens[i]);
  }
  // Every lens model's parameters begin with fx, fy (lens_models.h).
  lens[0] *= T(1.0) + focal_scale;
  lens[1] *= T(1.0) + focal_scale;
  T u;
  T v;
  LensModel::ImgFromCam(lens, normalized[0], normalized[1], &u, &v);
  residuals[0] = u - T(pixel.x());
  residuals[1] = v - T(pixel.y());
  return true;
}

// p0 = R(q) X + t for a pose block [qw, qx, qy, qz, tx, ty, tz].
template <typename T>
void PointInCam0(const T* cam0_from_world, const T* landmark, T p0[3]) {
  ceres::QuaternionRotatePoint(cam0_from_world, landmark, p0);
  p0[0] += cam0_from_world[4];
  p0[1] += cam0_from_world[5];
  p0[2] += cam0_from_world[6];
}

// p1 = exp([w]x) (R p0 + b u): the point in cam1 turned by w, R the
// calibration's cam1_from_cam0 rotation (row-major), b the baseline and u
// the translation's direction.
template <typename T, typename D>
void PointInCam1(const std::array<double, 9>& rotation, double baseline,
                 const D* direction, const T* cam1_rotation, const T* p0,
                 T p1[3]) {
  T q[3];
  for (int i = 0; i < 3; ++i) {
    q[i] = T(rotation[3 * i]) * p0[0] + T(rotation[3 * i + 1]) * p0[1] +
           T(rotation[3 * i + 2]) * p0[2] + T(baseline) * direction[i];
  }
  ceres::AngleAxisRotatePoint(cam1_rotation, q, p1);
}

}  // namespace track_internal

// A landmark seen by cam0: blocks (n, cam0_from_world, landmark,
// focal_scales).
template <typename LensModel>
struct Cam0TrackReprojectionError {
  Cam0TrackReprojectionError(const TrackCameraConstants& constants,
                             const Eigen::Vector2d& pixel)
      : constants(constants), pixel(pixel) {}

  template <typename T>
  bool operator()(const T* n, const T* cam0_from_world, const T* landmark,
                  const T* focal_scales, T* residuals) const {
    T p0[3];
    track_internal::PointInCam0(cam0_from_world, landmark, p0);
    return track_internal::ProjectThroughPort<LensModel>(
        constants, n[0], focal_scales[0], p0, pixel, residuals);
  }

  static ceres::CostFunction* Create(const TrackCameraConstants& constants,
                                     const Eigen::Vector2d& pixel) {
    return new ceres::AutoDiffCostFunction<Cam0TrackReprojectionError, 2, 1, 7,
                                           3, 2>(
        new Cam0TrackReprojectionError(constants, pixel));
  }

  const TrackCameraConstants constants;
  const Eigen::Vector2d pixel;
};

// A landmark seen by cam1: blocks (n, cam0_from_world, landmark,
// focal_scales, cam1_rotation, cam1_direction). `rotation` is the calibration's
// cam1_from_cam0 rotation (row-major 3 x 3 as Eigen stores a transposed
// matrix: element (i, j) at [3 * i + j]) and `baseline` |t| in metres.
template <typename LensModel>
struct Cam1TrackReprojectionError {
  Cam1TrackReprojectionError(const TrackCameraConstants& constants,
                             const std::array<double, 9>& rotation,
                             double baseline, const Eigen::Vector2d& pixel)
      : constants(constants),
        rotation(rotation),
        baseline(baseline),
        pixel(pixel) {}

  template <typename T>
  bool operator()(const T* n, const T* cam0_from_world, const T* landmark,
                  const T* focal_scales, const T* cam1_rotation,
                  const T* cam1_direction, T* residuals) const {
    T p0[3];
    track_internal::PointInCam0(cam0_from_world, landmark, p0);
    T p1[3];
    track_internal::PointInCam1(rotation, baseline, cam1_direction,
                                cam1_rotation, p0, p1);
    return track_internal::ProjectThroughPort<LensModel>(
        constants, n[0], focal_scales[1], p1, pixel, residuals);
  }

  static ceres::CostFunction* Create(const TrackCameraConstants& constants,
                                     const std::array<double, 9>& rotation,
                                     double baseline,
                                     const Eigen::Vector2d& pixel) {
    return new ceres::AutoDiffCostFunction<Cam1TrackReprojectionError, 2, 1, 7,
                                           3, 2, 3, 3>(
        new Cam1TrackReprojectionError(constants, rotation, baseline, pixel));
  }

  const TrackCameraConstants constants;
  const std::array<double, 9> rotation;
  const double baseline;
  const Eigen::Vector2d pixel;
};

// Cam1TrackReprojectionError with the translation's direction held (the
// calibration's, refine_translation_direction off): blocks (n,
// cam0_from_world, landmark, focal_scales, cam1_rotation). The same
// residual, with derivatives over 16 parameters instead of 19 (the
// bundle's hot path).
template <typename LensModel>
struct Cam1HeldDirectionTrackReprojectionError {
  Cam1HeldDirectionTrackReprojectionError(
      const TrackCameraConstants& constants,
      const std::array<double, 9>& rotation, double baseline,
      const std::array<double, 3>& direction, const Eigen::Vector2d& pixel)
      : constants(constants),
        rotation(rotation),
        baseline(baseline),
        direction(direction),
        pixel(pixel) {}

  template <typename T>
  bool operator()(const T* n, const T* cam0_from_world, const T* landmark,
                  const T* focal_scales, const T* cam1_rotation,
                  T* residuals) const {
    T p0[3];
    track_internal::PointInCam0(cam0_from_world, landmark, p0);
    T p1[3];
    track_internal::PointInCam1(rotation, baseline, direction.data(),
                                cam1_rotation, p0, p1);
    return track_internal::ProjectThroughPort<LensModel>(
        constants, n[0], focal_scales[1], p1, pixel, residuals);
  }

  static ceres::CostFunction* Create(const TrackCameraConstants& constants,
                                     const std::array<double, 9>& rotation,
                                     double baseline,
                                     const std::array<double, 3>& direction,
                                     const Eigen::Vector2d& pixel) {
    return new ceres::AutoDiffCostFunction<
        Cam1HeldDirectionTrackReprojectionError, 2, 1, 7, 3, 2, 3>(
        new Cam1HeldDirectionTrackReprojectionError(
            constants, rotation, baseline, direction, pixel));
  }

  const TrackCameraConstants constants;
  const std::array<double, 9> rotation;
  const double baseline;
  const std::array<double, 3> direction;
  const Eigen::Vector2d pixel;
};

}  // namespace rcm

#endif  // RCM_ESTIMATION_STEREO_TRACK_REPROJECTION_ERROR_H_
