#include "calibration_run.h"

#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <mutex>
#include <thread>
#include <utility>

#include "progress.h"
#include "rcm/calib/target_detector.h"
#include "rcm/util/number_format.h"

namespace rcm::cli {
namespace {

namespace fs = std::filesystem;

// Whether `folder` exists as a folder or can be created: its nearest
// existing ancestor must be a folder we may write in. Creates nothing, so
// that a run that fails later leaves no empty folders.
Status CheckFolderCanBeCreated(const std::string& folder) {
  fs::path existing = fs::path(folder).lexically_normal();
  std::error_code error;
  while (!existing.empty() && !fs::exists(existing, error)) {
    existing = existing.parent_path();
  }
  if (existing.empty()) existing = ".";
  if (!fs::is_directory(existing, error)) {
    return Status::Error("cannot create folder " + folder + ": " +
                         existing.string() + " is not a folder");
  }
  if (access(existing.c_str(), W_OK | X_OK) != 0) {
    return Status::Error("cannot create folder " + folder + ": " +
                         existing.string() + ": " + std::strerror(errno));
  }
  return Status::Ok();
}

}  // namespace

CalibrationOutputPaths CalibrationOutputPathsFor(const std::string& out,
                                                 const std::string& report) {
  const fs::path path(out);
  const std::string extension = path.extension().string();
  CalibrationOutputPaths paths;
  if (extension == ".yaml" || extension == ".yml") {
    paths.camchain = path.string();
    paths.report =
        (path.parent_path() / (path.stem().string() + "-report")).string();
  } else {
    paths.camchain = (path / "camchain.yaml").string();
    paths.report = (path / "report").string();
  }
  if (!report.empty()) paths.report = report;
  return paths;
}

Status CheckCalibrationOutputPaths(const CalibrationOutputPaths& paths) {
  std::error_code error;
  if (fs::is_directory(paths.camchain, error)) {
    return Status::Error(paths.camchain +
                         ": is a folder, expected the camchain file to write");
  }
  const std::string camchain_folder =
      fs::path(paths.camchain).parent_path().string();
  if (!camchain_folder.empty()) {
    RCM_RETURN_IF_ERROR(CheckFolderCanBeCreated(camchain_folder));
  }
  return CheckFolderCanBeCreated(paths.report);
}

std::string WithSigma(double value, double sigma, int digits,
                      std::optional<double> leave_out) {
  std::string text =
      FormatFixed(value, digits) + " +- " + FormatFixed(sigma, digits);
  if (leave_out) text += " (" + FormatFixed(*leave_out, digits) + ")";
  return text;
}

std::string BoardFlatnessText(bool estimated, const Eigen::Vector2d& warp,
                              const Eigen::Matrix2d& covariance,
                              std::optional<double> bowl_leave_out_sigma) {
  if (!estimated) return "board flatness: assumed flat (--flat-board)";
  const Eigen::Vector2d sigma = covariance.diagonal().cwiseSqrt();
  const std::optional<double> leave_out_mm =
      bowl_leave_out_sigma ? std::optional<double>(1e3 * *bowl_leave_out_sigma)
                           : std::nullopt;
  return "board flatness: bowl " +
         WithSigma(1e3 * warp.sum(), 1e3 * std::sqrt(covariance.sum()), 2,
                   leave_out_mm) +
         " mm at the centre (x " +
         WithSigma(1e3 * warp.x(), 1e3 * sigma.x(), 2, std::nullopt) + ", y " +
         WithSigma(1e3 * warp.y(), 1e3 * sigma.y(), 2, std::nullopt) + " mm)";
}

nlohmann::json BoardFlatnessJson(bool estimated, const Eigen::Vector2d& warp,
                                 const Eigen::Matrix2d& covariance,
                                 std::optional<double> bowl_leave_out_sigma) {
  nlohmann::json json = {{"estimated", estimated}};
  if (!estimated) return json;
  const Eigen::Vector2d sigma = covariance.diagonal().cwiseSqrt();
  json["board_warp_mm"] = {1e3 * warp.x(), 1e3 * warp.y()};
  json["board_warp_sigma_mm"] = {1e3 * sigma.x(), 1e3 * sigma.y()};
  json["bowl_mm"] = 1e3 * warp.sum();
  json["bowl_sigma_mm"] = 1e3 * std::sqrt(covariance.sum());
  if (bowl_leave_out_sigma) {
    json["bowl_leave_out_sigma_mm"] = 1e3 * *bowl_leave_out_sigma;
  }
  return json;
}

void CountViews(Detections* detections) {
  detections->stereo = detections->left_only = detections->right_only = 0;
  for (const calib::StereoView& view : detections->views) {
    detections->stereo += view.stereo() ? 1 : 0;
    detections->left_only += view.left && !view.right ? 1 : 0;
    detections->right_only += view.right && !view.left ? 1 : 0;
  }
}

StatusOr<Detections> DetectTargets(StereoImageSource* source,
                                   const calib::CalibrationTarget& target) {
  const size_t pairs = source->NumPairs();
  // Two workers, each reading (one at a time: a source need not be thread
  // safe) and then searching a whole pair on its own thread, keep both
  // cores busy where one searcher per image of a pair waited for the
  // slower image and for the decoding of the next pair.
  struct PairResult {
    StatusOr<StereoImagePair> pair = Status::Error("not read");
    calib::StereoView view;
    calib::ImageSize sizes[2];
  };
  std::vector<PairResult> results(pairs);
  calib::TargetDetectorOptions detector_options;
  detector_options.num_threads = 1;
  std::mutex mutex;
  size_t next = 0;
  size_t done = 0;
  int found = 0;
  Progress progress("rcm calibrate: detecting, pair", pairs);
  const auto work = [&] {
    for (;;) {
      size_t i = 0;
      PairResult* result = nullptr;
      {
        const std::lock_guard<std::mutex> lock(mutex);
        if (next == pairs) return;
        i = next++;
        result = &results[i];
        result->pair = source->ReadPair(i);
      }
      if (result->pair.ok()) {
        const StereoImagePair& pair = *result->pair;
        if (pair.right.empty()) {
          result->view.left =
              calib::DetectTarget(pair.left, target, detector_options);
          if (!result->view.left) result->view.note = "no target found";
        } else {
          result->view = calib::DetectTargetPair(pair.left, pair.right, target,
                                                 detector_options);
        }
      }
      const std::lock_guard<std::mutex> lock(mutex);
      const bool one_camera = result->pair.ok() && result->pair->right.empty();
      found +=
          one_camera ? result->view.left.has_value() : result->view.stereo();
      progress.Update(++done, std::to_string(found) +
                                  (one_camera ? " with the target"
                                              : " with the target in both"));
      // Only the sizes are needed from here on.
      if (result->pair.ok()) {
        cv::Mat* images[2] = {&result->pair->left, &result->pair->right};
        for (int c = 0; c < 2; ++c) {
          result->sizes[c] = {images[c]->cols, images[c]->rows};
          images[c]->release();
        }
      }
    }
  };
  {
    std::thread helper(work);
    work();
    helper.join();
  }

  Detections detections;
  for (size_t i = 0; i < pairs; ++i) {
    PairResult& result = results[i];
    if (!result.pair.ok()) {
      // One unreadable image loses its pair, never the pairing of others.
      detections.warnings.push_back(result.pair.status().message() +
                                    "; pair skipped");
      if (detections.unreadable++ == 0) {
        detections.first_unreadable = result.pair.status().message();
      }
      continue;
    }
    const StereoImagePair& pair = *result.pair;
    const bool one_camera = result.sizes[1].width == 0;
    const std::string* names[2] = {&pair.left_name, &pair.right_name};
    for (int c = 0; c < (one_camera ? 1 : 2); ++c) {
      const calib::ImageSize size = result.sizes[c];
      if (!detections.sizes[c]) {
        detections.sizes[c] = size;
      } else if (detections.sizes[c]->width != size.width ||
                 detections.sizes[c]->height != size.height) {
        return Status::Error(*names[c] + ": " + std::to_string(size.width) +
                             "x" + std::to_string(size.height) +
                             ", but the earlier " +
                             (c == 0 ? "left" : "right") + " images are " +
                             std::to_string(detections.sizes[c]->width) + "x" +
                             std::to_string(detections.sizes[c]->height) +
                             "; one camera's images must all have one size");
      }
    }
    calib::StereoView& view = result.view;
    view.left_name = pair.left_name;
    view.right_name = pair.right_name;
    view.timestamp = pair.timestamp.value_or(0.0);
    if (!view.note.empty() && !one_camera) {
      detections.warnings.push_back(pair.left_name + " and " + pair.right_name +
                                    ": " + view.note);
    }
    detections.views.push_back(std::move(view));
  }
  CountViews(&detections);
  return detections;
}

Status WriteCamchainWithCovariance(
    const std::string& camchain_path, const Camchain& camchain,
    const CalibrationCovarianceFile& covariance) {
  const std::string covariance_path = CovarianceSidecarPath(camchain_path);
  RCM_RETURN_IF_ERROR(WriteCalibrationCovariance(covariance_path, covariance));
  const Status written = WriteCamchain(camchain_path, camchain);
  if (!written.ok()) {
    std::error_code ignored;
    fs::remove(covariance_path, ignored);
  }
  return written;
}

Status CheckDetections(const Detections& detections, bool one_camera) {
  if (!detections.sizes[0] && !detections.sizes[1]) {
    const int more = detections.unreadable - 1;
    return Status::Error(
        "no pair could be read: " + detections.first_unreadable +
        (more > 0 ? " (and " + std::to_string(more) + " more " +
                        (more == 1 ? "pair)" : "pairs)")
                  : ""));
  }
  if (one_camera) {
    if (detections.left_only == 0) {
      return Status::Error("the target was found in none of the " +
                           std::to_string(detections.views.size()) +
                           " images; check the target flags and the images");
    }
    return Status::Ok();
  }
  if (detections.stereo == 0) {
    return Status::Error("the target was found in both images of no pair (" +
                         std::to_string(detections.left_only) + " left only, " +
                         std::to_string(detections.right_only) +
                         " right only, of " +
                         std::to_string(detections.views.size()) +
                         "); check the target flags and the images");
  }
  return Status::Ok();
}

}  // namespace rcm::cli
