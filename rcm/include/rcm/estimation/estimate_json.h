// The one serialization of RefractiveIndexEstimate: JSON whose keys are its
// fields' names, written by `rcm estimate --json` (and estimate.json), by
// rcm.Estimate.to_dict() in Python and by the demo. NaN and unset fields
// are null. Angles in the JSON are degrees and lengths millimetres or
// metres as each key's suffix says (_deg, _mm, _m); the per-frame series is
// the CSV of EstimatePerFrameCsv, not part of the JSON.
//
//   estimator, port, method, n, sigma_n, sigma_n_noise,
//   sigma_n_calibration, sigma_n_systematic, systematic_px, crlb, sigma_px,
//   n_closed_form, inliers, invalid, correspondences, frames   numbers
//   calibration   {source, rotation (held | self-calibrated | ...),
//                  prior_sigma_deg[3], sensitivity_per_deg[3] (dn/dr),
//                  sensitivity_per_mm[3] (dn/dt), sigma_n_rotation,
//                  sigma_n_translation, sigma_n_lenses, sigma_n_ports,
//                  sigma_n_medium, rotation_multiple_correlation,
//                  sigma_inflation_if_free}
//   systematic_field {chi_squared, dof, p_value, detected_px}
//   consistency   {frames, chi_squared, dof, p_value, inflation}
//   rotation      {angle_axis_deg[3], sigma_deg[3], correlation_with_n[3],
//                  multiple_correlation_with_n, with_prior}
//   focal_scale   {percent[2], sigma_percent[2], correlation_with_n[2]}
//   air_gap       {left_m, right_m, sigma_m, correlation_with_n}
//   n_seed, n_robust, cost, iterations           (refine)
//   skipped_frames, dropped_frames, window {frames, first_frame,
//   last_frame}, switches [{frame, detected_at_frame, n_before, n_after}]
//                                                (online, window)
//   masked, mask_eta                             (closed-form)
//   frames_used, landmarks (in the solve), tracks (landmarks seen in two
//   keyframes or more), observations (inlier pixels), motion (one line)
//                                                (bundle)
//   warnings      [one line each]
#ifndef RCM_ESTIMATION_ESTIMATE_JSON_H_
#define RCM_ESTIMATION_ESTIMATE_JSON_H_

#include <string>

#include "rcm/estimation/refractive_index_estimate.h"

namespace rcm {

// The JSON object, as text (indent < 0: one line; else pretty-printed with
// that indent). Keys of estimators that did not run are left out (those of
// the refine estimator's seeds for the window estimator, and so on); the
// keys every estimator has are always there.
std::string EstimateJson(const RefractiveIndexEstimate& estimate,
                         int indent = 2);

// The per-frame series as CSV: frame,t,n,sigma_n,switch (empty t, n,
// sigma_n when unknown; switch 1 on the first frame of a new medium).
std::string EstimatePerFrameCsv(const RefractiveIndexEstimate& estimate);

// The bundle's trajectory in the TUM format: a comment line, then one line
// per keyframe, "t tx ty tz qx qy qz qw" (world_from_cam0 in the first
// keyframe's frame, metres, Hamilton quaternion; t the keyframe's time in
// seconds, or its frame index without one). Only the comment without a
// bundle.
std::string EstimateTrajectoryTum(const RefractiveIndexEstimate& estimate);

}  // namespace rcm

#endif  // RCM_ESTIMATION_ESTIMATE_JSON_H_
