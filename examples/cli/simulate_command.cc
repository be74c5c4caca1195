// rcm simulate: a synthetic underwater stereo sequence with ground truth.
#include <gflags/gflags.h>

#include <chrono>
#include <cstdlib>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "command.h"
#include "index_flag.h"
#include "progress.h"
#include "rcm/io/atomic_file.h"
#include "rcm/io/number_format.h"
#include "rcm/sim/sequence_simulator.h"
#include "rcm/sim/sequence_writer.h"
#include "rig_flags.h"
#include "simulation_flags.h"


DEFINE_int32(matches_per_frame, 0,
             "also write matches.csv with this many exact correspondences "
             "per frame, sampled on the tank's surfaces seen by both cameras "
             "(0 = no matches.csv)");
DEFINE_double(match_noise, 0.0,
              "Gaussian noise added to the matches' pixels, standard "
              "deviation in pixels");
DEFINE_double(outliers, 0.0,
              "fraction of each frame's matches replaced by gross outliers");
DEFINE_string(depth_range, "",
              "MIN,MAX in meters: sample the matches at depths uniform in "
              "[MIN, MAX] on random left pixels' rays instead of on the "
              "tank's surfaces (needs --noimages)");
DEFINE_bool(images, true, "render the images (--noimages: matches only)");
DEFINE_bool(overwrite, false,
            "replace a sequence already in --out (its frames, matches, "
            "camchain and truth)");

namespace rcm::cli {
namespace {

constexpr char kUsage[] =
    "rcm simulate: a synthetic underwater stereo sequence with ground "
    "truth.\n\n"
    "usage: rcm simulate --out DIR [--n 1.333 | --media water:30,air:30]\n"
    "                    [--frames 20] [--air-gap 0.01 --glass-thickness "
    "0.005]\n"
    "                    [--matches-per-frame 500] [--calib RIG.yaml] "
    "[--seed 1]\n\n"
    "A robot moves through a textured pool with the stereo rig looking 16\n"
    "degrees down; each camera sees through an exact flat port (air gap,\n"
    "glass, optional tilt; vector Snell's law), not through the model that\n"
    "rcm estimates, so the data can test that model. Writes into DIR:\n"
    "  left/000000.png ...   8-bit mono images of cam0\n"
    "  right/000000.png ...  8-bit mono images of cam1\n"
    "  camchain.yaml         the in-air calibration (Kalibr)\n"
    "  truth.csv             frame,t,n,tx,ty,tz,qx,qy,qz,qw (world_from_cam0)\n"
    "  matches.csv           with --matches-per-frame: frame,xl,yl,xr,yr,t\n"
    "                        (points of the tank's surfaces, or with\n"
    "                        --depth-range points at sampled depths)\n"
    "  simulation.json       the settings, to reproduce the run\n"
    "truth.csv is written last; the same flags give the same bytes.";

int RunSimulate();

}  // namespace

extern const Subcommand kSimulateCommand = {
    "simulate",
    "synthetic stereo sequence through exact flat ports, with ground truth",
    kUsage,
    {__FILE__, kSimulationFlagsSource, kIndexFlagSource, kRigFlagsSource},
    RunSimulate};

namespace {

int RunSimulate() {
  const Subcommand& command = kSimulateCommand;
  if (FLAGS_out.empty()) {
    PrintError(command, "--out is required (see rcm simulate --help)");
    return kExitUsage;
  }
  StatusOr<Simulation> simulation =
      SimulationFromFlags(FLAGS_calib, FLAGS_left_camera, FLAGS_right_camera);
  if (!simulation.ok()) {
    PrintError(command, simulation.status().message());
    return kExitFailure;
  }
  SequenceOptions& options = simulation.value().options;
  options.render_images = FLAGS_images;
  options.matches_per_frame = FLAGS_matches_per_frame;
  options.match_noise_px = FLAGS_match_noise;
  options.outlier_fraction = FLAGS_outliers;
  if (!FLAGS_depth_range.empty()) {
    const size_t comma = FLAGS_depth_range.find(',');
    char* end = nullptr;
    const std::string min_text = FLAGS_depth_range.substr(0, comma);
    options.match_min_depth = std::strtod(min_text.c_str(), &end);
    bool ok = comma != std::string::npos && !min_text.empty() && *end == '\0';
    if (ok) {
      const std::string max_text = FLAGS_depth_range.substr(comma + 1);
      options.match_max_depth = std::strtod(max_text.c_str(), &end);
      ok = !max_text.empty() && *end == '\0';
    }
    if (!ok) {
      PrintError(command, "--depth-range " + FLAGS_depth_range +
                              ": expected MIN,MAX in meters, e.g. 0.6,6");
      return kExitUsage;
    }
    const Status valid = options.Check();
    if (!valid.ok()) {
      PrintError(command, "--depth-range: " + valid.message());
      return kExitUsage;
    }
  }
  if (!options.render_images && options.matches_per_frame == 0) {
    PrintError(command,
               "--noimages without --matches-per-frame would write no data");
    return kExitUsage;
  }

  const auto start = std::chrono::steady_clock::now();
  StatusOr<std::unique_ptr<SequenceSimulator>> simulator =
      SequenceSimulator::Create(simulation.value().rig, options);
  if (!simulator.ok()) {
    PrintError(command, simulator.status().message());
    return kExitFailure;
  }
  Progress progress("rcm simulate: frame", simulator.value()->num_frames());
  SequenceWriterOptions writer;
  writer.overwrite = FLAGS_overwrite;
  writer.progress = [&](int done, int) { progress.Update(done); };
  const Status written =
      WriteSequence(FLAGS_out, simulator.value().get(), writer);
  if (!written.ok()) {
    PrintError(command, written.message());
    return kExitFailure;
  }
  nlohmann::json settings = SimulationFlagsJson(simulation.value());
  settings["matches_per_frame"] = FLAGS_matches_per_frame;
  settings["match_noise"] = FLAGS_match_noise;
  settings["outliers"] = FLAGS_outliers;
  settings["images"] = FLAGS_images;
  settings["depth_range"] = FLAGS_depth_range;
  const Status settings_written = WriteFileAtomically(
      FLAGS_out + "/simulation.json", settings.dump(2) + "\n");
  if (!settings_written.ok()) {
    PrintError(command, settings_written.message());
    return kExitFailure;
  }
  const double seconds = std::chrono::duration<double>(
                             std::chrono::steady_clock::now() - start)
                             .count();

  const SequenceSimulator& sim = *simulator.value();
  if (FLAGS_json) {
    nlohmann::json report = settings;
    report["out"] = FLAGS_out;
    report["frames"] = sim.num_frames();
    report["switch_frames"] = sim.media().SwitchFrames();
    report["seconds"] = seconds;
    std::cout << report.dump() << std::endl;
    return kExitOk;
  }
  const Camera& left = sim.rig().left();
  std::cout << "rcm simulate: wrote " << sim.num_frames() << " frames to "
            << FLAGS_out << "/ in " << FormatFixed(seconds, 1) << " s\n"
            << "  rig      " << simulation.value().rig_name << " ("
            << left.width() << "x" << left.height() << ")\n"
            << "  media    " << sim.media().ToString() << "\n"
            << "  port     air gap " << options.left_port.air_gap
            << " m, glass " << options.left_port.glass_thickness
            << " m (index " << options.left_port.glass_index << ")\n"
            << "  files    "
            << (options.render_images ? "left/ right/ " : "")
            << (options.matches_per_frame > 0 ? "matches.csv " : "")
            << "camchain.yaml truth.csv simulation.json" << std::endl;
  return kExitOk;
}

}  // namespace
}  // namespace rcm::cli
