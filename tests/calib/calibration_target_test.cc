#include "rcm/calib/calibration_target.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <opencv2/aruco/charuco.hpp>
#include <string>
#include <vector>

#include "support/temp_file.h"

namespace rcm::calib::calibration_target_test {
namespace {

constexpr double kExact = 1e-15;

// Kalibr's templates (Kalibr wiki, "Calibration targets"), comments kept.
constexpr char kKalibrCheckerboard[] =
    "target_type: 'checkerboard' #gridtype\n"
    "targetCols: 6               #number of internal chessboard corners\n"
    "targetRows: 7               #number of internal chessboard corners\n"
    "rowSpacingMeters: 0.06      #size of one chessboard square [m]\n"
    "colSpacingMeters: 0.05      #size of one chessboard square [m]\n";

constexpr char kKalibrAprilGrid[] =
    "target_type: 'aprilgrid' #gridtype\n"
    "tagCols: 6               #number of apriltags\n"
    "tagRows: 4               #number of apriltags\n"
    "tagSize: 0.088           #size of apriltag, edge to edge [m]\n"
    "tagSpacing: 0.3          #ratio of space between tags to tagSize\n";

CalibrationTarget ParseOrDie(const std::string& text) {
  const StatusOr<CalibrationTarget> target =
      ParseCalibrationTarget(text, "t.yaml");
  CHECK(target.ok()) << target.status().message();
  return *target;
}

std::string ErrorOf(const std::string& text) {
  const StatusOr<CalibrationTarget> target =
      ParseCalibrationTarget(text, "t.yaml");
  if (target.ok()) return "(parsed fine)";
  return target.status().message();
}

void ExpectPointNear(const Eigen::Vector3d& actual,
                     const Eigen::Vector3d& expected) {
  EXPECT_NEAR(actual.x(), expected.x(), kExact);
  EXPECT_NEAR(actual.y(), expected.y(), kExact);
  EXPECT_EQ(actual.z(), 0.0);
}

TEST(CalibrationTarget, ParsesKalibrCheckerboard) {
  const StatusOr<CalibrationTarget> target =
      ParseCalibrationTarget(kKalibrCheckerboard, "t.yaml");
  ASSERT_TRUE(target.ok()) << target.status().message();
  EXPECT_EQ(target->type, TargetType::kCheckerboard);
  EXPECT_EQ(target->cols, 6);
  EXPECT_EQ(target->rows, 7);
  EXPECT_EQ(target->row_spacing, 0.06);
  EXPECT_EQ(target->col_spacing, 0.05);
  EXPECT_EQ(target->tag_size, 0.0);
  EXPECT_EQ(target->tag_spacing, 0.0);
}

TEST(CalibrationTarget, ParsesKalibrAprilGrid) {
  const StatusOr<CalibrationTarget> target =
      ParseCalibrationTarget(kKalibrAprilGrid, "t.yaml");
  ASSERT_TRUE(target.ok()) << target.status().message();
  EXPECT_EQ(target->type, TargetType::kAprilGrid);
  EXPECT_EQ(target->cols, 6);
  EXPECT_EQ(target->rows, 4);
  EXPECT_EQ(target->tag_size, 0.088);
  EXPECT_EQ(target->tag_spacing, 0.3);
  EXPECT_EQ(target->row_spacing, 0.0);
  EXPECT_EQ(target->col_spacing, 0.0);
}

TEST(CalibrationTarget, ParsesUnquotedTypeAndIgnoresUnknownKeys) {
  const StatusOr<CalibrationTarget> target = ParseCalibrationTarget(
      "target_type: aprilgrid\ntagCols: 2\ntagRows: 3\ntagSize: 0.1\n"
      "tagSpacing: 0.25\nprinted_by: lab printer\n",
      "t.yaml");
  ASSERT_TRUE(target.ok()) << target.status().message();
  EXPECT_EQ(target->type, TargetType::kAprilGrid);
  EXPECT_EQ(target->cols, 2);
  EXPECT_EQ(target->rows, 3);
}

TEST(CalibrationTarget, ReadsFile) {
  const std::string path =
      rcm::test::WriteTempFile("aprilgrid.yaml", kKalibrAprilGrid);
  const StatusOr<CalibrationTarget> target = ReadCalibrationTarget(path);
  std::remove(path.c_str());
  ASSERT_TRUE(target.ok()) << target.status().message();
  EXPECT_EQ(target->type, TargetType::kAprilGrid);
  EXPECT_EQ(NumTargetPoints(*target), 96);
}

TEST(CalibrationTarget, ReadMissingFileReportsPath) {
  const std::string path = rcm::test::TempFilePath("missing.yaml");
  const StatusOr<CalibrationTarget> target = ReadCalibrationTarget(path);
  ASSERT_FALSE(target.ok());
  EXPECT_EQ(target.status().message().rfind(path + ": cannot open: ", 0), 0u)
      << target.status().message();
}

TEST(CalibrationTarget, CheckerboardPointCount) {
  const CalibrationTarget target = ParseOrDie(kKalibrCheckerboard);
  EXPECT_EQ(NumTargetPoints(target), 42);
  EXPECT_EQ(TargetPoints(target).size(), 42u);
}

TEST(CalibrationTarget, CheckerboardIsRowMajorWithXAlongColumns) {
  const CalibrationTarget target = ParseOrDie(kKalibrCheckerboard);
  const std::vector<Eigen::Vector3d> points = TargetPoints(target);
  ASSERT_EQ(points.size(), 42u);
  EXPECT_EQ(points[0], Eigen::Vector3d::Zero());
  ExpectPointNear(points[1], {0.05, 0.0, 0.0});
  ExpectPointNear(points[6], {0.0, 0.06, 0.0});
  ExpectPointNear(points[41], {5 * 0.05, 6 * 0.06, 0.0});
}

TEST(CalibrationTarget, CheckerboardNeighbourDistancesAreTheSpacings) {
  const CalibrationTarget target = ParseOrDie(kKalibrCheckerboard);
  const std::vector<Eigen::Vector3d> points = TargetPoints(target);
  ASSERT_EQ(points.size(), 42u);
  for (int r = 0; r < target.rows; ++r) {
    for (int c = 0; c < target.cols; ++c) {
      const Eigen::Vector3d& point = points[r * target.cols + c];
      if (c + 1 < target.cols) {
        ExpectPointNear(points[r * target.cols + c + 1] - point,
                        {target.col_spacing, 0.0, 0.0});
      }
      if (r + 1 < target.rows) {
        ExpectPointNear(points[(r + 1) * target.cols + c] - point,
                        {0.0, target.row_spacing, 0.0});
      }
    }
  }
}

TEST(CalibrationTarget, AprilGridPointCount) {
  const CalibrationTarget target = ParseOrDie(kKalibrAprilGrid);
  EXPECT_EQ(NumTargetPoints(target), 4 * 6 * 4);
  EXPECT_EQ(TargetPoints(target).size(), 96u);
}

TEST(CalibrationTarget, AprilGridTagZeroCornerOrder) {
  const CalibrationTarget target = ParseOrDie(kKalibrAprilGrid);
  const std::vector<Eigen::Vector3d> points = TargetPoints(target);
  ASSERT_EQ(points.size(), 96u);
  const double s = 0.088;
  EXPECT_EQ(points[0], Eigen::Vector3d::Zero());
  ExpectPointNear(points[1], {s, 0.0, 0.0});
  ExpectPointNear(points[2], {s, s, 0.0});
  ExpectPointNear(points[3], {0.0, s, 0.0});
}

TEST(CalibrationTarget, AprilGridLastTagCornerOrder) {
  const CalibrationTarget target = ParseOrDie(kKalibrAprilGrid);
  const std::vector<Eigen::Vector3d> points = TargetPoints(target);
  ASSERT_EQ(points.size(), 96u);
  // Tag 23 is in column i = 5 and row j = 3 of the 6 x 4 grid.
  const double s = 0.088;
  const double pitch = 0.088 * 1.3;
  const double x = 5 * pitch;
  const double y = 3 * pitch;
  ExpectPointNear(points[92], {x, y, 0.0});
  ExpectPointNear(points[93], {x + s, y, 0.0});
  ExpectPointNear(points[94], {x + s, y + s, 0.0});
  ExpectPointNear(points[95], {x, y + s, 0.0});
}

TEST(CalibrationTarget, AprilGridTagIdsRunAlongColumnsFirst) {
  const CalibrationTarget target = ParseOrDie(kKalibrAprilGrid);
  const std::vector<Eigen::Vector3d> points = TargetPoints(target);
  ASSERT_EQ(points.size(), 96u);
  const double pitch = 0.088 * 1.3;
  ExpectPointNear(points[4 * 1], {pitch, 0.0, 0.0});  // tag 1: i = 1, j = 0
  ExpectPointNear(points[4 * 6], {0.0, pitch, 0.0});  // tag 6: i = 0, j = 1
}

TEST(CalibrationTarget, AprilGridGapBetweenTagsIsSpacingTimesSize) {
  const CalibrationTarget target = ParseOrDie(kKalibrAprilGrid);
  const std::vector<Eigen::Vector3d> points = TargetPoints(target);
  ASSERT_EQ(points.size(), 96u);
  const double gap = 0.3 * 0.088;
  for (int j = 0; j < target.rows; ++j) {
    for (int i = 0; i + 1 < target.cols; ++i) {
      const int id = j * target.cols + i;
      // Corner 1 (lower right) of a tag to corner 0 (lower left) of the
      // next tag along x.
      ExpectPointNear(points[4 * (id + 1)] - points[4 * id + 1],
                      {gap, 0.0, 0.0});
    }
  }
  for (int j = 0; j + 1 < target.rows; ++j) {
    for (int i = 0; i < target.cols; ++i) {
      const int id = j * target.cols + i;
      // Corner 3 (upper left) of a tag to corner 0 of the tag above it.
      ExpectPointNear(points[4 * (id + target.cols)] - points[4 * id + 3],
                      {0.0, gap, 0.0});
    }
  }
}

TEST(CalibrationTargetDeathTest, TargetPointsRejectsInvalidTarget) {
  CalibrationTarget target;
  target.type = TargetType::kCheckerboard;
  target.cols = 0;
  target.rows = 5;
  target.row_spacing = 0.1;
  target.col_spacing = 0.1;
  EXPECT_DEATH(TargetPoints(target), "invalid target size 0 x 5");
}

TEST(CalibrationTarget, ErrorMissingKey) {
  EXPECT_EQ(ErrorOf("target_type: 'aprilgrid'\ntagCols: 6\ntagRows: 6\n"
                    "tagSpacing: 0.3\n"),
            "t.yaml: missing key 'tagSize' (an aprilgrid needs tagCols, "
            "tagRows, tagSize, tagSpacing)");
}

TEST(CalibrationTarget, ErrorMissingTargetType) {
  EXPECT_EQ(ErrorOf("targetCols: 6\ntargetRows: 7\n"),
            "t.yaml: missing key 'target_type' (supported: checkerboard, "
            "aprilgrid, charuco)");
}

TEST(CalibrationTarget, ErrorUnknownType) {
  EXPECT_EQ(ErrorOf("\ntarget_type: 'circlegrid'\n"),
            "t.yaml:2: unknown target_type 'circlegrid' (supported: "
            "checkerboard, aprilgrid, charuco)");
}

TEST(CalibrationTarget, ErrorZeroTagCount) {
  EXPECT_EQ(ErrorOf("target_type: 'aprilgrid'\ntagCols: 0\ntagRows: 6\n"
                    "tagSize: 0.088\ntagSpacing: 0.3\n"),
            "t.yaml:2: tagCols: must be between 1 and 1000 tags, got 0");
}

TEST(CalibrationTarget, ErrorCheckerboardNeedsTwoInnerCorners) {
  EXPECT_EQ(ErrorOf("target_type: 'checkerboard'\ntargetCols: 6\n"
                    "targetRows: 1\nrowSpacingMeters: 0.06\n"
                    "colSpacingMeters: 0.06\n"),
            "t.yaml:3: targetRows: must be between 2 and 1000 inner corners, "
            "got 1");
}

TEST(CalibrationTarget, ErrorNegativeCount) {
  EXPECT_EQ(ErrorOf("target_type: 'checkerboard'\ntargetCols: -6\n"
                    "targetRows: 7\nrowSpacingMeters: 0.06\n"
                    "colSpacingMeters: 0.06\n"),
            "t.yaml:2: targetCols: must be between 2 and 1000 inner corners, "
            "got -6");
}

TEST(CalibrationTarget, ErrorHugeCount) {
  EXPECT_EQ(ErrorOf("target_type: 'aprilgrid'\ntagCols: 6\n"
                    "tagRows: 99999999999999999999999\ntagSize: 0.088\n"
                    "tagSpacing: 0.3\n"),
            "t.yaml:3: tagRows: '99999999999999999999999' is not an integer");
}

TEST(CalibrationTarget, ErrorCountNotInteger) {
  EXPECT_EQ(ErrorOf("target_type: 'checkerboard'\ntargetCols: 6.5\n"
                    "targetRows: 7\nrowSpacingMeters: 0.06\n"
                    "colSpacingMeters: 0.06\n"),
            "t.yaml:2: targetCols: '6.5' is not an integer");
}

TEST(CalibrationTarget, ErrorNegativeSize) {
  EXPECT_EQ(ErrorOf("target_type: 'aprilgrid'\ntagCols: 6\ntagRows: 6\n"
                    "tagSize: -0.088\ntagSpacing: 0.3\n"),
            "t.yaml:4: tagSize: must be positive and finite, got -0.088");
}

TEST(CalibrationTarget, ErrorZeroSpacing) {
  EXPECT_EQ(ErrorOf("target_type: 'aprilgrid'\ntagCols: 6\ntagRows: 6\n"
                    "tagSize: 0.088\ntagSpacing: 0\n"),
            "t.yaml:5: tagSpacing: must be positive and finite, got 0");
}

TEST(CalibrationTarget, ErrorInfiniteSize) {
  EXPECT_EQ(ErrorOf("target_type: 'checkerboard'\ntargetCols: 6\n"
                    "targetRows: 7\nrowSpacingMeters: inf\n"
                    "colSpacingMeters: 0.06\n"),
            "t.yaml:4: rowSpacingMeters: must be positive and finite, got inf");
}

TEST(CalibrationTarget, ErrorSizeNotANumber) {
  EXPECT_EQ(ErrorOf("target_type: 'checkerboard'\ntargetCols: 6\n"
                    "targetRows: 7\nrowSpacingMeters: 0.06\n"
                    "colSpacingMeters: 6cm\n"),
            "t.yaml:5: colSpacingMeters: '6cm' is not a number");
}

TEST(CalibrationTarget, ErrorValueIsAList) {
  EXPECT_EQ(ErrorOf("target_type: 'aprilgrid'\ntagCols: [6, 7]\n"
                    "tagRows: 6\ntagSize: 0.088\ntagSpacing: 0.3\n"),
            "t.yaml:2: tagCols: expected a number, got a list");
}

TEST(CalibrationTarget, ErrorValueIsMissing) {
  EXPECT_EQ(ErrorOf("target_type: 'aprilgrid'\ntagCols: 6\ntagRows: 6\n"
                    "tagSize:\ntagSpacing: 0.3\n"),
            "t.yaml:4: tagSize: expected a number, got nothing");
}

TEST(CalibrationTarget, ErrorSyntax) {
  EXPECT_EQ(ErrorOf("target_type: 'aprilgrid'\ntagCols: [6\ntagRows: 6\n"),
            "t.yaml:3: invalid YAML: end of sequence flow not found");
}

TEST(CalibrationTarget, ErrorEmptyFile) {
  EXPECT_EQ(ErrorOf("# nothing here\n"),
            "t.yaml: empty file (expected a Kalibr target YAML map)");
}

TEST(CalibrationTarget, ErrorTargetTypeWithoutValue) {
  EXPECT_EQ(ErrorOf("target_type:\ntagCols: 6\n"),
            "t.yaml:1: target_type: expected a name, got nothing (supported: "
            "checkerboard, aprilgrid, charuco)");
}

TEST(CalibrationTarget, ErrorDuplicateKey) {
  // PyYAML (Kalibr) would silently take the last value; rcm refuses to
  // guess.
  EXPECT_EQ(ErrorOf("target_type: 'aprilgrid'\ntagCols: 6\ntagRows: 6\n"
                    "tagSize: 0.088\ntagSpacing: 0.3\ntagCols: 7\n"),
            "t.yaml:6: duplicate key 'tagCols'");
}

TEST(CalibrationTarget, ErrorStaysOnOneLine) {
  EXPECT_EQ(ErrorOf("target_type: \"april\\ngrid\"\n"),
            "t.yaml:1: unknown target_type 'april\\x0agrid' (supported: "
            "checkerboard, aprilgrid, charuco)");
}

constexpr char kCharuco[] =
    "target_type: 'charuco'\n"
    "squaresX: 5\n"
    "squaresY: 7\n"
    "squareSize: 0.04\n"
    "markerSize: 0.03\n"
    "dictionary: 'DICT_4X4_50'\n";

TEST(CalibrationTarget, ParsesCharuco) {
  const StatusOr<CalibrationTarget> target =
      ParseCalibrationTarget(kCharuco, "t.yaml");
  ASSERT_TRUE(target.ok()) << target.status().message();
  EXPECT_EQ(target->type, TargetType::kCharuco);
  EXPECT_EQ(target->cols, 5);
  EXPECT_EQ(target->rows, 7);
  EXPECT_EQ(target->square_size, 0.04);
  EXPECT_EQ(target->marker_size, 0.03);
  EXPECT_EQ(target->dictionary, "DICT_4X4_50");
  EXPECT_EQ(target->tag_size, 0.0);
  EXPECT_EQ(target->col_spacing, 0.0);
  EXPECT_EQ(NumTargetPoints(*target), 4 * 6);
  EXPECT_EQ(NumCharucoMarkers(*target), 17);
}

TEST(CalibrationTarget, CharucoDefaultDictionary) {
  const CalibrationTarget target = ParseOrDie(
      "target_type: charuco\nsquaresX: 3\nsquaresY: 2\nsquareSize: 0.1\n"
      "markerSize: 0.07\n");
  EXPECT_EQ(target.dictionary, "DICT_6X6_250");
}

TEST(CalibrationTarget, CharucoPointsAreOpenCvsChessboardCorners) {
  const CalibrationTarget target = ParseOrDie(kCharuco);
  const std::vector<Eigen::Vector3d> points = TargetPoints(target);
  const cv::Ptr<cv::aruco::CharucoBoard> board =
      cv::aruco::CharucoBoard::create(
          5, 7, 0.04f, 0.03f,
          cv::aruco::getPredefinedDictionary(cv::aruco::DICT_4X4_50));
  ASSERT_EQ(points.size(), board->chessboardCorners.size());
  for (size_t k = 0; k < points.size(); ++k) {
    // OpenCV keeps float coordinates.
    constexpr double kToleranceFloat = 1e-7;
    EXPECT_NEAR(points[k].x(), board->chessboardCorners[k].x, kToleranceFloat);
    EXPECT_NEAR(points[k].y(), board->chessboardCorners[k].y, kToleranceFloat);
    EXPECT_EQ(points[k].z(), 0.0);
  }
  // Corner (r, c) is id r * (squaresX - 1) + c at ((c + 1) s, (r + 1) s).
  ExpectPointNear(points[0], {0.04, 0.04, 0.0});
  ExpectPointNear(points[1], {0.08, 0.04, 0.0});
  ExpectPointNear(points[4], {0.04, 0.08, 0.0});
}

TEST(CalibrationTarget, ErrorCharucoMarkerNotSmallerThanSquare) {
  EXPECT_EQ(ErrorOf("target_type: 'charuco'\nsquaresX: 5\nsquaresY: 7\n"
                    "squareSize: 0.04\nmarkerSize: 0.04\n"),
            "t.yaml:5: markerSize: must be smaller than squareSize (0.04 >= "
            "0.04)");
}

TEST(CalibrationTarget, ErrorCharucoOneSquare) {
  EXPECT_EQ(ErrorOf("target_type: 'charuco'\nsquaresX: 1\nsquaresY: 7\n"
                    "squareSize: 0.04\nmarkerSize: 0.03\n"),
            "t.yaml:2: squaresX: must be between 2 and 1000 squares, got 1");
}

TEST(CalibrationTarget, ErrorCharucoMissingKey) {
  EXPECT_EQ(ErrorOf("target_type: 'charuco'\nsquaresX: 5\nsquaresY: 7\n"
                    "squareSize: 0.04\n"),
            "t.yaml: missing key 'markerSize' (a charuco board needs "
            "squaresX, squaresY, squareSize, markerSize)");
}

TEST(CalibrationTarget, ErrorCharucoUnknownDictionary) {
  EXPECT_EQ(ErrorOf("target_type: 'charuco'\nsquaresX: 5\nsquaresY: 7\n"
                    "squareSize: 0.04\nmarkerSize: 0.03\n"
                    "dictionary: DICT_4X4_51\n"),
            "t.yaml:6: dictionary: unknown dictionary 'DICT_4X4_51' "
            "(OpenCV's predefined names, e.g. DICT_4X4_50, DICT_6X6_250, "
            "DICT_APRILTAG_36h11)");
}

TEST(CalibrationTarget, ErrorCharucoDictionaryTooSmall) {
  EXPECT_EQ(ErrorOf("target_type: 'charuco'\nsquaresX: 11\nsquaresY: 10\n"
                    "squareSize: 0.04\nmarkerSize: 0.03\n"
                    "dictionary: DICT_4X4_50\n"),
            "t.yaml:6: dictionary: dictionary DICT_4X4_50 has 50 markers, a "
            "11x10 board needs 55");
}

TEST(CalibrationTarget, ErrorCharucoDefaultDictionaryTooSmall) {
  EXPECT_EQ(ErrorOf("target_type: 'charuco'\nsquaresX: 30\n"
                    "squaresY: 20\nsquareSize: 0.04\nmarkerSize: 0.03\n"),
            "t.yaml:3: squaresY: dictionary DICT_6X6_250 has 250 markers, a "
            "30x20 board needs 300 (default dictionary; name a larger one)");
}

TEST(CalibrationTarget, ErrorCharucoDictionaryIsAList) {
  EXPECT_EQ(ErrorOf("target_type: 'charuco'\nsquaresX: 5\nsquaresY: 7\n"
                    "squareSize: 0.04\nmarkerSize: 0.03\n"
                    "dictionary: [a]\n"),
            "t.yaml:6: dictionary: expected a name, got a list");
}

TEST(CalibrationTarget, MakeTargetsLikeTheReader) {
  const CalibrationTarget checkerboard =
      MakeCheckerboardTarget(9, 6, 0.025).value();
  EXPECT_EQ(checkerboard.type, TargetType::kCheckerboard);
  EXPECT_EQ(checkerboard.col_spacing, 0.025);
  EXPECT_EQ(checkerboard.row_spacing, 0.025);
  const CalibrationTarget aprilgrid =
      MakeAprilGridTarget(6, 6, 0.088, 0.3).value();
  EXPECT_EQ(aprilgrid.type, TargetType::kAprilGrid);
  EXPECT_EQ(NumTargetPoints(aprilgrid), 144);
  const CalibrationTarget charuco =
      MakeCharucoTarget(5, 7, 0.04, 0.03, "DICT_4X4_50").value();
  EXPECT_EQ(charuco.dictionary, "DICT_4X4_50");
  EXPECT_EQ(NumTargetPoints(charuco), 24);
}

TEST(CalibrationTarget, MakeTargetErrors) {
  EXPECT_EQ(MakeCheckerboardTarget(9, 1, 0.025).status().message(),
            "checkerboard: rows must be between 2 and 1000 inner corners, "
            "got 1");
  EXPECT_EQ(MakeCheckerboardTarget(9, 6, -1.0).status().message(),
            "checkerboard: square size must be positive and finite, got -1");
  EXPECT_EQ(MakeAprilGridTarget(0, 6, 0.088, 0.3).status().message(),
            "aprilgrid: cols must be between 1 and 1000 tags, got 0");
  EXPECT_EQ(MakeAprilGridTarget(6, 6, 0.088, 0.0).status().message(),
            "aprilgrid: tag spacing must be positive and finite, got 0");
  EXPECT_EQ(
      MakeCharucoTarget(5, 7, 0.04, 0.05, "DICT_4X4_50").status().message(),
      "charuco: marker size must be smaller than the square size (0.05 >= "
      "0.04)");
  EXPECT_EQ(MakeCharucoTarget(5, 7, 0.04, 0.03, "4x4").status().message(),
            "charuco: unknown dictionary '4x4' (OpenCV's predefined names, "
            "e.g. DICT_4X4_50, DICT_6X6_250, DICT_APRILTAG_36h11)");
  EXPECT_EQ(
      MakeCharucoTarget(11, 10, 0.04, 0.03, "DICT_4X4_50").status().message(),
      "charuco: dictionary DICT_4X4_50 has 50 markers, a 11x10 board needs "
      "55");
}

TEST(CalibrationTarget, DescribeTarget) {
  EXPECT_EQ(DescribeTarget(MakeCheckerboardTarget(9, 6, 0.025).value()),
            "checkerboard 9x6 inner corners, 25 mm squares");
  EXPECT_EQ(DescribeTarget(ParseOrDie(kKalibrCheckerboard)),
            "checkerboard 6x7 inner corners, 50 x 60 mm squares");
  EXPECT_EQ(DescribeTarget(ParseOrDie(kKalibrAprilGrid)),
            "aprilgrid 6x4 tags, 88 mm tags, spacing 0.3");
  EXPECT_EQ(DescribeTarget(
                MakeCharucoTarget(5, 7, 0.04, 0.0305, "DICT_6X6_250").value()),
            "charuco 5x7 squares, 40 mm squares, 30.5 mm markers, "
            "DICT_6X6_250");
}

TEST(CalibrationTarget, FindArucoDictionary) {
  ASSERT_TRUE(FindArucoDictionary("DICT_APRILTAG_36h11").has_value());
  EXPECT_EQ(FindArucoDictionary("DICT_APRILTAG_36h11")->num_markers, 587);
  EXPECT_EQ(FindArucoDictionary("DICT_6X6_250")->opencv_id,
            cv::aruco::DICT_6X6_250);
  EXPECT_FALSE(FindArucoDictionary("dict_6x6_250").has_value());
  // The sizes are OpenCV's.
  for (const char* name :
       {"DICT_4X4_50", "DICT_5X5_1000", "DICT_7X7_250", "DICT_ARUCO_ORIGINAL",
        "DICT_APRILTAG_16h5", "DICT_APRILTAG_36h10"}) {
    const std::optional<ArucoDictionaryInfo> info = FindArucoDictionary(name);
    ASSERT_TRUE(info.has_value()) << name;
    EXPECT_EQ(
        info->num_markers,
        cv::aruco::getPredefinedDictionary(info->opencv_id)->bytesList.rows)
        << name;
  }
}

TEST(CalibrationTarget, ErrorRootIsNotAMap) {
  EXPECT_EQ(ErrorOf("- target_type: 'aprilgrid'\n"),
            "t.yaml:1: expected a map of target settings, got a list");
}

// Found by fuzz_calibration_target: a tagSpacing of 2.2e57 was accepted and
// neighbouring corners coincided.
TEST(CalibrationTarget, ErrorLengthOutOfRange) {
  EXPECT_EQ(ErrorOf("target_type: 'aprilgrid'\ntagCols: 6\ntagRows: 6\n"
                    "tagSize: 0.088\ntagSpacing: 2.2e57\n"),
            "t.yaml:5: tagSpacing: must be between 1e-06 and 10, got 2.2e57");
}

}  // namespace
}  // namespace rcm::calib::calibration_target_test
