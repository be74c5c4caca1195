// End-to-end tests of `rcm dome-check`: the pixel error of ignoring a dome
// port, from a camchain's dome block or the dome flags, its verdict,
// pictures and JSON, and bad input.
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "cli/cli_runner.h"
#include "support/temp_file.h"

namespace rcm::dome_check_cli_test {
namespace {

namespace fs = std::filesystem;
using test::IsOneLine;
using test::RunResult;

// Two 720x540 cameras without port blocks.
const std::string kRig = std::string(RCM_SOURCE_DIR) +
                         "/examples/data/alphasense_front_rectified.yaml";

// A 640x480 pinhole behind the 4-inch acrylic dome of the issue, 7.2 mm
// behind its centre (`decentering` replaces that), in the temporary file
// `name`.
std::string DomeCamchain(const std::string& decentering = "0.0, 0.0, 0.0072",
                         const std::string& name = "dome.yaml") {
  return test::WriteTempFile(name,
                             "cam0:\n"
                             "  camera_model: pinhole\n"
                             "  distortion_coeffs: []\n"
                             "  distortion_model: none\n"
                             "  intrinsics: [500.0, 500.0, 319.5, 239.5]\n"
                             "  port:\n"
                             "    decentering: [" +
                                 decentering +
                                 "]\n"
                                 "    glass_index: 1.495\n"
                                 "    inner_radius: 0.04355\n"
                                 "    outer_radius: 0.0473\n"
                                 "    type: dome\n"
                                 "  resolution: [640, 480]\n");
}

RunResult Rcm(std::vector<std::string> args) {
  args.insert(args.begin(), "dome-check");
  return test::RunProgram(RCM_BINARY, args);
}

nlohmann::json Json(const RunResult& result) {
  EXPECT_EQ(result.exit_code, 0) << result.err;
  return nlohmann::json::parse(result.out, nullptr, /*allow_exceptions=*/false);
}

TEST(DomeCheckCli, DecenteredDomeFromTheCamchainIsWorthModelling) {
  const std::string folder = test::TempFilePath("out");
  fs::remove_all(folder);
  const RunResult text =
      Rcm({"--camchain", DomeCamchain(), "--depth-range", "0.5,5",
           "--reference-depth", "1", "--out", folder});
  ASSERT_EQ(text.exit_code, 0) << text.err;
  EXPECT_TRUE(text.err.empty()) << text.err;
  // The verdict is the last line.
  EXPECT_NE(text.out.find("\nignoring this dome costs up to "),
            std::string::npos)
      << text.out;
  EXPECT_NE(text.out.find(": model it\n"), std::string::npos) << text.out;
  EXPECT_EQ(text.out.rfind(": model it\n"), text.out.size() - 11);
  EXPECT_NE(text.out.find("a central camera exact at 1 m"), std::string::npos);
  for (const char* name : {"dome_check_error.png", "dome_check_depths.png"}) {
    const cv::Mat picture = cv::imread(folder + "/" + name);
    EXPECT_FALSE(picture.empty()) << name;
  }
  const nlohmann::json json = nlohmann::json::parse(
      test::ReadWholeFile(folder + "/dome_check.json"), nullptr, false);
  ASSERT_TRUE(json.is_object());
  EXPECT_EQ(json["dome"]["decentering_m"][2], 0.0072);
  EXPECT_NEAR(json["dome"]["thickness_m"].get<double>(), 0.00375, 1e-12);
  ASSERT_EQ(json["depths"].size(), 12u);
  EXPECT_EQ(json["depths"][0]["depth_m"], 0.5);
  EXPECT_EQ(json["depths"][11]["depth_m"], 5.0);
  EXPECT_GT(json["max_px"].get<double>(), 5.0);
  EXPECT_FALSE(json["ignorable"].get<bool>());
  EXPECT_EQ(json["reference"]["depth_m"], 1.0);
  EXPECT_LT(json["reference"]["central_max_px"].get<double>(), 1e-9);
  EXPECT_GT(json["central_max_px"].get<double>(), 0.01);
  EXPECT_LT(json["central_max_px"].get<double>(), json["max_px"].get<double>());
}

TEST(DomeCheckCli, CentredDomeFromTheFlagsCanBeIgnored) {
  // The second camera of a stereo camchain, with --n and one depth.
  const nlohmann::json json =
      Json(Rcm({"--camchain", kRig, "--camera", "cam1", "--port", "dome",
                "--dome-inner-radius", "0.04355", "--dome-thickness", "0.00375",
                "--glass-index", "1.495", "--n", "1.34", "--depth-range", "1,1",
                "--json"}));
  ASSERT_TRUE(json.is_object());
  EXPECT_EQ(json["camera"], "cam1");
  EXPECT_EQ(json["n"], 1.34);
  ASSERT_EQ(json["depths"].size(), 1u);
  EXPECT_LE(json["max_px"].get<double>(), 1e-12);
  EXPECT_TRUE(json["ignorable"].get<bool>());
  EXPECT_NE(json["verdict"].get<std::string>().find("it can be ignored"),
            std::string::npos);
  EXPECT_TRUE(json["reference"].is_null());
  EXPECT_TRUE(json["central_max_px"].is_null());
}

struct BadInput {
  std::vector<std::string> args;
  int exit_code;
  std::string message;
};

TEST(DomeCheckCli, BadInputIsOneLine) {
  const std::string dome = DomeCamchain();
  const std::vector<BadInput> cases = {
      {{}, 2, "--camchain is required"},
      {{"--camchain", kRig}, 1, "no dome: cam0 of"},
      {{"--camchain", kRig, "--camera", "cam2"}, 1, "unknown camera 'cam2'"},
      {{"--camchain", dome, "--depth-range", "1"},
       2,
       "--depth-range 1: expected MIN,MAX"},
      {{"--camchain", dome, "--depth-range", "5,0.5"},
       2,
       "max_depth 0.5 m is below min_depth 5 m"},
      {{"--camchain", dome, "--depth-range", "0.01,1"},
       1,
       "depth 0.01 m is not beyond the dome"},
      {{"--camchain", dome, "--n", "2.5"}, 2, "--n 2.5 is outside [1, 2]"},
      {{"--camchain", dome, "--tolerance-px", "0"}, 2, "--tolerance-px 0.0"},
      {{"--camchain", kRig, "--port", "dome", "--dome-inner-radius", "0.04355",
        "--dome-thickness", "0.00375", "--dome-decentering", "0,0,0.05"},
       2,
       "outside the inner sphere"},
      {{"--camchain", DomeCamchain("0.0, 0.0, 0.05", "outside.yaml")},
       1,
       "outside the inner sphere"},
      {{"--camchain", dome, "--bag", "x.bag"},
       2,
       "--bag is not a flag of rcm dome-check"},
  };
  for (const BadInput& bad : cases) {
    const RunResult result = Rcm(bad.args);
    std::string args;
    for (const std::string& arg : bad.args) args += " " + arg;
    EXPECT_EQ(result.exit_code, bad.exit_code) << args << "\n" << result.err;
    EXPECT_TRUE(IsOneLine(result.err)) << args << "\n" << result.err;
    EXPECT_NE(result.err.find(bad.message), std::string::npos) << args << "\n"
                                                               << result.err;
    EXPECT_TRUE(result.out.empty()) << args;
  }
}

}  // namespace
}  // namespace rcm::dome_check_cli_test
