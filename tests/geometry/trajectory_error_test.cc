#include "rcm/geometry/trajectory_error.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <vector>

namespace rcm {
namespace {

// A loop of 24 poses on a 1 m circle, turning with the path, plus a climb.
std::vector<Rigid3d> Circle(double climb) {
  std::vector<Rigid3d> poses;
  for (int f = 0; f < 24; ++f) {
    const double angle = 2.0 * M_PI * f / 24.0;
    Rigid3d pose;
    pose.rotation = Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitZ()).matrix();
    pose.translation =
        Eigen::Vector3d(std::cos(angle), std::sin(angle), climb * f);
    poses.push_back(pose);
  }
  return poses;
}

// Rounding of sums over 24 poses of unit size.
constexpr double kExact = 1e-12;

// The estimate in another world frame (any rigid move) is the truth: no
// error.
TEST(TrajectoryError, AnyWorldFrameIsNoError) {
  const std::vector<Rigid3d> truth = Circle(0.01);
  Rigid3d moved;
  moved.rotation =
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).matrix();
  moved.translation = Eigen::Vector3d(5, -3, 2);
  std::vector<Rigid3d> estimated;
  for (const Rigid3d& pose : truth) estimated.push_back(moved * pose);
  const TrajectoryError error = CompareTrajectories(estimated, truth).value();
  EXPECT_EQ(error.frames, 24);
  EXPECT_LT(error.ate_m, kExact);
  EXPECT_LT(error.end_drift_m, kExact);
  EXPECT_LT(error.max_rotation_error_deg, 1e-9);
  // 24 chords of a unit circle, each 2 sin(pi / 24), and the climb.
  EXPECT_NEAR(error.path_length_m,
              23.0 * std::hypot(2.0 * std::sin(M_PI / 24.0), 0.01), kExact);
  EXPECT_NEAR(error.true_end_distance_m,
              std::hypot(2.0 * std::sin(M_PI / 24.0), 0.23), kExact);
}

// A scale error s about the centroid (a baseline off by s): the best rigid
// alignment is the identity, so ATE = s * rms distance from the centroid,
// and the end drift s |d|.
TEST(TrajectoryError, ScaleErrorGivesItsAteAndDrift) {
  const std::vector<Rigid3d> truth = Circle(0.0);
  const double s = 0.02;
  std::vector<Rigid3d> estimated = truth;
  for (Rigid3d& pose : estimated) pose.translation *= 1.0 + s;  // centroid 0
  const TrajectoryError error = CompareTrajectories(estimated, truth).value();
  EXPECT_NEAR(error.ate_m, s * 1.0, kExact);
  EXPECT_NEAR(error.end_drift_m, s * error.true_end_distance_m, kExact);
  EXPECT_LT(error.max_rotation_error_deg, 1e-9);
}

// A loop whose estimate does not close: the gap is the end drift, whatever
// the estimate's world frame.
TEST(TrajectoryError, LoopGapIsTheEndDrift) {
  std::vector<Rigid3d> truth = Circle(0.0);
  truth.push_back(truth[0]);  // back where it began
  std::vector<Rigid3d> estimated = truth;
  const Eigen::Vector3d gap(0.03, -0.04, 0.0);
  estimated.back().translation += gap;
  Rigid3d moved;
  moved.rotation = Eigen::AngleAxisd(-1.1, Eigen::Vector3d::UnitY()).matrix();
  moved.translation = Eigen::Vector3d(1, 1, 1);
  for (Rigid3d& pose : estimated) pose = moved * pose;
  const TrajectoryError error = CompareTrajectories(estimated, truth).value();
  EXPECT_LT(error.true_end_distance_m, kExact);
  EXPECT_NEAR(error.end_drift_m, 0.05, kExact);
  EXPECT_GT(error.ate_m, 0.0);
  EXPECT_LT(error.ate_m, 0.05);
}

TEST(TrajectoryError, BadInputRefusedInOneLine) {
  const std::vector<Rigid3d> truth = Circle(0.0);
  std::vector<Rigid3d> shorter(truth.begin(), truth.end() - 1);
  EXPECT_EQ(CompareTrajectories(shorter, truth).status().message(),
            "the estimated trajectory has 23 poses, the true one 24");
  EXPECT_FALSE(CompareTrajectories({truth[0]}, {truth[0]}).ok());
  std::vector<Rigid3d> broken = truth;
  broken[3].translation.x() = NAN;
  EXPECT_EQ(CompareTrajectories(broken, truth).status().message(),
            "pose 3 of a trajectory is not finite");
}

}  // namespace
}  // namespace rcm
