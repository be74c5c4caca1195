// rcm simulate: a synthetic underwater stereo sequence with ground truth.
#include <gflags/gflags.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <iostream>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "command.h"
#include "depth_range_flag.h"
#include "dome_port_flags.h"
#include "glass_index_flag.h"
#include "index_flag.h"
#include "number_list_flag.h"
#include "progress.h"
#include "rcm/calib/calibration_target.h"
#include "rcm/io/atomic_file.h"
#include "rcm/sim/sequence_simulator.h"
#include "rcm/sim/sequence_writer.h"
#include "rcm/util/number_format.h"
#include "rig_flags.h"
#include "simulation_flags.h"
#include "target_flags.h"

DEFINE_int32(matches_per_frame, 0,
             "also write matches.csv with this many exact correspondences "
             "per frame, sampled on the tank's surfaces seen by both cameras "
             "(0 = no matches.csv)");
DEFINE_double(match_noise, 0.0,
              "Gaussian noise added to the matches' pixels, standard "
              "deviation in pixels");
DEFINE_double(outliers, 0.0,
              "fraction of each frame's matches replaced by gross outliers");
DEFINE_string(exposure_delay, "",
              "MS,DEG_S[,M_S]: the right camera exposes MS milliseconds "
              "after the left (cameras not triggered together, e.g. a "
              "StereoPi) while the rig turns at DEG_S deg/s and moves at "
              "M_S m/s (standard deviation per axis, drawn per frame): the "
              "right image and the matches' right pixels see the scene "
              "moved in between");
DEFINE_string(board_distance, "0.6,2.0",
              "with --board: MIN,MAX in meters, the range of the board's "
              "distance in front of cam0");
DEFINE_string(board_warp, "",
              "with --board: X_MM,Y_MM, the board's bow (mrcal's "
              "calobject_warp, rcm calibrate's board_warp_mm: X_MM + Y_MM "
              "is the bowl at the centre; positive bows it away from the "
              "cameras); default flat");
DEFINE_string(right_dome_decentering, "",
              "with --port dome: X,Y,Z, the right camera's dome centre in "
              "its frame, meters (default: --dome-decentering, the same "
              "for both cameras)");
DEFINE_bool(images, true, "render the images (--noimages: matches only)");
DEFINE_bool(overwrite, false,
            "replace a sequence already in --out (its frames, matches, "
            "camchain, board and truth)");

namespace rcm::cli {
namespace {

constexpr char kSimulateUsage[] =
    "rcm simulate: a synthetic underwater stereo sequence with ground "
    "truth.\n\n"
    "usage: rcm simulate --out DIR [--n 1.333 | --media water:30,air:30]\n"
    "                    [--frames 20] [--air-gap 0.01 --glass-thickness "
    "0.005]\n"
    "                    [--matches-per-frame 500] [--calib RIG.yaml | --rig "
    "narrow]\n"
    "                    [--extrinsic-drift 0.5,0,0] [--lens-change 0.5,-0.3]\n"
    "                    [--tank 5,5,3 --loops 1]\n"
    "                    [--board chessboard --cols 9 --rows 6\n"
    "                    --square 0.03 [--board-distance 0.6,2]\n"
    "                    [--board-warp 1,0.5]] [--seed "
    "1]\n"
    "                    [--port dome --dome-inner-radius 0.04355\n"
    "                    --dome-thickness 0.00375 --glass-index 1.495\n"
    "                    --dome-decentering 0.002,-0.001,0.007\n"
    "                    [--right-dome-decentering X,Y,Z]]\n\n"
    "A robot moves through a textured pool with the stereo rig looking 16\n"
    "degrees down; each camera sees through an exact flat port (air gap,\n"
    "glass, optional tilt; vector Snell's law), not through the model that\n"
    "rcm estimates, so the data can test that model. With --port dome each\n"
    "camera sees through a dome instead (both of the same glass, centred\n"
    "at --dome-decentering in the camera's frame, the right one at\n"
    "--right-dome-decentering when given), traced exactly; the camchain\n"
    "stays the air calibration (no port block), as a user has it, for\n"
    "rcm calibrate --underwater --port dome. Writes into DIR:\n"
    "  left/000000.png ...   8-bit mono images of cam0\n"
    "  right/000000.png ...  8-bit mono images of cam1\n"
    "  camchain.yaml         the in-air calibration (Kalibr), without the\n"
    "                        --extrinsic-drift and --lens-change\n"
    "  board.csv             with --board: frame,t,tx,ty,tz,qx,qy,qz,qw,\n"
    "                        visible_left,visible_right (cam0_from_target\n"
    "                        in rcm calibrate's target frame; 1 when the\n"
    "                        camera sees every inner corner)\n"
    "  truth.csv             frame,t,n,tx,ty,tz,qx,qy,qz,qw (world_from_cam0)\n"
    "  matches.csv           with --matches-per-frame: frame,xl,yl,xr,yr,t\n"
    "                        (points of the tank's surfaces, or with\n"
    "                        --depth-range points at sampled depths;\n"
    "                        with --exposure-delay the right pixels see\n"
    "                        the scene moved during the delay)\n"
    "  simulation.json       the settings, to reproduce the run; with\n"
    "                        --port dome its port block holds the truth:\n"
    "                        decentering_m per camera (left, right)\n"
    "With --board a diver holds a printed chessboard (the flags of rcm\n"
    "calibrate; chessboards only) in front of the rig, moving it slowly and\n"
    "keeping it in view of both cameras when possible; --board-warp\n"
    "X_MM,Y_MM bows it as a hand-held board bows (rcm calibrate estimates\n"
    "the same warp).\n"
    "truth.csv is written last; the same flags give the same bytes.";

int RunSimulate();

}  // namespace

extern const Subcommand kSimulateCommand = {
    "simulate",
    "synthetic stereo sequence through exact flat or dome ports, with "
    "ground truth",
    kSimulateUsage,
    {__FILE__, kDepthRangeFlagSource, kDomePortFlagsSource,
     kSimulationFlagsSource, kGlassIndexFlagSource, kIndexFlagSource,
     kRigFlagsSource, kTargetFlagsSource},
    RunSimulate};

namespace {

constexpr double kDegree = M_PI / 180.0;

// "--flag VALUE", the context of an error line.
std::string FlagContext(const char* flag, const std::string& value) {
  return std::string("--") + flag + " " + value;
}

// True when the flag `name` (gflags' spelling) was set on the command line.
bool FlagGiven(const char* name) {
  gflags::CommandLineFlagInfo info;
  return gflags::GetCommandLineFlagInfo(name, &info) && !info.is_default;
}

// --exposure-delay into options->exposure_delay; one line on a bad value.
Status ExposureDelayFromFlag(SequenceOptions* options) {
  if (FLAGS_exposure_delay.empty()) return Status::Ok();
  const std::string context = "--exposure-delay " + FLAGS_exposure_delay;
  const StatusOr<std::vector<double>> values =
      ParseNumberList(FLAGS_exposure_delay);
  if (!values.ok() || (values->size() != 2 && values->size() != 3)) {
    return Status::Error(context + ": expected MS,DEG_S[,M_S], e.g. 10,5,0.05");
  }
  options->exposure_delay.delay = 1e-3 * (*values)[0];
  options->exposure_delay.angular_speed_sd = (*values)[1] * kDegree;
  options->exposure_delay.speed_sd = values->size() == 3 ? (*values)[2] : 0.0;
  return options->Check().WithContext(context);
}

// --port dome and its flags into options->left_dome, right_dome; one line
// on a bad value, a flat port's flag with a dome, or
// --right-dome-decentering without --port dome.
Status DomesFromFlags(SequenceOptions* options) {
  const StatusOr<std::optional<DomePort>> dome = DomePortFromFlags();
  if (!dome.ok()) return dome.status();
  if (!dome->has_value()) {
    if (FlagGiven("right_dome_decentering")) {
      return Status::Error("--right-dome-decentering needs --port dome");
    }
    return Status::Ok();
  }
  for (const char* flag : {"air_gap", "glass_thickness", "port_tilt"}) {
    if (FlagGiven(flag)) {
      std::string name = flag;
      std::replace(name.begin(), name.end(), '_', '-');
      return Status::Error("--port dome: --" + name +
                           " describes a flat port; a dome has "
                           "--dome-inner-radius, --dome-thickness and "
                           "--dome-decentering");
    }
  }
  options->left_dome = **dome;
  options->right_dome = **dome;
  if (!FLAGS_right_dome_decentering.empty()) {
    const std::string context =
        FlagContext("right-dome-decentering", FLAGS_right_dome_decentering);
    const StatusOr<std::vector<double>> values =
        ParseNumberList(FLAGS_right_dome_decentering);
    if (!values.ok() || values->size() != 3) {
      return Status::Error(
          context + ": expected X,Y,Z in meters, e.g. -0.001,0.002,0.008");
    }
    options->right_dome->decentering =
        Eigen::Vector3d((*values)[0], (*values)[1], (*values)[2]);
    RCM_RETURN_IF_ERROR(options->right_dome->Check().WithContext(context));
  }
  return Status::Ok();
}

// The dome of both cameras for simulation.json: the glass and the truth,
// decentering_m per camera (left, right).
nlohmann::json DomesJson(const SequenceOptions& options) {
  const DomePort& left = *options.left_dome;
  nlohmann::json decentering = nlohmann::json::array();
  for (const DomePort* dome : {&left, &*options.right_dome}) {
    decentering.push_back(
        {dome->decentering.x(), dome->decentering.y(), dome->decentering.z()});
  }
  return {{"type", "dome"},
          {"inner_radius", left.inner_radius},
          {"thickness", left.thickness},
          {"outer_radius", left.outer_radius()},
          {"glass_index", left.glass_index},
          {"decentering_m", decentering}};
}

// --board and --board-distance into options->board, board_motion.
Status BoardFromFlags(SequenceOptions* options) {
  if (!TargetGiven()) {
    for (const char* flag : {"board_distance", "board_warp"}) {
      if (FlagGiven(flag)) {
        std::string name = flag;
        std::replace(name.begin(), name.end(), '_', '-');
        return Status::Error("--" + name + " needs --board chessboard");
      }
    }
    return Status::Ok();
  }
  if (!FLAGS_target.empty()) {
    return Status::Error(
        "--target: rcm simulate renders chessboards only; give --board "
        "chessboard --cols N --rows M --square S");
  }
  if (!BoardIsChessboard()) {
    return Status::Error(FlagContext("board", FLAGS_board) +
                         ": rcm simulate renders chessboards only (--board "
                         "chessboard --cols N --rows M --square S)");
  }
  const StatusOr<calib::CalibrationTarget> target = TargetFromFlags();
  if (!target.ok()) return target.status();
  SceneBoard board;
  board.cols = target->cols;
  board.rows = target->rows;
  board.square = target->col_spacing;
  RCM_RETURN_IF_ERROR(
      board.Check().WithContext(FlagContext("board", FLAGS_board)));
  if (!FLAGS_board_warp.empty()) {
    // (The board's own flags checked first: an error here is the warp's.)
    const std::string warp_context =
        FlagContext("board-warp", FLAGS_board_warp);
    const StatusOr<std::vector<double>> warp =
        ParseNumberList(FLAGS_board_warp);
    if (!warp.ok() || warp->size() != 2) {
      return Status::Error(warp_context +
                           ": expected X_MM,Y_MM in millimetres, e.g. 1,0.5");
    }
    board.warp = 1e-3 * Eigen::Vector2d((*warp)[0], (*warp)[1]);
    RCM_RETURN_IF_ERROR(board.Check().WithContext(warp_context));
  }
  options->board = board;
  const std::string context =
      FlagContext("board-distance", FLAGS_board_distance);
  const StatusOr<std::vector<double>> range =
      ParseNumberList(FLAGS_board_distance);
  if (!range.ok() || range->size() != 2) {
    return Status::Error(context + ": expected MIN,MAX in meters, e.g. 0.6,2");
  }
  options->board_motion.min_distance = (*range)[0];
  options->board_motion.max_distance = (*range)[1];
  return options->board_motion.Check().WithContext(context);
}

// Rows of a 4x4 matrix, for JSON.
nlohmann::json MatrixRows(const Eigen::Matrix4d& matrix) {
  nlohmann::json rows = nlohmann::json::array();
  for (int r = 0; r < 4; ++r) {
    rows.push_back({matrix(r, 0), matrix(r, 1), matrix(r, 2), matrix(r, 3)});
  }
  return rows;
}

// Frames in which the board is fully visible: left, right, both.
std::array<int, 3> CountVisibleBoardFrames(const SequenceSimulator& sim) {
  std::array<int, 3> counts = {0, 0, 0};
  for (const BoardFrame& frame : sim.board_frames()) {
    counts[0] += frame.fully_visible[0] ? 1 : 0;
    counts[1] += frame.fully_visible[1] ? 1 : 0;
    counts[2] += frame.fully_visible[0] && frame.fully_visible[1] ? 1 : 0;
  }
  return counts;
}

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
  if (const Status domes = DomesFromFlags(&options); !domes.ok()) {
    PrintError(command, domes.message());
    return kExitUsage;
  }
  options.render_images = FLAGS_images;
  options.matches_per_frame = FLAGS_matches_per_frame;
  options.match_noise_px = FLAGS_match_noise;
  options.outlier_fraction = FLAGS_outliers;
  if (!FLAGS_depth_range.empty()) {
    const StatusOr<std::vector<double>> range =
        ParseNumberList(FLAGS_depth_range);
    if (!range.ok() || range->size() != 2) {
      PrintError(command, "--depth-range " + FLAGS_depth_range +
                              ": expected MIN,MAX in meters, e.g. 0.6,6");
      return kExitUsage;
    }
    options.match_min_depth = (*range)[0];
    options.match_max_depth = (*range)[1];
    const Status valid = options.Check();
    if (!valid.ok()) {
      PrintError(command, "--depth-range: " + valid.message());
      return kExitUsage;
    }
  }
  if (const Status drift = ExtrinsicDriftFromFlag(&options); !drift.ok()) {
    PrintError(command, drift.message());
    return kExitUsage;
  }
  if (const Status lens = LensChangeFromFlag(&options); !lens.ok()) {
    PrintError(command, lens.message());
    return kExitUsage;
  }
  if (const Status delay = ExposureDelayFromFlag(&options); !delay.ok()) {
    PrintError(command, delay.message());
    return kExitUsage;
  }
  if (const Status board = BoardFromFlags(&options); !board.ok()) {
    PrintError(command, board.message());
    return kExitUsage;
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
  if (options.left_dome) settings["port"] = DomesJson(options);
  settings["matches_per_frame"] = FLAGS_matches_per_frame;
  settings["match_noise"] = FLAGS_match_noise;
  settings["outliers"] = FLAGS_outliers;
  settings["images"] = FLAGS_images;
  settings["depth_range"] = FLAGS_depth_range;
  settings["extrinsic_drift"] = {{"rotation_deg",
                                  {options.cam1_drift.rotation.x() / kDegree,
                                   options.cam1_drift.rotation.y() / kDegree,
                                   options.cam1_drift.rotation.z() / kDegree}},
                                 {"translation_mm",
                                  {options.cam1_drift.translation.x() * 1e3,
                                   options.cam1_drift.translation.y() * 1e3,
                                   options.cam1_drift.translation.z() * 1e3}}};
  settings["lens_change_percent"] = {
      100.0 * options.lens_change.focal_scale[0],
      100.0 * options.lens_change.focal_scale[1]};
  settings["exposure_delay"] = {
      {"delay_ms", 1e3 * options.exposure_delay.delay},
      {"angular_speed_sd_deg_s",
       options.exposure_delay.angular_speed_sd / kDegree},
      {"speed_sd_m_s", options.exposure_delay.speed_sd}};
  // The extrinsics that made the data (camchain.yaml has the calibration).
  settings["true_cam1_from_cam0"] =
      MatrixRows(simulator.value()->true_rig().right_from_left().ToMatrix());
  if (options.board) {
    const std::array<int, 3> visible =
        CountVisibleBoardFrames(*simulator.value());
    settings["board"] = {
        {"type", "chessboard"},
        {"cols", options.board->cols},
        {"rows", options.board->rows},
        {"square", options.board->square},
        {"warp_mm",
         {1e3 * options.board->warp.x(), 1e3 * options.board->warp.y()}},
        {"distance",
         {options.board_motion.min_distance,
          options.board_motion.max_distance}},
        {"fully_visible_frames",
         {{"left", visible[0]}, {"right", visible[1]}, {"both", visible[2]}}}};
  } else {
    settings["board"] = nullptr;
  }
  const Status settings_written = WriteFileAtomically(
      FLAGS_out + "/simulation.json", settings.dump(2) + "\n");
  if (!settings_written.ok()) {
    PrintError(command, settings_written.message());
    return kExitFailure;
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
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
            << "  media    " << sim.media().ToString() << "\n";
  if (options.left_dome) {
    const DomePort& dome = *options.left_dome;
    const auto millimetres = [](const Eigen::Vector3d& v) {
      return "(" + FormatFixed(1e3 * v.x(), 2) + ", " +
             FormatFixed(1e3 * v.y(), 2) + ", " + FormatFixed(1e3 * v.z(), 2) +
             ") mm";
    };
    std::cout << "  port     dome, inner radius " << dome.inner_radius
              << " m, glass " << dome.thickness << " m (index "
              << dome.glass_index << "), centred at "
              << millimetres(dome.decentering) << " (cam0), "
              << millimetres(options.right_dome->decentering)
              << " (cam1); camchain.yaml has no port block\n";
  } else {
    std::cout << "  port     air gap " << options.left_port.air_gap
              << " m, glass " << options.left_port.glass_thickness
              << " m (index " << options.left_port.glass_index << ")\n";
  }
  if (!options.cam1_drift.IsZero()) {
    std::cout << "  drift    cam1 turned "
              << FormatFixed(options.cam1_drift.rotation.norm() / kDegree, 3)
              << " deg, moved "
              << FormatFixed(options.cam1_drift.translation.norm() * 1e3, 2)
              << " mm since the calibration in camchain.yaml\n";
  }
  if (!options.lens_change.IsZero()) {
    std::cout << "  lenses   focal lengths changed by "
              << FormatFixed(100.0 * options.lens_change.focal_scale[0], 2)
              << " % (cam0), "
              << FormatFixed(100.0 * options.lens_change.focal_scale[1], 2)
              << " % (cam1) since the calibration in camchain.yaml\n";
  }
  if (!options.exposure_delay.IsZero()) {
    std::cout << "  delay    cam1 exposes "
              << FormatFixed(1e3 * options.exposure_delay.delay, 1)
              << " ms after cam0, the rig turning at "
              << FormatFixed(options.exposure_delay.angular_speed_sd / kDegree,
                             1)
              << " deg/s and moving at "
              << FormatFixed(options.exposure_delay.speed_sd, 3)
              << " m/s per axis (sd, per frame)\n";
  }
  if (options.board) {
    const std::array<int, 3> visible = CountVisibleBoardFrames(sim);
    std::cout << "  board    chessboard " << options.board->cols << "x"
              << options.board->rows << " inner corners, "
              << FormatFixed(options.board->square * 1e3, 1) << " mm squares, "
              << options.board_motion.min_distance << "-"
              << options.board_motion.max_distance
              << " m away; every corner in both images in " << visible[2]
              << " of " << sim.num_frames() << " frames\n";
  }
  std::cout << "  files    " << (options.render_images ? "left/ right/ " : "")
            << (options.matches_per_frame > 0 ? "matches.csv " : "")
            << "camchain.yaml " << (options.board ? "board.csv " : "")
            << "truth.csv simulation.json" << std::endl;
  return kExitOk;
}

}  // namespace
}  // namespace rcm::cli
