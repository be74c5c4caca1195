// End-to-end tests of `rcm simulate`: what a user types, what they get.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "cli/cli_runner.h"
#include "rcm/calib/calibration_target.h"
#include "rcm/calib/target_detector.h"
#include "rcm/camera/dome_port_camera.h"
#include "rcm/camera/flat_port_camera.h"
#include "rcm/io/image_file.h"
#include "rcm/sim/reference_rigs.h"
#include "support/temp_file.h"
#include "support/test_rigs.h"

namespace rcm::simulate_cli_test {
namespace {

namespace fs = std::filesystem;
using test::IsOneLine;
using test::RunResult;

RunResult Rcm(const std::vector<std::string>& args) {
  return test::RunProgram(RCM_BINARY, args);
}

// A fresh output folder of the current test.
std::string Folder(const std::string& name) {
  const std::string folder = test::TempFilePath(name);
  fs::remove_all(folder);
  return folder;
}

// rcm simulate --out FOLDER and `flags`, a space-separated list.
RunResult Simulate(const std::string& folder, const std::string& flags) {
  std::vector<std::string> args = {"simulate", "--out", folder};
  std::istringstream words(flags);
  for (std::string word; words >> word;) args.push_back(word);
  return Rcm(args);
}

std::string ReadFile(const std::string& path) {
  std::ifstream file(path);
  std::stringstream text;
  text << file.rdbuf();
  return text.str();
}

// The rows of a CSV file, each split at its commas.
std::vector<std::vector<std::string>> ReadCsv(const std::string& path) {
  std::vector<std::vector<std::string>> rows;
  std::istringstream lines(ReadFile(path));
  for (std::string line; std::getline(lines, line);) {
    std::vector<std::string> fields;
    std::istringstream cells(line);
    for (std::string cell; std::getline(cells, cell, ',');) {
      fields.push_back(cell);
    }
    rows.push_back(fields);
  }
  return rows;
}

// The 11 numbers of the board.csv row at the start of `text`.
std::vector<double> BoardRow(const std::string& text) {
  std::istringstream fields(text);
  std::vector<double> values;
  for (std::string field;
       values.size() < 11 && std::getline(fields, field, ',');) {
    values.push_back(std::stod(field));
  }
  return values;
}

// cam0_from_target of a board.csv row (tx, ty, tz, qx, qy, qz, qw at 2-8).
Rigid3d Cam0FromTarget(const std::vector<double>& values) {
  Rigid3d cam0_from_target;
  cam0_from_target.translation =
      Eigen::Vector3d(values[2], values[3], values[4]);
  cam0_from_target.rotation =
      Eigen::Quaterniond(values[8], values[5], values[6], values[7])
          .toRotationMatrix();
  return cam0_from_target;
}

// Each detected corner within the detector's 0.3 px of where `camera`
// (FlatPortCamera or DomePortCamera) images the truth corner.
template <typename PortCamera>
void ExpectCornersWhereTheyProject(const calib::TargetObservation& seen,
                                   const calib::CalibrationTarget& target,
                                   const Rigid3d& cam0_from_target,
                                   const PortCamera& camera) {
  const std::vector<Eigen::Vector3d> corners = calib::TargetPoints(target);
  for (int k = 0; k < seen.size(); ++k) {
    const Eigen::Vector2d truth =
        camera.ImageFromPoint(cam0_from_target * corners[seen.point_ids[k]])
            .value();
    EXPECT_LT((seen.pixels[k] - truth).norm(), 0.3) << "corner " << k;
  }
}

void ExpectFailsWithOneLine(const RunResult& result, int exit_code,
                            const std::string& needle) {
  EXPECT_EQ(result.exit_code, exit_code) << result.err;
  EXPECT_TRUE(IsOneLine(result.err)) << "stderr:\n" << result.err;
  EXPECT_NE(result.err.find(needle), std::string::npos) << result.err;
  EXPECT_EQ(result.err.rfind("rcm simulate", 0), 0u) << result.err;
}

TEST(SimulateCli, WritesASequenceThatEstimateReads) {
  // Thin port, exact matches: rcm estimate reads the folder's camchain and
  // matches and returns the truth to 1e-9 (batch_refinement_test).
  const std::string folder = Folder("sequence");
  const RunResult simulated =
      Rcm({"simulate", "--out", folder, "--frames", "2", "--supersampling", "1",
           "--matches-per-frame", "200", "--n", "1.34"});
  ASSERT_EQ(simulated.exit_code, 0) << simulated.err;
  EXPECT_NE(simulated.out.find("wrote 2 frames"), std::string::npos)
      << simulated.out;
  for (const char* file :
       {"left/000000.png", "left/000001.png", "right/000001.png",
        "camchain.yaml", "truth.csv", "matches.csv", "simulation.json"}) {
    EXPECT_TRUE(fs::exists(folder + "/" + file)) << file;
  }
  EXPECT_EQ(ReadImage(folder + "/left/000001.png", true).value().size(),
            cv::Size(720, 540));
  const RunResult estimated =
      Rcm({"estimate", "--calib", folder + "/camchain.yaml", "--matches",
           folder + "/matches.csv", "--json"});
  ASSERT_EQ(estimated.exit_code, 0) << estimated.err;
  const nlohmann::json json = nlohmann::json::parse(estimated.out);
  EXPECT_NEAR(json["n"].get<double>(), 1.34, 1e-9);
  EXPECT_EQ(json["frames"].get<int>(), 2);
}

TEST(SimulateCli, SameSeedSameBytes) {
  const std::vector<std::string> flags = {
      "--frames",      "2",  "--supersampling",     "1",
      "--seed",        "9",  "--matches-per-frame", "50",
      "--match-noise", "0.5"};
  std::vector<std::string> folders;
  for (const char* name : {"a", "b"}) {
    folders.push_back(Folder(name));
    std::vector<std::string> args = {"simulate", "--out", folders.back()};
    args.insert(args.end(), flags.begin(), flags.end());
    ASSERT_EQ(Rcm(args).exit_code, 0);
  }
  for (const char* file : {"left/000000.png", "right/000001.png", "matches.csv",
                           "truth.csv", "camchain.yaml"}) {
    EXPECT_EQ(test::ReadWholeFile(folders[0] + "/" + file),
              test::ReadWholeFile(folders[1] + "/" + file))
        << file;
  }
}

TEST(SimulateCli, MediaSwitchesAreInTheTruth) {
  const std::string folder = Folder("media");
  const RunResult result =
      Rcm({"simulate", "--out", folder, "--noimages", "--matches-per-frame",
           "20", "--media", "water:2,air:1", "--json"});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const nlohmann::json json = nlohmann::json::parse(result.out);
  EXPECT_EQ(json["frames"].get<int>(), 3);
  EXPECT_EQ(json["switch_frames"], nlohmann::json::array({2}));
  const std::string truth = test::ReadWholeFile(folder + "/truth.csv");
  EXPECT_NE(truth.find("\n1,0.05,1.333,"), std::string::npos) << truth;
  EXPECT_NE(truth.find("\n2,0.1,1.0,"), std::string::npos) << truth;
  EXPECT_FALSE(fs::exists(folder + "/left"));
}

TEST(SimulateCli, DepthRangeMatchesWithoutImages) {
  // The correspondence generator alone: thin port, close range, exact.
  const std::string folder = Folder("depths");
  const RunResult simulated = Rcm(
      {"simulate", "--out", folder, "--noimages", "--depth-range", "0.3,1.5",
       "--matches-per-frame", "150", "--frames", "2", "--n", "1.6"});
  ASSERT_EQ(simulated.exit_code, 0) << simulated.err;
  const RunResult estimated =
      Rcm({"estimate", "--calib", folder + "/camchain.yaml", "--matches",
           folder + "/matches.csv", "--json"});
  ASSERT_EQ(estimated.exit_code, 0) << estimated.err;
  EXPECT_NEAR(nlohmann::json::parse(estimated.out)["n"].get<double>(), 1.6,
              1e-9);
  ExpectFailsWithOneLine(
      Rcm({"simulate", "--out", Folder("bad_range"), "--depth-range", "0.3",
           "--noimages", "--matches-per-frame", "5"}),
      2, "MIN,MAX");
  ExpectFailsWithOneLine(
      Rcm({"simulate", "--out", Folder("with_images"), "--depth-range",
           "0.3,1.5", "--matches-per-frame", "5"}),
      2, "no images");
}

// Cameras not triggered together: the matches of the delayed run differ
// from the synchronized run's in their right pixels only, and the frames
// then disagree beyond their noise, which rcm estimate reports (chi-square
// test) and counts in sigma_n. 10 ms at 20 deg/s and 0.2 m/s (sd) moves
// cam1's view by ~0.2 deg and ~2 mm per frame, several times the exact
// data's 1e-9.
TEST(SimulateCli, ExposureDelayMovesTheRightPixels) {
  const std::string synchronized = Folder("synchronized");
  const std::string delayed = Folder("delayed");
  const std::vector<std::string> base = {"simulate",
                                         "--noimages",
                                         "--depth-range",
                                         "0.5,6",
                                         "--matches-per-frame",
                                         "150",
                                         "--frames",
                                         "6"};
  std::vector<std::string> args = base;
  args.insert(args.end(), {"--out", synchronized});
  ASSERT_EQ(Rcm(args).exit_code, 0);
  args = base;
  args.insert(args.end(), {"--out", delayed, "--exposure-delay", "10,20,0.2"});
  const RunResult run = Rcm(args);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.out.find("cam1 exposes 10.0 ms after cam0"), std::string::npos)
      << run.out;
  const std::vector<std::vector<std::string>> a =
      ReadCsv(synchronized + "/matches.csv");
  const std::vector<std::vector<std::string>> b =
      ReadCsv(delayed + "/matches.csv");
  ASSERT_EQ(a.size(), b.size());
  ASSERT_GT(a.size(), 1u);
  // The same left pixels (frame, xl, yl), but for the few points whose
  // moved right pixel left the image and were drawn again; every right
  // pixel of a shared left pixel moved.
  std::map<std::vector<std::string>, std::vector<std::string>> right_of;
  for (size_t i = 1; i < a.size(); ++i) {
    ASSERT_GE(a[i].size(), 5u);
    right_of[{a[i][0], a[i][1], a[i][2]}] = {a[i][3], a[i][4]};
  }
  int shared = 0;
  for (size_t i = 1; i < b.size(); ++i) {
    ASSERT_GE(b[i].size(), 5u);
    const auto it = right_of.find({b[i][0], b[i][1], b[i][2]});
    if (it == right_of.end()) continue;
    ++shared;
    EXPECT_NE(it->second, (std::vector<std::string>{b[i][3], b[i][4]}));
  }
  EXPECT_GE(shared, static_cast<int>(0.9 * (b.size() - 1)));
  const nlohmann::json settings =
      nlohmann::json::parse(ReadFile(delayed + "/simulation.json"));
  EXPECT_DOUBLE_EQ(settings["exposure_delay"]["delay_ms"].get<double>(), 10.0);
  const RunResult estimated =
      Rcm({"estimate", "--calib", delayed + "/camchain.yaml", "--matches",
           delayed + "/matches.csv", "--json"});
  ASSERT_EQ(estimated.exit_code, 0) << estimated.err;
  const nlohmann::json json = nlohmann::json::parse(estimated.out);
  EXPECT_GT(json["consistency"]["inflation"].get<double>(), 1.0)
      << estimated.out;
  // With images: the right ones see the scene moved, the left ones not.
  const std::string images = Folder("delay_images");
  const std::string still = Folder("still_images");
  for (const std::string& folder : {images, still}) {
    std::vector<std::string> run = {
        "simulate", "--out",           folder, "--frames",
        "1",        "--supersampling", "1",    "--matches-per-frame",
        "20"};
    if (folder == images) run.insert(run.end(), {"--exposure-delay", "10,20"});
    ASSERT_EQ(Rcm(run).exit_code, 0) << folder;
  }
  EXPECT_EQ(test::ReadWholeFile(images + "/left/000000.png"),
            test::ReadWholeFile(still + "/left/000000.png"));
  EXPECT_NE(test::ReadWholeFile(images + "/right/000000.png"),
            test::ReadWholeFile(still + "/right/000000.png"));
  ExpectFailsWithOneLine(
      Rcm({"simulate", "--out", Folder("delay_bad"), "--noimages",
           "--matches-per-frame", "5", "--exposure-delay", "10"}),
      2, "MS,DEG_S");
  ExpectFailsWithOneLine(
      Rcm({"simulate", "--out", Folder("delay_big"), "--noimages",
           "--matches-per-frame", "5", "--exposure-delay", "500,5"}),
      2, "exposure delay");
}

TEST(SimulateCli, UsesTheCamerasOfAGivenRigFile) {
  // --left-camera cam1 --right-camera cam0 swaps the pair: the written
  // camchain's cam0 is the file's cam1 (fx 344.39...).
  const std::string folder = Folder("swapped");
  const RunResult result =
      Rcm({"simulate", "--out", folder, "--calib",
           std::string(RCM_SOURCE_DIR) +
               "/examples/data/alphasense_front_rectified.yaml",
           "--left-camera", "cam1", "--right-camera", "cam0", "--noimages",
           "--matches-per-frame", "20", "--frames", "1"});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const std::string camchain = test::ReadWholeFile(folder + "/camchain.yaml");
  const size_t cam0 = camchain.find("cam0:");
  const size_t cam1 = camchain.find("cam1:");
  const size_t fx = camchain.find("344.3933991977547");
  ASSERT_NE(fx, std::string::npos) << camchain;
  EXPECT_LT(cam0, fx);
  EXPECT_LT(fx, cam1);
}

TEST(SimulateCli, BadFlagsGiveOneLine) {
  const std::string folder = Folder("bad");
  ExpectFailsWithOneLine(Rcm({"simulate"}), 2, "--out is required");
  ExpectFailsWithOneLine(Rcm({"simulate", "--out", folder, "--n", "2.5"}), 1,
                         "outside [1, 2]");
  ExpectFailsWithOneLine(
      Rcm({"simulate", "--out", folder, "--media", "water:3,oil:2"}), 1,
      "--media");
  ExpectFailsWithOneLine(
      Rcm({"simulate", "--out", folder, "--air-gap", "-0.01"}), 1, "air_gap");
  ExpectFailsWithOneLine(Rcm({"simulate", "--out", folder, "--rig", "gopro"}),
                         1, "--rig");
  ExpectFailsWithOneLine(
      Rcm({"simulate", "--out", folder, "--calib", folder + "/missing.yaml"}),
      1, "missing.yaml");
  ExpectFailsWithOneLine(Rcm({"simulate", "--out", folder, "--noimages"}), 2,
                         "no data");
  ExpectFailsWithOneLine(
      Rcm({"simulate", "--out", folder, "--estimator", "window"}), 2,
      "not a flag of rcm simulate");
  EXPECT_FALSE(fs::exists(folder + "/truth.csv"));
}

TEST(SimulateCli, RefusesToOverwriteASequence) {
  const std::string folder = Folder("twice");
  const std::vector<std::string> args = {
      "simulate", "--out",    folder, "--noimages", "--matches-per-frame",
      "10",       "--frames", "1"};
  ASSERT_EQ(Rcm(args).exit_code, 0);
  ExpectFailsWithOneLine(Rcm(args), 1, "--overwrite");
  std::vector<std::string> overwrite = args;
  overwrite.push_back("--overwrite");
  EXPECT_EQ(Rcm(overwrite).exit_code, 0);
}

TEST(SimulateCli, NarrowRigWithDriftAndABoard) {
  // The sea dives' failure with its fix's input: the narrow housing, cam1
  // moved by 0.5 degrees and 1 mm since the calibration, a diver's
  // chessboard in view. camchain.yaml is the calibration; the truth of the
  // extrinsics is in simulation.json, the board's in board.csv, and
  // rcm::calib finds the board in the images.
  const std::string folder = Folder("narrow_board");
  const RunResult result = Simulate(
      folder,
      "--rig narrow --frames 2 --supersampling 1 --n 1.34 --extrinsic-drift "
      "0.5,0,0,1,0,0 --board chessboard --cols 9 --rows 6 --square 0.03 "
      "--matches-per-frame 50 --json");
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const nlohmann::json json = nlohmann::json::parse(result.out);
  EXPECT_EQ(json["rig"], "narrow");
  EXPECT_EQ(json["extrinsic_drift"]["rotation_deg"],
            nlohmann::json::array({0.5, 0.0, 0.0}));
  EXPECT_EQ(json["extrinsic_drift"]["translation_mm"],
            nlohmann::json::array({1.0, 0.0, 0.0}));
  EXPECT_EQ(json["board"]["fully_visible_frames"]["both"], 2);
  const Eigen::Matrix4d moved =
      NarrowFieldRig()
          .WithCam1Moved(Eigen::Vector3d(0.5 * M_PI / 180.0, 0.0, 0.0),
                         Eigen::Vector3d(1e-3, 0.0, 0.0))
          .value()
          .right_from_left()
          .ToMatrix();
  const nlohmann::json settings =
      nlohmann::json::parse(test::ReadWholeFile(folder + "/simulation.json"));
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) {
      EXPECT_NEAR(settings["true_cam1_from_cam0"][r][c].get<double>(),
                  moved(r, c), 1e-15);
    }
  }
  const std::string board = test::ReadWholeFile(folder + "/board.csv");
  EXPECT_EQ(board.rfind("frame,t,tx,ty,tz,qx,qy,qz,qw,visible_left,"
                        "visible_right\n0,0.0,",
                        0),
            0u)
      << board;
  EXPECT_EQ(std::count(board.begin(), board.end(), '\n'), 3);
  // Frame 1's pose, read back, puts the corners where rcm::calib finds
  // them in the left image (within the detector's 0.3 px; board 0.6-2 m
  // away, see tests/sim/board_rendering_test.cc).
  const size_t row = board.find("\n1,0.05,");
  ASSERT_NE(row, std::string::npos) << board;
  const std::vector<double> values = BoardRow(board.substr(row + 1));
  ASSERT_EQ(values.size(), 11u);
  EXPECT_EQ(values[9], 1.0);
  EXPECT_EQ(values[10], 1.0);
  const Rigid3d cam0_from_target = Cam0FromTarget(values);
  const cv::Mat left = ReadImage(folder + "/left/000001.png", true).value();
  EXPECT_EQ(left.size(), cv::Size(640, 480));
  const calib::CalibrationTarget target =
      calib::MakeCheckerboardTarget(9, 6, 0.03).value();
  const std::optional<calib::TargetObservation> seen =
      calib::DetectTarget(left, target);
  ASSERT_TRUE(seen.has_value());
  EXPECT_EQ(seen->size(), 54);
  const FlatPortCamera camera =
      FlatPortCamera::Create(NarrowFieldCam0(), FlatPort(), 1.34).value();
  ExpectCornersWhereTheyProject(*seen, target, cam0_from_target, camera);

  // The camchain is that of the same run without drift.
  const std::string calibrated = Folder("narrow_calibrated");
  ASSERT_EQ(Simulate(calibrated,
                     "--rig narrow --frames 1 --noimages --matches-per-frame 5")
                .exit_code,
            0);
  EXPECT_EQ(test::ReadWholeFile(folder + "/camchain.yaml"),
            test::ReadWholeFile(calibrated + "/camchain.yaml"));
}

// The 4-inch acrylic dome of issue 33, each camera decentered 1-3 mm
// laterally and 5-10 mm axially.
constexpr char kDomeFlags[] =
    "--port dome --dome-inner-radius 0.04355 --dome-thickness 0.00375 "
    "--glass-index 1.495 --dome-decentering 0.002,-0.001,0.007 "
    "--right-dome-decentering -0.0015,0.0025,0.009";

TEST(SimulateCli, DomePortDiveWritesTheTruthAndTheAirCamchain) {
  // A board dive through two decentered domes (3 frames at 1 Hz, small
  // images): the images exist, the truth (each camera's decentering) is in
  // simulation.json, camchain.yaml is the air calibration a user has (no
  // port block: the same bytes as a flat-port run's), and rcm::calib finds
  // the board where the dome puts it.
  const std::string folder = Folder("dome_board");
  const RunResult result = Simulate(
      folder, std::string("--rig narrow --frames 3 --frame-rate 1 "
                          "--supersampling 1 --n 1.34 --board chessboard "
                          "--cols 9 --rows 6 --square 0.03 ") +
                  kDomeFlags);
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_NE(result.out.find("port     dome"), std::string::npos) << result.out;
  for (int f = 0; f < 3; ++f) {
    for (const char* side : {"left", "right"}) {
      const std::string path =
          folder + "/" + side + "/00000" + std::to_string(f) + ".png";
      ASSERT_TRUE(fs::exists(path)) << path;
    }
  }
  const nlohmann::json settings =
      nlohmann::json::parse(test::ReadWholeFile(folder + "/simulation.json"));
  const nlohmann::json& port = settings["port"];
  EXPECT_EQ(port["type"], "dome");
  EXPECT_EQ(port["inner_radius"], 0.04355);
  EXPECT_EQ(port["thickness"], 0.00375);
  EXPECT_EQ(port["glass_index"], 1.495);
  EXPECT_EQ(port["decentering_m"],
            nlohmann::json::parse("[[0.002, -0.001, 0.007], "
                                  "[-0.0015, 0.0025, 0.009]]"));
  const std::string camchain = test::ReadWholeFile(folder + "/camchain.yaml");
  EXPECT_EQ(camchain.find("port"), std::string::npos) << camchain;
  const std::string flat = Folder("dome_board_flat");
  ASSERT_EQ(Simulate(flat,
                     "--rig narrow --frames 1 --noimages "
                     "--matches-per-frame 5")
                .exit_code,
            0);
  EXPECT_EQ(camchain, test::ReadWholeFile(flat + "/camchain.yaml"));

  // Frame 0's board pose, read back, puts the corners where rcm::calib
  // finds them in the left image through the left dome.
  const std::string board = test::ReadWholeFile(folder + "/board.csv");
  const size_t row = board.find("\n0,0.0,");
  ASSERT_NE(row, std::string::npos) << board;
  const std::vector<double> values = BoardRow(board.substr(row + 1));
  ASSERT_EQ(values.size(), 11u);
  ASSERT_EQ(values[9], 1.0);
  const Rigid3d cam0_from_target = Cam0FromTarget(values);
  const calib::CalibrationTarget target =
      calib::MakeCheckerboardTarget(9, 6, 0.03).value();
  const std::optional<calib::TargetObservation> seen = calib::DetectTarget(
      ReadImage(folder + "/left/000000.png", true).value(), target);
  ASSERT_TRUE(seen.has_value());
  EXPECT_EQ(seen->size(), 54);
  const DomePortCamera camera =
      DomePortCamera::Create(
          NarrowFieldCam0(),
          test::AcrylicDome(Eigen::Vector3d(0.002, -0.001, 0.007)), 1.34)
          .value();
  ExpectCornersWhereTheyProject(*seen, target, cam0_from_target, camera);
}

TEST(SimulateCli, BadDomeFlagsGiveOneLine) {
  const std::string folder = Folder("bad_dome");
  const std::string dome = kDomeFlags;
  ExpectFailsWithOneLine(Simulate(folder, dome + " --air-gap 0.01"), 2,
                         "--air-gap describes a flat port");
  ExpectFailsWithOneLine(Simulate(folder, dome + " --port-tilt 2"), 2,
                         "--port-tilt describes a flat port");
  ExpectFailsWithOneLine(
      Simulate(folder, "--right-dome-decentering 0.001,0,0.005"), 2,
      "--right-dome-decentering needs --port dome");
  ExpectFailsWithOneLine(
      Simulate(folder, "--port dome --dome-inner-radius 0.04355"), 2,
      "--dome-thickness");
  ExpectFailsWithOneLine(
      Simulate(folder, dome + " --right-dome-decentering 0,0,0.05"), 2,
      "outside the inner sphere");
  ExpectFailsWithOneLine(
      Simulate(folder, dome + " --right-dome-decentering 1,2"), 2,
      "expected X,Y,Z");
  ExpectFailsWithOneLine(
      Simulate(folder, dome + " --noimages --matches-per-frame 5 "
                              "--depth-range 0.5,2"),
      2, "not domes");
  EXPECT_FALSE(fs::exists(folder + "/truth.csv"));
}

TEST(SimulateCli, DriftAndBoardWithoutImages) {
  const std::string folder = Folder("drift_depths");
  const RunResult result = Simulate(
      folder,
      "--rig narrow --noimages --depth-range 0.5,3 --matches-per-frame 20 "
      "--frames 3 --extrinsic-drift 0,0.2,0 --board checkerboard --cols 7 "
      "--rows 5 --square 0.04 --board-distance 0.8,1.5");
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_NE(result.out.find("drift    cam1 turned 0.200 deg"),
            std::string::npos)
      << result.out;
  EXPECT_NE(result.out.find("in 3 of 3 frames"), std::string::npos)
      << result.out;
  EXPECT_FALSE(fs::exists(folder + "/left"));
  EXPECT_TRUE(fs::exists(folder + "/board.csv"));
  EXPECT_TRUE(fs::exists(folder + "/truth.csv"));
}

TEST(SimulateCli, BadDriftAndBoardFlagsGiveOneLine) {
  const std::string folder = Folder("bad_board");
  const auto with = [&](const std::string& flags) {
    return Simulate(folder,
                    "--noimages --matches-per-frame 5 --frames 1 " + flags);
  };
  const std::string board = "--board chessboard --cols 9 --rows 6 ";
  const struct {
    std::string flags;
    int exit_code;
    std::string needle;
  } cases[] = {
      {"--extrinsic-drift 0.5,0", 2, "expected RX,RY,RZ[,TX,TY,TZ]"},
      {"--extrinsic-drift 0.5,0,0,1", 2, "expected RX,RY,RZ[,TX,TY,TZ]"},
      {"--extrinsic-drift nan,0,0", 2, "expected RX,RY,RZ[,TX,TY,TZ]"},
      {"--extrinsic-drift 0,12,0", 2,
       "--extrinsic-drift 0,12,0: extrinsic drift rotation of 12 deg is "
       "above 10 deg"},
      {"--extrinsic-drift 0,0,0,60,0,0", 2, "above 50 mm"},
      {"--board aprilgrid --cols 6 --rows 6 --tag-size 0.088", 2,
       "rcm simulate renders chessboards only"},
      {"--board charuco", 2, "rcm simulate renders chessboards only"},
      {"--target " + folder + "/april.yaml", 2,
       "rcm simulate renders chessboards only"},
      {"--board chessboard --cols 1 --rows 6 --square 0.03", 2,
       "--board chessboard"},
      {board, 2, "--board chessboard"},  // no --square
      {board + "--square 0.03 --board-distance 2", 2,
       "--board-distance 2: expected MIN,MAX"},
      {board + "--square 0.03 --board-distance 2,1", 2, "0 < min <= max"},
      {"--board-distance 1,2", 2, "--board-distance needs --board"},
      {"--board-warp 1,1", 2, "--board-warp needs --board"},
      {board + "--square 0.03 --board-warp 1", 2,
       "--board-warp 1: expected X_MM,Y_MM"},
      {board + "--square 0.03 --board-warp 0,80", 2,
       "--board-warp 0,80: board warp (0, 0.08) m: each must be within 0.05 "
       "m"},
      {"--rig gopro", 1, "alphasense, alphasense-unrectified or narrow"},
  };
  for (const auto& bad : cases) {
    SCOPED_TRACE(bad.flags);
    ExpectFailsWithOneLine(with(bad.flags), bad.exit_code, bad.needle);
  }
  EXPECT_FALSE(fs::exists(folder + "/truth.csv"));
}

TEST(SimulateCli, HelpListsTheFlags) {
  const RunResult result = Rcm({"simulate", "--help"});
  EXPECT_EQ(result.exit_code, 0);
  for (const char* flag : {"--out",
                           "--media",
                           "--air-gap",
                           "--calib",
                           "--matches-per-frame",
                           "--seed",
                           "--overwrite",
                           "--extrinsic-drift",
                           "--board=",
                           "--cols=",
                           "--rows=",
                           "--square=",
                           "--board-distance",
                           "--board-warp",
                           "board.csv",
                           "narrow",
                           "--port",
                           "--dome-inner-radius",
                           "--dome-thickness",
                           "--dome-decentering",
                           "--right-dome-decentering",
                           "--glass-index",
                           "decentering_m"}) {
    EXPECT_NE(result.out.find(flag), std::string::npos) << flag;
  }
}

}  // namespace
}  // namespace rcm::simulate_cli_test
