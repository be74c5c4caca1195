#include "rcm/io/camera_info.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "support/camera_info_text.h"
#include "support/reader_inputs.h"
#include "support/temp_file.h"
#include "support/test_rigs.h"

namespace rcm::camera_info_test {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;
using ::testing::StartsWith;

// A camera_info as camera_calibration_parsers writes it (the ROS stereo
// calibrator's left.yaml). Line numbers for the error tests:
//   7 camera_matrix.data   8 distortion_model   12 distortion data
//  16 rectification data  20 projection data
constexpr char kLeft[] = R"(image_width: 720
image_height: 540
camera_name: left
camera_matrix:
  rows: 3
  cols: 3
  data: [346.7, 0, 360.5, 0, 346.8, 271.0, 0, 0, 1]
distortion_model: plumb_bob
distortion_coefficients:
  rows: 1
  cols: 5
  data: [-0.28, 0.07, 0.0002, -0.00003, 0]
rectification_matrix:
  rows: 3
  cols: 3
  data: [1, 0, 0, 0, 1, 0, 0, 0, 1]
projection_matrix:
  rows: 3
  cols: 4
  data: [350.0, 0, 362.0, 0, 0, 350.0, 270.0, 0, 0, 0, 1, 0]
)";

using test::ReplaceOnce;

std::string ParseError(const std::string& text) {
  return test::ErrorMessage(ParseCameraInfo(text, "left.yaml"));
}

// A stereo pair rectified the way OpenCV's stereoRectify / ROS do it, from
// a known rig: R_l turns the baseline onto the x axis (plus a roll about
// it), R_r = R_l R^T, both P share K' and the right one has Tx = -fx' B.
class CameraInfoStereo : public ::testing::Test {
 protected:
  void SetUp() override {
    const Eigen::Vector3d angle_axis(0.004, -0.012, 0.002);
    right_from_left_.rotation =
        Eigen::AngleAxisd(angle_axis.norm(), angle_axis.normalized())
            .toRotationMatrix();
    right_from_left_.translation = Eigen::Vector3d(-0.11, 0.0015, -0.0008);
    // Right camera center in the left frame.
    const Eigen::Vector3d center =
        -(right_from_left_.rotation.transpose() * right_from_left_.translation);
    const Eigen::Matrix3d rect_left =
        Eigen::AngleAxisd(0.003, Eigen::Vector3d::UnitX()).toRotationMatrix() *
        Eigen::Quaterniond::FromTwoVectors(center, Eigen::Vector3d::UnitX())
            .toRotationMatrix();
    const Eigen::Matrix3d rect_right =
        rect_left * right_from_left_.rotation.transpose();
    const double baseline = center.norm();

    Eigen::Matrix3d k_left;
    k_left << 346.68681661781403, 0.0, 360.53325988648163, 0.0,
        346.7780959214622, 271.0179819820658, 0.0, 0.0, 1.0;
    Eigen::Matrix3d k_right;
    k_right << 344.3933991977547, 0.0, 358.725925185576, 0.0, 344.2292927278568,
        262.02195974034373, 0.0, 0.0, 1.0;
    const double fx_rect = 345.123456789;
    Eigen::Matrix<double, 3, 4> p_left;
    p_left << fx_rect, 0.0, 352.25, 0.0, 0.0, fx_rect, 268.5, 0.0, 0.0, 0.0,
        1.0, 0.0;
    Eigen::Matrix<double, 3, 4> p_right = p_left;
    p_right(0, 3) = -fx_rect * baseline;

    left_text_ = test::CameraInfoText("alphasense/left", k_left,
                                      {-0.28, 0.07, 0.0002, -0.00003, 0.0},
                                      rect_left, p_left);
    right_text_ = test::CameraInfoText("alphasense/right", k_right,
                                       {-0.27, 0.068, -0.0001, 0.00005, 0.0},
                                       rect_right, p_right);
  }

  Rigid3d right_from_left_;
  std::string left_text_;
  std::string right_text_;
};

TEST_F(CameraInfoStereo, ParsesCameraInfo) {
  const StatusOr<CameraInfo> info = ParseCameraInfo(left_text_, "left.yaml");
  ASSERT_TRUE(info.ok()) << info.status().message();
  EXPECT_EQ(info->camera_name, "alphasense/left");
  EXPECT_EQ(info->camera.model(), LensModelId::kRadTan);
  EXPECT_EQ(info->camera.width(), 720);
  EXPECT_EQ(info->camera.height(), 540);
  EXPECT_EQ(info->camera.fx(), 346.68681661781403);
  EXPECT_EQ(info->camera.fy(), 346.7780959214622);
  EXPECT_EQ(info->camera.cx(), 360.53325988648163);
  EXPECT_EQ(info->camera.cy(), 271.0179819820658);
  EXPECT_EQ(info->camera.Distortion(),
            (std::vector<double>{-0.28, 0.07, 0.0002, -0.00003}));
  EXPECT_EQ(info->projection(0, 0), 345.123456789);
  EXPECT_EQ(info->projection(1, 2), 268.5);
  EXPECT_LT((info->rectification.transpose() * info->rectification -
             Eigen::Matrix3d::Identity())
                .cwiseAbs()
                .maxCoeff(),
            1e-15);
}

TEST_F(CameraInfoStereo, RecoversRightFromLeft) {
  const StatusOr<CameraInfo> left = ParseCameraInfo(left_text_, "left.yaml");
  const StatusOr<CameraInfo> right = ParseCameraInfo(right_text_, "right.yaml");
  ASSERT_TRUE(left.ok()) << left.status().message();
  ASSERT_TRUE(right.ok()) << right.status().message();
  const StatusOr<StereoRig> rig = StereoRigFromCameraInfo(*left, *right);
  ASSERT_TRUE(rig.ok()) << rig.status().message();
  EXPECT_LT((rig->right_from_left().rotation - right_from_left_.rotation)
                .cwiseAbs()
                .maxCoeff(),
            1e-12);
  EXPECT_LT((rig->right_from_left().translation - right_from_left_.translation)
                .cwiseAbs()
                .maxCoeff(),
            1e-12);
  EXPECT_EQ(rig->left().fx(), 346.68681661781403);
  EXPECT_EQ(rig->right().fx(), 344.3933991977547);
}

TEST_F(CameraInfoStereo, RejectsSwappedPair) {
  const StatusOr<CameraInfo> left = ParseCameraInfo(left_text_, "left.yaml");
  const StatusOr<CameraInfo> right = ParseCameraInfo(right_text_, "right.yaml");
  ASSERT_TRUE(left.ok() && right.ok());
  const StatusOr<StereoRig> rig = StereoRigFromCameraInfo(*right, *left);
  ASSERT_FALSE(rig.ok());
  EXPECT_THAT(rig.status().message(),
              StartsWith("left projection_matrix has a nonzero 4th column "
                         "(Tx = -"));
  EXPECT_THAT(rig.status().message(), HasSubstr("give the left camera first"));
}

TEST(CameraInfo, StereoRigRejectsMalformedProjection) {
  const StatusOr<CameraInfo> left = ParseCameraInfo(kLeft, "left.yaml");
  const StatusOr<CameraInfo> right = ParseCameraInfo(
      ReplaceOnce(kLeft, "[350.0, 0, 362.0, 0, 0, 350.0, 270.0, 0, 0, 0, 1, 0]",
                  "[350.0, 0, 362.0, -38.5, 0, 350.0, 270.0, 0, 0, 0, 2, 0]"),
      "right.yaml");
  ASSERT_TRUE(left.ok() && right.ok());
  const StatusOr<StereoRig> rig = StereoRigFromCameraInfo(*left, *right);
  ASSERT_FALSE(rig.ok());
  EXPECT_EQ(rig.status().message(),
            "right projection_matrix: expected [fx' 0 cx' Tx; 0 fy' cy' Ty; 0 "
            "0 1 0] with fx', fy' > 0, got [350.0 0.0 362.0 -38.5; 0.0 350.0 "
            "270.0 0.0; 0.0 0.0 2.0 0.0]");
}

TEST(CameraInfo, StereoRigRejectsZeroBaseline) {
  const StatusOr<CameraInfo> info = ParseCameraInfo(kLeft, "left.yaml");
  ASSERT_TRUE(info.ok()) << info.status().message();
  const StatusOr<StereoRig> rig = StereoRigFromCameraInfo(*info, *info);
  ASSERT_FALSE(rig.ok());
  EXPECT_THAT(rig.status().message(), StartsWith("zero baseline"));
}

TEST(CameraInfo, DefaultsRectificationAndProjection) {
  const std::string text = kLeft;
  const std::string without = text.substr(0, text.find("rectification_matrix"));
  const StatusOr<CameraInfo> info = ParseCameraInfo(without, "left.yaml");
  ASSERT_TRUE(info.ok()) << info.status().message();
  EXPECT_EQ(info->rectification, Eigen::Matrix3d::Identity());
  Eigen::Matrix<double, 3, 4> expected;
  expected << 346.7, 0.0, 360.5, 0.0, 0.0, 346.8, 271.0, 0.0, 0.0, 0.0, 1.0,
      0.0;
  EXPECT_EQ(info->projection, expected);
}

TEST(CameraInfo, AcceptsFourPlumbBobCoefficients) {
  const StatusOr<CameraInfo> info =
      ParseCameraInfo(ReplaceOnce(ReplaceOnce(kLeft, "cols: 5", "cols: 4"),
                                  "[-0.28, 0.07, 0.0002, -0.00003, 0]",
                                  "[-0.28, 0.07, 0.0002, -0.00003]"),
                      "left.yaml");
  ASSERT_TRUE(info.ok()) << info.status().message();
  EXPECT_EQ(info->camera.Distortion(),
            (std::vector<double>{-0.28, 0.07, 0.0002, -0.00003}));
}

TEST(CameraInfo, AllZeroPlumbBobIsRadTan) {
  const StatusOr<CameraInfo> info =
      ParseCameraInfo(ReplaceOnce(kLeft, "[-0.28, 0.07, 0.0002, -0.00003, 0]",
                                  "[0.0, 0.0, 0.0, 0.0, 0.0]"),
                      "left.yaml");
  ASSERT_TRUE(info.ok()) << info.status().message();
  EXPECT_EQ(info->camera.model(), LensModelId::kRadTan);
  EXPECT_EQ(info->camera.Distortion(), std::vector<double>(4, 0.0));
}

TEST(CameraInfo, RadTanNameIsAccepted) {
  const StatusOr<CameraInfo> info =
      ParseCameraInfo(ReplaceOnce(kLeft, "plumb_bob", "radtan"), "left.yaml");
  ASSERT_TRUE(info.ok()) << info.status().message();
  EXPECT_EQ(info->camera.model(), LensModelId::kRadTan);
}

TEST(CameraInfo, MissingDistortionModelMeansPlumbBob) {
  const StatusOr<CameraInfo> info = ParseCameraInfo(
      ReplaceOnce(kLeft, "distortion_model: plumb_bob\n", ""), "left.yaml");
  ASSERT_TRUE(info.ok()) << info.status().message();
  EXPECT_EQ(info->camera.model(), LensModelId::kRadTan);
}

TEST(CameraInfo, EquidistantTakesFourCoefficients) {
  const StatusOr<CameraInfo> info = ParseCameraInfo(
      ReplaceOnce(ReplaceOnce(ReplaceOnce(kLeft, "plumb_bob", "equidistant"),
                              "cols: 5", "cols: 4"),
                  "[-0.28, 0.07, 0.0002, -0.00003, 0]",
                  "[-0.0379, -0.00098, -0.00096, 2.36e-05]"),
      "left.yaml");
  ASSERT_TRUE(info.ok()) << info.status().message();
  EXPECT_EQ(info->camera.model(), LensModelId::kEquidistant);
  EXPECT_EQ(info->camera.Distortion(),
            (std::vector<double>{-0.0379, -0.00098, -0.00096, 2.36e-05}));
}

TEST(CameraInfo, NoneModelIsPinhole) {
  const StatusOr<CameraInfo> info = ParseCameraInfo(
      ReplaceOnce(ReplaceOnce(kLeft, "plumb_bob", "none"),
                  "[-0.28, 0.07, 0.0002, -0.00003, 0]", "[0, 0, 0, 0, 0]"),
      "left.yaml");
  ASSERT_TRUE(info.ok()) << info.status().message();
  EXPECT_EQ(info->camera.model(), LensModelId::kPinhole);
  EXPECT_TRUE(info->camera.Distortion().empty());
}

TEST(CameraInfo, EmptyModelNameIsPinhole) {
  const std::string text = kLeft;
  const std::string head = text.substr(0, text.find("distortion_model"));
  const std::string tail = text.substr(text.find("rectification_matrix"));
  const StatusOr<CameraInfo> info =
      ParseCameraInfo(head + "distortion_model: \"\"\n" + tail, "left.yaml");
  ASSERT_TRUE(info.ok()) << info.status().message();
  EXPECT_EQ(info->camera.model(), LensModelId::kPinhole);
}

// --- Malformed input
// ----------------------------------------------------------

TEST(CameraInfo, FixtureIsValid) { EXPECT_EQ(ParseError(kLeft), ""); }

TEST(CameraInfo, RejectsMissingCameraMatrix) {
  const std::string text = kLeft;
  const std::string without = text.substr(0, text.find("camera_matrix")) +
                              text.substr(text.find("distortion_model"));
  EXPECT_EQ(ParseError(without), "left.yaml: missing key 'camera_matrix'");
}

TEST(CameraInfo, RejectsMissingImageWidth) {
  EXPECT_EQ(ParseError(ReplaceOnce(kLeft, "image_width: 720\n", "")),
            "left.yaml: missing key 'image_width'");
}

TEST(CameraInfo, RejectsMissingData) {
  EXPECT_EQ(
      ParseError(ReplaceOnce(
          kLeft, "  data: [346.7, 0, 360.5, 0, 346.8, 271.0, 0, 0, 1]\n", "")),
      "left.yaml: camera_matrix: missing key 'data'");
}

TEST(CameraInfo, RejectsWrongDataLength) {
  EXPECT_EQ(ParseError(ReplaceOnce(kLeft,
                                   "[346.7, 0, 360.5, 0, 346.8, 271.0, "
                                   "0, 0, 1]",
                                   "[346.7, 0, 360.5, 0, 346.8, 271.0, 0, 0]")),
            "left.yaml:7: camera_matrix.data: expected 9 numbers (3x3), got 8");
}

TEST(CameraInfo, RejectsWrongRowCount) {
  EXPECT_EQ(ParseError(ReplaceOnce(kLeft, "  rows: 3\n  cols: 4",
                                   "  rows: 4\n  cols: 4")),
            "left.yaml:18: projection_matrix.rows: expected 3, got 4");
}

TEST(CameraInfo, RejectsColsThatDisagreeWithData) {
  EXPECT_EQ(ParseError(ReplaceOnce(kLeft, "cols: 5", "cols: 4")),
            "left.yaml:11: distortion_coefficients.cols: expected 5, got 4");
}

TEST(CameraInfo, RejectsUnknownModel) {
  EXPECT_EQ(ParseError(ReplaceOnce(kLeft, "plumb_bob", "fov")),
            "left.yaml:8: distortion_model: unknown model "
            "'fov' (supported: plumb_bob, radtan, "
            "equidistant, rational_polynomial, none)");
}

TEST(CameraInfo, ReadsRationalPolynomial) {
  const std::string text = ReplaceOnce(
      ReplaceOnce(ReplaceOnce(kLeft, "plumb_bob", "rational_polynomial"),
                  "cols: 5", "cols: 8"),
      "[-0.28, 0.07, 0.0002, -0.00003, 0]",
      "[0.5, 0.1, 0.0009, -0.0006, 0.001, 0.75, 0.2, 0.001]");
  const StatusOr<CameraInfo> info = ParseCameraInfo(text, "left.yaml");
  ASSERT_TRUE(info.ok()) << info.status().message();
  EXPECT_EQ(info->camera.model(), LensModelId::kRational);
  EXPECT_EQ(info->camera.Distortion(),
            (std::vector<double>{0.5, 0.1, 0.0009, -0.0006, 0.001, 0.75, 0.2,
                                 0.001}));
  EXPECT_EQ(ParseError(ReplaceOnce(kLeft, "plumb_bob", "rational_polynomial")),
            "left.yaml:12: distortion_coefficients.data: expected 8 numbers "
            "(k1, k2, p1, p2, k3, k4, k5, k6) for distortion_model "
            "'rational_polynomial', got 5");
}

TEST(CameraInfo, RejectsNonzeroK3) {
  EXPECT_EQ(ParseError(ReplaceOnce(kLeft, "-0.00003, 0]", "-0.00003, 0.01]")),
            "left.yaml:12: distortion_coefficients.data: k3 = 0.01 is not "
            "supported: rcm's radtan model has k1, k2, p1, p2; recalibrate "
            "with k3 fixed to 0");
}

TEST(CameraInfo, RejectsWrongPlumbBobCount) {
  EXPECT_EQ(ParseError(ReplaceOnce(ReplaceOnce(kLeft, "cols: 5", "cols: 8"),
                                   "-0.00003, 0]", "-0.00003, 0, 0, 0, 0]")),
            "left.yaml:12: distortion_coefficients.data: expected 4 or 5 "
            "numbers (k1, k2, p1, p2[, k3]) for distortion_model 'plumb_bob', "
            "got 8");
}

TEST(CameraInfo, RejectsWrongEquidistantCount) {
  EXPECT_EQ(ParseError(ReplaceOnce(kLeft, "plumb_bob", "equidistant")),
            "left.yaml:12: distortion_coefficients.data: expected 4 numbers "
            "(k1, k2, k3, k4) for distortion_model 'equidistant', got 5");
}

TEST(CameraInfo, RejectsCoefficientsForNoneModel) {
  EXPECT_EQ(ParseError(ReplaceOnce(kLeft, "plumb_bob", "none")),
            "left.yaml:12: distortion_coefficients.data: distortion_model "
            "'none' takes no coefficients, got nonzero -0.28");
}

TEST(CameraInfo, RejectsMissingCoefficients) {
  const std::string text = kLeft;
  const std::string without =
      text.substr(0, text.find("distortion_coefficients")) +
      text.substr(text.find("rectification_matrix"));
  EXPECT_EQ(ParseError(without),
            "left.yaml: missing key 'distortion_coefficients'");
}

TEST(CameraInfo, RejectsSkew) {
  EXPECT_EQ(ParseError(
                ReplaceOnce(kLeft, "[346.7, 0, 360.5,", "[346.7, 0.5, 360.5,")),
            "left.yaml:7: camera_matrix.data: nonzero skew K[0][1] = 0.5 is "
            "not supported");
}

TEST(CameraInfo, RejectsBadCameraMatrixLastRow) {
  EXPECT_EQ(
      ParseError(ReplaceOnce(kLeft, "271.0, 0, 0, 1]", "271.0, 0, 0, 2]")),
      "left.yaml:7: camera_matrix.data: expected [fx, 0, cx, 0, fy, cy, "
      "0, 0, 1], but K[2][2] = 2.0");
}

TEST(CameraInfo, RejectsNonRotationRectification) {
  EXPECT_THAT(ParseError(ReplaceOnce(kLeft, "[1, 0, 0, 0, 1, 0, 0, 0, 1]",
                                     "[1, 0, 0, 0, 1.1, 0, 0, 0, 1]")),
              StartsWith("left.yaml:16: rectification_matrix.data: not a rigid "
                         "transform: rotation is not orthonormal"));
}

TEST(CameraInfo, RejectsReflectionRectification) {
  EXPECT_EQ(ParseError(ReplaceOnce(kLeft, "[1, 0, 0, 0, 1, 0, 0, 0, 1]",
                                   "[1, 0, 0, 0, 1, 0, 0, 0, -1]")),
            "left.yaml:16: rectification_matrix.data: not a rigid transform: "
            "rotation has determinant -1 (a reflection)");
}

TEST(CameraInfo, RejectsNonPositiveFocalLength) {
  EXPECT_EQ(ParseError(ReplaceOnce(kLeft, "0, 346.8, 271.0,", "0, 0, 271.0,")),
            "left.yaml:7: camera_matrix.data: focal length must be positive, "
            "got fy = 0");
}

TEST(CameraInfo, RejectsNonPositiveImageSize) {
  EXPECT_EQ(ParseError(ReplaceOnce(kLeft, "image_height: 540",
                                   "image_height: "
                                   "-540")),
            "left.yaml:2: image_height: image size must be positive, got 720 x "
            "-540");
}

TEST(CameraInfo, RejectsNonNumber) {
  EXPECT_EQ(
      ParseError(ReplaceOnce(kLeft, "[346.7, 0, 360.5,", "[346.7, 0, abc,")),
      "left.yaml:7: camera_matrix.data: 'abc' is not a number");
}

TEST(CameraInfo, RejectsYamlSyntaxError) {
  EXPECT_THAT(
      ParseError(ReplaceOnce(kLeft, "camera_name: left", "camera_name: [left")),
      StartsWith("left.yaml:4: YAML syntax error: "));
}

TEST(CameraInfo, RejectsEmptyFile) {
  EXPECT_EQ(ParseError(""), "left.yaml: empty file");
}

TEST(CameraInfo, RejectsTopLevelScalar) {
  EXPECT_EQ(ParseError("camera_info\n"),
            "left.yaml:1: top level is not a map (expected a ROS camera_info "
            "with image_width, camera_matrix, ...), got 'camera_info'");
}

TEST(CameraInfo, ReadRejectsMissingFile) {
  const std::string path = test::TempFilePath("missing.yaml");
  const StatusOr<CameraInfo> info = ReadCameraInfo(path);
  ASSERT_FALSE(info.ok());
  EXPECT_EQ(info.status().message(),
            path + ": cannot open: No such file or directory");
}

// --- Writing
// ---------------------------------------------------------------------

// EuRoC's cam0, with a coefficient that prints in scientific notation.
Camera EurocCamera() {
  return Camera::Create(LensModelId::kRadTan, 752, 480,
                        {458.654, 457.296, 367.215, 248.375},
                        {-0.28340811, 0.07395907, 0.00019359, 1.76187114e-05})
      .value();
}

// Formats `info` and parses the text back; a parse error fails the test.
CameraInfo FormatAndParse(const CameraInfo& info) {
  const std::string text = FormatCameraInfo(info);
  StatusOr<CameraInfo> parsed = ParseCameraInfo(text, "written.yaml");
  EXPECT_TRUE(parsed.ok()) << parsed.status().message() << "\n" << text;
  return parsed.ok() ? std::move(parsed).value() : info;
}

// The names in this directory of files starting with `prefix`.
std::vector<std::string> FilesStartingWith(const std::string& directory,
                                           const std::string& prefix) {
  std::vector<std::string> names;
  for (const auto& entry : std::filesystem::directory_iterator(directory)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind(prefix, 0) == 0) names.push_back(name);
  }
  return names;
}

TEST(CameraInfo, FromCameraIsUnrectified) {
  const CameraInfo info = CameraInfoFromCamera("cam0", EurocCamera());
  EXPECT_EQ(info.camera_name, "cam0");
  EXPECT_EQ(info.camera, EurocCamera());
  EXPECT_EQ(info.rectification, Eigen::Matrix3d::Identity());
  Eigen::Matrix<double, 3, 4> expected;
  expected << 458.654, 0.0, 367.215, 0.0, 0.0, 457.296, 248.375, 0.0, 0.0, 0.0,
      1.0, 0.0;
  EXPECT_EQ(info.projection, expected);
}

TEST(CameraInfo, FormatIsWhatCameraCalibrationParsersWrite) {
  EXPECT_EQ(FormatCameraInfo(CameraInfoFromCamera("cam0", EurocCamera())),
            "image_width: 752\n"
            "image_height: 480\n"
            "camera_name: cam0\n"
            "camera_matrix:\n"
            "  rows: 3\n"
            "  cols: 3\n"
            "  data: [458.654, 0.0, 367.215, 0.0, 457.296, 248.375, 0.0, 0.0, "
            "1.0]\n"
            "distortion_model: plumb_bob\n"
            "distortion_coefficients:\n"
            "  rows: 1\n"
            "  cols: 5\n"
            "  data: [-0.28340811, 0.07395907, 0.00019359, 1.76187114e-05, "
            "0.0]\n"
            "rectification_matrix:\n"
            "  rows: 3\n"
            "  cols: 3\n"
            "  data: [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]\n"
            "projection_matrix:\n"
            "  rows: 3\n"
            "  cols: 4\n"
            "  data: [458.654, 0.0, 367.215, 0.0, 0.0, 457.296, 248.375, 0.0, "
            "0.0, 0.0, 1.0, 0.0]\n");
}

TEST(CameraInfo, RoundTripsRadTanBitExactly) {
  const CameraInfo info = CameraInfoFromCamera("cam0", EurocCamera());
  const CameraInfo parsed = FormatAndParse(info);
  EXPECT_EQ(parsed.camera_name, "cam0");
  EXPECT_EQ(parsed.camera, info.camera);
  EXPECT_EQ(parsed.rectification, info.rectification);
  EXPECT_EQ(parsed.projection, info.projection);
}

TEST(CameraInfo, RoundTripsEquidistantBitExactly) {
  for (const Camera& camera : {test::AlphasenseCam0(), test::AlphasenseCam1(),
                               test::WideEquidistantCamera()}) {
    ASSERT_EQ(camera.model(), LensModelId::kEquidistant);
    const CameraInfo info = CameraInfoFromCamera("fisheye", camera);
    EXPECT_THAT(FormatCameraInfo(info),
                HasSubstr("\ndistortion_model: equidistant\n"
                          "distortion_coefficients:\n  rows: 1\n  cols: 4\n"));
    const CameraInfo parsed = FormatAndParse(info);
    EXPECT_EQ(parsed.camera, camera);
    EXPECT_EQ(parsed.projection, info.projection);
  }
}

TEST(CameraInfo, RoundTripsRationalBitExactly) {
  const Camera camera = test::RationalCamera();
  const CameraInfo info = CameraInfoFromCamera("rational", camera);
  EXPECT_THAT(FormatCameraInfo(info),
              HasSubstr("\ndistortion_model: rational_polynomial\n"
                        "distortion_coefficients:\n  rows: 1\n  cols: 8\n"
                        "  data: [0.5, 0.1, 0.0009, -0.0006, 0.001, 0.75, "
                        "0.2, 0.001]\n"));
  const CameraInfo parsed = FormatAndParse(info);
  EXPECT_EQ(parsed.camera, camera);
  EXPECT_EQ(parsed.projection, info.projection);
  // And through a file.
  const std::string path = test::TempFilePath("rational_info.yaml");
  ASSERT_TRUE(WriteCameraInfo(path, info).ok());
  const StatusOr<CameraInfo> read = ReadCameraInfo(path);
  ASSERT_TRUE(read.ok()) << read.status().message();
  EXPECT_EQ(read->camera, camera);
}

// ROS has no double-sphere or EUCM model: writing one is a one-line error
// that leaves no file.
TEST(CameraInfo, RefusesToWriteUnifiedModels) {
  for (const Camera& camera : {test::DoubleSphereCamera(), test::EucmCamera()}) {
    const std::string path = test::TempFilePath("unified_info.yaml");
    const Status status =
        WriteCameraInfo(path, CameraInfoFromCamera("cam", camera));
    ASSERT_FALSE(status.ok());
    EXPECT_EQ(status.message(),
              path + ": a camera_info cannot hold the lens model '" +
                  std::string(LensModelName(camera.model())) +
                  "' (ROS has plumb_bob, rational_polynomial, equidistant): "
                  "write a Kalibr camchain instead");
    EXPECT_FALSE(std::filesystem::exists(path));
  }
}

TEST(CameraInfo, PinholeReadsBackAsZeroRadTanWithTheSameProjection) {
  const Camera pinhole = test::PinholeCamera();
  const CameraInfo info = CameraInfoFromCamera("pinhole", pinhole);
  EXPECT_THAT(FormatCameraInfo(info),
              HasSubstr("distortion_model: plumb_bob\n"
                        "distortion_coefficients:\n  rows: 1\n  cols: 5\n"
                        "  data: [0.0, 0.0, 0.0, 0.0, 0.0]\n"));
  const CameraInfo parsed = FormatAndParse(info);
  EXPECT_EQ(parsed.camera.model(), LensModelId::kRadTan);
  EXPECT_EQ(parsed.camera.Distortion(), std::vector<double>(4, 0.0));
  EXPECT_EQ(parsed.camera.width(), pinhole.width());
  EXPECT_EQ(parsed.camera.height(), pinhole.height());
  EXPECT_EQ(parsed.projection, info.projection);
  for (const Eigen::Vector2d& pixel : test::ImageGrid(pinhole, 80.0)) {
    const std::optional<Eigen::Vector2d> expected =
        pinhole.NormalizedFromImage(pixel);
    const std::optional<Eigen::Vector2d> normalized =
        parsed.camera.NormalizedFromImage(pixel);
    ASSERT_TRUE(expected.has_value() && normalized.has_value());
    EXPECT_LT((*normalized - *expected).norm(), 1e-12) << pixel.transpose();
    EXPECT_LT((parsed.camera.ImageFromNormalized(*expected) - pixel).norm(),
              1e-9)
        << pixel.transpose();
  }
}

TEST(CameraInfo, CameraNamesThatNeedQuotingRoundTrip) {
  for (const std::string name : {"", "alphasense/left", "a: b", "#1", "null",
                                 "~", "[x]", "it's \"q\""}) {
    const CameraInfo parsed =
        FormatAndParse(CameraInfoFromCamera(name, EurocCamera()));
    EXPECT_EQ(parsed.camera_name, name);
  }
}

TEST_F(CameraInfoStereo, WrittenFilesReproduceTheRig) {
  const StatusOr<CameraInfo> left = ParseCameraInfo(left_text_, "left.yaml");
  const StatusOr<CameraInfo> right = ParseCameraInfo(right_text_, "right.yaml");
  ASSERT_TRUE(left.ok() && right.ok());
  const std::string left_path = test::TempFilePath("left.yaml");
  const std::string right_path = test::TempFilePath("right.yaml");
  ASSERT_TRUE(WriteCameraInfo(left_path, *left).ok());
  ASSERT_TRUE(WriteCameraInfo(right_path, *right).ok());
  const StatusOr<CameraInfo> left_read = ReadCameraInfo(left_path);
  const StatusOr<CameraInfo> right_read = ReadCameraInfo(right_path);
  ASSERT_TRUE(left_read.ok()) << left_read.status().message();
  ASSERT_TRUE(right_read.ok()) << right_read.status().message();
  for (const auto& [read, original] :
       {std::pair{&*left_read, &*left}, std::pair{&*right_read, &*right}}) {
    EXPECT_EQ(read->camera_name, original->camera_name);
    EXPECT_EQ(read->camera, original->camera);
    EXPECT_EQ(read->rectification, original->rectification);
    EXPECT_EQ(read->projection, original->projection);
  }
  const StatusOr<StereoRig> expected = StereoRigFromCameraInfo(*left, *right);
  const StatusOr<StereoRig> rig =
      StereoRigFromCameraInfo(*left_read, *right_read);
  ASSERT_TRUE(expected.ok() && rig.ok());
  EXPECT_EQ(rig->right_from_left().rotation,
            expected->right_from_left().rotation);
  EXPECT_EQ(rig->right_from_left().translation,
            expected->right_from_left().translation);
  EXPECT_LT((rig->right_from_left().translation - right_from_left_.translation)
                .cwiseAbs()
                .maxCoeff(),
            1e-12);
  EXPECT_EQ(rig->left(), expected->left());
  EXPECT_EQ(rig->right(), expected->right());
  std::remove(left_path.c_str());
  std::remove(right_path.c_str());
}

TEST(CameraInfo, WriteReplacesAnExistingFile) {
  const std::string path = test::WriteTempFile("cam.yaml", "old contents\n");
  const CameraInfo info = CameraInfoFromCamera("cam0", EurocCamera());
  ASSERT_TRUE(WriteCameraInfo(path, info).ok());
  const StatusOr<CameraInfo> read = ReadCameraInfo(path);
  ASSERT_TRUE(read.ok()) << read.status().message();
  EXPECT_EQ(read->camera, info.camera);
  std::remove(path.c_str());
}

TEST(CameraInfo, WriteToUnwritableDirectoryFailsAndLeavesNothing) {
  const std::string directory = test::TempFilePath("no_such_dir");
  const std::string path = directory + "/cam0.yaml";
  const Status status =
      WriteCameraInfo(path, CameraInfoFromCamera("cam0", EurocCamera()));
  ASSERT_FALSE(status.ok());
  EXPECT_EQ(status.message(),
            path + ": cannot write: No such file or directory");
  EXPECT_FALSE(std::filesystem::exists(directory));

  // A directory that exists but cannot hold the file: the path names one.
  const std::string taken = test::TempFilePath("taken");
  std::filesystem::create_directory(taken);
  const Status over_directory =
      WriteCameraInfo(taken, CameraInfoFromCamera("cam0", EurocCamera()));
  ASSERT_FALSE(over_directory.ok());
  EXPECT_THAT(over_directory.message(), StartsWith(taken + ": "));
  EXPECT_THAT(over_directory.message(), Not(HasSubstr("\n")));
  EXPECT_TRUE(std::filesystem::is_directory(taken));
  const std::string prefix = std::filesystem::path(taken).filename().string();
  EXPECT_EQ(FilesStartingWith(::testing::TempDir(), prefix),
            std::vector<std::string>{prefix});
  std::filesystem::remove(taken);
}

}  // namespace
}  // namespace rcm::camera_info_test
