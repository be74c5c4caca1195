#include "rcm/calib/projection_uncertainty.h"

#include <ceres/jet.h>
#include <ceres/rotation.h>
#include <glog/logging.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>

#include "rcm/camera/camera.h"
#include "rcm/camera/lens_models.h"

namespace rcm::calib {
namespace {

// T_ref_board(pose) p for a homogeneous p: R(w) p_xyz + p_w t.
template <typename T>
void TransformHomogeneous(const T* pose, const Eigen::Vector4d& point,
                          T out[3]) {
  const T xyz[3] = {T(point.x()), T(point.y()), T(point.z())};
  ceres::AngleAxisRotatePoint(pose, xyz, out);
  for (int k = 0; k < 3; ++k) out[k] += point.w() * pose[3 + k];
}

// project(lens, T_cam_ref p_ref) for the homogeneous p_ref = (xyz, w);
// extrinsics nullptr for cam0 (T_cam_ref = I). False behind the camera.
template <typename T>
bool ProjectFromReference(LensModelId model, const T* lens,
                          const T* extrinsics, const T p_ref[3], double w,
                          T q[2]) {
  T p[3] = {p_ref[0], p_ref[1], p_ref[2]};
  if (extrinsics != nullptr) {
    ceres::AngleAxisRotatePoint(extrinsics, p_ref, p);
    for (int k = 0; k < 3; ++k) p[k] += w * extrinsics[3 + k];
  }
  if (!(p[2] > T(0.0))) return false;
  const T x = p[0] / p[2];
  const T y = p[1] / p[2];
  RCM_LENS_MODEL_SWITCH(model, LensModel::ImgFromCam(lens, x, y, &q[0], &q[1]);
                        return true;)
  return false;
}

const Camera& CameraOf(const StereoCalibration& calibration, int camera) {
  CHECK(camera >= 0 && camera < calibration.num_cameras) << camera;
  return camera == 0 ? calibration.cam0.camera : calibration.cam1.camera;
}

}  // namespace

double WorstDirectionSigma(const Eigen::Matrix2d& covariance) {
  const double a = covariance(0, 0);
  const double b = 0.5 * (covariance(0, 1) + covariance(1, 0));
  const double c = covariance(1, 1);
  const double largest = 0.5 * (a + c) + std::hypot(0.5 * (a - c), b);
  return std::sqrt(std::max(largest, 0.0));
}

std::optional<MeanFramesPoint> MeanFramesPointOf(
    const StereoCalibration& calibration, int camera,
    const Eigen::Vector2d& pixel, double distance) {
  const FullCovariance& layout = calibration.full_covariance;
  if (layout.size() == 0 || !(distance > 0.0)) return std::nullopt;
  const std::optional<Eigen::Vector2d> normalized =
      CameraOf(calibration, camera).NormalizedFromImage(pixel);
  if (!normalized || !normalized->allFinite()) return std::nullopt;
  const Eigen::Vector3d ray = normalized->homogeneous().normalized();
  const bool infinite = std::isinf(distance);
  // p_cam, then p_ref = T_ref_cam p_cam (ref = cam0).
  Eigen::Vector4d p_ref = infinite ? Eigen::Vector4d(ray.x(), ray.y(), ray.z(), 0.0)
                                   : (distance * ray).homogeneous();
  if (camera == 1) {
    const Rigid3d ref_from_cam = calibration.cam1_from_cam0.Inverse();
    p_ref.head<3>() =
        ref_from_cam.rotation * p_ref.head<3>() + p_ref.w() * ref_from_cam.translation;
  }
  MeanFramesPoint point;
  point.camera = camera;
  point.distance = distance;
  for (size_t v = 0; v < layout.pose_offset.size(); ++v) {
    if (layout.pose_offset[v] < 0) continue;
    // T_board_ref* from the solver's own pose parameters.
    const double* pose = calibration.full_parameters.data() + layout.pose_offset[v];
    Eigen::Matrix3d rotation;
    ceres::AngleAxisToRotationMatrix(pose, rotation.data());
    const Eigen::Vector3d translation(pose[3], pose[4], pose[5]);
    Eigen::Vector4d p_i;
    p_i.head<3>() =
        rotation.transpose() * (p_ref.head<3>() - p_ref.w() * translation);
    p_i.w() = p_ref.w();
    point.pose_offset.push_back(layout.pose_offset[v]);
    point.point_in_board.push_back(p_i);
  }
  if (point.pose_offset.empty()) return std::nullopt;
  return point;
}

std::optional<Eigen::Vector2d> MeanFramesPixel(
    const StereoCalibration& calibration, const MeanFramesPoint& point,
    const Eigen::VectorXd& parameters) {
  const FullCovariance& layout = calibration.full_covariance;
  CHECK_EQ(parameters.size(), layout.size());
  const int num_views = static_cast<int>(point.pose_offset.size());
  double p_ref[3] = {0.0, 0.0, 0.0};
  for (int i = 0; i < num_views; ++i) {
    double p[3];
    TransformHomogeneous(parameters.data() + point.pose_offset[i],
                         point.point_in_board[i], p);
    for (int k = 0; k < 3; ++k) p_ref[k] += p[k] / num_views;
  }
  const double w = point.point_in_board[0].w();
  double lens[kMaxLensParams] = {};
  const Camera& camera = CameraOf(calibration, point.camera);
  for (int k = 0; k < layout.num_lens_params; ++k) {
    lens[k] = parameters[layout.lens_offset[point.camera] + k];
  }
  Eigen::Vector2d q;
  if (!ProjectFromReference(
          camera.model(), lens,
          point.camera == 1 ? parameters.data() + layout.extrinsics_offset
                            : nullptr,
          p_ref, w, q.data())) {
    return std::nullopt;
  }
  return q;
}

std::optional<Eigen::MatrixXd> MeanFramesJacobian(
    const StereoCalibration& calibration, const MeanFramesPoint& point) {
  const FullCovariance& layout = calibration.full_covariance;
  const Eigen::VectorXd& b = calibration.full_parameters;
  const int num_views = static_cast<int>(point.pose_offset.size());
  const int n = layout.num_lens_params;
  // p_ref* and dp_ref / dpose_i (3 x 6 each).
  using PoseJet = ceres::Jet<double, 6>;
  double p_ref[3] = {0.0, 0.0, 0.0};
  std::vector<Eigen::Matrix<double, 3, 6>> d_pose(num_views);
  for (int i = 0; i < num_views; ++i) {
    PoseJet pose[6];
    for (int k = 0; k < 6; ++k) pose[k] = PoseJet(b[point.pose_offset[i] + k], k);
    PoseJet p[3];
    TransformHomogeneous(pose, point.point_in_board[i], p);
    for (int k = 0; k < 3; ++k) {
      p_ref[k] += p[k].a / num_views;
      d_pose[i].row(k) = p[k].v.transpose() / num_views;
    }
  }
  // dq / d(lens, extrinsics, p_ref).
  constexpr int kLens = kMaxLensParams;
  using Jet = ceres::Jet<double, kLens + 9>;
  Jet lens[kLens];
  for (int k = 0; k < kLens; ++k) {
    lens[k] = k < n ? Jet(b[layout.lens_offset[point.camera] + k], k) : Jet(0.0);
  }
  // The extrinsics block exists for cam1 only (a one-camera calibration
  // has none: extrinsics_offset is -1, and cam0's projection never reads
  // it).
  Jet extrinsics[6];
  for (int k = 0; k < 6; ++k) {
    extrinsics[k] = point.camera == 1
                        ? Jet(b[layout.extrinsics_offset + k], kLens + k)
                        : Jet(0.0);
  }
  Jet reference[3];
  for (int k = 0; k < 3; ++k) reference[k] = Jet(p_ref[k], kLens + 6 + k);
  Jet q[2];
  const Camera& camera = CameraOf(calibration, point.camera);
  if (!ProjectFromReference(camera.model(), lens,
                            point.camera == 1 ? extrinsics : nullptr, reference,
                            point.point_in_board[0].w(), q)) {
    return std::nullopt;
  }
  Eigen::MatrixXd jacobian = Eigen::MatrixXd::Zero(2, layout.size());
  for (int r = 0; r < 2; ++r) {
    for (int k = 0; k < n; ++k) {
      jacobian(r, layout.lens_offset[point.camera] + k) = q[r].v[k];
    }
    if (point.camera == 1) {
      for (int k = 0; k < 6; ++k) {
        jacobian(r, layout.extrinsics_offset + k) = q[r].v[kLens + k];
      }
    }
    const Eigen::RowVector3d d_reference(q[r].v[kLens + 6], q[r].v[kLens + 7],
                                         q[r].v[kLens + 8]);
    for (int i = 0; i < num_views; ++i) {
      jacobian.block<1, 6>(r, point.pose_offset[i]) = d_reference * d_pose[i];
    }
  }
  return jacobian;
}

std::optional<Eigen::Matrix2d> MeanFramesProjectionCovariance(
    const StereoCalibration& calibration, int camera,
    const Eigen::Vector2d& pixel, double distance) {
  const std::optional<MeanFramesPoint> point =
      MeanFramesPointOf(calibration, camera, pixel, distance);
  if (!point) return std::nullopt;
  const std::optional<Eigen::MatrixXd> jacobian =
      MeanFramesJacobian(calibration, *point);
  if (!jacobian) return std::nullopt;
  const Eigen::Matrix2d covariance =
      *jacobian * calibration.full_covariance.matrix * jacobian->transpose();
  return Eigen::Matrix2d(0.5 * (covariance + covariance.transpose()));
}

double MeanFramesProjectionUncertainty(const StereoCalibration& calibration,
                                       int camera, const Eigen::Vector2d& pixel,
                                       double distance) {
  const std::optional<Eigen::Matrix2d> covariance =
      MeanFramesProjectionCovariance(calibration, camera, pixel, distance);
  if (!covariance) return std::numeric_limits<double>::quiet_NaN();
  return WorstDirectionSigma(*covariance);
}

}  // namespace rcm::calib
