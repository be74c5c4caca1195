#include "rcm/stereo/stereo_rig.h"

#include <ceres/rotation.h>

#include <cmath>
#include <sstream>
#include <utility>
#include <vector>

namespace rcm {

StatusOr<StereoRig> StereoRig::Create(const Camera& left, const Camera& right,
                                      const Rigid3d& right_from_left) {
  const double baseline = right_from_left.translation.norm();
  if (!std::isfinite(baseline) || !right_from_left.rotation.allFinite()) {
    return Status::Error("stereo extrinsics are not finite");
  }
  if (baseline < kMinBaseline) {
    std::ostringstream message;
    message << "zero baseline (|t| = " << baseline
            << " m): the refractive index is unobservable without one";
    return Status::Error(message.str());
  }
  return StereoRig(left, right, right_from_left);
}

StatusOr<StereoRig> StereoRig::WithPorts(const FlatPort& left,
                                         const FlatPort& right) const {
  RCM_RETURN_IF_ERROR(left.Check().WithContext("left port"));
  RCM_RETURN_IF_ERROR(right.Check().WithContext("right port"));
  StereoRig rig = *this;
  rig.ports_ = Ports{left, right};
  // Unit normals (as a camchain stores them) are kept bit for bit.
  for (FlatPort* port : {&rig.ports_->left, &rig.ports_->right}) {
    if (std::abs(port->normal.norm() - 1.0) > 1e-12) {
      port->normal.stableNormalize();
    }
  }
  return rig;
}

StatusOr<StereoRig> StereoRig::WithCam1Moved(
    const Eigen::Vector3d& rotation, const Eigen::Vector3d& translation) const {
  if (!rotation.allFinite() || !translation.allFinite()) {
    return Status::Error("the change of cam1_from_cam0 is not finite");
  }
  Eigen::Matrix3d delta;
  ceres::AngleAxisToRotationMatrix(rotation.data(),
                                   ceres::ColumnMajorAdapter3x3(delta.data()));
  Rigid3d moved;
  moved.rotation = delta * right_from_left_.rotation;
  moved.translation = delta * right_from_left_.translation + translation;
  StatusOr<StereoRig> rig = Create(left_, right_, moved);
  if (!rig.ok()) return rig.status();
  rig->ports_ = ports_;
  rig->calibration_uncertainty_ = calibration_uncertainty_;
  return rig;
}

StatusOr<StereoRig> StereoRig::WithFocalScaled(double left_scale,
                                               double right_scale) const {
  const double scales[2] = {left_scale, right_scale};
  Camera cameras[2] = {left_, right_};
  for (int c = 0; c < 2; ++c) {
    if (!std::isfinite(scales[c]) || !(scales[c] > -1.0)) {
      return Status::Error("a focal scale is not finite or not above -1");
    }
    std::vector<double> params(cameras[c].params(),
                               cameras[c].params() + cameras[c].num_params());
    params[0] *= 1.0 + scales[c];
    params[1] *= 1.0 + scales[c];
    StatusOr<Camera> scaled = cameras[c].WithParams(params.data());
    if (!scaled.ok()) return scaled.status();
    cameras[c] = *std::move(scaled);
  }
  StatusOr<StereoRig> rig = Create(cameras[0], cameras[1], right_from_left_);
  if (!rig.ok()) return rig.status();
  rig->ports_ = ports_;
  rig->calibration_uncertainty_ = calibration_uncertainty_;
  return rig;
}

StatusOr<StereoRig> StereoRig::WithCalibrationUncertainty(
    std::optional<CalibrationUncertainty> uncertainty) const {
  if (uncertainty) {
    RCM_RETURN_IF_ERROR(
        uncertainty->Check(left_.num_params(), right_.num_params()));
  }
  StereoRig rig = *this;
  rig.calibration_uncertainty_ = std::move(uncertainty);
  return rig;
}

StereoRig::RectificationDeviation StereoRig::DeviationFromRectified() const {
  RectificationDeviation deviation;
  deviation.rotation = right_from_left_.RotationAngle();
  const Eigen::Vector3d& t = right_from_left_.translation;
  deviation.baseline_off_axis = std::atan2(t.tail<2>().norm(), std::abs(t.x()));
  return deviation;
}

std::optional<NormalizedCorrespondence> StereoRig::Normalize(
    const StereoCorrespondence& correspondence) const {
  NormalizedCorrespondence normalized;
  if (!left_.NormalizedFromImage(correspondence.left_pixel.data(),
                                 normalized.left.data()) ||
      !right_.NormalizedFromImage(correspondence.right_pixel.data(),
                                  normalized.right.data())) {
    return std::nullopt;
  }
  return normalized;
}

}  // namespace rcm
