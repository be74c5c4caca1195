// Underwater refinement of a stereo rig calibrated in air: the refractive
// index n of the water, the extrinsics cam1_from_cam0 as they are under
// water (housings drift: a few tenths of a degree move the epipolar
// estimate of n across its whole range, docs/design.md, "Rigs that drift")
// and optionally the ports' air gaps and tilts, from ~20 views of a planar
// target shown to the rig at the start of a dive. The lens intrinsics of
// the air calibration are held fixed: water does not change a lens, and
// the port model is what distinguishes refraction from distortion.
//
// Unknowns:
//   n                  in [1, 2]
//   cam1_from_cam0     (R_10, t_10), started from the air rig's; estimated
//                      when at least one view shows the target to both
//                      cameras, else held at the air rig's
//   cam0_from_target_v (R_v, t_v), one per used view
//   d_c                the air gap of camera c's port (estimate_air_gap),
//                      in [0, FlatPort::kMaxAirGap], started from the air
//                      rig's port block or 0
//   N_c                camera c's port normal (estimate_port_tilt), two
//                      parameters (a, b) = (N_x / N_z, N_y / N_z), started
//                      from the port block's normal or the optical axis
//   w                  the board's warp [warp_x, warp_y] (estimate_board_
//                      warp, board_warp.h), shared by all views, from 0
// A camera's port parameters are estimated only when that camera sees the
// target. The glass thickness and index come from air_rig.ports() (none:
// thin ports, no glass) and are never estimated.
//
// The ports: what a port block fixes and what the options free.
//   - Without port blocks every port starts as the paper's thin port (d = 0,
//     no glass, N = z). estimate_air_gap then estimates a gap from 0 with no
//     glass; when the housing has glass that was not described, the gap
//     absorbs it (a plate of thickness tg and index n_g acts, to first
//     order in the angle, as an air layer tg / n_g).
//   - With port blocks, the glass is taken as given; the gap and the normal
//     are constants unless estimate_air_gap / estimate_port_tilt free them
//     (a tilted normal with estimate_port_tilt off is used as it is).
//   - No valid port block contradicts either option, so none is refused: a
//     port block's gap and normal are start values when freed, constants
//     otherwise. (An estimated gap that ends at 0 is a thin port, reported
//     in `notes`; one that ends at FlatPort::kMaxAirGap, or a tilt beyond
//     FlatPort::kMaxTiltDegrees, is an error.)
//
// Residuals, for every corner j that camera c saw in view v at pixel u (the
// functors of underwater_reprojection_error.h):
//   e = pi_c(port_c(n, d_c, N_c, P_c)) - u,
//   P_0 = R_v X_j(w) + t_v,  P_1 = R_10 P_0 + t_10,
// X_j(w) the corner on the bowed board (X_j itself without the warp),
// pi_c the air lens of camera c (lens_models.h), port_c the exact flat port
// (rcm/camera/flat_port_projection.h), all by Ceres autodiff.
//
// Robust fit, exactly as CalibrateStereo in air (stereo_calibration.h,
// the same code): Huber at huber_px, outlier rounds that drop corners
// beyond max(outlier_sigmas robust sigmas, min_outlier_threshold_px),
// then plain least squares over the inliers.
//
// Start: every view's target pose by PnP (IPPE, then LM) on the rays of the
// thin-port model at initial_n: the corners are undistorted with the air
// lens to (xb, yb), whose ray in the water is (xb, yb, m(n0, rb)) (paper
// eq. 5), i.e. the normalized point (xb, yb) / m of the refractive camera's
// virtual pinhole. A view seen by cam1 only is posed from cam1 through the
// air extrinsics. Then the bundle adjustment, with no scan of n: from
// initial_n = 1.34 and the air extrinsics it converges for any true n in
// [1.0, 1.6] and drifts of 4 degrees (tests/calib/underwater_calibration_
// test.cc; measured to 20 degrees).
//
// Uncertainty: the covariance of the estimated parameters other than the
// target poses,
//   C = (J^T J)^-1 sigma^2,   sigma^2 = SSR / (2 m - p),
// from the m inlier corners and the p unknowns (target poses included), at
// the least-squares solution. The extrinsics enter C as [w; t] in the
// left-perturbation convention of StereoCalibration::extrinsics_covariance
// (R_10 = exp([w]x) R_10_hat, w in radians in the cam1 frame, t = t_10 in
// meters). C counts independent corner noise only; the leave-views-out
// (grouped jackknife) sigmas count errors shared within a view as well
// (cross_validation.h): the used views are split into g = min(folds, V)
// groups (the k-th used view in group k mod g), and each group is left out
// in turn. Each replicate re-solves the final least-squares problem
// without its views, from the full solution and on its inliers (the
// outlier rounds are not repeated), and
//   sigma_jk = sqrt((g - 1) / g * sum_k (x_k - mean x)^2).
//
// Errors (one line, nothing is returned): invalid options; an image size
// that differs from the air camera's; a bad observation (ids, pixels); no
// view showing the target, or fewer than kMinUnderwaterViews usable views;
// too few corners for the unknowns; a failed solve; n at the upper bound
// 2, or at the lower bound 1 with the data pulling it below by more than
// 3 sigma (n = 1 itself, a target in air, is an answer); each with the
// likely cause (the air calibration is not these cameras' as they are
// under water); an air gap at its upper bound or a tilt beyond the limit;
// a degenerate covariance (the views do not constrain every unknown).
#ifndef RCM_CALIB_UNDERWATER_CALIBRATION_H_
#define RCM_CALIB_UNDERWATER_CALIBRATION_H_

#include <Eigen/Core>
#include <array>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "rcm/calib/calibration_target.h"
#include "rcm/calib/stereo_calibration.h"
#include "rcm/calib/target_observation.h"
#include "rcm/camera/flat_port_geometry.h"
#include "rcm/geometry/rigid3d.h"
#include "rcm/stereo/stereo_rig.h"
#include "rcm/util/status.h"

namespace rcm::calib {

// Fewest views (with at least min_corners_per_view corners) a refinement
// needs: n is observable from one, but the robust statistics and any
// cross-check need a few.
inline constexpr int kMinUnderwaterViews = 3;

// The air side of a joint calibration: views of a target in air taken by
// the same two cameras (the air calibration's images, or others), so that
// one bundle adjustment estimates the lenses from both media (header of
// CalibrateUnderwater, "Air and water together").
struct AirTargetViews {
  CalibrationTarget target;  // the board shown in air
  std::vector<StereoView> views;
  ImageSize cam0_size;  // {0, 0} for a camera with no air view
  ImageSize cam1_size;
  // The air and water boards are one board: one warp for both media (the
  // targets must then be equal). Otherwise the air board has its own warp,
  // estimated when estimate_board_warp.
  bool same_board = false;
  bool estimate_board_warp = true;
};

struct UnderwaterCalibrationOptions {
  // n at which the target poses are initialized (thin-port PnP), and the
  // start of the solve: seawater ~1.34 (fresh water 1.333).
  double initial_n = 1.34;
  // Estimate each port's air gap (the thick-port model then applies).
  bool estimate_air_gap = false;
  // Estimate each port's normal (two parameters per port).
  bool estimate_port_tilt = false;
  // Estimate the board's flatness (board_warp.h, as
  // StereoCalibrationOptions::estimate_board_warp; also passed to the
  // conventional fit).
  bool estimate_board_warp = true;

  // Robust loss and outlier rejection, as StereoCalibrationOptions: Huber
  // scale [px]; outliers beyond outlier_sigmas robust sigmas of the
  // residual norms, the threshold floored at min_outlier_threshold_px;
  // max_outlier_rounds rounds (0 = keep every corner).
  double huber_px = 1.0;
  double outlier_sigmas = 5.0;
  double min_outlier_threshold_px = 2.0;
  int max_outlier_rounds = 3;
  // Ceres iterations per solve.
  int max_num_iterations = 200;
  // Views where only one camera saw the target also constrain n (and that
  // camera's port).
  bool use_single_camera_views = true;
  // Fewest corners a camera must see in a view for it to be used.
  int min_corners_per_view = 6;
  // Leave-views-out groups for the jackknife sigmas; 0 turns it off,
  // otherwise >= 2.
  int folds = 10;
  // Also fit a conventional model (CalibrateStereo with the air rig's lens
  // model, intrinsics free, no refraction) to the same corners, so that
  // the two fits can be compared.
  bool fit_conventional_model = true;
  // Carry the air lenses' covariance (air_rig.calibration_uncertainty(),
  // from the air calibration's sidecar) to n: sigma_n_lenses (header).
  bool propagate_lens_covariance = true;
  // Threads for Ceres.
  int num_threads = 2;

  // Fails on a value out of range, with the option's name.
  Status Check() const;
};

// A block of the covariance: its rows (and columns) in
// UnderwaterCovariance::matrix.
struct UnderwaterParameterBlock {
  // "n"; "cam1_from_cam0" [w (rad, cam1 frame, left perturbation),
  // t_10 (m)]; "cam0 air_gap", "cam1 air_gap" (m); "cam0 port_tilt",
  // "cam1 port_tilt" [N_x / N_z, N_y / N_z]; "board_warp" [warp_x,
  // warp_y] (m); with air views, "cam0 lens", "cam1 lens"
  // (Camera::params() order).
  std::string name;
  int offset = 0;
  int size = 0;
};

// The covariance of every estimated parameter but the target poses, for a
// covariance sidecar: blocks in the order above, only those estimated.
struct UnderwaterCovariance {
  std::vector<UnderwaterParameterBlock> blocks;
  Eigen::MatrixXd matrix;

  // The block called `name`; nullptr when it was not estimated.
  const UnderwaterParameterBlock* Find(std::string_view name) const;
  // The rows of block `row` and the columns of block `col` (both must
  // exist: CHECKed).
  Eigen::MatrixXd Block(std::string_view row, std::string_view col) const;
};

// How the extrinsics under water differ from the air calibration's:
//   R_water = exp([w]x) R_air         (w in the cam1 frame)
//   dt      = t_water - exp([w]x) t_air
// i.e. cam1 turned about its own center by w, then shifted by dt: the
// convention of StereoRig::WithCam1Moved, so that
// air_rig.WithCam1Moved(w, dt) is the underwater rig. Sigmas from the
// covariance (first order), and from the leave-out replicates when run.
struct ExtrinsicChange {
  Eigen::Vector3d rotation_deg = Eigen::Vector3d::Zero();  // w, per axis
  Eigen::Vector3d rotation_sigma_deg = Eigen::Vector3d::Zero();
  double angle_deg = 0.0;  // |w|
  double angle_sigma_deg = 0.0;
  Eigen::Vector3d translation_mm = Eigen::Vector3d::Zero();  // dt
  Eigen::Vector3d translation_sigma_mm = Eigen::Vector3d::Zero();
  // Covariance of [w (rad); dt (m)].
  Eigen::Matrix<double, 6, 6> covariance = Eigen::Matrix<double, 6, 6>::Zero();
  std::optional<Eigen::Vector3d> rotation_leave_out_sigma_deg;
  std::optional<double> angle_leave_out_sigma_deg;
  std::optional<Eigen::Vector3d> translation_leave_out_sigma_mm;
};

// One camera's port as estimated (or as given, when not estimated).
struct PortEstimate {
  FlatPort port;  // unit normal
  bool air_gap_estimated = false;
  double air_gap_sigma = 0.0;  // m
  bool tilt_estimated = false;
  // (N_x / N_z, N_y / N_z) and its standard deviations.
  Eigen::Vector2d tilt = Eigen::Vector2d::Zero();
  Eigen::Vector2d tilt_sigma = Eigen::Vector2d::Zero();
  double tilt_deg = 0.0;  // angle between N and the optical axis
};

// The grouped jackknife over views (header).
struct UnderwaterLeaveOut {
  int folds = 0;         // replicates run
  int failed_folds = 0;  // of which failed (a solve failed, n at the upper
                         // bound, or a freed parameter no longer observed:
                         // no stereo view left for the extrinsics, no view
                         // of a camera whose port is estimated); skipped
  // Jackknife standard deviations in the layout of
  // UnderwaterCovariance::matrix (w of the extrinsics about the full
  // solution, left perturbation).
  Eigen::VectorXd sigma;
  // Their jackknife covariance, (g - 1) / g sum_k (x_k - mean)(x_k -
  // mean)^T, same layout (the squares of sigma on its diagonal).
  Eigen::MatrixXd covariance;
  // The held-out error of each input view (the evidence of
  // underwater_model_selection.h): with the parameters of the replicate
  // that left the view out held, the view's target pose is fitted to its
  // inlier corners alone, and
  //   held_out_ssr[v] = sum |e|^2 over those corners   [px^2],
  //   held_out_corners[v] = their number.
  // NaN and 0 for a view that was not used, whose replicate failed, or a
  // corner of which the held parameters cannot image.
  std::vector<double> held_out_ssr;
  std::vector<int> held_out_corners;
};

// The conventional underwater calibration of the same corners: the air
// rig's lens model with its intrinsics and distortion free (no
// refraction), CalibrateStereo's bundle adjustment. Its residuals beside
// the refractive model's show which describes the images better; compare
// pixel_sigma (it accounts for its more unknowns).
struct ConventionalFit {
  bool ok = false;
  std::string error;  // why it failed, when !ok
  LensModelId model = LensModelId::kRadTan;
  double rms_px = 0.0;
  double inlier_rms_px = 0.0;
  double pixel_sigma = 0.0;
  int num_parameters = 0;
};

// Per input view: each camera's corner count and RMS residual (all its
// corners that the solution images, outliers included; 0 corners when the
// camera's view was not used).
struct UnderwaterViewResidual {
  std::array<int, 2> num_corners{};
  std::array<double, 2> rms_px{};
};

struct UnderwaterCalibration {
  explicit UnderwaterCalibration(const StereoRig& rig) : rig(rig) {}

  double n = 0.0;
  double sigma_n = 0.0;  // covariance
  std::optional<double> sigma_n_leave_out;
  // What the air lenses' uncertainty does to n, when the air rig carries a
  // lens covariance (and propagate_lens_covariance): with C_c camera c's
  // lens covariance = sum_i l_i e_i e_i^T, the final least squares is
  // solved again, from the solution, with camera c's lens moved by
  // sqrt(l_i) e_i, once per eigenpair, and
  //   sigma_n_lenses^2 = sum_{c, i} (n_{c,i} - n)^2,
  // the first-order propagation through the refit of every other unknown
  // (so the extrinsics fitted through those lenses move with them).
  std::optional<double> sigma_n_lenses;
  // The same refits' moves of the extrinsics, when they were estimated:
  // with de_{c,i} the move of [w; dt] (about the solution, the convention
  // of StereoRig::WithCam1Moved) in the refit of camera c's lens moved by
  // delta_{c,i} = sqrt(l_i) e_i, to first order
  //   Cov([w; dt], lenses) = sum_{c,i} de_{c,i} [delta_{c,i} in camera
  //                          c's columns]^T   6 x (p0 + p1), cam0's first,
  //   Cov([w; dt]) from the lenses = sum_{c,i} de_{c,i} de_{c,i}^T,
  // so that the lenses' covariance and the extrinsics' joint covariance is
  // [extrinsics_covariance + the second, the first; its transpose, the
  // lenses'] (CalibrationUncertainty::extrinsics_lens_covariance): what
  // the covariance sidecar carries, so that a target-free estimate with
  // this camchain moves the extrinsics with the lenses, as they were
  // fitted. Empty (and zero) when not computed.
  Eigen::MatrixXd extrinsics_lens_covariance;
  Eigen::Matrix<double, 6, 6> extrinsics_covariance_from_lenses =
      Eigen::Matrix<double, 6, 6>::Zero();
  // With air views (the joint calibration): the lenses were estimated from
  // both media, rig holds them, and each camera's lens covariance is the
  // joint covariance's block (empty for a camera no view saw). sigma_n,
  // extrinsics_covariance and extrinsic_change.covariance are then the
  // joint covariance's, less the lenses' share for sigma_n: with L the
  // lens blocks,
  //   sigma_n_lenses^2 = C_nL C_LL^-1 C_Ln,
  //   sigma_n^2        = C_nn - sigma_n_lenses^2  (n's variance were the
  //                                                lenses known),
  // extrinsics_lens_covariance = J C_{[w; t], L} (J the Jacobian of the
  // change [w; dt] in [w; t]), lens_cross_covariance the cam0-cam1 block
  // of C_LL (the extrinsics tie the lenses: the difference of the
  // principal points is known far better than either), and
  // extrinsics_covariance_from_lenses is zero (the extrinsics' covariance
  // already counts the lenses).
  bool lenses_estimated = false;
  std::array<Eigen::MatrixXd, 2> lens_covariance;
  Eigen::MatrixXd lens_cross_covariance;  // p0 x p1
  // The air side of the joint fit: views used, the RMS of their corners
  // (as rms_px), the air extrinsics and the air board's warp (the water
  // board's under same_board).
  int num_air_views_used = 0;
  double air_rms_px = 0.0;
  Rigid3d air_cam1_from_cam0;
  Eigen::Vector2d air_board_warp = Eigen::Vector2d::Zero();
  // The air cameras (bit for bit), the underwater extrinsics and the ports
  // (with the estimated gaps and normals; none when the air rig had none
  // and nothing about the ports was estimated).
  StereoRig rig;
  // False when no view showed the target to both cameras: the extrinsics
  // are then the air rig's, and not in the covariance.
  bool extrinsics_estimated = false;
  // Covariance of the extrinsics as [w; t] (left perturbation; zero when
  // not estimated), as StereoCalibration::extrinsics_covariance.
  Eigen::Matrix<double, 6, 6> extrinsics_covariance =
      Eigen::Matrix<double, 6, 6>::Zero();
  ExtrinsicChange extrinsic_change;
  std::array<PortEstimate, 2> ports;
  // The ports' parameters q = [d0, a0, b0, d1, a1, b1]
  // (CalibrationUncertainty's order: air gap, tilt (N_x, N_y) / N_z per
  // camera) as the fit has them, zero where a parameter was not estimated:
  // Cov(q) and Cov([w; dt], q) from the covariance (the change's convention,
  // as extrinsic_change.covariance), and their response to the lenses as
  // for the extrinsics above: Cov(q, lenses) (6 x (p0 + p1); empty when not
  // computed) and, from the lens refits, q's share of the lenses' covariance
  // of [w; dt; q], sum_{c,i} dq_{c,i} [de_{c,i}; dq_{c,i}]^T (zero with the
  // lenses estimated: the covariance counts them). What the sidecar's
  // `ports` block carries (calibration_covariance.h).
  Eigen::Matrix<double, 6, 6> port_covariance =
      Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix<double, 6, 6> extrinsics_port_covariance =
      Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::MatrixXd port_lens_covariance;
  Eigen::Matrix<double, 6, 12> port_covariance_from_lenses =
      Eigen::Matrix<double, 6, 12>::Zero();
  // True when a port parameter was estimated (port_covariance is not zero
  // by construction).
  bool ports_estimated = false;
  // The board's warp (m; zero when not estimated), as in StereoCalibration.
  bool board_warp_estimated = false;
  Eigen::Vector2d board_warp = Eigen::Vector2d::Zero();
  Eigen::Matrix2d board_warp_covariance = Eigen::Matrix2d::Zero();
  Eigen::Vector2d board_warp_sigma = Eigen::Vector2d::Zero();
  UnderwaterCovariance covariance;
  std::optional<UnderwaterLeaveOut> leave_out;

  // Per input view: cam0_from_target, nullopt when the view was not used.
  std::vector<std::optional<Rigid3d>> cam0_from_target;
  // Every corner of every used view, inliers and outliers.
  std::vector<CornerResidual> corners;
  std::vector<UnderwaterViewResidual> views;

  // sqrt(mean |e|^2) over all corners of used views (those the solution
  // cannot image, outliers with a NaN residual, left out), and over the
  // inliers.
  double rms_px = 0.0;
  double inlier_rms_px = 0.0;
  // Pixel noise estimated from the inliers, sqrt(SSR / (2 m - p)).
  double pixel_sigma = 0.0;
  // RMS at the start (thin-port PnP poses, initial_n, air extrinsics),
  // over the corners the start can image.
  double initial_rms_px = 0.0;

  int num_views_used = 0;
  int num_stereo_views = 0;
  int num_inliers = 0;
  int num_outliers = 0;
  int num_parameters = 0;  // p above

  ConventionalFit conventional;
  // What the caller may want to show the user, one line each: an air gap
  // estimated at 0, a leave-out or conventional fit that could not run.
  std::vector<std::string> notes;
};

// Refines the air rig `air_rig` on the target's views under water. The
// image sizes are those of the views' images: each must equal its air
// camera's (a camera that saw no target may pass {0, 0}). `progress`, when
// set, is called with (done, total) after the main fit and each leave-out
// replicate, and then after each lens refit (sigma_n_lenses). Fails with
// one line (header).
//
// Air and water together (`air` given): the air views' corners join the
// same bundle adjustment,
//   cam0:  e = pi(lens_0, R_a X(w_a) + t_a) - u
//   cam1:  e = pi(lens_1, R_10air (R_a X(w_a) + t_a) + t_10air) - u
// (board_reprojection_error.h) with their own poses (R_a, t_a), their own
// extrinsics cam1_from_cam0 in air (a housing may turn between the air
// calibration and the dive) and the air board's warp w_a (the water
// board's under same_board), and the lenses of both cameras become
// unknowns of both media (started from air_rig's). The robust fit, the
// covariance and the leave-out run over the whole problem; the leave-out
// groups are the water views, refitted with the lenses held (what their
// spread measures is the water views' share; the lenses' is the
// covariance's, sigma_n_lenses). No lens refits run. Errors beyond the
// above: an air image size that differs from the air rig's camera,
// same_board with targets that differ, no air view with a pose.
StatusOr<UnderwaterCalibration> CalibrateUnderwater(
    const CalibrationTarget& target, const std::vector<StereoView>& views,
    const ImageSize& cam0_size, const ImageSize& cam1_size,
    const StereoRig& air_rig, const UnderwaterCalibrationOptions& options = {},
    const std::function<void(int, int)>& progress = nullptr,
    const AirTargetViews* air = nullptr);

// Whether two targets are the same board (type, counts and sizes).
bool SameTarget(const CalibrationTarget& a, const CalibrationTarget& b);

// Whether `status` is CalibrateUnderwater's refusal of an n that ends on a
// bound of [1, 2] (the upper bound, or the lower one with the corners
// pulling below it): the air calibration does not describe the cameras,
// which no richer model of the water mends.
bool IsIndexOnBoundError(const Status& status);

}  // namespace rcm::calib

#endif  // RCM_CALIB_UNDERWATER_CALIBRATION_H_
