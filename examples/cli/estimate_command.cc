// rcm estimate: the refractive index n from stereo correspondences.
#include <gflags/gflags.h>
#include <unistd.h>

#include <Eigen/Cholesky>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "air_gap_flag.h"
#include "command.h"
#include "image_input_flags.h"
#include "medium_flag.h"
#include "progress.h"
#include "rcm/estimation/batch_refinement.h"
#include "rcm/estimation/calibration_propagation.h"
#include "rcm/estimation/match_refractive_index.h"
#include "rcm/estimation/medium_drift.h"
#include "rcm/estimation/online_estimator.h"
#include "rcm/estimation/paper_online_estimator.h"
#include "rcm/estimation/prepared_correspondence.h"
#include "rcm/estimation/refinement_options.h"
#include "rcm/estimation/sliding_window_estimator.h"
#include "rcm/estimation/thick_port_refinement.h"
#include "rcm/frontend/stereo_front_end.h"
#include "rcm/io/atomic_file.h"
#include "rcm/io/correspondence_csv.h"
#include "rcm/io/image_file.h"
#include "rcm/io/stereo_rig_file.h"
#include "rcm/plot/line_plot.h"
#include "rcm/stereo/epipolar.h"
#include "rcm/util/number_format.h"
#include "rcm/viz/match_index_image.h"
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
              "baseline (eq. 14, mask, radially weighted mean)");
DEFINE_int32(window, 20,
             "window: frames in the sliding window (w_s; 20 = 1 s at 20 Hz)");
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
namespace {

constexpr char kEstimateUsage[] =
    "rcm estimate: the refractive index n of the medium from the stereo\n"
    "images (folders or a ROS1 bag) or correspondences of a rig calibrated\n"
    "in air.\n\n"
    "usage: rcm estimate --calib RIG.yaml --left DIR --right DIR [--out DIR]\n"
    "       rcm estimate --calib RIG.yaml --bag BAG --left-topic T0 "
    "--right-topic T1\n"
    "       rcm estimate --calib RIG.yaml --matches MATCHES.csv\n"
    "   [--estimator refine|online|window|closed-form] [--window N]\n"
    "   [--from S --to S --stride K] [--features orb|sift|akaze] [--clahe]\n"
    "   [--per-frame OUT.csv] [--json]\n\n"
    "From images, each pair's keypoints are matched within the band of the\n"
    "refractive epipolar loci of the current n (the previous pair's own\n"
    "estimate; --search-range before there is one), refined to subpixel and\n"
    "fed to the estimator. Folders pair by file name (or sorted order, or a\n"
    "--pairs list); names that are stamps (ns or s) give the times that\n"
    "--from/--to count. Bags pair the two topics by header stamp.\n\n"
    "refine fits n to the distance of every match from its refractive "
    "epipolar\nlocus (Sampson distance, pixels) over all frames: a robust "
    "stage that finds n\namong outliers, then least squares on the inliers, "
    "whose covariance gives\nsigma_n. It works on any calibrated rig. "
    "closed-form is the paper's baseline;\nit assumes a rectified rig and is "
    "biased under pixel noise (docs/design.md Sec. 3).\n\n"
    "sigma_n counts the calibration's uncertainty (the camchain's covariance\n"
    "sidecar, or a drift prior of 0.1 deg, 0.1 mm per axis and 0.3 % in\n"
    "each camera's focal lengths: --drift-prior) and the matches'\n"
    "systematic error (--systematic-px) beside the pixel noise; cam1's\n"
    "rotation is self-calibrated with its prior. An n at the\n"
    "upper bound 2 is refused; a stale calibration is named (then\n"
    "rcm calibrate --underwater).\n\n"
    "Exit status: 0 on success, 1 when the input cannot give an estimate, "
    "2 on\nwrong flags.";

// Matching again with the self-calibrated rotation when it moves pixels at
// the focal length's distance from the center by more than this (the
// band's half-width is about a pixel), at most kMaxMatchingPasses passes.
constexpr double kRematchPx = 0.5;
constexpr int kMaxMatchingPasses = 3;

// Above this deviation from a rectified pair the closed form is biased.
constexpr double kRectifiedToleranceDeg = 0.05;

double Degrees(double radians) { return radians * 180.0 / M_PI; }

// One frame of the input: consecutive correspondences with equal `frame`.
struct Frame {
  int64_t frame = 0;
  std::optional<double> timestamp;
  std::vector<StereoCorrespondence> matches;
};

std::vector<Frame> SplitFrames(
    const std::vector<StereoCorrespondence>& matches) {
  std::vector<Frame> frames;
  for (const StereoCorrespondence& match : matches) {
    if (frames.empty() || frames.back().frame != match.frame) {
      frames.push_back({match.frame, match.timestamp, {}});
    }
    frames.back().matches.push_back(match);
  }
  return frames;
}

// A row of --per-frame.
struct FrameRow {
  int64_t frame = 0;
  std::optional<double> timestamp;
  double n = NAN;
  double sigma_n = NAN;
  bool medium_switch = false;
};

std::string FormatFrameRows(const std::vector<FrameRow>& rows) {
  std::ostringstream out;
  out.precision(17);
  out << "frame,t,n,sigma_n,switch\n";
  for (const FrameRow& row : rows) {
    out << row.frame << ",";
    if (row.timestamp) out << *row.timestamp;
    out << ",";
    if (std::isfinite(row.n)) out << row.n;
    out << ",";
    if (std::isfinite(row.sigma_n)) out << row.sigma_n;
    out << "," << (row.medium_switch ? 1 : 0) << "\n";
  }
  return out.str();
}

// What every estimator reports; fields an estimator does not have stay
// NaN / empty and print as null.
struct Report {
  std::string method;  // one line for the text report
  double n = NAN;
  double sigma_n = NAN;  // the total, as the estimators report it
  double sigma_n_noise = NAN;
  double sigma_n_calibration = NAN;
  double sigma_n_systematic = NAN;
  std::optional<CalibrationPropagation> calibration;
  std::optional<FrameConsistency> consistency;
  std::optional<RotationCorrection> rotation;  // refine
  double crlb = NAN;
  double sigma_px = NAN;
  std::optional<double> n_closed_form;
  int64_t inliers = 0;
  int64_t invalid = 0;
  std::vector<FrameRow> rows;
  nlohmann::json extra = nlohmann::json::object();
  std::vector<std::string> text_lines;  // estimator-specific lines
};

// The front end's pass over an image sequence: the matches of every pair,
// each pair guided by the previous pair's own estimate.
struct ImageRun {
  std::string source;  // the source's Describe()
  std::vector<Frame> frames;
  std::vector<FrameRow> own_rows;  // each pair's own estimate
  FrontEndTimings stage_ms;        // sums over the pairs
  double read_ms = 0.0;            // decoding, summed
  double guide_ms = 0.0;           // per-pair estimates, summed
  double seconds = 0.0;            // wall clock of the pass
  int reacquired = 0;
  // Passes of matching again with the self-calibrated rotation, and that
  // rotation (zero when the pairs were matched with the calibration).
  int rematched = 0;
  Eigen::Vector3d matching_rotation = Eigen::Vector3d::Zero();
  // The pair drawn in matches_by_n.png.
  cv::Mat picture_left;
  int64_t picture_frame = -1;
  std::vector<StereoCorrespondence> picture_matches;
};

double Milliseconds(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(
             std::chrono::steady_clock::now() - start)
      .count();
}

StatusOr<ImageRun> RunFrontEnd(const StereoRig& rig, StereoImageSource* source,
                               const StereoFrontEndOptions& options,
                               const RefinementOptions& refinement) {
  StatusOr<StereoFrontEnd> front_end = StereoFrontEnd::Create(rig, options);
  if (!front_end.ok()) return front_end.status();
  RefinementOptions own_options = refinement;
  own_options.refine_rotation = false;
  ImageRun run;
  run.source = source->Describe();
  const size_t pairs = source->NumPairs();
  const size_t picture_index =
      FLAGS_picture_frame >= 0 ? std::numeric_limits<size_t>::max() : pairs / 2;
  std::optional<RefractiveIndexInterval> guide;
  Progress progress("rcm estimate: pair", pairs);
  const auto start = std::chrono::steady_clock::now();
  for (size_t i = 0; i < pairs; ++i) {
    const auto read_start = std::chrono::steady_clock::now();
    StatusOr<StereoImagePair> pair = source->ReadPair(i);
    if (!pair.ok()) return pair.status();
    run.read_ms += Milliseconds(read_start);
    StatusOr<StereoMatches> matched = front_end->Match(
        pair->left, pair->right, pair->frame, pair->timestamp, guide);
    if (!matched.ok()) {
      return matched.status().WithContext(pair->left_name + " and " +
                                          pair->right_name);
    }
    run.stage_ms.preprocess_ms += matched->timings.preprocess_ms;
    run.stage_ms.detect_ms += matched->timings.detect_ms;
    run.stage_ms.match_ms += matched->timings.match_ms;
    run.stage_ms.refine_ms += matched->timings.refine_ms;
    run.stage_ms.total_ms += matched->timings.total_ms;
    run.reacquired += matched->reacquired ? 1 : 0;

    const auto guide_start = std::chrono::steady_clock::now();
    const StatusOr<RefinementSummary> own =
        RefineRefractiveIndex(rig, matched->matches, own_options);
    run.guide_ms += Milliseconds(guide_start);
    FrameRow row{pair->frame, pair->timestamp};
    std::string status = std::to_string(matched->matches.size()) + " matches";
    if (own.ok()) {
      row.n = own->n;
      row.sigma_n = own->sigma_n;
      guide = NextPairGuide(own->n, own->sigma_n);
      status += ", n = " + FormatFixed(own->n, 4) + " +- " +
                FormatFixed(own->sigma_n, 4);
    } else {
      guide.reset();  // back to the prior search range
    }
    run.own_rows.push_back(row);
    if (i == picture_index || pair->frame == FLAGS_picture_frame) {
      run.picture_left = pair->left;
      run.picture_frame = pair->frame;
      run.picture_matches = matched->matches;
    }
    run.frames.push_back(
        {pair->frame, pair->timestamp, std::move(matched->matches)});
    progress.Update(i + 1, status);
  }
  run.seconds = Milliseconds(start) / 1000.0;
  return run;
}

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

// The estimators' shared uncertainty fields.
template <typename Estimate>
void CopyUncertainty(const Estimate& estimate, Report* report) {
  report->sigma_n = estimate.sigma_n;
  report->sigma_n_noise = estimate.sigma_n_noise;
  report->sigma_n_calibration = estimate.sigma_n_calibration;
  report->sigma_n_systematic = estimate.sigma_n_systematic;
  report->calibration = estimate.calibration;
  report->consistency = estimate.consistency;
}

std::string LossDescription(const RefinementOptions& options) {
  std::string loss(RobustLossName(options.loss));
  if (options.loss != RobustLoss::kNone) {
    loss += " " + FormatFixed(options.loss_scale_px, 2) + " px";
  }
  return loss;
}

StatusOr<Report> RunRefine(const StereoRig& rig,
                           const std::vector<StereoCorrespondence>& matches,
                           const std::vector<Frame>& frames,
                           const RefinementOptions& options,
                           const std::vector<FrameRow>* own_rows) {
  StatusOr<RefinementSummary> summary = Status::Error("not run");
  std::optional<AirGapEstimate> air_gap;
  if (FLAGS_estimate_air_gap) {
    // The thick-port model with the gap free, from the rig's ports (a
    // rig without port blocks: thin ports, the gap estimated from 0).
    const StereoRig::Ports ports = rig.ports().value_or(StereoRig::Ports{});
    ThickPortRefinementOptions thick_options;
    thick_options.base = options;
    thick_options.estimate_air_gap = true;
    StatusOr<ThickPortRefinementSummary> thick = RefineRefractiveIndexThickPort(
        rig, ports.left, ports.right, matches, thick_options);
    if (!thick.ok()) return thick.status();
    air_gap = thick->air_gap;
    summary = std::move(thick->refinement);
  } else {
    summary = RefineRefractiveIndex(rig, matches, options);
  }
  if (!summary.ok()) return summary.status();
  Report report;
  report.method =
      std::string(rig.HasThickPort()
                      ? "robust least squares on the thick-port loci "
                        "(generalized epipolar constraint of the rays in the "
                        "medium; the camchain's port blocks)"
                      : "robust least squares on the refractive epipolar "
                        "loci") +
      " (loss " + LossDescription(options) + ", inliers within " +
      FormatFixed(options.inlier_threshold_px, 2) + " px)";
  report.n = summary->n;
  CopyUncertainty(*summary, &report);
  report.rotation = summary->rotation;
  report.crlb = summary->crlb;
  report.sigma_px = summary->sigma_px;
  report.n_closed_form = summary->n_closed_form;
  report.inliers = static_cast<int64_t>(summary->inliers.size());
  report.invalid = summary->num_invalid;
  report.extra["n_seed"] = summary->n_seed;
  report.extra["n_robust"] = summary->n_robust;
  report.extra["cost"] = summary->cost;
  report.extra["iterations"] = summary->num_iterations;
  report.text_lines.push_back(
      "  seeds      closed form " +
      (summary->n_closed_form ? FormatFixed(*summary->n_closed_form, 4)
                              : std::string("n/a")) +
      ", scan " + FormatFixed(summary->n_seed, 4) + ", robust stage " +
      FormatFixed(summary->n_robust, 5));
  if (air_gap) {
    report.extra["air_gap"] = {
        {"left_m", air_gap->left_air_gap},
        {"right_m", air_gap->right_air_gap},
        {"sigma_m", air_gap->sigma},
        {"correlation_with_n", air_gap->correlation_with_n}};
    report.text_lines.push_back(
        "  air gap    " + FormatFixed(1e3 * air_gap->left_air_gap, 2) +
        " mm (left), " + FormatFixed(1e3 * air_gap->right_air_gap, 2) +
        " mm (right) +- " + FormatFixed(1e3 * air_gap->sigma, 2) +
        " mm, correlation with n " +
        FormatFixed(air_gap->correlation_with_n, 2) +
        (std::abs(air_gap->correlation_with_n) > 0.9
             ? " (hardly separable from n: measure the gap instead)"
             : ""));
  }
  if (summary->rotation) {
    const RotationCorrection& rotation = *summary->rotation;
    const Eigen::Vector3d degrees = rotation.angle_axis * 180.0 / M_PI;
    const Eigen::Vector3d sigma_degrees = rotation.sigma * 180.0 / M_PI;
    report.extra["rotation"] = {
        {"angle_axis_deg", {degrees.x(), degrees.y(), degrees.z()}},
        {"sigma_deg",
         {sigma_degrees.x(), sigma_degrees.y(), sigma_degrees.z()}},
        {"correlation_with_n",
         {rotation.correlation_with_n.x(), rotation.correlation_with_n.y(),
          rotation.correlation_with_n.z()}},
        {"multiple_correlation_with_n", rotation.multiple_correlation_with_n},
        {"with_prior", rotation.with_prior}};
    std::ostringstream line;
    line << "  rotation   cam1 "
         << (rotation.with_prior ? "self-calibrated: turned by ("
                                 : "corrected by (")
         << FormatFixed(degrees.x(), 4) << ", " << FormatFixed(degrees.y(), 4)
         << ", " << FormatFixed(degrees.z(), 4) << ") deg +- ("
         << FormatFixed(sigma_degrees.x(), 4) << ", "
         << FormatFixed(sigma_degrees.y(), 4) << ", "
         << FormatFixed(sigma_degrees.z(), 4)
         << (rotation.with_prior ? ") since the calibration" : ")")
         << "; correlation with n R = "
         << FormatFixed(rotation.multiple_correlation_with_n, 2);
    report.text_lines.push_back(line.str());
  }
  if (summary->focal) {
    const FocalScaleCorrection& focal = *summary->focal;
    report.extra["focal_scale"] = {
        {"percent", {1e2 * focal.scale[0], 1e2 * focal.scale[1]}},
        {"sigma_percent", {1e2 * focal.sigma[0], 1e2 * focal.sigma[1]}},
        {"correlation_with_n",
         {focal.correlation_with_n[0], focal.correlation_with_n[1]}}};
    report.text_lines.push_back(
        "  lenses     focal lengths self-calibrated: cam0 " +
        FormatFixed(1e2 * focal.scale[0], 3) + " +- " +
        FormatFixed(1e2 * focal.sigma[0], 3) + " %, cam1 " +
        FormatFixed(1e2 * focal.scale[1], 3) + " +- " +
        FormatFixed(1e2 * focal.sigma[1], 3) + " % since the calibration");
  }
  if (own_rows != nullptr) {
    report.rows = *own_rows;  // computed by the front end's pass
  } else if (!FLAGS_per_frame.empty() || !FLAGS_out.empty()) {
    // Each frame's own estimate, for a look at how n varies over time.
    RefinementOptions frame_options = options;
    frame_options.num_threads = 1;
    Progress progress("rcm estimate: per-frame estimates, frame",
                      frames.size());
    for (size_t i = 0; i < frames.size(); ++i) {
      progress.Update(i + 1);
      FrameRow row{frames[i].frame, frames[i].timestamp};
      const StatusOr<RefinementSummary> own =
          RefineRefractiveIndex(rig, frames[i].matches, frame_options);
      if (own.ok()) {
        row.n = own->n;
        row.sigma_n = own->sigma_n;
      }
      report.rows.push_back(row);
    }
  }
  return report;
}

// The fields the online and window estimates share.
template <typename Estimate>
void CopyEstimate(const Estimate& estimate, Report* report) {
  report->n = estimate.n;
  CopyUncertainty(estimate, report);
  report->crlb = estimate.crlb;
  report->sigma_px = estimate.sigma_px;
  report->inliers = estimate.inliers;
}

std::string FrameLabel(int64_t frame) {
  return "frame " + std::to_string(frame);
}

StatusOr<Report> RunOnline(const StereoRig& rig,
                           const std::vector<Frame>& frames,
                           const RefinementOptions& options) {
  StatusOr<OnlineRefractiveIndexEstimator> estimator =
      OnlineRefractiveIndexEstimator::Create(rig, options);
  if (!estimator.ok()) return estimator.status();
  Report report;
  int64_t invalid = 0;
  Progress progress("rcm estimate: frame", frames.size());
  for (size_t i = 0; i < frames.size(); ++i) {
    progress.Update(i + 1);
    const OnlineRefractiveIndexEstimator::FrameUpdate update =
        estimator->AddFrame(frames[i].matches);
    invalid += update.correspondences - update.usable;
    FrameRow row{frames[i].frame, frames[i].timestamp};
    if (update.cumulative.ok()) {
      row.n = update.cumulative->n;
      row.sigma_n = update.cumulative->sigma_n;
    }
    report.rows.push_back(row);
  }
  const StatusOr<OnlineRefractiveIndexEstimator::Estimate> estimate =
      estimator->Current();
  if (!estimate.ok()) return estimate.status();
  report.method =
      "online robust least squares on the refractive epipolar loci (loss " +
      LossDescription(options) + ", inliers within " +
      FormatFixed(options.inlier_threshold_px, 2) + " px of each frame's fit)";
  CopyEstimate(*estimate, &report);
  report.invalid = invalid;
  report.extra["skipped_frames"] = estimator->num_skipped_frames();
  if (estimator->num_skipped_frames() > 0) {
    report.text_lines.push_back(
        "  skipped    " + std::to_string(estimator->num_skipped_frames()) +
        " frames with fewer than " + std::to_string(options.min_inliers) +
        " usable matches");
  }
  return report;
}

StatusOr<Report> RunWindow(const StereoRig& rig,
                           const std::vector<Frame>& frames,
                           const RefinementOptions& options,
                           const SlidingWindowOptions& window_options) {
  StatusOr<SlidingWindowRefractiveIndexEstimator> estimator =
      SlidingWindowRefractiveIndexEstimator::Create(rig, options,
                                                    window_options);
  if (!estimator.ok()) return estimator.status();
  Report report;
  int64_t invalid = 0;
  std::map<int64_t, size_t> row_of_frame;
  Progress progress("rcm estimate: frame", frames.size());
  for (size_t i = 0; i < frames.size(); ++i) {
    progress.Update(i + 1);
    const SlidingWindowRefractiveIndexEstimator::WindowUpdate update =
        estimator->AddFrame(frames[i].frame, frames[i].matches);
    invalid += update.correspondences - update.usable;
    FrameRow row{frames[i].frame, frames[i].timestamp};
    if (update.window.ok()) {
      row.n = update.window->n;
      row.sigma_n = update.window->sigma_n;
    }
    row_of_frame[frames[i].frame] = report.rows.size();
    report.rows.push_back(row);
  }
  nlohmann::json switches = nlohmann::json::array();
  for (const MediumSwitch& medium_switch : estimator->switches()) {
    const auto row = row_of_frame.find(medium_switch.first_frame);
    if (row != row_of_frame.end())
      report.rows[row->second].medium_switch = true;
    switches.push_back({{"frame", medium_switch.first_frame},
                        {"detected_at_frame", medium_switch.detected_at_frame},
                        {"n_before", medium_switch.n_before},
                        {"n_after", medium_switch.n_after}});
    report.text_lines.push_back(
        "  switch     at " + FrameLabel(medium_switch.first_frame) +
        " (confirmed at " + FrameLabel(medium_switch.detected_at_frame) +
        "): n " + FormatFixed(medium_switch.n_before, 4) + " -> " +
        FormatFixed(medium_switch.n_after, 4));
  }
  const StatusOr<SlidingWindowRefractiveIndexEstimator::Estimate> estimate =
      estimator->Current();
  if (!estimate.ok()) return estimate.status();
  report.method = "sliding window of " +
                  std::to_string(window_options.window_frames) +
                  " frames, robust least squares on the refractive epipolar "
                  "loci, change of medium at z > " +
                  FormatFixed(window_options.change_threshold, 1);
  CopyEstimate(*estimate, &report);
  report.invalid = invalid;
  report.extra["switches"] = switches;
  report.extra["window"] = {{"frames", estimate->frames},
                            {"first_frame", estimate->first_frame},
                            {"last_frame", estimate->last_frame}};
  report.extra["dropped_frames"] = estimator->num_dropped_frames();
  report.extra["skipped_frames"] = estimator->num_skipped_frames();
  report.text_lines.push_back(
      "  window     " + FrameLabel(estimate->first_frame) + " to " +
      FrameLabel(estimate->last_frame) + " (" +
      std::to_string(estimate->frames) + " frames); " +
      std::to_string(estimator->switches().size()) + " change" +
      (estimator->switches().size() == 1 ? "" : "s") + " of medium");
  return report;
}

StatusOr<Report> RunClosedForm(const StereoRig& rig,
                               const std::vector<Frame>& frames,
                               const Subcommand& command) {
  PaperOnlineEstimatorOptions options;
  options.eta = FLAGS_mask_eta;
  const StereoRig::RectificationDeviation deviation =
      rig.DeviationFromRectified();
  const double deviation_deg =
      Degrees(std::max(deviation.rotation, deviation.baseline_off_axis));
  if (deviation_deg > kRectifiedToleranceDeg) {
    PrintWarning(command,
                 "the rig is " + FormatFixed(deviation_deg, 2) +
                     " deg from a rectified pair; the closed form assumes "
                     "one and is biased on this rig");
  }
  PaperOnlineEstimator estimator(rig, options);
  Report report;
  for (const Frame& frame : frames) {
    for (const StereoCorrespondence& match : frame.matches) {
      estimator.Add(match);
    }
    const std::optional<PaperOnlineEstimator::Estimate> current =
        estimator.Current();
    FrameRow row{frame.frame, frame.timestamp};
    if (current) {
      row.n = current->n;
      row.sigma_n = current->standard_error;
    }
    report.rows.push_back(row);
  }
  const std::optional<PaperOnlineEstimator::Estimate> estimate =
      estimator.Current();
  if (!estimate) {
    return Status::Error(
        "no usable correspondence: " + std::to_string(estimator.num_masked()) +
        " removed by the observability mask, " +
        std::to_string(estimator.num_invalid()) +
        " invalid; matches near the image axes do not observe n (lower "
        "--mask-eta to keep more)");
  }
  report.method = "closed form (eq. 14), mask sqrt|u|sqrt|v| > " +
                  FormatFixed(options.eta, 2) +
                  ", radially weighted mean (eq. 17)";
  report.n = estimate->n;
  report.sigma_n = estimate->standard_error;
  report.inliers = estimator.num_used();
  report.invalid = estimator.num_invalid();
  report.n_closed_form = estimate->n;
  report.extra["masked"] = estimator.num_masked();
  report.extra["mask_eta"] = options.eta;
  report.text_lines.push_back(
      "  used       " + std::to_string(estimator.num_used()) + " (masked " +
      std::to_string(estimator.num_masked()) + ", invalid " +
      std::to_string(estimator.num_invalid()) + ")");
  return report;
}

constexpr double kDegreesPerRadian = 180.0 / M_PI;

// The calibration's uncertainty as the JSON reports it (null without one).
nlohmann::json CalibrationJson(const Report& report, const StereoRig& rig) {
  if (!report.calibration || !rig.calibration_uncertainty()) return nullptr;
  const CalibrationPropagation& p = *report.calibration;
  const Eigen::Vector3d per_degree = p.dn_drotation / kDegreesPerRadian;
  const Eigen::Vector3d per_mm = 1e-3 * p.dn_dtranslation;
  const Eigen::Matrix3d rotation =
      rig.calibration_uncertainty()->RotationPriorCovariance();
  return {
      {"source", p.source},
      {"rotation", RotationModeName(p.mode)},
      {"prior_sigma_deg",
       {std::sqrt(rotation(0, 0)) * kDegreesPerRadian,
        std::sqrt(rotation(1, 1)) * kDegreesPerRadian,
        std::sqrt(rotation(2, 2)) * kDegreesPerRadian}},
      {"sensitivity_per_deg", {per_degree.x(), per_degree.y(), per_degree.z()}},
      {"sensitivity_per_mm", {per_mm.x(), per_mm.y(), per_mm.z()}},
      {"sigma_n_rotation", std::sqrt(std::max(0.0, p.variance_rotation))},
      {"sigma_n_translation", std::sqrt(std::max(0.0, p.variance_translation))},
      {"sigma_n_lenses", std::sqrt(std::max(0.0, p.variance_lenses))},
      {"sigma_n_ports", std::sqrt(std::max(0.0, p.variance_ports))},
      {"rotation_multiple_correlation", p.rotation_multiple_correlation},
      {"sigma_inflation_if_free", JsonNumber(p.rotation_sigma_inflation)}};
}

// The residuals' test for a systematic field (calibration_propagation.h);
// null when not run.
nlohmann::json SystematicFieldJson(const Report& report) {
  if (!report.calibration || report.calibration->systematic_dof == 0) {
    return nullptr;
  }
  const CalibrationPropagation& p = *report.calibration;
  return {{"chi_squared", p.systematic_chi_squared},
          {"dof", p.systematic_dof},
          {"p_value", p.systematic_p_value},
          {"detected_px", p.systematic_detected_px}};
}

nlohmann::json ConsistencyJson(const std::optional<FrameConsistency>& c) {
  if (!c) return nullptr;
  return {{"frames", c->frames},
          {"chi_squared", c->chi_squared},
          {"dof", c->dof},
          {"p_value", c->p_value},
          {"inflation", c->inflation}};
}

// Beyond this many prior sigmas the self-calibrated rotation says the
// camchain is stale (3: a 0.3 % tail of the prior in one dimension).
constexpr double kStaleRotationSigmas = 3.0;
// Above this multiple correlation a free rotation is hardly separable
// from n (sigma_n more than 3.2x its value with the rotation known).
constexpr double kHardlySeparableCorrelation = 0.95;
// A sigma_n above this tells fresh from sea water at less than one sigma
// (their indices differ by 0.007).
constexpr double kWideSigmaN = 0.007;

// Warnings about the estimate's uncertainty: a stale calibration, a free
// rotation the data hardly separate from n, frames that disagree.
std::vector<std::string> UncertaintyWarnings(const Report& report,
                                             const StereoRig& rig) {
  std::vector<std::string> warnings;
  if (report.rotation && report.calibration && rig.calibration_uncertainty()) {
    const RotationCorrection& rotation = *report.rotation;
    const Eigen::Matrix3d prior =
        rig.calibration_uncertainty()->RotationPriorCovariance();
    const Eigen::LDLT<Eigen::Matrix3d> ldlt(prior);
    if (rotation.with_prior && ldlt.info() == Eigen::Success) {
      const double sigmas =
          std::sqrt(rotation.angle_axis.dot(ldlt.solve(rotation.angle_axis)));
      if (sigmas > kStaleRotationSigmas) {
        warnings.push_back(
            "the calibration is stale: cam1 has turned by " +
            FormatFixed(rotation.angle_axis.norm() * kDegreesPerRadian, 3) +
            " deg since it was made (" + FormatFixed(sigmas, 1) +
            " drift-prior sigmas); n is self-calibrated with the rotation, "
            "but for the best n calibrate in the water (rcm calibrate "
            "--underwater) and estimate with that camchain");
      }
    }
    if (!rotation.with_prior &&
        rotation.multiple_correlation_with_n > kHardlySeparableCorrelation) {
      warnings.push_back(
          "n and cam1's rotation are hardly separable in these data "
          "(correlation R = " +
          FormatFixed(rotation.multiple_correlation_with_n, 3) +
          "): sigma_n says so, " +
          FormatFixed(report.calibration->rotation_sigma_inflation, 1) +
          "x its value with the rotation known; calibrate in the water (rcm "
          "calibrate --underwater) for a better n");
    }
  }
  // The lenses' possible change since the calibration (the focal drift
  // prior of an air calibration) is most of a sigma_n too wide to use.
  // (A share above the whole sigma_n^2 is one that the held parameters
  // fitted with the lenses cancel, not most of it.)
  if (report.calibration && report.sigma_n > kWideSigmaN &&
      report.calibration->variance_lenses >
          0.5 * report.sigma_n * report.sigma_n &&
      report.calibration->variance_lenses <= report.sigma_n * report.sigma_n) {
    warnings.push_back(
        "sigma_n " + FormatFixed(report.sigma_n, 3) +
        " is mostly the lenses' (" +
        FormatFixed(std::sqrt(report.calibration->variance_lenses), 3) +
        "): these data cannot tell a change of the focal lengths since the "
        "calibration (" +
        report.calibration->source +
        ") from n; calibrate in the water (rcm calibrate --underwater, with "
        "the air views: --air-left/--air-right) for a better n");
  }
  if (report.calibration && report.calibration->systematic_detected_px > 0.0) {
    const CalibrationPropagation& p = *report.calibration;
    warnings.push_back(
        "the residuals show a smooth field beyond the pixel noise (chi2 " +
        FormatFixed(p.systematic_chi_squared, 1) + " for " +
        std::to_string(p.systematic_dof) + " dof, " +
        FormatFixed(p.systematic_detected_px, 3) +
        " px per coefficient): matches off the rigid scene (a water "
        "surface's mirror image, a swimmer, particles) or a lens model's "
        "error; sigma_n counts it (matches' systematic error " +
        FormatFixed(p.sigma_n_systematic, 4) +
        "); matches of the rigid scene only (--matches) give a better n");
  }
  if (report.consistency && report.consistency->inflation > 1.0) {
    warnings.push_back(
        "the frames disagree beyond their sigmas (chi2 " +
        FormatFixed(report.consistency->chi_squared, 1) + " for " +
        std::to_string(report.consistency->dof) +
        " dof): sigma_n's pixel-noise share is inflated x" +
        FormatFixed(report.consistency->inflation, 2) +
        " (matches correlated over frames, or a calibration error that "
        "acts differently at other depths)");
  }
  return warnings;
}

// A probability to two significant digits ("0.49", "3.4e-05").
std::string FormatProbability(double p) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.2g", p);
  return text;
}

// What the text report says of the calibration and the frames.
std::vector<std::string> CalibrationLines(const Report& report) {
  std::vector<std::string> lines;
  if (report.calibration) {
    const CalibrationPropagation& p = *report.calibration;
    const Eigen::Vector3d tenth = 0.1 * p.dn_drotation / kDegreesPerRadian;
    lines.push_back("  calibration " + p.source + "; n moves by (" +
                    FormatFixed(tenth.x(), 4) + ", " +
                    FormatFixed(tenth.y(), 4) + ", " +
                    FormatFixed(tenth.z(), 4) +
                    ") per 0.1 deg of cam1 rotation about x, y, z");
    if (p.mode == RotationMode::kHeld) {
      lines.push_back(
          "  rotation   held at the calibration's (its uncertainty is in "
          "sigma_n)");
    } else {
      lines.push_back(
          "  observability  from the data alone, n and cam1's rotation "
          "correlate with R = " +
          FormatFixed(p.rotation_multiple_correlation, 3) +
          " (a free rotation would multiply sigma_n by " +
          FormatFixed(p.rotation_sigma_inflation, 1) + ")");
    }
  }
  if (report.consistency) {
    const FrameConsistency& c = *report.consistency;
    const bool disagree = c.inflation > 1.0;
    lines.push_back("  frames     " + std::to_string(c.frames) +
                    (disagree ? " disagree beyond" : " agree within") +
                    " their sigmas: chi2 " + FormatFixed(c.chi_squared, 1) +
                    " for " + std::to_string(c.dof) + " dof (p " +
                    FormatProbability(c.p_value) + ")" +
                    (disagree
                         ? "; the pixel-noise share of sigma_n is inflated x" +
                               FormatFixed(c.inflation, 2)
                         : ""));
  }
  return lines;
}

// n per frame with its 1-sigma band, and the final estimate.
cv::Mat PlotPerFrame(const Report& report) {
  std::vector<double> x, n, low, high;
  for (const FrameRow& row : report.rows) {
    if (!std::isfinite(row.n)) continue;
    x.push_back(static_cast<double>(row.frame));
    n.push_back(row.n);
    const double sigma = std::isfinite(row.sigma_n) ? row.sigma_n : 0.0;
    low.push_back(row.n - sigma);
    high.push_back(row.n + sigma);
  }
  LinePlot plot;
  plot.SetTitle("n = " + FormatFixed(report.n, 5) + " +- " +
                FormatFixed(report.sigma_n, 5) + " (" + FLAGS_estimator + ")");
  plot.SetXLabel("frame");
  plot.SetYLabel("refractive index n");
  const std::string what = FLAGS_estimator == "refine"   ? "each frame alone"
                           : FLAGS_estimator == "window" ? "window estimate"
                                                         : "estimate so far";
  if (!x.empty()) {
    plot.AddBand(x, low, high, what + ": 1 sigma", PaletteColor(7), 0.2);
    plot.AddLine(x, n, what, LineStyle{PaletteColor(7)});
    plot.AddMarkers(x, n, "",
                    MarkerStyle{PaletteColor(7), MarkerShape::kCircle, 3.0});
  }
  if (std::isfinite(report.n)) {
    plot.AddHorizontalLine(report.n, "final estimate",
                           LineStyle{PaletteColor(0), 2.0});
  }
  for (const FrameRow& row : report.rows) {
    if (row.medium_switch) {
      plot.AddVerticalMarker(static_cast<double>(row.frame) - 0.5, "switch",
                             LineStyle{PaletteColor(3), 1.5, 6.0, 4.0});
    }
  }
  return plot.Render(1000, 600);
}

// The paper's Fig. 6b: a pair's matches colored by their own n.
cv::Mat MatchesByIndexPicture(const StereoRig& rig, const ImageRun& run,
                              double n) {
  const Eigen::Matrix3d essential = EssentialMatrix(rig.right_from_left());
  std::vector<Eigen::Vector2d> pixels;
  std::vector<std::optional<double>> values;
  int with_value = 0;
  for (const StereoCorrespondence& match : run.picture_matches) {
    pixels.push_back(match.left_pixel);
    const std::optional<PreparedCorrespondence> prepared =
        PrepareCorrespondence(rig, match);
    values.push_back(prepared ? RefractiveIndexOfMatch(essential, *prepared)
                              : std::nullopt);
    with_value += values.back() ? 1 : 0;
  }
  MatchIndexImageOptions options;
  options.center = std::isfinite(n) ? n : 1.333;
  options.half_range = 0.05;
  options.title = "frame " + std::to_string(run.picture_frame) + ": " +
                  std::to_string(with_value) + " of " +
                  std::to_string(pixels.size()) +
                  " matches by their own n (rings: none in [1, 2])";
  return DrawMatchesByRefractiveIndex(run.picture_left, pixels, values,
                                      options);
}

int RunEstimate();

}  // namespace

extern const Subcommand kEstimateCommand = {
    "estimate",
    "refractive index n from stereo images or correspondences",
    kEstimateUsage,
    {__FILE__, kRigFlagsSource, kImageInputFlagsSource, kAirGapFlagSource,
     kMediumFlagSource},
    RunEstimate};

namespace {

int RunEstimate() {
  const Subcommand& command = kEstimateCommand;
  if (FLAGS_calib.empty()) {
    PrintError(command, "--calib is required (see rcm estimate --help)");
    return kExitUsage;
  }
  const std::vector<std::string> estimators = {"refine", "online", "window",
                                               "closed-form"};
  if (std::find(estimators.begin(), estimators.end(), FLAGS_estimator) ==
      estimators.end()) {
    PrintError(command,
               "unknown estimator '" + FLAGS_estimator +
                   "' (available: refine, online, window, closed-form)");
    return kExitUsage;
  }
  if (FLAGS_refine_rotation && FLAGS_estimator != "refine") {
    PrintError(command, "--refine-rotation works with --estimator refine only");
    return kExitUsage;
  }
  if (FLAGS_estimate_air_gap &&
      (FLAGS_estimator != "refine" || FLAGS_refine_rotation)) {
    PrintError(command,
               "--estimate-air-gap works with --estimator refine only, "
               "without --refine-rotation");
    return kExitUsage;
  }
  SlidingWindowOptions window_options;
  window_options.window_frames = FLAGS_window;
  window_options.change_threshold = FLAGS_change_threshold;
  window_options.confirm_frames =
      std::min(window_options.confirm_frames, std::max(1, FLAGS_window));
  if (const Status status = window_options.Check(); !status.ok()) {
    PrintError(command, "--window/--change-threshold: " + status.message());
    return kExitUsage;
  }
  if (!RobustLossFromName(FLAGS_loss)) {
    PrintError(command, "unknown loss '" + FLAGS_loss +
                            "' (available: cauchy, huber, none)");
    return kExitUsage;
  }
  const RefinementOptions refinement = RefinementOptionsFromFlags();
  if (const Status status = refinement.Check(); !status.ok()) {
    PrintError(command, status.message());
    return kExitUsage;
  }
  const StatusOr<std::optional<MediumPrior>> medium = MediumFromFlag();
  if (!medium.ok()) {
    PrintError(command, medium.status().message());
    return kExitUsage;
  }
  PaperOnlineEstimatorOptions paper_options;
  paper_options.eta = FLAGS_mask_eta;
  if (const Status status = paper_options.Check(); !status.ok()) {
    PrintError(command, "--mask-eta: " + status.message());
    return kExitUsage;
  }

  const bool images = ImageInputGiven();
  if (images == !FLAGS_matches.empty()) {
    PrintError(command,
               images ? "give either --matches or images, not both"
                      : "no input: give --left DIR --right DIR, --pairs "
                        "LIST, --bag BAG or --matches CSV (see rcm estimate "
                        "--help)");
    return kExitUsage;
  }
  std::optional<StereoFrontEndOptions> front_end_options;
  if (images) {
    StatusOr<StereoFrontEndOptions> options = FrontEndOptionsFromFlags();
    if (!options.ok()) {
      PrintError(command, options.status().message());
      return kExitUsage;
    }
    front_end_options = *options;
  }

  RigFileOptions rig_options;
  if (const Status drift = DriftPriorFromFlag(&rig_options); !drift.ok()) {
    PrintError(command, drift.message());
    return kExitUsage;
  }
  const StatusOr<StereoRig> rig = ReadStereoRig(
      FLAGS_calib, FLAGS_left_camera, FLAGS_right_camera, rig_options);
  if (!rig.ok()) {
    PrintError(command, rig.status().message());
    return kExitFailure;
  }
  if (rig->HasThickPort() && FLAGS_estimator != "refine") {
    PrintError(command,
               FLAGS_calib +
                   " gives a thick port (an air gap or glass), which only "
                   "--estimator refine models; the " +
                   FLAGS_estimator +
                   " estimator assumes the paper's thin port");
    return kExitUsage;
  }
  // The output folder first: a run is not wasted on one that cannot be
  // written.
  if (!FLAGS_out.empty()) {
    std::error_code error;
    std::filesystem::create_directories(FLAGS_out, error);
    if (error || !std::filesystem::is_directory(FLAGS_out)) {
      PrintError(command, FLAGS_out + ": cannot create the output folder" +
                              (error ? " (" + error.message() + ")" : ""));
      return kExitFailure;
    }
  }

  std::vector<StereoCorrespondence> matches;
  std::vector<Frame> frames;
  std::optional<ImageRun> run;
  if (images) {
    StatusOr<std::unique_ptr<StereoImageSource>> source =
        OpenImageInputFromFlags();
    if (!source.ok()) {
      PrintError(command, source.status().message());
      return kExitFailure;
    }
    // Matching searches the refractive epipolar band of the rig, so a rig
    // that has turned since its calibration loses (and biases) the matches
    // that the turn moves out of the band. When the self-calibration finds
    // a turn that moves pixels by more than kRematchPx, the pairs are
    // matched again with the rig turned by it (the estimate itself keeps
    // the calibration and its prior), until the turn settles.
    StereoRig matching_rig = *rig;
    Eigen::Vector3d applied = Eigen::Vector3d::Zero();
    const double focal = std::max({rig->left().fx(), rig->left().fy(),
                                   rig->right().fx(), rig->right().fy()});
    for (int pass_index = 0;; ++pass_index) {
      StatusOr<ImageRun> pass = RunFrontEnd(matching_rig, source->get(),
                                            *front_end_options, refinement);
      if (!pass.ok()) {
        PrintError(command, pass.status().message());
        return kExitFailure;
      }
      const int rematched = run ? run->rematched + 1 : 0;
      run = std::move(*pass);
      run->rematched = rematched;
      run->matching_rotation = applied;
      frames = std::move(run->frames);
      matches.clear();
      for (const Frame& frame : frames) {
        matches.insert(matches.end(), frame.matches.begin(),
                       frame.matches.end());
      }
      if (FLAGS_estimator != "refine" || pass_index + 1 >= kMaxMatchingPasses) {
        break;
      }
      const StatusOr<RefinementSummary> pooled =
          RefineRefractiveIndex(*rig, matches, refinement);
      if (!pooled.ok() || !pooled->rotation || !pooled->rotation->with_prior ||
          (pooled->rotation->angle_axis - applied).norm() * focal <=
              kRematchPx) {
        break;
      }
      applied = pooled->rotation->angle_axis;
      StatusOr<StereoRig> turned = rig->WithCam1Moved(applied);
      if (!turned.ok()) break;
      matching_rig = std::move(turned).value();
    }
  } else {
    StatusOr<std::vector<StereoCorrespondence>> read =
        ReadCorrespondenceCsv(FLAGS_matches);
    if (!read.ok()) {
      PrintError(command, read.status().message());
      return kExitFailure;
    }
    matches = std::move(*read);
    // Frames in time order; matches of a frame stay in file order.
    std::stable_sort(
        matches.begin(), matches.end(),
        [](const StereoCorrespondence& a, const StereoCorrespondence& b) {
          return a.frame < b.frame;
        });
    frames = SplitFrames(matches);
  }

  StatusOr<Report> report = Status::Error("no estimator");
  if (FLAGS_estimator == "closed-form") {
    report = RunClosedForm(*rig, frames, command);
  } else if (FLAGS_estimator == "online") {
    report = RunOnline(*rig, frames, refinement);
  } else if (FLAGS_estimator == "window") {
    report = RunWindow(*rig, frames, refinement, window_options);
  } else {
    report = RunRefine(*rig, matches, frames, refinement,
                       run ? &run->own_rows : nullptr);
  }
  if (!report.ok()) {
    PrintError(command, report.status().message());
    return kExitFailure;
  }
  for (const std::string& warning : UncertaintyWarnings(*report, *rig)) {
    PrintWarning(command, warning);
  }
  // The medium (--medium): the estimate against it, and with the
  // refinement of thin ports cam1's rotation assuming it.
  nlohmann::json medium_json = nullptr;
  std::vector<std::string> medium_lines;
  if (*medium) {
    const MediumPrior& water = **medium;
    const MediumCheck check =
        CheckAgainstMedium(report->n, report->sigma_n, water);
    medium_json = MediumJson(water, check);
    medium_lines.push_back("  medium     " + water.Describe() + ": n is " +
                           FormatFixed(check.z, 1) + " sigma from it");
    if (check.contradicts) {
      PrintWarning(command,
                   check.message +
                       ": the camchain may no longer describe the rig (it "
                       "turned since the calibration?), or the water is "
                       "another");
    }
    if (FLAGS_estimator == "refine" && !rig->HasThickPort()) {
      const StatusOr<MediumDrift> drift =
          EstimateDriftAssumingMedium(*rig, matches, refinement, water);
      if (drift.ok()) {
        const Eigen::Vector3d degrees =
            drift->assuming_medium.rotation->angle_axis * 180.0 / M_PI;
        medium_json["assuming_medium"] = {
            {"n", drift->assuming_medium.n},
            {"sigma_n", drift->assuming_medium.sigma_n},
            {"rotation_deg", {degrees.x(), degrees.y(), degrees.z()}},
            {"turned_deg", drift->angle * 180.0 / M_PI},
            {"sigma_turned_deg", drift->sigma_angle * 180.0 / M_PI},
            {"turned", drift->turned}};
        medium_lines.push_back("             " + drift->message);
        if (drift->turned) {
          PrintWarning(command, "the calibration is stale: " + drift->message +
                                    "; calibrate in the water (rcm calibrate "
                                    "--underwater) or re-calibrate in air");
        }
      } else {
        medium_json["assuming_medium_error"] = drift.status().message();
        medium_lines.push_back("             " + drift.status().message());
      }
    }
  }

  const StereoRig::RectificationDeviation deviation =
      rig->DeviationFromRectified();
  nlohmann::json json;
  json["estimator"] = FLAGS_estimator;
  json["port"] = rig->HasThickPort() ? "thick" : "thin";
  json["n"] = JsonNumber(report->n);
  json["sigma_n"] = JsonNumber(report->sigma_n);
  json["sigma_n_noise"] = JsonNumber(report->sigma_n_noise);
  json["sigma_n_calibration"] = JsonNumber(report->sigma_n_calibration);
  json["sigma_n_systematic"] = JsonNumber(report->sigma_n_systematic);
  json["systematic_px"] = refinement.systematic_px;
  json["systematic_field"] = SystematicFieldJson(*report);
  json["calibration"] = CalibrationJson(*report, *rig);
  json["consistency"] = ConsistencyJson(report->consistency);
  json["n_closed_form"] = JsonNumber(report->n_closed_form);
  json["crlb"] = JsonNumber(report->crlb);
  json["sigma_px"] = JsonNumber(report->sigma_px);
  json["inliers"] = report->inliers;
  json["invalid"] = report->invalid;
  json["correspondences"] = matches.size();
  json["frames"] = frames.size();
  json.update(report->extra);
  json["medium"] = medium_json;
  json["rig"] = {
      {"calib", FLAGS_calib},
      {"left", FLAGS_left_camera},
      {"right", FLAGS_right_camera},
      {"baseline_m", rig->Baseline()},
      {"rotation_deg", Degrees(deviation.rotation)},
      {"baseline_off_axis_deg", Degrees(deviation.baseline_off_axis)}};
  if (run) {
    const double pairs = std::max<double>(1.0, frames.size());
    json["images"] = {
        {"source", run->source},
        {"pairs", frames.size()},
        {"features", FLAGS_features},
        {"clahe", FLAGS_clahe},
        {"matches_per_pair", matches.size() / pairs},
        {"reacquired_pairs", run->reacquired},
        {"rematched", run->rematched},
        {"matching_rotation_deg",
         {run->matching_rotation.x() * 180.0 / M_PI,
          run->matching_rotation.y() * 180.0 / M_PI,
          run->matching_rotation.z() * 180.0 / M_PI}},
        {"pairs_per_second", frames.size() / std::max(run->seconds, 1e-9)},
        {"ms_per_pair",
         {{"decode", run->read_ms / pairs},
          {"preprocess", run->stage_ms.preprocess_ms / pairs},
          {"detect", run->stage_ms.detect_ms / pairs},
          {"match", run->stage_ms.match_ms / pairs},
          {"refine", run->stage_ms.refine_ms / pairs},
          {"own_estimate", run->guide_ms / pairs}}}};
  } else {
    json["matches"] = FLAGS_matches;
  }

  // Files: each written whole or not at all (atomic), the summary last.
  std::vector<std::string> written;
  const auto write = [&](const std::string& path, const Status& status) {
    if (!status.ok()) {
      PrintError(command, status.message());
      return false;
    }
    written.push_back(path);
    return true;
  };
  if (!FLAGS_per_frame.empty() &&
      !write(FLAGS_per_frame,
             WriteFileAtomically(FLAGS_per_frame,
                                 FormatFrameRows(report->rows)))) {
    return kExitFailure;
  }
  if (!FLAGS_out.empty()) {
    const std::filesystem::path out(FLAGS_out);
    const std::string per_frame = (out / "per_frame.csv").string();
    const std::string plot = (out / "n_per_frame.png").string();
    if (!write(per_frame,
               WriteFileAtomically(per_frame, FormatFrameRows(report->rows))) ||
        !write(plot, WritePng(PlotPerFrame(*report), plot))) {
      return kExitFailure;
    }
    if (run) {
      const std::string csv = (out / "matches.csv").string();
      if (!write(csv, WriteCorrespondenceCsv(csv, matches))) {
        return kExitFailure;
      }
      if (!run->picture_left.empty()) {
        const std::string picture = (out / "matches_by_n.png").string();
        if (!write(picture,
                   WritePng(MatchesByIndexPicture(*rig, *run, report->n),
                            picture))) {
          return kExitFailure;
        }
      }
    }
    const std::string summary = (out / "estimate.json").string();
    if (!write(summary, WriteFileAtomically(summary, json.dump(2) + "\n"))) {
      return kExitFailure;
    }
  }
  if (FLAGS_json) {
    std::cout << json.dump(2) << std::endl;
    return kExitOk;
  }

  const double deviation_deg =
      Degrees(std::max(deviation.rotation, deviation.baseline_off_axis));
  std::ostringstream text;
  text << "rcm estimate: " << report->method << "\n"
       << "  rig        " << FLAGS_calib << " (" << FLAGS_left_camera
       << " left, " << FLAGS_right_camera << " right), baseline "
       << FormatFixed(rig->Baseline(), 4) << " m, "
       << FormatFixed(deviation_deg, 3) << " deg from rectified\n";
  if (run) {
    const double pairs = std::max<double>(1.0, frames.size());
    text << "  images     " << run->source << "\n"
         << "  front end  " << FLAGS_features << (FLAGS_clahe ? " + CLAHE" : "")
         << ": " << FormatFixed(matches.size() / pairs, 0)
         << " matches per pair, "
         << FormatFixed(frames.size() / std::max(run->seconds, 1e-9), 1)
         << " pairs/s (ms per pair: decode "
         << FormatFixed(run->read_ms / pairs, 1) << ", detect "
         << FormatFixed(run->stage_ms.detect_ms / pairs, 1) << ", match "
         << FormatFixed(run->stage_ms.match_ms / pairs, 1) << ", refine "
         << FormatFixed(run->stage_ms.refine_ms / pairs, 1) << ", estimate "
         << FormatFixed(run->guide_ms / pairs, 1) << ")\n";
    if (run->rematched > 0) {
      text << "  re-matched " << run->rematched
           << (run->rematched == 1 ? " time" : " times")
           << " with cam1 turned by "
           << FormatFixed(run->matching_rotation.norm() * 180.0 / M_PI, 3)
           << " deg (the self-calibrated rotation), so that the matching "
              "band follows the rig\n";
    }
    if (run->reacquired > 0) {
      text << "  re-acquired " << run->reacquired
           << " pairs whose matches left the band of the estimate (a change "
              "of medium?)\n";
    }
  } else {
    text << "  matches    " << FLAGS_matches << ": " << matches.size()
         << " correspondences in " << frames.size() << " frame"
         << (frames.size() == 1 ? "" : "s") << "\n";
  }
  if (FLAGS_estimator != "closed-form") {
    text << "  inliers    " << report->inliers
         << (FLAGS_estimator == "window" ? " in the window" : "") << " ("
         << report->invalid << " could not be undistorted)\n";
  }
  for (const std::string& line : report->text_lines) text << line << "\n";
  if (FLAGS_estimator == "closed-form") {
    text << "  n          " << FormatFixed(report->n, 5) << " +- "
         << FormatFixed(report->sigma_n, 5) << " (standard error)\n";
  } else {
    text << "  n          " << FormatFixed(report->n, 5) << " +- "
         << FormatFixed(report->sigma_n, 5) << " (1 sigma: pixel noise "
         << FormatFixed(report->sigma_n_noise, 5) << ", calibration "
         << FormatFixed(report->sigma_n_calibration, 5)
         << (report->sigma_n_systematic > 0.0
                 ? ", matches' systematic error " +
                       FormatFixed(report->sigma_n_systematic, 5)
                 : std::string())
         << "; Cramer-Rao bound " << FormatFixed(report->crlb, 5)
         << " with the calibration exact)\n"
         << "  pixel noise " << FormatFixed(report->sigma_px, 3)
         << " px (estimated from the inliers)\n";
    for (const std::string& line : CalibrationLines(*report)) {
      text << line << "\n";
    }
  }
  for (const std::string& line : medium_lines) text << line << "\n";
  if (!written.empty()) {
    text << "  wrote     ";
    for (const std::string& path : written) text << " " << path;
    text << "\n";
  }
  std::cout << text.str() << std::flush;
  return kExitOk;
}

}  // namespace
}  // namespace rcm::cli
