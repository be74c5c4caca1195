// How well a stereo rig's calibration is known when n is estimated with it:
// the covariance of cam1_from_cam0 and, where a calibration measured it, of
// each camera's lens parameters. The estimators carry it into sigma_n
// (calibration_propagation.h), so that a rig that may have moved since its
// calibration gives an honestly uncertain n instead of a confident wrong one.
//
// Extrinsics as the 6-vector [w; dt] of StereoRig::WithCam1Moved:
//
//   cam1_from_cam0 = (exp([w]x) R, exp([w]x) t + dt),
//
// w (radians) a turn of cam1 about its own center, dt (meters) a change of
// the translation, both in the cam1 frame. Their covariance is what the
// calibration measured plus what the rig may have drifted since, a drift
// prior of independent per-axis standard deviations s_w, s_t:
//
//   Sigma = Sigma_measured + diag(s_w^2, s_w^2, s_w^2, s_t^2, s_t^2, s_t^2).
//
// Measured on a real hand-built housing: 0.5 degrees between the air
// calibration and a dive, 1.3 degrees between two air calibrations two
// months apart; n moves by about 0.04 per 0.1 degree about cam1's x axis on
// a narrow-field rig. A rig without a measured covariance therefore gets the
// default drift prior of 0.1 degree and 0.1 mm per axis.
//
// The lenses drift too: a lens's focal length moves with its temperature
// and with the housing's pressure, between the air calibration and the
// water. A focal drift prior of relative standard deviation s_f scales
// each camera's focal lengths by (1 + e), e ~ N(0, s_f^2), independently
// per camera; with g = [fx, fy, 0, ..., 0] (Camera::params() order) it
// adds to each lens covariance
//
//   Sigma_lens += s_f^2 g g^T.
//
// A difference of 0.2 % between the cameras' changes moves n by 0.04 on a
// wide rig and by 0.13 on a narrow one at near-constant depth, so an air
// calibration without a measured lens change gets the default focal
// drift prior of 0.3 % (lens changes of 0.2-1 % are what real air-to-water
// dives show: 0.2 % is within one sigma, 1 % is 3.3 sigma); a calibration
// made under water (medium water) gets none, its lenses were measured in
// the water.
//
// Lens parameters in Camera::params() order, [fx, fy, cx, cy, d...] (px
// and unitless); an empty matrix means the lens is taken as exact.
//
// The extrinsics and the lenses can be correlated: an underwater
// calibration fits cam1_from_cam0 under water through the air lenses, so
// that a lens error moves the fitted extrinsics with it
// (calib/underwater_calibration.h, extrinsics_lens_covariance), and the
// two errors largely cancel in what the rig says about n. The joint
// covariance of x = [w; dt; left lens; right lens] is then
//
//   | Sigma_e      X_l      X_r   |
//   | X_l^T    Sigma_l      0     |     X = extrinsics_lens_covariance
//   | X_r^T       0     Sigma_r   |       = [X_l  X_r]  (6 x (p_l + p_r)),
//
// and without X (empty) the blocks are independent.
//
// The ports can be uncertain too: an underwater calibration that estimated
// the ports' air gaps and tilts (calib/underwater_calibration.h) fitted them
// with the extrinsics, and an air gap trades against cam1_from_cam0's
// translation along the axis (the gap moves the refracted rays' apparent
// centre), so that the translation's marginal is millimetres while given the
// ports it is a fraction of one. The ports' parameters
//
//   q = [d_l, a_l, b_l, d_r, a_r, b_r]   (kNumPortParams),
//
// d the air gap (meters), (a, b) = (N_x / N_z, N_y / N_z) the port normal's
// tilt (flat_port_geometry.h), then join the joint covariance after the
// lenses, with their covariance with everything before them
// (port_cross_covariance), so that an estimator that holds the ports carries
// their error with its correlations (calibration_propagation.h).
#ifndef RCM_GEOMETRY_CALIBRATION_UNCERTAINTY_H_
#define RCM_GEOMETRY_CALIBRATION_UNCERTAINTY_H_

#include <Eigen/Core>
#include <string>

#include "rcm/util/status.h"

namespace rcm {

struct CalibrationUncertainty {
  // The default drift prior's per-axis standard deviations.
  static constexpr double kDefaultDriftDegrees = 0.1;
  static constexpr double kDefaultDriftMillimeters = 0.1;
  // The default focal drift prior of an air calibration, percent.
  static constexpr double kDefaultFocalDriftPercent = 0.3;
  // The ports' parameters q above.
  static constexpr int kNumPortParams = 6;

  // Covariance of [w; dt] above (rad^2, rad m, m^2).
  Eigen::Matrix<double, 6, 6> extrinsics_covariance =
      Eigen::Matrix<double, 6, 6>::Zero();
  // Covariance of each camera's Camera::params(); empty = exact.
  Eigen::MatrixXd left_lens_covariance;
  Eigen::MatrixXd right_lens_covariance;
  // Cov([w; dt], [left params; right params]), 6 x (p_l + p_r); empty =
  // uncorrelated. Needs both lens covariances.
  Eigen::MatrixXd extrinsics_lens_covariance;
  // Cov(left params, right params), p_l x p_r; empty = uncorrelated. Needs
  // both lens covariances. (A joint calibration of both lenses, whose
  // relative position the extrinsics tie: the difference of the principal
  // points is known far better than either.)
  Eigen::MatrixXd lens_cross_covariance;
  // Cov(q) of the ports' parameters above, kNumPortParams square; empty =
  // the ports are exact (a component not estimated has zero variance).
  Eigen::MatrixXd port_covariance;
  // Cov([w; dt; left params; right params], q), (6 + p_l + p_r) x
  // kNumPortParams, a lens's rows only when its covariance is given;
  // empty = uncorrelated. Needs port_covariance.
  Eigen::MatrixXd port_cross_covariance;
  // The focal drift prior s_f that the lens covariances contain
  // (AddFocalDrift; several add as the root of the sum of squares), 0 when
  // none: an estimator that estimates each camera's focal scale under this
  // prior (batch_refinement.h) takes s_f^2 g g^T back out of the lens
  // covariances it holds (WithoutFocalDrift).
  double focal_drift_sigma = 0.0;
  // Where the numbers come from, in words, for reports: e.g. "default drift
  // prior 0.1 deg, 0.1 mm per axis" or "camchain-covariance.yaml + drift
  // prior 0.1 deg, 0.1 mm per axis".
  std::string source;

  // Only a drift prior (no measured covariance): s_w = rotation_sigma
  // (radians), s_t = translation_sigma (meters), both >= 0.
  static CalibrationUncertainty DriftPrior(double rotation_sigma,
                                           double translation_sigma);
  // DriftPrior(0.1 degree, 0.1 mm).
  static CalibrationUncertainty DefaultDriftPrior();
  // "drift prior 0.1 deg, 0.1 mm per axis" for those sigmas.
  static std::string DescribeDriftPrior(double rotation_sigma,
                                        double translation_sigma);
  // "focal drift prior 0.3 %" for a relative sigma of 0.003.
  static std::string DescribeFocalDrift(double focal_sigma);

  // Adds a drift prior to the extrinsics' covariance.
  void AddDrift(double rotation_sigma, double translation_sigma);
  // Adds the focal drift prior above, s_f = focal_sigma (relative, >= 0),
  // to each lens covariance; `left_params` and `right_params` are the
  // cameras' Camera::params() ([fx, fy, ...]). An empty lens covariance
  // becomes s_f^2 g g^T (the cross blocks, when empty, stay uncorrelated),
  // and `source` ends with DescribeFocalDrift. Does nothing when
  // focal_sigma is 0.
  void AddFocalDrift(double focal_sigma, const Eigen::VectorXd& left_params,
                     const Eigen::VectorXd& right_params);

  // The lens covariances without the focal drift prior (s_f^2 g g^T taken
  // back out of each, focal_drift_sigma 0): what the calibration measured.
  // `left_params` and `right_params` as for AddFocalDrift.
  CalibrationUncertainty WithoutFocalDrift(
      const Eigen::VectorXd& left_params,
      const Eigen::VectorXd& right_params) const;

  // The covariance of w alone (its marginal): how far cam1 may have turned
  // from the camchain's rotation whatever the lenses are.
  Eigen::Matrix3d RotationCovariance() const {
    return extrinsics_covariance.topLeftCorner<3, 3>();
  }
  // The covariance of w given the rest held at the camchain's values, the
  // prior of an estimator that self-calibrates w with dt and the lenses
  // held (batch_refinement.h, online_estimator.h): with q = [dt; left
  // params; right params; ports] and the joint covariance above,
  //
  //   Sigma_w|q = Sigma_ww - Sigma_wq Sigma_qq^+ Sigma_qw
  //
  // (the conditional of a Gaussian, ConditionalCovariance). It equals
  // RotationCovariance() when w is uncorrelated with q (a drift prior alone, an
  // air calibration without a rotation-translation correlation). An underwater
  // calibration fits cam1_from_cam0 through the air lenses, so a lens error
  // turns the fitted rotation with it by degrees while the two cancel in the
  // epipolar geometry: the marginal then says degrees, and the conditional what
  // the water views measured. The held q's own error is propagated with its
  // correlation with w (calibration_propagation.h). Eigenvalues are floored at
  // 1e-12 of the marginal's largest (a rotation the lenses determine is then
  // held).
  Eigen::Matrix3d RotationPriorCovariance() const;
  // True when nothing is uncertain (every entry zero, no lens covariance).
  bool IsZero() const;
  // The joint covariance of [w; dt; left params; right params; q] above
  // (the lens and port blocks of size 0 when empty; zero cross blocks
  // without extrinsics_lens_covariance, lens_cross_covariance or
  // port_cross_covariance).
  Eigen::MatrixXd JointCovariance() const;

  // Finite, symmetric (to a relative 1e-9) and positive semi-definite
  // matrices; lens covariances empty or of the cameras' parameter counts;
  // extrinsics_lens_covariance empty, or 6 x (p_l + p_r), and
  // lens_cross_covariance empty, or p_l x p_r, each with both lens
  // covariances given; port_covariance empty or kNumPortParams square,
  // port_cross_covariance empty or (6 + the lens rows) x kNumPortParams with
  // port_covariance given; the joint covariance positive semi-definite.
  // Errors name the matrix: "cam1_from_cam0 covariance is not positive
  // semi-definite".
  Status Check(int left_num_params, int right_num_params) const;
};

// The covariance of the first k variables of a Gaussian given the others,
// Sigma_xx - Sigma_xq Sigma_qq^+ Sigma_qx (Sigma_qq^+ the pseudo-inverse of
// its correlation form, directions below 1e-12 of its largest eigenvalue
// dropped; variables of zero variance left out), symmetric. `joint` is
// positive semi-definite, 0 <= k <= its size.
Eigen::MatrixXd ConditionalCovariance(const Eigen::MatrixXd& joint, int k);

// A covariance matrix as Check requires it: finite, symmetric to a
// relative 1e-9, smallest eigenvalue above -1e-9 times the largest entry.
// Errors: "NAME is not finite", "NAME is not symmetric", "NAME is not
// positive semi-definite".
Status CheckCovarianceMatrix(const Eigen::MatrixXd& matrix,
                             const std::string& name);

}  // namespace rcm

#endif  // RCM_GEOMETRY_CALIBRATION_UNCERTAINTY_H_
