// rcm dome-check: is a dome port worth modelling? The pixel error of
// ignoring it (rcm/estimation/dome_port_error.h) over the image and a
// range of depths, with a verdict, a picture and a plot.
#include <gflags/gflags.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "camera_flag.h"
#include "command.h"
#include "depth_range_flag.h"
#include "dome_port_flags.h"
#include "glass_index_flag.h"
#include "index_flag.h"
#include "number_list_flag.h"
#include "rcm/camera/dome_port_camera.h"
#include "rcm/estimation/dome_port_error.h"
#include "rcm/io/atomic_file.h"
#include "rcm/io/camchain.h"
#include "rcm/io/image_file.h"
#include "rcm/plot/line_plot.h"
#include "rcm/util/number_format.h"
#include "rcm/viz/image_error_map.h"
#include "reference_depth_flag.h"

DEFINE_string(camchain, "",
              "the in-air calibration: a Kalibr camchain of one or more "
              "cameras (its port block of type dome, or the --port dome "
              "flags)");
DEFINE_double(tolerance_px, 0.1,
              "the error, in pixels, below which the dome can be ignored");

namespace rcm::cli {
namespace {

namespace fs = std::filesystem;

constexpr char kDomeCheckUsage[] =
    "rcm dome-check: is my dome worth modelling?\n\n"
    "usage:\n"
    "  rcm dome-check --camchain air.yaml [--camera cam0] [--port dome\n"
    "      --dome-inner-radius M --dome-thickness M --glass-index N\n"
    "      --dome-decentering X,Y,Z] [--n 1.333] [--depth-range 0.3,10]\n"
    "      [--reference-depth M] [--out DIR] [--json]\n\n"
    "For a camera calibrated in air behind a dome port (the camchain's port\n"
    "block of type dome, or the --port dome flags) in water of index n: the\n"
    "pixel error of ignoring the dome, i.e. of using the air calibration\n"
    "under water as it is. A dome centred on the camera does not refract; a\n"
    "decentered one bends the rays by an amount that depends on the\n"
    "distance. Prints the max and RMS error over the image at depths across\n"
    "--depth-range (camera-frame z, meters), the worst depth and a verdict.\n"
    "--reference-depth M (given) adds the error at M and that of the best\n"
    "central camera, exact at M (what a conventional underwater calibration\n"
    "or a corrected pinhole image gives at best) across the range. --out\n"
    "DIR writes DIR/dome_check_error.png (the error over the image at the\n"
    "worst depth), DIR/dome_check_depths.png (the error against depth) and\n"
    "DIR/dome_check.json.";

// Pixels for people: two significant digits below 1, two decimals below
// 10, one above.
std::string FormatDomePx(double value) {
  if (!std::isfinite(value)) return "n/a";
  if (value >= 10.0) return FormatFixed(value, 1);
  if (value >= 1.0) return FormatFixed(value, 2);
  std::ostringstream text;
  text << std::setprecision(2) << value;
  return text.str();
}

// Meters: three significant digits (0.3, 0.411, 10).
std::string FormatDomeDepth(double value) {
  std::ostringstream text;
  text << std::setprecision(3) << value;
  return text.str();
}

std::string FormatDomeMm(double meters) { return FormatFixed(1e3 * meters, 2); }

nlohmann::json DomeErrorJson(const DomePortErrorAtDepth& at) {
  nlohmann::json json = {{"depth_m", at.depth},
                         {"max_px", JsonNumber(at.ignored.max_px)},
                         {"rms_px", JsonNumber(at.ignored.rms_px)},
                         {"median_px", JsonNumber(at.ignored.median_px)},
                         {"samples", at.ignored.num_samples},
                         {"unusable_samples", at.num_unusable}};
  if (at.central) {
    json["central_max_px"] = JsonNumber(at.central->max_px);
    json["central_rms_px"] = JsonNumber(at.central->rms_px);
  }
  return json;
}

// The one-line answer.
std::string DomeVerdict(const DomePortError& error, double tolerance) {
  const DomePortErrorAtDepth& worst = error.depths[error.worst_index];
  const DomePortErrorAtDepth& far = error.depths.back();
  const DomePortErrorAtDepth& near = error.depths.front();
  if (error.max_px < tolerance) {
    return "ignoring this dome costs < " + FormatDomePx(tolerance) +
           " px (at most " + FormatDomePx(error.max_px) + " px between " +
           FormatDomeDepth(near.depth) + " and " + FormatDomeDepth(far.depth) +
           " m): it can be ignored";
  }
  std::string text = "ignoring this dome costs up to " +
                     FormatDomePx(worst.ignored.max_px) + " px at " +
                     FormatDomeDepth(worst.depth) + " m";
  const DomePortErrorAtDepth& other =
      error.worst_index + 1 == static_cast<int>(error.depths.size()) ? near
                                                                     : far;
  if (&other != &worst) {
    text += " (" + FormatDomePx(other.ignored.max_px) + " px at " +
            FormatDomeDepth(other.depth) + " m)";
  }
  return text + ": model it";
}

// The line on the central camera (with --reference-depth).
std::string DomeCentralNote(const DomePortError& error, double reference_depth,
                            double tolerance) {
  const double central = error.central_max_px.value_or(NAN);
  return "a central camera exact at " + FormatDomeDepth(reference_depth) +
         " m (what a conventional underwater calibration approximates) is off "
         "by up to " +
         FormatDomePx(central) + " px between " +
         FormatDomeDepth(error.depths.front().depth) + " and " +
         FormatDomeDepth(error.depths.back().depth) + " m" +
         (central < tolerance ? ": enough for this range"
                              : ": the dome's parallax; model the dome");
}

cv::Mat DomeDepthPlot(const DomePortError& error, double tolerance,
                      const std::string& title) {
  std::vector<double> depth, max, rms, central;
  for (const DomePortErrorAtDepth& at : error.depths) {
    depth.push_back(at.depth);
    max.push_back(at.ignored.max_px);
    rms.push_back(at.ignored.rms_px);
    if (at.central) central.push_back(at.central->max_px);
  }
  LinePlot plot;
  plot.SetTitle(title);
  plot.SetXLabel("depth (m)");
  plot.SetYLabel("error (px)");
  double top = error.max_px;
  LineStyle max_style, rms_style, central_style;
  max_style.color = PaletteColor(0);
  rms_style.color = PaletteColor(2);
  central_style.color = PaletteColor(3);
  MarkerStyle markers;
  markers.color = PaletteColor(0);
  plot.AddLine(depth, max, "ignoring the dome: max", max_style);
  plot.AddMarkers(depth, max, "", markers);
  plot.AddLine(depth, rms, "ignoring the dome: RMS", rms_style);
  if (!central.empty()) {
    plot.AddLine(depth, central, "central camera exact at the reference: max",
                 central_style);
    top = std::max(top, *error.central_max_px);
  }
  LineStyle dashed;
  dashed.color = cv::Scalar(128, 128, 128);
  dashed.dash = 8.0;
  plot.AddHorizontalLine(tolerance, "tolerance", dashed);
  plot.SetYRange(0.0, 1.05 * std::max(top, tolerance));
  if (depth.size() > 1) plot.SetXRange(0.0, depth.back());
  return plot.Render(1000, 600);
}

int RunDomeCheck();

}  // namespace

extern const Subcommand kDomeCheckCommand = {
    "dome-check",
    "is my dome worth modelling: the pixel error of ignoring it",
    kDomeCheckUsage,
    {__FILE__, kCameraFlagSource, kDepthRangeFlagSource, kDomePortFlagsSource,
     kGlassIndexFlagSource, kIndexFlagSource, kReferenceDepthFlagSource},
    RunDomeCheck};

namespace {

int RunDomeCheck() {
  const Subcommand& command = kDomeCheckCommand;
  const auto start = std::chrono::steady_clock::now();
  if (FLAGS_camchain.empty()) {
    PrintError(command,
               "--camchain is required: the camera's in-air calibration (see "
               "rcm dome-check --help)");
    return kExitUsage;
  }
  const StatusOr<double> n = RefractiveIndexFromFlag(/*required=*/false);
  if (!n.ok()) {
    PrintError(command, n.status().message());
    return kExitUsage;
  }
  DomePortErrorOptions options;
  const std::string range_text =
      FLAGS_depth_range.empty() ? "0.3,10" : FLAGS_depth_range;
  const StatusOr<std::vector<double>> range = ParseNumberList(range_text);
  if (!range.ok() || range->size() != 2) {
    PrintError(command, "--depth-range " + range_text +
                            ": expected MIN,MAX in meters, e.g. 0.3,10");
    return kExitUsage;
  }
  options.min_depth = (*range)[0];
  options.max_depth = (*range)[1];
  if (!gflags::GetCommandLineFlagInfoOrDie("reference_depth").is_default) {
    options.reference_depth = FLAGS_reference_depth;
  }
  if (!(FLAGS_tolerance_px > 0.0) || !std::isfinite(FLAGS_tolerance_px)) {
    PrintError(command, "--tolerance-px " + FormatDouble(FLAGS_tolerance_px) +
                            " is not a positive number of pixels");
    return kExitUsage;
  }
  if (const Status status = options.Check(); !status.ok()) {
    const bool reference =
        status.message().find("reference_depth") != std::string::npos;
    PrintError(command, (reference ? std::string("--reference-depth: ")
                                   : "--depth-range " + range_text + ": ") +
                            status.message());
    return kExitUsage;
  }
  const StatusOr<std::optional<DomePort>> flag_dome = DomePortFromFlags();
  if (!flag_dome.ok()) {
    PrintError(command, flag_dome.status().message());
    return kExitUsage;
  }

  const StatusOr<Camchain> camchain = ReadCamchain(FLAGS_camchain);
  if (!camchain.ok()) {
    PrintError(command, camchain.status().message());
    return kExitFailure;
  }
  const StatusOr<int> index = FindCamchainCamera(*camchain, FLAGS_camera);
  if (!index.ok()) {
    PrintError(command, FLAGS_camchain + ": " + index.status().message());
    return kExitFailure;
  }
  const CamchainCamera& entry = camchain->cameras[*index];
  DomePort dome;
  if (flag_dome->has_value()) {
    if (entry.port.has_value()) {
      PrintError(command, FLAGS_camchain + ": " + FLAGS_camera +
                              " has a flat port block; --port dome describes "
                              "a dome");
      return kExitFailure;
    }
    dome = **flag_dome;
  } else if (entry.dome.has_value()) {
    dome = *entry.dome;
  } else {
    PrintError(command, "no dome: " + FLAGS_camera + " of " + FLAGS_camchain +
                            " has no port block of type dome; give one, or "
                            "--port dome --dome-inner-radius M "
                            "--dome-thickness M");
    return kExitFailure;
  }
  const StatusOr<DomePortCamera> dome_camera =
      DomePortCamera::Create(entry.camera, dome, *n);
  if (!dome_camera.ok()) {
    PrintError(command, dome_camera.status().message());
    return kExitFailure;
  }
  const Camera& camera = entry.camera;
  // ~180 samples along the longer side, whatever the resolution.
  options.grid_step =
      std::max(1.0, std::max(camera.width(), camera.height()) / 180.0);
  const StatusOr<DomePortError> error =
      EvaluateDomePortError(*dome_camera, options);
  if (!error.ok()) {
    PrintError(command, error.status().message());
    return kExitFailure;
  }

  const double tolerance = FLAGS_tolerance_px;
  const std::string verdict = DomeVerdict(*error, tolerance);
  const DomePortErrorAtDepth& worst = error->depths[error->worst_index];
  nlohmann::json json;
  json["camchain"] = FLAGS_camchain;
  json["camera"] = FLAGS_camera;
  json["n"] = *n;
  json["dome"] = {
      {"inner_radius_m", dome.inner_radius},
      {"outer_radius_m", dome.outer_radius()},
      {"thickness_m", dome.thickness},
      {"glass_index", dome.glass_index},
      {"decentering_m",
       {dome.decentering.x(), dome.decentering.y(), dome.decentering.z()}}};
  json["image_size"] = {camera.width(), camera.height()};
  json["grid_step_px"] = options.grid_step;
  json["depths"] = nlohmann::json::array();
  for (const DomePortErrorAtDepth& at : error->depths) {
    json["depths"].push_back(DomeErrorJson(at));
  }
  json["worst_depth_m"] = worst.depth;
  json["max_px"] = JsonNumber(error->max_px);
  json["rms_px"] = JsonNumber(error->rms_px);
  json["reference"] = error->at_reference ? DomeErrorJson(*error->at_reference)
                                          : nlohmann::json();
  json["central_max_px"] = JsonNumber(error->central_max_px);
  json["tolerance_px"] = tolerance;
  json["ignorable"] = error->max_px < tolerance;
  json["verdict"] = verdict;

  std::vector<std::string> written;
  if (!FLAGS_out.empty()) {
    std::error_code code;
    fs::create_directories(FLAGS_out, code);
    const std::string where = FLAGS_camera + " behind a dome decentered (" +
                              FormatDomeMm(dome.decentering.x()) + ", " +
                              FormatDomeMm(dome.decentering.y()) + ", " +
                              FormatDomeMm(dome.decentering.z()) +
                              ") mm, n = " + FormatFixed(*n, 3);
    ImageErrorMapOptions map_options;
    map_options.title =
        where + ": ignoring the dome at " + FormatDomeDepth(worst.depth) + " m";
    const std::string map_path =
        (fs::path(FLAGS_out) / "dome_check_error.png").string();
    const std::string plot_path =
        (fs::path(FLAGS_out) / "dome_check_depths.png").string();
    const std::string json_path =
        (fs::path(FLAGS_out) / "dome_check.json").string();
    const StatusOr<cv::Mat> map =
        DrawImageErrorMap(error->worst_field, map_options);
    Status status = map.ok() ? WritePng(*map, map_path) : map.status();
    if (status.ok()) {
      status = WritePng(DomeDepthPlot(*error, tolerance, where), plot_path);
    }
    if (status.ok()) {
      json["pictures"] = {map_path, plot_path};
      status = WriteFileAtomically(json_path, json.dump(2) + "\n");
    }
    if (!status.ok()) {
      PrintError(command, status.message());
      return kExitFailure;
    }
    written = {map_path, plot_path, json_path};
  }

  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
          .count();
  if (FLAGS_json) {
    json["seconds"] = seconds;
    std::cout << json.dump() << std::endl;
    return kExitOk;
  }
  std::cout << "rcm dome-check: " << FLAGS_camera << " of " << FLAGS_camchain
            << " (" << camera.width() << "x" << camera.height()
            << ") behind a dome of r1 " << FormatDomeMm(dome.inner_radius)
            << " mm, r2 " << FormatDomeMm(dome.outer_radius()) << " mm, glass "
            << FormatFixed(dome.glass_index, 3) << ", decentered ("
            << FormatDomeMm(dome.decentering.x()) << ", "
            << FormatDomeMm(dome.decentering.y()) << ", "
            << FormatDomeMm(dome.decentering.z())
            << ") mm, in water of n = " << FormatFixed(*n, 3) << "\n"
            << "  the error of ignoring the dome (the air calibration under "
               "water), over "
            << error->worst_field.cols << " x " << error->worst_field.rows
            << " pixels every " << FormatFixed(options.grid_step, 1) << " px:\n"
            << "    depth m    max px    RMS px";
  if (options.reference_depth) std::cout << "  central max px";
  std::cout << "\n";
  for (const DomePortErrorAtDepth& at : error->depths) {
    std::cout << "    " << std::setw(7) << FormatDomeDepth(at.depth) << "  "
              << std::setw(8) << FormatDomePx(at.ignored.max_px) << "  "
              << std::setw(8) << FormatDomePx(at.ignored.rms_px);
    if (at.central)
      std::cout << "  " << std::setw(14) << FormatDomePx(at.central->max_px);
    std::cout << "\n";
  }
  std::cout << "  worst at " << FormatDomeDepth(worst.depth) << " m: max "
            << FormatDomePx(worst.ignored.max_px) << " px, RMS "
            << FormatDomePx(worst.ignored.rms_px) << " px; over all depths RMS "
            << FormatDomePx(error->rms_px) << " px\n";
  if (error->at_reference) {
    std::cout << "  at the reference depth "
              << FormatDomeDepth(error->at_reference->depth) << " m: max "
              << FormatDomePx(error->at_reference->ignored.max_px)
              << " px, RMS "
              << FormatDomePx(error->at_reference->ignored.rms_px) << " px\n"
              << "  "
              << DomeCentralNote(*error, *options.reference_depth, tolerance)
              << "\n";
  }
  for (const std::string& path : written) {
    std::cout << "  wrote " << path << "\n";
  }
  std::cout << "  done in " << FormatFixed(seconds, 1) << " s\n"
            << verdict << "\n";
  return kExitOk;
}

}  // namespace
}  // namespace rcm::cli
