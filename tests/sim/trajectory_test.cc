#include "rcm/sim/trajectory.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>

#include "rcm/sim/reference_rigs.h"

namespace rcm::trajectory_test {
namespace {

constexpr double kDegrees = M_PI / 180.0;

// The trajectory needs the tank's size only: a flat (untextured) tank.
TankScene Pool() {
  TankSceneOptions options;
  options.constant_albedo = 0.5;
  return TankScene::Create(options).value();
}

// Angle of the camera's optical axis below the horizontal.
double PitchBelowHorizon(const Rigid3d& world_from_cam) {
  return std::asin(-world_from_cam.rotation(2, 2));
}

TEST(Trajectory, DefaultOptionsAreValid) {
  EXPECT_TRUE(TrajectoryOptions().Check().ok());
}

TEST(Trajectory, CheckRejectsBadOptions) {
  const auto message = [](const TrajectoryOptions& options) {
    return options.Check().message();
  };
  TrajectoryOptions options;
  options.frames = 0;
  EXPECT_NE(message(options).find("frames"), std::string::npos);
  options = TrajectoryOptions();
  options.frame_rate = 0.0;
  EXPECT_NE(message(options).find("frame_rate"), std::string::npos);
  options = TrajectoryOptions();
  options.speed = -0.1;
  EXPECT_NE(message(options).find("speed"), std::string::npos);
  options = TrajectoryOptions();
  options.pitch_deg = 85.0;
  EXPECT_NE(message(options).find("pitch_deg"), std::string::npos);
  options = TrajectoryOptions();
  options.wall_margin = 1.05;  // minus the 0.1 m sway: under 1 m
  EXPECT_NE(message(options).find("wall_margin"), std::string::npos);
  options = TrajectoryOptions();
  options.yaw_amplitude_deg = NAN;
  EXPECT_NE(message(options).find("yaw_amplitude_deg"), std::string::npos);
  EXPECT_FALSE(GenerateTrajectory(Pool(), options).ok());
}

TEST(Trajectory, FailsWhenTheTankIsTooSmall) {
  TankSceneOptions small;
  small.length = 3.0;
  small.width = 3.0;
  small.constant_albedo = 0.5;
  EXPECT_FALSE(
      GenerateTrajectory(TankScene::Create(small).value(), TrajectoryOptions())
          .ok());
  TankSceneOptions shallow;
  shallow.depth = 1.4;
  shallow.constant_albedo = 0.5;
  // 1.2 m + 0.05 m heave is closer than 0.3 m to a 1.4 m surface.
  EXPECT_FALSE(GenerateTrajectory(TankScene::Create(shallow).value(),
                                  TrajectoryOptions())
                   .ok());
}

TEST(Trajectory, PosesStayInsideAtTheRightHeightAndPitch) {
  const TankScene scene = Pool();
  TrajectoryOptions options;
  options.frames = 1600;  // 80 s: more than one lap of the 23 m ellipse
  const std::vector<TimedPose> poses =
      GenerateTrajectory(scene, options).value();
  ASSERT_EQ(poses.size(), 1600u);
  const Rigid3d cam0_from_cam1 =
      AlphasenseFrontUnrectifiedRig().right_from_left().Inverse();
  // The wobbles add at most their amplitudes; 1e-9 covers rounding.
  const double height_slack = options.heave_amplitude + 1e-9;
  const double pitch_slack = options.rock_amplitude_deg * kDegrees + 1e-9;
  for (size_t i = 0; i < poses.size(); ++i) {
    const Rigid3d& pose = poses[i].world_from_cam0;
    EXPECT_DOUBLE_EQ(poses[i].t, i / 20.0);
    EXPECT_LT((pose.rotation.transpose() * pose.rotation -
               Eigen::Matrix3d::Identity())
                  .cwiseAbs()
                  .maxCoeff(),
              1e-12);
    EXPECT_NEAR(pose.rotation.determinant(), 1.0, 1e-12);
    EXPECT_NEAR(pose.translation.z(), options.height, height_slack);
    EXPECT_NEAR(PitchBelowHorizon(pose), options.pitch_deg * kDegrees,
                pitch_slack);
    // Roll: the camera's x axis stays near the horizontal.
    EXPECT_LT(std::abs(pose.rotation(2, 0)),
              std::sin(options.rock_amplitude_deg * kDegrees) + 1e-9);
    // Both cameras more than 1 m from every wall.
    for (const Eigen::Vector3d& center :
         {pose.translation, (pose * cam0_from_cam1).translation}) {
      EXPECT_GT(center.x(), 1.0);
      EXPECT_LT(center.x(), scene.length() - 1.0);
      EXPECT_GT(center.y(), 1.0);
      EXPECT_LT(center.y(), scene.width() - 1.0);
    }
  }
}

TEST(Trajectory, MovesSmoothlyAtTheRequestedSpeed) {
  const TankScene scene = Pool();
  TrajectoryOptions options;
  options.frames = 800;
  const std::vector<TimedPose> poses =
      GenerateTrajectory(scene, options).value();
  const double dt = 1.0 / options.frame_rate;
  // Bounds from the motion's parts. The ellipse's semi-axes are 4.4 and
  // 2.4 m, its smallest radius of curvature b^2 / a = 1.31 m. Speed: the
  // path's 0.3 m/s, scaled by 1 +- sway / radius where the sway offsets
  // it, plus the sway's own rate (0.1 m * 2 pi / 6 s). Acceleration: path
  // curvature (0.07 m/s^2), sway and heave (amplitude (2 pi / period)^2 for
  // periods >= 6 s and >= 4 s: 0.11 and 0.12) and their coupling (0.05)
  // stay under 0.35 m/s^2. Turn rate: the path's 0.25 rad/s plus yaw, pitch
  // and roll wobbles (< 0.18 rad/s).
  const double min_radius = 2.4 * 2.4 / 4.4;
  const double min_speed =
      options.speed * (1.0 - options.sway_amplitude / min_radius);
  const double max_speed =
      options.speed * (1.0 + options.sway_amplitude / min_radius) +
      options.sway_amplitude * 2.0 * M_PI / 6.0;
  constexpr double kMaxAcceleration = 0.35;  // m/s^2
  constexpr double kMaxTurnRate = 0.5;       // rad/s
  for (size_t i = 1; i + 1 < poses.size(); ++i) {
    const Eigen::Vector3d& previous = poses[i - 1].world_from_cam0.translation;
    const Eigen::Vector3d& current = poses[i].world_from_cam0.translation;
    const Eigen::Vector3d& next = poses[i + 1].world_from_cam0.translation;
    const double speed = (next - current).head<2>().norm() / dt;
    EXPECT_GT(speed, min_speed);
    EXPECT_LT(speed, max_speed);
    EXPECT_LT((next - 2.0 * current + previous).norm() / (dt * dt),
              kMaxAcceleration);
    const Eigen::Matrix3d turn = poses[i].world_from_cam0.rotation.transpose() *
                                 poses[i + 1].world_from_cam0.rotation;
    EXPECT_LT(Eigen::AngleAxisd(turn).angle() / dt, kMaxTurnRate);
  }
}

TEST(Trajectory, DependsOnlyOnTheSeed) {
  const TankScene scene = Pool();
  TrajectoryOptions options;
  options.frames = 50;
  const std::vector<TimedPose> a = GenerateTrajectory(scene, options).value();
  const std::vector<TimedPose> b = GenerateTrajectory(scene, options).value();
  options.seed = 2;
  const std::vector<TimedPose> c = GenerateTrajectory(scene, options).value();
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].world_from_cam0.translation,
              b[i].world_from_cam0.translation);
    EXPECT_EQ(a[i].world_from_cam0.rotation, b[i].world_from_cam0.rotation);
    EXPECT_GT(
        (a[i].world_from_cam0.translation - c[i].world_from_cam0.translation)
            .norm(),
        0.01);
  }
}

TEST(Trajectory, AStillCameraHovers) {
  TrajectoryOptions options;
  options.frames = 10;
  options.speed = 0.0;
  options.sway_amplitude = 0.0;
  options.heave_amplitude = 0.0;
  options.yaw_amplitude_deg = 0.0;
  options.rock_amplitude_deg = 0.0;
  const std::vector<TimedPose> poses =
      GenerateTrajectory(Pool(), options).value();
  for (const TimedPose& pose : poses) {
    EXPECT_LT((pose.world_from_cam0.translation -
               poses[0].world_from_cam0.translation)
                  .norm(),
              1e-12);
    EXPECT_NEAR(PitchBelowHorizon(pose.world_from_cam0), 16.0 * kDegrees,
                1e-12);
  }
}

// A loop ends where it began: the last pose is the first, position and
// orientation, up to the arc-length table's 1e-7 of the perimeter (the
// tolerance: 1e-6 m on a 5.7 m lap) and rounding of the wobbles' sines.
// Between, the rig flies the lap at one speed, so the frames are evenly
// spaced along it and the path is the laps' length.
TEST(Trajectory, LoopsEndWhereTheyBegan) {
  TankSceneOptions tank;
  tank.length = 5.0;
  tank.width = 5.0;
  tank.constant_albedo = 0.5;
  const TankScene scene = TankScene::Create(tank).value();
  for (const int loops : {1, 2}) {
    TrajectoryOptions options;
    options.frames = 61;
    options.loops = loops;
    const std::vector<TimedPose> poses =
        GenerateTrajectory(scene, options).value();
    const Rigid3d& first = poses.front().world_from_cam0;
    const Rigid3d& last = poses.back().world_from_cam0;
    EXPECT_LT((last.translation - first.translation).norm(), 1e-6);
    EXPECT_LT((last.rotation - first.rotation).norm(), 1e-6);
    // The middle frame of one lap is across the circle (radius 0.9 m).
    if (loops == 1) {
      EXPECT_GT((poses[30].world_from_cam0.translation - first.translation)
                    .head<2>()
                    .norm(),
                1.5);
    }
  }
  TrajectoryOptions fast;
  fast.frames = 2;
  fast.frame_rate = 1.0;
  fast.loops = 1;  // 5.65 m in one second
  const StatusOr<std::vector<TimedPose>> refused =
      GenerateTrajectory(scene, fast);
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.status().message().find("beyond 5"), std::string::npos)
      << refused.status().message();
  TrajectoryOptions bad;
  bad.loops = -1;
  EXPECT_NE(bad.Check().message().find("loops"), std::string::npos);
  bad.loops = 1;
  bad.frames = 1;
  EXPECT_NE(bad.Check().message().find("loops"), std::string::npos);
}

}  // namespace
}  // namespace rcm::trajectory_test
