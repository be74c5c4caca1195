#include "rcm/sim/non_rigid_layer.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "rcm/sim/stereo_sampler.h"
#include "support/test_rigs.h"

namespace rcm::non_rigid_layer_test {
namespace {

using ::testing::HasSubstr;

// The surface's mirror of a real dive, as the simulator's Monte Carlo
// draws it: the top 30 % of the image, 0.3 px kept over the frames and
// 0.3 px more per frame.
NonRigidLayer Mirror() {
  NonRigidLayer layer;
  layer.image_fraction = 0.3;
  layer.offset_px = 0.3;
  layer.offset_sd_px = 0.3;
  return layer;
}

TEST(NonRigidLayer, NoBandOrNoOffsetChangesNothing) {
  NonRigidLayer layer = Mirror();
  EXPECT_FALSE(layer.IsZero());
  layer.image_fraction = 0.0;
  EXPECT_TRUE(layer.IsZero());
  EXPECT_EQ(layer.OffsetOfFrame(3, 5), 0.0);
  layer = Mirror();
  layer.offset_px = 0.0;
  layer.offset_sd_px = 0.0;
  EXPECT_TRUE(layer.IsZero());
  EXPECT_EQ(layer.OffsetOfFrame(3, 5), 0.0);

  // A sampler with a zero layer draws the same sample, bit for bit.
  StereoSamplerOptions options;
  options.num_frames = 3;
  options.per_frame = 50;
  const StereoRig rig = test::AlphasenseRealisticRig();
  const std::vector<StereoCorrespondence> plain =
      SampleStereoCorrespondences(rig, options).value();
  options.non_rigid_layer = layer;
  const std::vector<StereoCorrespondence> zero =
      SampleStereoCorrespondences(rig, options).value();
  ASSERT_EQ(plain.size(), zero.size());
  for (size_t i = 0; i < plain.size(); ++i) {
    EXPECT_EQ(plain[i].left_pixel, zero[i].left_pixel);
    EXPECT_EQ(plain[i].right_pixel, zero[i].right_pixel);
  }
}

TEST(NonRigidLayer, BadValuesAreRefused) {
  NonRigidLayer layer = Mirror();
  ASSERT_TRUE(layer.Check().ok());
  layer.image_fraction = 1.5;
  EXPECT_THAT(layer.Check().message(),
              HasSubstr("image fraction 1.5 is outside [0, 1]"));
  layer = Mirror();
  layer.offset_px = -20.0;
  EXPECT_THAT(layer.Check().message(), HasSubstr("offset of -20 px"));
  layer = Mirror();
  layer.offset_sd_px = NAN;
  EXPECT_THAT(layer.Check().message(), HasSubstr("offset sd of nan px"));
  StereoSamplerOptions options;
  options.non_rigid_layer = layer;
  EXPECT_THAT(options.Check().message(), HasSubstr("non-rigid layer"));
}

// The per-frame offsets of 4000 frames: mean offset_px and sd offset_sd_px,
// each within 4 standard errors (sd / sqrt(4000) = 0.016 sd for the mean,
// 0.011 sd for the sd).
TEST(NonRigidLayer, FramesOffsetsHaveTheStatedMeanAndSpread) {
  const NonRigidLayer layer = Mirror();
  constexpr int kFrames = 4000;
  double sum = 0.0;
  double sum2 = 0.0;
  for (int f = 0; f < kFrames; ++f) {
    const double offset = layer.OffsetOfFrame(11, f);
    EXPECT_EQ(offset, layer.OffsetOfFrame(11, f));  // keyed, not stateful
    sum += offset;
    sum2 += offset * offset;
  }
  const double mean = sum / kFrames;
  const double sd = std::sqrt(sum2 / kFrames - mean * mean);
  EXPECT_NEAR(mean, layer.offset_px, 4.0 * 0.016 * layer.offset_sd_px);
  EXPECT_NEAR(sd, layer.offset_sd_px, 4.0 * 0.011 * layer.offset_sd_px);
}

// The sampler moves the right pixels of the band's matches by their
// frame's offset, exactly, and leaves every other pixel as it was: the
// same points are drawn (no moved pixel leaves the image for this seed).
TEST(NonRigidLayer, MovesTheBandsRightPixelsByTheFramesOffset) {
  const StereoRig rig = test::AlphasenseRealisticRig();
  StereoSamplerOptions options;
  options.num_frames = 4;
  options.per_frame = 200;
  options.seed = 7;
  const std::vector<StereoCorrespondence> rigid =
      SampleStereoCorrespondences(rig, options).value();
  options.non_rigid_layer = Mirror();
  const std::vector<StereoCorrespondence> layered =
      SampleStereoCorrespondences(rig, options).value();
  ASSERT_EQ(rigid.size(), layered.size());
  int moved = 0;
  for (size_t i = 0; i < rigid.size(); ++i) {
    ASSERT_EQ(rigid[i].left_pixel, layered[i].left_pixel) << i;
    EXPECT_EQ(rigid[i].right_pixel.x(), layered[i].right_pixel.x());
    const bool on_layer = options.non_rigid_layer.Covers(rigid[i].left_pixel,
                                                         rig.left().height());
    const double offset =
        on_layer ? options.non_rigid_layer.OffsetOfFrame(
                       options.seed, static_cast<int>(rigid[i].frame))
                 : 0.0;
    EXPECT_EQ(layered[i].right_pixel.y(), rigid[i].right_pixel.y() + offset);
    moved += on_layer ? 1 : 0;
  }
  // About 30 % of the matches are in the band (binomial, 800 draws: 240 +-
  // 13; 4 sigma either way).
  EXPECT_GT(moved, 240 - 52);
  EXPECT_LT(moved, 240 + 52);
}

}  // namespace
}  // namespace rcm::non_rigid_layer_test
