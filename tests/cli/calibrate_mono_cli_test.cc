// rcm calibrate --left DIR alone: one camera, end to end on OpenCV's sample
// left images (opencv-doc; scripts/setup.sh installs it), its one-camera
// camchain, and that camchain refused by the stereo subcommands; and
// rcm calibrate --bag with --left-topic alone, on rendered views.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <random>
#include <string>
#include <vector>

#include "calib/opencv_calibrate_camera.h"
#include "calib/synthetic_target_views.h"
#include "cli/cli_runner.h"
#include "rcm/calib/calibration_target.h"
#include "rcm/calib/corners_file.h"
#include "rcm/calib/target_image.h"
#include "rcm/calib/target_renderer.h"
#include "rcm/io/calibration_covariance_file.h"
#include "rcm/io/camchain.h"
#include "support/temp_file.h"
#include "support/test_rigs.h"
#ifdef RCM_HAVE_ROSBAG
#include "rcm/rosbag/bag_image_writer.h"
#endif

namespace rcm::calibrate_mono_cli_test {
namespace {

namespace fs = std::filesystem;
using test::RunResult;

RunResult Rcm(const std::vector<std::string>& args) {
  return test::RunProgram(RCM_BINARY, args);
}

constexpr char kDataDir[] = "/usr/share/doc/opencv-doc/examples/data/";

// A folder of the first `count` of the sample's left images (its numbering
// skips 10).
std::string SampleLeftFolder(const std::string& name, int count = 13) {
  constexpr int kNumbers[] = {1, 2, 3, 4, 5, 6, 7, 8, 9, 11, 12, 13, 14};
  const std::string dir = test::TempFilePath(name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  for (int i = 0; i < count; ++i) {
    char file[32];
    std::snprintf(file, sizeof(file), "left%02d.jpg", kNumbers[i]);
    std::error_code error;
    fs::copy_file(std::string(kDataDir) + file, dir + "/" + file, error);
    EXPECT_FALSE(error) << "cannot copy " << kDataDir << file
                        << ": install opencv-doc (scripts/setup.sh)";
  }
  return dir;
}

std::vector<std::string> With(std::vector<std::string> args,
                              const std::vector<std::string>& more) {
  args.insert(args.end(), more.begin(), more.end());
  return args;
}

const std::vector<std::string>& BoardFlags() {
  static const std::vector<std::string> flags = {
      "--board", "chessboard", "--cols",   "9",
      "--rows",  "6",          "--square", "0.025"};
  return flags;
}

void ExpectOneLineError(const RunResult& result, int exit_code,
                        const std::string& needle) {
  EXPECT_EQ(result.exit_code, exit_code) << result.err;
  EXPECT_TRUE(test::IsOneLine(result.err)) << "stderr:\n" << result.err;
  EXPECT_NE(result.err.find(needle), std::string::npos) << result.err;
}

// The acceptance through the executable: the camchain of
// `rcm calibrate --left` alone, flat board, equals cv::calibrateCamera on
// the corners the run detected (--corners-out) within 0.01 px RMS and
// 0.1 px in each intrinsic (mono_calibration_opencv_sample_test.cc holds
// the library to the same, and says why).
TEST(CalibrateMonoCli, OpenCvSampleLeftImagesEqualCalibrateCamera) {
  constexpr double kRmsTolerancePx = 0.01;
  constexpr double kIntrinsicsTolerancePx = 0.1;
  const std::string left = SampleLeftFolder("left");
  const std::string out = test::TempFilePath("out");
  fs::remove_all(out);
  fs::create_directories(out);
  const std::string corners = out + "/corners.vnl";
  const RunResult result = Rcm(
      With({"calibrate", "--left", left, "--out", out + "/one.yaml",
            "--flat-board", "--folds", "3", "--corners-out", corners, "--json"},
           BoardFlags()));
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const nlohmann::json json = nlohmann::json::parse(result.out);
  EXPECT_EQ(json["cameras"], 1);
  EXPECT_EQ(json["views_used"], 13);
  EXPECT_EQ(json["outliers"], 0);
  EXPECT_FALSE(json.contains("cam1"));
  EXPECT_FALSE(json.contains("cam1_from_cam0"));
  EXPECT_FALSE(json["projection_uncertainty"].contains("cam1"));
  EXPECT_GT(json["projection_uncertainty"]["cam0"]["median_px"].get<double>(),
            0.0);
  EXPECT_TRUE(json["cross_validation"]["parameters"].contains("cam0 fx"));
  EXPECT_FALSE(json["cross_validation"]["parameters"].contains("baseline"));

  // A camchain of cam0 alone, its sidecar of one camera, the report of one.
  const Camchain camchain = ReadCamchain(out + "/one.yaml").value();
  ASSERT_EQ(camchain.cameras.size(), 1u);
  const Camera& camera = camchain.cameras[0].camera;
  EXPECT_EQ(camera.model(), LensModelId::kRadTan);
  const CalibrationCovarianceFile sidecar =
      ReadCalibrationCovariance(out + "/one-covariance.yaml").value();
  ASSERT_EQ(sidecar.cameras.size(), 1u);
  EXPECT_EQ(sidecar.cameras[0].intrinsics_covariance.rows(), 8);
  for (const char* file :
       {"calibration.json", "per_view.csv", "per_view_rms.png",
        "residuals_cam0.png", "coverage_cam0.png",
        "intrinsics_only_uncertainty_cam0.png",
        "projection_uncertainty_cam0.png"}) {
    EXPECT_TRUE(fs::exists(out + "/one-report/" + file)) << file;
  }
  EXPECT_FALSE(fs::exists(out + "/one-report/residuals_cam1.png"));

  const calib::CalibrationTarget board =
      calib::MakeCheckerboardTarget(9, 6, 0.025).value();
  const std::vector<calib::CornersFileImage> images =
      calib::ReadCornersFile(corners, calib::NumTargetPoints(board)).value();
  std::vector<calib::StereoView> views;
  for (const calib::CornersFileImage& image : images) {
    views.emplace_back();
    views.back().left = image.observation;
  }
  ASSERT_EQ(views.size(), 13u);
  const calib::test::OpenCvCamera opencv =
      calib::test::OpenCvCalibrateCamera(board, views, 640, 480);
  std::printf(
      "rcm calibrate --left: rms %.6f px  fx %.4f fy %.4f cx %.4f "
      "cy %.4f\ncv::calibrateCamera: rms %.6f px  fx %.4f fy %.4f "
      "cx %.4f cy %.4f\n",
      json["rms_px"].get<double>(), camera.fx(), camera.fy(), camera.cx(),
      camera.cy(), opencv.rms_px, opencv.fx, opencv.fy, opencv.cx, opencv.cy);
  EXPECT_NEAR(json["rms_px"].get<double>(), opencv.rms_px, kRmsTolerancePx);
  EXPECT_NEAR(camera.fx(), opencv.fx, kIntrinsicsTolerancePx);
  EXPECT_NEAR(camera.fy(), opencv.fy, kIntrinsicsTolerancePx);
  EXPECT_NEAR(camera.cx(), opencv.cx, kIntrinsicsTolerancePx);
  EXPECT_NEAR(camera.cy(), opencv.cy, kIntrinsicsTolerancePx);

  // The same corners from the file (--corners with --left alone), the
  // text report: one camera, no baseline; the same camchain.
  const RunResult text = Rcm(With(
      {"calibrate", "--corners", corners, "--left", left, "--image-size",
       "640,480", "--out", out + "/again.yaml", "--flat-board", "--folds", "0"},
      BoardFlags()));
  ASSERT_EQ(text.exit_code, 0) << text.err;
  EXPECT_NE(text.out.find("13 views used (one camera)"), std::string::npos)
      << text.out;
  EXPECT_NE(text.out.find("cam0 radtan  fx "), std::string::npos) << text.out;
  EXPECT_EQ(text.out.find("baseline"), std::string::npos) << text.out;
  EXPECT_EQ(text.out.find("cam1"), std::string::npos) << text.out;
  const Camchain again = ReadCamchain(out + "/again.yaml").value();
  ASSERT_EQ(again.cameras.size(), 1u);
  for (int i = 0; i < camera.num_params(); ++i) {
    EXPECT_NEAR(again.cameras[0].camera.params()[i], camera.params()[i],
                1e-9 * std::max(1.0, std::abs(camera.params()[i])));
  }
}

// The one-camera path end to end without images (cheap enough for the
// sanitizers): a corners file of synthetic views of one camera, --left
// naming its rows, the leave-out folds on.
TEST(CalibrateMonoCli, CornersFileOfOneCameraGivesCamchainSidecarAndReport) {
  const Camera truth = rcm::test::EurocRadtanCamera();
  const calib::CalibrationTarget board =
      calib::MakeCheckerboardTarget(9, 6, 0.04).value();
  const std::vector<Eigen::Vector3d> points = calib::TargetPoints(board);
  std::mt19937 rng(3);
  std::vector<calib::CornersFileImage> images;
  for (const Rigid3d& pose : calib::test::BoardPoses(truth, board, 8, 7)) {
    images.push_back(
        {"cam/" + std::to_string(images.size()) + ".png",
         calib::test::ObserveTargetWith(truth, calib::test::InAir(truth), pose,
                                        points, 0.1, &rng)});
  }
  const std::string out = test::TempFilePath("out");
  fs::remove_all(out);
  fs::create_directories(out);
  ASSERT_TRUE(calib::WriteCornersFile(out + "/corners.vnl", images,
                                      calib::NumTargetPoints(board))
                  .ok());
  const RunResult result =
      Rcm({"calibrate", "--corners", out + "/corners.vnl", "--left", "cam/*",
           "--image-size", "752,480", "--board", "chessboard", "--cols", "9",
           "--rows", "6", "--square", "0.04", "--folds", "2", "--out",
           out + "/one.yaml"});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_NE(result.out.find("8 views used (one camera)"), std::string::npos)
      << result.out;
  EXPECT_NE(result.out.find("board flatness: bowl "), std::string::npos)
      << result.out;
  const Camchain camchain = ReadCamchain(out + "/one.yaml").value();
  ASSERT_EQ(camchain.cameras.size(), 1u);
  // 0.1 px of noise on 8 views: the focal lengths within 1 %.
  EXPECT_NEAR(camchain.cameras[0].camera.fx() / truth.fx(), 1.0, 1e-2);
  EXPECT_EQ(
      ReadCalibrationCovariance(out + "/one-covariance.yaml")->cameras.size(),
      1u);
  const nlohmann::json json = nlohmann::json::parse(
      test::ReadWholeFile(out + "/one-report/calibration.json"));
  EXPECT_EQ(json["cameras"], 1);
  EXPECT_EQ(json["cross_validation"]["folds"], 2);
  EXPECT_TRUE(fs::exists(out + "/one-report/per_view_rms.png"));
}

TEST(CalibrateMonoCli, BadInputIsOneLine) {
  const std::string out = test::TempFilePath("out");
  fs::remove_all(out);
  // Two views of the board: too few for a camera.
  const std::string two = SampleLeftFolder("two", 2);
  ExpectOneLineError(
      Rcm(With({"calibrate", "--left", two, "--out", out + "/one.yaml",
                "--folds", "0"},
               BoardFlags())),
      1, "cam0 sees the target with at least 6 corners in 2 view(s)");
  // No board in any image.
  const std::string blank = test::TempFilePath("blank");
  fs::remove_all(blank);
  fs::create_directories(blank);
  for (const char* name : {"a.png", "b.png", "c.png"}) {
    ASSERT_TRUE(cv::imwrite(blank + "/" + name,
                            cv::Mat(480, 640, CV_8UC1, cv::Scalar(90))));
  }
  ExpectOneLineError(
      Rcm(With({"calibrate", "--left", blank, "--out", out + "/one.yaml"},
               BoardFlags())),
      1, "the target was found in none of the 3 images");
  // --right alone.
  ExpectOneLineError(
      Rcm(With({"calibrate", "--right", two, "--out", out + "/one.yaml"},
               BoardFlags())),
      1, "--left and --right go together");
  EXPECT_FALSE(fs::exists(out + "/one.yaml"));
}

#ifdef RCM_HAVE_ROSBAG
// One camera from a bag: --left-topic without --right-topic, as --left
// alone from a folder. 8 rendered views of a 480x360 camera (its right
// camera's topic in the bag too, and not read); about a second.
TEST(CalibrateMonoCli, BagWithTheLeftTopicAloneCalibratesOneCamera) {
  const Camera truth =
      Camera::Create(LensModelId::kRadTan, 480, 360,
                     {300.0, 301.0, 242.0, 178.0}, {-0.2, 0.05, 4e-4, -3e-4})
          .value();
  const calib::CalibrationTarget board =
      calib::MakeCheckerboardTarget(7, 5, 0.04).value();
  const calib::TargetRenderer renderer =
      calib::TargetRenderer::Create(truth,
                                    calib::DrawTargetImage(board, 3000.0))
          .value();
  calib::TargetRenderOptions render_options;
  render_options.noise_sigma = 2.0;
  const std::string out = test::TempFilePath("out");
  fs::remove_all(out);
  fs::create_directories(out);
  const std::string bag = out + "/one.bag";
  StatusOr<BagImageWriter> writer = BagImageWriter::Create(bag);
  ASSERT_TRUE(writer.ok()) << writer.status().message();
  const std::vector<Rigid3d> poses =
      calib::test::BoardPoses(truth, board, 8, 5, 0.5, 0.8, 30.0);
  for (size_t i = 0; i < poses.size(); ++i) {
    const double stamp = 1700000000.0 + 0.5 * static_cast<double>(i);
    render_options.seed = static_cast<unsigned>(i);
    ASSERT_TRUE(writer
                    ->WriteImage("/cam0/image_raw", stamp,
                                 renderer.Render(poses[i], render_options),
                                 "mono8", "cam0")
                    .ok());
    ASSERT_TRUE(writer
                    ->WriteImage("/cam1/image_raw", stamp,
                                 cv::Mat(360, 480, CV_8UC1, cv::Scalar(90)),
                                 "mono8", "cam1")
                    .ok());
  }
  ASSERT_TRUE(writer->Close().ok());

  const RunResult result =
      Rcm({"calibrate", "--bag", bag, "--left-topic", "/cam0/image_raw",
           "--board", "chessboard", "--cols", "7", "--rows", "5", "--square",
           "0.04", "--folds", "0", "--out", out + "/one.yaml"});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_NE(result.out.find("(/cam0/image_raw, left camera only): 8 images"),
            std::string::npos)
      << result.out;
  EXPECT_NE(result.out.find("8 views used (one camera)"), std::string::npos)
      << result.out;
  EXPECT_EQ(result.out.find("cam1"), std::string::npos) << result.out;
  const Camchain camchain = ReadCamchain(out + "/one.yaml").value();
  ASSERT_EQ(camchain.cameras.size(), 1u);
  const Camera& camera = camchain.cameras[0].camera;
  EXPECT_EQ(camchain.cameras[0].rostopic, "/cam0/image_raw");
  EXPECT_EQ(camera.width(), 480);
  EXPECT_EQ(camera.height(), 360);
  // Rendered views, 2 grey levels of noise: the focal lengths within 1 %.
  EXPECT_NEAR(camera.fx() / truth.fx(), 1.0, 1e-2);
  EXPECT_NEAR(camera.fy() / truth.fy(), 1.0, 1e-2);
  EXPECT_EQ(
      ReadCalibrationCovariance(out + "/one-covariance.yaml")->cameras.size(),
      1u);

  // The stereo subcommands read pairs: the left topic alone is one line.
  const std::string rig = out + "/rig.yaml";
  ASSERT_TRUE(
      WriteCamchain(rig, CamchainFromStereoRig(test::EurocRadtanTwinRig()))
          .ok());
  ExpectOneLineError(
      Rcm({"estimate", "--calib", rig, "--bag", bag, "--left-topic",
           "/cam0/image_raw"}),
      1,
      "--bag needs --right-topic too: this command reads stereo pairs (only "
      "rcm calibrate takes one camera's --left-topic alone)");
  // --right-topic alone is no camera.
  ExpectOneLineError(
      Rcm({"calibrate", "--bag", bag, "--right-topic", "/cam1/image_raw",
           "--board", "chessboard", "--cols", "7", "--rows", "5", "--square",
           "0.04", "--out", out + "/right.yaml"}),
      1, "--right-topic needs --left-topic");
  EXPECT_FALSE(fs::exists(out + "/right.yaml"));
}
#endif  // RCM_HAVE_ROSBAG

// A one-camera camchain given to the subcommands that need a stereo pair:
// one line that says so, exit 1.
TEST(CalibrateMonoCli, OneCameraCamchainIsRefusedByStereoCommands) {
  Camchain camchain;
  camchain.cameras.push_back(
      {Camera::Create(LensModelId::kRadTan, 640, 480,
                      {530.0, 531.0, 320.0, 240.0}, {-0.2, 0.1, 0.0, 0.0})
           .value(),
       std::nullopt,
       std::nullopt,
       std::nullopt,
       {},
       ""});
  const std::string one = test::TempFilePath("one.yaml");
  ASSERT_TRUE(WriteCamchain(one, camchain).ok());
  const std::string out = test::TempFilePath("out");
  const std::string needle =
      one +
      " has one camera (cam0); a stereo rig needs two: calibrate the "
      "pair with --left and --right";
  ExpectOneLineError(
      Rcm({"export", "--calib", one, "--n", "1.333", "--out", out}), 1, needle);
  ExpectOneLineError(Rcm({"estimate", "--calib", one, "--matches",
                          test::TempFilePath("matches.csv")}),
                     1, needle);
  const std::string images = SampleLeftFolder("images", 1);
  ExpectOneLineError(Rcm({"undistort", "--calib", one, "--n", "1.333", "--left",
                          images, "--right", images, "--out", out}),
                     1, needle);
}

}  // namespace
}  // namespace rcm::calibrate_mono_cli_test
