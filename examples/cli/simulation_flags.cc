#include "simulation_flags.h"

#include <cmath>
#include <sstream>

#include "index_flag.h"
#include "number_list_flag.h"
#include "rcm/io/stereo_rig_file.h"
#include "rcm/sim/media_schedule.h"
#include "rcm/sim/reference_rigs.h"

DEFINE_string(media, "",
              "media per frame, MEDIUM:FRAMES,... with MEDIUM air, water (= "
              "--n) or an index, e.g. water:30,air:30,water:30 (default: "
              "water for --frames frames)");
DEFINE_int32(frames, 20, "frames to simulate when --media is not set");
DEFINE_double(frame_rate, 20.0,
              "frames per second (the dataset's 20 Hz); the robot flies at "
              "0.3 m/s and a hand-held board moves over seconds, so a lower "
              "rate spreads few frames over more views (1: twenty views of "
              "a board in twenty frames)");
DEFINE_string(rig, "alphasense",
              "built-in rig when --calib is not given: alphasense (the "
              "dataset rig of docs/design.md Sec. 6 on rectified extrinsics), "
              "alphasense-unrectified (0.5 deg rotation, baseline off axis) "
              "or narrow (a hand-built housing: 640x480 radtan, f 500 px, "
              "65 mm baseline, 2.5 deg toe-in)");
DEFINE_double(air_gap, 0.0,
              "port: air between the camera center and the glass, meters "
              "(0 = the paper's thin port)");
DEFINE_double(glass_thickness, 0.0, "port: glass thickness, meters");
DEFINE_double(port_tilt, 0.0,
              "port: tilt of the glass normal from the optical axis "
              "(pitch), degrees");
DEFINE_double(image_noise, 1.5,
              "sensor read noise, standard deviation in 8-bit levels");
DEFINE_int32(supersampling, 2,
             "rays per pixel along each axis (anti-aliasing), 1-4");
DEFINE_uint64(seed, 1, "random seed; the outputs depend only on the flags");
DEFINE_string(tank, "12,8,3",
              "LENGTH,WIDTH,DEPTH of the pool, meters; the robot circles "
              "it 1.6 m from the walls (a 5,5,3 pool: a 5.7 m lap)");
DEFINE_int32(loops, 0,
             "0: the robot flies on at 0.3 m/s; K >= 1: the frames fly "
             "exactly K laps, the last frame where the first was (a loop "
             "dive: an odometry's loop-closure gap is its drift)");
DEFINE_string(extrinsic_drift, "",
              "RX,RY,RZ[,TX,TY,TZ]: cam1 has moved since the air "
              "calibration by this rotation (angle-axis, degrees, cam1 "
              "frame) and change of cam1_from_cam0's translation (mm): the "
              "images and matches are those of the moved rig, the "
              "calibration stays as it was (StereoRig::WithCam1Moved)");

DEFINE_string(lens_change, "",
              "PCT0[,PCT1]: each camera's focal lengths have changed by this "
              "many percent since the air calibration (one value: both "
              "cameras): the images and matches are those of the changed "
              "lenses, the calibration stays as it was");

namespace rcm::cli {

extern const char kSimulationFlagsSource[] = __FILE__;

namespace {

constexpr double kRadiansPerDegree = M_PI / 180.0;

}  // namespace

Status ExtrinsicDriftFromFlag(SequenceOptions* options) {
  if (FLAGS_extrinsic_drift.empty()) return Status::Ok();
  const std::string context = "--extrinsic-drift " + FLAGS_extrinsic_drift;
  const StatusOr<std::vector<double>> values =
      ParseNumberList(FLAGS_extrinsic_drift);
  if (!values.ok() || (values->size() != 3 && values->size() != 6)) {
    return Status::Error(context +
                         ": expected RX,RY,RZ[,TX,TY,TZ] (degrees, "
                         "millimetres), e.g. 0.5,0,0");
  }
  const std::vector<double>& v = values.value();
  options->cam1_drift.rotation =
      Eigen::Vector3d(v[0], v[1], v[2]) * kRadiansPerDegree;
  if (v.size() == 6) {
    options->cam1_drift.translation = Eigen::Vector3d(v[3], v[4], v[5]) * 1e-3;
  }
  return options->cam1_drift.Check().WithContext(context);
}

Status LensChangeFromFlag(SequenceOptions* options) {
  if (FLAGS_lens_change.empty()) return Status::Ok();
  const std::string context = "--lens-change " + FLAGS_lens_change;
  const StatusOr<std::vector<double>> values =
      ParseNumberList(FLAGS_lens_change);
  if (!values.ok() || (values->size() != 1 && values->size() != 2)) {
    return Status::Error(context +
                         ": expected PCT0[,PCT1] (percent), e.g. 0.5,-0.3");
  }
  const std::vector<double>& v = values.value();
  options->lens_change.focal_scale = {0.01 * v[0],
                                      0.01 * v[v.size() == 2 ? 1 : 0]};
  return options->lens_change.Check().WithContext(context);
}

StatusOr<Simulation> SimulationFromFlags(const std::string& calib,
                                         const std::string& left,
                                         const std::string& right) {
  Simulation simulation{AlphasenseFrontRectifiedRig(), "alphasense", {}};
  if (!calib.empty()) {
    StatusOr<StereoRig> rig = ReadStereoRig(calib, left, right);
    if (!rig.ok()) return rig.status();
    simulation.rig = rig.value();
    simulation.rig_name = calib;
  } else if (FLAGS_rig == "alphasense-unrectified" ||
             FLAGS_rig == "alphasense_unrectified") {
    simulation.rig = AlphasenseFrontUnrectifiedRig();
    simulation.rig_name = "alphasense-unrectified";
  } else if (FLAGS_rig == "narrow") {
    simulation.rig = NarrowFieldRig();
    simulation.rig_name = "narrow";
  } else if (FLAGS_rig != "alphasense") {
    return Status::Error("--rig " + FLAGS_rig +
                         ": expected alphasense, alphasense-unrectified or "
                         "narrow");
  }

  StatusOr<double> n = RefractiveIndexFromFlag(/*required=*/false);
  if (!n.ok()) return n.status();
  StatusOr<MediaSchedule> media =
      FLAGS_media.empty() ? MediaSchedule::Constant(FLAGS_n, FLAGS_frames)
                          : MediaSchedule::Parse(FLAGS_media, FLAGS_n);
  if (!media.ok()) {
    return media.status().WithContext(FLAGS_media.empty() ? "--frames"
                                                          : "--media");
  }
  SequenceOptions& options = simulation.options;
  options.media = media.value().segments();
  FlatPort port;
  port.air_gap = FLAGS_air_gap;
  port.glass_thickness = FLAGS_glass_thickness;
  port.glass_index = FLAGS_glass_index;
  port.normal = TiltedPortNormal(FLAGS_port_tilt * M_PI / 180.0, 0.0);
  RCM_RETURN_IF_ERROR(port.Check());
  options.left_port = port;
  options.right_port = port;
  if (!std::isfinite(FLAGS_image_noise) || FLAGS_image_noise < 0.0) {
    return Status::Error("--image-noise must be >= 0");
  }
  if (FLAGS_supersampling < 1 || FLAGS_supersampling > 4) {
    return Status::Error("--supersampling must be in [1, 4]");
  }
  if (!(FLAGS_frame_rate >= 0.1 && FLAGS_frame_rate <= 1000.0)) {
    return Status::Error("--frame-rate must be in [0.1, 1000] Hz");
  }
  options.trajectory.frame_rate = FLAGS_frame_rate;
  {
    const StatusOr<std::vector<double>> tank = ParseNumberList(FLAGS_tank);
    if (!tank.ok() || tank->size() != 3) {
      return Status::Error("--tank " + FLAGS_tank +
                           ": expected LENGTH,WIDTH,DEPTH (meters), e.g. "
                           "5,5,3");
    }
    options.scene.length = (*tank)[0];
    options.scene.width = (*tank)[1];
    options.scene.depth = (*tank)[2];
    RCM_RETURN_IF_ERROR(options.scene.Check().WithContext("--tank"));
  }
  options.trajectory.loops = FLAGS_loops;
  RCM_RETURN_IF_ERROR(options.trajectory.Check().WithContext("--loops"));
  options.render.read_noise = FLAGS_image_noise;
  options.render.supersampling = FLAGS_supersampling;
  options.seed = FLAGS_seed;
  RCM_RETURN_IF_ERROR(options.Check());
  return simulation;
}

nlohmann::json SimulationFlagsJson(const Simulation& simulation) {
  const SequenceOptions& options = simulation.options;
  nlohmann::json media = nlohmann::json::array();
  for (const MediaSegment& segment : options.media) {
    media.push_back({{"n", segment.n}, {"frames", segment.frames}});
  }
  const FlatPort& port = options.left_port;
  return {{"rig", simulation.rig_name},
          {"media", media},
          {"port",
           {{"air_gap", port.air_gap},
            {"glass_thickness", port.glass_thickness},
            {"glass_index", port.glass_index},
            {"normal", {port.normal.x(), port.normal.y(), port.normal.z()}}}},
          // The pool, world frame of truth.csv: [0, length] x [0, width] x
          // [0, depth] meters (TankScene), for checks of depth against it.
          {"tank",
           {{"length", options.scene.length},
            {"width", options.scene.width},
            {"depth", options.scene.depth}}},
          {"frame_rate", options.trajectory.frame_rate},
          {"loops", options.trajectory.loops},
          {"image_noise", FLAGS_image_noise},
          {"supersampling", FLAGS_supersampling},
          {"seed", options.seed}};
}

}  // namespace rcm::cli
