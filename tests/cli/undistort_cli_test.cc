// End-to-end tests of `rcm undistort`: a small simulated dive (240x180
// fisheyes, written by `rcm simulate`) corrected from folders and from a
// ROS1 bag, the files read back, and every refused input.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "cli/cli_runner.h"
#include "rcm/io/camchain.h"
#include "rcm/io/camera_info.h"
#include "rcm/io/image_file.h"
#include "rcm/io/stereo_rig_file.h"
#include "rcm/stereo/virtual_pinhole_rig.h"
#include "support/temp_file.h"
#ifdef RCM_HAVE_ROSBAG
#include "rcm/rosbag/bag_image_writer.h"
#include "rcm/rosbag/bag_stereo_source.h"
#endif

namespace rcm::undistort_cli_test {
namespace {

namespace fs = std::filesystem;
using test::IsOneLine;
using test::RunResult;

constexpr int kFrames = 2;
constexpr int kWidth = 240;
constexpr int kHeight = 180;

RunResult Rcm(const std::vector<std::string>& args) {
  return test::RunProgram(RCM_BINARY, args);
}

std::string Folder(const std::string& name) {
  const std::string folder = test::TempFilePath(name);
  fs::remove_all(folder);
  return folder;
}

Rigid3d Transform(double angle, const Eigen::Vector3d& axis,
                  const Eigen::Vector3d& translation) {
  return Rigid3d{Eigen::AngleAxisd(angle, axis.normalized()).toRotationMatrix(),
                 translation};
}

// A small rig for fast tests: the dataset's fisheye coefficients at a
// third of its resolution, cam1 0.5 degrees from rectified, with the IMU
// extrinsics, time shift and topics a Kalibr camchain carries.
Camchain SmallCamchain(int width = kWidth, int height = kHeight) {
  const double scale = width / static_cast<double>(kWidth);
  const Camera cam0 = Camera::Create(LensModelId::kEquidistant, width, height,
                                     {116.0 * scale, 116.1 * scale,
                                      120.2 * scale, 90.3 * scale},
                                     {-0.0379, -0.001, -0.001, 2.4e-05})
                          .value();
  const Camera cam1 = Camera::Create(LensModelId::kEquidistant, width, height,
                                     {115.0 * scale, 114.8 * scale,
                                      119.6 * scale, 87.4 * scale},
                                     {-0.0397, 0.0016, -0.0023, 0.00035})
                          .value();
  const Rigid3d cam0_from_imu = Transform(M_PI / 2, Eigen::Vector3d(0, 0, 1),
                                          Eigen::Vector3d(0.02, -0.01, 0.005));
  const Rigid3d cam1_from_cam0 =
      Transform(0.5 * M_PI / 180.0, Eigen::Vector3d(0.3, 1.0, 0.1),
                Eigen::Vector3d(-0.11, 0.0015, -0.002));
  Camchain camchain;
  camchain.cameras.push_back(
      {cam0, std::nullopt, cam0_from_imu, 0.0012, {1}, "/cam0/image_raw"});
  camchain.cameras.push_back({cam1,
                              cam1_from_cam0,
                              cam1_from_cam0 * cam0_from_imu,
                              0.0012,
                              {0},
                              "/cam1/image_raw"});
  return camchain;
}

// A simulated dive of the small rig (n = 1.333): DIR/camchain.yaml (the
// rig as written by rcm simulate), DIR/rig.yaml (with the IMU fields),
// DIR/left, DIR/right.
std::string Dive() {
  const std::string folder = Folder("dive");
  fs::create_directories(folder);
  const std::string rig = folder + "/rig.yaml";
  EXPECT_TRUE(WriteCamchain(rig, SmallCamchain()).ok());
  const RunResult simulated =
      Rcm({"simulate", "--calib", rig, "--out", folder, "--frames",
           std::to_string(kFrames), "--supersampling", "1"});
  EXPECT_EQ(simulated.exit_code, 0) << simulated.err;
  return folder;
}

std::vector<std::string> FolderArgs(const std::string& dive,
                                    const std::string& out) {
  return {
      "undistort",    "--calib", dive + "/rig.yaml", "--n",   "1.333", "--left",
      dive + "/left", "--right", dive + "/right",    "--out", out};
}

std::vector<std::string> With(std::vector<std::string> args,
                              const std::vector<std::string>& more) {
  args.insert(args.end(), more.begin(), more.end());
  return args;
}

TEST(UndistortCli, FoldersGiveCorrectedImagesAndTheirCalibration) {
  const std::string dive = Dive();
  const std::string out = Folder("out");
  const RunResult result = Rcm(FolderArgs(dive, out));
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_TRUE(result.err.empty()) << result.err;
  EXPECT_NE(result.out.find("fit no-border"), std::string::npos) << result.out;
  EXPECT_NE(result.out.find("x K_n"), std::string::npos) << result.out;
  EXPECT_NE(result.out.find("ms per image"), std::string::npos) << result.out;

  // The corrected images are exactly the library's, under the input names.
  const StereoRig raw_rig = ReadStereoRig(dive + "/rig.yaml").value();
  const VirtualPinholeRig rig =
      VirtualPinholeRig::Create(raw_rig, 1.333).value();
  for (const char* name : {"000000.png", "000001.png"}) {
    for (bool left : {true, false}) {
      const std::string side = left ? "/left/" : "/right/";
      const cv::Mat raw = ReadImage(dive + side + name, true).value();
      const cv::Mat corrected = ReadImage(out + side + name, true).value();
      ASSERT_EQ(corrected.size(), cv::Size(kWidth, kHeight)) << side << name;
      const cv::Mat expected = (left ? rig.left() : rig.right()).Correct(raw);
      EXPECT_EQ(cv::norm(corrected, expected, cv::NORM_INF), 0.0)
          << side << name;
    }
  }
  // The camchain is the corrected rig, with the IMU extrinsics (unrotated
  // views: unchanged), time shift and topics of the input.
  const Camchain camchain = ReadCamchain(out + "/camchain.yaml").value();
  const StereoRig read = StereoRigFromCamchain(camchain, 0, 1).value();
  EXPECT_EQ(read.left(), rig.corrected_rig().left());
  EXPECT_EQ(read.right(), rig.corrected_rig().right());
  EXPECT_EQ(read.left().model(), LensModelId::kPinhole);
  EXPECT_EQ(read.right_from_left().ToMatrix(),
            raw_rig.right_from_left().ToMatrix());
  const Camchain input = SmallCamchain();
  EXPECT_EQ(camchain.cameras[0].cam_from_imu->ToMatrix(),
            input.cameras[0].cam_from_imu->ToMatrix());
  EXPECT_EQ(camchain.cameras[1].timeshift_cam_imu, 0.0012);
  EXPECT_EQ(camchain.cameras[1].rostopic, "/cam1/image_raw");
  // The camera_info files describe the same cameras.
  const CameraInfo left_info = ReadCameraInfo(out + "/left.yaml").value();
  const CameraInfo right_info = ReadCameraInfo(out + "/right.yaml").value();
  EXPECT_EQ(left_info.camera.width(), kWidth);
  EXPECT_EQ(left_info.camera.fx(), rig.left().pinhole.fx());
  EXPECT_EQ(right_info.camera.cy(), rig.right().pinhole.cy());
  EXPECT_EQ(right_info.projection.col(3), Eigen::Vector3d::Zero());
}

TEST(UndistortCli, JsonReportsTheViewsAndTimes) {
  const std::string dive = Dive();
  const std::string out = Folder("out");
  const RunResult result =
      Rcm(With(FolderArgs(dive, out), {"--fit", "full", "--json"}));
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const nlohmann::json json = nlohmann::json::parse(result.out);
  EXPECT_EQ(json["n"].get<double>(), 1.333);
  EXPECT_EQ(json["fit"], "full");
  EXPECT_EQ(json["rectified"], false);
  EXPECT_EQ(json["pairs"].get<int>(), kFrames);
  EXPECT_EQ(json["images_written"].get<int>(), 2 * kFrames);
  for (const char* side : {"left", "right"}) {
    const nlohmann::json& camera = json["cameras"][side];
    EXPECT_EQ(camera["k"].size(), 4u);
    EXPECT_EQ(camera["width"].get<int>(), kWidth);
    EXPECT_EQ(camera["height"].get<int>(), kHeight);
    // The whole field of view: wider than K_n, some black corners.
    EXPECT_LT(camera["focal_scale"].get<double>(), 1.0);
    EXPECT_GT(camera["black_fraction"].get<double>(), 0.0);
  }
  EXPECT_GT(json["ms"]["maps"].get<double>(), 0.0);
  EXPECT_GT(json["ms"]["remap_per_image"].get<double>(), 0.0);
  EXPECT_GT(json["ms"]["per_pair"].get<double>(), 0.0);
  EXPECT_EQ(json["files"]["camchain"].get<std::string>(),
            out + "/camchain.yaml");
  EXPECT_TRUE(fs::exists(out + "/camchain.yaml"));
}

TEST(UndistortCli, RectifiedOutputIsAStereoPair) {
  const std::string dive = Dive();
  const std::string out = Folder("out");
  const RunResult result = Rcm(With(
      FolderArgs(dive, out), {"--rectify", "--size", "200x150", "--json"}));
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const nlohmann::json json = nlohmann::json::parse(result.out);
  EXPECT_EQ(json["rectified"], true);
  EXPECT_EQ(json["cameras"]["left"]["k"], json["cameras"]["right"]["k"]);
  EXPECT_EQ(ReadImage(out + "/right/000001.png", true).value().size(),
            cv::Size(200, 150));
  // The camchain: R = I, t along x; the IMU extrinsics rotated into the
  // rectified view, so that an IMU point lands where the chain puts it.
  const Camchain camchain = ReadCamchain(out + "/camchain.yaml").value();
  const Rigid3d& right_from_left = *camchain.cameras[1].cam_from_previous;
  EXPECT_EQ(right_from_left.rotation, Eigen::Matrix3d::Identity());
  EXPECT_EQ(right_from_left.translation.y(), 0.0);
  EXPECT_EQ(right_from_left.translation.z(), 0.0);
  const Eigen::Vector3d point_in_imu(0.3, 0.2, 1.0);
  EXPECT_LT(
      (*camchain.cameras[1].cam_from_imu * point_in_imu -
       right_from_left * (*camchain.cameras[0].cam_from_imu * point_in_imu))
          .norm(),
      1e-9);
  // The camera_info pair is the same stereo rig.
  const StereoRig from_info =
      StereoRigFromCameraInfo(ReadCameraInfo(out + "/left.yaml").value(),
                              ReadCameraInfo(out + "/right.yaml").value())
          .value();
  EXPECT_LT(
      (from_info.right_from_left().ToMatrix() - right_from_left.ToMatrix())
          .cwiseAbs()
          .maxCoeff(),
      1e-12);
}

// The checks every refused run shares: a non-zero exit, one line on
// stderr from rcm undistort naming the problem, no camchain.
void ExpectRefused(const RunResult& result, const std::string& needle,
                   const std::string& out) {
  EXPECT_NE(result.exit_code, 0) << needle;
  EXPECT_TRUE(IsOneLine(result.err)) << "stderr:\n" << result.err;
  EXPECT_EQ(result.err.rfind("rcm undistort: error: ", 0), 0u) << result.err;
  EXPECT_NE(result.err.find(needle), std::string::npos) << result.err;
  if (!out.empty()) {
    EXPECT_FALSE(fs::exists(out + "/camchain.yaml")) << needle;
  }
}

TEST(UndistortCli, RefusesMissingAndBadFlags) {
  const std::string dive = Dive();
  const std::string out = Folder("out");
  const std::vector<std::string> input = {"--left", dive + "/left", "--right",
                                          dive + "/right"};
  ExpectRefused(Rcm(With({"undistort", "--n", "1.333", "--out", out}, input)),
                "--calib is required", out);
  ExpectRefused(
      Rcm(With({"undistort", "--calib", dive + "/rig.yaml", "--out", out},
               input)),
      "--n is required", out);
  ExpectRefused(
      Rcm(With({"undistort", "--calib", dive + "/rig.yaml", "--n", "1.333"},
               input)),
      "--out is required", "");
  ExpectRefused(Rcm(With(FolderArgs(dive, out), {"--n", "2.5"})),
                "--n 2.5 is outside [1, 2]", out);
  ExpectRefused(Rcm(With(FolderArgs(dive, out), {"--fit", "wide"})),
                "unknown --fit 'wide'", out);
  ExpectRefused(Rcm(With(FolderArgs(dive, out), {"--size", "640"})),
                "--size must be WIDTHxHEIGHT", out);
  ExpectRefused(Rcm(With(FolderArgs(dive, out), {"--focal", "-3"})), "--focal",
                out);
  ExpectRefused(Rcm({"undistort", "--calib", dive + "/rig.yaml", "--n", "1.333",
                     "--out", out}),
                "no images", out);
  EXPECT_FALSE(fs::exists(out));
}

TEST(UndistortCli, RefusesBadInputAndOutput) {
  const std::string dive = Dive();
  const std::string out = Folder("out");
  // An unreadable rig.
  std::vector<std::string> args = FolderArgs(dive, out);
  args[2] = dive + "/missing.yaml";
  ExpectRefused(Rcm(args), "missing.yaml", out);
  // Images of another size than the calibration's: the file and both sizes.
  const std::string large = dive + "/large.yaml";
  ASSERT_TRUE(WriteCamchain(large, SmallCamchain(360, 270)).ok());
  args[2] = large;
  ExpectRefused(Rcm(args),
                "000000.png: image is 240x180 but the "
                "calibration's cam0 is 360x270",
                out);
  EXPECT_FALSE(fs::exists(out + "/left")) << "nothing written";
  // An empty input folder.
  const std::string empty = Folder("empty");
  fs::create_directories(empty + "/left");
  fs::create_directories(empty + "/right");
  ExpectRefused(
      Rcm({"undistort", "--calib", dive + "/rig.yaml", "--n", "1.333", "--left",
           empty + "/left", "--right", empty + "/right", "--out", out}),
      "no images", out);
  // An output that cannot be created: a path through a regular file.
  const std::string file = test::WriteTempFile("file", "not a folder");
  ExpectRefused(Rcm(FolderArgs(dive, file + "/out")), "cannot create", "");
  // The output is the input: OUT/left would be the raw left folder (the
  // dive has the camchain rcm simulate wrote, so no camchain check).
  ExpectRefused(Rcm(FolderArgs(dive, dive)), "is the input folder", "");
  ExpectRefused(Rcm(FolderArgs(dive, dive + "/left/")), "is the input folder",
                dive + "/left");
  // Both input folders untouched.
  EXPECT_EQ(std::distance(fs::directory_iterator(dive + "/left"),
                          fs::directory_iterator()),
            kFrames);
}

TEST(UndistortCli, FailedRerunLeavesNoCamchainOfTheEarlierRun) {
  // A rerun into a finished output that fails while writing images must
  // not leave the first run's camchain to make it look complete.
  const std::string dive = Dive();
  const std::string out = Folder("out");
  ASSERT_EQ(Rcm(FolderArgs(dive, out)).exit_code, 0);
  ASSERT_TRUE(fs::exists(out + "/camchain.yaml"));
  // The second pair replaced by images of another size.
  cv::Mat small(kHeight / 2, kWidth / 2, CV_8UC1, cv::Scalar(128));
  ASSERT_TRUE(WritePng(small, dive + "/left/000001.png").ok());
  ASSERT_TRUE(WritePng(small, dive + "/right/000001.png").ok());
  const RunResult result = Rcm(With(FolderArgs(dive, out), {"--fit", "full"}));
  ExpectRefused(result,
                "left/000001.png: image is 120x90 but the calibration's cam0 "
                "is 240x180",
                out);
}

#ifdef RCM_HAVE_ROSBAG
// The dive as a bag: mono8 images on /cam0/image_raw and /cam1/image_raw
// with an unrelated topic in between.
std::string DiveBag(const std::string& dive) {
  const std::string path = test::TempFilePath("dive.bag");
  fs::remove(path);
  StatusOr<BagImageWriter> writer = BagImageWriter::Create(path);
  EXPECT_TRUE(writer.ok()) << writer.status().message();
  for (int i = 0; i < kFrames; ++i) {
    char name[32];
    std::snprintf(name, sizeof(name), "/%06d.png", i);
    const double stamp = 1700000000.0 + 0.05 * i;
    for (const char* side : {"left", "right"}) {
      const std::string topic =
          std::string(side) == "left" ? "/cam0/image_raw" : "/cam1/image_raw";
      EXPECT_TRUE(
          writer
              ->WriteImage(topic, stamp,
                           ReadImage(dive + "/" + side + name, true).value(),
                           "mono8", side)
              .ok());
    }
    EXPECT_TRUE(writer
                    ->WriteImage("/other/image", stamp + 0.01,
                                 cv::Mat(4, 4, CV_8UC1, cv::Scalar(7)), "mono8",
                                 "other")
                    .ok());
  }
  EXPECT_TRUE(writer->Close().ok());
  return path;
}

TEST(UndistortCli, BagGivesACorrectedBagAndItsCamchain) {
  const std::string dive = Dive();
  const std::string bag = DiveBag(dive);
  const std::string out = test::TempFilePath("corrected.bag");
  const std::string camchain_path =
      test::TempFilePath("corrected-camchain.yaml");
  fs::remove(out);
  fs::remove(camchain_path);
  const RunResult result =
      Rcm({"undistort", "--calib", dive + "/rig.yaml", "--n", "1.333", "--bag",
           bag, "--left-topic", "/cam0/image_raw", "--right-topic",
           "/cam1/image_raw", "--out", out, "--rectify", "--json"});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const nlohmann::json json = nlohmann::json::parse(result.out);
  EXPECT_EQ(json["images_written"].get<int>(), 2 * kFrames);
  EXPECT_EQ(json["bag"]["camera_info_topics"][0], "/cam0/camera_info");
  EXPECT_EQ(json["bag"]["copied_messages"].get<int>(), kFrames);
  // The camchain next to the bag names the image topics.
  const Camchain camchain = ReadCamchain(camchain_path).value();
  EXPECT_EQ(camchain.cameras[0].rostopic, "/cam0/image_raw");
  EXPECT_EQ(camchain.cameras[1].rostopic, "/cam1/image_raw");
  EXPECT_EQ(camchain.cameras[0].camera.model(), LensModelId::kPinhole);
  // The bag's images are the library's corrected images.
  const StereoRig raw_rig = ReadStereoRig(dive + "/rig.yaml").value();
  VirtualPinholeRigOptions options;
  options.rectify = true;
  const VirtualPinholeRig rig =
      VirtualPinholeRig::Create(raw_rig, 1.333, options).value();
  BagStereoOptions bag_options;
  bag_options.left_topic = "/cam0/image_raw";
  bag_options.right_topic = "/cam1/image_raw";
  std::unique_ptr<StereoImageSource> source =
      OpenBagStereoSource(out, bag_options).value();
  ASSERT_EQ(source->NumPairs(), static_cast<size_t>(kFrames));
  for (size_t i = 0; i < source->NumPairs(); ++i) {
    const StereoImagePair pair = source->ReadPair(i).value();
    char name[32];
    std::snprintf(name, sizeof(name), "/%06zu.png", i);
    const cv::Mat raw_left = ReadImage(dive + "/left" + name, true).value();
    EXPECT_EQ(cv::norm(pair.left, rig.left().Correct(raw_left), cv::NORM_INF),
              0.0);
  }

  // The same bag to folders: names are the stamps in nanoseconds.
  const std::string folders = Folder("from_bag");
  const RunResult to_folders =
      Rcm({"undistort", "--calib", dive + "/rig.yaml", "--n", "1.333", "--bag",
           bag, "--left-topic", "/cam0/image_raw", "--right-topic",
           "/cam1/image_raw", "--out", folders});
  ASSERT_EQ(to_folders.exit_code, 0) << to_folders.err;
  EXPECT_TRUE(fs::exists(folders + "/left/1700000000000000000.png"));
  EXPECT_TRUE(fs::exists(folders + "/camchain.yaml"));

  // Refused: the output bag is the input, a missing topic.
  ExpectRefused(Rcm({"undistort", "--calib", dive + "/rig.yaml", "--n", "1.333",
                     "--bag", bag, "--left-topic", "/cam0/image_raw",
                     "--right-topic", "/cam1/image_raw", "--out", bag}),
                "is the input bag", "");
  const std::string bad = test::TempFilePath("bad.bag");
  ExpectRefused(Rcm({"undistort", "--calib", dive + "/rig.yaml", "--n", "1.333",
                     "--bag", bag, "--left-topic", "/cam0/image_raw",
                     "--right-topic", "/cam9/image_raw", "--out", bad}),
                "/cam9/image_raw", "");
  EXPECT_FALSE(fs::exists(bad));
  EXPECT_FALSE(fs::exists(test::TempFilePath("bad-camchain.yaml")));
  const std::string large = dive + "/large.yaml";
  ASSERT_TRUE(WriteCamchain(large, SmallCamchain(360, 270)).ok());
  ExpectRefused(Rcm({"undistort", "--calib", large, "--n", "1.333", "--bag",
                     bag, "--left-topic", "/cam0/image_raw", "--right-topic",
                     "/cam1/image_raw", "--out", bad}),
                "image is 240x180 but the calibration's cam", "");
  EXPECT_FALSE(fs::exists(bad));
  EXPECT_FALSE(fs::exists(test::TempFilePath("bad-camchain.yaml")));
}
#endif  // RCM_HAVE_ROSBAG

}  // namespace
}  // namespace rcm::undistort_cli_test

namespace rcm::undistort_cli_test {
namespace {

// Port blocks in the rig: the corrected images are made for the reference
// depth, stated in the report; the corrected camchain is a pinhole rig
// without port blocks.
TEST(UndistortCli, ThickPortIsCorrectedAtTheReferenceDepth) {
  const std::string dive = Dive();
  Camchain camchain = SmallCamchain();
  FlatPort port;
  port.air_gap = 0.008;
  port.glass_thickness = 0.006;
  for (CamchainCamera& camera : camchain.cameras) camera.port = port;
  const std::string rig = dive + "/thick_rig.yaml";
  ASSERT_TRUE(WriteCamchain(rig, camchain).ok());
  const std::string out = Folder("out");
  const RunResult result =
      Rcm({"undistort", "--calib", rig, "--n", "1.333", "--left",
           dive + "/left", "--right", dive + "/right", "--out", out,
           "--reference-depth", "1.5", "--json"});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const nlohmann::json json = nlohmann::json::parse(result.out);
  EXPECT_EQ(json["port"], "thick");
  EXPECT_DOUBLE_EQ(json["reference_depth_m"].get<double>(), 1.5);
  EXPECT_EQ(test::ReadWholeFile(out + "/camchain.yaml").find("port"),
            std::string::npos);
  const RunResult text = Rcm({"undistort", "--calib", rig, "--n", "1.333",
                              "--left", dive + "/left", "--right",
                              dive + "/right", "--out", Folder("text")});
  ASSERT_EQ(text.exit_code, 0) << text.err;
  EXPECT_NE(text.out.find("exact for points 2.00 m in front of the cameras"),
            std::string::npos)
      << text.out;
}

}  // namespace
}  // namespace rcm::undistort_cli_test
