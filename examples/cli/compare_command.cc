// rcm compare: the refractive index implied by an air and an underwater
// calibration of the same camera, with the residual map.
#include <gflags/gflags.h>

#include <chrono>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "air_flag.h"
#include "camera_flag.h"
#include "command.h"
#include "rcm/estimation/calibration_comparison.h"
#include "rcm/io/atomic_file.h"
#include "rcm/io/camera_file.h"
#include "rcm/io/image_file.h"
#include "rcm/util/number_format.h"
#include "rcm/viz/image_error_map.h"

DEFINE_string(water, "",
              "the underwater calibration of the same camera: a Kalibr "
              "camchain or a ROS camera_info");
DEFINE_bool(shift, true,
            "also estimate a shift of the air calibration's principal point");
DEFINE_double(inset, 0.05,
              "fraction of the image width and height left out at each side "
              "(where the underwater calibration saw no target)");

namespace rcm::cli {
namespace {

constexpr char kCompareUsage[] =
    "rcm compare: the refractive index implied by an air and an underwater\n"
    "calibration of one camera\n\n"
    "usage:\n"
    "  rcm compare --air air.yaml --water water.yaml [--camera cam0] "
    "[--out DIR]\n\n"
    "For a camera calibrated in air and, conventionally, under water (e.g.\n"
    "Kalibr on a dive), finds the refractive index n (and, with --shift, a\n"
    "shift of the principal point) for which the refractive model of the air\n"
    "calibration agrees best with the underwater one, in pixels over a grid\n"
    "on the image. Prints n, its formal sigma, the shift and the residual\n"
    "statistics; --out DIR writes DIR/compare_residuals.png (the residual\n"
    "map) and DIR/compare.json. Residuals far above the calibrations' own\n"
    "accuracy mean the thin-port model does not describe the housing (an air\n"
    "gap or a thick or tilted port), or the calibrations are of different\n"
    "lens states (focus).";

nlohmann::json ComparisonJson(const CalibrationComparison& comparison) {
  const IndexFromRays& fit = comparison.fit;
  const PixelErrorStats& stats = comparison.residual_stats;
  return {{"n", JsonNumber(fit.n)},
          {"sigma_n_formal", JsonNumber(fit.sigma_n)},
          {"principal_point_shift_px",
           {JsonNumber(fit.principal_point_shift.x()),
            JsonNumber(fit.principal_point_shift.y())}},
          {"sigma_principal_point_shift_px",
           {JsonNumber(fit.sigma_principal_point_shift.x()),
            JsonNumber(fit.sigma_principal_point_shift.y())}},
          {"correlation_n_shift",
           {JsonNumber(fit.correlation_n_shift.x()),
            JsonNumber(fit.correlation_n_shift.y())}},
          {"residual_rms_px", JsonNumber(stats.rms_px)},
          {"residual_median_px", JsonNumber(stats.median_px)},
          {"residual_max_px", JsonNumber(stats.max_px)},
          {"samples", stats.num_samples},
          {"unusable_samples", comparison.num_unusable},
          {"iterations", fit.num_iterations},
          {"converged", fit.converged}};
}

// Two significant digits: the formal sigma spans 1e-7 (an exported
// model) to 1e-2 (a poor calibration).
std::string FormatSignificant(double value) {
  std::ostringstream text;
  text << std::setprecision(2) << value;
  return text.str();
}

int RunCompare();

}  // namespace

extern const Subcommand kCompareCommand = {
    "compare",
    "n implied by an air and an underwater calibration of one camera",
    kCompareUsage,
    {__FILE__, kAirFlagSource, kCameraFlagSource},
    RunCompare};

namespace {

int RunCompare() {
  const Subcommand& command = kCompareCommand;
  const auto start = std::chrono::steady_clock::now();
  if (FLAGS_air.empty() || FLAGS_water.empty()) {
    PrintError(command,
               "--air and --water are required: the two calibrations of the "
               "camera");
    return kExitUsage;
  }
  CalibrationComparisonOptions options;
  options.estimate_principal_point_shift = FLAGS_shift;
  options.inset = FLAGS_inset;
  if (Status status = options.Check(); !status.ok()) {
    PrintError(command, status.message());
    return kExitUsage;
  }
  const StatusOr<Camera> air = ReadCameraFile(FLAGS_air, FLAGS_camera);
  if (!air.ok()) {
    PrintError(command, air.status().message());
    return kExitFailure;
  }
  const StatusOr<Camera> water = ReadCameraFile(FLAGS_water, FLAGS_camera);
  if (!water.ok()) {
    PrintError(command, water.status().message());
    return kExitFailure;
  }
  const StatusOr<CalibrationComparison> comparison =
      CompareCalibrations(*air, *water, options);
  if (!comparison.ok()) {
    PrintError(command, comparison.status().message());
    return kExitFailure;
  }

  nlohmann::json json = ComparisonJson(*comparison);
  json["air"] = FLAGS_air;
  json["water"] = FLAGS_water;
  json["camera"] = FLAGS_camera;
  json["inset"] = options.inset;
  std::string picture_path;
  if (!FLAGS_out.empty()) {
    std::error_code error;
    std::filesystem::create_directories(FLAGS_out, error);
    picture_path =
        (std::filesystem::path(FLAGS_out) / "compare_residuals.png").string();
    ImageErrorMapOptions map_options;
    map_options.title = FLAGS_camera + ": air calibration at n = " +
                        FormatFixed(comparison->fit.n, 5) +
                        " against the underwater calibration";
    map_options.region = comparison->region;
    map_options.region_label = "compared region";
    const StatusOr<cv::Mat> picture =
        DrawImageErrorMap(comparison->residual_field, map_options);
    Status status =
        picture.ok() ? WritePng(*picture, picture_path) : picture.status();
    if (status.ok()) {
      status = WriteFileAtomically(
          (std::filesystem::path(FLAGS_out) / "compare.json").string(),
          json.dump(2) + "\n");
    }
    if (!status.ok()) {
      PrintError(command, status.message());
      return kExitFailure;
    }
  }

  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
          .count();
  if (FLAGS_json) {
    json["seconds"] = seconds;
    std::cout << json.dump() << std::endl;
    return kExitOk;
  }
  const IndexFromRays& fit = comparison->fit;
  const PixelErrorStats& stats = comparison->residual_stats;
  std::cout << "rcm compare: " << FLAGS_camera << " of " << FLAGS_air
            << " (air) against " << FLAGS_water << " (under water)\n"
            << "  n = " << FormatFixed(fit.n, 5) << " +- "
            << FormatSignificant(fit.sigma_n)
            << " (formal: the residuals are model error, not noise)\n";
  if (options.estimate_principal_point_shift) {
    std::cout << "  principal point shift ("
              << FormatFixed(fit.principal_point_shift.x(), 2) << ", "
              << FormatFixed(fit.principal_point_shift.y(), 2) << ") px\n";
  }
  std::cout << "  residual: RMS " << FormatFixed(stats.rms_px, 3)
            << " px, median " << FormatFixed(stats.median_px, 3) << " px, max "
            << FormatFixed(stats.max_px, 3) << " px over " << stats.num_samples
            << " pixels (" << FormatFixed(100.0 * options.inset, 0)
            << " % inset)\n";
  if (comparison->num_unusable > 0) {
    std::cout << "  " << comparison->num_unusable
              << " pixels not compared (past total internal reflection or "
                 "outside a lens' valid region)\n";
  }
  if (!picture_path.empty()) std::cout << "  wrote " << picture_path << "\n";
  std::cout << "  done in " << FormatFixed(seconds, 1) << " s\n";
  return kExitOk;
}

}  // namespace
}  // namespace rcm::cli
