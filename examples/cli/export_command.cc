// rcm export: the conventional water-side camera models (equidistant,
// radtan) that best reproduce the refractive model of an air-calibrated
// rig, for VIO frameworks that read raw underwater images.
#include <gflags/gflags.h>

#include <array>
#include <chrono>
#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "command.h"
#include "index_flag.h"
#include "lens_model_flag.h"
#include "rcm/camera/refractive_camera.h"
#include "rcm/estimation/water_side_model_fit.h"
#include "rcm/io/atomic_file.h"
#include "rcm/io/camchain.h"
#include "rcm/io/camera_file.h"
#include "rcm/io/camera_info.h"
#include "rcm/io/image_file.h"
#include "rcm/io/stereo_rig_file.h"
#include "rcm/stereo/virtual_pinhole_rig.h"
#include "rcm/util/number_format.h"
#include "rcm/viz/image_error_map.h"
#include "reference_depth_flag.h"
#include "rig_flags.h"

DEFINE_double(fit_inset, 0.05,
              "fraction of the image width and height left out of the fit at "
              "each side (0: fit the whole image)");
DEFINE_double(grid_step, 4.0, "spacing of the fitted pixel grid, pixels");

namespace rcm::cli {
namespace {

constexpr char kExportUsage[] =
    "rcm export: the conventional water-side camera models of a rig\n\n"
    "usage:\n"
    "  rcm export --calib camchain.yaml --n 1.333\n"
    "      [--model equidistant|radtan|rational|ds|eucm] --out DIR | FILE.yaml"
    "\n\n"
    "Fits, for each camera, the lens model (--model, default equidistant)\n"
    "that best reproduces the refractive model of the air calibration at\n"
    "index --n (least squares in pixels over a grid on the image), so a VIO\n"
    "that knows only conventional models can use the raw underwater images\n"
    "directly. Writes the Kalibr camchain of the fitted cameras (same\n"
    "extrinsics; T_cam_imu, timeshift and rostopic kept), one ROS\n"
    "camera_info per camera (not for ds and eucm, which ROS has no\n"
    "model for), a fit-error map per camera (PNG) and\n"
    "export.json; prints the RMS and maximum fit error inside the fit\n"
    "region (--fit-inset) and over the whole image.\n"
    "--out DIR writes DIR/camchain.yaml, DIR/left.yaml, DIR/right.yaml,\n"
    "DIR/fit_error_left.png, DIR/fit_error_right.png, DIR/export.json;\n"
    "--out FILE.yaml writes the camchain there and the others next to it\n"
    "as FILE-left.yaml, FILE-fit_error_left.png, ...";

// Where the files go (see kExportUsage).
struct ExportPaths {
  std::string camchain;
  std::string prefix;  // the other files are prefix + "left.yaml", ...
};

ExportPaths ExportPathsFromFlags() {
  namespace fs = std::filesystem;
  const fs::path out(FLAGS_out);
  const std::string extension = out.extension().string();
  if (extension == ".yaml" || extension == ".yml") {
    return {out.string(), (out.parent_path() / out.stem()).string() + "-"};
  }
  return {(out / "camchain.yaml").string(), (out / "").string()};
}

// The camchain of the fitted pair, with the input's IMU calibration and
// topics when --calib is a camchain.
StatusOr<Camchain> FittedCamchain(const StereoRig& fitted_rig) {
  Camchain camchain = CamchainFromStereoRig(fitted_rig);
  if (FLAGS_calib.find(',') != std::string::npos) return camchain;
  const StatusOr<Camchain> source = ReadCamchain(FLAGS_calib);
  if (!source.ok()) return source.status();
  const StatusOr<int> left = FindCamchainCamera(*source, FLAGS_left_camera);
  const StatusOr<int> right = FindCamchainCamera(*source, FLAGS_right_camera);
  if (!left.ok() || !right.ok()) {
    return Status::Error(FLAGS_calib + ": cameras not found");
  }
  if (Status status =
          CopyCamchainImuAndTopics(*source, *left, *right, &camchain);
      !status.ok()) {
    return status.WithContext(FLAGS_calib);
  }
  return camchain;
}

nlohmann::json StatsJson(const PixelErrorStats& stats) {
  return {{"rms_px", JsonNumber(stats.rms_px)},
          {"median_px", JsonNumber(stats.median_px)},
          {"max_px", JsonNumber(stats.max_px)},
          {"samples", stats.num_samples}};
}

nlohmann::json FitJson(const WaterSideModelFit& fit) {
  const Camera& camera = fit.camera;
  return {{"distortion_model", std::string(LensModelName(camera.model()))},
          {"intrinsics", {camera.fx(), camera.fy(), camera.cx(), camera.cy()}},
          {"distortion_coeffs", camera.Distortion()},
          {"resolution", {camera.width(), camera.height()}},
          {"fit_region", StatsJson(fit.inset)},
          {"whole_image", StatsJson(fit.full)},
          {"not_invertible_samples", fit.num_not_invertible},
          {"iterations", fit.num_iterations},
          {"converged", fit.converged}};
}

std::string Px(double value) { return FormatFixed(value, 3) + " px"; }

int RunExport();

}  // namespace

extern const Subcommand kExportCommand = {
    "export",
    "conventional water-side models (equidistant, radtan) fitted to the "
    "refractive model",
    kExportUsage,
    {__FILE__, kRigFlagsSource, kIndexFlagSource, kLensModelFlagSource,
     kReferenceDepthFlagSource},
    RunExport};

namespace {

int RunExport() {
  const Subcommand& command = kExportCommand;
  const auto start = std::chrono::steady_clock::now();
  if (FLAGS_calib.empty()) {
    PrintError(command, "--calib is required: the in-air calibration");
    return kExitUsage;
  }
  if (FLAGS_out.empty()) {
    PrintError(command,
               "--out is required: a folder, or the camchain to write (e.g. "
               "--out water.yaml)");
    return kExitUsage;
  }
  const StatusOr<double> n = RefractiveIndexFromFlag(/*required=*/true);
  if (!n.ok()) {
    PrintError(command, n.status().message());
    return kExitUsage;
  }
  const StatusOr<LensModelId> model =
      LensModelFromFlag(LensModelId::kEquidistant);
  if (!model.ok()) {
    PrintError(command, model.status().message());
    return kExitUsage;
  }
  WaterSideModelFitOptions options;
  options.model = *model;
  options.fit_inset = FLAGS_fit_inset;
  options.report_inset = FLAGS_fit_inset;
  options.grid_step = FLAGS_grid_step;
  if (Status status = options.Check(); !status.ok()) {
    PrintError(command, status.message());
    return kExitUsage;
  }

  // A camchain's dome blocks: each camera its dome's, central at
  // --reference-depth.
  RigFileOptions rig_options;
  rig_options.domes_allowed = true;
  const StatusOr<StereoRig> rig = ReadStereoRig(
      FLAGS_calib, FLAGS_left_camera, FLAGS_right_camera, rig_options);
  if (!rig.ok()) {
    PrintError(command, rig.status().message());
    return kExitFailure;
  }
  const StatusOr<std::optional<std::array<DomePort, 2>>> domes =
      ReadStereoRigDomes(FLAGS_calib, FLAGS_left_camera, FLAGS_right_camera);
  if (!domes.ok()) {
    PrintError(command, domes.status().message());
    return kExitFailure;
  }

  // Fit both cameras.
  const char* names[2] = {"left", "right"};
  std::vector<WaterSideModelFit> fits;
  for (int k = 0; k < 2; ++k) {
    const StatusOr<RefractiveCamera> camera =
        RefractiveCameraOfRig(*rig, k == 0, *n, FLAGS_reference_depth, *domes);
    if (!camera.ok()) {
      PrintError(command, camera.status().message());
      return kExitFailure;
    }
    StatusOr<WaterSideModelFit> fit = FitWaterSideModel(*camera, options);
    if (!fit.ok()) {
      PrintError(command,
                 std::string(names[k]) + " camera: " + fit.status().message());
      return kExitFailure;
    }
    if (fit->num_not_invertible > 0) {
      PrintWarning(command,
                   std::string(names[k]) + " camera: the fitted " +
                       std::string(LensModelName(*model)) + " lens folds at " +
                       std::to_string(fit->num_not_invertible) +
                       " sampled pixels; a VIO would project rays there to "
                       "wrong pixels (try --model equidistant)");
    }
    fits.push_back(std::move(fit).value());
  }
  const StatusOr<StereoRig> fitted_rig =
      StereoRig::Create(fits[0].camera, fits[1].camera, rig->right_from_left());
  const StatusOr<Camchain> camchain =
      fitted_rig.ok() ? FittedCamchain(*fitted_rig)
                      : StatusOr<Camchain>(fitted_rig.status());
  if (!camchain.ok()) {
    PrintError(command, camchain.status().message());
    return kExitFailure;
  }

  // Side files first, the camchain last: a camchain on disk means the
  // export finished.
  const ExportPaths paths = ExportPathsFromFlags();
  std::error_code error;
  const std::filesystem::path directory =
      std::filesystem::path(paths.camchain).parent_path();
  if (!directory.empty()) std::filesystem::create_directories(directory, error);
  nlohmann::json json;
  json["n"] = *n;
  json["calib"] = FLAGS_calib;
  json["model"] = std::string(LensModelName(*model));
  json["fit_inset"] = options.fit_inset;
  json["port"] = domes->has_value()    ? "dome"
                 : rig->HasThickPort() ? "thick"
                                       : "thin";
  if (domes->has_value()) {
    json["dome_parallax_px"] = DomeParallaxJson(*rig, **domes, *n);
  }
  if (rig->HasThickPort() || domes->has_value()) {
    json["reference_depth_m"] = FLAGS_reference_depth;
  }
  for (int k = 0; k < 2; ++k) {
    const std::string name = names[k];
    if (!CheckCameraInfoModel(fits[k].camera).ok()) {
      // ds, eucm: the camchain is the only file that can hold them.
    } else if (Status status =
                   WriteCameraInfo(paths.prefix + name + ".yaml",
                                   CameraInfoFromCamera(name, fits[k].camera));
               !status.ok()) {
      PrintError(command, status.message());
      return kExitFailure;
    }
    ImageErrorMapOptions map_options;
    map_options.title =
        name + " camera: " + std::string(LensModelName(*model)) +
        " fit to the refractive model, n = " + FormatFixed(*n, 4);
    // Scaled to the fit region's errors, so that its structure shows; the
    // corners outside it saturate (their figures are in the legend).
    map_options.color_max = fits[k].inset.max_px;
    map_options.region = fits[k].inset_region;
    map_options.region_label = "fit region";
    const StatusOr<cv::Mat> picture =
        DrawImageErrorMap(fits[k].errors, map_options);
    if (picture.ok()) {
      if (Status status =
              WritePng(*picture, paths.prefix + "fit_error_" + name + ".png");
          !status.ok()) {
        PrintError(command, status.message());
        return kExitFailure;
      }
    }
    json[name] = FitJson(fits[k]);
  }
  json["camchain"] = paths.camchain;
  if (Status status = WriteFileAtomically(paths.prefix + "export.json",
                                          json.dump(2) + "\n");
      !status.ok()) {
    PrintError(command, status.message());
    return kExitFailure;
  }
  if (Status status = WriteCamchain(paths.camchain, *camchain); !status.ok()) {
    PrintError(command, status.message());
    return kExitFailure;
  }

  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
          .count();
  if (FLAGS_json) {
    json["seconds"] = seconds;
    std::cout << json.dump() << std::endl;
    return kExitOk;
  }
  std::cout << "rcm export: " << LensModelName(*model)
            << " water-side models of " << FLAGS_calib << " at n = " << *n
            << "\n";
  if (rig->HasThickPort()) std::cout << "  " << ThickPortNote(*rig) << "\n";
  if (domes->has_value()) {
    std::cout << "  " << DomeNote(*rig, **domes, *n) << "\n";
  }
  for (int k = 0; k < 2; ++k) {
    const WaterSideModelFit& fit = fits[k];
    const Camera& camera = fit.camera;
    std::cout << "  " << names[k] << ": intrinsics ["
              << FormatFixed(camera.fx(), 3) << ", "
              << FormatFixed(camera.fy(), 3) << ", "
              << FormatFixed(camera.cx(), 3) << ", "
              << FormatFixed(camera.cy(), 3) << "], distortion [";
    const std::vector<double> distortion = camera.Distortion();
    for (size_t i = 0; i < distortion.size(); ++i) {
      std::cout << (i ? ", " : "") << FormatDouble(distortion[i]);
    }
    std::cout << "]\n    fit error: RMS " << Px(fit.inset.rms_px) << ", max "
              << Px(fit.inset.max_px) << " inside the fit region ("
              << FormatFixed(100.0 * options.fit_inset, 0) << " % inset); RMS "
              << Px(fit.full.rms_px) << ", max " << Px(fit.full.max_px)
              << " over the whole image\n";
  }
  std::cout << "  wrote " << paths.camchain << ", " << paths.prefix
            << "{left,right}.yaml (camera_info), " << paths.prefix
            << "fit_error_{left,right}.png, " << paths.prefix
            << "export.json\n  done in " << FormatFixed(seconds, 1) << " s\n";
  return kExitOk;
}

}  // namespace
}  // namespace rcm::cli
