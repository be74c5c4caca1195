// Underwater calibration through dome ports: where each dome's centre
// sits relative to its camera (the decentering), and optionally the
// water's index n, from views of a planar target under water, with the
// air calibration's lenses (and a stereo rig's extrinsics) held.
//
// Unknowns: per camera c the decentering C_c (the dome's centre in the
// camera frame, meters, dome_port_geometry.h), one pose cam0_from_target_v
// per view, the board's warp w (two numbers shared by all views,
// board_warp.h; held at 0 for a flat board) and, with estimate_n, n.
// Residuals (dome_reprojection_error.h), for every corner j camera c saw
// in view v at pixel u:
//   e = pi(lens_c, dome(n, C_c, R_c (R_v X_j(w) + t_v) + t_c)) - u,
// (R_c, t_c) = cam_c_from_cam0 of the air calibration (identity for cam0).
// Fit: Huber solves with outlier rounds, then least squares over the
// inliers (board_bundle_adjustment.h, as the air calibration); then a view
// whose inlier RMS exceeds 4 times the median view's is dropped whole (a
// detector that failed on a steep or crowded board moves many corners by
// less than the corner threshold, which misses them) and the rest refitted.
// Then each view is weighed by its own corner noise (weigh_views) and the
// solution refitted: with s_v^2 = SSR_v / (2 m_v - 6) the residual
// variance of view v's m_v inlier corners (one pose),
//   w_v = clamp(median_u s_u^2 / s_v^2, 1/16, 16).
// A detector's corners are noisier where they crowd (a far or steep
// board: on rendered dives 0.126 px RMS per axis under 8 px apart against
// 0.023 px at 20-30 px), and unweighted, those views dominate the
// decentering's error. On 200 rendered dives (benchmarks/dome_monte_carlo,
// 14 views) weighing the views took the RMS error from (0.093, 0.068,
// 0.212) mm to (0.050, 0.041, 0.111) for one camera and from (0.063,
// 0.030, 0.070) to (0.026, 0.016, 0.040) for a pair, and the dives within
// 0.2 mm on every component from 152 to 189 and from 194 to 200.
//
// Observability. A decentered dome bends a ray by an amount that depends
// on how far the ray is from the dome's centre and on the distance to the
// scene: the lateral decentering (C_x, C_y) turns the image by ~|C| / Z
// and is seen at once; the axial one (C_z) changes the magnification with
// the distance, like n does, so C_z and n are strongly correlated and n
// through a dome is weakly observable: views at several distances
// separate them. Both are reported: sigma_n and the correlation of n with
// each decentering component.
//
// Uncertainty. cov = sigma^2 (J^T W J)^-1 at the solution, sigma^2 =
// sum_v w_v SSR_v / (2 m - p) over the m inlier corners and p unknowns. It
// counts independent corner noise only, and a detector's errors are also
// shared within a view (corners crowded on a steep or far board err
// alike; so may a board's bow that differs between views). So the used
// views are also left out in g = min(folds, V) groups, each replicate
// refitted from the solution on its inliers with the same weights, and
// the grouped jackknife
//   sigma_jk = sqrt((g - 1) / g * sum_k (x_k - mean x)^2)
// counts them; the noise sigma of each component is the root mean square
// of the two, sqrt((sigma_c^2 + sigma_jk^2) / 2) (JackknifeNoiseSigma,
// cross_validation.h, which says why; from fewer than 5 replicates the
// larger of the two). On the 200 rendered dives its z sd is 0.99-1.03 for
// one camera and 0.99-1.12 for a pair; on independent Gaussian corners
// 0.84-1.17 (DomeCalibration.MonteCarlo*). n's sigma is made the same way
// from its own leave-out.
//
// Candidates. Real boards are rarely flat, so two models are fitted, the
// board flat and bowed (when estimate_board_warp), as the flat-port path does
// (underwater_model_selection.h): with d_v = ln(s_flat(v) / s_bowed(v)),
// s(v) the view's SSR, the evidence against the flat board is
// mean(d) / (sd(d) / sqrt(V)) over the V views (in-sample: the bow adds
// two unknowns to thousands of corners, so its own fit improvement per
// view is ~2 / (2 m_v) and the statistic measures whether the views
// agree that the board bows). The answer is the bowed board's, which nests
// the flat one and is unbiased whether or not the board bows; when the
// flat board stays plausible (evidence <= evidence_sigmas) each
// component's sigma is widened by its weighted spread, as
// underwater_model_selection.h weighs candidates:
//   sigma_model^2 = w / (1 + w) b^2,  w = exp(-evidence^2 / 2),
//   b^2 = max(0, (C_bowed - C_flat)^2 - |s_bowed^2 - s_flat^2|) (the
// Hausman correction of nested fits), and n's likewise.
#ifndef RCM_CALIB_DOME_CALIBRATION_H_
#define RCM_CALIB_DOME_CALIBRATION_H_

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "rcm/calib/calibration_target.h"
#include "rcm/calib/stereo_calibration.h"
#include "rcm/calib/target_observation.h"
#include "rcm/calib/underwater_calibration.h"
#include "rcm/camera/camera.h"
#include "rcm/camera/dome_port_geometry.h"
#include "rcm/geometry/rigid3d.h"
#include "rcm/util/status.h"

namespace rcm::calib {

struct DomeCalibrationOptions {
  // Estimate n with the decentering; otherwise n is held at `n`.
  bool estimate_n = false;
  // The medium's index, held or the start, [1, 2] (fresh water 1.333, sea
  // water 1.34).
  double n = 1.333;
  // Fit the bowed board beside the flat one (see the header); off: the
  // board is flat.
  bool estimate_board_warp = true;
  // Evidence (t statistic over the views) above which the flat board is
  // ruled out.
  double evidence_sigmas = 3.0;
  // Weigh each view by its own corner noise (header): 1 / its residual
  // variance, relative to the median view's, within [1/16, 16].
  bool weigh_views = true;
  // Leave-views-out groups of the chosen model's sigma (header); 0: none,
  // else >= 2 (min(folds, V) groups).
  int folds = 10;
  // Huber loss scale [px] of the robust solves.
  double huber_px = 1.0;
  // Corners beyond outlier_sigmas robust standard deviations, and at least
  // min_outlier_threshold_px, are dropped (as the air calibration).
  double outlier_sigmas = 5.0;
  double min_outlier_threshold_px = 2.0;
  int max_outlier_rounds = 3;
  // Ceres iterations per solve.
  int max_num_iterations = 200;
  // Fewest corners a camera must see in a view for it to be used.
  int min_corners_per_view = 6;
  // Also fit a conventional lens model freely to the underwater corners
  // (no dome): its RMS beside the dome model's shows which describes the
  // images better.
  bool fit_conventional_model = true;
  int num_threads = 2;

  Status Check() const;
};

// One camera looking through its dome.
struct DomeCameraInput {
  Camera camera;  // the air calibration's lens, held
  // The dome's glass (radii, index); its decentering is the start.
  DomePort dome;
};

// One candidate model's fit.
struct DomeCandidate {
  std::string name;  // "flat board", "bowed board"
  bool board_warp = false;
  std::vector<Eigen::Vector3d> decentering;  // per camera, meters
  std::vector<Eigen::Vector3d> decentering_sigma;
  double n = 0.0;
  double sigma_n = 0.0;  // 0 when n is held
  double rms_px = 0.0;
  double pixel_sigma = 0.0;
  double evidence = 0.0;  // against it, in sigmas (0 for the best)
  bool plausible = true;
};

struct DomeCalibration {
  int num_cameras = 0;
  // Per camera: the decentering [m], its covariance (noise, of the chosen
  // model) and its total sigma (noise and model spread), and the spread
  // alone.
  std::vector<Eigen::Vector3d> decentering;
  std::vector<Eigen::Matrix3d> decentering_covariance;
  std::vector<Eigen::Vector3d> decentering_sigma;
  std::vector<Eigen::Vector3d> decentering_sigma_model;
  // Its parts: the noise sigma (the root mean square of the covariance's
  // and the leave-out's, JackknifeNoiseSigma; the covariance's without
  // folds) and the leave-out sigma itself (zero without folds).
  std::vector<Eigen::Vector3d> decentering_sigma_noise;
  std::vector<Eigen::Vector3d> decentering_sigma_leave_out;
  int folds = 0;         // leave-out replicates run
  int failed_folds = 0;  // of which failed
  // n: estimated or held, its total sigma (0 when held), the spread part,
  // and its correlation with each camera's decentering components.
  bool n_estimated = false;
  double n = 0.0;
  double sigma_n = 0.0;
  double sigma_n_model = 0.0;
  double sigma_n_leave_out = 0.0;
  std::vector<Eigen::Vector3d> correlation_n_decentering;
  // The board's warp [m] when the chosen model bows it.
  bool board_warp_estimated = false;
  Eigen::Vector2d board_warp = Eigen::Vector2d::Zero();
  Eigen::Vector2d board_warp_sigma = Eigen::Vector2d::Zero();
  // Both candidates and the one chosen (index into candidates).
  std::vector<DomeCandidate> candidates;
  int chosen = 0;
  std::string rule;  // the rule's outcome, one line

  // Per input view: cam0_from_target, nullopt when not used.
  std::vector<std::optional<Rigid3d>> cam0_from_target;
  std::vector<CornerResidual> corners;  // of the chosen model
  double rms_px = 0.0;                  // all corners that project
  double inlier_rms_px = 0.0;           // inliers
  std::vector<double> rms_px_per_camera;
  double pixel_sigma = 0.0;
  int num_views_used = 0;
  int num_inliers = 0;
  int num_outliers = 0;
  int num_parameters = 0;
  int num_outlier_views = 0;  // views dropped whole (header)
  // Per input view, the weight of its corners relative to the median
  // view's (header; 1 without weigh_views), 0 when the view is not used.
  std::vector<double> view_weights;

  // The conventional fit (the air model's lens free, no dome) of the same
  // corners, per camera for one camera, of the pair for two.
  ConventionalFit conventional;

  // The lenses: estimated with the air views, else the input's.
  bool lenses_estimated = false;
  std::vector<Camera> cameras;
  int num_air_views_used = 0;
  double air_rms_px = 0.0;  // the air views' corners, traced at n = 1
};

// Errors: cameras not 1 or 2, a dome that fails Check, options that fail
// Check, fewer than 3 usable views (or air views), every solve failing.
// With one camera only the views' `left` observations are used; with two,
// `cam1_from_cam0` is the air calibration's extrinsics (held).
//
// With `air_views` (the joint calibration of air and water), the lenses are
// estimated too, from the cameras' lenses as the start: the air views are
// traced through the same domes at n = 1, so that an air calibration made
// through the dome, whose lens holds the shell's weak meniscus bending in
// air, does not bias the decentering (measured on noise-free views of a
// camera 7.2 mm behind a 4-inch acrylic dome: its air lens 0.43 % short in
// focal length, held, put the axial decentering at 6.44 mm; the joint
// calibration recovers 7.2 mm). The air board is the water board when
// air_views->same_board (one warp), else has its own warp.
StatusOr<DomeCalibration> CalibrateDome(
    const std::vector<StereoView>& views,
    const std::vector<DomeCameraInput>& cameras, const Rigid3d& cam1_from_cam0,
    const CalibrationTarget& target, const DomeCalibrationOptions& options,
    const AirTargetViews* air_views = nullptr);

}  // namespace rcm::calib

#endif  // RCM_CALIB_DOME_CALIBRATION_H_
