#include "rcm/estimation/online_estimator.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <utility>

#include "rcm/estimation/prepared_correspondence.h"
#include "rcm/estimation/robust_locus_fit.h"
#include "rcm/geometry/epipolar.h"

namespace rcm {

StatusOr<LocusEstimate> EstimateFromLocusCost(
    const LocusCostFunction& cost, const RefinementOptions& options) {
  const int64_t inliers = cost.num_matches();
  if (inliers < options.min_inliers) {
    std::ostringstream message;
    message << "too few inliers: " << inliers << ", at least "
            << options.min_inliers << " needed";
    return Status::Error(message.str());
  }
  const LocusCostFunction::Minimum minimum = cost.Minimize();
  const double crlb_per_px = minimum.information > 0.0
                                 ? 1.0 / std::sqrt(minimum.information)
                                 : std::numeric_limits<double>::infinity();
  if (!(crlb_per_px <= options.max_crlb_per_px)) {
    std::ostringstream message;
    message << "the correspondences do not observe n: at 1 px of noise its "
               "uncertainty would be "
            << crlb_per_px << " (limit " << options.max_crlb_per_px
            << "); matches on the image axes or far away carry no "
               "information on n";
    return Status::Error(message.str());
  }
  LocusEstimate estimate;
  estimate.n = minimum.n;
  estimate.inliers = inliers;
  // The interpolant of C can dip a rounding error below 0 on exact data.
  estimate.sigma_px =
      std::sqrt(std::max(0.0, minimum.cost) / static_cast<double>(inliers - 1));
  estimate.sigma_n = estimate.sigma_px * crlb_per_px;
  estimate.crlb = estimate.sigma_n;
  return estimate;
}

FrameFit FitFrame(const StereoRig& rig,
                  const std::vector<StereoCorrespondence>& frame_matches,
                  const RefinementOptions& options) {
  FrameFit fit;
  const Eigen::Matrix3d essential = EssentialMatrix(rig.right_from_left());
  fit.correspondences = static_cast<int64_t>(frame_matches.size());
  const PreparedCorrespondences prepared =
      PrepareCorrespondences(rig, frame_matches);
  const std::vector<PreparedCorrespondence>& matches = prepared.prepared;
  fit.usable = static_cast<int64_t>(matches.size());
  if (fit.usable < options.min_inliers) {
    std::ostringstream message;
    message << "frame skipped: " << fit.usable << " usable matches of "
            << fit.correspondences << ", at least " << options.min_inliers
            << " needed";
    fit.estimate = Status::Error(message.str());
    return fit;
  }
  fit.skipped = false;

  // Stage 1 on the frame alone, and its inliers.
  fit.n_robust = MinimizeRobustLocusCost(essential, matches, options);
  std::vector<PreparedCorrespondence> inlier_matches;
  std::vector<int64_t> inlier_sources;
  for (const int64_t i : ClassifyLocusInliers(rig.right_from_left(), matches,
                                              fit.n_robust, options)) {
    inlier_matches.push_back(matches[i]);
    inlier_sources.push_back(prepared.source_index[i]);
  }
  std::vector<int64_t> rejected;
  fit.cost.AddMatches(essential, inlier_matches, options.num_threads,
                      &rejected);
  // Matches whose residual is undefined somewhere in [1, 2] (at an
  // epipole) are left out of C_f; drop them from the reported inliers too.
  fit.inliers.reserve(inlier_sources.size() - rejected.size());
  for (size_t i = 0, r = 0; i < inlier_sources.size(); ++i) {
    if (r < rejected.size() && rejected[r] == static_cast<int64_t>(i)) {
      ++r;
      continue;
    }
    fit.inliers.push_back(inlier_sources[i]);
  }
  fit.estimate = EstimateFromLocusCost(fit.cost, options);

  // The calibration's share needs the inliers' normal equations.
  if (rig.calibration_uncertainty()) {
    const CalibrationParameterLayout layout = CalibrationParameterLayout::Of(rig);
    fit.normal_equations = LocusNormalEquations(layout.Size());
    std::vector<StereoCorrespondence> raw;
    raw.reserve(fit.inliers.size());
    for (const int64_t i : fit.inliers) raw.push_back(frame_matches[i]);
    std::vector<PreparedCorrespondence> kept;
    kept.reserve(fit.inliers.size());
    for (size_t i = 0, r = 0; i < inlier_matches.size(); ++i) {
      if (r < rejected.size() && rejected[r] == static_cast<int64_t>(i)) {
        ++r;
        continue;
      }
      kept.push_back(inlier_matches[i]);
    }
    std::vector<int64_t> all(kept.size());
    for (size_t i = 0; i < all.size(); ++i) all[i] = static_cast<int64_t>(i);
    AccumulateLocusNormalEquations(
        rig, raw, kept, all, fit.estimate.ok() ? fit.estimate->n : fit.n_robust,
        Eigen::Vector3d::Zero(), &fit.normal_equations);
  }
  return fit;
}

StatusOr<CalibratedLocusEstimate> EstimateWithCalibration(
    const StereoRig& rig, const LocusCostFunction& cost,
    const LocusNormalEquations& normal_equations,
    const FrameEstimateSums& frame_estimates,
    const RefinementOptions& options) {
  const StatusOr<LocusEstimate> locus = EstimateFromLocusCost(cost, options);
  if (!locus.ok()) return locus.status();
  CalibratedLocusEstimate estimate;
  estimate.locus = *locus;
  estimate.consistency =
      FrameConsistencyOf(frame_estimates, locus->n, locus->sigma_px);
  const double inflation =
      estimate.consistency ? estimate.consistency->inflation : 1.0;
  estimate.sigma_n_noise = locus->sigma_n * inflation;
  if (rig.calibration_uncertainty()) {
    StatusOr<CalibrationPropagation> propagation = PropagateCalibration(
        normal_equations, CalibrationParameterLayout::Of(rig),
        *rig.calibration_uncertainty(), RotationMode::kHeld, locus->sigma_px,
        inflation);
    if (!propagation.ok()) return propagation.status();
    estimate.sigma_n_calibration = propagation->sigma_n_calibration;
    estimate.calibration = *propagation;
  }
  estimate.sigma_n =
      std::hypot(estimate.sigma_n_noise, estimate.sigma_n_calibration);
  return estimate;
}

OnlineRefractiveIndexEstimator::OnlineRefractiveIndexEstimator(
    const StereoRig& rig, const RefinementOptions& options)
    : rig_(rig),
      options_(options),
      normal_equations_(CalibrationParameterLayout::Of(rig).Size()) {}

StatusOr<OnlineRefractiveIndexEstimator> OnlineRefractiveIndexEstimator::Create(
    const StereoRig& rig, const RefinementOptions& options) {
  RCM_RETURN_IF_ERROR(options.Check());
  if (options.refine_rotation) {
    return Status::Error(
        "the online estimator estimates n alone: the rotation correction "
        "(refine_rotation) is available in the batch refinement only");
  }
  return OnlineRefractiveIndexEstimator(rig, options);
}

OnlineRefractiveIndexEstimator::FrameUpdate
OnlineRefractiveIndexEstimator::AddFrame(
    const std::vector<StereoCorrespondence>& frame_matches) {
  FrameUpdate update;
  update.frame = num_frames_++;
  num_correspondences_ += static_cast<int64_t>(frame_matches.size());
  FrameFit fit = FitFrame(rig_, frame_matches, options_);
  update.correspondences = fit.correspondences;
  update.usable = fit.usable;
  update.skipped = fit.skipped;
  if (fit.skipped) {
    ++num_skipped_frames_;
  } else {
    cost_.Add(fit.cost);
    if (rig_.calibration_uncertainty()) {
      normal_equations_.Add(fit.normal_equations);
    }
    if (fit.estimate.ok()) {
      frame_estimates_.Add(fit.estimate->n, fit.cost.Information(fit.estimate->n));
    }
    update.inliers = std::move(fit.inliers);
  }
  update.frame_estimate = std::move(fit.estimate);
  update.cumulative = Current();
  return update;
}

StatusOr<OnlineRefractiveIndexEstimator::Estimate>
OnlineRefractiveIndexEstimator::Current() const {
  const StatusOr<CalibratedLocusEstimate> calibrated = EstimateWithCalibration(
      rig_, cost_, normal_equations_, frame_estimates_, options_);
  if (!calibrated.ok()) return calibrated.status();
  const LocusEstimate& locus = calibrated->locus;
  Estimate estimate;
  estimate.n = locus.n;
  estimate.sigma_n = calibrated->sigma_n;
  estimate.sigma_n_noise = calibrated->sigma_n_noise;
  estimate.sigma_n_calibration = calibrated->sigma_n_calibration;
  estimate.crlb = locus.crlb;
  estimate.sigma_px = locus.sigma_px;
  estimate.consistency = calibrated->consistency;
  estimate.calibration = calibrated->calibration;
  estimate.inliers = locus.inliers;
  estimate.correspondences = num_correspondences_;
  estimate.frames = num_frames_;
  return estimate;
}

}  // namespace rcm
