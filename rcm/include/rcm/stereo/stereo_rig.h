// StereoRig: the two in-air calibrated cameras of a pair and the transform
// between them. The left camera is the reference frame (cam0 by default).
#ifndef RCM_STEREO_STEREO_RIG_H_
#define RCM_STEREO_STEREO_RIG_H_

#include <Eigen/Core>
#include <optional>

#include "rcm/camera/camera.h"
#include "rcm/camera/flat_port_geometry.h"
#include "rcm/geometry/calibration_uncertainty.h"
#include "rcm/geometry/rigid3d.h"
#include "rcm/geometry/stereo_correspondence.h"
#include "rcm/util/status.h"

namespace rcm {

class StereoRig {
 public:
  // Shortest accepted baseline in meters: below it the two cameras see the
  // same rays and n is unobservable.
  static constexpr double kMinBaseline = 1e-6;

  // Fails on a zero (< kMinBaseline) or non-finite baseline.
  static StatusOr<StereoRig> Create(const Camera& left, const Camera& right,
                                    const Rigid3d& right_from_left);

  // The housings' flat ports (flat_port_geometry.h), when the rig file
  // gives them (a camchain's `port` blocks). A rig with a thick port is
  // estimated with the thick-port model (thick_port_refinement.h); without
  // ports, or with two thin ones, with the paper's thin port.
  struct Ports {
    FlatPort left;
    FlatPort right;
  };
  const std::optional<Ports>& ports() const { return ports_; }
  // True when a port has an air gap, glass or a tilted normal.
  bool HasThickPort() const {
    return ports_.has_value() &&
           (!ports_->left.IsThin() || !ports_->right.IsThin());
  }
  // A copy of the rig with ports (normals normalized). Errors: a port
  // that fails FlatPort::Check, prefixed "left port: " or "right port: ".
  StatusOr<StereoRig> WithPorts(const FlatPort& left,
                                const FlatPort& right) const;

  // How well the calibration is known (calibration_uncertainty.h): read
  // with the rig from a file (stereo_rig_file.h: the calibration's
  // covariance sidecar, or the default drift prior), nullopt for a rig made
  // in code, whose calibration the estimators then take as exact.
  const std::optional<CalibrationUncertainty>& calibration_uncertainty() const {
    return calibration_uncertainty_;
  }
  // A copy of the rig with `uncertainty` (nullopt: exact). Fails when it
  // fails CalibrationUncertainty::Check for these cameras.
  StatusOr<StereoRig> WithCalibrationUncertainty(
      std::optional<CalibrationUncertainty> uncertainty) const;

  // A copy of the rig with cam1 moved relative to cam0: cam1_from_cam0 =
  // (R, t) becomes
  //
  //   R' = exp([w]x) R,   t' = exp([w]x) t + dt,
  //
  // i.e. cam1 turned about its own center by the angle-axis w (radians, in
  // the cam1 frame), then cam1_from_cam0's translation changed by dt
  // (meters, cam1 frame). The convention of the rotation correction
  // (sampson_coplanarity_error.h) and of `rcm simulate --extrinsic-drift`.
  // Ports and the calibration uncertainty are kept. Fails as Create does
  // (non-finite, zero baseline).
  StatusOr<StereoRig> WithCam1Moved(
      const Eigen::Vector3d& rotation,
      const Eigen::Vector3d& translation = Eigen::Vector3d::Zero()) const;

  // A copy of the rig whose cameras' focal lengths (fx, fy, the first two
  // of Camera::params for every lens model) are scaled by (1 + left_scale)
  // and (1 + right_scale): a lens change since the calibration
  // (calibration_uncertainty.h's focal drift). Ports and the calibration
  // uncertainty are kept. Fails when a scale is not finite or not above -1.
  StatusOr<StereoRig> WithFocalScaled(double left_scale,
                                      double right_scale) const;

  const Camera& left() const { return left_; }
  const Camera& right() const { return right_; }
  const Rigid3d& right_from_left() const { return right_from_left_; }
  double Baseline() const { return right_from_left_.translation.norm(); }

  // How far the rig is from the ideal rectified pair (R = I, t = [tx, 0, 0])
  // that the paper's closed form (eq. 14) assumes.
  struct RectificationDeviation {
    double rotation = 0.0;           // radians, angle of right_from_left
    double baseline_off_axis = 0.0;  // radians, angle between t and +-x
  };
  RectificationDeviation DeviationFromRectified() const;

  // Lens-undistorted normalized coordinates of both pixels; nullopt when
  // either pixel cannot be undistorted.
  std::optional<NormalizedCorrespondence> Normalize(
      const StereoCorrespondence& correspondence) const;

 private:
  StereoRig(const Camera& left, const Camera& right,
            const Rigid3d& right_from_left)
      : left_(left), right_(right), right_from_left_(right_from_left) {}

  Camera left_;
  Camera right_;
  Rigid3d right_from_left_;
  std::optional<Ports> ports_;
  std::optional<CalibrationUncertainty> calibration_uncertainty_;
};

}  // namespace rcm

#endif  // RCM_STEREO_STEREO_RIG_H_
