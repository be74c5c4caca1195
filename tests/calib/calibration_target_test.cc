#include "rcm/calib/calibration_target.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <string>
#include <vector>

#include "support/temp_file.h"

namespace rcm::calib {
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
      test::WriteTempFile("aprilgrid.yaml", kKalibrAprilGrid);
  const StatusOr<CalibrationTarget> target = ReadCalibrationTarget(path);
  std::remove(path.c_str());
  ASSERT_TRUE(target.ok()) << target.status().message();
  EXPECT_EQ(target->type, TargetType::kAprilGrid);
  EXPECT_EQ(NumTargetPoints(*target), 96);
}

TEST(CalibrationTarget, ReadMissingFileReportsPath) {
  const std::string path = test::TempFilePath("missing.yaml");
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
            "aprilgrid)");
}

TEST(CalibrationTarget, ErrorUnknownType) {
  EXPECT_EQ(ErrorOf("\ntarget_type: 'charuco'\n"),
            "t.yaml:2: unknown target_type 'charuco' (supported: "
            "checkerboard, aprilgrid)");
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
            "checkerboard, aprilgrid)");
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
            "checkerboard, aprilgrid)");
}

TEST(CalibrationTarget, ErrorRootIsNotAMap) {
  EXPECT_EQ(ErrorOf("- target_type: 'aprilgrid'\n"),
            "t.yaml:1: expected a map of target settings, got a list");
}

}  // namespace
}  // namespace rcm::calib
