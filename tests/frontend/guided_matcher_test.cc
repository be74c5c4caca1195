#include "rcm/frontend/guided_matcher.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <numeric>
#include <random>
#include <tuple>
#include <vector>

#include "rcm/camera/refractive_camera.h"
#include "rcm/sim/reference_rigs.h"

namespace rcm::guided_matcher_test {
namespace {

constexpr double kWater = 1.333;

// Exact pixels of one scene point in both cameras.
struct ExactPair {
  Eigen::Vector3d point;  // left camera frame
  Eigen::Vector2d left;
  Eigen::Vector2d right;
};

// `count` exact pairs of points at depths 0.6-6 m on the rays of uniform
// left pixels, in water; pairs whose right pixel leaves the image are left
// out.
std::vector<ExactPair> ExactPairs(const StereoRig& rig, int count,
                                  uint64_t seed) {
  const RefractiveCamera left =
      RefractiveCamera::Create(rig.left(), kWater).value();
  const RefractiveCamera right =
      RefractiveCamera::Create(rig.right(), kWater).value();
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, rig.left().width() - 1.0);
  std::uniform_real_distribution<double> v(0.0, rig.left().height() - 1.0);
  std::uniform_real_distribution<double> depth(0.6, 6.0);
  std::vector<ExactPair> pairs;
  while (static_cast<int>(pairs.size()) < count) {
    // v before u, in a statement of its own (argument order is unspecified).
    const double drawn_v = v(rng);
    const Eigen::Vector3d bearing =
        left.BearingInWaterFromImage(Eigen::Vector2d(u(rng), drawn_v)).value();
    ExactPair pair;
    pair.point = bearing * (depth(rng) / bearing.z());
    const std::optional<Eigen::Vector2d> right_pixel =
        right.ImageFromPointInWater(rig.right_from_left() * pair.point);
    if (!right_pixel || !rig.right().InImage(*right_pixel)) continue;
    pair.left = left.ImageFromPointInWater(pair.point).value();
    pair.right = *right_pixel;
    pairs.push_back(pair);
  }
  return pairs;
}

// The right pixel of the point at `depth` on the left ray of `pair`, or
// the left pixel of the point at `depth` on its right ray (right_ray):
// another pixel on the exact locus.
Eigen::Vector2d OtherPixelOnTheLocus(const StereoRig& rig,
                                     const ExactPair& pair, double depth,
                                     bool right_ray) {
  const RefractiveCamera left =
      RefractiveCamera::Create(rig.left(), kWater).value();
  const RefractiveCamera right =
      RefractiveCamera::Create(rig.right(), kWater).value();
  if (!right_ray) {
    const Eigen::Vector3d point = pair.point * (depth / pair.point.z());
    return right.ImageFromPointInWater(rig.right_from_left() * point).value();
  }
  const Eigen::Vector3d bearing =
      right.BearingInWaterFromImage(pair.right).value();
  const Eigen::Vector3d point_in_right = bearing * (depth / bearing.z());
  return left
      .ImageFromPointInWater(rig.right_from_left().Inverse() * point_in_right)
      .value();
}

Features MakeFeatures(const std::vector<Eigen::Vector2d>& pixels,
                      const cv::Mat& descriptors, int norm_type) {
  Features features;
  for (const Eigen::Vector2d& pixel : pixels) {
    features.keypoints.emplace_back(static_cast<float>(pixel.x()),
                                    static_cast<float>(pixel.y()), 7.0f);
  }
  features.descriptors = descriptors.clone();
  features.norm_type = norm_type;
  return features;
}

// ORB-like binary descriptors: 32 random bytes a row.
cv::Mat RandomBinaryDescriptors(int rows, cv::RNG* rng) {
  cv::Mat descriptors(rows, 32, CV_8U);
  rng->fill(descriptors, cv::RNG::UNIFORM, 0, 256);
  return descriptors;
}

// `row` of `descriptors` with `bits` distinct bits flipped.
cv::Mat FlipBits(const cv::Mat& descriptors, int row, int bits, uint64_t seed) {
  std::vector<int> order(descriptors.cols * 8);
  std::iota(order.begin(), order.end(), 0);
  std::shuffle(order.begin(), order.end(), std::mt19937_64(seed));
  cv::Mat flipped = descriptors.row(row).clone();
  for (int i = 0; i < bits; ++i) {
    flipped.at<uchar>(0, order[i] / 8) ^=
        static_cast<uchar>(1 << (order[i] % 8));
  }
  return flipped;
}

LocusBand Band(const StereoRig& rig, const RefractiveIndexInterval& interval) {
  return LocusBand::Create(rig, interval, LocusBandOptions()).value();
}

std::vector<KeypointMatch> Match(const Features& left, const Features& right,
                                 const LocusBand& band,
                                 const GuidedMatchOptions& options) {
  return MatchInLocusBand(left, band.LeftKeys(left.keypoints), right,
                          band.RightKeys(right.keypoints), band, options);
}

// A left keypoint whose exact right pixel and whose distractors share its
// descriptor. Built for one band.
struct DistractorScene {
  Features left;
  Features right;
  std::vector<int> true_right;  // of each left keypoint
};

// Left keypoints of exact pairs, their right keypoints in shuffled order
// with identical descriptors, and per left keypoint `distractors` right
// keypoints with that same descriptor at random pixels outside its band.
DistractorScene MakeDistractorScene(const StereoRig& rig, const LocusBand& band,
                                    int count, int distractors,
                                    bool float_descriptors, uint64_t seed) {
  const std::vector<ExactPair> pairs = ExactPairs(rig, count, seed);
  cv::RNG rng(seed);
  cv::Mat descriptors;
  if (float_descriptors) {
    descriptors.create(count, 128, CV_32F);
    rng.fill(descriptors, cv::RNG::UNIFORM, 0.0f, 1.0f);
  } else {
    descriptors = RandomBinaryDescriptors(count, &rng);
  }
  std::vector<int> order(count);
  std::iota(order.begin(), order.end(), 0);
  std::shuffle(order.begin(), order.end(), std::mt19937_64(seed));
  DistractorScene scene;
  scene.true_right.assign(count, -1);
  std::vector<Eigen::Vector2d> left_pixels;
  std::vector<Eigen::Vector2d> right_pixels;
  cv::Mat right_descriptors;
  for (int k = 0; k < count; ++k) {
    left_pixels.push_back(pairs[k].left);
    const int i = order[k];
    scene.true_right[i] = static_cast<int>(right_pixels.size());
    right_pixels.push_back(pairs[i].right);
    right_descriptors.push_back(descriptors.row(i));
  }
  std::mt19937_64 pixel_rng(seed + 1);
  std::uniform_real_distribution<double> u(0.0, rig.right().width() - 1.0);
  std::uniform_real_distribution<double> v(0.0, rig.right().height() - 1.0);
  for (int i = 0; i < count; ++i) {
    const LocusKey left_key = band.LeftKey(pairs[i].left);
    for (int added = 0; added < distractors;) {
      const double drawn_v = v(pixel_rng);  // before u, as above
      const Eigen::Vector2d pixel(u(pixel_rng), drawn_v);
      if (band.Contains(left_key, band.RightKey(pixel))) continue;
      right_pixels.push_back(pixel);
      right_descriptors.push_back(descriptors.row(i));
      ++added;
    }
  }
  const int norm = float_descriptors ? cv::NORM_L2 : cv::NORM_HAMMING;
  scene.left = MakeFeatures(left_pixels, descriptors, norm);
  scene.right = MakeFeatures(right_pixels, right_descriptors, norm);
  return scene;
}

void ExpectExactlyTheTrueMatches(const std::vector<KeypointMatch>& matches,
                                 const DistractorScene& scene) {
  ASSERT_EQ(matches.size(), scene.true_right.size());
  for (size_t i = 0; i < matches.size(); ++i) {
    EXPECT_EQ(matches[i].left, static_cast<int>(i));
    EXPECT_EQ(matches[i].right, scene.true_right[i]) << "left " << i;
    EXPECT_EQ(matches[i].distance, 0.0f);
  }
}

TEST(GuidedMatcher, FindsTrueMatchesAmongIdenticalDistractorsOutsideTheBand) {
  // Every left keypoint has 3 right keypoints with its very descriptor
  // outside its band: without the band the ratio test would reject them
  // all (three candidates at distance 0), with it only the true one is a
  // candidate. In the narrow band of an estimate and in the wide prior one.
  for (const StereoRig& rig :
       {AlphasenseFrontRectifiedRig(), AlphasenseFrontUnrectifiedRig()}) {
    for (const RefractiveIndexInterval& interval :
         {RefractiveIndexInterval::Around(kWater, 1e-4, 6.0, 0.01),
          RefractiveIndexInterval{1.0, 1.6}}) {
      const LocusBand band = Band(rig, interval);
      const DistractorScene scene =
          MakeDistractorScene(rig, band, 200, 3, false, 21);
      ASSERT_EQ(scene.right.keypoints.size(), 800u);
      ExpectExactlyTheTrueMatches(
          Match(scene.left, scene.right, band, GuidedMatchOptions()), scene);
    }
  }
}

TEST(GuidedMatcher, FloatDescriptorsUseTheL2Norm) {
  const StereoRig rig = AlphasenseFrontUnrectifiedRig();
  const LocusBand band = Band(rig, {1.3, 1.4});
  const DistractorScene scene =
      MakeDistractorScene(rig, band, 150, 2, true, 22);
  ExpectExactlyTheTrueMatches(
      Match(scene.left, scene.right, band, GuidedMatchOptions()), scene);

  // The Hamming limit does not apply to float descriptors: a true pair
  // 0.5 apart in L2 (random rows are ~4 apart) is still matched with a
  // limit of 0 bits.
  DistractorScene noisy = scene;
  noisy.right.descriptors = scene.right.descriptors.clone();
  noisy.right.descriptors.row(scene.true_right[0]).at<float>(0, 0) += 0.5f;
  GuidedMatchOptions options;
  options.max_hamming_distance = 0;
  const std::vector<KeypointMatch> matches =
      Match(noisy.left, noisy.right, band, options);
  ASSERT_EQ(matches.size(), scene.true_right.size());
  EXPECT_EQ(matches[0].right, scene.true_right[0]);
  EXPECT_NEAR(matches[0].distance, 0.5f, 1e-6);
}

// One left keypoint and two right candidates in its band: the true right
// pixel and the right pixel of a farther point on the same left ray.
struct TwoCandidates {
  Features left;
  Features right;
};

TwoCandidates MakeTwoCandidates(int true_bits, int other_bits) {
  const StereoRig rig = AlphasenseFrontRectifiedRig();
  const ExactPair pair = ExactPairs(rig, 1, 23)[0];
  cv::RNG rng(23);
  const cv::Mat descriptor = RandomBinaryDescriptors(1, &rng);
  TwoCandidates scene;
  scene.left = MakeFeatures({pair.left}, descriptor, cv::NORM_HAMMING);
  cv::Mat right_descriptors;
  right_descriptors.push_back(FlipBits(descriptor, 0, true_bits, 1));
  right_descriptors.push_back(FlipBits(descriptor, 0, other_bits, 2));
  scene.right = MakeFeatures(
      {pair.right,
       OtherPixelOnTheLocus(rig, pair, 1.5 * pair.point.z(), false)},
      right_descriptors, cv::NORM_HAMMING);
  return scene;
}

TEST(GuidedMatcher, RatioTestDecidesBetweenCandidatesInTheBand) {
  const LocusBand band =
      Band(AlphasenseFrontRectifiedRig(),
           RefractiveIndexInterval::Around(kWater, 1e-4, 6.0, 0.01));
  {
    // Precondition: both candidates are in the band.
    const TwoCandidates scene = MakeTwoCandidates(0, 0);
    const std::vector<LocusKey> left = band.LeftKeys(scene.left.keypoints);
    const std::vector<LocusKey> right = band.RightKeys(scene.right.keypoints);
    ASSERT_TRUE(band.Contains(left[0], right[0]));
    ASSERT_TRUE(band.Contains(left[0], right[1]));
  }
  const GuidedMatchOptions options;  // ratio 0.8
  // Equal distances: ambiguous, no match.
  const TwoCandidates identical = MakeTwoCandidates(0, 0);
  EXPECT_TRUE(Match(identical.left, identical.right, band, options).empty());
  const TwoCandidates equal = MakeTwoCandidates(12, 12);
  EXPECT_TRUE(Match(equal.left, equal.right, band, options).empty());
  // 20 < 0.8 * 24 = 19.2 fails; 20 < 0.8 * 26 = 20.8 passes.
  const TwoCandidates close = MakeTwoCandidates(20, 24);
  EXPECT_TRUE(Match(close.left, close.right, band, options).empty());
  const TwoCandidates apart = MakeTwoCandidates(20, 26);
  const std::vector<KeypointMatch> matches =
      Match(apart.left, apart.right, band, options);
  ASSERT_EQ(matches.size(), 1u);
  EXPECT_EQ(matches[0].right, 0);
  EXPECT_EQ(matches[0].distance, 20.0f);
  // The nearer candidate wins whichever comes first.
  const TwoCandidates reversed = MakeTwoCandidates(26, 20);
  const std::vector<KeypointMatch> other =
      Match(reversed.left, reversed.right, band, options);
  ASSERT_EQ(other.size(), 1u);
  EXPECT_EQ(other[0].right, 1);
  // Ratio 1 accepts anything but a tie.
  GuidedMatchOptions loose;
  loose.ratio = 1.0;
  EXPECT_EQ(Match(close.left, close.right, band, loose).size(), 1u);
  EXPECT_TRUE(Match(equal.left, equal.right, band, loose).empty());
}

TEST(GuidedMatcher, SingleCandidatePassesTheRatioTest) {
  const LocusBand band = Band(AlphasenseFrontRectifiedRig(), {1.3, 1.4});
  TwoCandidates scene = MakeTwoCandidates(30, 0);
  scene.right.keypoints.resize(1);
  scene.right.descriptors = scene.right.descriptors.row(0).clone();
  GuidedMatchOptions options;
  options.ratio = 0.01;
  const std::vector<KeypointMatch> matches =
      Match(scene.left, scene.right, band, options);
  ASSERT_EQ(matches.size(), 1u);
  EXPECT_EQ(matches[0].distance, 30.0f);
}

// Two left keypoints on the locus of one right keypoint (points at two
// depths on its ray), `bits` from its descriptor each; each has that right
// keypoint as its only candidate.
struct TwoLeft {
  Features left;
  Features right;
};

TwoLeft MakeTwoLeft(int first_bits, int second_bits) {
  const StereoRig rig = AlphasenseFrontRectifiedRig();
  const ExactPair pair = ExactPairs(rig, 1, 24)[0];
  cv::RNG rng(24);
  const cv::Mat descriptor = RandomBinaryDescriptors(1, &rng);
  TwoLeft scene;
  scene.right = MakeFeatures({pair.right}, descriptor, cv::NORM_HAMMING);
  cv::Mat left_descriptors;
  left_descriptors.push_back(FlipBits(descriptor, 0, first_bits, 1));
  left_descriptors.push_back(FlipBits(descriptor, 0, second_bits, 2));
  scene.left = MakeFeatures(
      {pair.left, OtherPixelOnTheLocus(rig, pair, 2.0 * pair.point.z(), true)},
      left_descriptors, cv::NORM_HAMMING);
  return scene;
}

TEST(GuidedMatcher, CrossCheckKeepsTheMutualBest) {
  const LocusBand band =
      Band(AlphasenseFrontRectifiedRig(),
           RefractiveIndexInterval::Around(kWater, 0.0, 6.0, 0.01));
  {
    const TwoLeft scene = MakeTwoLeft(0, 0);
    const std::vector<LocusKey> left = band.LeftKeys(scene.left.keypoints);
    const std::vector<LocusKey> right = band.RightKeys(scene.right.keypoints);
    ASSERT_TRUE(band.Contains(left[0], right[0]));
    ASSERT_TRUE(band.Contains(left[1], right[0]));
    // Two distinct left keypoints.
    ASSERT_GT(cv::norm(scene.left.keypoints[0].pt - scene.left.keypoints[1].pt),
              1.0);
  }
  GuidedMatchOptions cross;
  GuidedMatchOptions one_way;
  one_way.cross_check = false;
  for (const auto& [first_bits, second_bits, winner] :
       {std::tuple<int, int, int>{5, 10, 0},
        std::tuple<int, int, int>{10, 5, 1}}) {
    const TwoLeft scene = MakeTwoLeft(first_bits, second_bits);
    const std::vector<KeypointMatch> mutual =
        Match(scene.left, scene.right, band, cross);
    ASSERT_EQ(mutual.size(), 1u);
    EXPECT_EQ(mutual[0].left, winner);
    EXPECT_EQ(mutual[0].right, 0);
    const std::vector<KeypointMatch> both =
        Match(scene.left, scene.right, band, one_way);
    ASSERT_EQ(both.size(), 2u);
    EXPECT_EQ(both[0].left, 0);
    EXPECT_EQ(both[1].left, 1);
    EXPECT_EQ(both[0].distance, static_cast<float>(first_bits));
    EXPECT_EQ(both[1].distance, static_cast<float>(second_bits));
  }
  // A tie goes to the lower left index.
  const TwoLeft tie = MakeTwoLeft(7, 7);
  const std::vector<KeypointMatch> mutual =
      Match(tie.left, tie.right, band, cross);
  ASSERT_EQ(mutual.size(), 1u);
  EXPECT_EQ(mutual[0].left, 0);
}

TEST(GuidedMatcher, MaxHammingDistanceIsInclusive) {
  const LocusBand band = Band(AlphasenseFrontRectifiedRig(), {1.3, 1.4});
  GuidedMatchOptions options;  // 64 bits
  TwoCandidates at_limit = MakeTwoCandidates(64, 0);
  at_limit.right.keypoints.resize(1);
  at_limit.right.descriptors = at_limit.right.descriptors.row(0).clone();
  EXPECT_EQ(Match(at_limit.left, at_limit.right, band, options).size(), 1u);
  TwoCandidates beyond = MakeTwoCandidates(65, 0);
  beyond.right.keypoints.resize(1);
  beyond.right.descriptors = beyond.right.descriptors.row(0).clone();
  EXPECT_TRUE(Match(beyond.left, beyond.right, band, options).empty());
  options.max_hamming_distance = 65;
  EXPECT_EQ(Match(beyond.left, beyond.right, band, options).size(), 1u);
  options.max_hamming_distance = 0;
  EXPECT_TRUE(Match(at_limit.left, at_limit.right, band, options).empty());
}

TEST(GuidedMatcher, SameMatchesOnAnyNumberOfThreads) {
  // 400 exact pairs with descriptors 0-40 bits apart, 400 left and 400
  // right keypoints without a partner, and two left keypoints (the first
  // and the last, in different threads' chunks) tied on one right one.
  const StereoRig rig = AlphasenseFrontUnrectifiedRig();
  const LocusBand band = Band(rig, {1.0, 1.6});
  const std::vector<ExactPair> pairs = ExactPairs(rig, 400, 25);
  cv::RNG rng(25);
  std::mt19937_64 random(25);
  std::uniform_int_distribution<int> bits(0, 40);
  std::uniform_real_distribution<double> u(0.0, 719.0);
  std::uniform_real_distribution<double> v(0.0, 539.0);
  std::vector<Eigen::Vector2d> left_pixels;
  std::vector<Eigen::Vector2d> right_pixels;
  cv::Mat left_descriptors;
  cv::Mat right_descriptors;
  // The tie: left 0 and the last left keypoint on the ray of right 0.
  const cv::Mat tied = RandomBinaryDescriptors(1, &rng);
  left_pixels.push_back(pairs[0].left);
  left_descriptors.push_back(tied);
  right_pixels.push_back(pairs[0].right);
  right_descriptors.push_back(tied);
  for (size_t i = 1; i < pairs.size(); ++i) {
    const cv::Mat descriptor = RandomBinaryDescriptors(1, &rng);
    left_pixels.push_back(pairs[i].left);
    left_descriptors.push_back(descriptor);
    right_pixels.push_back(pairs[i].right);
    right_descriptors.push_back(FlipBits(descriptor, 0, bits(random), i));
  }
  for (int i = 0; i < 400; ++i) {
    const double left_v = v(random);  // before u, as above
    left_pixels.emplace_back(u(random), left_v);
    left_descriptors.push_back(RandomBinaryDescriptors(1, &rng));
    const double right_v = v(random);
    right_pixels.emplace_back(u(random), right_v);
    right_descriptors.push_back(RandomBinaryDescriptors(1, &rng));
  }
  left_pixels.push_back(
      OtherPixelOnTheLocus(rig, pairs[0], 2.0 * pairs[0].point.z(), true));
  left_descriptors.push_back(tied);
  const Features left =
      MakeFeatures(left_pixels, left_descriptors, cv::NORM_HAMMING);
  const Features right =
      MakeFeatures(right_pixels, right_descriptors, cv::NORM_HAMMING);
  const int last = static_cast<int>(left_pixels.size()) - 1;

  GuidedMatchOptions options;
  options.num_threads = 1;
  const std::vector<KeypointMatch> serial = Match(left, right, band, options);
  // Most true pairs survive (the wide prior band holds a few random
  // keypoints per left one).
  ASSERT_GT(serial.size(), 300u);
  EXPECT_EQ(serial[0].left, 0);
  EXPECT_EQ(serial[0].right, 0);
  EXPECT_NE(serial.back().left, last);
  for (int threads : {2, 3, 7}) {
    options.num_threads = threads;
    const std::vector<KeypointMatch> parallel =
        Match(left, right, band, options);
    ASSERT_EQ(parallel.size(), serial.size()) << threads << " threads";
    for (size_t i = 0; i < serial.size(); ++i) {
      EXPECT_EQ(parallel[i].left, serial[i].left);
      EXPECT_EQ(parallel[i].right, serial[i].right);
      EXPECT_EQ(parallel[i].distance, serial[i].distance);
    }
  }
  // Without the cross-check the last left keypoint keeps its tie.
  options.cross_check = false;
  EXPECT_EQ(Match(left, right, band, options).back().left, last);
}

TEST(GuidedMatcher, EmptyInputsGiveNoMatches) {
  const StereoRig rig = AlphasenseFrontRectifiedRig();
  const LocusBand band = Band(rig, {1.0, 1.6});
  const DistractorScene scene =
      MakeDistractorScene(rig, band, 10, 0, false, 26);
  const Features empty;
  const GuidedMatchOptions options;
  EXPECT_TRUE(Match(empty, scene.right, band, options).empty());
  EXPECT_TRUE(Match(scene.left, empty, band, options).empty());
  EXPECT_TRUE(Match(empty, empty, band, options).empty());
  ASSERT_EQ(Match(scene.left, scene.right, band, options).size(), 10u);
}

TEST(GuidedMatcher, InvalidKeysAreNotMatched) {
  const StereoRig rig = AlphasenseFrontRectifiedRig();
  const LocusBand band = Band(rig, {1.0, 1.6});
  const DistractorScene scene =
      MakeDistractorScene(rig, band, 10, 0, false, 27);
  std::vector<LocusKey> left_keys = band.LeftKeys(scene.left.keypoints);
  std::vector<LocusKey> right_keys = band.RightKeys(scene.right.keypoints);
  left_keys[2].valid = false;
  right_keys[scene.true_right[5]].valid = false;
  const std::vector<KeypointMatch> matches =
      MatchInLocusBand(scene.left, left_keys, scene.right, right_keys, band,
                       GuidedMatchOptions());
  ASSERT_EQ(matches.size(), 8u);
  for (const KeypointMatch& match : matches) {
    EXPECT_NE(match.left, 2);
    EXPECT_NE(match.left, 5);
    EXPECT_EQ(match.right, scene.true_right[match.left]);
  }
}

TEST(GuidedMatcher, OptionsCheck) {
  EXPECT_TRUE(GuidedMatchOptions().Check().ok());
  GuidedMatchOptions options;
  options.ratio = 0.0;
  EXPECT_EQ(options.Check().message(),
            "ratio test threshold must be in (0, 1], got 0.000000");
  options.ratio = 1.5;
  EXPECT_FALSE(options.Check().ok());
  options.ratio = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(options.Check().ok());
  options.ratio = 1.0;
  EXPECT_TRUE(options.Check().ok());
  options.max_hamming_distance = -1;
  EXPECT_EQ(options.Check().message(),
            "max Hamming distance must be in [0, 256], got -1");
  options.max_hamming_distance = 257;
  EXPECT_FALSE(options.Check().ok());
  options.max_hamming_distance = 256;
  EXPECT_TRUE(options.Check().ok());
  options.num_threads = 0;
  EXPECT_EQ(options.Check().message(), "threads must be at least 1, got 0");
}

}  // namespace
}  // namespace rcm::guided_matcher_test
