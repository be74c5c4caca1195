#include "rcm/calib/cross_validation.h"

#include <algorithm>
#include <cmath>
#include <mutex>
#include <optional>
#include <thread>
#include <utility>

#include "air_calibration.h"

namespace rcm::calib {
namespace {

// A quantity of the table: its name, unit, value and covariance sigma.
struct Quantity {
  const char* name;
  const char* unit;
  double value;
  double sigma;
};

// The quantities of a calibration, in ParameterSpread order: the board's
// bowl last when the warp is estimated; one camera: cam0's and the bowl.
std::vector<Quantity> Quantities(const StereoCalibration& c) {
  static const char* const kNames[2][4] = {
      {"cam0 fx", "cam0 fy", "cam0 cx", "cam0 cy"},
      {"cam1 fx", "cam1 fy", "cam1 cx", "cam1 cy"}};
  std::vector<Quantity> quantities;
  for (int camera = 0; camera < c.num_cameras; ++camera) {
    const CameraCalibration& cc = camera == 0 ? c.cam0 : c.cam1;
    const double values[4] = {cc.camera.fx(), cc.camera.fy(), cc.camera.cx(),
                              cc.camera.cy()};
    for (int i = 0; i < 4; ++i) {
      quantities.push_back({kNames[camera][i], "px", values[i], cc.sigma[i]});
    }
  }
  if (c.num_cameras == 2) {
    quantities.push_back({"baseline", "m", c.baseline, c.baseline_sigma});
  }
  if (c.board_warp_estimated) {
    quantities.push_back(
        {"board bowl", "m", c.BoardBowl(), c.BoardBowlSigma()});
  }
  return quantities;
}

}  // namespace

Status CrossValidationOptions::Check() const {
  if (folds < 2)
    return Status::Error("cross-validation needs at least 2 folds");
  return Status::Ok();
}

StatusOr<CrossValidation> CrossValidateStereo(
    const CalibrationTarget& target, const std::vector<StereoView>& views,
    const ImageSize& cam0_size, const ImageSize& cam1_size,
    const StereoCalibration& full,
    const StereoCalibrationOptions& calibration_options,
    const CrossValidationOptions& options,
    const std::function<void(int, int)>& progress) {
  if (Status status = options.Check(); !status.ok()) return status;
  const int num_views = static_cast<int>(views.size());
  const int groups = std::min(options.folds, num_views);
  if (groups < 2) {
    return Status::Error("cross-validation needs at least 2 views");
  }
  // The folds run side by side, calibration_options.num_threads at a
  // time with one Ceres thread each: small solves, which a second Ceres
  // thread speeds up far less than a second fold does. Each fold's result
  // is that of a one-thread solve, whatever the number of threads.
  StereoCalibrationOptions fold_options = calibration_options;
  fold_options.compute_covariance = false;
  fold_options.num_threads = 1;
  // The cameras of the full calibration: one, or the pair.
  std::vector<ImageSize> sizes = {cam0_size, cam1_size};
  sizes.resize(full.num_cameras);
  std::vector<std::optional<std::vector<Quantity>>> fold_estimates(groups);
  std::mutex mutex;
  int next = 0;
  int done = 0;
  const auto work = [&] {
    for (;;) {
      int k = 0;
      {
        const std::lock_guard<std::mutex> lock(mutex);
        if (next == groups) return;
        k = next++;
      }
      std::vector<StereoView> subset;
      for (int v = 0; v < num_views; ++v) {
        if (v % groups != k) subset.push_back(views[v]);
      }
      const StatusOr<StereoCalibration> calibration =
          internal::CalibrateInAir(target, subset, sizes, fold_options);
      const std::lock_guard<std::mutex> lock(mutex);
      if (calibration.ok()) fold_estimates[k] = Quantities(*calibration);
      ++done;
      if (progress) progress(done, groups);
    }
  };
  {
    const int workers = std::clamp(calibration_options.num_threads, 1, groups);
    std::vector<std::thread> threads;
    for (int w = 1; w < workers; ++w) threads.emplace_back(work);
    work();
    for (std::thread& thread : threads) thread.join();
  }
  std::vector<std::vector<Quantity>> estimates;
  CrossValidation result;
  result.folds = groups;
  for (std::optional<std::vector<Quantity>>& estimate : fold_estimates) {
    if (estimate) {
      estimates.push_back(std::move(*estimate));
    } else {
      ++result.failed_folds;
    }
  }
  const int g = static_cast<int>(estimates.size());
  if (g < 2) {
    return Status::Error("cross-validation: only " + std::to_string(g) +
                         " of " + std::to_string(groups) +
                         " leave-out calibrations succeeded");
  }
  const std::vector<Quantity> full_values = Quantities(full);
  const int num_quantities = static_cast<int>(full_values.size());
  for (int q = 0; q < num_quantities; ++q) {
    ParameterSpread spread;
    spread.name = full_values[q].name;
    spread.unit = full_values[q].unit;
    spread.full = full_values[q].value;
    spread.reported_sigma = full_values[q].sigma;
    double mean = 0.0;
    spread.min = spread.max = estimates[0][q].value;
    for (const std::vector<Quantity>& e : estimates) {
      mean += e[q].value;
      spread.min = std::min(spread.min, e[q].value);
      spread.max = std::max(spread.max, e[q].value);
    }
    mean /= g;
    double sum = 0.0;
    for (const std::vector<Quantity>& e : estimates) {
      sum += (e[q].value - mean) * (e[q].value - mean);
    }
    spread.jackknife_sigma = std::sqrt((g - 1.0) / g * sum);
    result.parameters.push_back(spread);
  }
  return result;
}

double JackknifeNoiseSigma(double covariance_sigma, double jackknife_sigma,
                           int replicates) {
  if (replicates < 2 || !std::isfinite(jackknife_sigma)) {
    return covariance_sigma;
  }
  if (replicates < kMinJackknifeReplicates) {
    return std::max(covariance_sigma, jackknife_sigma);
  }
  return std::sqrt(0.5 * (covariance_sigma * covariance_sigma +
                          jackknife_sigma * jackknife_sigma));
}

}  // namespace rcm::calib
