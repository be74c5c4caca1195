// rcm calibrate: air stereo calibration from images of a target.
#include <gflags/gflags.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "command.h"
#include "image_input_flags.h"
#include "lens_model_flag.h"
#include "progress.h"
#include "rcm/calib/calibration_covariance.h"
#include "rcm/calib/calibration_report.h"
#include "rcm/calib/calibration_target.h"
#include "rcm/calib/cross_validation.h"
#include "rcm/calib/stereo_calibration.h"
#include "rcm/calib/target_detector.h"
#include "rcm/geometry/stereo_rig.h"
#include "rcm/io/atomic_file.h"
#include "rcm/io/calibration_covariance_file.h"
#include "rcm/io/camchain.h"
#include "rcm/io/number_format.h"
#include "target_flags.h"

DEFINE_string(report, "",
              "folder of the report (pictures, per-view CSV, JSON); default: "
              "next to the camchain, <name>-report");
DEFINE_int32(folds, 10,
             "cross-validation: calibrate again leaving out 1/folds of the "
             "views, folds times, and report the spread (0: off)");
DEFINE_double(huber, 1.0, "Huber loss scale of the robust solves, pixels");
DEFINE_double(outlier_sigmas, 5.0,
              "corners beyond this many robust sigmas are outliers (and "
              "beyond 2 px)");
DEFINE_int32(min_corners, 6,
             "fewest corners of a view in one image for it to be used");

namespace rcm::cli {
namespace {

using calib::CalibrationTarget;
using calib::ImageSize;
using calib::StereoCalibration;
using calib::StereoView;

constexpr char kUsage[] =
    "rcm calibrate: calibrate a stereo rig in air from images of a target\n\n"
    "usage:\n"
    "  rcm calibrate --left DIR --right DIR --board chessboard --cols 9 "
    "--rows 6\n"
    "      --square 0.025 [--model radtan|equidistant] --out camchain.yaml\n"
    "  rcm calibrate --bag FILE.bag --left-topic T0 --right-topic T1 "
    "--target april.yaml\n"
    "      --model equidistant --out camchain.yaml\n\n"
    "Detects the target in every pair, calibrates both cameras' lenses, the\n"
    "extrinsics cam1_from_cam0 (cam0 = left) and every target pose by a\n"
    "Ceres bundle adjustment, and writes the Kalibr camchain (--out) and a\n"
    "report folder: residual and coverage pictures, the projection\n"
    "uncertainty over each image, per-view RMS, calibration.json.\n"
    "--out names the camchain file (.yaml) or a folder that gets\n"
    "camchain.yaml and report/. Boards: chessboard (OpenCV's "
    "findChessboardCornersSB;\n"
    "--cols/--rows count inner corners), aprilgrid (Kalibr's, AprilTag "
    "36h11),\n"
    "charuco (OpenCV's).";

// Where the outputs go: --out FILE.yaml -> FILE.yaml + FILE-report/;
// --out DIR -> DIR/camchain.yaml + DIR/report/. --report overrides.
struct OutputPaths {
  std::string camchain;
  std::string report;
};

OutputPaths OutputPathsFromFlags() {
  namespace fs = std::filesystem;
  const fs::path out(FLAGS_out);
  const std::string extension = out.extension().string();
  OutputPaths paths;
  if (extension == ".yaml" || extension == ".yml") {
    paths.camchain = out.string();
    paths.report =
        (out.parent_path() / (out.stem().string() + "-report")).string();
  } else {
    paths.camchain = (out / "camchain.yaml").string();
    paths.report = (out / "report").string();
  }
  if (!FLAGS_report.empty()) paths.report = FLAGS_report;
  return paths;
}

// "fx 532.69 +- 0.37" with the leave-out sigma when there is one.
std::string WithSigma(double value, double sigma, int digits,
                      std::optional<double> jackknife) {
  std::string text =
      FormatFixed(value, digits) + " +- " + FormatFixed(sigma, digits);
  if (jackknife) text += " (" + FormatFixed(*jackknife, digits) + ")";
  return text;
}

// Whether `folder` exists as a folder or can be created: its nearest
// existing ancestor must be a folder we may write in. Creates nothing, so
// that a run that fails later leaves no empty folders.
Status CheckFolderCanBeCreated(const std::string& folder) {
  namespace fs = std::filesystem;
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

// The outputs before the detection: a calibration is not wasted on a
// camchain or report that cannot be written.
Status CheckOutputPaths(const OutputPaths& paths) {
  namespace fs = std::filesystem;
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

// The detection pass over every pair. Its warnings wait until the pass is
// over, so that a run that fails says one thing, its error.
struct Detections {
  std::vector<StereoView> views;
  std::optional<ImageSize> sizes[2];
  int unreadable = 0;
  std::string first_unreadable;  // why the first unreadable pair was skipped
  std::vector<std::string> warnings;
};

StatusOr<Detections> DetectAll(StereoImageSource* source,
                               const CalibrationTarget& target) {
  Detections detections;
  const size_t pairs = source->NumPairs();
  Progress progress("rcm calibrate: detecting, pair", pairs);
  int found = 0;
  for (size_t i = 0; i < pairs; ++i) {
    StatusOr<StereoImagePair> pair = source->ReadPair(i);
    if (!pair.ok()) {
      // One unreadable image loses its pair, never the pairing of others.
      detections.warnings.push_back(pair.status().message() + "; pair skipped");
      if (detections.unreadable++ == 0) {
        detections.first_unreadable = pair.status().message();
      }
      progress.Update(i + 1);
      continue;
    }
    const cv::Mat* images[2] = {&pair->left, &pair->right};
    const std::string* names[2] = {&pair->left_name, &pair->right_name};
    for (int c = 0; c < 2; ++c) {
      const ImageSize size{images[c]->cols, images[c]->rows};
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
    StereoView view = calib::DetectTargetPair(pair->left, pair->right, target);
    view.left_name = pair->left_name;
    view.right_name = pair->right_name;
    view.timestamp = pair->timestamp.value_or(0.0);
    if (!view.note.empty()) {
      detections.warnings.push_back(pair->left_name + " and " +
                                    pair->right_name + ": " + view.note);
    }
    found += view.stereo() ? 1 : 0;
    detections.views.push_back(std::move(view));
    progress.Update(i + 1, std::to_string(found) + " with the target in both");
  }
  return detections;
}

nlohmann::json CameraJson(const calib::CameraCalibration& calibration) {
  const Camera& camera = calibration.camera;
  nlohmann::json json;
  json["distortion_model"] = std::string(LensModelName(camera.model()));
  json["resolution"] = {camera.width(), camera.height()};
  json["intrinsics"] = {camera.fx(), camera.fy(), camera.cx(), camera.cy()};
  json["distortion_coeffs"] = camera.Distortion();
  std::vector<double> sigma(calibration.sigma.begin(),
                            calibration.sigma.begin() + camera.num_params());
  json["sigma"] = sigma;
  return json;
}

int RunCalibrate();

}  // namespace

extern const Subcommand kCalibrateCommand = {
    "calibrate",
    "air stereo calibration from target images (folders or a ROS1 bag)",
    kUsage,
    {__FILE__, kImageInputFlagsSource, kTargetFlagsSource,
     kLensModelFlagSource},
    RunCalibrate};

namespace {

int RunCalibrate() {
  const Subcommand& command = kCalibrateCommand;
  const auto start = std::chrono::steady_clock::now();
  if (FLAGS_out.empty()) {
    PrintError(command,
               "--out is required: the camchain to write (e.g. --out "
               "camchain.yaml) or a folder");
    return kExitUsage;
  }
  if (!ImageInputGiven()) {
    PrintError(command,
               "no images: give --left DIR --right DIR, --pairs FILE or --bag "
               "FILE with --left-topic/--right-topic");
    return kExitUsage;
  }
  const StatusOr<LensModelId> model = LensModelFromFlag(LensModelId::kRadTan);
  if (!model.ok()) {
    PrintError(command, model.status().message());
    return kExitUsage;
  }
  calib::StereoCalibrationOptions options;
  options.model = *model;
  options.huber_px = FLAGS_huber;
  options.outlier_sigmas = FLAGS_outlier_sigmas;
  options.min_corners_per_view = FLAGS_min_corners;
  if (const Status status = options.Check(); !status.ok()) {
    PrintError(command, status.message());
    return kExitUsage;
  }
  if (FLAGS_folds < 0 || FLAGS_folds == 1) {
    PrintError(command, "--folds must be 0 (off) or at least 2");
    return kExitUsage;
  }
  const StatusOr<CalibrationTarget> target = TargetFromFlags();
  if (!target.ok()) {
    PrintError(command, target.status().message());
    return kExitUsage;
  }
  const OutputPaths paths = OutputPathsFromFlags();

  StatusOr<std::unique_ptr<StereoImageSource>> source =
      OpenImageInputFromFlags();
  if (!source.ok()) {
    PrintError(command, source.status().message());
    return kExitFailure;
  }
  if ((*source)->NumPairs() == 0) {
    PrintError(command, (*source)->Describe() + ": no image pairs");
    return kExitFailure;
  }
  if (const Status status = CheckOutputPaths(paths); !status.ok()) {
    PrintError(command, status.message());
    return kExitFailure;
  }
  // What is being calibrated, with the report on stdout; stderr keeps to
  // warnings and the error.
  if (!FLAGS_json) {
    std::cout << "rcm calibrate: " << (*source)->Describe() << "; target "
              << calib::DescribeTarget(*target) << std::endl;
  }
  StatusOr<Detections> detections = DetectAll(source->get(), *target);
  if (!detections.ok()) {
    PrintError(command, detections.status().message());
    return kExitFailure;
  }
  const std::vector<StereoView>& views = detections->views;
  int stereo = 0;
  int left_only = 0;
  int right_only = 0;
  for (const StereoView& view : views) {
    stereo += view.stereo() ? 1 : 0;
    left_only += view.left && !view.right ? 1 : 0;
    right_only += view.right && !view.left ? 1 : 0;
  }
  if (!detections->sizes[0] || !detections->sizes[1]) {
    const int more = detections->unreadable - 1;
    PrintError(command,
               "no pair could be read: " + detections->first_unreadable +
                   (more > 0 ? " (and " + std::to_string(more) + " more " +
                                   (more == 1 ? "pair)" : "pairs)")
                             : ""));
    return kExitFailure;
  }
  if (stereo == 0) {
    PrintError(command, "the target was found in both images of no pair (" +
                            std::to_string(left_only) + " left only, " +
                            std::to_string(right_only) + " right only, of " +
                            std::to_string(views.size()) +
                            "); check the target flags and the images");
    return kExitFailure;
  }
  const ImageSize sizes[2] = {*detections->sizes[0], *detections->sizes[1]};
  for (const std::string& warning : detections->warnings) {
    PrintWarning(command, warning);
  }

  Progress solving("rcm calibrate: bundle adjustment", 2);
  solving.Update(1);
  const StatusOr<StereoCalibration> calibration =
      calib::CalibrateStereo(*target, views, sizes[0], sizes[1], options);
  solving.Update(2);
  if (!calibration.ok()) {
    PrintError(command, calibration.status().message());
    return kExitFailure;
  }

  std::optional<calib::CrossValidation> cross_validation;
  if (FLAGS_folds >= 2) {
    calib::CrossValidationOptions cv_options;
    cv_options.folds = FLAGS_folds;
    Progress progress("rcm calibrate: cross-validation, fold",
                      std::min<size_t>(FLAGS_folds, views.size()));
    StatusOr<calib::CrossValidation> result = calib::CrossValidateStereo(
        *target, views, sizes[0], sizes[1], *calibration, options, cv_options,
        [&progress](int done, int) { progress.Update(done); });
    if (result.ok()) {
      cross_validation = *result;
    } else {
      PrintWarning(command, result.status().message());
    }
  }

  calib::CalibrationReport report =
      calib::SummarizeCalibration(*calibration, views, sizes[0], sizes[1]);
  if (cross_validation) {
    for (const calib::ParameterSpread& p : cross_validation->parameters) {
      // The covariance assumes independent corner noise; a leave-out
      // spread well above it means errors correlated within views.
      if (p.jackknife_sigma > 2.0 * p.reported_sigma) {
        report.warnings.push_back(
            p.name + ": the leave-out spread (sigma " +
            FormatFixed(p.jackknife_sigma, p.unit == "m" ? 6 : 3) + " " +
            p.unit + ") is " +
            FormatFixed(p.jackknife_sigma / p.reported_sigma, 1) +
            "x the covariance's; corner errors are correlated within views "
            "(board flatness, blur, lens model): trust the leave-out figure");
        break;
      }
    }
  }

  // The rig file is the product: written last, after the report, so that a
  // camchain on disk always comes with its report.
  Camchain camchain;
  {
    StatusOr<StereoRig> rig =
        StereoRig::Create(calibration->cam0.camera, calibration->cam1.camera,
                          calibration->cam1_from_cam0);
    if (!rig.ok()) {
      PrintError(command, rig.status().message());
      return kExitFailure;
    }
    camchain = CamchainFromStereoRig(*rig);
    if (!FLAGS_bag.empty()) {
      camchain.cameras[0].rostopic = FLAGS_left_topic;
      camchain.cameras[1].rostopic = FLAGS_right_topic;
    }
  }

  nlohmann::json json;
  json["camchain"] = paths.camchain;
  json["covariance"] = CovarianceSidecarPath(paths.camchain);
  json["report"] = paths.report;
  json["target"] = calib::DescribeTarget(*target);
  json["source"] = (*source)->Describe();
  json["pairs"] = views.size() + detections->unreadable;
  json["unreadable_pairs"] = detections->unreadable;
  json["stereo_views"] = stereo;
  json["left_only_views"] = left_only;
  json["right_only_views"] = right_only;
  json["views_used"] = calibration->num_views_used;
  json["corners"] = calibration->num_inliers + calibration->num_outliers;
  json["outliers"] = calibration->num_outliers;
  json["rms_px"] = calibration->rms_px;
  json["inlier_rms_px"] = calibration->inlier_rms_px;
  json["pixel_sigma"] = calibration->pixel_sigma;
  json["initial_rms_px"] = calibration->initial_rms_px;
  json["cam0"] = CameraJson(calibration->cam0);
  json["cam1"] = CameraJson(calibration->cam1);
  json["cam1_from_cam0"] = {{"matrix", {}},
                            {"baseline", calibration->baseline},
                            {"baseline_sigma", calibration->baseline_sigma}};
  const Eigen::Matrix4d matrix = calibration->cam1_from_cam0.ToMatrix();
  for (int r = 0; r < 4; ++r) {
    json["cam1_from_cam0"]["matrix"].push_back(
        {matrix(r, 0), matrix(r, 1), matrix(r, 2), matrix(r, 3)});
  }
  std::vector<double> sigma6;
  for (int i = 0; i < 6; ++i) {
    sigma6.push_back(std::sqrt(calibration->extrinsics_covariance(i, i)));
  }
  json["cam1_from_cam0"]["sigma_rotation_rad"] = {sigma6[0], sigma6[1],
                                                  sigma6[2]};
  json["cam1_from_cam0"]["sigma_translation_m"] = {sigma6[3], sigma6[4],
                                                   sigma6[5]};
  for (int c = 0; c < 2; ++c) {
    const calib::CalibrationReport::CameraStats& s = report.cameras[c];
    json["coverage"]["cam" + std::to_string(c)] = s.coverage;
    json["projection_uncertainty_px"]["cam" + std::to_string(c)] = {
        {"median", JsonNumber(s.uncertainty_median_px)},
        {"p95", JsonNumber(s.uncertainty_p95_px)},
        {"max", JsonNumber(s.uncertainty_max_px)}};
  }
  if (cross_validation) {
    nlohmann::json folds = nlohmann::json::object();
    folds["folds"] = cross_validation->folds;
    folds["failed_folds"] = cross_validation->failed_folds;
    for (const calib::ParameterSpread& p : cross_validation->parameters) {
      folds["parameters"][p.name] = {{"full", p.full},
                                     {"min", p.min},
                                     {"max", p.max},
                                     {"jackknife_sigma", p.jackknife_sigma},
                                     {"covariance_sigma", p.reported_sigma}};
    }
    json["cross_validation"] = folds;
  }
  json["warnings"] = report.warnings;

  if (Status status = calib::WriteCalibrationReport(
          paths.report, report, *calibration, views, sizes[0], sizes[1]);
      !status.ok()) {
    PrintError(command, status.message());
    return kExitFailure;
  }
  if (Status status = WriteFileAtomically(
          (std::filesystem::path(paths.report) / "calibration.json").string(),
          json.dump(2) + "\n");
      !status.ok()) {
    PrintError(command, status.message());
    return kExitFailure;
  }
  // The covariance sidecar, which the estimators read with the camchain
  // (rcm/io/calibration_covariance_file.h), just before it; removed again
  // if the camchain cannot be written, so that an older camchain never
  // gets this calibration's sidecar.
  const std::string covariance_path = CovarianceSidecarPath(paths.camchain);
  if (Status status = WriteCalibrationCovariance(
          covariance_path,
          calib::AirCalibrationCovariance(*calibration, cross_validation));
      !status.ok()) {
    PrintError(command, status.message());
    return kExitFailure;
  }
  if (Status status = WriteCamchain(paths.camchain, camchain); !status.ok()) {
    std::error_code ignored;
    std::filesystem::remove(covariance_path, ignored);
    PrintError(command, status.message());
    return kExitFailure;
  }

  for (const std::string& warning : report.warnings) {
    PrintWarning(command, warning);
  }
  if (FLAGS_json) {
    std::cout << json.dump(2) << std::endl;
    return kExitOk;
  }
  auto jackknife = [&](const std::string& name) -> std::optional<double> {
    if (!cross_validation) return std::nullopt;
    for (const calib::ParameterSpread& p : cross_validation->parameters) {
      if (p.name == name) return p.jackknife_sigma;
    }
    return std::nullopt;
  };
  std::printf("%d views used (%d stereo), %d corners, %d outliers\n",
              calibration->num_views_used, calibration->num_stereo_views,
              calibration->num_inliers + calibration->num_outliers,
              calibration->num_outliers);
  std::printf("rms %.4f px (inliers %.4f px), pixel noise %.4f px per axis\n",
              calibration->rms_px, calibration->inlier_rms_px,
              calibration->pixel_sigma);
  std::printf("+- covariance sigma%s\n",
              cross_validation ? " (leave-out sigma)" : "");
  for (int c = 0; c < 2; ++c) {
    const calib::CameraCalibration& cc =
        c == 0 ? calibration->cam0 : calibration->cam1;
    const std::string cam = "cam" + std::to_string(c);
    std::printf(
        "%s %s  fx %s  fy %s  cx %s  cy %s\n", cam.c_str(),
        std::string(LensModelName(cc.camera.model())).c_str(),
        WithSigma(cc.camera.fx(), cc.sigma[0], 2, jackknife(cam + " fx"))
            .c_str(),
        WithSigma(cc.camera.fy(), cc.sigma[1], 2, jackknife(cam + " fy"))
            .c_str(),
        WithSigma(cc.camera.cx(), cc.sigma[2], 2, jackknife(cam + " cx"))
            .c_str(),
        WithSigma(cc.camera.cy(), cc.sigma[3], 2, jackknife(cam + " cy"))
            .c_str());
    std::string distortion;
    const std::vector<double> d = cc.camera.Distortion();
    for (size_t i = 0; i < d.size(); ++i) {
      distortion += (i ? ", " : "") + FormatFixed(d[i], 5) + " +- " +
                    FormatFixed(cc.sigma[4 + i], 5);
    }
    if (!distortion.empty()) {
      std::printf("     distortion [%s]\n", distortion.c_str());
    }
  }
  std::printf(
      "baseline %s mm, rotation %.4f deg\n",
      WithSigma(1e3 * calibration->baseline, 1e3 * calibration->baseline_sigma,
                3,
                jackknife("baseline")
                    ? std::optional<double>(1e3 * *jackknife("baseline"))
                    : std::nullopt)
          .c_str(),
      calibration->cam1_from_cam0.RotationAngle() * 180.0 / M_PI);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
          .count();
  std::printf("wrote %s (with %s) and %s/ in %.1f s\n",
              paths.camchain.c_str(),
              CovarianceSidecarPath(paths.camchain).c_str(),
              paths.report.c_str(), seconds);
  return kExitOk;
}

}  // namespace
}  // namespace rcm::cli
