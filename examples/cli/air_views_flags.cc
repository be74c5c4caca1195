#include "air_views_flags.h"

#include <memory>
#include <utility>

#include "calibration_input.h"
#include "calibration_run.h"
#include "rcm/io/stereo_image_folders.h"

DEFINE_string(air_left, "",
              "with --underwater: the left camera's images of the target in "
              "air (a folder; with --air-corners, the file's rows as a "
              "folder or a pattern with one '*'), so that one bundle "
              "adjustment estimates the lenses from air and water together");
DEFINE_string(air_right, "",
              "with --underwater: the right camera's images of the target in "
              "air (see --air-left)");
DEFINE_string(air_corners, "",
              "with --underwater: the air views' corners (mrcal's "
              "corners.vnl), their rows named by --air-left/--air-right");
DEFINE_string(air_target, "",
              "with air views: the board shown in air, a Kalibr target YAML "
              "(default: the water board of --board/--target)");
DEFINE_bool(same_board, false,
            "with air views: air and water show one board, so one warp "
            "(its bow) for both media");

namespace rcm::cli {

extern const char kAirViewsFlagsSource[] = __FILE__;

bool AirViewsGiven() {
  return !FLAGS_air_left.empty() || !FLAGS_air_right.empty() ||
         !FLAGS_air_corners.empty();
}

StatusOr<AirViewsInput> ReadAirViews(
    const calib::CalibrationTarget& water_target, bool estimate_board_warp,
    bool allow_left_only) {
  if (!AirViewsGiven()) {
    if (FLAGS_same_board || !FLAGS_air_target.empty()) {
      return Status::Error(
          std::string(FLAGS_same_board ? "--same-board" : "--air-target") +
          " goes with air views: --air-left DIR --air-right DIR, or "
          "--air-corners FILE");
    }
    return Status::Error("no air views");
  }
  const bool left_only =
      allow_left_only && !FLAGS_air_left.empty() && FLAGS_air_right.empty();
  if (!left_only && (FLAGS_air_left.empty() || FLAGS_air_right.empty())) {
    return Status::Error(
        "--air-left and --air-right go together: give both cameras' air "
        "images");
  }
  AirViewsInput input;
  calib::AirTargetViews& air = input.views;
  air.target = water_target;
  if (!FLAGS_air_target.empty()) {
    StatusOr<calib::CalibrationTarget> target =
        calib::ReadCalibrationTarget(FLAGS_air_target);
    if (!target.ok()) return target.status().WithContext("--air-target");
    air.target = *target;
  }
  air.same_board = FLAGS_same_board;
  air.estimate_board_warp = estimate_board_warp;
  if (air.same_board && !calib::SameTarget(air.target, water_target)) {
    return Status::Error("--same-board: the air board (" +
                         calib::DescribeTarget(air.target) +
                         ", --air-target) is not the water board (" +
                         calib::DescribeTarget(water_target) + ")");
  }
  Detections detections;
  if (!FLAGS_air_corners.empty()) {
    // (The air images are the same cameras': --image-size serves both.)
    CornersSource source{FLAGS_air_corners,
                         FLAGS_air_left,
                         FLAGS_air_right,
                         FLAGS_image_size,
                         {}};
    source.flags = {"--air-corners", "--air-left", "--air-right"};
    StatusOr<CalibrationInput> read =
        ReadCornersInput(air.target, left_only, source);
    if (!read.ok()) return read.status();
    detections = std::move(read->detections);
    input.description = "air " + read->description;
  } else {
    StereoFolderOptions options;
    options.left_only = left_only;
    options.left_dir = FLAGS_air_left;
    options.right_dir = FLAGS_air_right;
    StatusOr<std::unique_ptr<StereoImageSource>> source =
        OpenStereoImageFolders(options);
    if (!source.ok()) return source.status().WithContext("air views");
    if ((*source)->NumPairs() == 0) {
      return Status::Error("air views: " + (*source)->Describe() +
                           ": no image pairs");
    }
    input.description = "air " + (*source)->Describe();
    StatusOr<Detections> detected = DetectTargets(source->get(), air.target);
    if (!detected.ok()) return detected.status().WithContext("air views");
    detections = *std::move(detected);
  }
  if (detections.stereo + detections.left_only + detections.right_only == 0) {
    return Status::Error(input.description +
                         ": the target is found in no air image");
  }
  for (const std::string& warning : detections.warnings) {
    input.warnings.push_back("air views: " + warning);
  }
  air.views = std::move(detections.views);
  air.cam0_size = detections.sizes[0].value_or(calib::ImageSize{0, 0});
  air.cam1_size = detections.sizes[1].value_or(calib::ImageSize{0, 0});
  return input;
}

}  // namespace rcm::cli
