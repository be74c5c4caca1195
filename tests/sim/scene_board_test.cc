#include "rcm/sim/scene_board.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <random>
#include <vector>

#include "rcm/calib/board_warp.h"
#include "rcm/calib/calibration_target.h"
#include "rcm/calib/target_image.h"
#include "rcm/sim/scene_intersection.h"

namespace rcm::scene_board_test {
namespace {

SceneBoard Board(int cols, int rows, double square) {
  SceneBoard board;
  board.cols = cols;
  board.rows = rows;
  board.square = square;
  return board;
}

// The board upright 1 m in front of a camera at the pool's center looking
// along world +x (camera x = world -y, y = world -z, z = world +x), its
// printed side towards the camera.
Rigid3d WorldFromTarget(const SceneBoard& board) {
  Rigid3d world_from_camera;
  world_from_camera.rotation << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  world_from_camera.translation = Eigen::Vector3d(6.0, 4.0, 1.5);
  Rigid3d camera_from_target;
  camera_from_target.translation =
      Eigen::Vector3d(0.0, 0.0, 1.0) - board.Center();
  return world_from_camera * camera_from_target;
}

TEST(SceneBoard, CornersMatchCalibTargetPoints) {
  // The truth pose of the simulator's board must compare directly with
  // rcm::calib's estimate: the same points, in the same order, bit for bit.
  for (const SceneBoard& board : {SceneBoard(), Board(7, 5, 0.04),
                                  Board(2, 2, 0.005), Board(11, 8, 0.1)}) {
    const std::vector<Eigen::Vector3d> expected = calib::TargetPoints(
        calib::MakeCheckerboardTarget(board.cols, board.rows, board.square)
            .value());
    const std::vector<Eigen::Vector3d> corners = board.Corners();
    ASSERT_EQ(corners.size(), expected.size());
    for (size_t i = 0; i < corners.size(); ++i) {
      EXPECT_EQ(corners[i], expected[i]) << "point " << i;
    }
  }
}

// A bowed board's corners are calib's warped target points (the warp that
// rcm calibrate estimates), to rounding: the two evaluate the same
// polynomial in another order (1e-15 m on a board of decimetres).
TEST(SceneBoard, BowedCornersMatchCalibWarpedTargetPoints) {
  constexpr double kRounding = 1e-15;
  for (const Eigen::Vector2d warp :
       {Eigen::Vector2d(1e-3, 0.5e-3), Eigen::Vector2d(-3e-3, 2e-3)}) {
    SceneBoard board = Board(9, 6, 0.0254);
    board.warp = warp;
    ASSERT_TRUE(board.Check().ok());
    const std::vector<Eigen::Vector3d> expected = calib::WarpedTargetPoints(
        calib::MakeCheckerboardTarget(board.cols, board.rows, board.square)
            .value(),
        warp);
    const std::vector<Eigen::Vector3d> corners = board.Corners();
    ASSERT_EQ(corners.size(), expected.size());
    for (size_t i = 0; i < corners.size(); ++i) {
      EXPECT_LT((corners[i] - expected[i]).norm(), kRounding) << i;
    }
    // The bowl at the centre is warp_x + warp_y.
    const Eigen::Vector3d center = board.Center();
    EXPECT_NEAR(board.Height(center.x(), center.y()), warp.sum(), kRounding);
  }
}

TEST(SceneBoard, PatternIsCalibsPrintedPattern) {
  // Black and white where calib::DrawTargetImage prints them (its texture
  // maps pixels to the same target frame), over the pattern and the white
  // margin: at the center of every square of the printed area.
  const SceneBoard board = Board(5, 4, 0.04);
  const calib::TargetImage image = calib::DrawTargetImage(
      calib::MakeCheckerboardTarget(board.cols, board.rows, board.square)
          .value(),
      1000.0);
  Eigen::Matrix3d target_from_texture = Eigen::Matrix3d::Identity();
  target_from_texture.topRows<2>() = image.target_from_texture;
  const Eigen::Matrix3d texture_from_target = target_from_texture.inverse();
  int black = 0;
  for (int j = -2; j <= board.rows; ++j) {
    for (int i = -2; i <= board.cols; ++i) {
      const double x = (i + 0.5) * board.square;
      const double y = (j + 0.5) * board.square;
      ASSERT_TRUE(board.InPrintedArea(x, y));
      const Eigen::Vector3d texel =
          texture_from_target * Eigen::Vector3d(x, y, 1);
      const int printed =
          image.image.at<uint8_t>(static_cast<int>(std::lround(texel.y())),
                                  static_cast<int>(std::lround(texel.x())));
      const double albedo = board.FilteredAlbedo(x, y, 0.0, 0.0);
      EXPECT_EQ(albedo, printed == 0 ? board.black_albedo : board.white_albedo)
          << "square " << i << ", " << j;
      black += printed == 0;
    }
  }
  EXPECT_EQ(black, 15);  // of the 6 x 5 squares, top-left black
  EXPECT_EQ(
      board.FilteredAlbedo(-0.5 * board.square, -0.5 * board.square, 0.0, 0.0),
      board.black_albedo);
  EXPECT_FALSE(board.InPrintedArea(board.MinX() - 1e-9, 0.0));
  EXPECT_FALSE(board.InPrintedArea(0.0, board.MaxY() + 1e-9));
}

TEST(SceneBoard, FilteredAlbedoIsTheBoxMean) {
  // Against a midpoint rule on a 400 x 400 grid over the box (error below
  // one grid cell's share of the box for each edge crossing it: ~4 / 400
  // of the black-white contrast, 0.008), at boxes anywhere on the board,
  // the pattern's edges and the margin included.
  constexpr int kGrid = 400;
  constexpr double kTolerance = 4.0 / kGrid;
  const SceneBoard board = Board(4, 3, 0.05);
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> x(board.MinX(), board.MaxX());
  std::uniform_real_distribution<double> y(board.MinY(), board.MaxY());
  std::uniform_real_distribution<double> half(0.0, 0.08);
  for (int trial = 0; trial < 200; ++trial) {
    // One draw per statement: argument order is unspecified.
    const double cx = x(rng);
    const double cy = y(rng);
    const double hx = half(rng);
    const double hy = half(rng);
    double sum = 0.0;
    for (int j = 0; j < kGrid; ++j) {
      for (int i = 0; i < kGrid; ++i) {
        sum += board.FilteredAlbedo(cx - hx + (i + 0.5) * 2.0 * hx / kGrid,
                                    cy - hy + (j + 0.5) * 2.0 * hy / kGrid, 0.0,
                                    0.0);
      }
    }
    EXPECT_NEAR(board.FilteredAlbedo(cx, cy, hx, hy), sum / (kGrid * kGrid),
                kTolerance * (board.white_albedo - board.black_albedo))
        << cx << " " << cy << " " << hx << " " << hy;
  }
  // A box of one period in both directions inside the pattern averages
  // black and white equally.
  EXPECT_NEAR(board.FilteredAlbedo(1.0 * board.square, 1.0 * board.square,
                                   board.square, board.square),
              0.5 * (board.black_albedo + board.white_albedo), 1e-12);
}

TEST(SceneBoard, CheckRejectsBadBoards) {
  EXPECT_TRUE(SceneBoard().Check().ok());
  EXPECT_NE(Board(1, 6, 0.03).Check().message().find("inner corners"),
            std::string::npos);
  EXPECT_NE(Board(9, 101, 0.03).Check().message().find("inner corners"),
            std::string::npos);
  EXPECT_NE(Board(9, 6, 0.0).Check().message().find("square"),
            std::string::npos);
  EXPECT_NE(Board(9, 6, NAN).Check().message().find("square"),
            std::string::npos);
  SceneBoard board;
  board.black_albedo = 0.9;
  EXPECT_NE(board.Check().message().find("albedo"), std::string::npos);
  board = SceneBoard();
  board.warp = Eigen::Vector2d(0.0, 0.2);
  EXPECT_NE(board.Check().message().find("board warp (0, 0.2) m"),
            std::string::npos);
  board.warp = Eigen::Vector2d(NAN, 0.0);
  EXPECT_NE(board.Check().message().find("board warp"), std::string::npos);
}

// Rays meet a bowed board on its surface: the hit lies on z = h(x, y) to
// the Newton iteration's tolerance (1e-12 m), on the ray, its normal the
// surface's (-h_x, -h_y, 1) turned towards the ray; a ray towards a corner
// of the bowed board meets it at the corner. Off-centre rays at 30-40
// degrees to the board, 2-3 mm of bow.
TEST(PlacedBoard, RaysMeetABowedBoardOnItsSurface) {
  constexpr double kTolerance = 1e-12;
  SceneBoard board;
  board.warp = Eigen::Vector2d(2e-3, 1e-3);
  Rigid3d world_from_target = WorldFromTarget(board);
  // Tilt the board by 35 degrees about its y axis.
  world_from_target.rotation =
      world_from_target.rotation *
      Eigen::AngleAxisd(35.0 * M_PI / 180.0, Eigen::Vector3d::UnitY()).matrix();
  const PlacedBoard placed(board, world_from_target);
  const Eigen::Vector3d camera(6.0, 4.0, 1.5);
  const Rigid3d target_from_world = world_from_target.Inverse();
  for (const Eigen::Vector3d& corner : board.Corners()) {
    const Eigen::Vector3d point = world_from_target * corner;
    const Eigen::Vector3d direction = (point - camera).normalized();
    const std::optional<BoardHit> hit = placed.Intersect(camera, direction);
    ASSERT_TRUE(hit.has_value());
    EXPECT_LT((hit->point - point).norm(), kTolerance);
    EXPECT_TRUE(hit->printed_side);
    const Eigen::Vector3d in_target = target_from_world * hit->point;
    EXPECT_NEAR(in_target.z(), board.Height(in_target.x(), in_target.y()),
                kTolerance);
    const Eigen::Vector2d slope = board.Slope(in_target.x(), in_target.y());
    const Eigen::Vector3d normal =
        -(world_from_target.rotation *
          Eigen::Vector3d(-slope.x(), -slope.y(), 1.0).normalized());
    EXPECT_LT((hit->normal - normal).norm(), kTolerance);
    EXPECT_LT(hit->normal.dot(direction), 0.0);
  }
  // The same rays miss the flat board's plane points by the bow.
  SceneBoard flat = board;
  flat.warp.setZero();
  const PlacedBoard placed_flat(flat, world_from_target);
  const Eigen::Vector3d through = world_from_target * flat.Center();
  const BoardHit bowed =
      placed.Intersect(camera, (through - camera).normalized()).value();
  const BoardHit plane =
      placed_flat.Intersect(camera, (through - camera).normalized()).value();
  EXPECT_GT((bowed.point - plane.point).norm(), 2e-3);
  EXPECT_LT((plane.point - through).norm(), kTolerance);
}

TEST(PlacedBoard, RaysMeetThePrintedSideWherePlaneAndAreaSay) {
  const SceneBoard board;
  const PlacedBoard placed(board, WorldFromTarget(board));
  const Rigid3d& world_from_target = placed.world_from_target();
  const Eigen::Vector3d camera(6.0, 4.0, 1.5);
  // Towards a point of the board: hit there, at its distance, from the
  // printed side, the normal back towards the camera.
  const Eigen::Vector3d target_point(0.1, 0.05, 0.0);
  const Eigen::Vector3d point = world_from_target * target_point;
  const Eigen::Vector3d direction = (point - camera).normalized();
  const BoardHit hit = placed.Intersect(camera, direction).value();
  EXPECT_NEAR((hit.point - point).norm(), 0.0, 1e-12);
  EXPECT_NEAR(hit.distance, (point - camera).norm(), 1e-12);
  EXPECT_NEAR((hit.point_in_target - target_point.head<2>()).norm(), 0.0,
              1e-12);
  EXPECT_TRUE(hit.printed_side);
  EXPECT_NEAR((hit.normal - Eigen::Vector3d(-1.0, 0.0, 0.0)).norm(), 0.0,
              1e-12);
  EXPECT_NEAR((hit.direction_in_target -
               world_from_target.rotation.transpose() * direction)
                  .norm(),
              0.0, 1e-12);
  // From behind: the back, its normal the other way.
  const Eigen::Vector3d behind = point + Eigen::Vector3d(0.5, 0.0, 0.0);
  const BoardHit back =
      placed.Intersect(behind, -Eigen::Vector3d::UnitX()).value();
  EXPECT_FALSE(back.printed_side);
  EXPECT_NEAR((back.normal - Eigen::Vector3d::UnitX()).norm(), 0.0, 1e-12);
  EXPECT_EQ(board.Shade(back, 0.0), board.white_albedo);
  // Beyond the margin, away from the board, parallel to it: no hit.
  const Eigen::Vector3d outside =
      world_from_target * Eigen::Vector3d(board.MaxX() + 0.01, 0.0, 0.0);
  EXPECT_FALSE(placed.Intersect(camera, (outside - camera).normalized()));
  EXPECT_FALSE(placed.Intersect(camera, -direction));
  EXPECT_FALSE(placed.Intersect(camera, Eigen::Vector3d::UnitY()));
}

TEST(PlacedBoard, ShadeFiltersOverTheSampleFootprint) {
  // Head on, the footprint is a square of the sample's width; grazing, it
  // stretches along the ray's direction on the board by 1 / cos.
  const SceneBoard board;
  BoardHit hit;
  hit.point_in_target = Eigen::Vector2d(0.0, 0.015);  // on an edge x = 0
  hit.direction_in_target = Eigen::Vector3d::UnitZ();
  EXPECT_EQ(board.Shade(hit, 0.01),
            board.FilteredAlbedo(0.0, 0.015, 0.005, 0.005));
  const double angle = 60.0 * M_PI / 180.0;
  hit.direction_in_target =
      Eigen::Vector3d(std::sin(angle), 0.0, std::cos(angle));
  EXPECT_NEAR(board.Shade(hit, 0.01),
              board.FilteredAlbedo(0.0, 0.015, 0.01, 0.005), 1e-15);
}

TEST(SceneIntersection, TheBoardOccludesTheTankOnlyInFrontOfIt) {
  const TankScene tank = TankScene::Create([] {
                           TankSceneOptions options;
                           options.constant_albedo = 0.5;
                           return options;
                         }())
                             .value();
  const SceneBoard board;
  const PlacedBoard placed(board, WorldFromTarget(board));
  const Eigen::Vector3d camera(6.0, 4.0, 1.5);
  const Eigen::Vector3d at_board =
      (placed.world_from_target() * board.Center() - camera).normalized();
  const SceneHit hit = IntersectScene(tank, &placed, camera, at_board).value();
  EXPECT_TRUE(hit.on_board);
  EXPECT_NEAR(hit.distance(), 1.0, 1e-12);
  EXPECT_EQ(hit.point(), hit.board.point);
  // Without the board, or past its edge, the tank: the wall x = 12.
  for (const SceneHit& tank_hit :
       {IntersectScene(tank, nullptr, camera, at_board).value(),
        IntersectScene(tank, &placed, camera,
                       Eigen::Vector3d(1.0, 0.3, 0.0).normalized())
            .value()}) {
    EXPECT_FALSE(tank_hit.on_board);
    EXPECT_EQ(tank_hit.tank.surface, TankSurface::kWall);
    EXPECT_NEAR(tank_hit.point().x(), 12.0, 1e-12);
  }
  EXPECT_EQ(IntersectScene(tank, nullptr, camera, at_board)->tank.point,
            tank.Intersect(camera, at_board)->point);
  // A board beyond the wall is hidden by it.
  Rigid3d far = WorldFromTarget(board);
  far.translation.x() += 7.0;
  const PlacedBoard hidden(board, far);
  EXPECT_FALSE(IntersectScene(tank, &hidden, camera, at_board)->on_board);
  // Outside the tank: no hit at all.
  EXPECT_FALSE(
      IntersectScene(tank, &placed, Eigen::Vector3d(-1.0, 4.0, 1.5), at_board));
}

}  // namespace
}  // namespace rcm::scene_board_test
