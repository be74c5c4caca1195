// The calibration board rendered into the pool (stereo_renderer.h,
// scene_board.h) against ground truth: the pixels are the exact pixel
// integrals of the pattern seen through the port, and rcm::calib's
// chessboard detector finds the corners where the exact flat-port (or
// dome) projection of the truth corners puts them.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include "rcm/calib/calibration_target.h"
#include "rcm/calib/target_detector.h"
#include "rcm/camera/dome_port_geometry.h"
#include "rcm/camera/flat_port_camera.h"
#include "rcm/sim/board_motion.h"
#include "rcm/sim/port_camera.h"
#include "rcm/sim/reference_rigs.h"
#include "rcm/sim/scene_board.h"
#include "rcm/sim/stereo_renderer.h"
#include "rcm/sim/trajectory.h"
#include "sim/test_pool.h"
#include "support/test_rigs.h"

namespace rcm::board_rendering_test {
namespace {

constexpr double kWaterIndex = 1.34;

using test::Pool;
using test::RobotPose;

// 8 mm of air and 6 mm of glass: a real housing's port.
FlatPort ThickPort() {
  FlatPort port;
  port.air_gap = 0.008;
  port.glass_thickness = 0.006;
  return port;
}

// The board `distance` ahead of cam0, centered between the two optical
// axes, tilted by `tilt_deg` about a skew axis in its plane and turned by
// `roll_deg` about its normal.
Rigid3d BoardPose(const StereoRig& rig, const SceneBoard& board,
                  double distance, double tilt_deg, double roll_deg) {
  const BoardMotion motion =
      BoardMotion::Create(board, BoardMotionOptions(), rig.right_from_left())
          .value();
  Rigid3d pose;
  pose.rotation =
      (Eigen::AngleAxisd(tilt_deg * M_PI / 180.0,
                         Eigen::Vector3d(0.8, 0.6, 0.0)) *
       Eigen::AngleAxisd(roll_deg * M_PI / 180.0, Eigen::Vector3d::UnitZ()))
          .toRotationMatrix();
  pose.translation =
      motion.NeutralPoint(distance) - pose.rotation * board.Center();
  return pose;
}

// Decenterings of 1-3 mm laterally and 5-10 mm axially, one per camera.
const std::array<std::optional<DomePort>, 2> kDomes = {
    rcm::test::AcrylicDome(Eigen::Vector3d(0.002, -0.001, 0.007)),
    rcm::test::AcrylicDome(Eigen::Vector3d(-0.0015, 0.0025, 0.009))};

struct Scene {
  StereoImages images;
  std::array<PortCamera, 2> cameras;
  std::array<Rigid3d, 2> world_from_camera;
  PlacedBoard board;
};

// With `domes`, each camera looks through its dome (when given) instead
// of `port`.
Scene Render(const StereoRig& rig, const FlatPort& port,
             const SceneBoard& board, const Rigid3d& cam0_from_target,
             const RenderOptions& options,
             const std::array<std::optional<DomePort>, 2>& domes = {}) {
  StereoRenderer renderer = StereoRenderer::Create(rig, port, port, &Pool(),
                                                   options, domes[0], domes[1])
                                .value();
  const Rigid3d world_from_cam0 = RobotPose();
  const PlacedBoard placed(board, world_from_cam0 * cam0_from_target);
  return Scene{
      renderer.Render(world_from_cam0, kWaterIndex, 0, &placed).value(),
      {PortCamera::Create(rig.left(), port, domes[0], kWaterIndex).value(),
       PortCamera::Create(rig.right(), port, domes[1], kWaterIndex).value()},
      {world_from_cam0, world_from_cam0 * rig.right_from_left().Inverse()},
      placed};
}

struct CornerErrors {
  int detected = 0;
  double median = 0.0;  // px
  double max = 0.0;     // px
};

// rcm::calib's detections in camera c's image against the exact
// projections of the truth corners.
CornerErrors DetectionErrors(const Scene& scene, int c) {
  const SceneBoard& board = scene.board.board();
  const calib::CalibrationTarget target =
      calib::MakeCheckerboardTarget(board.cols, board.rows, board.square)
          .value();
  const std::optional<calib::TargetObservation> observation =
      calib::DetectTarget(c == 0 ? scene.images.left : scene.images.right,
                          target);
  CornerErrors errors;
  if (!observation) return errors;
  const std::vector<Eigen::Vector3d> corners = board.Corners();
  const Rigid3d camera_from_target =
      scene.world_from_camera[c].Inverse() * scene.board.world_from_target();
  std::vector<double> distances;
  for (int k = 0; k < observation->size(); ++k) {
    const Eigen::Vector2d truth =
        scene.cameras[c]
            .ImageFromPoint(camera_from_target *
                            corners[observation->point_ids[k]])
            .value();
    distances.push_back((observation->pixels[k] - truth).norm());
  }
  std::sort(distances.begin(), distances.end());
  errors.detected = observation->size();
  errors.median = distances[distances.size() / 2];
  errors.max = distances.back();
  return errors;
}

// Detection against the truth (findChessboardCornersSB with
// CALIB_CB_ACCURACY, each corner refined by cornerSubPix on its junction,
// calib/target_detector.h). Measured (median / max over both cameras, the
// board 1.2 m ahead, tilted 30 degrees, default rendering with sensor
// noise):
//   narrow      thin port 0.030 / 0.065 px, 8 mm air + 6 mm glass 0.028 /
//               0.078 px
//   alphasense  thin port 0.031 / 0.081 px, 8 mm air + 6 mm glass 0.029 /
//               0.078 px
// SB alone gave 0.035 / 0.097 px (narrow) and 0.061 / 0.168 px
// (alphasense), its border corners pulled outward (BorderCornersAreNot-
// PulledOutward); the brief's 0.1 / 0.3 px then held, the bounds are now
// tightened to ~1.6 and ~1.8 times the refined figures. The residual is the
// detector's: the renders are not shifted from the exact pixel integral by
// more than ~0.01 px (PixelsAreTheExactPixelIntegral). With SB alone, its
// largest errors depended on the view in a way that was not the
// renderer's: on this rig in air, calib's own target renderer
// (target_renderer.h) gave maxima of 0.28-0.53 px with the board 0.6-0.8
// m away, tilted 35 degrees, and 0.09-0.15 px at 0.5, 0.9 and 1.2 m; this
// renderer did the same (measured while writing this test). Hence 1.2 m.
constexpr double kMedianTolerancePx = 0.05;
constexpr double kMaxTolerancePx = 0.15;

void ExpectCornersWhereTheyProject(const StereoRig& rig) {
  const SceneBoard board;  // 9 x 6 inner corners, 30 mm squares
  for (const FlatPort& port : {FlatPort(), ThickPort()}) {
    SCOPED_TRACE("air gap " + std::to_string(port.air_gap));
    const Scene scene =
        Render(rig, port, board, BoardPose(rig, board, 1.2, 30.0, 7.0),
               RenderOptions());
    for (int c = 0; c < 2; ++c) {
      SCOPED_TRACE(c == 0 ? "left" : "right");
      const CornerErrors errors = DetectionErrors(scene, c);
      EXPECT_EQ(errors.detected, board.cols * board.rows);
      EXPECT_LT(errors.median, kMedianTolerancePx);
      EXPECT_LT(errors.max, kMaxTolerancePx);
    }
  }
}

TEST(BoardRendering, NarrowRigCornersAreDetectedWhereTheyProject) {
  ExpectCornersWhereTheyProject(NarrowFieldRig());
}

TEST(BoardRendering, AlphasenseCornersAreDetectedWhereTheyProject) {
  ExpectCornersWhereTheyProject(AlphasenseFrontRectifiedRig());
}

// Through decentered domes (kDomes) the same: the renderer traces the
// dome's exact rays, so the corners are found where
// DomePortCamera::ImageFromPoint puts them, within the flat port's bounds.
TEST(BoardRendering, DomeCornersAreDetectedWhereTheDomeProjects) {
  const StereoRig rig = AlphasenseFrontRectifiedRig();
  const SceneBoard board;
  const Scene scene =
      Render(rig, FlatPort(), board, BoardPose(rig, board, 1.2, 30.0, 7.0),
             RenderOptions(), kDomes);
  for (int c = 0; c < 2; ++c) {
    SCOPED_TRACE(c == 0 ? "left" : "right");
    ASSERT_TRUE(scene.cameras[c].is_dome());
    const CornerErrors errors = DetectionErrors(scene, c);
    std::printf(
        "%s through its dome: %d corners, median %.3f px, max %.3f px\n",
        c == 0 ? "left" : "right", errors.detected, errors.median, errors.max);
    EXPECT_EQ(errors.detected, board.cols * board.rows);
    EXPECT_LT(errors.median, kMedianTolerancePx);
    EXPECT_LT(errors.max, kMaxTolerancePx);
  }
}

// The mean error of the detected corners on the pattern's border (the
// outer rows and columns) along the outward direction of the border (away
// from the pattern, in the image: from the next corner inwards to the
// corner), over both cameras' images of `scene`; each corner counts once
// per border it is on. Adds to *sum and *count.
void AddBorderOutwardErrors(const Scene& scene, double* sum, int* count) {
  const SceneBoard& board = scene.board.board();
  const calib::CalibrationTarget target =
      calib::MakeCheckerboardTarget(board.cols, board.rows, board.square)
          .value();
  const std::vector<Eigen::Vector3d> corners = board.Corners();
  for (int c = 0; c < 2; ++c) {
    const std::optional<calib::TargetObservation> observation =
        calib::DetectTarget(c == 0 ? scene.images.left : scene.images.right,
                            target);
    ASSERT_TRUE(observation.has_value());
    const Rigid3d camera_from_target =
        scene.world_from_camera[c].Inverse() * scene.board.world_from_target();
    const auto truth = [&](int id) {
      return scene.cameras[c]
          .ImageFromPoint(camera_from_target * corners[id])
          .value();
    };
    for (int k = 0; k < observation->size(); ++k) {
      const int id = observation->point_ids[k];
      const int r = id / board.cols, col = id % board.cols;
      const Eigen::Vector2d error = observation->pixels[k] - truth(id);
      std::vector<int> inward;  // the neighbour towards the pattern
      if (r == 0) inward.push_back(id + board.cols);
      if (r == board.rows - 1) inward.push_back(id - board.cols);
      if (col == 0) inward.push_back(id + 1);
      if (col == board.cols - 1) inward.push_back(id - 1);
      for (const int next : inward) {
        *sum += error.dot((truth(id) - truth(next)).normalized());
        ++*count;
      }
    }
  }
}

// The corners on the border of the pattern are found where they project,
// not pulled out towards the white margin. findChessboardCornersSB alone
// (before calib refined its corners on their junctions) put them outward
// on the dataset rig by 0.05-0.09 px with the board at 0.6-0.9 m and 1.6-2
// m (measured on rcm simulate's dives), which took n 2.35e-3 high on the
// end-to-end dive of seed 1: a board spread at its border looks like extra
// refraction. The interior corners were unbiased. Here (40 mm squares, the
// board 0.75 and 1.8 m ahead) SB alone gives +0.078 px; refined, -0.001
// px. The bound: the refined corners scatter by ~0.1 px each
// (their RMS error on these renders), so the mean over the 2 x 2 x 30
// border terms has a standard error of ~0.01 px; 3 of them.
TEST(BoardRendering, BorderCornersAreNotPulledOutward) {
  constexpr double kMeanOutwardTolerancePx = 0.03;
  const StereoRig rig = AlphasenseFrontRectifiedRig();
  SceneBoard board;
  board.square = 0.04;
  double sum = 0.0;
  int count = 0;
  for (const double distance : {0.75, 1.8}) {
    SCOPED_TRACE("distance " + std::to_string(distance));
    const Scene scene =
        Render(rig, FlatPort(), board,
               BoardPose(rig, board, distance, 30.0, 7.0), RenderOptions());
    AddBorderOutwardErrors(scene, &sum, &count);
  }
  ASSERT_GT(count, 0);
  EXPECT_LT(std::abs(sum / count), kMeanOutwardTolerancePx);
}

// The exact pixel integral of the board's radiance: the mean over
// kSamples x kSamples point samples of the pixel of
//   radiance = albedo irradiance T + water (1 - T)
// along exact rays (double precision, no ray table), point albedo. Lamp
// off, so irradiance is the daylight term alone. In DN, without noise.
double ExactPixel(const Scene& scene, const RenderOptions& options, int x,
                  int y) {
  constexpr int kSamples = 12;  // per pixel along each axis
  const PortCamera& camera = scene.cameras[0];
  const Rigid3d& world_from_camera = scene.world_from_camera[0];
  double radiance = 0.0;
  for (int j = 0; j < kSamples; ++j) {
    for (int i = 0; i < kSamples; ++i) {
      const Eigen::Vector2d sample(x + (i + 0.5) / kSamples - 0.5,
                                   y + (j + 0.5) / kSamples - 0.5);
      const RayInMedium ray = camera.RayFromImage(sample).value();
      const BoardHit hit =
          scene.board
              .Intersect(world_from_camera * ray.origin,
                         world_from_camera.rotation * ray.direction)
              .value();
      const double albedo = scene.board.board().FilteredAlbedo(
          hit.point_in_target.x(), hit.point_in_target.y(), 0.0, 0.0);
      const double irradiance = options.ambient * (0.7 + 0.3 * hit.normal.z());
      const double transmittance =
          std::exp(-options.water_attenuation * hit.distance);
      radiance += albedo * irradiance * transmittance +
                  options.water_radiance * (1.0 - transmittance);
    }
  }
  return 255.0 * options.exposure * radiance / (kSamples * kSamples);
}

// The left image's pixels around every corner against ExactPixel, the
// narrow rig behind `port` or, where given, `domes`.
void ExpectExactPixelIntegral(
    const FlatPort& port, const std::array<std::optional<DomePort>, 2>& domes) {
  // Around every corner of the left image (narrow rig, thick port, board
  // 0.9 m ahead, tilted 35 degrees: 20 px squares), the rendered pixels
  // against ExactPixel:
  // - where it matters for calibration, position: the least-squares
  //   sub-pixel shift between the two over each corner's 5 x 5 window,
  //   d = -(sum g g^T)^-1 sum g (rendered - exact), g the exact window's
  //   gradient. It scatters about zero by ~0.01 px (rounding to DN, the
  //   reference's own point sampling): measured mean over the 54 corners
  //   0.002 px, largest 0.037 px. A systematic error (a ray table off by
  //   half a sample would shift by 0.25 px) shows in the mean;
  // - the values: the renderer filters each of its 2 x 2 samples over the
  //   sample's own footprint (0.5-0.7 px here), a blur the pure pixel box
  //   lacks, symmetric about each edge (so no shift). It differs from the
  //   pixel box by up to footprint / 8 of a step at an edge's ends: on the
  //   ~100 DN steps here measured mean 0.46 DN, max 4.0 DN.
  constexpr double kMeanShiftTolerancePx = 0.01;
  constexpr double kShiftTolerancePx = 0.06;
  constexpr double kMeanToleranceDn = 0.6;
  constexpr double kMaxToleranceDn = 8.0;
  constexpr int kHalf = 2;  // 5 x 5 windows
  RenderOptions options;
  options.read_noise = 0.0;
  options.full_well = 0.0;
  options.light_intensity = 0.0;
  const StereoRig rig = NarrowFieldRig();
  const SceneBoard board;
  const Scene scene = Render(
      rig, port, board, BoardPose(rig, board, 0.9, 35.0, 7.0), options, domes);
  const Rigid3d camera_from_target =
      scene.world_from_camera[0].Inverse() * scene.board.world_from_target();
  double sum = 0.0, worst = 0.0, worst_shift = 0.0;
  Eigen::Vector2d shift_sum = Eigen::Vector2d::Zero();
  int count = 0;
  for (const Eigen::Vector3d& corner : board.Corners()) {
    const Eigen::Vector2d center =
        scene.cameras[0].ImageFromPoint(camera_from_target * corner).value();
    const int cx = static_cast<int>(std::lround(center.x()));
    const int cy = static_cast<int>(std::lround(center.y()));
    // The exact window with a border of one pixel for the gradient.
    Eigen::MatrixXd exact(2 * kHalf + 3, 2 * kHalf + 3);
    for (int j = 0; j < exact.rows(); ++j) {
      for (int i = 0; i < exact.cols(); ++i) {
        exact(j, i) =
            ExactPixel(scene, options, cx - kHalf - 1 + i, cy - kHalf - 1 + j);
      }
    }
    Eigen::Matrix2d normal = Eigen::Matrix2d::Zero();
    Eigen::Vector2d gradient_dot_error = Eigen::Vector2d::Zero();
    for (int j = 1; j <= 2 * kHalf + 1; ++j) {
      for (int i = 1; i <= 2 * kHalf + 1; ++i) {
        const double rendered = scene.images.left.at<uint8_t>(
            cy - kHalf - 1 + j, cx - kHalf - 1 + i);
        const double error = rendered - exact(j, i);
        const Eigen::Vector2d g(0.5 * (exact(j, i + 1) - exact(j, i - 1)),
                                0.5 * (exact(j + 1, i) - exact(j - 1, i)));
        normal += g * g.transpose();
        gradient_dot_error += g * error;
        sum += std::abs(error);
        worst = std::max(worst, std::abs(error));
        ++count;
      }
    }
    const Eigen::Vector2d shift = -normal.ldlt().solve(gradient_dot_error);
    worst_shift = std::max(worst_shift, shift.norm());
    shift_sum += shift;
  }
  std::printf("shift mean %.4f px, largest %.4f px; DN mean %.2f, max %.1f\n",
              shift_sum.norm() / board.Corners().size(), worst_shift,
              sum / count, worst);
  EXPECT_LT(shift_sum.norm() / board.Corners().size(), kMeanShiftTolerancePx);
  EXPECT_LT(worst_shift, kShiftTolerancePx);
  EXPECT_LT(sum / count, kMeanToleranceDn);
  EXPECT_LT(worst, kMaxToleranceDn);
}

TEST(BoardRendering, PixelsAreTheExactPixelIntegral) {
  ExpectExactPixelIntegral(ThickPort(), {});
}

// Through a decentered dome the renderer's ray table holds the dome's
// exact rays: the same bounds.
TEST(BoardRendering, DomePixelsAreTheExactPixelIntegral) {
  ExpectExactPixelIntegral(FlatPort(), kDomes);
}

}  // namespace
}  // namespace rcm::board_rendering_test
