#include "rcm/io/stereo_rig_file.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>

#include "rcm/io/atomic_file.h"

namespace rcm {
namespace {

using ::testing::HasSubstr;
using ::testing::StartsWith;

// Three cameras: cam1 is 0.11 m right of cam0, cam2 0.09 m right of cam1.
constexpr char kCamchain[] = R"(cam0:
  cam_overlaps: [1, 2]
  camera_model: pinhole
  distortion_coeffs: [-0.0379, -0.00098, -0.00096, 2.36e-05]
  distortion_model: equidistant
  intrinsics: [346.7, 346.8, 360.5, 271.0]
  resolution: [720, 540]
cam1:
  T_cn_cnm1:
  - [1.0, 0.0, 0.0, -0.11]
  - [0.0, 1.0, 0.0, 0.0]
  - [0.0, 0.0, 1.0, 0.0]
  - [0.0, 0.0, 0.0, 1.0]
  cam_overlaps: [0, 2]
  camera_model: pinhole
  distortion_coeffs: [-0.0397, 0.00161, -0.00233, 0.00035]
  distortion_model: equidistant
  intrinsics: [344.4, 344.2, 358.7, 262.0]
  resolution: [720, 540]
cam2:
  T_cn_cnm1:
  - [0.0, -1.0, 0.0, -0.09]
  - [1.0, 0.0, 0.0, 0.0]
  - [0.0, 0.0, 1.0, 0.0]
  - [0.0, 0.0, 0.0, 1.0]
  cam_overlaps: [0, 1]
  camera_model: pinhole
  distortion_coeffs: []
  distortion_model: none
  intrinsics: [500.0, 500.0, 320.0, 240.0]
  resolution: [640, 480]
)";

// A ROS-rectified pair with identity rectification and a 0.12 m baseline:
// Tx = -fx' * B = -350 * 0.12.
std::string CameraInfoText(const std::string& name, double fx, double tx) {
  return "image_width: 720\n"
         "image_height: 540\n"
         "camera_name: " +
         name +
         "\n"
         "camera_matrix:\n"
         "  rows: 3\n"
         "  cols: 3\n"
         "  data: [" +
         std::to_string(fx) +
         ", 0, 360, 0, 346, 270, 0, 0, 1]\n"
         "distortion_model: plumb_bob\n"
         "distortion_coefficients:\n"
         "  rows: 1\n"
         "  cols: 5\n"
         "  data: [-0.28, 0.07, 0.0002, -0.00003, 0]\n"
         "rectification_matrix:\n"
         "  rows: 3\n"
         "  cols: 3\n"
         "  data: [1, 0, 0, 0, 1, 0, 0, 0, 1]\n"
         "projection_matrix:\n"
         "  rows: 3\n"
         "  cols: 4\n"
         "  data: [350, 0, 362, " +
         std::to_string(tx) + ", 0, 350, 270, 0, 0, 0, 1, 0]\n";
}

// Writes `contents` to a file in the test temp directory; returns its path.
std::string WriteTemp(const std::string& name, const std::string& contents) {
  const std::string path = ::testing::TempDir() + "/stereo_rig_file_" + name;
  const Status status = WriteFileAtomically(path, contents);
  EXPECT_TRUE(status.ok()) << status.message();
  return path;
}

std::string ErrorOf(const StatusOr<StereoRig>& rig) {
  return rig.ok() ? "" : rig.status().message();
}

TEST(StereoRigFile, ReadsCamchainDefaultPair) {
  const std::string path = WriteTemp("default.yaml", kCamchain);
  const StatusOr<StereoRig> rig = ReadStereoRig(path);
  ASSERT_TRUE(rig.ok()) << rig.status().message();
  EXPECT_EQ(rig->left().fx(), 346.7);
  EXPECT_EQ(rig->right().fx(), 344.4);
  EXPECT_EQ(rig->right_from_left().rotation, Eigen::Matrix3d::Identity());
  EXPECT_EQ(rig->right_from_left().translation,
            Eigen::Vector3d(-0.11, 0.0, 0.0));
}

TEST(StereoRigFile, SelectsNamedCameras) {
  const std::string path = WriteTemp("named.yaml", kCamchain);
  const StatusOr<StereoRig> rig = ReadStereoRig(path, "cam0", "cam2");
  ASSERT_TRUE(rig.ok()) << rig.status().message();
  EXPECT_EQ(rig->right().fx(), 500.0);
  // cam2_from_cam0 = T21 * T10: the rotation of T21, t = R21 t10 + t21.
  EXPECT_NEAR(rig->right_from_left().translation.x(), -0.09, 1e-15);
  EXPECT_NEAR(rig->right_from_left().translation.y(), -0.11, 1e-15);
  EXPECT_EQ(rig->right_from_left().rotation(1, 0), 1.0);
}

TEST(StereoRigFile, ReversedNamesInvertTheTransform) {
  const std::string path = WriteTemp("reversed.yaml", kCamchain);
  const StatusOr<StereoRig> rig = ReadStereoRig(path, "cam1", "cam0");
  ASSERT_TRUE(rig.ok()) << rig.status().message();
  EXPECT_EQ(rig->left().fx(), 344.4);
  EXPECT_EQ(rig->right_from_left().translation,
            Eigen::Vector3d(0.11, 0.0, 0.0));
}

TEST(StereoRigFile, RejectsUnknownCamera) {
  const std::string path = WriteTemp("unknown.yaml", kCamchain);
  EXPECT_EQ(ErrorOf(ReadStereoRig(path, "cam0", "cam7")),
            path +
                ": unknown camera 'cam7' (the camchain has cam0, cam1, "
                "cam2)");
}

TEST(StereoRigFile, RejectsCameraNameThatIsNotCamN) {
  const std::string path = WriteTemp("bad_name.yaml", kCamchain);
  EXPECT_EQ(ErrorOf(ReadStereoRig(path, "left", "cam1")),
            path +
                ": unknown camera 'left' (the camchain has cam0, cam1, "
                "cam2)");
}

TEST(StereoRigFile, RejectsSameCameraTwice) {
  const std::string path = WriteTemp("same.yaml", kCamchain);
  EXPECT_EQ(ErrorOf(ReadStereoRig(path, "cam1", "cam1")),
            path + ": left and right are the same camera (cam1)");
}

TEST(StereoRigFile, ReportsCamchainErrorsWithPath) {
  const std::string path =
      WriteTemp("bad_camchain.yaml",
                std::string(kCamchain).replace(
                    std::string(kCamchain).find("pinhole"), 7, "omni"));
  EXPECT_EQ(ErrorOf(ReadStereoRig(path)),
            path +
                ":3: cam0.camera_model: unknown model 'omni' (supported: "
                "pinhole)");
}

TEST(StereoRigFile, ReportsYamlSyntaxError) {
  const std::string path = WriteTemp("syntax.yaml", "cam0: [1, 2\n");
  EXPECT_THAT(ErrorOf(ReadStereoRig(path)),
              StartsWith(path + ":2: YAML syntax error: "));
}

TEST(StereoRigFile, ReportsEmptyFile) {
  const std::string path = WriteTemp("empty.yaml", "");
  EXPECT_EQ(ErrorOf(ReadStereoRig(path)), path + ": empty file");
}

TEST(StereoRigFile, RejectsUnrecognisedFile) {
  const std::string path = WriteTemp("other.yaml", "image_width: 720\n");
  EXPECT_EQ(ErrorOf(ReadStereoRig(path)),
            path +
                ": neither a Kalibr camchain (no 'cam0') nor a ROS "
                "camera_info (no 'camera_matrix')");
}

TEST(StereoRigFile, RejectsTopLevelList) {
  const std::string path = WriteTemp("list.yaml", "- cam0\n- cam1\n");
  EXPECT_EQ(ErrorOf(ReadStereoRig(path)),
            path +
                ": neither a Kalibr camchain (no 'cam0') nor a ROS "
                "camera_info (no 'camera_matrix')");
}

TEST(StereoRigFile, RejectsMissingFile) {
  const std::string path = ::testing::TempDir() + "/stereo_rig_file_none.yaml";
  EXPECT_EQ(ErrorOf(ReadStereoRig(path)),
            path + ": cannot open: No such file or directory");
}

TEST(StereoRigFile, ReadsCameraInfoPair) {
  const std::string left =
      WriteTemp("left.yaml", CameraInfoText("left", 346.5, 0.0));
  const std::string right =
      WriteTemp("right.yaml", CameraInfoText("right", 344.5, -42.0));
  const StatusOr<StereoRig> rig = ReadStereoRig(left + "," + right);
  ASSERT_TRUE(rig.ok()) << rig.status().message();
  EXPECT_EQ(rig->left().fx(), 346.5);
  EXPECT_EQ(rig->right().fx(), 344.5);
  EXPECT_EQ(rig->left().model(), LensModelId::kRadTan);
  EXPECT_EQ(rig->right_from_left().rotation, Eigen::Matrix3d::Identity());
  EXPECT_NEAR(rig->right_from_left().translation.x(), -0.12, 1e-15);
  EXPECT_EQ(rig->right_from_left().translation.y(), 0.0);
  EXPECT_EQ(rig->right_from_left().translation.z(), 0.0);
}

TEST(StereoRigFile, RejectsSwappedCameraInfoPair) {
  const std::string left =
      WriteTemp("swap_left.yaml", CameraInfoText("left", 346.5, 0.0));
  const std::string right =
      WriteTemp("swap_right.yaml", CameraInfoText("right", 344.5, -42.0));
  EXPECT_THAT(ErrorOf(ReadStereoRig(right + "," + left)),
              StartsWith(right + "," + left +
                         ": left projection_matrix has a nonzero 4th column"));
}

TEST(StereoRigFile, RejectsCameraNamesWithCameraInfoPair) {
  const std::string left =
      WriteTemp("names_left.yaml", CameraInfoText("left", 346.5, 0.0));
  const std::string right =
      WriteTemp("names_right.yaml", CameraInfoText("right", 344.5, -42.0));
  EXPECT_THAT(ErrorOf(ReadStereoRig(left + "," + right, "cam1", "cam0")),
              StartsWith("camera names ('cam1', 'cam0') select cameras of a "
                         "Kalibr camchain; with two ROS camera_info files"));
}

TEST(StereoRigFile, RejectsSingleCameraInfo) {
  const std::string path =
      WriteTemp("single.yaml", CameraInfoText("left", 346.5, 0.0));
  EXPECT_EQ(ErrorOf(ReadStereoRig(path)),
            path +
                ": is a ROS camera_info, which describes one camera; give "
                "the left and right files as 'left.yaml,right.yaml'");
}

TEST(StereoRigFile, RejectsCamchainInPair) {
  const std::string camchain = WriteTemp("pair_camchain.yaml", kCamchain);
  const std::string right =
      WriteTemp("pair_right.yaml", CameraInfoText("right", 344.5, -42.0));
  EXPECT_THAT(ErrorOf(ReadStereoRig(camchain + "," + right)),
              StartsWith(camchain + ": is a Kalibr camchain, expected a ROS "
                                    "camera_info"));
}

TEST(StereoRigFile, RejectsPairWithEmptyPath) {
  const std::string left =
      WriteTemp("lonely_left.yaml", CameraInfoText("left", 346.5, 0.0));
  EXPECT_EQ(ErrorOf(ReadStereoRig(left + ",")),
            "'" + left +
                ",': expected one camchain path or two camera_info paths "
                "'left.yaml,right.yaml'");
}

TEST(StereoRigFile, RejectsThreePaths) {
  EXPECT_THAT(ErrorOf(ReadStereoRig("a.yaml,b.yaml,c.yaml")),
              HasSubstr("expected one camchain path or two camera_info paths"));
}

TEST(StereoRigFile, ReportsCameraInfoErrorsWithPath) {
  const std::string left =
      WriteTemp("k3_left.yaml", CameraInfoText("left", 346.5, 0.0));
  std::string bad = CameraInfoText("right", 344.5, -42.0);
  bad.replace(bad.find("-0.00003, 0]"), 12, "-0.00003, 0.1]");
  const std::string right = WriteTemp("k3_right.yaml", bad);
  EXPECT_THAT(ErrorOf(ReadStereoRig(left + "," + right)),
              StartsWith(right + ":12: distortion_coefficients.data: k3 = 0.1 "
                                 "is not supported"));
}

}  // namespace
}  // namespace rcm
