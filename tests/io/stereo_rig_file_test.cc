#include "rcm/io/stereo_rig_file.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <optional>
#include <string>

#include "rcm/io/calibration_covariance_file.h"
#include "rcm/io/camchain.h"
#include "support/camera_info_text.h"
#include "support/reader_inputs.h"
#include "support/temp_file.h"
#include "support/test_rigs.h"

namespace rcm::stereo_rig_file_test {
namespace {

using ::testing::HasSubstr;
using ::testing::StartsWith;

using test::ErrorMessage;
using test::WriteTempFile;

// A Kalibr camchain of three cameras: cam1 is 0.11 m right of cam0, cam2
// 0.09 m right of cam1 and turned by 90 degrees about the optical axis.
std::string ThreeCameraCamchain() {
  Rigid3d cam1_from_cam0;
  cam1_from_cam0.translation = Eigen::Vector3d(-0.11, 0.0, 0.0);
  Rigid3d cam2_from_cam1;
  cam2_from_cam1.rotation << 0.0, -1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0;
  cam2_from_cam1.translation = Eigen::Vector3d(-0.09, 0.0, 0.0);
  Camchain camchain;
  camchain.cameras = {
      {Camera::Create(LensModelId::kEquidistant, 720, 540,
                      {346.7, 346.8, 360.5, 271.0},
                      {-0.0379, -0.00098, -0.00096, 2.36e-05})
           .value(),
       std::nullopt,
       std::nullopt,
       std::nullopt,
       {1, 2},
       ""},
      {Camera::Create(LensModelId::kEquidistant, 720, 540,
                      {344.4, 344.2, 358.7, 262.0},
                      {-0.0397, 0.00161, -0.00233, 0.00035})
           .value(),
       cam1_from_cam0,
       std::nullopt,
       std::nullopt,
       {0, 2},
       ""},
      {Camera::Create(LensModelId::kPinhole, 640, 480,
                      {500.0, 500.0, 320.0, 240.0}, {})
           .value(),
       cam2_from_cam1,
       std::nullopt,
       std::nullopt,
       {0, 1},
       ""},
  };
  return FormatCamchain(camchain);
}

// One camera of a ROS-rectified pair with identity rectification; the
// pair has a 0.12 m baseline when the right one has
// tx = -fx' * B = -350 * 0.12.
std::string RectifiedCameraInfoText(const std::string& name, double fx,
                                    double tx) {
  Eigen::Matrix3d camera_matrix;
  camera_matrix << fx, 0.0, 360.0, 0.0, 346.0, 270.0, 0.0, 0.0, 1.0;
  Eigen::Matrix<double, 3, 4> projection;
  projection << 350.0, 0.0, 362.0, tx, 0.0, 350.0, 270.0, 0.0, 0.0, 0.0, 1.0,
      0.0;
  return test::CameraInfoText(name, camera_matrix,
                              {-0.28, 0.07, 0.0002, -0.00003, 0.0},
                              Eigen::Matrix3d::Identity(), projection);
}

TEST(StereoRigFile, ReadsCamchainDefaultPair) {
  const std::string path = WriteTempFile("default.yaml", ThreeCameraCamchain());
  const StatusOr<StereoRig> rig = ReadStereoRig(path);
  ASSERT_TRUE(rig.ok()) << rig.status().message();
  EXPECT_EQ(rig->left().fx(), 346.7);
  EXPECT_EQ(rig->right().fx(), 344.4);
  EXPECT_EQ(rig->right_from_left().rotation, Eigen::Matrix3d::Identity());
  EXPECT_EQ(rig->right_from_left().translation,
            Eigen::Vector3d(-0.11, 0.0, 0.0));
}

// A rig of the unified models (issue 21) through a camchain file, with
// the covariance sidecar of its 6-parameter lenses beside it.
TEST(StereoRigFile, ReadsUnifiedModelRigWithItsCovariance) {
  Rigid3d right_from_left;
  right_from_left.translation = Eigen::Vector3d(-0.1, 0.001, 0.0);
  const StereoRig rig = StereoRig::Create(test::DoubleSphereCamera(),
                                          test::EucmCamera(), right_from_left)
                            .value();
  const std::string path = test::TempFilePath("unified.yaml");
  ASSERT_TRUE(WriteCamchain(path, CamchainFromStereoRig(rig)).ok());
  CalibrationCovarianceFile covariance;
  covariance.cameras.resize(2);
  for (auto& camera : covariance.cameras) {
    camera.intrinsics_covariance = 1e-4 * Eigen::MatrixXd::Identity(6, 6);
  }
  covariance.cameras[1].from_previous_covariance =
      1e-8 * Eigen::Matrix<double, 6, 6>::Identity();
  ASSERT_TRUE(
      WriteCalibrationCovariance(CovarianceSidecarPath(path), covariance).ok());
  const StatusOr<StereoRig> read = ReadStereoRig(path);
  ASSERT_TRUE(read.ok()) << read.status().message();
  EXPECT_EQ(read->left(), rig.left());
  EXPECT_EQ(read->right(), rig.right());
  EXPECT_EQ(read->right_from_left().translation, right_from_left.translation);
}

TEST(StereoRigFile, SelectsNamedCameras) {
  const std::string path = WriteTempFile("named.yaml", ThreeCameraCamchain());
  const StatusOr<StereoRig> rig = ReadStereoRig(path, "cam0", "cam2");
  ASSERT_TRUE(rig.ok()) << rig.status().message();
  EXPECT_EQ(rig->right().fx(), 500.0);
  // cam2_from_cam0 = T21 * T10: the rotation of T21, t = R21 t10 + t21.
  EXPECT_NEAR(rig->right_from_left().translation.x(), -0.09, 1e-15);
  EXPECT_NEAR(rig->right_from_left().translation.y(), -0.11, 1e-15);
  EXPECT_EQ(rig->right_from_left().rotation(1, 0), 1.0);
}

TEST(StereoRigFile, ReversedNamesInvertTheTransform) {
  const std::string path =
      WriteTempFile("reversed.yaml", ThreeCameraCamchain());
  const StatusOr<StereoRig> rig = ReadStereoRig(path, "cam1", "cam0");
  ASSERT_TRUE(rig.ok()) << rig.status().message();
  EXPECT_EQ(rig->left().fx(), 344.4);
  EXPECT_EQ(rig->right_from_left().translation,
            Eigen::Vector3d(0.11, 0.0, 0.0));
}

TEST(StereoRigFile, RejectsUnknownCamera) {
  const std::string path = WriteTempFile("unknown.yaml", ThreeCameraCamchain());
  EXPECT_EQ(ErrorMessage(ReadStereoRig(path, "cam0", "cam7")),
            path +
                ": unknown camera 'cam7' (the camchain has cam0, cam1, "
                "cam2)");
}

TEST(StereoRigFile, RejectsCameraNameThatIsNotCamN) {
  const std::string path =
      WriteTempFile("bad_name.yaml", ThreeCameraCamchain());
  EXPECT_EQ(ErrorMessage(ReadStereoRig(path, "left", "cam1")),
            path +
                ": unknown camera 'left' (the camchain has cam0, cam1, "
                "cam2)");
}

TEST(StereoRigFile, RejectsSameCameraTwice) {
  const std::string path = WriteTempFile("same.yaml", ThreeCameraCamchain());
  EXPECT_EQ(ErrorMessage(ReadStereoRig(path, "cam1", "cam1")),
            path + ": left and right are the same camera (cam1)");
}

TEST(StereoRigFile, ReportsCamchainErrorsWithPath) {
  std::string camchain = ThreeCameraCamchain();
  camchain.replace(camchain.find("pinhole"), 7, "omni");
  const std::string path = WriteTempFile("bad_camchain.yaml", camchain);
  EXPECT_EQ(ErrorMessage(ReadStereoRig(path)),
            path +
                ":3: cam0.camera_model: unknown model 'omni' (supported: "
                "pinhole, ds, eucm)");
}

TEST(StereoRigFile, ReportsYamlSyntaxError) {
  const std::string path = WriteTempFile("syntax.yaml", "cam0: [1, 2\n");
  EXPECT_THAT(ErrorMessage(ReadStereoRig(path)),
              StartsWith(path + ":2: YAML syntax error: "));
}

TEST(StereoRigFile, ReportsEmptyFile) {
  const std::string path = WriteTempFile("empty.yaml", "");
  EXPECT_EQ(ErrorMessage(ReadStereoRig(path)), path + ": empty file");
}

TEST(StereoRigFile, RejectsUnrecognisedFile) {
  const std::string path = WriteTempFile("other.yaml", "image_width: 720\n");
  EXPECT_EQ(ErrorMessage(ReadStereoRig(path)),
            path +
                ": neither a Kalibr camchain (no 'cam0') nor a ROS "
                "camera_info (no 'camera_matrix')");
}

TEST(StereoRigFile, RejectsTopLevelList) {
  const std::string path = WriteTempFile("list.yaml", "- cam0\n- cam1\n");
  EXPECT_EQ(ErrorMessage(ReadStereoRig(path)),
            path +
                ": neither a Kalibr camchain (no 'cam0') nor a ROS "
                "camera_info (no 'camera_matrix')");
}

TEST(StereoRigFile, RejectsMissingFile) {
  const std::string path = test::TempFilePath("none.yaml");
  EXPECT_EQ(ErrorMessage(ReadStereoRig(path)),
            path + ": cannot open: No such file or directory");
}

TEST(StereoRigFile, ReadsCameraInfoPair) {
  const std::string left =
      WriteTempFile("left.yaml", RectifiedCameraInfoText("left", 346.5, 0.0));
  const std::string right = WriteTempFile(
      "right.yaml", RectifiedCameraInfoText("right", 344.5, -42.0));
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
  const std::string left = WriteTempFile(
      "swap_left.yaml", RectifiedCameraInfoText("left", 346.5, 0.0));
  const std::string right = WriteTempFile(
      "swap_right.yaml", RectifiedCameraInfoText("right", 344.5, -42.0));
  EXPECT_THAT(ErrorMessage(ReadStereoRig(right + "," + left)),
              StartsWith(right + "," + left +
                         ": left projection_matrix has a nonzero 4th column"));
}

TEST(StereoRigFile, RejectsCameraNamesWithCameraInfoPair) {
  const std::string left = WriteTempFile(
      "names_left.yaml", RectifiedCameraInfoText("left", 346.5, 0.0));
  const std::string right = WriteTempFile(
      "names_right.yaml", RectifiedCameraInfoText("right", 344.5, -42.0));
  EXPECT_THAT(ErrorMessage(ReadStereoRig(left + "," + right, "cam1", "cam0")),
              StartsWith("camera names ('cam1', 'cam0') select cameras of a "
                         "Kalibr camchain; with two ROS camera_info files"));
}

TEST(StereoRigFile, RejectsSingleCameraInfo) {
  const std::string path =
      WriteTempFile("single.yaml", RectifiedCameraInfoText("left", 346.5, 0.0));
  EXPECT_EQ(ErrorMessage(ReadStereoRig(path)),
            path +
                ": is a ROS camera_info, which describes one camera; give "
                "the left and right files as 'left.yaml,right.yaml'");
}

TEST(StereoRigFile, RejectsCamchainInPair) {
  const std::string camchain =
      WriteTempFile("pair_camchain.yaml", ThreeCameraCamchain());
  const std::string right = WriteTempFile(
      "pair_right.yaml", RectifiedCameraInfoText("right", 344.5, -42.0));
  EXPECT_THAT(ErrorMessage(ReadStereoRig(camchain + "," + right)),
              StartsWith(camchain + ": is a Kalibr camchain, expected a ROS "
                                    "camera_info"));
}

// Found by the CLI bad-input table: an empty or non-YAML file in a pair was
// "a Kalibr camchain"; it is a camera_info with its own problem.
TEST(StereoRigFile, ReportsEmptyOrGarbledCameraInfoInPair) {
  const std::string left = WriteTempFile(
      "garbled_left.yaml", RectifiedCameraInfoText("left", 344.5, 0.0));
  const std::string empty = WriteTempFile("garbled_empty.yaml", "");
  EXPECT_EQ(ErrorMessage(ReadStereoRig(left + "," + empty)),
            empty + ": empty file");
  const std::string syntax =
      WriteTempFile("garbled_syntax.yaml", "image_width: [720\n");
  EXPECT_THAT(ErrorMessage(ReadStereoRig(left + "," + syntax)),
              StartsWith(syntax + ":2: YAML syntax error: "));
}

TEST(StereoRigFile, RejectsPairWithEmptyPath) {
  const std::string left = WriteTempFile(
      "lonely_left.yaml", RectifiedCameraInfoText("left", 346.5, 0.0));
  EXPECT_EQ(ErrorMessage(ReadStereoRig(left + ",")),
            "'" + left +
                ",': expected one camchain path or two camera_info paths "
                "'left.yaml,right.yaml'");
}

TEST(StereoRigFile, RejectsThreePaths) {
  EXPECT_THAT(ErrorMessage(ReadStereoRig("a.yaml,b.yaml,c.yaml")),
              HasSubstr("expected one camchain path or two camera_info paths"));
}

TEST(StereoRigFile, ReportsCameraInfoErrorsWithPath) {
  const std::string left = WriteTempFile(
      "k3_left.yaml", RectifiedCameraInfoText("left", 346.5, 0.0));
  std::string bad = RectifiedCameraInfoText("right", 344.5, -42.0);
  bad.replace(bad.find("-3e-05, 0.0]"), 12, "-3e-05, 0.1]");
  const std::string right = WriteTempFile("k3_right.yaml", bad);
  EXPECT_THAT(ErrorMessage(ReadStereoRig(left + "," + right)),
              StartsWith(right + ":12: distortion_coefficients.data: k3 = 0.1 "
                                 "is not supported"));
}

}  // namespace
}  // namespace rcm::stereo_rig_file_test
