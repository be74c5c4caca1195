#include "rcm/io/camera_file.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>

#include "rcm/io/camchain.h"
#include "rcm/io/camera_info.h"
#include "support/reader_inputs.h"
#include "support/temp_file.h"
#include "support/test_rigs.h"

namespace rcm::camera_file_test {
namespace {

using ::testing::HasSubstr;
using ::testing::StartsWith;

using test::ErrorMessage;
using test::WriteTempFile;

std::string TwoCameraCamchainText() {
  return FormatCamchain(CamchainFromStereoRig(test::AlphasenseRealisticRig()));
}

TEST(CameraFile, ReadsEachCameraOfACamchain) {
  const std::string path = WriteTempFile("rig.yaml", TwoCameraCamchainText());
  const StereoRig rig = test::AlphasenseRealisticRig();
  const StatusOr<Camera> cam0 = ReadCameraFile(path);
  const StatusOr<Camera> cam1 = ReadCameraFile(path, "cam1");
  ASSERT_TRUE(cam0.ok()) << cam0.status().message();
  ASSERT_TRUE(cam1.ok()) << cam1.status().message();
  EXPECT_EQ(*cam0, rig.left());
  EXPECT_EQ(*cam1, rig.right());
}

TEST(CameraFile, ReadsACameraInfo) {
  const Camera camera = test::EurocRadtanCamera();
  const std::string path =
      WriteTempFile("left.yaml", FormatCameraInfo(CameraInfoFromCamera(
                                     "left", camera)));
  const StatusOr<Camera> read = ReadCameraFile(path);
  ASSERT_TRUE(read.ok()) << read.status().message();
  EXPECT_EQ(*read, camera);
}

TEST(CameraFile, RejectsUnknownCamchainCamera) {
  const std::string path = WriteTempFile("rig.yaml", TwoCameraCamchainText());
  const std::string message = ErrorMessage(ReadCameraFile(path, "cam2"));
  EXPECT_THAT(message, StartsWith(path + ": unknown camera 'cam2'"));
  EXPECT_THAT(message, HasSubstr("cam0, cam1"));
  EXPECT_THAT(ErrorMessage(ReadCameraFile(path, "left")),
              HasSubstr("unknown camera 'left'"));
}

TEST(CameraFile, CameraNameDoesNotApplyToACameraInfo) {
  const Camera camera = test::EurocRadtanCamera();
  const std::string path = WriteTempFile(
      "left.yaml", FormatCameraInfo(CameraInfoFromCamera("left", camera)));
  const StatusOr<Camera> read = ReadCameraFile(path, "cam1");
  ASSERT_TRUE(read.ok()) << read.status().message();
  EXPECT_EQ(*read, camera);
}

TEST(CameraFile, ReportsMissingEmptyAndUnrecognisedFiles) {
  const std::string missing = test::TempFilePath("missing.yaml");
  EXPECT_THAT(ErrorMessage(ReadCameraFile(missing)), StartsWith(missing));
  const std::string empty = WriteTempFile("empty.yaml", "");
  EXPECT_THAT(ErrorMessage(ReadCameraFile(empty)), StartsWith(empty));
  const std::string other = WriteTempFile("other.yaml", "foo: 1\n");
  EXPECT_THAT(ErrorMessage(ReadCameraFile(other)),
              HasSubstr("neither a Kalibr camchain"));
  const std::string garbage = WriteTempFile("garbage.yaml", "\x01\x02[{\n");
  EXPECT_THAT(ErrorMessage(ReadCameraFile(garbage)), StartsWith(garbage));
}

}  // namespace
}  // namespace rcm::camera_file_test
