// SequenceBundleAdjustment: n, cam1's turn since the air calibration and
// the rig's trajectory from landmarks tracked over a dive, with no target
// (issue 32; the paper's promise of a model "self-calibrating in real-time
// and free of known correspondences or calibration targets").
//
// Why motion helps. From one stereo pair, n and cam1's rotation w are
// nearly one unknown for epipolar geometry (docs/design.md Sec. 3:
// multiple correlation 0.97 on the paper's rig). A thin flat port keeps
// each camera central, with n acting as a radial distortion of known form
// (refractive_model.h): seen from many poses, the same landmarks fix it,
// as a moving camera self-calibrates its distortion; the calibrated
// baseline then fixes w and the metric scale.
//
// The problem. Keyframes f = 0..F-1 with the left camera's pose
// cam0_from_world_f, landmarks X_l (world = keyframe 0's left camera),
// observations u_fcl of landmark l by camera c in keyframe f. Minimized:
//
//   sum_fcl rho(|pi_c(n, w, u, cam0_from_world_f, X_l) - u_fcl|^2)
//
// pi_c the refractive projection of stereo_track_reprojection_error.h, rho
// a robust loss (stage 1), then the plain least squares over the inliers
// (stage 2, |r| <= inlier_threshold_px), as the epipolar estimator
// (batch_refinement.h). Keyframe 0's pose is held (the gauge of the
// position and orientation), the baseline |t| is the calibration's (the
// scale); n is bounded to [1, 2]. Ceres' sparse Schur solver eliminates
// the landmarks; rotations live on the quaternion manifold, the
// translation's direction (when free) on the sphere.
//
// The uncertainty (docs/design.md Sec. 3's total sigma_n):
//
//   sigma_n^2 = sigma_n_noise^2 + sigma_n_calibration^2
//               + sigma_n_systematic^2
//
// sigma_n_noise from the stage-2 covariance (J^T J)^-1 scaled by the
// pixel noise s^2 = sum r^2 / (N - p) over the inliers; the rotation's
// covariance likewise, and `correlation_n_rotation` the multiple
// correlation of n with w that the data leave (0: motion separates them;
// near 1: the data cannot tell them apart).
//
// Lenses that changed (self_calibrate_focal): with a focal drift prior s_f
// in the calibration, each camera's focal lengths are scaled by 1 + e_c,
// e_c unknowns under the prior residual (s / s_f) e_c (s the pixel noise,
// so that the prior weighs as the pixels do). Paraxially n and a focal
// length are one unknown (the virtual pinhole n f, paper eq. 9); the
// rays far off axis and the motion tell them apart. n's variance is then
// split: s^2 [(J^T J)^-1]_nn with the e_c held is the noise's share, the
// rest what the prior leaves, counted with the calibration's.
//
// sigma_n_calibration carries what the calibration leaves uncertain and
// the bundle holds (the translation's change dt, the lenses without the
// focal prior when e_c are estimated, a thick port's air gaps and tilts
// when the covariance has them; calibration_uncertainty.h): the joint
// covariance of [w; dt; lenses; ports] is split into its principal
// directions e_k (eigenvalues l_k), and n's linear response to the rig
// moved by +- sqrt(l_k) e_k is taken at the solution theta:
//
//   dr_k = (r(theta; rig + sqrt(l_k) e_k) - r(theta; rig - sqrt(l_k) e_k)) / 2
//   dn_k = -e_n^T (J^T J)^-1 J^T dr_k = -v . dr_k,   v = J (J^T J)^-1 e_n
//   sigma_n_calibration^2 = sum_k dn_k^2
//
// v from the covariance's column of n (the landmarks' part by their Schur
// blocks): one evaluation of the residuals per move, where re-solving the
// bundle took three Gauss-Newton steps per move (sigma_n_calibration
// within 0.2 % of it on a synthetic dive and 2.5 % on 10 rendered pairs
// under the 0.3 % focal drift prior, whose response curves a little; the
// whole estimate 6.5 s there instead of 14). The parts the bundle estimates
// (the turn, the direction when free) absorb their own moves: their dr lies in
// J's columns to first order, so dn is the third-order remainder (2e-7 for a
// 0.1 degree turn in the tests).
//
// The tracks' systematic floor (systematic_px, the front end's 0.03 px
// for tracks of images: kFrontEndSystematicPx): the noise model takes the
// observations' errors as independent, so that their effect on n falls as
// 1 / sqrt(N), but a matcher's errors are smooth over the image too
// (lighting, sub-pixel interpolation; calibration_propagation.h). As for
// the refine estimator, each camera's residuals in u and in v get a field
//
//   r += sum_k c_k phi_k(x, y),  phi = (1, x, y, x^2, x y, y^2),
//   c_k ~ N(0, systematic_px^2),
//
// (x, y) the pixel scaled to [-1, 1] over the image, held at c = 0 and
// carried into sigma_n by the same linear response: dn_k =
// -systematic_px v . phi_k, sigma_n_systematic^2 = sum_k dn_k^2 over the
// 24 coefficients. On a rendered 40-pair loop of a narrow rig the bundle
// was 4 of its noise sigmas off without it (rare mismatches along the
// stereo band, radially stretched match noise).
//
// When motion does not help. Motion separates n from the turn through the
// parallax of the landmarks between keyframes; three dives give the
// bundle little beyond the epipolar geometry of each pair
// (ClassifyBundleMotion, with the rig's poses after the robust stage):
//
//   static          the keyframes' centres within min_translation_fraction
//                   of the landmarks' median distance
//   along the axis  every displacement within axial_cone_deg of keyframe
//                   0's optical axis (a rig swimming straight ahead: the
//                   image flow is radial, as n's is)
//   one plane       the landmarks on one plane (its thickness below
//                   plane_thickness of its extent) that every keyframe
//                   sees from one distance (within plane_distance_spread)
//
// each while the rig turns by less than min_rotation_deg (a turning camera
// self-calibrates its radial distortion, and n is one). On synthetic dives
// with 0.3 px of noise the bundle's sigma_n grows there (static: 6e-3
// instead of 1e-3), honestly, but an error of the model has no parallax to
// be told from, so the bundle refuses in one line that names the case
// (allow_degenerate_motion solves anyway) and the epipolar estimate with
// its own sigma is the one to use.
//
// Refusals, one line and never a number: tracks that reference a frame,
// camera or landmark that does not exist or hold a non-finite pixel; a
// keyframe that shares too few landmarks with the ones before it; motion
// that does not help (above); fewer inlier observations than unknowns; a
// singular covariance (the data do not observe n); n pinned at the upper
// bound 2, which no medium reaches.
#ifndef RCM_ESTIMATION_SEQUENCE_BUNDLE_ADJUSTMENT_H_
#define RCM_ESTIMATION_SEQUENCE_BUNDLE_ADJUSTMENT_H_

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "rcm/estimation/refinement_options.h"
#include "rcm/estimation/stereo_track_reprojection_error.h"
#include "rcm/geometry/rigid3d.h"
#include "rcm/geometry/stereo_tracks.h"
#include "rcm/stereo/stereo_rig.h"
#include "rcm/util/status.h"

namespace rcm {

struct SequenceBundleOptions {
  // Where n starts, and the index the initial landmarks are triangulated
  // with, when the epipolar seed is off or fails: water by default.
  double initial_n = 1.333;
  // Start from n and cam1's turn fitted to the keyframes' stereo pairs
  // alone (RefineRefractiveIndex with refine_rotation: the epipolar
  // estimate, thin ports), so that the landmarks are triangulated with a
  // rig that fits the data. From the stale calibration instead, a narrow
  // rig whose cam1 turned by a degree triangulates landmarks metres off,
  // and 2 of 50 trials ended with n pinned at 2.
  bool epipolar_seed = true;
  // Estimate n; false holds it at initial_n, for odometry with n known or
  // assumed (the odometry table of docs/bundle.md: n held at the truth, or
  // at 1, water ignored). The seed's turn is kept, its n is not, and the
  // result's n is initial_n with sigma_n 0 (not estimated), no covariance
  // and no refusal of motion that cannot separate n from the turn.
  bool refine_n = true;
  // Estimate cam1's rotation change since the calibration (the drift the
  // epipolar estimator cannot tell from n); false holds the camchain's.
  bool refine_rotation = true;
  // Estimate the direction of cam1_from_cam0's translation too (its
  // length stays the calibration's: the scale).
  bool refine_translation_direction = false;
  // Lenses that changed since the calibration: where the rig's calibration
  // uncertainty has a focal drift prior s_f (CalibrationUncertainty::
  // focal_drift_sigma > 0, the default of an air camchain), estimate each
  // camera's focal scale 1 + e_c with the rest, under the prior
  // N(0, s_f^2) on e_c, as the refine estimator does (batch_refinement.h);
  // the propagation then holds the lenses without that prior. false: the
  // focal lengths held, the prior propagated into sigma_n.
  bool self_calibrate_focal = true;
  // When motion does not help (above): the thresholds, and whether to solve
  // anyway.
  double min_translation_fraction = 0.02;
  double min_rotation_deg = 2.0;
  double axial_cone_deg = 10.0;
  double plane_thickness = 0.02;
  double plane_distance_spread = 0.05;
  bool allow_degenerate_motion = false;
  // Stage 1's loss on the reprojection error, and its scale in pixels.
  RobustLoss loss = RobustLoss::kCauchy;
  double loss_scale_px = 1.0;
  // Observations within this many pixels of their projection after stage 1
  // are stage 2's inliers.
  double inlier_threshold_px = 2.0;
  // Triangulation: rays closer to parallel than this (degrees) do not
  // initialize a landmark (its depth would be noise).
  double min_triangulation_angle_deg = 0.1;
  // A keyframe needs this many landmarks of the keyframes before it to be
  // placed (its pose is the PnP of those).
  int min_shared_landmarks = 8;
  // Landmarks seen from fewer keyframes than this are left out of the
  // solve (NaN in the result). A landmark of one keyframe carries only its
  // pair's epipolar geometry, which the tracked landmarks of that pair
  // carry too: on a rendered 40-pair dive two thirds of the landmarks were
  // of one keyframe, and leaving them out kept sigma_n (5.5e-5 against
  // 5.4e-5) and cut the solve from 9.5 to 3.5 s. 1 keeps every landmark.
  int min_landmark_keyframes = 2;
  // Ceres iterations of each stage.
  int max_iterations = 100;
  // Carry the calibration's remaining uncertainty into sigma_n (above).
  bool propagate_calibration = true;
  // The tracks' systematic floor, pixels per coefficient (above); 0: their
  // errors independent (exact or simulated tracks). EstimateRefractive
  // IndexFromTracks sets the refinement's (the front end's 0.03 px).
  double systematic_px = 0.0;
  // Principal directions of the calibration's covariance below this
  // fraction of its largest eigenvalue are dropped from the propagation.
  double propagation_eigenvalue_floor = 1e-12;
  // Threads of Ceres and of the covariance.
  int num_threads = 2;

  // Errors name the field: "initial n = 0.9 is outside [1, 2]".
  Status Check() const;
};

// The bundle's unknowns.
struct SequenceBundleState {
  double n = 1.333;
  // w of StereoRig::WithCam1Moved: cam1 turned about its own centre
  // (radians, cam1 frame).
  Eigen::Vector3d cam1_rotation = Eigen::Vector3d::Zero();
  // Unit direction of cam1_from_cam0's translation before the turn (cam1
  // frame): the calibration's t / |t| unless refined.
  Eigen::Vector3d cam1_direction = Eigen::Vector3d::UnitX();
  // e_c: each camera's focal lengths scaled by 1 + e_c since the
  // calibration (self_calibrate_focal; zero when held).
  Eigen::Vector2d focal_scales = Eigen::Vector2d::Zero();
  // One per keyframe; keyframe 0's is the identity (the world frame).
  std::vector<Rigid3d> cam0_from_world;
  // World points, metres; NaN for a landmark that could not be placed.
  std::vector<Eigen::Vector3d> landmarks;
};

// How the rig moved over the keyframes, and what it saw (header).
enum class BundleMotion { kMoving, kStatic, kAlongAxis, kOnePlane };

struct BundleMotionSummary {
  static constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

  BundleMotion kind = BundleMotion::kMoving;
  // The largest distance of a keyframe's centre from keyframe 0's, metres,
  // and its largest rotation from keyframe 0's, degrees.
  double translation_span_m = kNaN;
  double rotation_span_deg = kNaN;
  // The landmarks' median distance from keyframe 0's centre, metres.
  double median_distance_m = kNaN;
  // The largest angle between a keyframe's displacement from keyframe 0
  // and keyframe 0's optical axis (either way), degrees.
  double axis_angle_deg = kNaN;
  // The landmarks' smallest principal spread over their largest, and the
  // keyframes' distances to their plane: (max - min) / mean.
  double plane_thickness = kNaN;
  double plane_distance_spread = kNaN;

  // One line: "the rig does not move: its keyframes lie within 4 mm of
  // each other (landmarks 3.2 m away) and turn by 0.3 deg"; for kMoving
  // "the rig moves 0.87 m and turns by 8.1 deg".
  std::string Describe() const;
};

// The summary of `state` (poses and placed landmarks) under the options'
// thresholds (header).
BundleMotionSummary ClassifyBundleMotion(const SequenceBundleState& state,
                                         const SequenceBundleOptions& options);

struct SequenceBundleResult {
  static constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

  SequenceBundleState state;
  double n = kNaN;
  // Total, and its parts (above).
  double sigma_n = kNaN;
  double sigma_n_noise = kNaN;
  double sigma_n_calibration = kNaN;
  double sigma_n_systematic = kNaN;  // 0 without a floor
  // Covariance of cam1_rotation from the noise, rad^2 (zero when held).
  Eigen::Matrix3d rotation_covariance = Eigen::Matrix3d::Zero();
  // Covariance of n with each component of cam1_rotation from the noise
  // (radians; zero when held).
  Eigen::Vector3d n_rotation_covariance = Eigen::Vector3d::Zero();
  // Multiple correlation of n with cam1_rotation left by the data (NaN
  // when the rotation is held).
  double correlation_n_rotation = kNaN;
  // The correlation of n with each component of cam1_rotation (zero when
  // held).
  Eigen::Vector3d correlation_n_rotation_components = Eigen::Vector3d::Zero();
  // With the focal scales estimated (self_calibrate_focal and a focal
  // drift prior): their covariance and with n (the noise and the prior).
  bool focal_scales_estimated = false;
  Eigen::Matrix2d focal_scale_covariance = Eigen::Matrix2d::Zero();
  Eigen::Vector2d n_focal_scale_covariance = Eigen::Vector2d::Zero();
  Eigen::Vector2d correlation_n_focal_scales = Eigen::Vector2d::Zero();
  // Pixel noise estimated from the stage-2 residuals.
  double pixel_sigma = kNaN;
  int64_t num_observations = 0;  // given
  int64_t num_inliers = 0;       // in stage 2
  int num_landmarks = 0;         // placed and used in stage 2
  int num_frames = 0;
  int iterations = 0;  // Ceres iterations, both stages
  // Principal directions of the calibration the propagation moved.
  int propagation_directions = 0;
  // How the rig moved (from the solution).
  BundleMotionSummary motion;

  // world_from_cam0 of keyframe f: the left camera's pose in keyframe 0's
  // frame (the trajectory TUM files hold).
  Rigid3d WorldFromCam0(int f) const {
    return state.cam0_from_world[f].Inverse();
  }
};

class SequenceBundleAdjustment {
 public:
  // Fails when the options do not Check or the rig has no baseline.
  static StatusOr<SequenceBundleAdjustment> Create(
      const StereoRig& rig, const SequenceBundleOptions& options);

  // A starting state from the tracks alone: n and w from the epipolar seed
  // (n = options.initial_n, w = 0 without it), each landmark triangulated from
  // its first stereo observation (or from two left views once their poses are
  // known), keyframe 0 the world and each later keyframe placed by the PnP
  // (OpenCV's RANSAC, then its iterative refinement) of the landmarks already
  // placed, in water bearings (a central camera: the thin port, or a thick one
  // made central at 2 m). Errors: tracks that do not Check, a keyframe with
  // fewer than min_shared_landmarks placed landmarks in view.
  StatusOr<SequenceBundleState> Initialize(const StereoTracks& tracks) const;

  // Stages 1 and 2 from `initial`, then the uncertainty (above).
  StatusOr<SequenceBundleResult> Solve(
      const StereoTracks& tracks, const SequenceBundleState& initial) const;
  // Initialize, then Solve.
  StatusOr<SequenceBundleResult> Solve(const StereoTracks& tracks) const;

  const StereoRig& rig() const { return rig_; }
  const SequenceBundleOptions& options() const { return options_; }

 private:
  SequenceBundleAdjustment(const StereoRig& rig,
                           const SequenceBundleOptions& options)
      : rig_(rig), options_(options) {}

  StereoRig rig_;
  SequenceBundleOptions options_;
};

}  // namespace rcm

#endif  // RCM_ESTIMATION_SEQUENCE_BUNDLE_ADJUSTMENT_H_
