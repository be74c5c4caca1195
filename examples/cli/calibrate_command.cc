// rcm calibrate: air calibration of a stereo rig, or of one camera (--left
// alone), from images of a target.
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

#include "air_flag.h"
#include "air_gap_flag.h"
#include "air_views_flags.h"
#include "calibrate_dome.h"
#include "calibrate_underwater.h"
#include "calibration_input.h"
#include "calibration_run.h"
#include "command.h"
#include "dome_port_flags.h"
#include "glass_index_flag.h"
#include "image_input_flags.h"
#include "index_flag.h"
#include "lens_model_flag.h"
#include "medium_flag.h"
#include "progress.h"
#include "rcm/calib/calibration_covariance.h"
#include "rcm/calib/calibration_report.h"
#include "rcm/calib/calibration_target.h"
#include "rcm/calib/cross_validation.h"
#include "rcm/calib/mono_calibration.h"
#include "rcm/calib/projection_uncertainty.h"
#include "rcm/calib/stereo_calibration.h"
#include "rcm/calib/target_detector.h"
#include "rcm/io/atomic_file.h"
#include "rcm/io/calibration_covariance_file.h"
#include "rcm/io/camchain.h"
#include "rcm/stereo/stereo_rig.h"
#include "rcm/util/number_format.h"
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
DEFINE_bool(flat_board, false,
            "assume the board is flat: do not estimate its bow (two "
            "parameters shared by all views, mrcal's calobject_warp; also "
            "with --underwater)");
DEFINE_string(uncertainty_distance, "inf",
              "distance [m] of the projection uncertainty in the report "
              "(mrcal's mean-frames method through the board poses); inf: "
              "at infinity; not with --underwater");
DEFINE_int32(min_corners, 6,
             "fewest corners of a view in one image for it to be used");

namespace rcm::cli {
namespace {

using calib::CalibrationTarget;
using calib::ImageSize;
using calib::StereoCalibration;
using calib::StereoView;

constexpr char kCalibrateUsage[] =
    "rcm calibrate: calibrate a stereo rig (or one camera) in air from images\n"
    "of a target, or refine it under water\n\n"
    "usage:\n"
    "  rcm calibrate --left DIR --right DIR --board chessboard --cols 9 "
    "--rows 6\n"
    "      --square 0.025 [--model radtan|equidistant|rational|ds|eucm]\n"
    "      --out camchain.yaml\n"
    "  rcm calibrate --left DIR --board chessboard --cols 9 --rows 6 "
    "--square 0.025\n"
    "      --out camera.yaml                      (one camera)\n"
    "  rcm calibrate --bag FILE.bag --left-topic T0 --right-topic T1 "
    "--target april.yaml\n"
    "      --model equidistant --out camchain.yaml\n"
    "  rcm calibrate --bag FILE.bag --left-topic T0 --target april.yaml "
    "--out camera.yaml\n"
    "                                             (one camera)\n\n"
    "Detects the target in every pair, calibrates both cameras' lenses, the\n"
    "extrinsics cam1_from_cam0 (cam0 = left) and every target pose by a\n"
    "Ceres bundle adjustment (with the board's bow, two parameters shared\n"
    "by all views, as mrcal's calobject_warp; --flat-board assumes a flat\n"
    "board, as OpenCV does), and writes the Kalibr camchain (--out) and a\n"
    "report folder: residual and coverage pictures, the projection\n"
    "uncertainty over each image (mrcal's mean-frames method, through the\n"
    "board poses, at --uncertainty-distance, default infinity; and the\n"
    "intrinsics-only figure), per-view RMS, calibration.json.\n"
    "--left alone (or --corners with --left only, or --bag with --left-topic\n"
    "alone) calibrates one camera the same way, without the extrinsics, and\n"
    "writes a camchain with cam0 only (the stereo subcommands refuse it:\n"
    "they need a pair).\n"
    "--out names the camchain file (.yaml) or a folder that gets\n"
    "camchain.yaml and report/; camchain-covariance.yaml beside the camchain\n"
    "tells rcm estimate how well it is known.\n\n"
    "Under water, at the start of a dive (about 20 views of the target):\n"
    "  rcm calibrate --underwater --air AIR.yaml --left DIR --right DIR \\\n"
    "      --board chessboard --cols 9 --rows 6 --square 0.03 --out water/\n"
    "keeps the air lenses and estimates n, cam1_from_cam0 as it is in the\n"
    "water and every target pose through the refractive model, under each\n"
    "candidate model (board flat or bowed; ports thin, with air gaps,\n"
    "tilted, or both; --flat-board, --thin-port, --estimate-air-gap,\n"
    "--estimate-port-tilt narrow them), chooses the one that best predicts\n"
    "views left out, and counts the models the data cannot tell apart and\n"
    "the air lenses' uncertainty in sigma_n; --left alone: one camera. It\n"
    "writes the camchain with the underwater extrinsics, which rcm estimate,\n"
    "undistort and export take as they are, and a report (underwater.json,\n"
    "residual and coverage pictures, per-view RMS).\n"
    "With the air views too (--air-left DIR --air-right DIR, or\n"
    "--air-corners FILE with --air-left/--air-right naming its rows), one\n"
    "bundle adjustment estimates the lenses from air and water together\n"
    "(started from --air's), with n, both media's extrinsics and every pose;\n"
    "--same-board: one board, one bow in both media (--air-target FILE: the\n"
    "air board, when it is another). The camchain then holds those lenses\n"
    "and its sidecar their joint covariance with the extrinsics.\n\n"
    "Boards: chessboard (OpenCV's "
    "findChessboardCornersSB;\n"
    "--cols/--rows count inner corners), aprilgrid (Kalibr's, AprilTag "
    "36h11),\n"
    "charuco (OpenCV's).";

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

// cam1_from_cam0 of a pair: its matrix, baseline and sigmas.
nlohmann::json ExtrinsicsJson(const StereoCalibration& calibration) {
  nlohmann::json json = {{"matrix", {}},
                         {"baseline", calibration.baseline},
                         {"baseline_sigma", calibration.baseline_sigma}};
  const Eigen::Matrix4d matrix = calibration.cam1_from_cam0.ToMatrix();
  for (int r = 0; r < 4; ++r) {
    json["matrix"].push_back(
        {matrix(r, 0), matrix(r, 1), matrix(r, 2), matrix(r, 3)});
  }
  std::vector<double> sigma6;
  for (int i = 0; i < 6; ++i) {
    sigma6.push_back(std::sqrt(calibration.extrinsics_covariance(i, i)));
  }
  json["sigma_rotation_rad"] = {sigma6[0], sigma6[1], sigma6[2]};
  json["sigma_translation_m"] = {sigma6[3], sigma6[4], sigma6[5]};
  return json;
}

int RunCalibrate();

}  // namespace

extern const Subcommand kCalibrateCommand = {
    "calibrate",
    "air calibration of a stereo rig or one camera from target images "
    "(folders or a ROS1 bag)",
    kCalibrateUsage,
    {__FILE__, kImageInputFlagsSource, kCalibrationInputFlagsSource,
     kTargetFlagsSource, kLensModelFlagSource, kUnderwaterFlagsSource,
     kAirGapFlagSource, kAirFlagSource, kAirViewsFlagsSource, kMediumFlagSource,
     kDomeCalibrationFlagsSource, kDomePortFlagsSource, kGlassIndexFlagSource,
     kIndexFlagSource},
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
               "no images: give --left DIR --right DIR (--left DIR alone: one "
               "camera), --pairs FILE or --bag FILE with "
               "--left-topic/--right-topic (--left-topic alone: one camera)");
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
  options.estimate_board_warp = !FLAGS_flat_board;
  if (const Status status = options.Check(); !status.ok()) {
    PrintError(command, status.message());
    return kExitUsage;
  }
  if (FLAGS_folds < 0 || FLAGS_folds == 1) {
    PrintError(command, "--folds must be 0 (off) or at least 2");
    return kExitUsage;
  }
  double uncertainty_distance = calib::kInfiniteDistance;
  if (FLAGS_uncertainty_distance != "inf" &&
      FLAGS_uncertainty_distance != "infinity") {
    char* end = nullptr;
    errno = 0;
    uncertainty_distance =
        std::strtod(FLAGS_uncertainty_distance.c_str(), &end);
    if (end == FLAGS_uncertainty_distance.c_str() || *end != '\0' ||
        errno != 0 || !(uncertainty_distance > 0.0) ||
        !std::isfinite(uncertainty_distance)) {
      PrintError(command,
                 "--uncertainty-distance must be a positive distance in "
                 "meters or inf, got '" +
                     FLAGS_uncertainty_distance + "'");
      return kExitUsage;
    }
  }
  const StatusOr<CalibrationTarget> target = TargetFromFlags();
  if (!target.ok()) {
    PrintError(command, target.status().message());
    return kExitUsage;
  }
  const CalibrationOutputPaths paths =
      CalibrationOutputPathsFor(FLAGS_out, FLAGS_report);
  if (FLAGS_underwater) {
    if (!gflags::GetCommandLineFlagInfoOrDie("model").is_default) {
      PrintError(command,
                 "--model does not go with --underwater: the lenses are the "
                 "air calibration's (--air)");
      return kExitUsage;
    }
    if (!gflags::GetCommandLineFlagInfoOrDie("uncertainty_distance")
             .is_default) {
      PrintError(command,
                 "--uncertainty-distance does not go with --underwater: the "
                 "underwater report gives n's and the extrinsics' sigmas, "
                 "not a projection uncertainty (the lenses are --air's)");
      return kExitUsage;
    }
    UnderwaterRunOptions underwater;
    underwater.huber_px = FLAGS_huber;
    underwater.outlier_sigmas = FLAGS_outlier_sigmas;
    underwater.min_corners = FLAGS_min_corners;
    underwater.folds = FLAGS_folds;
    underwater.estimate_board_warp = !FLAGS_flat_board;
    return RunCalibrateUnderwater(command, *target, paths, underwater);
  }
  if (!FLAGS_air.empty() || FLAGS_estimate_air_gap ||
      FLAGS_estimate_port_tilt || FLAGS_thin_port || !FLAGS_medium.empty() ||
      AirViewsGiven() || FLAGS_same_board || !FLAGS_air_target.empty()) {
    PrintError(command,
               "--air, --air-left/--air-right/--air-corners, --air-target, "
               "--same-board, --estimate-air-gap, --estimate-port-tilt, "
               "--thin-port and --medium go with --underwater");
    return kExitUsage;
  }
  if (const Status status = CheckNoDomeFlags("an air calibration");
      !status.ok()) {
    PrintError(command, status.message());
    return kExitUsage;
  }

  // What is being calibrated, with the report on stdout; stderr keeps to
  // warnings and the error.
  StatusOr<CalibrationInput> input = ReadCalibrationInput(
      *target, /*allow_left_only=*/true, paths,
      [&target](const std::string& description) {
        if (!FLAGS_json) {
          std::cout << "rcm calibrate: " << description << "; target "
                    << calib::DescribeTarget(*target) << std::endl;
        }
      });
  if (!input.ok()) {
    PrintError(command, input.status().message());
    return kExitFailure;
  }
  const Detections* detections = &input->detections;
  const std::vector<StereoView>& views = detections->views;
  // --left alone (folders or a corners file) or --left-topic alone (a
  // bag): one camera.
  const bool one_camera = OneCameraImageInputGiven() && !detections->sizes[1];
  const int num_cameras = one_camera ? 1 : 2;
  if (const Status status = CheckDetections(*detections, one_camera);
      !status.ok()) {
    PrintError(command, status.message());
    return kExitFailure;
  }
  const int stereo = detections->stereo;
  const int left_only = detections->left_only;
  const int right_only = detections->right_only;
  // One camera: its size stands for cam1's, which the library ignores.
  const ImageSize sizes[2] = {*detections->sizes[0],
                              *detections->sizes[one_camera ? 0 : 1]};
  for (const std::string& warning : detections->warnings) {
    PrintWarning(command, warning);
  }

  Progress solving("rcm calibrate: bundle adjustment", 2);
  solving.Update(1);
  const StatusOr<StereoCalibration> calibration =
      one_camera
          ? calib::CalibrateMono(*target, views, sizes[0], options)
          : calib::CalibrateStereo(*target, views, sizes[0], sizes[1], options);
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

  calib::CalibrationReportOptions report_options;
  report_options.uncertainty_distance_m = uncertainty_distance;
  calib::CalibrationReport report = calib::SummarizeCalibration(
      *calibration, views, sizes[0], sizes[1], report_options);
  // The leave-out sigma of a quantity of the table (ParameterSpread::name).
  auto jackknife = [&](const std::string& name) -> std::optional<double> {
    if (!cross_validation) return std::nullopt;
    for (const calib::ParameterSpread& p : cross_validation->parameters) {
      if (p.name == name) return p.jackknife_sigma;
    }
    return std::nullopt;
  };
  if (cross_validation) {
    for (const calib::ParameterSpread& p : cross_validation->parameters) {
      // The covariance assumes independent corner noise; a leave-out
      // spread well above it means errors correlated within views.
      if (p.jackknife_sigma > 2.0 * p.reported_sigma) {
        report.warnings.push_back(
            p.name + ": the leave-out spread (sigma " +
            (p.name == "board bowl"
                 ? FormatFixed(1e3 * p.jackknife_sigma, 3) + " mm"
                 : FormatFixed(p.jackknife_sigma, p.unit == "m" ? 6 : 3) + " " +
                       p.unit) +
            ") is " + FormatFixed(p.jackknife_sigma / p.reported_sigma, 1) +
            "x the covariance's; corner errors are correlated within views "
            "(board flatness, blur, lens model): trust the leave-out figure");
        break;
      }
    }
  }

  // The rig file is the product: written last, after the report, so that a
  // camchain on disk always comes with its report.
  Camchain camchain;
  if (one_camera) {
    camchain.cameras.push_back(
        CamchainCamera{calibration->cam0.camera, std::nullopt, std::nullopt,
                       std::nullopt, std::vector<int>(), std::string()});
    if (!FLAGS_bag.empty()) camchain.cameras[0].rostopic = FLAGS_left_topic;
  } else {
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
  json["source"] = input->description;
  json["cameras"] = num_cameras;
  json["pairs"] = views.size() + detections->unreadable;
  json["unreadable_pairs"] = detections->unreadable;
  if (!one_camera) {
    json["stereo_views"] = stereo;
    json["left_only_views"] = left_only;
    json["right_only_views"] = right_only;
  }
  json["views_used"] = calibration->num_views_used;
  json["corners"] = calibration->num_inliers + calibration->num_outliers;
  json["outliers"] = calibration->num_outliers;
  json["rms_px"] = calibration->rms_px;
  json["inlier_rms_px"] = calibration->inlier_rms_px;
  json["pixel_sigma"] = calibration->pixel_sigma;
  json["initial_rms_px"] = calibration->initial_rms_px;
  json["cam0"] = CameraJson(calibration->cam0);
  if (!one_camera) {
    json["cam1"] = CameraJson(calibration->cam1);
    json["cam1_from_cam0"] = ExtrinsicsJson(*calibration);
  }
  json["board_flatness"] = BoardFlatnessJson(
      calibration->board_warp_estimated, calibration->board_warp,
      calibration->board_warp_covariance, jackknife("board bowl"));
  for (int c = 0; c < num_cameras; ++c) {
    const calib::CalibrationReport::CameraStats& s = report.cameras[c];
    json["coverage"]["cam" + std::to_string(c)] = s.coverage;
    // mrcal's mean-frames figure at the stated distance, and the
    // intrinsics-only one (the ray held fixed in the camera).
    json["projection_uncertainty"]["cam" + std::to_string(c)] = {
        {"distance_m", std::isinf(uncertainty_distance)
                           ? nlohmann::json("inf")
                           : nlohmann::json(uncertainty_distance)},
        {"median_px", JsonNumber(s.projection_uncertainty_median_px)},
        {"p95_px", JsonNumber(s.projection_uncertainty_p95_px)},
        {"max_px", JsonNumber(s.projection_uncertainty_max_px)}};
    json["intrinsics_only_uncertainty_px"]["cam" + std::to_string(c)] = {
        {"median", JsonNumber(s.intrinsics_only_uncertainty_median_px)},
        {"p95", JsonNumber(s.intrinsics_only_uncertainty_p95_px)},
        {"max", JsonNumber(s.intrinsics_only_uncertainty_max_px)}};
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
          paths.report, report, *calibration, views, sizes[0], sizes[1],
          report_options);
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
  if (Status status = WriteCamchainWithCovariance(
          paths.camchain, camchain,
          calib::AirCalibrationCovariance(*calibration, cross_validation));
      !status.ok()) {
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
  const std::string kind =
      one_camera ? "one camera"
                 : std::to_string(calibration->num_stereo_views) + " stereo";
  std::printf("%d views used (%s), %d corners, %d outliers\n",
              calibration->num_views_used, kind.c_str(),
              calibration->num_inliers + calibration->num_outliers,
              calibration->num_outliers);
  std::printf("rms %.4f px (inliers %.4f px), pixel noise %.4f px per axis\n",
              calibration->rms_px, calibration->inlier_rms_px,
              calibration->pixel_sigma);
  std::printf("+- covariance sigma%s\n",
              cross_validation ? " (leave-out sigma)" : "");
  for (int c = 0; c < num_cameras; ++c) {
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
  if (!one_camera) {
    std::printf(
        "baseline %s mm, rotation %.4f deg\n",
        WithSigma(1e3 * calibration->baseline,
                  1e3 * calibration->baseline_sigma, 3,
                  jackknife("baseline")
                      ? std::optional<double>(1e3 * *jackknife("baseline"))
                      : std::nullopt)
            .c_str(),
        calibration->cam1_from_cam0.RotationAngle() * 180.0 / M_PI);
  }
  for (int c = 0; c < num_cameras; ++c) {
    const calib::CalibrationReport::CameraStats& s = report.cameras[c];
    std::printf(
        "cam%d projection uncertainty at %s: median %.3f, 95 %% %.3f px "
        "(intrinsics only: median %.3f px)\n",
        c, calib::DistanceName(uncertainty_distance).c_str(),
        s.projection_uncertainty_median_px, s.projection_uncertainty_p95_px,
        s.intrinsics_only_uncertainty_median_px);
  }
  std::printf("%s\n", BoardFlatnessText(calibration->board_warp_estimated,
                                        calibration->board_warp,
                                        calibration->board_warp_covariance,
                                        jackknife("board bowl"))
                          .c_str());
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
          .count();
  std::printf("wrote %s (with %s) and %s/ in %.1f s\n", paths.camchain.c_str(),
              CovarianceSidecarPath(paths.camchain).c_str(),
              paths.report.c_str(), seconds);
  return kExitOk;
}

}  // namespace
}  // namespace rcm::cli
