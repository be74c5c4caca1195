// rcm calibrate --underwater --port dome through the executable: corners
// files of synthetic views through decentered domes, the camchain with the
// dome blocks and the JSON the issue names; bad input in one line.
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <random>
#include <string>
#include <vector>

#include "calib/synthetic_target_views.h"
#include "cli/cli_runner.h"
#include "rcm/calib/calibration_target.h"
#include "rcm/calib/corners_file.h"
#include "rcm/camera/dome_port_camera.h"
#include "rcm/io/camchain.h"
#include "support/temp_file.h"
#include "support/test_rigs.h"

namespace rcm::calibrate_dome_cli_test {
namespace {

namespace fs = std::filesystem;
using test::RunResult;

RunResult Rcm(const std::vector<std::string>& args) {
  return test::RunProgram(RCM_BINARY, args);
}

calib::CalibrationTarget Board() {
  return calib::MakeCheckerboardTarget(9, 6, 0.04).value();
}

std::vector<std::string> With(std::vector<std::string> args,
                              const std::vector<std::string>& more) {
  args.insert(args.end(), more.begin(), more.end());
  return args;
}

// The flags of the 4-inch acrylic dome, from its radii.
const std::vector<std::string>& DomeFlags() {
  static const std::vector<std::string> flags = {"--port",
                                                 "dome",
                                                 "--dome-inner-radius",
                                                 "0.04355",
                                                 "--dome-outer-radius",
                                                 "0.0473",
                                                 "--glass-index",
                                                 "1.495"};
  return flags;
}

const std::vector<std::string>& BoardFlags() {
  static const std::vector<std::string> flags = {
      "--board", "chessboard", "--cols",   "9",
      "--rows",  "6",          "--square", "0.04"};
  return flags;
}

// A folder with the air camchain of `cameras` (cam1 at the realistic rig's
// extrinsics) and the corners file of noise-free views through each
// camera's dome in water of index 1.333.
struct DomeDive {
  std::string dir;
  std::string air;
  std::string corners;
};
DomeDive WriteDomeDive(const std::string& name,
                       const std::vector<Eigen::Vector3d>& decentering) {
  const StereoRig rig = rcm::test::AlphasenseRealisticRig();
  const Camera cameras[2] = {rig.left(), rig.right()};
  DomeDive dive;
  dive.dir = test::TempFilePath(name);
  fs::remove_all(dive.dir);
  fs::create_directories(dive.dir);
  Camchain air = CamchainFromStereoRig(rig);
  air.cameras.resize(decentering.size(), air.cameras[0]);
  dive.air = dive.dir + "/air.yaml";
  EXPECT_TRUE(WriteCamchain(dive.air, air).ok());
  const std::vector<Eigen::Vector3d> points = calib::TargetPoints(Board());
  const std::vector<Rigid3d> poses = calib::test::BoardPoses(
      rig.left(), Board(), 10, 5, 0.4, 1.4, 35.0, 1.333);
  std::vector<calib::CornersFileImage> images;
  std::mt19937 rng(1);
  for (size_t c = 0; c < decentering.size(); ++c) {
    const DomePortCamera through =
        DomePortCamera::Create(cameras[c],
                               ::rcm::test::AcrylicDome(decentering[c]), 1.333)
            .value();
    const Rigid3d cam_from_cam0 = c == 0 ? Rigid3d() : rig.right_from_left();
    for (size_t v = 0; v < poses.size(); ++v) {
      images.push_back(
          {(c == 0 ? "left/" : "right/") + std::to_string(v) + ".png",
           calib::test::ObserveTargetWith(
               cameras[c],
               [&](const Eigen::Vector3d& p) {
                 return through.ImageFromPoint(p);
               },
               cam_from_cam0 * poses[v], points, 0.0, &rng)});
    }
  }
  dive.corners = dive.dir + "/corners.vnl";
  EXPECT_TRUE(calib::WriteCornersFile(dive.corners, images,
                                      calib::NumTargetPoints(Board()))
                  .ok());
  return dive;
}

void ExpectOneLineError(const RunResult& result, const std::string& needle) {
  EXPECT_NE(result.exit_code, 0) << result.err;
  EXPECT_TRUE(test::IsOneLine(result.err)) << "stderr:\n" << result.err;
  EXPECT_NE(result.err.find(needle), std::string::npos) << result.err;
}

// The corners file holds pixels to 1e-9 px or better, so the decentering
// comes back to ~1e-9 m.
constexpr double kCornersFileDecenteringTolerance = 1e-7;  // meters

TEST(CalibrateDomeCli, OneCameraGivesDecenteringAndDomeCamchain) {
  const Eigen::Vector3d truth(0.002, -0.001, 0.0072);
  const DomeDive dive = WriteDomeDive("dome_one", {truth});
  const RunResult result = Rcm(
      With(With({"calibrate", "--underwater", "--air", dive.air, "--corners",
                 dive.corners, "--left", "left/*", "--image-size", "720,540",
                 "--folds", "0", "--json", "--out", dive.dir + "/water.yaml"},
                DomeFlags()),
           BoardFlags()));
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const nlohmann::json json = nlohmann::json::parse(result.out);
  EXPECT_EQ(json["port"], "dome");
  EXPECT_EQ(json["cameras"], 1);
  ASSERT_EQ(json["decentering_m"].size(), 1u);
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(json["decentering_m"][0][i].get<double>(), truth[i],
                kCornersFileDecenteringTolerance);
    EXPECT_GT(json["decentering_sigma_m"][0][i].get<double>(), 0.0);
  }
  EXPECT_LT(json["rms_px"].get<double>(), 1e-6);
  EXPECT_TRUE(json["conventional"]["ok"].get<bool>());
  EXPECT_GT(json["conventional"]["rms_px"].get<double>(),
            json["rms_px"].get<double>());
  EXPECT_FALSE(json["n_estimated"].get<bool>());
  EXPECT_EQ(json["candidates"].size(), 2u);
  // One weight per view, each within [1/16, 16] of the median view's.
  ASSERT_EQ(json["view_weights"].size(), json["views_used"].get<size_t>());
  for (const nlohmann::json& weight : json["view_weights"]) {
    EXPECT_GE(weight.get<double>(), 1.0 / 16.0);
    EXPECT_LE(weight.get<double>(), 16.0);
  }
  const Camchain written = ReadCamchain(dive.dir + "/water.yaml").value();
  ASSERT_EQ(written.cameras.size(), 1u);
  ASSERT_TRUE(written.cameras[0].dome.has_value());
  EXPECT_NEAR((written.cameras[0].dome->decentering - truth).norm(), 0.0,
              kCornersFileDecenteringTolerance);
  EXPECT_NEAR(written.cameras[0].dome->thickness, 0.00375, 1e-12);
  EXPECT_TRUE(fs::exists(dive.dir + "/water-report/underwater.json"));
  EXPECT_TRUE(fs::exists(dive.dir + "/water-report/residuals_cam0.png"));
}

// The joint calibration: air views through the same dome (n = 1) in a
// corners file, the lens estimated from both media.
TEST(CalibrateDomeCli, AirViewsThroughTheDomeEstimateTheLens) {
  const Eigen::Vector3d truth(0.0005, -0.0005, 0.0072);
  const DomeDive dive = WriteDomeDive("dome_joint", {truth});
  const Camera camera = rcm::test::AlphasenseRealisticRig().left();
  const DomePortCamera in_air =
      DomePortCamera::Create(camera, ::rcm::test::AcrylicDome(truth), 1.0)
          .value();
  std::vector<calib::CornersFileImage> images;
  std::mt19937 rng(2);
  const std::vector<Eigen::Vector3d> points = calib::TargetPoints(Board());
  for (const Rigid3d& pose :
       calib::test::BoardPoses(camera, Board(), 10, 9, 0.4, 1.2)) {
    images.push_back(
        {"air/" + std::to_string(images.size()) + ".png",
         calib::test::ObserveTargetWith(
             camera,
             [&](const Eigen::Vector3d& p) { return in_air.ImageFromPoint(p); },
             pose, points, 0.0, &rng)});
  }
  const std::string air_corners = dive.dir + "/air_corners.vnl";
  ASSERT_TRUE(calib::WriteCornersFile(air_corners, images,
                                      calib::NumTargetPoints(Board()))
                  .ok());
  const RunResult result = Rcm(With(With({"calibrate",
                                          "--underwater",
                                          "--air",
                                          dive.air,
                                          "--corners",
                                          dive.corners,
                                          "--left",
                                          "left/*",
                                          "--image-size",
                                          "720,540",
                                          "--air-corners",
                                          air_corners,
                                          "--air-left",
                                          "air/*",
                                          "--same-board",
                                          "--folds",
                                          "0",
                                          "--json",
                                          "--out",
                                          dive.dir + "/water.yaml"},
                                         DomeFlags()),
                                    BoardFlags()));
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const nlohmann::json json = nlohmann::json::parse(result.out);
  EXPECT_TRUE(json["lenses_estimated"].get<bool>());
  EXPECT_EQ(json["air_views"]["views_used"], 10);
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(json["decentering_m"][0][i].get<double>(), truth[i],
                kCornersFileDecenteringTolerance);
  }
  const Camchain written = ReadCamchain(dive.dir + "/water.yaml").value();
  EXPECT_NEAR(written.cameras[0].camera.fx(), camera.fx(), 1e-4);
}

TEST(CalibrateDomeCli, StereoWithNEstimated) {
  const Eigen::Vector3d left(0.0015, 0.001, 0.006);
  const Eigen::Vector3d right(-0.001, 0.002, 0.008);
  const DomeDive dive = WriteDomeDive("dome_two", {left, right});
  const RunResult result =
      Rcm(With(With({"calibrate", "--underwater", "--estimate-n", "--air",
                     dive.air, "--corners", dive.corners, "--left", "left/*",
                     "--right", "right/*", "--image-size", "720,540", "--folds",
                     "0", "--out", dive.dir + "/water.yaml"},
                    DomeFlags()),
               BoardFlags()));
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_NE(result.out.find("cam1: dome centre ("), std::string::npos)
      << result.out;
  EXPECT_NE(result.out.find("weakly observable through a dome"),
            std::string::npos)
      << result.out;
  const nlohmann::json json = nlohmann::json::parse(
      test::ReadWholeFile(dive.dir + "/water-report/underwater.json"));
  EXPECT_EQ(json["cameras"], 2);
  EXPECT_NEAR(json["n"].get<double>(), 1.333, 1e-7);
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(json["decentering_m"][0][i].get<double>(), left[i],
                kCornersFileDecenteringTolerance);
    EXPECT_NEAR(json["decentering_m"][1][i].get<double>(), right[i],
                kCornersFileDecenteringTolerance);
  }
  EXPECT_EQ(ReadCamchain(dive.dir + "/water.yaml").value().cameras.size(), 2u);
}

TEST(CalibrateDomeCli, BadInputIsOneLine) {
  const DomeDive dive =
      WriteDomeDive("dome_bad", {Eigen::Vector3d(0, 0, 0.005)});
  const std::vector<std::string> base =
      With({"calibrate", "--underwater", "--air", dive.air, "--corners",
            dive.corners, "--left", "left/*", "--image-size", "720,540",
            "--out", dive.dir + "/bad.yaml"},
           BoardFlags());
  ExpectOneLineError(Rcm(With(base, {"--port", "dome"})),
                     "--port dome needs --dome-inner-radius");
  ExpectOneLineError(Rcm(With(base, {"--port", "dome", "--dome-inner-radius",
                                     "0.04355", "--dome-thickness", "0.005",
                                     "--dome-outer-radius", "0.0473"})),
                     "not the 0.005 m given");
  ExpectOneLineError(Rcm(With(base, {"--port", "dome", "--dome-inner-radius",
                                     "0.04355", "--dome-thickness", "0.00375",
                                     "--dome-decentering", "0,0,0.05"})),
                     "outside the inner sphere");
  ExpectOneLineError(Rcm(With(base, {"--port", "globe"})),
                     "--port globe: expected flat or dome");
  ExpectOneLineError(Rcm(With(base, {"--estimate-n"})),
                     "--estimate-n goes with --underwater --port dome");
  ExpectOneLineError(Rcm(With(With(base, DomeFlags()), {"--estimate-air-gap"})),
                     "describe flat ports");
  // A one-camera air camchain with a stereo pair's corners.
  const DomeDive pair = WriteDomeDive(
      "dome_pair",
      {Eigen::Vector3d(0, 0, 0.005), Eigen::Vector3d(0, 0, 0.005)});
  ExpectOneLineError(
      Rcm(With(
          With({"calibrate", "--underwater", "--air", dive.air, "--corners",
                pair.corners, "--left", "left/*", "--right", "right/*",
                "--image-size", "720,540", "--out", dive.dir + "/bad2.yaml"},
               DomeFlags()),
          BoardFlags())),
      "has one camera (cam0)");
  EXPECT_FALSE(fs::exists(dive.dir + "/bad.yaml"));
  EXPECT_FALSE(fs::exists(dive.dir + "/bad2.yaml"));
}

// A camchain with dome blocks through the tools that need a central camera:
// rcm export and rcm undistort make each camera central at
// --reference-depth and report the parallax at other depths.
TEST(DomeRigCli, ExportAndUndistortAtTheReferenceDepth) {
  const std::string dir = test::TempFilePath("dome_rig");
  fs::remove_all(dir);
  fs::create_directories(dir + "/left");
  fs::create_directories(dir + "/right");
  Camchain camchain =
      CamchainFromStereoRig(rcm::test::AlphasenseRealisticRig());
  camchain.cameras[0].port.reset();
  camchain.cameras[1].port.reset();
  camchain.cameras[0].dome =
      ::rcm::test::AcrylicDome(Eigen::Vector3d(0.001, 0.0, 0.007));
  camchain.cameras[1].dome =
      ::rcm::test::AcrylicDome(Eigen::Vector3d(-0.001, 0.0, 0.006));
  ASSERT_TRUE(WriteCamchain(dir + "/rig.yaml", camchain).ok());
  const RunResult exported =
      Rcm({"export", "--calib", dir + "/rig.yaml", "--n", "1.333",
           "--reference-depth", "1.5", "--out", dir + "/water.yaml", "--json"});
  ASSERT_EQ(exported.exit_code, 0) << exported.err;
  const nlohmann::json json = nlohmann::json::parse(exported.out);
  EXPECT_EQ(json["port"], "dome");
  EXPECT_EQ(json["reference_depth_m"], 1.5);
  ASSERT_EQ(json["dome_parallax_px"].size(), 2u);
  // Exact at 1.5 m, off at the other depths (the smallest sampled is the
  // nearest, 0.3 m).
  const nlohmann::json& left = json["dome_parallax_px"][0];
  EXPECT_GT(left.front()["max_px"].get<double>(), 0.1);
  EXPECT_TRUE(fs::exists(dir + "/water.yaml"));

  const cv::Mat gray(540, 720, CV_8UC1, cv::Scalar(128));
  ASSERT_TRUE(cv::imwrite(dir + "/left/0.png", gray));
  ASSERT_TRUE(cv::imwrite(dir + "/right/0.png", gray));
  const RunResult undistorted =
      Rcm({"undistort", "--calib", dir + "/rig.yaml", "--n", "1.333", "--left",
           dir + "/left", "--right", dir + "/right", "--out", dir + "/out"});
  ASSERT_EQ(undistorted.exit_code, 0) << undistorted.err;
  EXPECT_NE(undistorted.out.find("dome (camchain port blocks): exact for "
                                 "points 2.00 m"),
            std::string::npos)
      << undistorted.out;
  EXPECT_TRUE(fs::exists(dir + "/out/left/0.png"));
  // A dome on one camera only is one line.
  camchain.cameras[1].dome.reset();
  ASSERT_TRUE(WriteCamchain(dir + "/half.yaml", camchain).ok());
  ExpectOneLineError(Rcm({"export", "--calib", dir + "/half.yaml", "--n",
                          "1.333", "--out", dir + "/half_water.yaml"}),
                     "cam1 has no dome port block, cam0 has one");
}

}  // namespace
}  // namespace rcm::calibrate_dome_cli_test
