// The covariance sidecar of a camchain: how well the calibration in
// camchain.yaml is known, in camchain-covariance.yaml next to it (rcm's
// own file; Kalibr knows nothing of it). `rcm calibrate` writes it with the
// camchain (in air, and with --underwater); ReadStereoRig (stereo_rig_file.h)
// reads it with the camchain and hands the estimators the rig's
// CalibrationUncertainty (calibration_uncertainty.h).
//
//   # rcm: covariance of the calibration in camchain.yaml
//   medium: air                  # where it was calibrated: air | water
//   drift_prior:                 # what the rig may drift after it, per axis
//     rotation_deg: 0.1          #   (the estimators add it to the
//     translation_mm: 0.1        #   covariance below)
//     focal_percent: 0.3         # each camera's focal lengths, relative
//                                #   (calibration_uncertainty.h); absent:
//                                #   0.3 for medium air, 0 for water
//   cam0:
//     intrinsics_covariance:     # of [fx, fy, cx, cy, d...] (Camera::params)
//     - [0.137, 0.13, ...]       # rows, as many as the camera has parameters
//     ...
//   cam1:
//     intrinsics_covariance: ...
//     T_cn_cnm1_covariance:      # 6x6, of [w; dt] of T_cn_cnm1 =
//     cam1_from_cam0:
//     - [...]                    # (exp([w]x) R, exp([w]x) t + dt), w in
//     ...                        # radians and dt in meters, cam1 frame
//     T_cn_cnm1_intrinsics_covariance:  # 6 rows: [w; dt] against
//     - [...]                    # [cam0's intrinsics, cam1's] (p0 + p1
//     ...                        # columns), written by an underwater
//                                # calibration (the extrinsics fitted through
//                                # the air lenses move with them)
//   ports:                       # cam0's and cam1's flat ports, as an
//     covariance:                # underwater calibration estimated them:
//     - [...]                    # 6x6, of q = [d0, a0, b0, d1, a1, b1], d the
//     ...                        # air gap (m), (a, b) = (N_x, N_y) / N_z the
//                                # normal's tilt (calibration_uncertainty.h)
//     cross_covariance:          # 6 + p0 + p1 rows: [w; dt] of cam1's
//     - [...]                    # T_cn_cnm1, cam0's intrinsics, cam1's (a
//     ...                        # camera's rows only when it has
//                                # intrinsics_covariance) against q
//
// Every key but `medium` is optional (a camera without intrinsics_covariance
// has lenses taken as exact; cam0 never has T_cn_cnm1_covariance). A
// camera's T_cn_cnm1_intrinsics_covariance needs its T_cn_cnm1_covariance
// and both cameras' intrinsics_covariance, and the joint covariance they
// make (CalibrationUncertainty::JointCovariance) must be positive
// semi-definite; so must the joint covariance with `ports`, whose
// cross_covariance needs its covariance. Numbers
// are written as the shortest text that reads back to the same double, so
// that a file reads back bit for bit; matrices are written symmetrized,
// (M + M^T) / 2. Reading never throws; errors are one
// line, "SOURCE[:LINE]: FIELD: MESSAGE" as for the camchain (yaml_fields.h).
#ifndef RCM_IO_CALIBRATION_COVARIANCE_FILE_H_
#define RCM_IO_CALIBRATION_COVARIANCE_FILE_H_

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "rcm/geometry/calibration_uncertainty.h"
#include "rcm/util/status.h"

namespace rcm {

struct CalibrationCovarianceFile {
  struct Camera {
    // Of Camera::params(); empty when absent.
    Eigen::MatrixXd intrinsics_covariance;
    // Of [w; dt] of T_cn_cnm1; absent on cam0.
    std::optional<Eigen::Matrix<double, 6, 6>> from_previous_covariance;
    // Cov([w; dt] of T_cn_cnm1, [previous camera's params; this camera's
    // params]), 6 x (p_prev + p); empty when absent (always on cam0).
    Eigen::MatrixXd from_previous_intrinsics_covariance;
    // Cov(previous camera's params, this camera's params), p_prev x p;
    // empty when absent (always on cam0): key intrinsics_cross_covariance,
    // a joint calibration's (CalibrationUncertainty::
    // lens_cross_covariance).
    Eigen::MatrixXd previous_intrinsics_covariance;
  };
  // "air" or "water".
  std::string medium = "air";
  // The drift prior's per-axis standard deviations, radians and meters.
  double drift_rotation_sigma = 0.0;
  double drift_translation_sigma = 0.0;
  // The focal drift prior, relative (0.003 = 0.3 %).
  double drift_focal_sigma = 0.0;
  // cameras[k] is camk.
  std::vector<Camera> cameras;
  // cam0's and cam1's ports (key ports): Cov(q) and Cov([w; dt; cam0's
  // intrinsics; cam1's], q) (CalibrationUncertainty::port_covariance,
  // port_cross_covariance); empty when absent.
  Eigen::MatrixXd port_covariance;
  Eigen::MatrixXd port_cross_covariance;
};

// camchain.yaml -> camchain-covariance.yaml (same folder, the camchain's
// name without its extension, then "-covariance.yaml").
std::string CovarianceSidecarPath(const std::string& camchain_path);

// Parses the text; `source_name` prefixes every error. Fails on a missing
// or unknown medium, an unknown key, a matrix that is not square (or not
// 6x6), not finite, not symmetric or not positive semi-definite, a drift
// prior that is negative, and cameras that are not cam0, cam1, ...
// consecutively.
StatusOr<CalibrationCovarianceFile> ParseCalibrationCovariance(
    const std::string& text, const std::string& source_name);
StatusOr<CalibrationCovarianceFile> ReadCalibrationCovariance(
    const std::string& path);

std::string FormatCalibrationCovariance(const CalibrationCovarianceFile& file);
// Writes atomically (atomic_file.h).
Status WriteCalibrationCovariance(const std::string& path,
                                  const CalibrationCovarianceFile& file);

// The uncertainty of the stereo pair (cam<left_index>, cam<right_index>):
// the two cameras' intrinsics covariances, and the extrinsics' covariance
// of T_cn_cnm1 and its cross-covariance with the intrinsics when
// right_index = left_index + 1 (other pairs chain several transforms:
// their extrinsics get the drift prior alone), the ports' covariances for
// the pair (cam0, cam1), plus the file's drift prior, or `drift_override`
// (rotation, translation sigmas) when given, and the file's focal drift prior
// on `left_params` and `right_params` (the cameras' Camera::params()), or
// `focal_override`. `source` names the file in CalibrationUncertainty::source.
// Fails on an index beyond the file's cameras.
StatusOr<CalibrationUncertainty> PairCalibrationUncertainty(
    const CalibrationCovarianceFile& file, int left_index, int right_index,
    const std::string& source, const Eigen::VectorXd& left_params,
    const Eigen::VectorXd& right_params,
    std::optional<std::pair<double, double>> drift_override = std::nullopt,
    std::optional<double> focal_override = std::nullopt);

}  // namespace rcm

#endif  // RCM_IO_CALIBRATION_COVARIANCE_FILE_H_
