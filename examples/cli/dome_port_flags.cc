#include "dome_port_flags.h"

#include <cmath>
#include <iterator>
#include <string>
#include <vector>

#include "number_list_flag.h"

DEFINE_string(port, "flat",
              "the housing's port: flat (the camchain's port blocks, or "
              "the paper's thin port) or dome (with --dome-inner-radius "
              "and --dome-thickness, for a camchain without dome blocks)");
DEFINE_double(dome_inner_radius, 0.0,
              "with --port dome: the dome's inner radius, meters (e.g. "
              "0.04355)");
DEFINE_double(dome_thickness, 0.0,
              "with --port dome: the dome's glass thickness, meters (or "
              "--dome-outer-radius)");
DEFINE_double(dome_outer_radius, 0.0,
              "with --port dome: the dome's outer radius, meters (instead "
              "of, or agreeing with, --dome-thickness)");
DEFINE_string(dome_decentering, "",
              "with --port dome: X,Y,Z, the dome's centre in the camera "
              "frame, meters (default 0,0,0, centred; a camera 7 mm behind "
              "the centre is 0,0,0.007): a calibration's start, a "
              "simulation's truth, a check's value");

namespace rcm::cli {

extern const char kDomePortFlagsSource[] = __FILE__;

namespace {

bool IsDefault(const char* name) {
  gflags::CommandLineFlagInfo info;
  return !gflags::GetCommandLineFlagInfo(name, &info) || info.is_default;
}

}  // namespace

std::string FirstGivenFlag(const std::vector<const char*>& names) {
  for (const char* name : names) {
    if (IsDefault(name)) continue;
    std::string flag = std::string("--") + name;
    for (char& c : flag) c = c == '_' ? '-' : c;
    return flag;
  }
  return "";
}

bool DomePortRequested() { return FLAGS_port == "dome"; }

StatusOr<std::optional<DomePort>> DomePortFromFlags() {
  if (FLAGS_port != "flat" && FLAGS_port != "dome") {
    return Status::Error("--port " + FLAGS_port + ": expected flat or dome");
  }
  const char* dome_flags[] = {"dome_inner_radius", "dome_thickness",
                              "dome_outer_radius", "glass_index",
                              "dome_decentering"};
  if (FLAGS_port == "flat") {
    const std::string given = FirstGivenFlag(
        std::vector<const char*>(std::begin(dome_flags), std::end(dome_flags)));
    if (!given.empty()) {
      return Status::Error(given + " describes a dome: give --port dome");
    }
    return std::optional<DomePort>();
  }
  DomePort dome;
  if (IsDefault("dome_inner_radius")) {
    return Status::Error("--port dome needs --dome-inner-radius M");
  }
  dome.inner_radius = FLAGS_dome_inner_radius;
  const bool has_thickness = !IsDefault("dome_thickness");
  const bool has_outer = !IsDefault("dome_outer_radius");
  if (!has_thickness && !has_outer) {
    return Status::Error(
        "--port dome needs --dome-thickness M (or --dome-outer-radius M)");
  }
  if (has_outer) {
    const StatusOr<double> thickness =
        DomeThicknessFromRadii(dome.inner_radius, FLAGS_dome_outer_radius,
                               has_thickness ? FLAGS_dome_thickness : -1.0);
    if (!thickness.ok()) {
      return Status::Error("--port dome: " + thickness.status().message());
    }
    dome.thickness = has_thickness ? FLAGS_dome_thickness : *thickness;
  } else {
    dome.thickness = FLAGS_dome_thickness;
  }
  dome.glass_index = FLAGS_glass_index;
  if (!FLAGS_dome_decentering.empty()) {
    const StatusOr<std::vector<double>> centre =
        ParseNumberList(FLAGS_dome_decentering);
    if (!centre.ok() || centre->size() != 3) {
      return Status::Error("--dome-decentering " + FLAGS_dome_decentering +
                           ": expected X,Y,Z (meters), e.g. 0,0,0.007");
    }
    dome.decentering =
        Eigen::Vector3d((*centre)[0], (*centre)[1], (*centre)[2]);
  }
  if (const Status status = dome.Check(); !status.ok()) {
    return Status::Error("--port dome: " + status.message());
  }
  return std::optional<DomePort>(dome);
}

StatusOr<std::vector<DomePort>> DomesOfCameras(const Camchain& camchain,
                                               int num_cameras) {
  const StatusOr<std::optional<DomePort>> flags = DomePortFromFlags();
  if (!flags.ok()) return flags.status();
  std::vector<DomePort> domes;
  int with_block = 0;
  for (int c = 0; c < num_cameras; ++c) {
    const CamchainCamera& camera = camchain.cameras[c];
    if (flags->has_value()) {
      if (camera.port.has_value()) {
        return Status::Error("cam" + std::to_string(c) +
                             " has a flat port block; --port dome describes "
                             "a dome");
      }
      domes.push_back(**flags);
    } else if (camera.dome.has_value()) {
      domes.push_back(*camera.dome);
      ++with_block;
    }
  }
  if (!flags->has_value() && with_block == 0) {
    return Status::Error(
        "no dome: give --port dome --dome-inner-radius M --dome-thickness "
        "M, or a camchain with port blocks of type dome");
  }
  if (!flags->has_value() && with_block != num_cameras) {
    return Status::Error(
        "only some cameras have a dome port block; give every camera one, "
        "or --port dome for all");
  }
  return domes;
}

}  // namespace rcm::cli
