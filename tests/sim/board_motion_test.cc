#include "rcm/sim/board_motion.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <memory>
#include <vector>

#include "rcm/camera/flat_port_camera.h"
#include "rcm/sim/reference_rigs.h"
#include "rcm/sim/sequence_simulator.h"

namespace rcm::board_motion_test {
namespace {

constexpr double kDegree = M_PI / 180.0;
constexpr double kFrameInterval = 0.05;  // s, 20 Hz

// The fastest the default motion can go between frames, from |dw/dt| <= 2
// pi / T_min per coordinate (board_motion.h) at 20 Hz:
// - center: depth 0.7 m 2 pi / 6 s = 0.73 m/s; lateral offset d tan(20
//   deg) (1, 0.75) w at d <= 2 m: 1.43 m/s from w and 0.33 m/s from d;
//   so at most |(0.73, 1.76)| = 1.9 m/s, 9.5 cm per frame;
// - orientation: tilt 40 deg |(w_tx', w_ty')| <= 40 deg sqrt(2) 2 pi / 3 s
//   = 118 deg/s, roll 10 deg 2 pi / 5 s = 13 deg/s: 6.6 deg per frame.
constexpr double kMaxCenterStep = 0.095;    // meters per frame
constexpr double kMaxTurn = 6.6 * kDegree;  // radians per frame
// The largest offset of the center (2 m tan(20 deg) |(1, 0.75)|) and turn
// (tilt and roll) that the excursion scales.
constexpr double kMaxOffset = 0.91;  // meters
constexpr double kMaxExcursionTurn = 50.0 * kDegree;

// The angle of the board's normal (target z) from cam0's optical axis.
double TiltOf(const Rigid3d& cam0_from_target) {
  return std::acos(std::clamp(cam0_from_target.rotation(2, 2), -1.0, 1.0));
}

// The board's center in cam0.
Eigen::Vector3d CenterOf(const SceneBoard& board,
                         const Rigid3d& cam0_from_target) {
  return cam0_from_target * board.Center();
}

BoardMotion Motion(uint64_t seed = 1) {
  BoardMotionOptions options;
  options.seed = seed;
  return BoardMotion::Create(SceneBoard(), options,
                             NarrowFieldRig().right_from_left())
      .value();
}

TEST(BoardMotion, StaysInItsRangesAndMovesLikeAHand) {
  // Over two minutes at 20 Hz: the center's depth in [0.6, 2] m, the tilt
  // at most 40 degrees, and between frames changes a hand can make.
  const BoardMotion motion = Motion();
  const SceneBoard& board = motion.board();
  double min_depth = 1e9, max_depth = 0.0, max_tilt = 0.0;
  for (int f = 0; f < 2400; ++f) {
    const double t = f * kFrameInterval;
    const Rigid3d pose = motion.Cam0FromTarget(t);
    const Rigid3d next = motion.Cam0FromTarget(t + kFrameInterval);
    const double depth = CenterOf(board, pose).z();
    min_depth = std::min(min_depth, depth);
    max_depth = std::max(max_depth, depth);
    max_tilt = std::max(max_tilt, TiltOf(pose));
    EXPECT_LT((CenterOf(board, next) - CenterOf(board, pose)).norm(),
              kMaxCenterStep);
    EXPECT_LT((pose.Inverse() * next).RotationAngle(), kMaxTurn);
  }
  EXPECT_GE(min_depth, 0.6);
  EXPECT_LE(max_depth, 2.0);
  EXPECT_LE(max_tilt, 40.0 * kDegree + 1e-12);
  // ... and it uses them: a diver shows the board near and far, tilted.
  EXPECT_LT(min_depth, 0.8);
  EXPECT_GT(max_depth, 1.8);
  EXPECT_GT(max_tilt, 30.0 * kDegree);
}

TEST(BoardMotion, WithoutExcursionItFacesTheRigOnTheNeutralPoint) {
  // e = 0: target axes along cam0's (upright, printed side to the rig),
  // centered midway between the two cameras' axes at its depth.
  const BoardMotion motion = Motion();
  const Rigid3d pose = motion.Cam0FromTarget(3.0, 0.0);
  EXPECT_TRUE(pose.rotation.isIdentity(1e-15));
  const Eigen::Vector3d center = CenterOf(motion.board(), pose);
  EXPECT_NEAR((center - motion.NeutralPoint(center.z())).norm(), 0.0, 1e-15);
  // The narrow rig's axes meet 1.49 m ahead, on cam0's axis; nearer, the
  // neutral point is half way to cam1's axis, x = (b - d tan 2.5 deg) / 2.
  const double meet = kNarrowFieldBaseline / std::tan(kNarrowFieldToeIn);
  EXPECT_NEAR(motion.NeutralPoint(meet).head<2>().norm(), 0.0, 1e-12);
  EXPECT_NEAR(motion.NeutralPoint(0.6).x(),
              0.5 * (kNarrowFieldBaseline - 0.6 * std::tan(kNarrowFieldToeIn)),
              1e-12);
}

TEST(BoardMotion, DependsOnlyOnTheSeed) {
  const Rigid3d a = Motion(5).Cam0FromTarget(1.7);
  const Rigid3d b = Motion(5).Cam0FromTarget(1.7);
  const Rigid3d c = Motion(6).Cam0FromTarget(1.7);
  EXPECT_EQ(a.rotation, b.rotation);
  EXPECT_EQ(a.translation, b.translation);
  EXPECT_GT((a.translation - c.translation).norm(), 1e-3);
}

TEST(BoardMotion, CheckRejectsBadOptions) {
  EXPECT_TRUE(BoardMotionOptions().Check().ok());
  BoardMotionOptions options;
  options.min_distance = 0.0;
  EXPECT_NE(options.Check().message().find("distance"), std::string::npos);
  options = BoardMotionOptions();
  options.max_distance = 0.5;  // below min
  EXPECT_NE(options.Check().message().find("distance"), std::string::npos);
  options = BoardMotionOptions();
  options.max_tilt_deg = 80.0;
  EXPECT_NE(options.Check().message().find("tilt"), std::string::npos);
  options = BoardMotionOptions();
  options.max_roll_deg = NAN;
  EXPECT_NE(options.Check().message().find("roll"), std::string::npos);
  options = BoardMotionOptions();
  options.max_off_axis_deg = -1.0;
  EXPECT_NE(options.Check().message().find("off_axis"), std::string::npos);
  SceneBoard board;
  board.cols = 1;
  EXPECT_FALSE(BoardMotion::Create(board, BoardMotionOptions(),
                                   NarrowFieldRig().right_from_left())
                   .ok());
}

// A sequence of the narrow rig in water with the default board (poses and
// board frames only: no images, no matches).
std::unique_ptr<SequenceSimulator> BoardSequence(int frames,
                                                 const FlatPort& port) {
  SequenceOptions options;
  options.media = {MediaSegment{1.34, frames}};
  options.render_images = false;
  options.left_port = port;
  options.right_port = port;
  options.board = SceneBoard();
  return SequenceSimulator::Create(NarrowFieldRig(), options).value();
}

TEST(PlanBoardFrames, KeepsTheBoardInViewAndTellsTheTruthAboutIt) {
  // 20 s of a dive with a thick port: every frame shows every corner to
  // both cameras (the narrow rig sees the 0.33 x 0.24 m board whole from
  // 0.6 m), the excursion glides, and each flag agrees with an
  // independent projection of the corners (with the margin) through the
  // exact port.
  FlatPort port;
  port.air_gap = 0.008;
  port.glass_thickness = 0.006;
  const std::unique_ptr<SequenceSimulator> simulator = BoardSequence(400, port);
  const StereoRig& rig = simulator->true_rig();
  const std::vector<BoardFrame>& frames = simulator->board_frames();
  ASSERT_EQ(frames.size(), 400u);
  const FlatPortCamera cameras[2] = {
      FlatPortCamera::Create(rig.left(), port, 1.34).value(),
      FlatPortCamera::Create(rig.right(), port, 1.34).value()};
  const Rigid3d cam_from_cam0[2] = {Rigid3d(), rig.right_from_left()};
  const SceneBoard board;
  int reduced = 0;
  for (size_t f = 0; f < frames.size(); ++f) {
    SCOPED_TRACE(f);
    const BoardFrame& frame = frames[f];
    EXPECT_TRUE(frame.fully_visible[0] && frame.fully_visible[1]);
    for (int c = 0; c < 2; ++c) {
      bool inside = true;
      for (const Eigen::Vector3d& corner : board.Corners()) {
        const std::optional<Eigen::Vector2d> pixel = cameras[c].ImageFromPoint(
            cam_from_cam0[c] * (frame.cam0_from_target * corner));
        const Camera& camera = c == 0 ? rig.left() : rig.right();
        inside = inside && pixel && pixel->x() >= kBoardMarginPx - 0.5 &&
                 pixel->y() >= kBoardMarginPx - 0.5 &&
                 pixel->x() <= camera.width() - 0.5 - kBoardMarginPx &&
                 pixel->y() <= camera.height() - 0.5 - kBoardMarginPx;
      }
      EXPECT_EQ(frame.fully_visible[c], inside) << "camera " << c;
    }
    const double depth = CenterOf(board, frame.cam0_from_target).z();
    EXPECT_GE(depth, 0.6);
    EXPECT_LE(depth, 2.0);
    EXPECT_LE(TiltOf(frame.cam0_from_target), 40.0 * kDegree + 1e-12);
    if (f > 0) {
      EXPECT_LE(std::abs(frame.excursion - frames[f - 1].excursion),
                kMaxExcursionStep + 1e-12);
      // A hand's motion plus the excursion's glide on top.
      EXPECT_LT((CenterOf(board, frame.cam0_from_target) -
                 CenterOf(board, frames[f - 1].cam0_from_target))
                    .norm(),
                kMaxCenterStep + kMaxExcursionStep * kMaxOffset);
      EXPECT_LT(
          (frames[f - 1].cam0_from_target.Inverse() * frame.cam0_from_target)
              .RotationAngle(),
          kMaxTurn + kMaxExcursionStep * kMaxExcursionTurn);
    }
    reduced += frame.excursion < 1.0;
  }
  // The full excursion would leave the view now and then (20 degrees off
  // the axis near 0.6 m, tilted): the plan pulled it in, in 54 frames.
  EXPECT_GT(reduced, 20);
}

TEST(PlanBoardFrames, ABoardTooLargeForTheViewIsRecordedAsNotVisible) {
  // 1.1 x 0.8 m at 0.6-0.7 m: wider than the narrow rig's water view.
  SequenceOptions options;
  options.media = {MediaSegment{1.34, 5}};
  options.render_images = false;
  SceneBoard board;
  board.square = 0.1;
  options.board = board;
  options.board_motion.max_distance = 0.7;
  const std::unique_ptr<SequenceSimulator> simulator =
      SequenceSimulator::Create(NarrowFieldRig(), options).value();
  for (const BoardFrame& frame : simulator->board_frames()) {
    EXPECT_FALSE(frame.fully_visible[0]);
    EXPECT_FALSE(frame.fully_visible[1]);
    EXPECT_EQ(frame.excursion, 0.0);
  }
}

}  // namespace
}  // namespace rcm::board_motion_test
