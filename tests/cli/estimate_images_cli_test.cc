// End-to-end tests of `rcm estimate` on images: a simulated dive written
// by `rcm simulate` as two image folders and as a ROS1 bag, read back and
// estimated through the whole front end.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "cli/cli_runner.h"
#include "rcm/io/correspondence_csv.h"
#include "rcm/io/image_file.h"
#include "support/temp_file.h"
#ifdef RCM_HAVE_ROSBAG
#include "rcm/rosbag/bag_image_writer.h"
#endif

namespace rcm::estimate_images_cli_test {
namespace {

namespace fs = std::filesystem;
using test::IsOneLine;
using test::RunResult;

// The accuracy bound for 10 pairs; 4 pairs of ~1200 matches give
// sigma_n ~ 2e-4 (the estimator's own figure), so 2e-3 is ~10 sigma.
constexpr double kNTolerance = 2e-3;
constexpr double kNTrue = 1.345;
constexpr int kFrames = 4;

RunResult Rcm(const std::vector<std::string>& args) {
  return test::RunProgram(RCM_BINARY, args);
}

std::string Folder(const std::string& name) {
  const std::string folder = test::TempFilePath(name);
  fs::remove_all(folder);
  return folder;
}

// One simulated dive for all tests of this file (rendering is the slow
// part): rectified dataset rig, thin port, n = 1.345.
const std::string& Dive() {
  static const std::string folder = [] {
    const std::string out = Folder("dive");
    const RunResult simulated =
        Rcm({"simulate", "--out", out, "--frames", std::to_string(kFrames),
             "--n", std::to_string(kNTrue), "--supersampling", "1"});
    EXPECT_EQ(simulated.exit_code, 0) << simulated.err;
    return out;
  }();
  return folder;
}

void ExpectFailsWithOneLine(const RunResult& result, int exit_code,
                            const std::string& needle) {
  EXPECT_EQ(result.exit_code, exit_code) << result.err;
  EXPECT_TRUE(IsOneLine(result.err)) << "stderr:\n" << result.err;
  EXPECT_NE(result.err.find(needle), std::string::npos) << result.err;
  EXPECT_EQ(result.err.rfind("rcm estimate", 0), 0u) << result.err;
}

TEST(EstimateImagesCli, FoldersGiveNAndThePictures) {
  const std::string out = Folder("estimate_out");
  const RunResult result =
      Rcm({"estimate", "--calib", Dive() + "/camchain.yaml", "--left",
           Dive() + "/left", "--right", Dive() + "/right", "--out", out});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_NE(result.out.find("pairs/s"), std::string::npos) << result.out;
  const nlohmann::json json =
      nlohmann::json::parse(test::ReadWholeFile(out + "/estimate.json"));
  EXPECT_NEAR(json["n"].get<double>(), kNTrue, kNTolerance);
  EXPECT_EQ(json["images"]["pairs"].get<int>(), kFrames);
  EXPECT_GT(json["images"]["matches_per_pair"].get<double>(), 500.0);
  EXPECT_EQ(ReadImage(out + "/n_per_frame.png", false).value().size(),
            cv::Size(1000, 600));
  const cv::Mat picture = ReadImage(out + "/matches_by_n.png", false).value();
  EXPECT_GT(picture.cols, 720);
  EXPECT_GT(picture.rows, 540);
  // The matches are kept, and estimate reads them back to the same n.
  const RunResult again = Rcm({"estimate", "--calib", Dive() + "/camchain.yaml",
                               "--matches", out + "/matches.csv", "--json"});
  ASSERT_EQ(again.exit_code, 0) << again.err;
  EXPECT_NEAR(nlohmann::json::parse(again.out)["n"].get<double>(),
              json["n"].get<double>(), 1e-9);
  const std::string per_frame = test::ReadWholeFile(out + "/per_frame.csv");
  EXPECT_EQ(std::count(per_frame.begin(), per_frame.end(), '\n'), kFrames + 1);
}

TEST(EstimateImagesCli, EveryEstimatorRunsOnImages) {
  for (const char* estimator : {"online", "window", "closed-form"}) {
    const RunResult result =
        Rcm({"estimate", "--calib", Dive() + "/camchain.yaml", "--left",
             Dive() + "/left", "--right", Dive() + "/right", "--estimator",
             estimator, "--json"});
    ASSERT_EQ(result.exit_code, 0) << estimator << ": " << result.err;
    const double n = nlohmann::json::parse(result.out)["n"].get<double>();
    // The closed form is the paper's biased baseline (docs/design.md,
    // "The estimator of record"): only a sanity bound for it.
    EXPECT_NEAR(n, kNTrue,
                std::string(estimator) == "closed-form" ? 0.1 : kNTolerance)
        << estimator;
  }
  // A freely refined rotation (--refine-rotation) is the final estimate's;
  // the sequence's window keeps its self-calibration.
  const RunResult free_rotation =
      Rcm({"estimate", "--calib", Dive() + "/camchain.yaml", "--left",
           Dive() + "/left", "--right", Dive() + "/right", "--refine-rotation",
           "--json"});
  ASSERT_EQ(free_rotation.exit_code, 0) << free_rotation.err;
  const nlohmann::json json = nlohmann::json::parse(free_rotation.out);
  ASSERT_TRUE(json.contains("rotation")) << free_rotation.out;
  EXPECT_FALSE(json["rotation"]["with_prior"].get<bool>());
  EXPECT_LT(std::abs(json["n"].get<double>() - kNTrue),
            std::max(kNTolerance, 5.0 * json["sigma_n"].get<double>()));
}

// --estimator bundle end to end: 6 rendered pairs 7.5 cm apart (4 Hz), cam1
// turned half a degree since the camchain; the JSON, the trajectory and its
// picture. n within the file's 2e-3 (its sigma ~4e-4 with the front end's
// systematic floor), the turn within 0.05 degrees (the bound).
TEST(EstimateImagesCli, BundleWritesTheTrajectory) {
  const std::string dive = Folder("bundle_dive");
  const RunResult simulated =
      Rcm({"simulate", "--out", dive, "--frames", "6", "--frame-rate", "4",
           "--n", std::to_string(kNTrue), "--supersampling", "1",
           "--extrinsic-drift", "0.14,0.48,0.10", "--seed", "11"});
  ASSERT_EQ(simulated.exit_code, 0) << simulated.err;
  const std::string out = Folder("bundle_out");
  const RunResult result = Rcm(
      {"estimate", "--calib", dive + "/camchain.yaml", "--left", dive + "/left",
       "--right", dive + "/right", "--estimator", "bundle", "--out", out});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const nlohmann::json json =
      nlohmann::json::parse(test::ReadWholeFile(out + "/estimate.json"));
  ASSERT_EQ(json["estimator"].get<std::string>(), "bundle") << json.dump(2);
  EXPECT_NEAR(json["n"].get<double>(), kNTrue, kNTolerance);
  EXPECT_EQ(json["frames_used"].get<int>(), 6);
  EXPECT_GT(json["tracks"].get<int>(), 500);
  EXPECT_GT(json["sigma_n_systematic"].get<double>(), 0.0);
  ASSERT_TRUE(json.contains("focal_scale")) << json.dump(2);
  ASSERT_TRUE(json.contains("rotation")) << json.dump(2);
  const double turn_error =
      std::hypot(json["rotation"]["angle_axis_deg"][0].get<double>() - 0.14,
                 json["rotation"]["angle_axis_deg"][1].get<double>() - 0.48,
                 json["rotation"]["angle_axis_deg"][2].get<double>() - 0.10);
  EXPECT_LT(turn_error, 0.05) << json["rotation"].dump();
  const std::string tum = test::ReadWholeFile(out + "/trajectory.tum");
  EXPECT_EQ(std::count(tum.begin(), tum.end(), '\n'), 6 + 1);  // + header
  EXPECT_EQ(ReadImage(out + "/trajectory.png", false).value().size(),
            cv::Size(900, 800));
}

TEST(EstimateImagesCli, StrideKeepsFrameNumbers) {
  const std::string per_frame = test::TempFilePath("stride.csv");
  const RunResult result =
      Rcm({"estimate", "--calib", Dive() + "/camchain.yaml", "--left",
           Dive() + "/left", "--right", Dive() + "/right", "--stride", "2",
           "--per-frame", per_frame});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const std::string rows = test::ReadWholeFile(per_frame);
  EXPECT_EQ(rows.find("\n1,"), std::string::npos) << rows;
  EXPECT_NE(rows.find("\n2,"), std::string::npos) << rows;
}

TEST(EstimateImagesCli, BadImageInputIsOneLine) {
  const std::string calib = Dive() + "/camchain.yaml";
  const std::string empty = Folder("empty_images");
  fs::create_directories(empty);
  ExpectFailsWithOneLine(Rcm({"estimate", "--calib", calib, "--left", empty,
                              "--right", Dive() + "/right"}),
                         1, "no images");
  ExpectFailsWithOneLine(
      Rcm({"estimate", "--calib", calib, "--left", Dive() + "/left"}), 1,
      "--left and --right go together");
  ExpectFailsWithOneLine(
      Rcm({"estimate", "--calib", calib, "--left", Dive() + "/left", "--right",
           Dive() + "/right", "--features", "surf"}),
      2, "unknown --features 'surf'");
  ExpectFailsWithOneLine(
      Rcm({"estimate", "--calib", calib, "--left", Dive() + "/left", "--right",
           Dive() + "/right", "--from", "1"}),
      1, "a time range needs timestamps");
  // Images of another size than the calibration.
  const std::string small = Folder("small_images");
  fs::create_directories(small + "/left");
  fs::create_directories(small + "/right");
  const cv::Mat image(48, 64, CV_8UC1, cv::Scalar(90));
  ASSERT_TRUE(WritePng(image, small + "/left/0.png").ok());
  ASSERT_TRUE(WritePng(image, small + "/right/0.png").ok());
  ExpectFailsWithOneLine(Rcm({"estimate", "--calib", calib, "--left",
                              small + "/left", "--right", small + "/right"}),
                         1, "but the calibration is for 720 x 540");
}

#ifdef RCM_HAVE_ROSBAG
// The dive as a bag: mono8 left, PNG-compressed right (both lossless), as
// a recording of raw and compressed topics would hold them.
std::string DiveBag() {
  const std::string path = test::TempFilePath("dive.bag");
  fs::remove(path);
  StatusOr<BagImageWriter> writer = BagImageWriter::Create(path);
  EXPECT_TRUE(writer.ok()) << writer.status().message();
  for (int i = 0; i < kFrames; ++i) {
    char name[32];
    std::snprintf(name, sizeof(name), "/%06d.png", i);
    const double stamp = 1700000000.0 + 0.05 * i;
    EXPECT_TRUE(
        writer
            ->WriteImage("/cam0/image_raw", stamp,
                         ReadImage(Dive() + "/left" + name, true).value(),
                         "mono8", "cam0")
            .ok());
    EXPECT_TRUE(
        writer
            ->WriteCompressed("/cam1/image_raw/compressed", stamp + 0.0004,
                              ReadImage(Dive() + "/right" + name, true).value(),
                              "png", "cam1")
            .ok());
  }
  EXPECT_TRUE(writer->Close().ok());
  return path;
}

TEST(EstimateImagesCli, BagGivesTheSameNAsTheFolders) {
  const std::string bag = DiveBag();
  const RunResult from_bag =
      Rcm({"estimate", "--calib", Dive() + "/camchain.yaml", "--bag", bag,
           "--left-topic", "/cam0/image_raw", "--right-topic",
           "/cam1/image_raw/compressed", "--json"});
  ASSERT_EQ(from_bag.exit_code, 0) << from_bag.err;
  const RunResult from_folders =
      Rcm({"estimate", "--calib", Dive() + "/camchain.yaml", "--left",
           Dive() + "/left", "--right", Dive() + "/right", "--json"});
  ASSERT_EQ(from_folders.exit_code, 0) << from_folders.err;
  const nlohmann::json bag_json = nlohmann::json::parse(from_bag.out);
  // The same pixels give the same matches and the same n.
  EXPECT_EQ(bag_json["n"].get<double>(),
            nlohmann::json::parse(from_folders.out)["n"].get<double>());
  EXPECT_NEAR(bag_json["n"].get<double>(), kNTrue, kNTolerance);
  EXPECT_EQ(bag_json["images"]["pairs"].get<int>(), kFrames);

  // Time range from the first pair's stamp: pairs at 0.05 and 0.10 s.
  const RunResult ranged =
      Rcm({"estimate", "--calib", Dive() + "/camchain.yaml", "--bag", bag,
           "--left-topic", "/cam0/image_raw", "--right-topic",
           "/cam1/image_raw/compressed", "--from", "0.04", "--to", "0.11",
           "--json"});
  ASSERT_EQ(ranged.exit_code, 0) << ranged.err;
  EXPECT_EQ(nlohmann::json::parse(ranged.out)["images"]["pairs"].get<int>(), 2);
}

TEST(EstimateImagesCli, BagWithoutTheTopicsIsOneLine) {
  const std::string bag = DiveBag();
  ExpectFailsWithOneLine(
      Rcm({"estimate", "--calib", Dive() + "/camchain.yaml", "--bag", bag,
           "--left-topic", "/alphasense/cam0/image_raw", "--right-topic",
           "/cam1/image_raw/compressed"}),
      1, "no topic /alphasense/cam0/image_raw");
  ExpectFailsWithOneLine(
      Rcm({"estimate", "--calib", Dive() + "/camchain.yaml", "--bag", bag}), 1,
      "--bag needs --left-topic and --right-topic");
  ExpectFailsWithOneLine(Rcm({"estimate", "--calib", Dive() + "/camchain.yaml",
                              "--bag", Dive() + "/camchain.yaml",
                              "--left-topic", "/a", "--right-topic", "/b"}),
                         1, "not a readable ROS1 bag");
}
#endif  // RCM_HAVE_ROSBAG

}  // namespace
}  // namespace rcm::estimate_images_cli_test
