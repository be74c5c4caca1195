// rcm calibrate end to end: rendered target images written as two folders
// (and as a bag), calibrated by the executable, the camchain read back.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "calib/synthetic_target_views.h"
#include "cli/cli_runner.h"
#include "rcm/calib/calibration_target.h"
#include "rcm/calib/target_image.h"
#include "rcm/calib/target_renderer.h"
#include "rcm/io/calibration_covariance_file.h"
#include "rcm/io/camchain.h"
#include "support/temp_file.h"
#ifdef RCM_HAVE_ROSBAG
#include "rcm/rosbag/bag_image_writer.h"
#endif

namespace rcm::calibrate_cli_test {
namespace {

namespace fs = std::filesystem;
using calib::CalibrationTarget;
using test::RunResult;

RunResult Rcm(const std::vector<std::string>& args) {
  return test::RunProgram(RCM_BINARY, args);
}

// A small radtan rig (480x360, f = 300 px, 8 cm baseline) so that the
// renders and detections of a test take about a second.
StereoRig SmallRig() {
  const Camera left =
      Camera::Create(LensModelId::kRadTan, 480, 360,
                     {300.0, 301.0, 242.0, 178.0}, {-0.2, 0.05, 4e-4, -3e-4})
          .value();
  const Camera right =
      Camera::Create(LensModelId::kRadTan, 480, 360,
                     {302.0, 302.5, 236.0, 183.0}, {-0.19, 0.045, -2e-4, 1e-4})
          .value();
  Rigid3d right_from_left;
  right_from_left.rotation =
      Eigen::AngleAxisd(0.01, Eigen::Vector3d(0.1, 1.0, 0.2).normalized())
          .toRotationMatrix();
  right_from_left.translation = Eigen::Vector3d(-0.08, 0.001, 0.0);
  return StereoRig::Create(left, right, right_from_left).value();
}

CalibrationTarget Board() {
  return calib::MakeCheckerboardTarget(7, 5, 0.04).value();
}

constexpr int kPairs = 14;

// The rendered pairs, and which show the whole board (every corner 3 px or
// more inside the image), as the chessboard detector needs it.
struct RenderedPairs {
  std::vector<cv::Mat> left;
  std::vector<cv::Mat> right;
  std::vector<bool> left_whole;
  std::vector<bool> right_whole;

  int Stereo() const {
    int count = 0;
    for (int i = 0; i < kPairs; ++i) count += left_whole[i] && right_whole[i];
    return count;
  }
  int Used() const {
    int count = 0;
    for (int i = 0; i < kPairs; ++i) count += left_whole[i] || right_whole[i];
    return count;
  }
  // The first pair showing the whole board to both cameras, after `after`.
  int StereoPair(int after = -1) const {
    for (int i = after + 1; i < kPairs; ++i) {
      if (left_whole[i] && right_whole[i]) return i;
    }
    return -1;
  }
};

bool WholeBoard(const Camera& camera, const Rigid3d& camera_from_target) {
  for (const std::optional<Eigen::Vector2d>& pixel :
       calib::ProjectTargetPoints(camera, camera_from_target, Board())) {
    if (!pixel || pixel->x() < 3.0 || pixel->y() < 3.0 ||
        pixel->x() > camera.width() - 4.0 ||
        pixel->y() > camera.height() - 4.0) {
      return false;
    }
  }
  return true;
}

std::string Views(int used, int stereo) {
  return std::to_string(used) + " views used (" + std::to_string(stereo) +
         " stereo)";
}

RenderedPairs Render() {
  const StereoRig rig = SmallRig();
  const calib::TargetImage texture = calib::DrawTargetImage(Board(), 3000.0);
  const calib::TargetRenderer left =
      calib::TargetRenderer::Create(rig.left(), texture).value();
  const calib::TargetRenderer right =
      calib::TargetRenderer::Create(rig.right(), texture).value();
  const std::vector<Rigid3d> poses =
      calib::test::BoardPoses(rig.left(), Board(), kPairs, 5, 0.5, 0.8, 30.0);
  calib::TargetRenderOptions options;
  options.noise_sigma = 2.0;
  RenderedPairs pairs;
  for (int i = 0; i < kPairs; ++i) {
    options.seed = 2 * i;
    pairs.left.push_back(left.Render(poses[i], options));
    options.seed = 2 * i + 1;
    pairs.right.push_back(
        right.Render(rig.right_from_left() * poses[i], options));
    pairs.left_whole.push_back(WholeBoard(rig.left(), poses[i]));
    pairs.right_whole.push_back(
        WholeBoard(rig.right(), rig.right_from_left() * poses[i]));
  }
  return pairs;
}

std::string WriteFolders(const RenderedPairs& pairs, const std::string& name) {
  const std::string dir = test::TempFilePath(name);
  fs::remove_all(dir);
  fs::create_directories(dir + "/left");
  fs::create_directories(dir + "/right");
  for (size_t i = 0; i < pairs.left.size(); ++i) {
    char file[32];
    std::snprintf(file, sizeof(file), "/%03zu.png", i);
    EXPECT_TRUE(cv::imwrite(dir + "/left" + file, pairs.left[i]));
    EXPECT_TRUE(cv::imwrite(dir + "/right" + file, pairs.right[i]));
  }
  return dir;
}

const RenderedPairs& Pairs() {
  static const RenderedPairs* pairs = new RenderedPairs(Render());
  return *pairs;
}

std::vector<std::string> BoardFlags() {
  return {"--board", "chessboard", "--cols",   "7",
          "--rows",  "5",          "--square", "0.04"};
}

std::vector<std::string> Args(const std::string& dir, const std::string& out,
                              std::vector<std::string> extra = {}) {
  std::vector<std::string> args = {"calibrate", "--left",       dir + "/left",
                                   "--right",   dir + "/right", "--out",
                                   out};
  for (const std::string& flag : BoardFlags()) args.push_back(flag);
  for (const std::string& flag : extra) args.push_back(flag);
  return args;
}

// This checks the command's plumbing (the camchain is the calibration),
// not the method's accuracy, which calibration_on_renders_test.cc holds to
// the 0.1 %. With 14 small views of a 7x5 board at 0.5-0.8 m the
// focal lengths are weakly tied to the board distances: measured +0.46 %
// (2.9 covariance sigmas, 0.47 px) on all four at once. Bounds: focal
// lengths within 1 %, principal points within 2 px, baseline within 1 %.
void ExpectCloseToTruth(const std::string& camchain_path) {
  const StatusOr<Camchain> camchain = ReadCamchain(camchain_path);
  ASSERT_TRUE(camchain.ok()) << camchain.status().message();
  const StereoRig rig = StereoRigFromCamchain(*camchain, 0, 1).value();
  const StereoRig truth = SmallRig();
  const Camera* estimates[2] = {&rig.left(), &rig.right()};
  const Camera* truths[2] = {&truth.left(), &truth.right()};
  for (int c = 0; c < 2; ++c) {
    EXPECT_NEAR(estimates[c]->fx() / truths[c]->fx(), 1.0, 1e-2);
    EXPECT_NEAR(estimates[c]->fy() / truths[c]->fy(), 1.0, 1e-2);
    EXPECT_NEAR(estimates[c]->cx(), truths[c]->cx(), 2.0);
    EXPECT_NEAR(estimates[c]->cy(), truths[c]->cy(), 2.0);
  }
  EXPECT_NEAR(rig.Baseline() / truth.Baseline(), 1.0, 1e-2);
}

TEST(CalibrateCli, FoldersToCamchainAndReport) {
  const std::string dir = WriteFolders(Pairs(), "pairs");
  const std::string out = dir + "/rig.yaml";
  const RunResult result = Rcm(Args(dir, out, {"--folds", "4"}));
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const RenderedPairs& pairs = Pairs();
  EXPECT_GE(pairs.Stereo(), 10);
  EXPECT_NE(result.out.find(Views(pairs.Used(), pairs.Stereo())),
            std::string::npos)
      << result.out;
  ExpectCloseToTruth(out);
  // The covariance sidecar: medium air, its drift priors (0.1 degree and
  // 0.1 mm per axis, 0.3 % in each camera's focal lengths), both lenses'
  // covariance and the extrinsics'.
  const CalibrationCovarianceFile sidecar =
      ReadCalibrationCovariance(dir + "/rig-covariance.yaml").value();
  EXPECT_EQ(sidecar.medium, "air");
  EXPECT_NEAR(sidecar.drift_rotation_sigma, 0.1 * M_PI / 180.0, 1e-15);
  EXPECT_NEAR(sidecar.drift_translation_sigma, 1e-4, 1e-15);
  EXPECT_NEAR(sidecar.drift_focal_sigma, 0.003, 1e-15);
  ASSERT_EQ(sidecar.cameras.size(), 2u);
  EXPECT_EQ(sidecar.cameras[0].intrinsics_covariance.rows(), 8);
  EXPECT_TRUE(sidecar.cameras[1].from_previous_covariance.has_value());
  for (const char* file :
       {"calibration.json", "per_view.csv", "per_view_rms.png",
        "residuals_cam0.png", "residuals_cam1.png", "coverage_cam0.png",
        "coverage_cam1.png", "intrinsics_only_uncertainty_cam0.png",
        "intrinsics_only_uncertainty_cam1.png",
        "projection_uncertainty_cam0.png", "projection_uncertainty_cam1.png"}) {
    EXPECT_TRUE(fs::exists(dir + "/rig-report/" + file)) << file;
  }
  const nlohmann::json json = nlohmann::json::parse(
      test::ReadWholeFile(dir + "/rig-report/calibration.json"));
  EXPECT_EQ(json["stereo_views"], pairs.Stereo());
  EXPECT_EQ(json["cross_validation"]["folds"], 4);
  EXPECT_LT(json["rms_px"].get<double>(), 0.2);
  // The board's flatness (a flat board rendered: its bowl within a few
  // tenths of a millimetre, 0 within 4 sigma) and both uncertainties.
  EXPECT_TRUE(json["board_flatness"]["estimated"].get<bool>());
  EXPECT_EQ(json["board_flatness"]["board_warp_mm"].size(), 2u);
  EXPECT_LT(std::abs(json["board_flatness"]["bowl_mm"].get<double>()),
            4.0 * json["board_flatness"]["bowl_sigma_mm"].get<double>());
  EXPECT_NE(result.out.find("board flatness: bowl "), std::string::npos)
      << result.out;
  // The bowl's leave-out sigma: the folds' row, in the JSON's board
  // flatness (mm) and in the text's parentheses.
  const nlohmann::json& bowl_row =
      json["cross_validation"]["parameters"]["board bowl"];
  ASSERT_TRUE(bowl_row.is_object()) << json["cross_validation"].dump();
  EXPECT_GT(bowl_row["jackknife_sigma"].get<double>(), 0.0);
  EXPECT_DOUBLE_EQ(
      json["board_flatness"]["bowl_leave_out_sigma_mm"].get<double>(),
      1e3 * bowl_row["jackknife_sigma"].get<double>());
  EXPECT_DOUBLE_EQ(1e3 * bowl_row["full"].get<double>(),
                   json["board_flatness"]["bowl_mm"].get<double>());
  char leave_out[32];
  std::snprintf(
      leave_out, sizeof(leave_out), " (%.2f) mm at the centre",
      json["board_flatness"]["bowl_leave_out_sigma_mm"].get<double>());
  const size_t flatness = result.out.find("board flatness: bowl ");
  ASSERT_NE(flatness, std::string::npos) << result.out;
  EXPECT_NE(
      result.out.substr(flatness, result.out.find('\n', flatness) - flatness)
          .find(leave_out),
      std::string::npos)
      << result.out;
  EXPECT_EQ(json["projection_uncertainty"]["cam0"]["distance_m"], "inf");
  EXPECT_GT(json["projection_uncertainty"]["cam1"]["median_px"].get<double>(),
            0.0);
  EXPECT_GT(
      json["intrinsics_only_uncertainty_px"]["cam0"]["median"].get<double>(),
      0.0);
  EXPECT_NE(result.out.find("cam0 projection uncertainty at infinity"),
            std::string::npos)
      << result.out;
}

TEST(CalibrateCli, JsonOnStdoutAndAnOutputFolder) {
  const std::string dir = WriteFolders(Pairs(), "pairs");
  const RunResult result = Rcm(Args(dir, dir + "/calibration",
                                    {"--json", "--folds", "0", "--flat-board",
                                     "--uncertainty-distance", "1.5"}));
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const nlohmann::json json = nlohmann::json::parse(result.out);
  EXPECT_FALSE(json["board_flatness"]["estimated"].get<bool>());
  EXPECT_EQ(json["projection_uncertainty"]["cam0"]["distance_m"], 1.5);
  EXPECT_EQ(
      Rcm(Args(dir, dir + "/calibration", {"--uncertainty-distance", "-1"}))
          .exit_code,
      2);
  EXPECT_EQ(json["camchain"], dir + "/calibration/camchain.yaml");
  EXPECT_FALSE(json.contains("cross_validation"));
  EXPECT_FALSE(json["board_flatness"].contains("bowl_leave_out_sigma_mm"));
  EXPECT_EQ(json["cam0"]["distortion_model"], "radtan");
  EXPECT_EQ(json["cam0"]["sigma"].size(), 8u);
  ExpectCloseToTruth(dir + "/calibration/camchain.yaml");
  EXPECT_TRUE(fs::exists(dir + "/calibration/report/coverage_cam0.png"));
}

// The same calibration to rounding: two solves over the same corners in
// another order (a corners file keeps them in point order, the detector
// in its own, so the sums run differently) agree to ~1e-13 relative.
void ExpectSameCalibration(const std::string& a_path,
                           const std::string& b_path) {
  constexpr double kRelativeTolerance = 1e-9;
  const Camchain a = ReadCamchain(a_path).value();
  const Camchain b = ReadCamchain(b_path).value();
  ASSERT_EQ(a.cameras.size(), b.cameras.size());
  for (size_t c = 0; c < a.cameras.size(); ++c) {
    const Camera& x = a.cameras[c].camera;
    const Camera& y = b.cameras[c].camera;
    ASSERT_EQ(x.model(), y.model());
    for (int i = 0; i < x.num_params(); ++i) {
      EXPECT_NEAR(x.params()[i], y.params()[i],
                  kRelativeTolerance * std::max(1.0, std::abs(y.params()[i])))
          << "cam" << c << " parameter " << i;
    }
  }
  const Rigid3d& ta = *a.cameras[1].cam_from_previous;
  const Rigid3d& tb = *b.cameras[1].cam_from_previous;
  EXPECT_LT((ta.translation - tb.translation).norm(),
            kRelativeTolerance * tb.translation.norm());
  EXPECT_LT((ta.rotation - tb.rotation).norm(), kRelativeTolerance);
}

// --corners-out writes what the run calibrated from; --corners with the
// same --left/--right reads it back instead of detecting: the same
// corners (the file keeps shortest round-trip decimals), the same
// calibration.
TEST(CalibrateCli, CornersOutThenCornersGivesTheSameCamchain) {
  const std::string dir = WriteFolders(Pairs(), "pairs");
  const std::string corners = dir + "/corners.vnl";
  const RunResult detected = Rcm(Args(
      dir, dir + "/detected.yaml", {"--folds", "0", "--corners-out", corners}));
  ASSERT_EQ(detected.exit_code, 0) << detected.err;
  const std::string text = test::ReadWholeFile(corners);
  // 35 rows per image that shows the 7x5 board, one per image without it.
  const RenderedPairs& pairs = Pairs();
  EXPECT_EQ(text.rfind("# filename x y level\n", 0), 0u);
  EXPECT_NE(text.find(dir + "/left/000.png "), std::string::npos);
  EXPECT_NE(text.find(dir + "/right/000.png "), std::string::npos);
  EXPECT_GE(std::count(text.begin(), text.end(), '\n'),
            1 + 35 * 2 * pairs.Stereo());

  const RunResult read = Rcm(
      Args(dir, dir + "/read.yaml", {"--folds", "0", "--corners", corners}));
  ASSERT_EQ(read.exit_code, 0) << read.err;
  EXPECT_NE(read.out.find("corners file " + corners), std::string::npos)
      << read.out;
  ExpectSameCalibration(dir + "/read.yaml", dir + "/detected.yaml");
}

// mrcal's way of naming the cameras: one folder, a glob per camera, the
// frame number where '*' is; the images need not be at hand.
TEST(CalibrateCli, CornersOfMrcalStyleNamesPairByTheirNumber) {
  const std::string dir = WriteFolders(Pairs(), "pairs");
  const std::string corners = dir + "/corners.vnl";
  ASSERT_EQ(Rcm(Args(dir, dir + "/detected.yaml",
                     {"--folds", "0", "--corners-out", corners}))
                .exit_code,
            0);
  // left/007.png -> frames/left007.png, right/007.png -> frames/right007.png,
  // and the right camera's rows first: order does not matter, names do.
  std::string left_rows;
  std::string right_rows;
  {
    std::istringstream lines(test::ReadWholeFile(corners));
    for (std::string line; std::getline(lines, line);) {
      if (line.empty() || line[0] == '#') continue;
      for (const char* camera : {"left", "right"}) {
        const std::string from = dir + "/" + camera + "/";
        if (line.compare(0, from.size(), from) == 0) {
          (camera[0] == 'l' ? left_rows : right_rows) +=
              "frames/" + std::string(camera) + line.substr(from.size()) + "\n";
        }
      }
    }
  }
  const std::string renamed = dir + "/mrcal.vnl";
  std::ofstream(renamed) << "# filename x y level\n" << right_rows << left_rows;
  const cv::Size size = Pairs().left.front().size();
  const RunResult read =
      Rcm({"calibrate",
           "--corners",
           renamed,
           "--left",
           "frames/left*.png",
           "--right",
           "frames/right*.png",
           "--image-size",
           std::to_string(size.width) + "," + std::to_string(size.height),
           "--out",
           dir + "/read.yaml",
           "--folds",
           "0",
           "--board",
           "chessboard",
           "--cols",
           "7",
           "--rows",
           "5",
           "--square",
           BoardFlags()[7]});
  ASSERT_EQ(read.exit_code, 0) << read.err;
  ExpectSameCalibration(dir + "/read.yaml", dir + "/detected.yaml");
}

TEST(CalibrateCli, BoardInOneImageOnlyIsNamedAndUsedForThatCamera) {
  RenderedPairs pairs = Pairs();
  const int blanked = pairs.StereoPair();
  ASSERT_GE(blanked, 0);
  pairs.right[blanked] =
      cv::Mat(pairs.right[blanked].size(), CV_8UC1, cv::Scalar(160));
  const std::string dir = WriteFolders(pairs, "pairs");
  const RunResult result = Rcm(Args(dir, dir + "/rig.yaml", {"--folds", "0"}));
  ASSERT_EQ(result.exit_code, 0) << result.err;
  char name[16];
  std::snprintf(name, sizeof(name), "%03d.png", blanked);
  EXPECT_NE(result.err.find(name + std::string(" and ") + dir + "/right/" +
                            name + ": board found in the left image only"),
            std::string::npos)
      << result.err;
  EXPECT_NE(result.out.find(Views(pairs.Used(), pairs.Stereo() - 1)),
            std::string::npos)
      << result.out;
  ExpectCloseToTruth(dir + "/rig.yaml");
}

TEST(CalibrateCli, UnreadableImageSkipsItsPairOnly) {
  const std::string dir = WriteFolders(Pairs(), "pairs");
  const int broken = Pairs().StereoPair();
  ASSERT_GE(broken, 0);
  char name[16];
  std::snprintf(name, sizeof(name), "%03d.png", broken);
  {
    std::FILE* file = std::fopen((dir + "/left/" + name).c_str(), "wb");
    ASSERT_NE(file, nullptr);
    std::fputs("not a png", file);
    std::fclose(file);
  }
  const RunResult result = Rcm(Args(dir, dir + "/rig.yaml", {"--folds", "0"}));
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_NE(result.err.find(name), std::string::npos) << result.err;
  EXPECT_NE(result.err.find("pair skipped"), std::string::npos) << result.err;
  EXPECT_NE(result.out.find(Views(Pairs().Used() - 1, Pairs().Stereo() - 1)),
            std::string::npos)
      << result.out;
  ExpectCloseToTruth(dir + "/rig.yaml");
}

TEST(CalibrateCli, FoldersOfDifferentLengthsAreRefused) {
  const std::string dir = WriteFolders(Pairs(), "pairs");
  fs::rename(dir + "/right/013.png", dir + "/right/extra.png");
  fs::remove(dir + "/right/012.png");
  const RunResult result = Rcm(Args(dir, dir + "/rig.yaml"));
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_TRUE(test::IsOneLine(result.err)) << result.err;
  EXPECT_NE(result.err.find("14"), std::string::npos) << result.err;
  EXPECT_NE(result.err.find("13"), std::string::npos) << result.err;
  EXPECT_FALSE(fs::exists(dir + "/rig.yaml"));
}

TEST(CalibrateCli, NoTargetAnywhere) {
  RenderedPairs pairs = Pairs();
  // Fresh images: a copied cv::Mat shares its pixels with Pairs().
  for (cv::Mat& image : pairs.left) {
    image = cv::Mat(image.size(), CV_8UC1, cv::Scalar(90));
  }
  const std::string dir = WriteFolders(pairs, "pairs");
  const RunResult result = Rcm(Args(dir, dir + "/rig.yaml", {"--folds", "0"}));
  EXPECT_EQ(result.exit_code, 1);
  const std::string expected =
      "the target was found in both images of no pair (0 left only, " +
      std::to_string(std::count(Pairs().right_whole.begin(),
                                Pairs().right_whole.end(), true)) +
      " right only, of 14)";
  EXPECT_NE(result.err.find(expected), std::string::npos) << result.err;
  EXPECT_FALSE(fs::exists(dir + "/rig.yaml"));
}

TEST(CalibrateCli, UsageErrors) {
  const std::string dir = WriteFolders(Pairs(), "pairs");
  struct Case {
    std::vector<std::string> args;
    std::string message;
  };
  const std::vector<Case> cases = {
      {{"calibrate", "--left", dir + "/left", "--right", dir + "/right"},
       "--out is required"},
      {{"calibrate", "--out", dir + "/x.yaml", "--board", "chessboard"},
       "no images"},
      {{"calibrate", "--left", dir + "/left", "--right", dir + "/right",
        "--out", dir + "/x.yaml"},
       "no target"},
      {{"calibrate", "--left", dir + "/left", "--right", dir + "/right",
        "--out", dir + "/x.yaml", "--board", "circles"},
       "unknown --board 'circles'"},
      {{"calibrate", "--left", dir + "/left", "--right", dir + "/right",
        "--out", dir + "/x.yaml", "--board", "chessboard", "--cols", "7",
        "--rows", "5", "--square", "0.04", "--model", "fisheye"},
       "unknown --model 'fisheye'"},
      {{"calibrate", "--left", dir + "/left", "--right", dir + "/right",
        "--out", dir + "/x.yaml", "--board", "chessboard", "--cols", "1",
        "--rows", "5", "--square", "0.04"},
       "--board chessboard"},
  };
  for (const Case& c : cases) {
    const RunResult result = Rcm(c.args);
    EXPECT_EQ(result.exit_code, 2) << c.message;
    EXPECT_TRUE(test::IsOneLine(result.err)) << result.err;
    EXPECT_NE(result.err.find(c.message), std::string::npos) << result.err;
  }
  EXPECT_FALSE(fs::exists(dir + "/x.yaml"));
}

TEST(CalibrateCli, UnwritableOutputLeavesNoCamchain) {
  const std::string dir = WriteFolders(Pairs(), "pairs");
  const std::string blocker = dir + "/file";
  std::FILE* file = std::fopen(blocker.c_str(), "wb");
  ASSERT_NE(file, nullptr);
  std::fclose(file);
  const RunResult result =
      Rcm(Args(dir, blocker + "/rig.yaml", {"--folds", "0"}));
  EXPECT_EQ(result.exit_code, 1);
  // The last line of stderr is the one error (the source and warnings
  // come before it).
  const size_t last = result.err.rfind('\n', result.err.size() - 2);
  const std::string last_line = result.err.substr(last + 1);
  EXPECT_NE(last_line.find("rcm calibrate: error: cannot create folder"),
            std::string::npos)
      << result.err;
  EXPECT_EQ(result.err.find("error:"), result.err.rfind("error:"));
  EXPECT_FALSE(fs::exists(blocker + "/rig.yaml"));
}

#ifdef RCM_HAVE_ROSBAG
TEST(CalibrateCli, BagGivesTheFoldersResult) {
  const RenderedPairs& pairs = Pairs();
  const std::string dir = WriteFolders(pairs, "pairs");
  const std::string bag = test::TempFilePath("calib.bag");
  fs::remove(bag);
  StatusOr<BagImageWriter> writer = BagImageWriter::Create(bag);
  ASSERT_TRUE(writer.ok()) << writer.status().message();
  for (int i = 0; i < kPairs; ++i) {
    const double stamp = 1700000000.0 + 0.5 * i;
    ASSERT_TRUE(writer
                    ->WriteImage("/cam0/image_raw", stamp, pairs.left[i],
                                 "mono8", "cam0")
                    .ok());
    ASSERT_TRUE(writer
                    ->WriteImage("/cam1/image_raw", stamp + 0.001,
                                 pairs.right[i], "mono8", "cam1")
                    .ok());
  }
  ASSERT_TRUE(writer->Close().ok());
  std::vector<std::string> args = {"calibrate",
                                   "--bag",
                                   bag,
                                   "--left-topic",
                                   "/cam0/image_raw",
                                   "--right-topic",
                                   "/cam1/image_raw",
                                   "--out",
                                   dir + "/bag.yaml",
                                   "--folds",
                                   "0"};
  for (const std::string& flag : BoardFlags()) args.push_back(flag);
  const RunResult from_bag = Rcm(args);
  ASSERT_EQ(from_bag.exit_code, 0) << from_bag.err;
  const RunResult from_folders =
      Rcm(Args(dir, dir + "/folders.yaml", {"--folds", "0"}));
  ASSERT_EQ(from_folders.exit_code, 0) << from_folders.err;
  // The same pixels give the same calibration (to the last digits that
  // Ceres' two-thread summation order leaves free); the bag's camchain
  // names the topics.
  const Camchain a = ReadCamchain(dir + "/bag.yaml").value();
  const Camchain b = ReadCamchain(dir + "/folders.yaml").value();
  for (int c = 0; c < 2; ++c) {
    for (int i = 0; i < 8; ++i) {
      EXPECT_NEAR(a.cameras[c].camera.params()[i],
                  b.cameras[c].camera.params()[i],
                  1e-9 * (1.0 + std::abs(b.cameras[c].camera.params()[i])));
    }
  }
  EXPECT_EQ(a.cameras[0].rostopic, "/cam0/image_raw");
  EXPECT_EQ(a.cameras[1].rostopic, "/cam1/image_raw");
}
#endif

TEST(CalibrateCli, HelpListsTheTargetFlags) {
  // The target flags live in target_flags.cc, shared with rcm simulate.
  const RunResult result = Rcm({"calibrate", "--help"});
  EXPECT_EQ(result.exit_code, 0);
  for (const char* flag :
       {"--target=", "--board=", "--cols=", "--rows=", "--square=",
        "--tag-size=", "--tag-spacing=", "--marker=", "--dictionary="}) {
    EXPECT_NE(result.out.find(flag), std::string::npos) << flag;
  }
}

}  // namespace
}  // namespace rcm::calibrate_cli_test
