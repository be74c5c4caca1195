#include "rcm/estimation/online_estimator.h"

#include <glog/logging.h>

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <utility>

#include "rcm/estimation/batch_refinement.h"
#include "rcm/estimation/prepared_correspondence.h"
#include "rcm/estimation/robust_locus_fit.h"
#include "rcm/stereo/epipolar.h"

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

FrameFit FitFrame(
    const StereoRig& rig,
    const std::vector<StereoCorrespondence>& frame_matches,
    const RefinementOptions& options,
    const std::optional<Eigen::Vector3d>& linearization_rotation) {
  FrameFit fit;
  const Eigen::Matrix3d essential = EssentialMatrix(rig.right_from_left());
  fit.correspondences = static_cast<int64_t>(frame_matches.size());
  PreparedCorrespondences prepared = PrepareCorrespondences(rig, frame_matches);
  fit.usable = static_cast<int64_t>(prepared.prepared.size());
  if (fit.usable < options.min_inliers) {
    std::ostringstream message;
    message << "frame skipped: " << fit.usable << " usable matches of "
            << fit.correspondences << ", at least " << options.min_inliers
            << " needed";
    fit.estimate = Status::Error(message.str());
    return fit;
  }
  fit.skipped = false;

  // Stage 1 on the frame alone, and its inliers: with self-calibration,
  // the batch refinement of the frame (robust stage with cam1's rotation
  // and its prior, and the focal scales with theirs, inliers classified
  // with them); otherwise, or when that fails, n alone with the rotation
  // and the lenses held.
  const CalibrationParameterLayout layout = SelfCalibrationLayout(rig, options);
  Eigen::Vector3d rotation = Eigen::Vector3d::Zero();
  Eigen::Vector2d focal_scale = Eigen::Vector2d::Zero();
  Rigid3d extrinsics = rig.right_from_left();
  StereoRig frame_rig = rig;    // the lenses at the frame's focal scales
  bool own_lenses = false;      // frame_rig's are not the calibration's
  std::vector<int64_t> chosen;  // indices into prepared.prepared
  // The refinement's normal equations over its inliers (`chosen`).
  std::optional<LocusNormalEquations> own_equations;
  Eigen::Vector3d own_rows_rotation = Eigen::Vector3d::Zero();  // where taken
  if (SelfCalibrates(rig, options)) {
    RefinementOptions frame_options = options;
    frame_options.self_calibrate_focal = layout.focal;
    // Its rows at the estimator's linearization rotation, where this frame
    // pools them (below).
    frame_options.rows_at_rotation = linearization_rotation;
    StatusOr<RefinementSummary> own =
        RefineRefractiveIndex(rig, frame_matches, frame_options);
    if (own.ok() && own->rotation) {
      fit.n_robust = own->n_robust;
      rotation = own->rotation->angle_axis;
      extrinsics = own->rotation->cam1_from_cam0;
      if (own->focal) {
        StatusOr<StereoRig> scaled =
            rig.WithFocalScaled(own->focal->scale[0], own->focal->scale[1]);
        if (scaled.ok()) {
          focal_scale = own->focal->scale;
          frame_rig = *std::move(scaled);
          own_lenses = true;
          prepared = PrepareCorrespondences(frame_rig, frame_matches);
        }
      }
      // Its inliers are indices into the frame, increasing, as are
      // prepared.source_index.
      for (size_t i = 0, k = 0; i < prepared.source_index.size(); ++i) {
        while (k < own->inliers.size() &&
               own->inliers[k] < prepared.source_index[i]) {
          ++k;
        }
        if (k < own->inliers.size() &&
            own->inliers[k] == prepared.source_index[i]) {
          chosen.push_back(static_cast<int64_t>(i));
        }
      }
      if (chosen.size() == own->inliers.size()) {
        own_equations = std::move(own->normal_equations);
        own_rows_rotation = own->rows_rotation.value_or(rotation);
      }
    }
  }
  if (chosen.empty()) {
    own_equations.reset();
    rotation.setZero();
    focal_scale.setZero();
    extrinsics = rig.right_from_left();
    if (own_lenses) {
      own_lenses = false;
      frame_rig = rig;
      prepared = PrepareCorrespondences(rig, frame_matches);
    }
    fit.n_robust =
        MinimizeRobustLocusCost(essential, prepared.prepared, options);
    chosen = ClassifyLocusInliers(extrinsics, prepared.prepared, fit.n_robust,
                                  options);
  }
  const std::vector<PreparedCorrespondence>& inlier_pool = prepared.prepared;
  std::vector<PreparedCorrespondence> inlier_matches;
  std::vector<int64_t> inlier_sources;
  for (const int64_t i : chosen) {
    inlier_matches.push_back(inlier_pool[i]);
    inlier_sources.push_back(prepared.source_index[i]);
  }
  std::vector<int64_t> rejected;
  fit.cost.AddMatches(EssentialMatrix(extrinsics), inlier_matches,
                      options.num_threads, &rejected);
  // Matches whose residual is undefined somewhere in [1, 2] (at an
  // epipole) are left out of C_f; drop them from the reported inliers too.
  fit.inliers.reserve(inlier_sources.size() - rejected.size());
  std::vector<PreparedCorrespondence> kept;
  kept.reserve(inlier_sources.size() - rejected.size());
  for (size_t i = 0, r = 0; i < inlier_sources.size(); ++i) {
    if (r < rejected.size() && rejected[r] == static_cast<int64_t>(i)) {
      ++r;
      continue;
    }
    fit.inliers.push_back(inlier_sources[i]);
    kept.push_back(inlier_matches[i]);
  }
  // n at the frame's own rotation and lenses (the calibration's, or
  // self-calibrated).
  fit.estimate = EstimateFromLocusCost(fit.cost, options);

  // The calibration's share and the self-calibration need the inliers'
  // normal equations, taken at the frame's n and at the estimator's
  // linearization rotation when there is one (header), else at the
  // frame's own (whether the frame's refinement self-calibrated or fell
  // back to the calibration's rotation: the intercepts carry where the
  // rows were taken). The refinement's, which it took at that rotation
  // (rows_at_rotation above), when the frame keeps all its inliers (the
  // rows are the same; the refinement took them at its own n, which the
  // intercepts carry to first order); else taken here.
  const Eigen::Vector3d linearization =
      linearization_rotation.value_or(rotation);
  if (own_equations && rejected.empty() && linearization == own_rows_rotation &&
      own_equations->information.rows() == layout.Size()) {
    fit.normal_equations = *std::move(own_equations);
  } else if (rig.calibration_uncertainty() || options.systematic_px > 0.0) {
    fit.normal_equations = LocusNormalEquations(layout.Size());
    std::vector<StereoCorrespondence> raw;
    raw.reserve(fit.inliers.size());
    for (const int64_t i : fit.inliers) raw.push_back(frame_matches[i]);
    std::vector<int64_t> all(kept.size());
    for (size_t i = 0; i < all.size(); ++i) all[i] = static_cast<int64_t>(i);
    AccumulateLocusNormalEquations(
        frame_rig, layout, raw, kept, all,
        fit.estimate.ok() ? fit.estimate->n : fit.n_robust, linearization,
        focal_scale, &fit.normal_equations);
  }
  if (fit.estimate.ok()) {
    FrameFit::Model model;
    const double information = fit.normal_equations.information(0, 0);
    if ((rig.calibration_uncertainty() || options.systematic_px > 0.0) &&
        information > 0.0) {
      model.information = information;
      model.coupling.head<3>() =
          fit.normal_equations.information.block<3, 1>(1, 0);
      const CalibrationParameterLayout layout =
          SelfCalibrationLayout(rig, options);
      if (layout.focal) {
        model.coupling.tail<2>() =
            fit.normal_equations.information.block<2, 1>(layout.Focal(), 0);
      }
      model.n = -fit.normal_equations.gradient_intercept[0] / information;
    } else {
      model.n = fit.estimate->n;
      model.information = fit.cost.Information(fit.estimate->n);
    }
    fit.model = model;
  }
  return fit;
}

StatusOr<PooledLocusEstimate> FrameEstimateOf(const StereoRig& rig,
                                              const FrameFit& fit,
                                              const RefinementOptions& options,
                                              double scatter_inflation) {
  if (!fit.estimate.ok()) return fit.estimate.status();
  FrameEstimateSums own;
  if (fit.model) {
    own.Add(fit.model->n, fit.model->information, fit.model->coupling);
  }
  const StatusOr<CalibratedLocusEstimate> calibrated = EstimateWithCalibration(
      rig, fit.cost, fit.normal_equations, own, options, scatter_inflation);
  if (!calibrated.ok()) return calibrated.status();
  return PooledEstimateOf(*calibrated);
}

bool SelfCalibrates(const StereoRig& rig, const RefinementOptions& options) {
  return options.self_calibrate_rotation && rig.calibration_uncertainty() &&
         !rig.calibration_uncertainty()->RotationCovariance().isZero(0.0);
}

CalibrationParameterLayout SelfCalibrationLayout(
    const StereoRig& rig, const RefinementOptions& options) {
  return CalibrationParameterLayout::Of(rig, options.systematic_px,
                                        options.self_calibrate_focal &&
                                            SelfCalibrates(rig, options) &&
                                            !rig.HasThickPort());
}

StatusOr<CalibratedLocusEstimate> EstimateWithCalibration(
    const StereoRig& rig, const LocusCostFunction& cost,
    const LocusNormalEquations& normal_equations,
    const FrameEstimateSums& frame_estimates, const RefinementOptions& options,
    double scatter_inflation) {
  CHECK_GE(scatter_inflation, 1.0);
  // The consistency test's inflation, at least scatter_inflation.
  const auto inflation_of =
      [scatter_inflation](const std::optional<FrameConsistency>& consistency) {
        return std::max(scatter_inflation,
                        consistency ? consistency->inflation : 1.0);
      };
  // n alone first: it checks the inliers and the observability of n.
  const StatusOr<LocusEstimate> locus = EstimateFromLocusCost(cost, options);
  if (!locus.ok()) return locus.status();
  CalibratedLocusEstimate estimate;
  estimate.locus = *locus;
  if (!rig.calibration_uncertainty() && options.systematic_px == 0.0) {
    estimate.consistency =
        FrameConsistencyOf(frame_estimates, locus->n, locus->sigma_px);
    const double inflation = inflation_of(estimate.consistency);
    estimate.sigma_n_noise = estimate.sigma_n = locus->sigma_n * inflation;
    RCM_RETURN_IF_ERROR(CheckNotPinnedAtUpperBound(locus->n, estimate.sigma_n));
    return estimate;
  }
  const CalibrationUncertainty uncertainty =
      rig.calibration_uncertainty().value_or(CalibrationUncertainty());
  const CalibrationParameterLayout layout = SelfCalibrationLayout(rig, options);
  LocusNormalEquations at_solution = normal_equations;
  const bool self_calibrate = SelfCalibrates(rig, options);
  Eigen::Vector3d rotation = Eigen::Vector3d::Zero();
  Eigen::Vector2d focal_scale = Eigen::Vector2d::Zero();
  if (self_calibrate) {
    const QuadraticSelfCalibration pooled = SelfCalibrateQuadratic(
        normal_equations, layout, uncertainty.RotationPriorCovariance(),
        uncertainty.focal_drift_sigma, locus->sigma_px);
    estimate.locus.n = pooled.n;
    estimate.locus.sigma_px = pooled.sigma_px;
    rotation = pooled.rotation;
    estimate.rotation = rotation;
    if (layout.focal) {
      focal_scale = pooled.focal_scale;
      estimate.focal_scale = focal_scale;
    }
  } else {
    // n alone: the information on n at the estimate, from the interpolant.
    at_solution.information(0, 0) = cost.Information(locus->n);
  }
  const double n = estimate.locus.n;
  const double sigma_px = estimate.locus.sigma_px;
  estimate.locus.crlb = sigma_px / std::sqrt(cost.Information(n));
  estimate.consistency = FrameConsistencyOf(
      frame_estimates, n, sigma_px, SelfCalibrationOf(rotation, focal_scale));
  const double inflation = inflation_of(estimate.consistency);
  StatusOr<CalibrationPropagation> propagation = PropagateCalibration(
      at_solution, layout, uncertainty,
      self_calibrate ? RotationMode::kPrior : RotationMode::kHeld, sigma_px,
      inflation);
  if (!propagation.ok()) return propagation.status();
  if (self_calibrate) {
    estimate.sigma_n_noise = propagation->sigma_n_noise;
  } else {
    // n alone: the pixel-noise share exactly as without a calibration
    // uncertainty (the interpolant's information at n).
    estimate.sigma_n_noise = estimate.locus.crlb * inflation;
  }
  estimate.sigma_n_calibration = propagation->sigma_n_calibration;
  estimate.sigma_n_systematic = propagation->sigma_n_systematic;
  estimate.sigma_n =
      std::sqrt(estimate.sigma_n_noise * estimate.sigma_n_noise +
                estimate.sigma_n_calibration * estimate.sigma_n_calibration +
                estimate.sigma_n_systematic * estimate.sigma_n_systematic);
  estimate.locus.sigma_n = estimate.sigma_n;
  estimate.calibration = *propagation;
  RCM_RETURN_IF_ERROR(CheckNotPinnedAtUpperBound(n, estimate.sigma_n));
  return estimate;
}

PooledLocusEstimate PooledEstimateOf(const CalibratedLocusEstimate& estimate) {
  PooledLocusEstimate pooled;
  pooled.n = estimate.locus.n;
  pooled.sigma_n = estimate.sigma_n;
  pooled.sigma_n_noise = estimate.sigma_n_noise;
  pooled.sigma_n_calibration = estimate.sigma_n_calibration;
  pooled.sigma_n_systematic = estimate.sigma_n_systematic;
  pooled.crlb = estimate.locus.crlb;
  pooled.sigma_px = estimate.locus.sigma_px;
  pooled.inliers = estimate.locus.inliers;
  pooled.consistency = estimate.consistency;
  pooled.calibration = estimate.calibration;
  pooled.rotation = estimate.rotation;
  pooled.focal_scale = estimate.focal_scale;
  return pooled;
}

OnlineRefractiveIndexEstimator::OnlineRefractiveIndexEstimator(
    const StereoRig& rig, const RefinementOptions& options)
    : rig_(rig),
      options_(options),
      normal_equations_(SelfCalibrationLayout(rig, options).Size()) {}

StatusOr<OnlineRefractiveIndexEstimator> OnlineRefractiveIndexEstimator::Create(
    const StereoRig& rig, const RefinementOptions& options) {
  RCM_RETURN_IF_ERROR(options.Check());
  if (options.refine_rotation) {
    return Status::Error(
        "the online estimator estimates n alone: the rotation correction "
        "(refine_rotation) is available in the batch refinement only");
  }
  if (options.n_prior) {
    return Status::Error(
        "the online estimator estimates n from the data alone: the prior on "
        "n (the medium) is available in the batch refinement only");
  }
  return OnlineRefractiveIndexEstimator(rig, options);
}

OnlineRefractiveIndexEstimator::FrameUpdate
OnlineRefractiveIndexEstimator::AddFrame(
    const std::vector<StereoCorrespondence>& frame_matches) {
  FrameUpdate update;
  update.frame = num_frames_++;
  num_correspondences_ += static_cast<int64_t>(frame_matches.size());
  FrameFit fit =
      FitFrame(rig_, frame_matches, options_, linearization_.rotation);
  update.correspondences = fit.correspondences;
  update.usable = fit.usable;
  update.skipped = fit.skipped;
  if (fit.skipped) {
    ++num_skipped_frames_;
  } else {
    cost_.Add(fit.cost);
    if (rig_.calibration_uncertainty() || options_.systematic_px > 0.0) {
      normal_equations_.Add(fit.normal_equations);
    }
    if (fit.model) {
      frame_estimates_.Add(fit.model->n, fit.model->information,
                           fit.model->coupling);
    }
    update.inliers = std::move(fit.inliers);
  }
  update.cumulative = Current();
  double inflation = 1.0;
  if (update.cumulative.ok()) {
    linearization_.Follow(update.cumulative->rotation);
    inflation = ScatterInflationOf(*update.cumulative);
  }
  update.frame_estimate = FrameEstimateOf(rig_, fit, options_, inflation);
  return update;
}

StatusOr<OnlineRefractiveIndexEstimator::Estimate>
OnlineRefractiveIndexEstimator::Current() const {
  const StatusOr<CalibratedLocusEstimate> calibrated = EstimateWithCalibration(
      rig_, cost_, normal_equations_, frame_estimates_, options_);
  if (!calibrated.ok()) return calibrated.status();
  Estimate estimate;
  static_cast<PooledLocusEstimate&>(estimate) = PooledEstimateOf(*calibrated);
  estimate.correspondences = num_correspondences_;
  estimate.frames = num_frames_;
  return estimate;
}

}  // namespace rcm
