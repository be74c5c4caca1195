// rcm calibrate --underwater: n and the rig's extrinsics as they are under
// water, from images of a target shown to the rig at the start of a dive,
// with the air calibration's lenses held (rcm::calib CalibrateUnderwater).
#include "calibrate_underwater.h"

#include <gflags/gflags.h>

#include <chrono>
#include <cmath>
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
#include "calibrate_dome.h"
#include "calibration_input.h"
#include "calibration_run.h"
#include "dome_port_flags.h"
#include "image_input_flags.h"
#include "medium_flag.h"
#include "progress.h"
#include "rcm/calib/calibration_covariance.h"
#include "rcm/calib/calibration_report.h"
#include "rcm/calib/underwater_calibration.h"
#include "rcm/calib/underwater_model_selection.h"
#include "rcm/io/atomic_file.h"
#include "rcm/io/calibration_covariance_file.h"
#include "rcm/io/camchain.h"
#include "rcm/io/image_file.h"
#include "rcm/io/stereo_rig_file.h"
#include "rcm/util/number_format.h"

DEFINE_bool(underwater, false,
            "calibrate under water: n and the extrinsics cam1_from_cam0 as "
            "they are in the water, from views of the target through the "
            "ports, with the lenses of the air calibration --air held "
            "(--left alone: one camera, n only)");
DEFINE_bool(estimate_port_tilt, false,
            "--underwater: the ports are tilted: fit only candidate models "
            "that estimate each port's tilt (two angles per port)");
DEFINE_bool(thin_port, false,
            "--underwater: the ports are thin (the paper's model): fit only "
            "candidate models without an air gap or tilt");

namespace rcm::cli {

extern const char kUnderwaterFlagsSource[] = __FILE__;

namespace {

using calib::ImageSize;
using calib::StereoView;
using calib::UnderwaterCalibration;
using calib::UnderwaterCandidate;
using calib::UnderwaterModelSelection;

std::string SizeText(int width, int height) {
  return std::to_string(width) + "x" + std::to_string(height);
}

// The air camchain's port blocks must describe both housings alike for
// --estimate-air-gap: a block on one camera only leaves the other's glass
// unknown (thin, or the block's?), and the gap estimated behind it would
// mean a different thing for each camera.
Status CheckPortsForAirGap(const std::string& air) {
  if (air.find(',') != std::string::npos) return Status::Ok();  // camera_info
  const StatusOr<Camchain> camchain = ReadCamchain(air);
  if (!camchain.ok() || camchain->cameras.size() < 2) return Status::Ok();
  const bool left = camchain->cameras[0].port.has_value();
  const bool right = camchain->cameras[1].port.has_value();
  if (left != right) {
    return Status::Error(
        air + ": cam" + std::string(left ? "0" : "1") +
        " has a port block and cam" + std::string(left ? "1" : "0") +
        " has none, which contradicts --estimate-air-gap: the gap is "
        "estimated behind each port's glass, so describe both ports (a "
        "port block with air_gap 0 for an unknown gap) or neither");
  }
  return Status::Ok();
}

std::string Vector3Text(const Eigen::Vector3d& v, int digits) {
  return "(" + FormatFixed(v.x(), digits) + ", " + FormatFixed(v.y(), digits) +
         ", " + FormatFixed(v.z(), digits) + ")";
}

// The report's pictures and table: the underwater corners drawn as the
// air calibration's are (calibration_report.h), through a StereoCalibration
// that holds the underwater solution's residuals and poses.
// The drawing of an underwater result for the report: its lenses, poses
// and corners as a calibration's.
calib::StereoCalibration UnderwaterDrawing(
    const UnderwaterCalibration& result) {
  calib::StereoCalibration drawing(result.rig.left(), result.rig.right());
  drawing.cam1_from_cam0 = result.rig.right_from_left();
  drawing.cam0_from_target = result.cam0_from_target;
  drawing.corners = result.corners;
  drawing.rms_px = result.rms_px;
  drawing.inlier_rms_px = result.inlier_rms_px;
  drawing.pixel_sigma = result.pixel_sigma;
  drawing.num_views_used = result.num_views_used;
  drawing.num_stereo_views = result.num_stereo_views;
  drawing.num_inliers = result.num_inliers;
  drawing.num_outliers = result.num_outliers;
  return drawing;
}

}  // namespace

nlohmann::json Vector3Json(const Eigen::Vector3d& v) {
  return {v.x(), v.y(), v.z()};
}

Status WriteUnderwaterReport(const std::string& folder,
                             const calib::StereoCalibration& drawing,
                             const std::vector<StereoView>& views,
                             const ImageSize sizes[2], bool one_camera,
                             calib::CalibrationReport* report) {
  *report = calib::SummarizeCalibration(drawing, views, sizes[0], sizes[1]);
  std::error_code error;
  std::filesystem::create_directories(folder, error);
  if (error) {
    return Status::Error("cannot create folder " + folder + ": " +
                         error.message());
  }
  const std::filesystem::path dir(folder);
  for (int c = 0; c < (one_camera ? 1 : 2); ++c) {
    const std::string cam = "cam" + std::to_string(c);
    RCM_RETURN_IF_ERROR(
        WritePng(calib::DrawResidualField(drawing, c, sizes[c]),
                 (dir / ("residuals_" + cam + ".png")).string()));
    RCM_RETURN_IF_ERROR(
        WritePng(calib::DrawCoverage(drawing, views, c, sizes[c]),
                 (dir / ("coverage_" + cam + ".png")).string()));
  }
  RCM_RETURN_IF_ERROR(WritePng(calib::DrawPerViewRms(*report),
                               (dir / "per_view_rms.png").string()));
  return WriteFileAtomically((dir / "per_view.csv").string(),
                             calib::FormatPerViewCsv(*report));
}

StatusOr<UnderwaterInputs> ReadUnderwaterInputs(
    const calib::CalibrationTarget& target, const CalibrationOutputPaths& paths,
    bool estimate_board_warp, bool allow_left_only_air,
    const std::string& banner, const std::string& air_note) {
  UnderwaterInputs inputs;
  // The air views first: nothing is detected in the water when they fail.
  if (AirViewsGiven() || FLAGS_same_board || !FLAGS_air_target.empty()) {
    StatusOr<AirViewsInput> read =
        ReadAirViews(target, estimate_board_warp, allow_left_only_air);
    if (!read.ok()) return read.status();
    inputs.air_views = *std::move(read);
    if (!FLAGS_json) {
      std::cout << banner << ": " << inputs.air_views->description << " ("
                << air_note << ")" << std::endl;
    }
  }
  StatusOr<CalibrationInput> input = ReadCalibrationInput(
      target, /*allow_left_only=*/true, paths,
      [&](const std::string& description) {
        if (!FLAGS_json) {
          std::cout << banner << ": " << description << "; target "
                    << calib::DescribeTarget(target) << "; air calibration "
                    << FLAGS_air << std::endl;
        }
      });
  if (!input.ok()) return input.status();
  inputs.input = *std::move(input);
  return inputs;
}

namespace {

// The candidates as the JSON lists them.
nlohmann::json CandidatesJson(const UnderwaterModelSelection& selection) {
  nlohmann::json list = nlohmann::json::array();
  for (size_t k = 0; k < selection.candidates.size(); ++k) {
    const UnderwaterCandidate& candidate = selection.candidates[k];
    nlohmann::json item = {{"model", candidate.model.Name()},
                           {"chosen", static_cast<int>(k) == selection.chosen},
                           {"ok", candidate.fit.has_value()}};
    if (!candidate.fit) {
      item["error"] = candidate.error;
      list.push_back(item);
      continue;
    }
    const UnderwaterCalibration& fit = *candidate.fit;
    item["n"] = fit.n;
    item["sigma_n"] = candidate.sigma_n_noise;
    item["sigma_n_covariance"] = fit.sigma_n;
    item["sigma_n_leave_out"] = JsonNumber(fit.sigma_n_leave_out);
    item["rms_px"] = fit.rms_px;
    item["held_out_rms_px"] = std::isfinite(candidate.held_out_rms_px)
                                  ? nlohmann::json(candidate.held_out_rms_px)
                                  : nullptr;
    item["evidence_sigmas"] = std::isfinite(candidate.evidence)
                                  ? nlohmann::json(candidate.evidence)
                                  : nullptr;
    item["plausible"] = candidate.plausible;
    item["parameters"] = fit.num_parameters;
    list.push_back(item);
  }
  return list;
}

// The candidates as rcm calibrate prints them: one row each.
std::string CandidateTable(const UnderwaterModelSelection& selection) {
  std::string table =
      "candidate models (evidence: held-out error above the best's, in "
      "standard errors over " +
      std::to_string(selection.num_evidence_views) +
      " views; plausible within 2):\n";
  char line[256];
  std::snprintf(line, sizeof(line), "  %-40s %-19s %8s %9s %9s\n", "model", "n",
                "rms px", "held-out", "evidence");
  table += line;
  for (size_t k = 0; k < selection.candidates.size(); ++k) {
    const UnderwaterCandidate& candidate = selection.candidates[k];
    const std::string name =
        (static_cast<int>(k) == selection.chosen ? "* " : "  ") +
        candidate.model.Name();
    if (!candidate.fit) {
      table += "  " + name + ": " + candidate.error + "\n";
      continue;
    }
    const std::string held_out = std::isfinite(candidate.held_out_rms_px)
                                     ? FormatFixed(candidate.held_out_rms_px, 4)
                                     : std::string("-");
    const std::string evidence = std::isfinite(candidate.evidence)
                                     ? FormatFixed(candidate.evidence, 1) +
                                           (candidate.plausible ? "" : " x")
                                     : std::string("-");
    std::snprintf(
        line, sizeof(line), "  %-40s %-19s %8.4f %9s %9s\n", name.c_str(),
        WithSigma(candidate.fit->n, candidate.sigma_n_noise, 5, std::nullopt)
            .c_str(),
        candidate.fit->rms_px, held_out.c_str(), evidence.c_str());
    table += line;
  }
  table +=
      "  (* chosen: the lowest held-out error, the simplest without folds; x: "
      "ruled out, evidence above 2)\n";
  return table;
}

}  // namespace

int RunCalibrateUnderwater(const Subcommand& command,
                           const calib::CalibrationTarget& target,
                           const CalibrationOutputPaths& paths,
                           const UnderwaterRunOptions& run) {
  // A dome (--port dome, or dome blocks in the air camchain) has its own
  // calibration: the decentering, with n held or estimated.
  if (DomePortRequested() || AirCamchainHasDomes()) {
    return RunCalibrateDome(command, target, paths, run);
  }
  if (const Status status = CheckNoDomeFlags("a flat port"); !status.ok()) {
    PrintError(command, status.message());
    return kExitUsage;
  }
  const auto start = std::chrono::steady_clock::now();
  if (FLAGS_air.empty()) {
    PrintError(command,
               "--underwater needs --air AIR.yaml, the in-air calibration of "
               "the rig whose lenses it keeps");
    return kExitUsage;
  }
  if (FLAGS_thin_port && (FLAGS_estimate_air_gap || FLAGS_estimate_port_tilt)) {
    PrintError(command,
               "--thin-port contradicts --estimate-air-gap and "
               "--estimate-port-tilt: a thin port has neither");
    return kExitUsage;
  }
  const StatusOr<std::optional<MediumPrior>> medium = MediumFromFlag();
  if (!medium.ok()) {
    PrintError(command, medium.status().message());
    return kExitUsage;
  }
  calib::UnderwaterModelSelectionOptions options;
  options.fit.huber_px = run.huber_px;
  options.fit.outlier_sigmas = run.outlier_sigmas;
  options.fit.min_corners_per_view = run.min_corners;
  options.fit.folds = run.folds;
  options.candidates = calib::UnderwaterCandidates(
      !run.estimate_board_warp, FLAGS_estimate_air_gap,
      FLAGS_estimate_port_tilt, FLAGS_thin_port);
  if (const Status status = options.Check(); !status.ok()) {
    PrintError(command, status.message());
    return kExitUsage;
  }

  const StatusOr<StereoRig> air_rig = ReadStereoRig(FLAGS_air);
  if (!air_rig.ok()) {
    PrintError(command, air_rig.status().message());
    return kExitFailure;
  }
  if (FLAGS_estimate_air_gap) {
    if (const Status status = CheckPortsForAirGap(FLAGS_air); !status.ok()) {
      PrintError(command, status.message());
      return kExitFailure;
    }
  }
  StatusOr<UnderwaterInputs> inputs = ReadUnderwaterInputs(
      target, paths, run.estimate_board_warp, /*allow_left_only_air=*/false,
      "rcm calibrate --underwater", "lenses from air and water together");
  if (!inputs.ok()) {
    PrintError(command, inputs.status().message());
    return kExitFailure;
  }
  const std::optional<AirViewsInput>& air_views = inputs->air_views;
  const CalibrationInput* input = &inputs->input;
  const Detections* detections = &input->detections;
  const bool one_camera = !detections->sizes[1].has_value() &&
                          detections->right_only == 0 &&
                          OneCameraImageInputGiven();
  if (const Status status = CheckDetections(*detections, one_camera);
      !status.ok()) {
    PrintError(command, "under water: " + status.message());
    return kExitFailure;
  }
  // The images must be the air cameras'.
  const Camera* air_cameras[2] = {&air_rig->left(), &air_rig->right()};
  ImageSize sizes[2];
  for (int c = 0; c < 2; ++c) {
    sizes[c] = ImageSize{air_cameras[c]->width(), air_cameras[c]->height()};
    if (!detections->sizes[c]) continue;
    if (detections->sizes[c]->width != sizes[c].width ||
        detections->sizes[c]->height != sizes[c].height) {
      PrintError(command,
                 std::string(c == 0 ? "the left" : "the right") +
                     " images are " +
                     SizeText(detections->sizes[c]->width,
                              detections->sizes[c]->height) +
                     " but cam" + std::to_string(c) + " of " + FLAGS_air +
                     " is " + SizeText(sizes[c].width, sizes[c].height) +
                     ": the air calibration must be of these cameras at this "
                     "resolution");
      return kExitFailure;
    }
  }
  for (const std::string& warning : detections->warnings) {
    PrintWarning(command, warning);
  }

  const std::vector<StereoView>& views = detections->views;
  // The selection reports hundredths of a candidate; the bar counts
  // candidates, with the percentage of the one being fitted.
  const size_t num_candidates = options.candidates.size();
  std::optional<Progress> solving(std::in_place,
                                  "rcm calibrate: underwater candidate models",
                                  num_candidates);
  const StatusOr<UnderwaterModelSelection> selection =
      calib::SelectUnderwaterModel(
          target, views, sizes[0], one_camera ? ImageSize{0, 0} : sizes[1],
          *air_rig, options,
          [&solving](int done, int) {
            solving->Update(static_cast<size_t>(done / 100),
                            std::to_string(done % 100) + " % of the next");
          },
          air_views ? &air_views->views : nullptr);
  solving.reset();
  if (!selection.ok()) {
    PrintError(command, selection.status().message());
    return kExitFailure;
  }
  const UnderwaterCalibration* result = &selection->Chosen();
  const calib::UnderwaterCandidateModel& model =
      selection->candidates[selection->chosen].model;
  // The conventional fit ran with the thin-port candidate of the same
  // board, when there was one.
  calib::ConventionalFit conventional = result->conventional;
  for (const UnderwaterCandidate& candidate : selection->candidates) {
    if (candidate.fit && candidate.model.board_warp == model.board_warp &&
        !candidate.model.air_gap && !candidate.model.port_tilt) {
      conventional = candidate.fit->conventional;
    }
  }

  // The report first, the camchain last.
  calib::CalibrationReport report;
  if (const Status status =
          WriteUnderwaterReport(paths.report, UnderwaterDrawing(*result), views,
                                sizes, one_camera, &report);
      !status.ok()) {
    PrintError(command, status.message());
    return kExitFailure;
  }
  std::vector<std::string> warnings = result->notes;
  if (air_views) {
    warnings.insert(warnings.begin(), air_views->warnings.begin(),
                    air_views->warnings.end());
  }
  if (!selection->pinned) warnings.push_back(selection->advice);
  // The medium (--medium): n against its physics.
  nlohmann::json medium_json = nullptr;
  if (*medium) {
    const MediumCheck check =
        CheckAgainstMedium(selection->n, selection->sigma_n, **medium);
    medium_json = MediumJson(**medium, check);
    if (check.contradicts) {
      warnings.push_back(check.message +
                         ": the air calibration may not describe the lenses "
                         "under water, or the water is another");
    }
  }
  if (conventional.ok && conventional.pixel_sigma < 0.9 * result->pixel_sigma) {
    warnings.push_back(
        "a conventional " + std::string(LensModelName(conventional.model)) +
        " model fitted freely to the same corners fits them better (pixel "
        "noise " +
        FormatFixed(conventional.pixel_sigma, 3) + " px against " +
        FormatFixed(result->pixel_sigma, 3) +
        " px): the port model may not describe the housing (an air gap or "
        "glass: port blocks, --estimate-air-gap; a tilted port: "
        "--estimate-port-tilt), or the lenses changed since the air "
        "calibration");
  }
  for (const std::string& warning : report.warnings)
    warnings.push_back(warning);

  const calib::ExtrinsicChange& change = result->extrinsic_change;
  nlohmann::json json;
  json["camchain"] = paths.camchain;
  json["covariance"] = CovarianceSidecarPath(paths.camchain);
  json["report"] = paths.report;
  json["air"] = FLAGS_air;
  json["target"] = calib::DescribeTarget(target);
  json["source"] = input->description;
  json["cameras"] = one_camera ? 1 : 2;
  json["n"] = selection->n;
  json["sigma_n"] = selection->sigma_n;
  json["sigma_n_noise"] = selection->sigma_n_noise;
  json["sigma_n_lenses"] = selection->sigma_n_lenses;
  json["sigma_n_model"] = selection->sigma_n_model;
  json["sigma_n_covariance"] = result->sigma_n;
  json["sigma_n_leave_out"] = JsonNumber(result->sigma_n_leave_out);
  // The sidecar's widening of the held geometry to the leave-out spread.
  json["geometry_leave_out_scale"] = calib::GeometryLeaveOutScale(*result);
  json["model"] = model.Name();
  json["pinned"] = selection->pinned;
  json["advice"] = selection->advice;
  json["medium"] = medium_json;
  json["evidence_views"] = selection->num_evidence_views;
  json["candidates"] = CandidatesJson(*selection);
  json["rms_px"] = result->rms_px;
  json["inlier_rms_px"] = result->inlier_rms_px;
  json["pixel_sigma"] = result->pixel_sigma;
  json["initial_rms_px"] = result->initial_rms_px;
  json["views_used"] = result->num_views_used;
  json["stereo_views"] = result->num_stereo_views;
  json["corners"] = result->num_inliers + result->num_outliers;
  json["outliers"] = result->num_outliers;
  json["extrinsics_estimated"] = result->extrinsics_estimated;
  json["extrinsic_change_deg"] =
      result->extrinsics_estimated ? nlohmann::json(change.angle_deg) : nullptr;
  if (result->extrinsics_estimated) {
    json["extrinsic_change"] = {
        {"angle_deg", change.angle_deg},
        {"angle_sigma_deg", change.angle_sigma_deg},
        {"angle_leave_out_sigma_deg",
         JsonNumber(change.angle_leave_out_sigma_deg)},
        {"rotation_leave_out_sigma_deg",
         change.rotation_leave_out_sigma_deg
             ? Vector3Json(*change.rotation_leave_out_sigma_deg)
             : nlohmann::json(nullptr)},
        {"translation_leave_out_sigma_mm",
         change.translation_leave_out_sigma_mm
             ? Vector3Json(*change.translation_leave_out_sigma_mm)
             : nlohmann::json(nullptr)},
        {"rotation_deg", Vector3Json(change.rotation_deg)},
        {"rotation_sigma_deg", Vector3Json(change.rotation_sigma_deg)},
        {"translation_mm", Vector3Json(change.translation_mm)},
        {"translation_sigma_mm", Vector3Json(change.translation_sigma_mm)}};
  }
  for (int c = 0; c < 2; ++c) {
    const calib::PortEstimate& port = result->ports[c];
    json["ports"]["cam" + std::to_string(c)] = {
        {"air_gap_m", port.port.air_gap},
        {"air_gap_sigma_m",
         port.air_gap_estimated ? nlohmann::json(port.air_gap_sigma) : nullptr},
        {"glass_thickness_m", port.port.glass_thickness},
        {"glass_index", port.port.glass_index},
        {"tilt_deg", port.tilt_deg},
        {"tilt_estimated", port.tilt_estimated}};
  }
  json["conventional"] = {
      {"model", std::string(LensModelName(conventional.model))},
      {"ok", conventional.ok},
      {"rms_px",
       conventional.ok ? nlohmann::json(conventional.rms_px) : nullptr},
      {"pixel_sigma",
       conventional.ok ? nlohmann::json(conventional.pixel_sigma) : nullptr},
      {"error", conventional.error}};
  json["board_flatness"] =
      BoardFlatnessJson(result->board_warp_estimated, result->board_warp,
                        result->board_warp_covariance);
  if (air_views) {
    json["air_views"] = {
        {"source", air_views->description},
        {"views_used", result->num_air_views_used},
        {"rms_px", result->air_rms_px},
        {"same_board", air_views->views.same_board},
        {"board_warp_mm",
         {1e3 * result->air_board_warp.x(), 1e3 * result->air_board_warp.y()}}};
  } else {
    json["air_views"] = nullptr;
  }
  json["lenses_estimated"] = result->lenses_estimated;
  json["warnings"] = warnings;
  if (Status status = WriteFileAtomically(
          (std::filesystem::path(paths.report) / "underwater.json").string(),
          json.dump(2) + "\n");
      !status.ok()) {
    PrintError(command, status.message());
    return kExitFailure;
  }

  Camchain camchain = CamchainFromStereoRig(result->rig);
  if (FLAGS_air.find(',') == std::string::npos) {
    // The air camchain's IMU calibration and topics carry over.
    if (const StatusOr<Camchain> air = ReadCamchain(FLAGS_air); air.ok()) {
      if (const Status status = CopyCamchainImuAndTopics(*air, 0, 1, &camchain);
          !status.ok()) {
        PrintError(command, status.message());
        return kExitFailure;
      }
    }
  }
  if (Status status = WriteCamchainWithCovariance(
          paths.camchain, camchain,
          calib::UnderwaterCalibrationCovariance(*result, *air_rig));
      !status.ok()) {
    PrintError(command, status.message());
    return kExitFailure;
  }

  for (const std::string& warning : warnings) PrintWarning(command, warning);
  if (FLAGS_json) {
    std::cout << json.dump(2) << std::endl;
    return kExitOk;
  }
  std::printf("%d views used (%d stereo), %d corners, %d outliers\n",
              result->num_views_used, result->num_stereo_views,
              result->num_inliers + result->num_outliers, result->num_outliers);
  if (air_views) {
    std::printf(
        "air views: %d used, rms %.4f px; the lenses estimated from air and "
        "water together%s\n",
        result->num_air_views_used, result->air_rms_px,
        air_views->views.same_board ? ", one board (one bow) in both" : "");
  }
  std::printf(
      "refractive model: rms %.4f px (inliers %.4f px), pixel noise %.4f px "
      "per axis\n",
      result->rms_px, result->inlier_rms_px, result->pixel_sigma);
  if (conventional.ok) {
    std::printf(
        "conventional %s fitted freely to the same corners: rms %.4f px, "
        "pixel noise %.4f px\n",
        std::string(LensModelName(conventional.model)).c_str(),
        conventional.rms_px, conventional.pixel_sigma);
  } else {
    std::printf("conventional model: %s\n", conventional.error.c_str());
  }
  std::printf("%s", CandidateTable(*selection).c_str());
  std::printf(
      "n %s (%s)\n  sigma_n: noise %.5f (covariance %.5f%s), %s "
      "%.5f%s, models the data cannot tell apart %.5f\n",
      WithSigma(selection->n, selection->sigma_n, 5, std::nullopt).c_str(),
      model.Name().c_str(), selection->sigma_n_noise, result->sigma_n,
      result->sigma_n_leave_out
          ? (", leave-out " + FormatFixed(*result->sigma_n_leave_out, 5))
                .c_str()
          : "",
      result->lenses_estimated ? "lenses (joint fit)" : "air lenses",
      selection->sigma_n_lenses,
      result->sigma_n_lenses ? ""
                             : " (the air camchain has no lens covariance)",
      selection->sigma_n_model);
  std::printf("below: +- covariance sigma%s\n",
              result->sigma_n_leave_out ? " (leave-out sigma)" : "");
  if (result->extrinsics_estimated) {
    std::printf(
        "cam1 has turned by %s deg since the air calibration: %s +- %s deg "
        "about x, y, z; translation changed by %s +- %s mm\n",
        WithSigma(change.angle_deg, change.angle_sigma_deg, 3,
                  change.angle_leave_out_sigma_deg)
            .c_str(),
        Vector3Text(change.rotation_deg, 3).c_str(),
        Vector3Text(change.rotation_sigma_deg, 3).c_str(),
        Vector3Text(change.translation_mm, 2).c_str(),
        Vector3Text(change.translation_sigma_mm, 2).c_str());
  } else {
    std::printf("extrinsics: the air calibration's (one camera)\n");
  }
  if (!result->board_warp_estimated && run.estimate_board_warp) {
    std::printf("board flatness: flat in the chosen model\n");
  } else {
    std::printf("%s\n", BoardFlatnessText(result->board_warp_estimated,
                                          result->board_warp,
                                          result->board_warp_covariance)
                            .c_str());
  }
  for (int c = 0; c < (one_camera ? 1 : 2); ++c) {
    const calib::PortEstimate& port = result->ports[c];
    if (!port.air_gap_estimated && !port.tilt_estimated) continue;
    std::printf("cam%d port:", c);
    if (port.air_gap_estimated) {
      std::printf(" air gap %s mm",
                  WithSigma(1e3 * port.port.air_gap, 1e3 * port.air_gap_sigma,
                            2, std::nullopt)
                      .c_str());
    }
    if (port.tilt_estimated) std::printf(" tilt %.3f deg", port.tilt_deg);
    std::printf("\n");
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
          .count();
  std::printf("wrote %s (with %s) and %s/ in %.1f s\n", paths.camchain.c_str(),
              CovarianceSidecarPath(paths.camchain).c_str(),
              paths.report.c_str(), seconds);
  return kExitOk;
}

}  // namespace rcm::cli
