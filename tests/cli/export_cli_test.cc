// End-to-end tests of `rcm export` and `rcm compare`: the water-side
// models a VIO loads, and the index an air and an underwater calibration
// imply (an exported model must give back the n it was exported at).
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "cli/cli_runner.h"
#include "rcm/io/camchain.h"
#include "rcm/io/camera_info.h"
#include "rcm/io/image_file.h"
#include "support/temp_file.h"

namespace rcm::export_cli_test {
namespace {

namespace fs = std::filesystem;
using test::IsOneLine;
using test::RunResult;

const std::string kRig =
    std::string(RCM_SOURCE_DIR) + "/examples/data/alphasense_front_rectified.yaml";

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
                            const std::string& needle,
                            const std::string& subcommand) {
  EXPECT_EQ(result.exit_code, exit_code) << result.err;
  EXPECT_TRUE(IsOneLine(result.err)) << "stderr:\n" << result.err;
  EXPECT_NE(result.err.find(needle), std::string::npos) << result.err;
  EXPECT_EQ(result.err.rfind("rcm " + subcommand + ": error: ", 0), 0u)
      << result.err;
}

TEST(ExportCli, WritesWaterSideCamchainCameraInfosAndMaps) {
  const std::string folder = Folder("out");
  const RunResult result =
      Rcm({"export", "--calib", kRig, "--n", "1.333", "--out", folder});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_NE(result.out.find("inside the fit region (5 % inset)"),
            std::string::npos)
      << result.out;
  for (const char* file : {"camchain.yaml", "left.yaml", "right.yaml",
                           "fit_error_left.png", "fit_error_right.png",
                           "export.json"}) {
    EXPECT_TRUE(fs::exists(folder + "/" + file)) << file;
  }
  const StatusOr<Camchain> air = ReadCamchain(kRig);
  const StatusOr<Camchain> water = ReadCamchain(folder + "/camchain.yaml");
  ASSERT_TRUE(air.ok() && water.ok()) << water.status().message();
  ASSERT_EQ(water->cameras.size(), 2u);
  for (int k = 0; k < 2; ++k) {
    const Camera& camera = water->cameras[k].camera;
    EXPECT_EQ(camera.model(), LensModelId::kEquidistant);
    // The water-side focal is about n times the air focal (eq. 9).
    EXPECT_NEAR(camera.fx() / air->cameras[k].camera.fx(), 1.333, 0.01);
    // Extrinsics, IMU calibration and topics are those of the input.
    EXPECT_EQ(water->cameras[k].rostopic, air->cameras[k].rostopic);
    EXPECT_EQ(water->cameras[k].cam_from_imu.has_value(),
              air->cameras[k].cam_from_imu.has_value());
    const StatusOr<CameraInfo> info =
        ReadCameraInfo(folder + (k == 0 ? "/left.yaml" : "/right.yaml"));
    ASSERT_TRUE(info.ok()) << info.status().message();
    EXPECT_EQ(info->camera, camera);
  }
  EXPECT_EQ(water->cameras[1].cam_from_previous->translation,
            air->cameras[1].cam_from_previous->translation);
  const nlohmann::json json =
      nlohmann::json::parse(test::ReadWholeFile(folder + "/export.json"));
  // Acceptance (issue 9): within 0.1 px RMS inside the 5 % inset.
  EXPECT_LT(json["left"]["fit_region"]["rms_px"].get<double>(), 0.1);
  EXPECT_LT(json["right"]["fit_region"]["rms_px"].get<double>(), 0.1);
  EXPECT_GT(json["left"]["whole_image"]["max_px"].get<double>(),
            json["left"]["fit_region"]["max_px"].get<double>());
  EXPECT_EQ(ReadImage(folder + "/fit_error_left.png", false).value().channels(),
            3);
}

TEST(ExportCli, OutFileNamesTheCamchainAndPrefixesTheOthers) {
  const std::string folder = Folder("out");
  const RunResult result =
      Rcm({"export", "--calib", kRig, "--n", "1.34", "--model", "radtan",
           "--out", folder + "/water.yaml", "--json"});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  for (const char* file : {"water.yaml", "water-left.yaml", "water-right.yaml",
                           "water-fit_error_left.png", "water-export.json"}) {
    EXPECT_TRUE(fs::exists(folder + "/" + file)) << file;
  }
  const nlohmann::json json = nlohmann::json::parse(result.out);
  EXPECT_EQ(json["model"], "radtan");
  EXPECT_EQ(json["left"]["distortion_model"], "radtan");
  EXPECT_DOUBLE_EQ(json["n"].get<double>(), 1.34);
}

// Acceptance (issue 9): compare recovers n within 2e-4 from a "water"
// calibration that export produced from the same air calibration.
TEST(ExportCli, CompareRecoversTheExportedIndex) {
  const std::string folder = Folder("out");
  ASSERT_EQ(Rcm({"export", "--calib", kRig, "--n", "1.3371", "--out", folder})
                .exit_code,
            0);
  for (const std::string camera : {"cam0", "cam1"}) {
    const RunResult result =
        Rcm({"compare", "--air", kRig, "--water", folder + "/camchain.yaml",
             "--camera", camera, "--json", "--out", folder + "/" + camera});
    ASSERT_EQ(result.exit_code, 0) << result.err;
    const nlohmann::json json = nlohmann::json::parse(result.out);
    EXPECT_NEAR(json["n"].get<double>(), 1.3371, 2e-4) << camera;
    EXPECT_LT(json["residual_rms_px"].get<double>(), 0.1);
    EXPECT_TRUE(fs::exists(folder + "/" + camera + "/compare_residuals.png"));
    EXPECT_TRUE(fs::exists(folder + "/" + camera + "/compare.json"));
  }
  // A camera_info as the underwater calibration: its one camera.
  const RunResult from_info = Rcm({"compare", "--air", kRig, "--water",
                                   folder + "/right.yaml", "--camera", "cam1"});
  ASSERT_EQ(from_info.exit_code, 0) << from_info.err;
  EXPECT_NE(from_info.out.find("n = 1.337"), std::string::npos)
      << from_info.out;
}

TEST(ExportCli, BadInputIsOneLine) {
  const std::string folder = Folder("out");
  const std::string missing = test::TempFilePath("missing.yaml");
  const std::string garbage = test::WriteTempFile("garbage.yaml", "\x01\x02{[");
  struct Case {
    std::vector<std::string> args;
    int exit_code;
    std::string needle;
  };
  const std::vector<Case> cases = {
      {{"export", "--n", "1.33", "--out", folder}, 2, "--calib is required"},
      {{"export", "--calib", kRig, "--n", "1.33"}, 2, "--out is required"},
      {{"export", "--calib", kRig, "--out", folder}, 2, "--n is required"},
      {{"export", "--calib", kRig, "--n", "2.5", "--out", folder},
       2,
       "--n 2.5 is outside [1, 2]"},
      {{"export", "--calib", kRig, "--n", "nan", "--out", folder},
       2,
       "is outside [1, 2]"},
      {{"export", "--calib", kRig, "--n", "1.33", "--model", "fisheye", "--out",
        folder},
       2,
       "unknown --model 'fisheye'"},
      {{"export", "--calib", kRig, "--n", "1.33", "--fit-inset", "0.6", "--out",
        folder},
       2,
       "fit_inset 0.6 is outside [0, 0.45]"},
      {{"export", "--calib", missing, "--n", "1.33", "--out", folder},
       1,
       missing},
      {{"export", "--calib", garbage, "--n", "1.33", "--out", folder},
       1,
       garbage},
      {{"export", "--calib", kRig, "--n", "1.33", "--out",
        "/proc/rcm-cannot-write/out"},
       1,
       "/proc/rcm-cannot-write/out"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.args.back());
    ExpectFailsWithOneLine(Rcm(c.args), c.exit_code, c.needle, "export");
  }
  // Nothing that looks complete was left behind.
  EXPECT_FALSE(fs::exists(folder + "/camchain.yaml"));
}

TEST(CompareCli, BadInputIsOneLine) {
  const std::string missing = test::TempFilePath("missing.yaml");
  const std::string other_size = test::WriteTempFile(
      "euroc.yaml",
      FormatCameraInfo(CameraInfoFromCamera(
          "euroc", Camera::Create(LensModelId::kRadTan, 752, 480,
                                  {458.654, 457.296, 367.215, 248.375},
                                  {-0.28340811, 0.07395907, 0.00019359,
                                   1.76187114e-05})
                       .value())));
  struct Case {
    std::vector<std::string> args;
    int exit_code;
    std::string needle;
  };
  const std::vector<Case> cases = {
      {{"compare", "--air", kRig}, 2, "--air and --water are required"},
      {{"compare", "--air", kRig, "--water", missing}, 1, missing},
      {{"compare", "--air", kRig, "--water", kRig, "--camera", "cam7"},
       1,
       "unknown camera 'cam7'"},
      {{"compare", "--air", kRig, "--water", other_size},
       1,
       "the air calibration is for 720 x 540 images and the underwater one "
       "for 752 x 480"},
      {{"compare", "--air", kRig, "--water", kRig, "--inset", "-1"},
       2,
       "inset -1 is outside [0, 0.45]"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.args.back());
    ExpectFailsWithOneLine(Rcm(c.args), c.exit_code, c.needle, "compare");
  }
}

// The same calibration as air and water: refraction is absent, n = 1 (the
// lower bound) and the residual vanishes.
TEST(CompareCli, SameCalibrationGivesUnitIndex) {
  const RunResult result =
      Rcm({"compare", "--air", kRig, "--water", kRig, "--json"});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const nlohmann::json json = nlohmann::json::parse(result.out);
  EXPECT_NEAR(json["n"].get<double>(), 1.0, 1e-9);
  EXPECT_LT(json["residual_max_px"].get<double>(), 1e-6);
}

}  // namespace
}  // namespace rcm::export_cli_test

namespace rcm::export_cli_test {
namespace {

// The dataset rig with port blocks (8 mm of air, 6 mm of glass).
std::string ThickPortRig() {
  std::string text = test::ReadWholeFile(kRig);
  const std::string block = "  resolution: [720, 540]\n";
  for (size_t at = text.find(block); at != std::string::npos;
       at = text.find(block, at + 1)) {
    text.insert(at + block.size(),
                "  port: {air_gap: 0.008, glass_thickness: 0.006}\n");
  }
  return test::WriteTempFile("thick_rig.yaml", text);
}

// With port blocks, export fits the thick port's camera, central at the
// reference depth, and says so; the exported camchain is a conventional
// model without port blocks.
TEST(ExportCli, HonoursThePortAtTheReferenceDepth) {
  const std::string folder = Folder("out");
  const RunResult result =
      Rcm({"export", "--calib", ThickPortRig(), "--n", "1.333",
           "--reference-depth", "1.5", "--out", folder, "--json"});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const nlohmann::json json = nlohmann::json::parse(result.out);
  EXPECT_EQ(json["port"], "thick");
  EXPECT_DOUBLE_EQ(json["reference_depth_m"].get<double>(), 1.5);
  EXPECT_LT(json["left"]["fit_region"]["rms_px"].get<double>(), 0.1);
  const std::string camchain = test::ReadWholeFile(folder + "/camchain.yaml");
  EXPECT_EQ(camchain.find("port"), std::string::npos);
  // The same rig without blocks gives a different (thin-port) model.
  const RunResult thin =
      Rcm({"export", "--calib", kRig, "--n", "1.333", "--json", "--out",
           Folder("thin")});
  ASSERT_EQ(thin.exit_code, 0) << thin.err;
  EXPECT_EQ(nlohmann::json::parse(thin.out)["port"], "thin");
  EXPECT_NE(nlohmann::json::parse(thin.out)["left"]["intrinsics"],
            json["left"]["intrinsics"]);
}

TEST(ExportCli, RejectsAReferenceDepthInsideTheHousing) {
  ExpectFailsWithOneLine(
      Rcm({"export", "--calib", ThickPortRig(), "--n", "1.333",
           "--reference-depth", "0.01", "--out", Folder("out")}),
      1, "reference depth 0.01 m is not beyond the port's glass", "export");
}

}  // namespace
}  // namespace rcm::export_cli_test
