// rcm calibrate --underwater --port dome: see calibrate_dome.h.
#include "calibrate_dome.h"

#include <gflags/gflags.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "air_flag.h"
#include "air_gap_flag.h"
#include "air_views_flags.h"
#include "calibration_input.h"
#include "dome_port_flags.h"
#include "image_input_flags.h"
#include "index_flag.h"
#include "medium_flag.h"
#include "progress.h"
#include "rcm/calib/dome_calibration.h"
#include "rcm/io/atomic_file.h"
#include "rcm/io/camchain.h"
#include "rcm/util/number_format.h"

DEFINE_bool(estimate_n, false,
            "rcm calibrate --underwater --port dome: estimate n with the "
            "decentering (weakly observable through a dome: n and the "
            "dome's axial decentering both scale the image with distance; "
            "the report gives their correlation); otherwise n is held at "
            "--n");

namespace rcm::cli {

extern const char kDomeCalibrationFlagsSource[] = __FILE__;

namespace {

using calib::DomeCalibration;
using calib::ImageSize;
using calib::StereoView;

std::string MillimetresText(const Eigen::Vector3d& value,
                            const Eigen::Vector3d& sigma) {
  std::string text = "(";
  for (int i = 0; i < 3; ++i) {
    text += (i == 0 ? "" : ", ") + FormatFixed(1e3 * value[i], 2) + " +- " +
            FormatFixed(1e3 * sigma[i], 2);
  }
  return text + ") mm";
}

// The flags of the flat-port path that a dome does not take.
Status CheckDomeFlags() {
  if (FLAGS_estimate_air_gap || FLAGS_estimate_port_tilt || FLAGS_thin_port) {
    return Status::Error(
        "--port dome: --estimate-air-gap, --estimate-port-tilt and "
        "--thin-port describe flat ports");
  }
  if (FLAGS_air.empty()) {
    return Status::Error(
        "--underwater --port dome needs --air AIR.yaml, the in-air "
        "calibration of the camera (or rig) whose lenses it keeps");
  }
  if (FLAGS_air.find(',') != std::string::npos) {
    return Status::Error("--port dome: --air must be one camchain, not " +
                         FLAGS_air);
  }
  return Status::Ok();
}

}  // namespace

Status CheckNoDomeFlags(const std::string& where) {
  if (FLAGS_port != "flat" && FLAGS_port != "dome") {
    return Status::Error("--port " + FLAGS_port + ": expected flat or dome");
  }
  if (FLAGS_port == "dome") {
    return Status::Error("--port dome goes with --underwater, not " + where);
  }
  const std::string given = FirstGivenFlag(
      {"dome_inner_radius", "dome_thickness", "dome_outer_radius",
       "dome_decentering", "glass_index", "estimate_n", "n"});
  if (!given.empty()) {
    return Status::Error(given + " goes with --underwater --port dome, not " +
                         where);
  }
  return Status::Ok();
}

bool AirCamchainHasDomes() {
  if (FLAGS_air.empty() || FLAGS_air.find(',') != std::string::npos) {
    return false;
  }
  const StatusOr<Camchain> camchain = ReadCamchain(FLAGS_air);
  if (!camchain.ok()) return false;
  for (const CamchainCamera& camera : camchain->cameras) {
    if (camera.dome.has_value()) return true;
  }
  return false;
}

int RunCalibrateDome(const Subcommand& command,
                     const calib::CalibrationTarget& target,
                     const CalibrationOutputPaths& paths,
                     const UnderwaterRunOptions& run) {
  const auto start = std::chrono::steady_clock::now();
  if (const Status status = CheckDomeFlags(); !status.ok()) {
    PrintError(command, status.message());
    return kExitUsage;
  }
  const StatusOr<std::optional<MediumPrior>> medium = MediumFromFlag();
  if (!medium.ok()) {
    PrintError(command, medium.status().message());
    return kExitUsage;
  }
  calib::DomeCalibrationOptions options;
  options.estimate_n = FLAGS_estimate_n;
  options.n = FLAGS_n;
  options.estimate_board_warp = run.estimate_board_warp;
  options.huber_px = run.huber_px;
  options.outlier_sigmas = run.outlier_sigmas;
  options.min_corners_per_view = run.min_corners;
  options.folds = run.folds;
  if (const Status status = options.Check(); !status.ok()) {
    PrintError(command, "--port dome: " + status.message());
    return kExitUsage;
  }
  const StatusOr<Camchain> air = ReadCamchain(FLAGS_air);
  if (!air.ok()) {
    PrintError(command, air.status().message());
    return kExitFailure;
  }
  // The air views of the joint calibration (the lenses estimated, the air
  // views traced through the dome at n = 1) and the water views.
  StatusOr<UnderwaterInputs> inputs = ReadUnderwaterInputs(
      target, paths, run.estimate_board_warp,
      /*allow_left_only_air=*/FLAGS_right.empty(),
      "rcm calibrate --underwater --port dome",
      "lenses from air and water together, the air views through the dome");
  if (!inputs.ok()) {
    PrintError(command, inputs.status().message());
    return kExitFailure;
  }
  const std::optional<AirViewsInput>& air_views = inputs->air_views;
  const CalibrationInput* input = &inputs->input;
  const Detections& detections = input->detections;
  const bool one_camera =
      !detections.sizes[1].has_value() && detections.right_only == 0;
  const int num_cameras = one_camera ? 1 : 2;
  if (static_cast<int>(air->cameras.size()) < num_cameras) {
    PrintError(command, FLAGS_air +
                            " has one camera (cam0), but the images are of "
                            "a stereo pair: give the pair's air camchain");
    return kExitFailure;
  }
  if (const Status status = CheckDetections(detections, one_camera);
      !status.ok()) {
    PrintError(command, "under water: " + status.message());
    return kExitFailure;
  }
  const StatusOr<std::vector<DomePort>> domes =
      DomesOfCameras(*air, num_cameras);
  if (!domes.ok()) {
    PrintError(command, domes.status().message());
    return kExitFailure;
  }
  std::vector<calib::DomeCameraInput> cameras;
  ImageSize sizes[2];
  for (int c = 0; c < num_cameras; ++c) {
    const Camera& camera = air->cameras[c].camera;
    sizes[c] = ImageSize{camera.width(), camera.height()};
    if (detections.sizes[c] &&
        (detections.sizes[c]->width != sizes[c].width ||
         detections.sizes[c]->height != sizes[c].height)) {
      PrintError(command,
                 std::string(c == 0 ? "the left" : "the right") +
                     " images are " +
                     std::to_string(detections.sizes[c]->width) + "x" +
                     std::to_string(detections.sizes[c]->height) + " but cam" +
                     std::to_string(c) + " of " + FLAGS_air + " is " +
                     std::to_string(sizes[c].width) + "x" +
                     std::to_string(sizes[c].height) +
                     ": the air calibration must be of these cameras at "
                     "this resolution");
      return kExitFailure;
    }
    cameras.push_back({camera, (*domes)[c]});
  }
  if (one_camera) sizes[1] = sizes[0];
  Rigid3d cam1_from_cam0;
  if (!one_camera) {
    const StatusOr<StereoRig> rig = StereoRigFromCamchain(
        [&] {
          Camchain lenses = *air;
          for (CamchainCamera& camera : lenses.cameras) camera.dome.reset();
          return lenses;
        }(),
        0, 1);
    if (!rig.ok()) {
      PrintError(command, FLAGS_air + ": " + rig.status().message());
      return kExitFailure;
    }
    cam1_from_cam0 = rig->right_from_left();
  }
  for (const std::string& warning : detections.warnings) {
    PrintWarning(command, warning);
  }

  std::optional<Progress> solving(std::in_place,
                                  "rcm calibrate: the dome's decentering", 1);
  const StatusOr<DomeCalibration> result =
      calib::CalibrateDome(detections.views, cameras, cam1_from_cam0, target,
                           options, air_views ? &air_views->views : nullptr);
  solving.reset();
  if (!result.ok()) {
    PrintError(command, result.status().message());
    return kExitFailure;
  }

  // The report first, the camchain last.
  calib::StereoCalibration drawing(result->cameras[0],
                                   result->cameras[num_cameras - 1]);
  drawing.num_cameras = num_cameras;
  drawing.cam1_from_cam0 = cam1_from_cam0;
  drawing.cam0_from_target = result->cam0_from_target;
  drawing.corners = result->corners;
  drawing.rms_px = result->rms_px;
  drawing.inlier_rms_px = result->inlier_rms_px;
  drawing.pixel_sigma = result->pixel_sigma;
  drawing.num_views_used = result->num_views_used;
  drawing.num_inliers = result->num_inliers;
  drawing.num_outliers = result->num_outliers;
  calib::CalibrationReport report;
  if (const Status status = WriteUnderwaterReport(
          paths.report, drawing, detections.views, sizes, one_camera, &report);
      !status.ok()) {
    PrintError(command, status.message());
    return kExitFailure;
  }

  std::vector<std::string> warnings;
  if (air_views) {
    warnings.insert(warnings.end(), air_views->warnings.begin(),
                    air_views->warnings.end());
  }
  const calib::ConventionalFit& conventional = result->conventional;
  // As the flat-port path: the pixel noise accounts for the conventional
  // fit's more unknowns; 10 % below the dome's is a better fit.
  if (conventional.ok && conventional.pixel_sigma < 0.9 * result->pixel_sigma) {
    warnings.push_back(
        "a conventional " + std::string(LensModelName(conventional.model)) +
        " model fitted freely to the same corners fits them better (pixel "
        "noise " +
        FormatFixed(conventional.pixel_sigma, 3) + " px against " +
        FormatFixed(result->pixel_sigma, 3) +
        " px): the dome's geometry (radii, glass) may be wrong, or the lens "
        "changed since the air calibration");
  }
  for (int c = 0; c < num_cameras; ++c) {
    if (result->decentering_sigma[c].maxCoeff() > 1e-3) {
      warnings.push_back(
          "cam" + std::to_string(c) +
          ": the decentering is uncertain by more than 1 mm; views nearer "
          "the dome and at more distances pin it");
    }
  }
  nlohmann::json medium_json = nullptr;
  if (*medium && result->n_estimated) {
    const MediumCheck check =
        CheckAgainstMedium(result->n, result->sigma_n, **medium);
    medium_json = MediumJson(**medium, check);
    if (check.contradicts) warnings.push_back(check.message);
  }
  for (const std::string& warning : report.warnings) {
    warnings.push_back(warning);
  }

  nlohmann::json json;
  json["camchain"] = paths.camchain;
  json["report"] = paths.report;
  json["air"] = FLAGS_air;
  json["target"] = calib::DescribeTarget(target);
  json["source"] = input->description;
  json["port"] = "dome";
  json["cameras"] = num_cameras;
  nlohmann::json decentering = nlohmann::json::array();
  nlohmann::json decentering_sigma = nlohmann::json::array();
  nlohmann::json decentering_sigma_model = nlohmann::json::array();
  nlohmann::json correlation = nlohmann::json::array();
  nlohmann::json dome_json = nlohmann::json::array();
  for (int c = 0; c < num_cameras; ++c) {
    decentering.push_back(Vector3Json(result->decentering[c]));
    decentering_sigma.push_back(Vector3Json(result->decentering_sigma[c]));
    decentering_sigma_model.push_back(
        Vector3Json(result->decentering_sigma_model[c]));
    correlation.push_back(Vector3Json(result->correlation_n_decentering[c]));
    dome_json.push_back({{"inner_radius_m", (*domes)[c].inner_radius},
                         {"thickness_m", (*domes)[c].thickness},
                         {"glass_index", (*domes)[c].glass_index}});
  }
  json["decentering_m"] = decentering;
  json["decentering_sigma_m"] = decentering_sigma;
  json["decentering_sigma_model_m"] = decentering_sigma_model;
  nlohmann::json leave_out = nlohmann::json::array();
  for (int c = 0; c < num_cameras; ++c) {
    leave_out.push_back(Vector3Json(result->decentering_sigma_leave_out[c]));
  }
  json["decentering_sigma_leave_out_m"] = leave_out;
  json["folds"] = result->folds;
  json["failed_folds"] = result->failed_folds;
  json["dome"] = dome_json;
  json["n"] = result->n;
  json["n_estimated"] = result->n_estimated;
  json["sigma_n"] = result->n_estimated ? nlohmann::json(result->sigma_n)
                                        : nlohmann::json(nullptr);
  json["sigma_n_model"] = result->n_estimated
                              ? nlohmann::json(result->sigma_n_model)
                              : nlohmann::json(nullptr);
  json["correlation_n_decentering"] =
      result->n_estimated ? correlation : nlohmann::json(nullptr);
  json["medium"] = medium_json;
  nlohmann::json candidates = nlohmann::json::array();
  for (const calib::DomeCandidate& candidate : result->candidates) {
    nlohmann::json entry;
    entry["model"] = candidate.name;
    nlohmann::json values = nlohmann::json::array();
    for (const Eigen::Vector3d& v : candidate.decentering) {
      values.push_back(Vector3Json(v));
    }
    entry["decentering_m"] = values;
    entry["n"] = candidate.n;
    entry["rms_px"] = candidate.rms_px;
    entry["pixel_sigma"] = candidate.pixel_sigma;
    entry["evidence"] = candidate.evidence;
    entry["plausible"] = candidate.plausible;
    candidates.push_back(entry);
  }
  json["candidates"] = candidates;
  json["model"] = result->candidates[result->chosen].name;
  json["rule"] = result->rule;
  json["rms_px"] = result->rms_px;
  json["rms_px_per_camera"] = result->rms_px_per_camera;
  json["inlier_rms_px"] = result->inlier_rms_px;
  json["pixel_sigma"] = result->pixel_sigma;
  json["views_used"] = result->num_views_used;
  json["corners"] = result->num_inliers + result->num_outliers;
  json["outliers"] = result->num_outliers;
  json["outlier_views"] = result->num_outlier_views;
  json["view_weights"] = result->view_weights;
  json["conventional"] = {
      {"model", std::string(LensModelName(conventional.model))},
      {"ok", conventional.ok},
      {"rms_px",
       conventional.ok ? nlohmann::json(conventional.rms_px) : nullptr},
      {"pixel_sigma",
       conventional.ok ? nlohmann::json(conventional.pixel_sigma) : nullptr},
      {"error", conventional.error}};
  Eigen::Matrix2d warp_covariance = Eigen::Matrix2d::Zero();
  warp_covariance.diagonal() = result->board_warp_sigma.array().square();
  json["board_flatness"] = BoardFlatnessJson(
      result->board_warp_estimated, result->board_warp, warp_covariance);
  json["lenses_estimated"] = result->lenses_estimated;
  if (air_views) {
    json["air_views"] = {{"source", air_views->description},
                         {"views_used", result->num_air_views_used},
                         {"rms_px", result->air_rms_px},
                         {"same_board", air_views->views.same_board}};
  } else {
    json["air_views"] = nullptr;
  }
  json["warnings"] = warnings;
  if (Status status = WriteFileAtomically(
          (std::filesystem::path(paths.report) / "underwater.json").string(),
          json.dump(2) + "\n");
      !status.ok()) {
    PrintError(command, status.message());
    return kExitFailure;
  }

  // The air camchain with each camera's dome (the estimated decentering)
  // and, from the joint calibration, its lens.
  Camchain camchain = *air;
  camchain.cameras.erase(camchain.cameras.begin() + num_cameras,
                         camchain.cameras.end());
  for (int c = 0; c < num_cameras; ++c) {
    DomePort dome = (*domes)[c];
    dome.decentering = result->decentering[c];
    camchain.cameras[c].camera = result->cameras[c];
    camchain.cameras[c].port.reset();
    camchain.cameras[c].dome = dome;
  }
  if (Status status = WriteCamchain(paths.camchain, camchain); !status.ok()) {
    PrintError(command, status.message());
    return kExitFailure;
  }

  for (const std::string& warning : warnings) PrintWarning(command, warning);
  if (FLAGS_json) {
    std::cout << json.dump(2) << std::endl;
    return kExitOk;
  }
  std::printf("%d views used, %d corners, %d outliers\n",
              result->num_views_used,
              result->num_inliers + result->num_outliers, result->num_outliers);
  double lightest = 0.0, heaviest = 0.0;
  for (double weight : result->view_weights) {
    if (weight <= 0.0) continue;
    lightest = lightest > 0.0 ? std::min(lightest, weight) : weight;
    heaviest = std::max(heaviest, weight);
  }
  if (heaviest > 0.0) {
    std::printf(
        "views weighed by their corner noise: %.2f to %.2f of the median "
        "view's weight (view_weights in the report)\n",
        lightest, heaviest);
  }
  for (int c = 0; c < num_cameras; ++c) {
    std::printf(
        "cam%d: dome centre %s in the camera frame (rms %.4f px)\n", c,
        MillimetresText(result->decentering[c], result->decentering_sigma[c])
            .c_str(),
        result->rms_px_per_camera[c]);
  }
  if (result->n_estimated) {
    std::string correlation_text;
    for (int c = 0; c < num_cameras; ++c) {
      correlation_text +=
          (c == 0 ? "" : "; ") + std::string("cam") + std::to_string(c) +
          " z " + FormatFixed(result->correlation_n_decentering[c].z(), 3);
    }
    std::printf(
        "n %.4f +- %.4f (weakly observable through a dome: correlation with "
        "the axial decentering %s)\n",
        result->n, result->sigma_n, correlation_text.c_str());
  } else {
    std::printf("n %.4f held (--n; --estimate-n to estimate it)\n", result->n);
  }
  if (result->lenses_estimated) {
    std::printf(
        "air views: %d used, rms %.4f px through the dome at n = 1; the "
        "lenses estimated from air and water together\n",
        result->num_air_views_used, result->air_rms_px);
  }
  std::printf("%s\n", result->rule.c_str());
  std::printf("rms %.4f px (pixel noise %.4f px)", result->rms_px,
              result->pixel_sigma);
  if (conventional.ok) {
    std::printf("; a conventional %s model fitted freely: rms %.4f px",
                std::string(LensModelName(conventional.model)).c_str(),
                conventional.rms_px);
  }
  std::printf("\n");
  std::printf(
      "wrote %s and %s/ in %.1f s\n", paths.camchain.c_str(),
      paths.report.c_str(),
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
          .count());
  return kExitOk;
}

}  // namespace rcm::cli
