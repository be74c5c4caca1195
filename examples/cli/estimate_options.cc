// rcm estimate's flags and the library's options they give: flags ->
// options, with the flags named in the errors (exit 2). The run itself is
// estimate_command.cc; the report estimate_report.cc.
#include "estimate_options.h"

#include <gflags/gflags.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "air_gap_flag.h"
#include "command.h"
#include "image_input_flags.h"
#include "medium_flag.h"
#include "rcm/estimation/refinement_options.h"
#include "rcm/frontend/feature_detector.h"
#include "rig_flags.h"

DEFINE_string(matches, "",
              "correspondence CSV with header frame,xl,yl,xr,yr[,t] in raw "
              "pixels (instead of images)");
DEFINE_string(features, "orb",
              "images: keypoints and descriptors: orb (fast, the default), "
              "sift (the paper's) or akaze");
DEFINE_int32(max_features, 2000, "images: keypoints per image");
DEFINE_bool(clahe, false,
            "images: equalize contrast (CLAHE) before detection, for dark "
            "or hazy water");
DEFINE_double(ratio, 0.8,
              "images: Lowe's ratio test among the candidates in a "
              "keypoint's refractive epipolar band");
DEFINE_string(search_range, "1.0,1.6",
              "images: MIN,MAX, the refractive indices matching considers "
              "before an estimate exists (and when re-acquiring)");
DEFINE_int32(picture_frame, -1,
             "images: the frame drawn in matches_by_n.png (-1: the pair in "
             "the middle of the run)");
DEFINE_string(estimator, "refine",
              "refine: robust least squares over all frames (the estimator "
              "of record); online: the same estimate updated frame by frame "
              "in constant memory; window: over the last --window frames, "
              "restarting when the medium changes; closed-form: the paper's "
              "baseline (eq. 14, mask, radially weighted mean); bundle "
              "(images only): n, cam1's turn and the trajectory from "
              "landmarks tracked over the pairs (a bundle adjustment; where "
              "the motion cannot separate n from the turn, the refine "
              "estimate with a warning)");
DEFINE_int32(window, 20,
             "window: frames in the sliding window (w_s; 20 = 1 s at 20 Hz)");
DEFINE_int32(bundle_window, 0,
             "bundle: adjust the last this many pairs (0: the whole dive)");
DEFINE_double(change_threshold, 5.0,
              "window: a frame whose own n differs from the window's by more "
              "than this many combined sigmas is inconsistent; two in a row "
              "that agree declare a change of medium");
DEFINE_string(per_frame, "",
              "also write one row per frame to this CSV: frame,t,n,sigma_n,"
              "switch (refine: each frame's own estimate; online and "
              "closed-form: the estimate so far; window: the window's "
              "estimate; switch = 1 on the first frame of a new medium)");
DEFINE_string(loss, "cauchy",
              "robust loss of the refinement's first stage: cauchy, huber or "
              "none");
DEFINE_double(loss_scale, 1.0,
              "scale of the robust loss, in pixels of distance from the "
              "refractive epipolar locus");
DEFINE_double(inlier_threshold, 2.0,
              "matches within this many pixels of their locus (and in front "
              "of both cameras) are the inliers of the final least squares; "
              "inf keeps all");
DEFINE_bool(refine_rotation, false,
            "refine: also estimate a small rotation correction of cam1 "
            "(reported with its correlation with n)");
DEFINE_string(drift_prior, "",
              "DEG[,MM[,PCT]]: how far the rig may have drifted since its "
              "calibration, per axis (cam1's rotation in degrees, its "
              "translation in millimetres) and each camera's focal lengths "
              "(percent), carried into sigma_n; default: the camchain's "
              "covariance sidecar (rcm calibrate writes it) or 0.1,0.1,0.3 "
              "(an underwater calibration's sidecar: no focal drift); MM left "
              "out is DEG, PCT left out the sidecar's or 0.3 (0,0,0 = the "
              "calibration exact)");
DEFINE_bool(self_calibrate, true,
            "refine: estimate cam1's rotation with n, with the drift prior "
            "as its prior (the data decide it where they separate it from "
            "n); --noself-calibrate holds it at the calibration's and only "
            "propagates its uncertainty");
DEFINE_bool(self_calibrate_focal, true,
            "refine: estimate each camera's focal scale with n, with the "
            "focal drift prior (--drift-prior's PCT) as its prior; "
            "--noself-calibrate-focal holds the lenses at the calibration's "
            "and only propagates the prior");
DEFINE_double(systematic_px, -1.0,
              "the matches' systematic error floor, pixels: the standard "
              "deviation of each coefficient of a smooth low-order field "
              "added to every residual, which averaging does not remove "
              "(lighting gradients, sub-pixel interpolation), carried into "
              "sigma_n; default: 0.03 for matches of the image front end "
              "(measured on renders), 0 for --matches");
DEFINE_bool(detect_systematic, true,
            "refine: test the residuals for a smooth field beyond the pixel "
            "noise (matches off the rigid scene: a water surface's mirror "
            "image, a swimmer) and, where they show one (p < 1 %), widen "
            "sigma_n by the field they estimate");
DEFINE_double(mask_eta, 0.3,
              "closed-form: use a match when sqrt|u| sqrt|v| > eta, (u, v) "
              "its normalized left coordinates");

namespace rcm::cli {

extern const char kEstimateFlagsSource[] = __FILE__;

namespace {

StatusOr<StereoFrontEndOptions> FrontEndOptionsFromFlags() {
  StereoFrontEndOptions options;
  const std::optional<FeatureType> type = FeatureTypeFromName(FLAGS_features);
  if (!type) {
    return Status::Error("unknown --features '" + FLAGS_features +
                         "' (available: orb, sift, akaze)");
  }
  options.features.type = *type;
  options.features.max_features = FLAGS_max_features;
  options.clahe.enabled = FLAGS_clahe;
  options.matching.ratio = FLAGS_ratio;
  double low = 0.0;
  double high = 0.0;
  char tail = 0;
  if (std::sscanf(FLAGS_search_range.c_str(), "%lf,%lf%c", &low, &high,
                  &tail) != 2) {
    return Status::Error("--search-range must be MIN,MAX, got '" +
                         FLAGS_search_range + "'");
  }
  options.search_range = {low, high};
  RCM_RETURN_IF_ERROR(options.search_range.Check().WithContext(
      "--search-range " + FLAGS_search_range));
  RCM_RETURN_IF_ERROR(options.Check());
  return options;
}

RefinementOptions RefinementOptionsFromFlags() {
  RefinementOptions options;
  options.loss = RobustLossFromName(FLAGS_loss).value_or(RobustLoss::kCauchy);
  options.loss_scale_px = FLAGS_loss_scale;
  options.inlier_threshold_px = FLAGS_inlier_threshold;
  options.refine_rotation = FLAGS_refine_rotation;
  options.self_calibrate_rotation = FLAGS_self_calibrate;
  options.self_calibrate_focal = FLAGS_self_calibrate_focal;
  options.detect_systematic = FLAGS_detect_systematic;
  options.systematic_px =
      FLAGS_systematic_px >= 0.0
          ? FLAGS_systematic_px
          : (FLAGS_matches.empty() ? kFrontEndSystematicPx : 0.0);
  return options;
}

// --drift-prior DEG[,MM[,PCT]] into `options` (radians, meters, relative);
// left as they are when the flag is not given.
Status DriftPriorFromFlag(RigFileOptions* options) {
  if (FLAGS_drift_prior.empty()) return Status::Ok();
  double degrees = 0.0;
  double millimeters = NAN;
  double percent = NAN;
  char tail = 0;
  const int read = std::sscanf(FLAGS_drift_prior.c_str(), "%lf,%lf,%lf%c",
                               &degrees, &millimeters, &percent, &tail);
  // MM left out: the same number as DEG (as in the default 0.1,0.1).
  if (read == 1) millimeters = degrees;
  if ((read < 1 || read > 3) || !std::isfinite(degrees) ||
      !std::isfinite(millimeters) || degrees < 0.0 || millimeters < 0.0 ||
      degrees > 10.0 || millimeters > 100.0 ||
      (read == 3 && !(percent >= 0.0 && percent <= 10.0))) {
    return Status::Error(
        "--drift-prior must be DEG[,MM[,PCT]] with 0 <= DEG <= 10, 0 <= MM <= "
        "100 and 0 <= PCT <= 10, got '" +
        FLAGS_drift_prior + "'");
  }
  options->drift_prior = {degrees * M_PI / 180.0, 1e-3 * millimeters};
  if (read == 3) options->focal_drift = 1e-2 * percent;
  return Status::Ok();
}

}  // namespace

StatusOr<EstimateCliOptions> EstimateOptionsFromFlags() {
  if (FLAGS_calib.empty()) {
    return Status::Error("--calib is required (see rcm estimate --help)");
  }
  const std::optional<EstimatorKind> estimator =
      EstimatorFromName(FLAGS_estimator);
  if (!estimator) {
    return Status::Error(
        "unknown estimator '" + FLAGS_estimator +
        "' (available: refine, online, window, closed-form, bundle)");
  }
  const bool refine = *estimator == EstimatorKind::kRefine;
  if (FLAGS_refine_rotation && !refine) {
    return Status::Error(
        "--refine-rotation works with --estimator refine only");
  }
  if (FLAGS_estimate_air_gap && (!refine || FLAGS_refine_rotation)) {
    return Status::Error(
        "--estimate-air-gap works with --estimator refine only, without "
        "--refine-rotation");
  }
  EstimateCliOptions cli;
  EstimationOptions& estimation = cli.estimation;
  estimation.estimator = *estimator;
  estimation.estimate_air_gap = FLAGS_estimate_air_gap;
  estimation.window.SetWindowFrames(FLAGS_window);
  estimation.bundle_window = FLAGS_bundle_window;
  estimation.window.change_threshold = FLAGS_change_threshold;
  if (const Status status = estimation.window.Check(); !status.ok()) {
    return status.WithContext("--window/--change-threshold");
  }
  if (!RobustLossFromName(FLAGS_loss)) {
    return Status::Error("unknown loss '" + FLAGS_loss +
                         "' (available: cauchy, huber, none)");
  }
  estimation.refinement = RefinementOptionsFromFlags();
  RCM_RETURN_IF_ERROR(estimation.refinement.Check());
  StatusOr<std::optional<MediumPrior>> medium = MediumFromFlag();
  if (!medium.ok()) return medium.status();
  cli.medium = *medium;
  estimation.closed_form.eta = FLAGS_mask_eta;
  RCM_RETURN_IF_ERROR(estimation.closed_form.Check().WithContext("--mask-eta"));
  // Each frame's own estimate, for a look at how n varies over time (from
  // images the front end's pass has them).
  estimation.per_frame_estimates =
      !FLAGS_per_frame.empty() || !FLAGS_out.empty();

  cli.images = ImageInputGiven();
  if (cli.images == !FLAGS_matches.empty()) {
    return Status::Error(
        cli.images ? "give either --matches or images, not both"
                   : "no input: give --left DIR --right DIR, --pairs LIST, "
                     "--bag BAG or --matches CSV (see rcm estimate --help)");
  }
  if (cli.images) {
    StatusOr<StereoFrontEndOptions> front_end = FrontEndOptionsFromFlags();
    if (!front_end.ok()) return front_end.status();
    cli.front_end = *front_end;
  }
  RCM_RETURN_IF_ERROR(DriftPriorFromFlag(&cli.rig));
  return cli;
}

}  // namespace rcm::cli
