#include "target_flags.h"

#include <string>

DEFINE_string(target, "",
              "Kalibr target YAML (checkerboard, aprilgrid; or charuco, see "
              "docs/calibrate.md); instead of --board and its flags");
DEFINE_string(board, "",
              "target type: chessboard (= checkerboard), aprilgrid, charuco");
DEFINE_int32(cols, 0,
             "chessboard: inner corners along a row; aprilgrid: tags along "
             "x; charuco: squares along x");
DEFINE_int32(rows, 0,
             "chessboard: inner corners along a column; aprilgrid: tags "
             "along y; charuco: squares along y");
DEFINE_double(square, 0.0, "chessboard, charuco: square size in metres");
DEFINE_double(tag_size, 0.0,
              "aprilgrid: tag edge in metres, black border included");
DEFINE_double(tag_spacing, 0.3,
              "aprilgrid: gap between tags as a fraction of --tag-size");
DEFINE_double(marker, 0.0, "charuco: marker edge in metres");
DEFINE_string(dictionary, "DICT_6X6_250", "charuco: OpenCV aruco dictionary");

namespace rcm::cli {

extern const char kTargetFlagsSource[] = __FILE__;

bool TargetGiven() { return !FLAGS_target.empty() || !FLAGS_board.empty(); }

bool BoardIsChessboard() {
  return FLAGS_board == "chessboard" || FLAGS_board == "checkerboard";
}

StatusOr<calib::CalibrationTarget> TargetFromFlags() {
  if (!FLAGS_target.empty()) {
    if (!FLAGS_board.empty()) {
      return Status::Error("give either --target or --board, not both");
    }
    return calib::ReadCalibrationTarget(FLAGS_target);
  }
  if (FLAGS_board.empty()) {
    return Status::Error(
        "no target: give --board chessboard|aprilgrid|charuco with its "
        "sizes, or --target FILE.yaml");
  }
  auto make = [] {
    if (BoardIsChessboard()) {
      return calib::MakeCheckerboardTarget(FLAGS_cols, FLAGS_rows,
                                           FLAGS_square);
    }
    if (FLAGS_board == "aprilgrid") {
      return calib::MakeAprilGridTarget(FLAGS_cols, FLAGS_rows, FLAGS_tag_size,
                                        FLAGS_tag_spacing);
    }
    return calib::MakeCharucoTarget(FLAGS_cols, FLAGS_rows, FLAGS_square,
                                    FLAGS_marker, FLAGS_dictionary);
  };
  if (!BoardIsChessboard() && FLAGS_board != "aprilgrid" &&
      FLAGS_board != "charuco") {
    return Status::Error("unknown --board '" + FLAGS_board +
                         "' (available: chessboard, aprilgrid, charuco)");
  }
  StatusOr<calib::CalibrationTarget> target = make();
  if (!target.ok()) {
    return target.status().WithContext("--board " + FLAGS_board);
  }
  return target;
}

}  // namespace rcm::cli
