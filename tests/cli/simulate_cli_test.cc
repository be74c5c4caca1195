// End-to-end tests of `rcm simulate`: what a user types, what they get.
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "cli/cli_runner.h"
#include "rcm/io/image_file.h"
#include "support/temp_file.h"

namespace rcm {
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
      Rcm({"simulate", "--out", folder, "--frames", "2", "--supersampling",
           "1", "--matches-per-frame", "200", "--n", "1.34"});
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
      "--frames",         "2",   "--supersampling", "1", "--seed", "9",
      "--matches-per-frame", "50", "--match-noise", "0.5"};
  std::vector<std::string> folders;
  for (const char* name : {"a", "b"}) {
    folders.push_back(Folder(name));
    std::vector<std::string> args = {"simulate", "--out", folders.back()};
    args.insert(args.end(), flags.begin(), flags.end());
    ASSERT_EQ(Rcm(args).exit_code, 0);
  }
  for (const char* file : {"left/000000.png", "right/000001.png",
                           "matches.csv", "truth.csv", "camchain.yaml"}) {
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
  const RunResult simulated =
      Rcm({"simulate", "--out", folder, "--noimages", "--depth-range",
           "0.3,1.5", "--matches-per-frame", "150", "--frames", "2", "--n",
           "1.6"});
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

TEST(SimulateCli, UsesTheCamerasOfAGivenRigFile) {
  // --left-camera cam1 --right-camera cam0 swaps the pair: the written camchain's cam0 is
  // the file's cam1 (fx 344.39...).
  const std::string folder = Folder("swapped");
  const RunResult result = Rcm(
      {"simulate", "--out", folder, "--calib",
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
  const std::vector<std::string> args = {"simulate", "--out", folder,
                                         "--noimages", "--matches-per-frame",
                                         "10", "--frames", "1"};
  ASSERT_EQ(Rcm(args).exit_code, 0);
  ExpectFailsWithOneLine(Rcm(args), 1, "--overwrite");
  std::vector<std::string> overwrite = args;
  overwrite.push_back("--overwrite");
  EXPECT_EQ(Rcm(overwrite).exit_code, 0);
}

TEST(SimulateCli, HelpListsTheFlags) {
  const RunResult result = Rcm({"simulate", "--help"});
  EXPECT_EQ(result.exit_code, 0);
  for (const char* flag : {"--out", "--media", "--air-gap", "--calib",
                           "--matches-per-frame", "--seed", "--overwrite"}) {
    EXPECT_NE(result.out.find(flag), std::string::npos) << flag;
  }
}

}  // namespace
}  // namespace rcm
