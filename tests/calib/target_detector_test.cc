#include "rcm/calib/target_detector.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <string>
#include <vector>

#include "rcm/calib/calibration_target.h"
#include "rcm/calib/target_image.h"
#include "rcm/calib/target_renderer.h"
#include "rcm/sim/reference_rigs.h"
#include "rcm/stereo/stereo_rig.h"

namespace rcm::calib::target_detector_test {
namespace {

// Detected corners against the renderer's ground truth, on 4x4
// supersampled renders (blur 0.5 px, noise 2 gray levels) at kViews,
// through AlphasenseFrontCam0 / EurocCam0. Measured (median, max):
// findChessboardCornersSB with CALIB_CB_ACCURACY 0.048 / 0.020 px,
// 0.303 / 0.136 px (the largest on one column of the tilted fisheye
// view): the brief's 0.1 / 0.3 px, the max with a little headroom.
constexpr double kToleranceChessboardMedianPx = 0.1;
constexpr double kToleranceChessboardMaxPx = 0.35;
// Kalibr tag corners refined by cornerSubPix on their X-junctions:
// 0.057 / 0.047 px, 0.219 / 0.205 px.
constexpr double kToleranceAprilGridMedianPx = 0.1;
constexpr double kToleranceAprilGridMaxPx = 0.3;
// interpolateCornersCharuco, refined again: 0.091 / 0.080 px, 0.184 /
// 0.167 px.
constexpr double kToleranceCharucoMedianPx = 0.15;
constexpr double kToleranceCharucoMaxPx = 0.3;

CalibrationTarget Checkerboard() {
  return MakeCheckerboardTarget(8, 5, 0.04).value();
}
CalibrationTarget AprilGrid() {
  return MakeAprilGridTarget(5, 4, 0.06, 0.3).value();
}
CalibrationTarget Charuco() {
  return MakeCharucoTarget(7, 5, 0.05, 0.037, "DICT_5X5_100").value();
}

// Texture pixels per metre: finer than a quarter camera pixel at the
// distances below.
constexpr double kPixelsPerMetre = 4000.0;

// The target's centre in its own frame.
Eigen::Vector3d TargetCentre(const CalibrationTarget& target) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  const std::vector<Eigen::Vector3d> points = TargetPoints(target);
  for (const Eigen::Vector3d& point : points) sum += point;
  return sum / static_cast<double>(points.size());
}

// The camera sees the printed side upright (target x right), the target's
// centre at `centre_in_camera`, turned by `roll` about the optical axis and
// tilted by `tilt_x`, `tilt_y` [rad] about the camera's x and y axes.
Rigid3d ViewPose(const CalibrationTarget& target,
                 const Eigen::Vector3d& centre_in_camera, double tilt_x,
                 double tilt_y, double roll) {
  // Checkerboard and charuco frames have y down as printed (z into the
  // board), Kalibr's aprilgrid y up (z out of the board).
  const Eigen::Matrix3d printed =
      target.type == TargetType::kAprilGrid
          ? Eigen::Vector3d(1.0, -1.0, -1.0).asDiagonal().toDenseMatrix()
          : Eigen::Matrix3d::Identity();
  Rigid3d pose;
  pose.rotation = (Eigen::AngleAxisd(tilt_x, Eigen::Vector3d::UnitX()) *
                   Eigen::AngleAxisd(tilt_y, Eigen::Vector3d::UnitY()) *
                   Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitZ()))
                      .toRotationMatrix() *
                  printed;
  pose.translation = centre_in_camera - pose.rotation * TargetCentre(target);
  return pose;
}

TargetRenderOptions RenderOptions(uint64_t seed) {
  TargetRenderOptions options;
  options.supersampling = 4;
  options.blur_sigma_px = 0.5;
  options.noise_sigma = 2.0;
  options.seed = seed;
  return options;
}

struct Errors {
  std::vector<double> errors;
  int missing = 0;  // truth in the image, not detected

  double Median() const {
    std::vector<double> sorted = errors;
    std::sort(sorted.begin(), sorted.end());
    return sorted.empty() ? 0.0 : sorted[sorted.size() / 2];
  }
  double Max() const {
    return errors.empty() ? 0.0
                          : *std::max_element(errors.begin(), errors.end());
  }
};

// Adds the errors of `observation` against the truth. Every detected id
// must have a truth in the image.
void AddErrors(const TargetObservation& observation,
               const std::vector<std::optional<Eigen::Vector2d>>& truth,
               Errors* errors) {
  for (int k = 0; k < observation.size(); ++k) {
    const int id = observation.point_ids[k];
    ASSERT_GE(id, 0);
    ASSERT_LT(id, static_cast<int>(truth.size()));
    ASSERT_TRUE(truth[id].has_value()) << "id " << id;
    errors->errors.push_back((observation.pixels[k] - *truth[id]).norm());
  }
}

struct View {
  Eigen::Vector3d centre;
  double tilt_x, tilt_y, roll;
};

// Views of the board near the image centre and towards a corner, tilted.
const View kViews[] = {
    {{0.0, 0.0, 0.55}, 0.0, 0.0, 0.05},
    {{0.05, -0.03, 0.6}, 0.35, -0.3, 0.2},
    {{-0.08, 0.06, 0.5}, -0.3, 0.35, -0.15},
};

// Renders `target` through `camera` at kViews and returns the errors of
// DetectTarget (all views must be detected).
Errors MeasureOnRenders(const Camera& camera, const CalibrationTarget& target,
                        const char* label) {
  const TargetRenderer renderer =
      TargetRenderer::Create(camera, DrawTargetImage(target, kPixelsPerMetre))
          .value();
  Errors errors;
  uint64_t seed = 1;
  for (const View& view : kViews) {
    const Rigid3d pose =
        ViewPose(target, view.centre, view.tilt_x, view.tilt_y, view.roll);
    const cv::Mat image = renderer.Render(pose, RenderOptions(seed++));

    const std::optional<TargetObservation> observation =
        DetectTarget(image, target);
    EXPECT_TRUE(observation.has_value()) << label << " view " << seed - 1;
    if (!observation) continue;
    const std::vector<std::optional<Eigen::Vector2d>> truth =
        ProjectTargetPoints(camera, pose, target);
    AddErrors(*observation, truth, &errors);
    int visible = 0;
    for (const auto& pixel : truth) visible += pixel.has_value();
    errors.missing += visible - observation->size();
  }
  std::printf("%s: %zu corners, %d missed, median %.3f px, max %.3f px\n",
              label, errors.errors.size(), errors.missing, errors.Median(),
              errors.Max());
  return errors;
}

TEST(TargetDetector, ChessboardSubpixelOnRender) {
  for (const Camera& camera : {AlphasenseFrontCam0(), EurocCam0()}) {
    const Errors errors = MeasureOnRenders(
        camera, Checkerboard(),
        camera.width() == 720 ? "chessboard alphasense" : "chessboard euroc");
    ASSERT_FALSE(errors.errors.empty());
    EXPECT_EQ(errors.missing, 0);
    EXPECT_LT(errors.Median(), kToleranceChessboardMedianPx);
    EXPECT_LT(errors.Max(), kToleranceChessboardMaxPx);
  }
}

TEST(TargetDetector, AprilGridSubpixelOnRender) {
  for (const Camera& camera : {AlphasenseFrontCam0(), EurocCam0()}) {
    const Errors errors = MeasureOnRenders(
        camera, AprilGrid(),
        camera.width() == 720 ? "aprilgrid alphasense" : "aprilgrid euroc");
    ASSERT_FALSE(errors.errors.empty());
    EXPECT_EQ(errors.missing, 0);
    EXPECT_LT(errors.Median(), kToleranceAprilGridMedianPx);
    EXPECT_LT(errors.Max(), kToleranceAprilGridMaxPx);
  }
}

TEST(TargetDetector, CharucoSubpixelOnRender) {
  for (const Camera& camera : {AlphasenseFrontCam0(), EurocCam0()}) {
    const Errors errors = MeasureOnRenders(
        camera, Charuco(),
        camera.width() == 720 ? "charuco alphasense" : "charuco euroc");
    ASSERT_FALSE(errors.errors.empty());
    EXPECT_EQ(errors.missing, 0);
    EXPECT_LT(errors.Median(), kToleranceCharucoMedianPx);
    EXPECT_LT(errors.Max(), kToleranceCharucoMaxPx);
  }
}

// The id of the truth nearest to `pixel`.
int NearestTruth(const Eigen::Vector2d& pixel,
                 const std::vector<std::optional<Eigen::Vector2d>>& truth) {
  int best = -1;
  double best_distance = std::numeric_limits<double>::infinity();
  for (size_t id = 0; id < truth.size(); ++id) {
    if (!truth[id]) continue;
    const double distance = (*truth[id] - pixel).norm();
    if (distance < best_distance) {
      best_distance = distance;
      best = static_cast<int>(id);
    }
  }
  return best;
}

// A stereo pair of `target` rendered through the unrectified Alphasense
// rig, the left camera at `left_from_target`.
struct RenderedPair {
  cv::Mat left, right;
  std::vector<std::optional<Eigen::Vector2d>> left_truth, right_truth;
};

RenderedPair RenderPair(const CalibrationTarget& target,
                        const Rigid3d& left_from_target) {
  const StereoRig rig = AlphasenseFrontUnrectifiedRig();
  const TargetImage texture = DrawTargetImage(target, kPixelsPerMetre);
  const Rigid3d right_from_target = rig.right_from_left() * left_from_target;
  RenderedPair pair;
  pair.left = TargetRenderer::Create(rig.left(), texture)
                  .value()
                  .Render(left_from_target, RenderOptions(11));
  pair.right = TargetRenderer::Create(rig.right(), texture)
                   .value()
                   .Render(right_from_target, RenderOptions(12));
  pair.left_truth = ProjectTargetPoints(rig.left(), left_from_target, target);
  pair.right_truth =
      ProjectTargetPoints(rig.right(), right_from_target, target);
  return pair;
}

// Every id of the view names the same physical corner in both images.
void ExpectConsistentIds(const StereoView& view, const RenderedPair& pair) {
  ASSERT_TRUE(view.stereo()) << view.note;
  std::map<int, int> left_physical;
  for (int k = 0; k < view.left->size(); ++k) {
    left_physical[view.left->point_ids[k]] =
        NearestTruth(view.left->pixels[k], pair.left_truth);
  }
  int compared = 0;
  for (int k = 0; k < view.right->size(); ++k) {
    const auto left = left_physical.find(view.right->point_ids[k]);
    if (left == left_physical.end()) continue;
    EXPECT_EQ(NearestTruth(view.right->pixels[k], pair.right_truth),
              left->second)
        << "id " << view.right->point_ids[k];
    ++compared;
  }
  EXPECT_GT(compared, 0);
}

TEST(TargetDetector, ChessboardPairRotated180HasConsistentIds) {
  // Turned by 180 degrees in the image: the detector's first corner is the
  // board's last, and the canonical order relabels it.
  const CalibrationTarget target = Checkerboard();
  const RenderedPair pair = RenderPair(
      target, ViewPose(target, {0.03, 0.01, 0.6}, 0.2, -0.25, M_PI + 0.1));
  const StereoView view = DetectTargetPair(pair.left, pair.right, target);
  EXPECT_EQ(view.note, "");
  ExpectConsistentIds(view, pair);
  EXPECT_EQ(view.left->detector, "chessboard-sb");
  EXPECT_EQ(view.right->detector, "chessboard-sb");
  // Canonical: corner 0 is the one nearest the top-left of the image.
  const Eigen::Vector2d first = view.left->pixels[0];
  for (const Eigen::Vector2d& pixel : view.left->pixels) {
    EXPECT_LE(first.sum(), pixel.sum() + 1e-9);
  }
}

TEST(TargetDetector, SquareChessboardPairHasConsistentIds) {
  // A square grid: the order is ambiguous by 90 degrees as well.
  const CalibrationTarget target = MakeCheckerboardTarget(6, 6, 0.04).value();
  const RenderedPair pair = RenderPair(
      target, ViewPose(target, {0.0, 0.0, 0.55}, -0.2, 0.2, 0.5 * M_PI));
  const StereoView view = DetectTargetPair(pair.left, pair.right, target);
  ExpectConsistentIds(view, pair);
}

TEST(TargetDetector, AprilGridAndCharucoPairsHaveConsistentIds) {
  for (const CalibrationTarget& target : {AprilGrid(), Charuco()}) {
    const RenderedPair pair = RenderPair(
        target, ViewPose(target, {0.0, 0.02, 0.55}, 0.15, 0.2, M_PI));
    const StereoView view = DetectTargetPair(pair.left, pair.right, target);
    EXPECT_EQ(view.note, "");
    ExpectConsistentIds(view, pair);
  }
}

TEST(TargetDetector, PairWithBoardOnlyInLeftImage) {
  const CalibrationTarget target = Checkerboard();
  const RenderedPair pair =
      RenderPair(target, ViewPose(target, {0.0, 0.0, 0.6}, 0.1, 0.1, 0.0));
  const cv::Mat empty_right(pair.right.size(), CV_8UC1, cv::Scalar(160));
  const StereoView view = DetectTargetPair(pair.left, empty_right, target);
  EXPECT_TRUE(view.left.has_value());
  EXPECT_FALSE(view.right.has_value());
  EXPECT_EQ(view.note, "board found in the left image only");
}

TEST(TargetDetector, PairOneThreadEqualsTwoThreads) {
  const CalibrationTarget target = Charuco();
  const RenderedPair pair =
      RenderPair(target, ViewPose(target, {0.0, 0.0, 0.6}, 0.1, 0.1, 0.0));
  TargetDetectorOptions one_thread;
  one_thread.num_threads = 1;
  const StereoView a = DetectTargetPair(pair.left, pair.right, target);
  const StereoView b =
      DetectTargetPair(pair.left, pair.right, target, one_thread);
  ASSERT_TRUE(a.stereo() && b.stereo());
  EXPECT_EQ(a.left->point_ids, b.left->point_ids);
  EXPECT_EQ(a.right->pixels, b.right->pixels);
}

TEST(TargetDetector, ImageWithoutBoardGivesNullopt) {
  // A render of one target type holds no board of the others.
  const CalibrationTarget checkerboard = Checkerboard();
  const RenderedPair pair = RenderPair(
      checkerboard, ViewPose(checkerboard, {0.0, 0.0, 0.6}, 0.1, 0.1, 0.0));
  EXPECT_FALSE(DetectTarget(pair.left, AprilGrid()).has_value());
  EXPECT_FALSE(DetectTarget(pair.left, Charuco()).has_value());
  const CalibrationTarget charuco = Charuco();
  const RenderedPair charuco_pair =
      RenderPair(charuco, ViewPose(charuco, {0.0, 0.0, 0.6}, 0.1, 0.1, 0.0));
  EXPECT_FALSE(DetectTarget(charuco_pair.left, AprilGrid()).has_value());
  // No markers of the board's dictionary in an aprilgrid.
  const CalibrationTarget aprilgrid = AprilGrid();
  const RenderedPair aprilgrid_pair = RenderPair(
      aprilgrid, ViewPose(aprilgrid, {0.0, 0.0, 0.6}, 0.1, 0.1, 0.0));
  EXPECT_FALSE(DetectTarget(aprilgrid_pair.left, charuco).has_value());
}

TEST(TargetDetector, BlankTinyAndEmptyImagesNeverCrash) {
  const std::vector<cv::Mat> images = {
      cv::Mat(),
      cv::Mat(1, 1, CV_8UC1, cv::Scalar(0)),
      cv::Mat(15, 40, CV_8UC1, cv::Scalar(255)),
      cv::Mat(16, 16, CV_8UC3, cv::Scalar(0, 0, 0)),
      cv::Mat(120, 160, CV_8UC1, cv::Scalar(160)),
      cv::Mat(120, 160, CV_8UC4, cv::Scalar(10, 20, 30, 255)),
      cv::Mat(120, 160, CV_32FC1, cv::Scalar(0.5)),
      cv::Mat(120, 160, CV_8UC2, cv::Scalar(1, 2)),
  };
  for (const CalibrationTarget& target :
       {Checkerboard(), AprilGrid(), Charuco()}) {
    for (const cv::Mat& image : images) {
      EXPECT_FALSE(DetectTarget(image, target).has_value());
      const StereoView view = DetectTargetPair(image, image, target);
      EXPECT_FALSE(view.left.has_value());
      EXPECT_FALSE(view.right.has_value());
      EXPECT_EQ(view.note, "board found in neither image");
    }
  }
}

TEST(TargetDetector, DetectsInBgrImage) {
  const CalibrationTarget target = Checkerboard();
  const RenderedPair pair =
      RenderPair(target, ViewPose(target, {0.0, 0.0, 0.6}, 0.1, 0.1, 0.0));
  cv::Mat bgr;
  cv::cvtColor(pair.left, bgr, cv::COLOR_GRAY2BGR);
  const std::optional<TargetObservation> observation =
      DetectTarget(bgr, target);
  ASSERT_TRUE(observation.has_value());
  EXPECT_EQ(observation->size(), NumTargetPoints(target));
}

TEST(TargetDetectorOptions, Check) {
  EXPECT_TRUE(TargetDetectorOptions().Check().ok());
  TargetDetectorOptions options;
  options.min_charuco_corners = 3;
  EXPECT_EQ(options.Check().message(), "min_charuco_corners = 3 must be >= 4");
  options = TargetDetectorOptions();
  options.chessboard_pair_max_ratio = 1.0;
  EXPECT_FALSE(options.Check().ok());
  options = TargetDetectorOptions();
  options.num_threads = 0;
  EXPECT_FALSE(options.Check().ok());
}

}  // namespace
}  // namespace rcm::calib::target_detector_test
