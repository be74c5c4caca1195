#include "rcm/sim/exposure_delay.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <vector>

#include "rcm/estimation/batch_refinement.h"
#include "rcm/sim/stereo_sampler.h"
#include "support/test_rigs.h"

namespace rcm::exposure_delay_test {
namespace {

constexpr double kDegree = M_PI / 180.0;
// Exact correspondences carry ~1e-13 px residuals; the solver's
// tolerances carry that to n within 1e-9 (batch_refinement_test.cc).
constexpr double kExactTolerance = 1e-9;

ExposureDelay HandHeld() {
  ExposureDelay delay;
  delay.delay = 0.010;
  delay.angular_speed_sd = 10.0 * kDegree;
  delay.speed_sd = 0.1;
  return delay;
}

TEST(ExposureDelay, NoDelayOrNoMotionIsTheIdentity) {
  ExposureDelay delay = HandHeld();
  delay.delay = 0.0;
  EXPECT_TRUE(delay.IsZero());
  const Rigid3d motion = delay.MotionOfFrame(7, 3);
  EXPECT_EQ(motion.rotation, Eigen::Matrix3d::Identity());
  EXPECT_EQ(motion.translation, Eigen::Vector3d::Zero());
  delay = HandHeld();
  delay.angular_speed_sd = 0.0;
  delay.speed_sd = 0.0;
  EXPECT_TRUE(delay.IsZero());
  EXPECT_FALSE(HandHeld().IsZero());
}

TEST(ExposureDelay, RejectsInvalidOptions) {
  EXPECT_TRUE(HandHeld().Check().ok());
  ExposureDelay delay = HandHeld();
  delay.delay = 0.2;
  EXPECT_FALSE(delay.Check().ok());
  delay = HandHeld();
  delay.delay = std::nan("");
  EXPECT_FALSE(delay.Check().ok());
  delay = HandHeld();
  delay.angular_speed_sd = -1.0;
  EXPECT_FALSE(delay.Check().ok());
  delay = HandHeld();
  delay.speed_sd = 10.0;
  EXPECT_FALSE(delay.Check().ok());
  StereoSamplerOptions options;
  options.exposure_delay.delay = -0.5;
  EXPECT_FALSE(options.Check().ok());
}

// Each component of the motion is N(0, (sd delay)^2): over 4000 frames the
// sample sd is within 5 % (the sd of a sample sd of 4000 draws is 1.1 %),
// and a frame's motion depends on (seed, frame) only.
TEST(ExposureDelay, MotionsHaveTheStatedSpread) {
  const ExposureDelay delay = HandHeld();
  constexpr int kFrames = 4000;
  Eigen::Matrix<double, 6, 1> sum2 = Eigen::Matrix<double, 6, 1>::Zero();
  for (int f = 0; f < kFrames; ++f) {
    const Rigid3d motion = delay.MotionOfFrame(11, f);
    const Eigen::AngleAxisd angle_axis(motion.rotation);
    const Eigen::Vector3d w = angle_axis.angle() * angle_axis.axis();
    for (int k = 0; k < 3; ++k) {
      sum2[k] += w[k] * w[k];
      sum2[3 + k] += motion.translation[k] * motion.translation[k];
    }
  }
  for (int k = 0; k < 6; ++k) {
    const double expected =
        (k < 3 ? delay.angular_speed_sd : delay.speed_sd) * delay.delay;
    EXPECT_NEAR(std::sqrt(sum2[k] / kFrames), expected, 0.05 * expected) << k;
  }
  const Rigid3d a = delay.MotionOfFrame(11, 5);
  const Rigid3d b = delay.MotionOfFrame(11, 5);
  EXPECT_EQ(a.rotation, b.rotation);
  EXPECT_EQ(a.translation, b.translation);
  EXPECT_NE(delay.MotionOfFrame(12, 5).translation, a.translation);
}

// With a delay the left pixels are those of the synchronized sample, bit
// for bit, and each frame's matches are exact for the rig whose cam1 is
// where it was at the right exposure, right_from_left * motion: the
// refinement on that rig gives n to 1e-9, on the calibrated rig it does
// not.
TEST(ExposureDelay, SamplerMovesTheRightPixelsByTheFramesMotion) {
  const StereoRig rig = test::AlphasenseRealisticRig();
  StereoSamplerOptions options;
  options.n = 1.34;
  options.num_frames = 2;
  options.per_frame = 150;
  options.seed = 5;
  const std::vector<StereoCorrespondence> synchronized =
      SampleStereoCorrespondences(rig, options).value();
  options.exposure_delay = HandHeld();
  const std::vector<StereoCorrespondence> delayed =
      SampleStereoCorrespondences(rig, options).value();
  ASSERT_EQ(delayed.size(), synchronized.size());
  for (int frame = 0; frame < options.num_frames; ++frame) {
    std::vector<StereoCorrespondence> matches;
    for (size_t i = 0; i < delayed.size(); ++i) {
      if (delayed[i].frame != frame) continue;
      // (A right pixel that left the image would have redrawn the point.)
      if (delayed[i].left_pixel != synchronized[i].left_pixel) break;
      matches.push_back(delayed[i]);
    }
    ASSERT_EQ(matches.size(), 150u) << "frame " << frame;
    // cam1 at the right exposure in WithCam1Moved's convention:
    // exp([w]x) R = R M_R, exp([w]x) t + dt = R M_t + t.
    const Rigid3d motion =
        options.exposure_delay.MotionOfFrame(options.seed, frame);
    const Rigid3d& right_from_left = rig.right_from_left();
    const Eigen::Matrix3d turn = right_from_left.rotation * motion.rotation *
                                 right_from_left.rotation.transpose();
    const Eigen::AngleAxisd angle_axis(turn);
    const Eigen::Vector3d w = angle_axis.angle() * angle_axis.axis();
    const Eigen::Vector3d dt = right_from_left.rotation * motion.translation +
                               right_from_left.translation -
                               turn * right_from_left.translation;
    const StereoRig moved = rig.WithCam1Moved(w, dt).value();
    EXPECT_NEAR(
        RefineRefractiveIndex(moved, matches, RefinementOptions()).value().n,
        1.34, kExactTolerance)
        << "frame " << frame;
    const StatusOr<RefinementSummary> calibrated =
        RefineRefractiveIndex(rig, matches, RefinementOptions());
    if (calibrated.ok()) {
      EXPECT_GT(std::abs(calibrated->n - 1.34), 1e-4) << "frame " << frame;
    }
  }
}

}  // namespace
}  // namespace rcm::exposure_delay_test
