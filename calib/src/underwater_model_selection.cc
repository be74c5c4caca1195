#include "rcm/calib/underwater_model_selection.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <mutex>
#include <string>
#include <utility>

#include "board_bundle_adjustment.h"
#include "rcm/util/number_format.h"
#include "rcm/util/parallel_for.h"

namespace rcm::calib {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kDegreesPerRadian = 180.0 / M_PI;
// A held-out SSR floor for the log ratio [px^2] (noise-free corners reach
// 1e-27).
constexpr double kTinySsr = 1e-300;

// The held-out SSR of view v by candidate c, NaN when it has none.
double HeldOut(const UnderwaterCandidate& candidate, int v) {
  if (!candidate.fit || !candidate.fit->leave_out) return kNaN;
  const std::vector<double>& ssr = candidate.fit->leave_out->held_out_ssr;
  return v < static_cast<int>(ssr.size()) ? ssr[v] : kNaN;
}

// Evidence and plausibility of the fitted candidates (header); returns
// the number of common views.
int WeighEvidence(double evidence_sigmas,
                  std::vector<UnderwaterCandidate>* candidates, int num_views) {
  std::vector<int> fitted;
  for (size_t k = 0; k < candidates->size(); ++k) {
    if ((*candidates)[k].fit) fitted.push_back(static_cast<int>(k));
  }
  std::vector<int> common;
  for (int v = 0; v < num_views; ++v) {
    bool all = !fitted.empty();
    for (int k : fitted) all &= std::isfinite(HeldOut((*candidates)[k], v));
    if (all) common.push_back(v);
  }
  for (int k : fitted) {
    UnderwaterCandidate& candidate = (*candidates)[k];
    candidate.plausible = true;
    candidate.evidence = kNaN;
    candidate.held_out_rms_px = kNaN;
  }
  if (fitted.size() < 2 ||
      static_cast<int>(common.size()) < kMinEvidenceViews) {
    return static_cast<int>(common.size());
  }
  // The best: the lowest sum of log held-out SSRs (the geometric mean over
  // views, the scale of the paired log ratios below).
  std::vector<double> sum_log(candidates->size(), 0.0);
  int best = fitted.front();
  for (int k : fitted) {
    const UnderwaterCandidate& candidate = (*candidates)[k];
    double total = 0.0;
    int corners = 0;
    for (int v : common) {
      total += HeldOut(candidate, v);
      sum_log[k] += std::log(std::max(HeldOut(candidate, v), kTinySsr));
      corners += candidate.fit->leave_out->held_out_corners[v];
    }
    (*candidates)[k].held_out_rms_px = std::sqrt(total / corners);
    if (sum_log[k] < sum_log[best]) best = k;
  }
  const double num_common = static_cast<double>(common.size());
  for (int k : fitted) {
    UnderwaterCandidate& candidate = (*candidates)[k];
    if (k == best) {
      candidate.evidence = 0.0;
      continue;
    }
    // The paired log ratios; their mean is the difference of the means.
    const double mean = (sum_log[k] - sum_log[best]) / num_common;
    std::vector<double> d;
    for (int v : common) {
      d.push_back(
          std::log(std::max(HeldOut(candidate, v), kTinySsr) /
                   std::max(HeldOut((*candidates)[best], v), kTinySsr)));
    }
    double sum = 0.0;
    for (const double x : d) sum += (x - mean) * (x - mean);
    const double se = std::sqrt(sum / (num_common - 1.0) / num_common);
    candidate.evidence =
        se > 0.0 ? mean / se
                 : (mean > 0.0 ? std::numeric_limits<double>::infinity() : 0.0);
    candidate.plausible = candidate.evidence <= evidence_sigmas;
  }
  return static_cast<int>(common.size());
}

// sigma_n_noise of a fit (header): its leave-out sigma when that exceeds
// the covariance's by more than the leave-out's own sampling error allows
// (internal::LeaveOutOrCovarianceSigma), else the covariance's.
double NoiseSigma(const UnderwaterCalibration& fit) {
  if (!fit.sigma_n_leave_out || !fit.leave_out) return fit.sigma_n;
  return internal::LeaveOutOrCovarianceSigma(
      fit.sigma_n, *fit.sigma_n_leave_out,
      fit.leave_out->folds - fit.leave_out->failed_folds);
}

// What separates n from the model `other` that spreads it, given the
// chosen `model`, and the views the dive had (distances, tilts).
std::string Advice(const UnderwaterModelSelection& selection,
                   const UnderwaterCandidateModel& other, double limit) {
  const UnderwaterCandidateModel& model =
      selection.candidates[selection.chosen].model;
  double near = std::numeric_limits<double>::infinity();
  double far = 0.0;
  double tilt = 0.0;
  for (const std::optional<Rigid3d>& pose :
       selection.Chosen().cam0_from_target) {
    if (!pose) continue;
    const double distance = pose->translation.norm();
    near = std::min(near, distance);
    far = std::max(far, distance);
    const double cosine = std::abs(pose->rotation.col(2).z());
    tilt = std::max(
        tilt, kDegreesPerRadian * std::acos(std::clamp(cosine, 0.0, 1.0)));
  }
  std::string what;
  std::string help;
  if (other.board_warp != model.board_warp) {
    what = "the board's bow";
    help =
        "views of the board at several distances (from half to twice the "
        "present ones) and tilted by 30-45 deg separate n from the bow; so do "
        "the air calibration's views of the same board";
  } else {
    what = other.air_gap != model.air_gap ? "the ports' air gaps"
                                          : "the ports' tilts";
    help =
        "views with the board near the image corners and at several "
        "distances separate n from the port";
  }
  return "this dive cannot pin n to " + FormatFixed(limit, 4) + ": sigma_n " +
         FormatFixed(selection.sigma_n, 4) + " of which " +
         FormatFixed(selection.sigma_n_model, 4) +
         " is the models the data cannot tell apart (" + what +
         "); the board was at " + FormatFixed(near, 2) + "-" +
         FormatFixed(far, 2) + " m and tilted up to " + FormatFixed(tilt, 0) +
         " deg: " + help;
}

}  // namespace

std::string UnderwaterCandidateModel::Name() const {
  std::string name = board_warp ? "bowed board, " : "flat board, ";
  if (air_gap && port_tilt) return name + "air gaps and tilted ports";
  if (air_gap) return name + "air gaps";
  if (port_tilt) return name + "tilted ports";
  return name + "thin ports";
}

int UnderwaterCandidateModel::ExtraParameters() const {
  return (board_warp ? 2 : 0) + (air_gap ? 2 : 0) + (port_tilt ? 4 : 0);
}

bool UnderwaterCandidateModel::operator==(
    const UnderwaterCandidateModel& other) const {
  return board_warp == other.board_warp && air_gap == other.air_gap &&
         port_tilt == other.port_tilt;
}

std::vector<UnderwaterCandidateModel> UnderwaterCandidates(bool flat_board,
                                                           bool air_gap,
                                                           bool port_tilt,
                                                           bool thin_port) {
  std::vector<UnderwaterCandidateModel> ports;
  if (thin_port) {
    ports.push_back({false, false, false});
  } else if (air_gap || port_tilt) {
    ports.push_back({false, air_gap, port_tilt});
  } else {
    ports = {{false, false, false},
             {false, true, false},
             {false, false, true},
             {false, true, true}};
  }
  std::vector<UnderwaterCandidateModel> candidates;
  for (const bool warp : {false, true}) {
    if (warp && flat_board) continue;
    for (UnderwaterCandidateModel port : ports) {
      port.board_warp = warp;
      candidates.push_back(port);
    }
  }
  std::stable_sort(
      candidates.begin(), candidates.end(),
      [](const UnderwaterCandidateModel& a, const UnderwaterCandidateModel& b) {
        return a.ExtraParameters() < b.ExtraParameters();
      });
  return candidates;
}

Status UnderwaterModelSelectionOptions::Check() const {
  RCM_RETURN_IF_ERROR(fit.Check());
  if (candidates.empty()) return Status::Error("candidates is empty");
  for (size_t i = 0; i < candidates.size(); ++i) {
    for (size_t j = 0; j < i; ++j) {
      if (candidates[i] == candidates[j]) {
        return Status::Error("candidates lists " + candidates[i].Name() +
                             " twice");
      }
    }
  }
  if (!(evidence_sigmas > 0.0) || !std::isfinite(evidence_sigmas)) {
    return Status::Error("evidence_sigmas must be positive and finite");
  }
  if (!(max_sigma_n > 0.0) || !std::isfinite(max_sigma_n)) {
    return Status::Error("max_sigma_n must be positive and finite");
  }
  return Status::Ok();
}

StatusOr<UnderwaterModelSelection> SelectUnderwaterModel(
    const CalibrationTarget& target, const std::vector<StereoView>& views,
    const ImageSize& cam0_size, const ImageSize& cam1_size,
    const StereoRig& air_rig, const UnderwaterModelSelectionOptions& options,
    const std::function<void(int, int)>& progress, const AirTargetViews* air) {
  RCM_RETURN_IF_ERROR(options.Check());
  const int num_candidates = static_cast<int>(options.candidates.size());
  // The candidates are independent: they share the threads, each fit on
  // num_threads / (candidates at once) of them. Progress in hundredths of
  // a candidate, summed over the candidates.
  constexpr int kSteps = 100;
  const int parallel = std::clamp(options.fit.num_threads, 1, num_candidates);
  // The lens refits (sigma_n_lenses) only count for the chosen candidate:
  // they run once, after the choice, as one more candidate's worth of steps.
  const bool lens_refits = options.fit.propagate_lens_covariance &&
                           air_rig.calibration_uncertainty().has_value() &&
                           air == nullptr;
  const int total_steps = (num_candidates + (lens_refits ? 1 : 0)) * kSteps;
  UnderwaterModelSelection selection;
  selection.candidates.resize(num_candidates);
  std::vector<int> done(num_candidates + 1, 0);
  std::mutex progress_mutex;
  const auto report = [&](int k, int steps) {
    if (!progress) return;
    std::lock_guard<std::mutex> lock(progress_mutex);
    done[k] = steps;
    int sum = 0;
    for (int d : done) sum += d;
    progress(sum, total_steps);
  };
  ParallelFor(num_candidates, parallel, 1, [&](int64_t begin, int64_t end) {
    for (int k = static_cast<int>(begin); k < end; ++k) {
      UnderwaterCandidate& candidate = selection.candidates[k];
      candidate.model = options.candidates[k];
      UnderwaterCalibrationOptions fit = options.fit;
      fit.num_threads = std::max(1, options.fit.num_threads / parallel);
      fit.propagate_lens_covariance = false;
      fit.estimate_board_warp = candidate.model.board_warp;
      fit.estimate_air_gap = candidate.model.air_gap;
      fit.estimate_port_tilt = candidate.model.port_tilt;
      // The conventional fit depends on the board only: the thin-port
      // candidates carry it.
      fit.fit_conventional_model &=
          !candidate.model.air_gap && !candidate.model.port_tilt;
      StatusOr<UnderwaterCalibration> result = CalibrateUnderwater(
          target, views, cam0_size, cam1_size, air_rig, fit,
          [&](int steps, int total) {
            report(k, steps * kSteps / std::max(total, 1));
          },
          air);
      if (result.ok()) {
        candidate.sigma_n_noise = NoiseSigma(*result);
        candidate.fit = *std::move(result);
      } else {
        candidate.error = result.status().message();
        candidate.on_bound = IsIndexOnBoundError(result.status());
      }
      report(k, kSteps);
    }
  });
  std::vector<UnderwaterCandidate>& candidates = selection.candidates;
  // A candidate whose n ends on a bound of [1, 2] (IsIndexOnBoundError)
  // says the air calibration does not describe these cameras: the dive is
  // refused, whatever a richer model makes of it.
  for (const UnderwaterCandidate& candidate : candidates) {
    if (!candidate.fit && candidate.on_bound) {
      return Status::Error(candidate.error + " (" + candidate.model.Name() +
                           ")");
    }
  }
  bool any = false;
  for (const UnderwaterCandidate& candidate : candidates) {
    any |= candidate.fit.has_value();
  }
  if (!any) {
    if (num_candidates == 1) return Status::Error(candidates[0].error);
    return Status::Error("no candidate model fits these views; " +
                         candidates[0].model.Name() + ": " +
                         candidates[0].error);
  }
  selection.num_evidence_views = WeighEvidence(
      options.evidence_sigmas, &candidates, static_cast<int>(views.size()));

  // The plausible candidate of the lowest held-out error; without
  // evidence, the simplest.
  for (int k = 0; k < num_candidates; ++k) {
    const UnderwaterCandidate& candidate = candidates[k];
    if (!candidate.fit || !candidate.plausible) continue;
    if (selection.chosen < 0) {
      selection.chosen = k;
      continue;
    }
    const UnderwaterCandidate& chosen = candidates[selection.chosen];
    if (candidate.evidence < chosen.evidence) selection.chosen = k;
  }
  UnderwaterCandidate& chosen = candidates[selection.chosen];
  if (lens_refits) {
    // The chosen model's fit again, every thread on its lens refits (the
    // main fit is the same least squares from the same start; no folds).
    UnderwaterCalibrationOptions fit = options.fit;
    fit.estimate_board_warp = chosen.model.board_warp;
    fit.estimate_air_gap = chosen.model.air_gap;
    fit.estimate_port_tilt = chosen.model.port_tilt;
    fit.folds = 0;
    fit.fit_conventional_model = false;
    const StatusOr<UnderwaterCalibration> lenses = CalibrateUnderwater(
        target, views, cam0_size, cam1_size, air_rig, fit,
        [&](int steps, int total) {
          report(num_candidates, steps * kSteps / std::max(total, 1));
        });
    if (lenses.ok()) {
      chosen.fit->sigma_n_lenses = lenses->sigma_n_lenses;
      chosen.fit->extrinsics_lens_covariance =
          lenses->extrinsics_lens_covariance;
      chosen.fit->extrinsics_covariance_from_lenses =
          lenses->extrinsics_covariance_from_lenses;
      chosen.fit->port_lens_covariance = lenses->port_lens_covariance;
      chosen.fit->port_covariance_from_lenses =
          lenses->port_covariance_from_lenses;
      for (const std::string& note : lenses->notes) {
        if (note.rfind("lens uncertainty", 0) == 0) {
          chosen.fit->notes.push_back(note);
        }
      }
    } else {
      chosen.fit->notes.push_back("lens uncertainty: the refit failed (" +
                                  lenses.status().message() +
                                  "); sigma_n leaves the lenses out");
    }
    report(num_candidates, kSteps);
  }
  selection.n = chosen.fit->n;
  selection.sigma_n_noise = chosen.sigma_n_noise;
  selection.sigma_n_lenses = chosen.fit->sigma_n_lenses.value_or(0.0);
  // The model spread: the de-noised squared difference of each other
  // plausible candidate's n, weighted by exp(-evidence^2 / 2) (1 without
  // evidence).
  int spreading = -1;
  double weighted = 0.0;
  double total_weight = 1.0;  // the chosen's
  double largest = 0.0;
  for (int k = 0; k < num_candidates; ++k) {
    const UnderwaterCandidate& candidate = candidates[k];
    if (k == selection.chosen || !candidate.fit || !candidate.plausible) {
      continue;
    }
    const double weight =
        std::isfinite(candidate.evidence)
            ? std::exp(-0.5 * candidate.evidence * candidate.evidence)
            : 1.0;
    const double difference = candidate.fit->n - selection.n;
    const double noise =
        std::abs(candidate.sigma_n_noise * candidate.sigma_n_noise -
                 chosen.sigma_n_noise * chosen.sigma_n_noise);
    const double bias2 = std::max(0.0, difference * difference - noise);
    weighted += weight * bias2;
    total_weight += weight;
    if (weight * bias2 > largest) {
      largest = weight * bias2;
      spreading = k;
    }
  }
  selection.sigma_n_model = std::sqrt(weighted / total_weight);
  selection.sigma_n =
      std::sqrt(selection.sigma_n_noise * selection.sigma_n_noise +
                selection.sigma_n_lenses * selection.sigma_n_lenses +
                selection.sigma_n_model * selection.sigma_n_model);
  selection.pinned = selection.sigma_n <= options.max_sigma_n;
  if (!selection.pinned) {
    if (spreading >= 0) {
      selection.advice =
          Advice(selection, candidates[spreading].model, options.max_sigma_n);
    } else {
      selection.advice =
          "this dive cannot pin n to " + FormatFixed(options.max_sigma_n, 4) +
          ": sigma_n " + FormatFixed(selection.sigma_n, 4) + " (noise " +
          FormatFixed(selection.sigma_n_noise, 4) + ", lenses " +
          FormatFixed(selection.sigma_n_lenses, 4) +
          "): more views, at several distances and tilts, and a sharper "
          "air calibration would help";
    }
  }
  return selection;
}

}  // namespace rcm::calib
