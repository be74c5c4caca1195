#include "rcm/sim/stereo_sampler.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iterator>

#include "rcm/camera/refractive_camera.h"
#include "rcm/estimation/batch_refinement.h"
#include "rcm/camera/flat_port_camera.h"
#include "support/test_rigs.h"

namespace rcm::stereo_sampler_test {
namespace {

TEST(StereoSampler, SamplesRequestedFramesInsideBothImages) {
  const StereoRig rig = test::AlphasenseRealisticRig();
  StereoSamplerOptions options;
  options.num_frames = 3;
  options.per_frame = 40;
  const std::vector<StereoCorrespondence> sample =
      SampleStereoCorrespondences(rig, options).value();
  ASSERT_EQ(sample.size(), 120u);
  for (size_t i = 0; i < sample.size(); ++i) {
    EXPECT_EQ(sample[i].frame, static_cast<int64_t>(i / 40));
    EXPECT_DOUBLE_EQ(sample[i].timestamp.value(), sample[i].frame / 20.0);
    EXPECT_TRUE(rig.left().InImage(sample[i].left_pixel));
    EXPECT_TRUE(rig.right().InImage(sample[i].right_pixel));
  }
}

TEST(StereoSampler, PointsAreConsistentWithTheModel) {
  // Triangulating the two bearings in the medium recovers one point in
  // front of both cameras within the depth range.
  const StereoRig rig = test::AlphasenseRealisticRig();
  StereoSamplerOptions options;
  options.n = 1.34;
  options.min_depth = 1.0;
  options.max_depth = 2.0;
  const RefractiveCamera left =
      RefractiveCamera::Create(rig.left(), 1.34).value();
  const RefractiveCamera right =
      RefractiveCamera::Create(rig.right(), 1.34).value();
  const Rigid3d left_from_right = rig.right_from_left().Inverse();
  for (const StereoCorrespondence& c :
       SampleStereoCorrespondences(rig, options).value()) {
    const Eigen::Vector3d a =
        left.BearingInWaterFromImage(c.left_pixel).value();
    const Eigen::Vector3d b =
        left_from_right.rotation *
        right.BearingInWaterFromImage(c.right_pixel).value();
    const Eigen::Vector3d o = left_from_right.translation;
    // Closest points of the rays s a and o + u b.
    const double ab = a.dot(b), ao = a.dot(o), bo = b.dot(o);
    const double s = (ao - ab * bo) / (1.0 - ab * ab);
    const double u = (ab * ao - bo) / (1.0 - ab * ab);
    EXPECT_LT((s * a - (o + u * b)).norm(), 1e-10);
    EXPECT_GE((s * a).z(), 1.0 - 1e-9);
    EXPECT_LE((s * a).z(), 2.0 + 1e-9);
  }
}

TEST(StereoSampler, SameSeedSameSample) {
  const StereoRig rig = test::AlphasenseIdealRig();
  StereoSamplerOptions options;
  const auto a = SampleStereoCorrespondences(rig, options).value();
  const auto b = SampleStereoCorrespondences(rig, options).value();
  options.seed = 2;
  const auto c = SampleStereoCorrespondences(rig, options).value();
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].left_pixel, b[i].left_pixel);
    EXPECT_EQ(a[i].right_pixel, b[i].right_pixel);
  }
  EXPECT_NE(a[0].left_pixel, c[0].left_pixel);
}

TEST(StereoSampler, RejectsInvalidOptions) {
  const StereoRig rig = test::AlphasenseIdealRig();
  StereoSamplerOptions options;
  options.n = 2.5;
  EXPECT_FALSE(SampleStereoCorrespondences(rig, options).ok());
  options = StereoSamplerOptions();
  options.min_depth = 0.0;
  EXPECT_FALSE(SampleStereoCorrespondences(rig, options).ok());
  options = StereoSamplerOptions();
  options.max_depth = 0.1;
  EXPECT_FALSE(SampleStereoCorrespondences(rig, options).ok());
  options = StereoSamplerOptions();
  options.per_frame = 0;
  EXPECT_FALSE(SampleStereoCorrespondences(rig, options).ok());
}

TEST(StereoSampler, FailsWhenCamerasDoNotOverlap) {
  // Right camera turned around: nothing is seen by both.
  Rigid3d right_from_left;
  right_from_left.rotation = Eigen::Vector3d(-1.0, 1.0, -1.0).asDiagonal();
  right_from_left.translation = Eigen::Vector3d(-0.1, 0.0, 0.0);
  const StereoRig rig =
      StereoRig::Create(test::PinholeCamera(), test::PinholeCamera(),
                        right_from_left)
          .value();
  const StatusOr<std::vector<StereoCorrespondence>> sample =
      SampleStereoCorrespondences(rig, StereoSamplerOptions());
  ASSERT_FALSE(sample.ok());
  EXPECT_NE(sample.status().message().find("visible in both images"),
            std::string::npos);
}

TEST(StereoSampler, PixelNoiseHasRequestedSpread) {
  const StereoRig rig = test::AlphasenseIdealRig();
  StereoSamplerOptions options;
  options.per_frame = 2000;
  const auto exact = SampleStereoCorrespondences(rig, options).value();
  auto noisy = exact;
  AddPixelNoise(0.5, 3, &noisy);
  double sum_squares = 0.0;
  for (size_t i = 0; i < exact.size(); ++i) {
    sum_squares += (noisy[i].left_pixel - exact[i].left_pixel).squaredNorm() +
                   (noisy[i].right_pixel - exact[i].right_pixel).squaredNorm();
  }
  // 8000 draws: the sample sigma has a relative standard error of 0.8 %.
  EXPECT_NEAR(std::sqrt(sum_squares / (4.0 * exact.size())), 0.5, 0.5 * 0.04);
}

TEST(StereoSampler, OutliersReplaceTheRequestedFractionOfRightPixels) {
  const StereoRig rig = test::AlphasenseIdealRig();
  const std::vector<StereoCorrespondence> exact =
      test::ExactMatches(rig, 1.333, 1000);
  std::vector<StereoCorrespondence> data = exact;
  const std::vector<int64_t> outliers = AddOutliers(rig, 0.2, 5, &data);
  ASSERT_EQ(outliers.size(), 200u);
  EXPECT_TRUE(std::is_sorted(outliers.begin(), outliers.end()));
  size_t changed = 0;
  for (size_t i = 0; i < data.size(); ++i) {
    EXPECT_EQ(data[i].left_pixel, exact[i].left_pixel);
    EXPECT_TRUE(rig.right().InImage(data[i].right_pixel));
    const bool is_outlier = std::binary_search(
        outliers.begin(), outliers.end(), static_cast<int64_t>(i));
    changed += data[i].right_pixel != exact[i].right_pixel;
    if (!is_outlier) {
      EXPECT_EQ(data[i].right_pixel, exact[i].right_pixel);
    }
  }
  EXPECT_EQ(changed, 200u);
  // Deterministic per seed.
  std::vector<StereoCorrespondence> again = exact;
  EXPECT_EQ(AddOutliers(rig, 0.2, 5, &again), outliers);
  EXPECT_EQ(again[outliers[0]].right_pixel, data[outliers[0]].right_pixel);
  // The edge fractions.
  std::vector<StereoCorrespondence> none = exact;
  EXPECT_TRUE(AddOutliers(rig, 0.0, 5, &none).empty());
  std::vector<StereoCorrespondence> all = exact;
  EXPECT_EQ(AddOutliers(rig, 1.0, 5, &all).size(), exact.size());
}

TEST(FlatPortSampler, ThinPortReproducesTheModelSampler) {
  // The same draws traced through the simulator's thin port and through the
  // model: identical up to the lens undistortion's round trip (1e-9 px).
  constexpr double kPixelTolerance = 1e-9;
  const StereoRig rig = test::AlphasenseRealisticRig();
  StereoSamplerOptions options;
  options.num_frames = 2;
  options.per_frame = 200;
  const std::vector<StereoCorrespondence> model =
      SampleStereoCorrespondences(rig, options).value();
  const std::vector<StereoCorrespondence> exact =
      SampleFlatPortCorrespondences(rig, FlatPort(), FlatPort(), options)
          .value();
  ASSERT_EQ(model.size(), exact.size());
  for (size_t i = 0; i < model.size(); ++i) {
    EXPECT_EQ(model[i].frame, exact[i].frame);
    EXPECT_LT((model[i].left_pixel - exact[i].left_pixel).norm(),
              kPixelTolerance);
    EXPECT_LT((model[i].right_pixel - exact[i].right_pixel).norm(),
              kPixelTolerance);
  }
}

TEST(FlatPortSampler, EachFrameIsInItsOwnMedium) {
  // Thin port, media switching per frame: the refinement recovers each
  // frame's n exactly from that frame's matches.
  const StereoRig rig = test::AlphasenseRealisticRig();
  StereoSamplerOptions options;
  options.num_frames = 3;
  options.per_frame = 150;
  const std::vector<double> media = {1.333, 1.0, 1.6};
  const std::vector<StereoCorrespondence> sample =
      SampleFlatPortCorrespondences(rig, FlatPort(), FlatPort(), options,
                                    media)
          .value();
  for (int frame = 0; frame < 3; ++frame) {
    std::vector<StereoCorrespondence> of_frame;
    std::copy_if(sample.begin(), sample.end(), std::back_inserter(of_frame),
                 [&](const auto& c) { return c.frame == frame; });
    const RefinementSummary summary =
        RefineRefractiveIndex(rig, of_frame, RefinementOptions()).value();
    EXPECT_NEAR(summary.n, media[frame], 1e-9) << "frame " << frame;
  }
}

TEST(FlatPortSampler, ThickPortRaysMeetAtTheScenePoint) {
  // With 20 mm of air and 8 mm of glass the two pixels' rays in the medium
  // (each from its own point on the glass) intersect: their distance is
  // zero to the precision of the lens round trip (~1e-9 px at f = 345 px
  // and a few meters: ~1e-11 m).
  constexpr double kRayDistanceTolerance = 1e-9;  // meters
  const StereoRig rig = test::AlphasenseRealisticRig();
  FlatPort port;
  port.air_gap = 0.02;
  port.glass_thickness = 0.008;
  StereoSamplerOptions options;
  options.per_frame = 300;
  const std::vector<StereoCorrespondence> sample =
      SampleFlatPortCorrespondences(rig, port, port, options).value();
  ASSERT_EQ(sample.size(), 300u);
  const FlatPortCamera left =
      FlatPortCamera::Create(rig.left(), port, options.n).value();
  const FlatPortCamera right =
      FlatPortCamera::Create(rig.right(), port, options.n).value();
  const Rigid3d left_from_right = rig.right_from_left().Inverse();
  for (const StereoCorrespondence& c : sample) {
    const RayInMedium l = left.RayFromImage(c.left_pixel).value();
    const RayInMedium r_in_right = right.RayFromImage(c.right_pixel).value();
    const Eigen::Vector3d r_origin = left_from_right * r_in_right.origin;
    const Eigen::Vector3d r_direction =
        left_from_right.rotation * r_in_right.direction;
    const Eigen::Vector3d normal = l.direction.cross(r_direction);
    ASSERT_GT(normal.norm(), 1e-6);  // not parallel
    EXPECT_LT(std::abs((r_origin - l.origin).dot(normal.normalized())),
              kRayDistanceTolerance);
  }
}

TEST(FlatPortSampler, RejectsBadMediaAndPorts) {
  const StereoRig rig = test::AlphasenseRealisticRig();
  StereoSamplerOptions options;
  options.num_frames = 2;
  EXPECT_FALSE(SampleFlatPortCorrespondences(rig, FlatPort(), FlatPort(),
                                             options, {1.333})
                   .ok());
  EXPECT_FALSE(SampleFlatPortCorrespondences(rig, FlatPort(), FlatPort(),
                                             options, {1.333, 2.5})
                   .ok());
  FlatPort bad;
  bad.glass_index = 3.0;
  const StatusOr<std::vector<StereoCorrespondence>> result =
      SampleFlatPortCorrespondences(rig, FlatPort(), bad, options);
  ASSERT_FALSE(result.ok());
  EXPECT_NE(result.status().message().find("right port"), std::string::npos);
}

}  // namespace
}  // namespace rcm::stereo_sampler_test
