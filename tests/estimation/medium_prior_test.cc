#include "rcm/estimation/medium_prior.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <string>

#include "rcm/estimation/medium_drift.h"
#include "rcm/sim/stereo_sampler.h"
#include "rcm/util/number_format.h"
#include "support/test_budget.h"
#include "support/test_rigs.h"

namespace rcm::medium_prior_test {
namespace {

constexpr double kDegree = M_PI / 180.0;

// 10 frames of 150 exact matches of `rig` at depths 0.9-1.1 m: a narrow
// field at one depth, where n and cam1's rotation correlate with R ~ 0.99.
std::vector<StereoCorrespondence> AtOneDepth(const StereoRig& rig, double n,
                                             uint64_t seed) {
  StereoSamplerOptions sampler;
  sampler.n = n;
  sampler.min_depth = 0.9;
  sampler.max_depth = 1.1;
  sampler.num_frames = 10;
  sampler.per_frame = 150;
  sampler.seed = seed;
  return SampleStereoCorrespondences(rig, sampler).value();
}

// The refractive index of pure water at 20 C and the sodium D line
// (589.3 nm), relative to air: 1.33299 (CRC Handbook of Chemistry and
// Physics). Quan and Fry's fit reproduces the data it was fitted to
// within a few 1e-5; 1e-4 is the bar here.
TEST(WaterRefractiveIndex, PureWaterAtTwentyDegreesAndTheSodiumLine) {
  EXPECT_NEAR(WaterRefractiveIndex(0.0, 20.0, 589.3).value(), 1.33299, 1e-4);
}

// Salt raises n (about 2e-4 per g/kg), heat and longer waves lower it.
TEST(WaterRefractiveIndex,
     IncreasesWithSalinityDecreasesWithTemperatureAndWavelength) {
  const double base = WaterRefractiveIndex(20.0, 15.0, 550.0).value();
  EXPECT_NEAR((WaterRefractiveIndex(21.0, 15.0, 550.0).value() - base), 1.9e-4,
              0.2e-4);
  EXPECT_LT(WaterRefractiveIndex(20.0, 16.0, 550.0).value(), base);
  EXPECT_LT(WaterRefractiveIndex(20.0, 15.0, 560.0).value(), base);
}

TEST(WaterRefractiveIndex, OutsideTheEquationsRangeIsAnError) {
  EXPECT_FALSE(WaterRefractiveIndex(-1.0, 15.0, 550.0).ok());
  EXPECT_FALSE(WaterRefractiveIndex(40.0, 15.0, 550.0).ok());
  EXPECT_FALSE(WaterRefractiveIndex(35.0, 31.0, 550.0).ok());
  EXPECT_FALSE(WaterRefractiveIndex(35.0, 15.0, 800.0).ok());
  EXPECT_FALSE(WaterRefractiveIndex(NAN, 15.0, 550.0).ok());
}

// The named media: their ranges are those of the equation at the corners
// of their boxes of conditions (medium_prior.h), and sigma is that of a
// uniform n over the range.
TEST(MediumPrior, FreshAndSeaWater) {
  const MediumPrior fresh = ParseMediumPrior("fresh").value();
  EXPECT_NEAR(fresh.min_n, WaterRefractiveIndex(0.0, 30.0, 650.0).value(),
              1e-12);
  EXPECT_NEAR(fresh.max_n, WaterRefractiveIndex(1.0, 0.0, 450.0).value(),
              1e-12);
  const MediumPrior sea = ParseMediumPrior("sea").value();
  EXPECT_NEAR(sea.min_n, WaterRefractiveIndex(30.0, 30.0, 650.0).value(),
              1e-12);
  EXPECT_NEAR(sea.max_n, WaterRefractiveIndex(35.0, 0.0, 450.0).value(), 1e-12);
  for (const MediumPrior& medium : {fresh, sea}) {
    EXPECT_NEAR(medium.n, 0.5 * (medium.min_n + medium.max_n), 1e-15);
    EXPECT_NEAR(medium.sigma, (medium.max_n - medium.min_n) / std::sqrt(12.0),
                1e-15);
    std::printf("%s\n", medium.Describe().c_str());
  }
  // The values docs/estimate.md and the --medium help state.
  EXPECT_EQ(fresh.Describe().substr(0, 31), "fresh water (n 1.3302-1.3404: 0");
  EXPECT_EQ(sea.Describe().substr(0, 29), "sea water (n 1.3356-1.3474: 3");
  EXPECT_EQ(FormatFixed(fresh.n, 4) + " +- " + FormatFixed(fresh.sigma, 4),
            "1.3353 +- 0.0029");
  EXPECT_EQ(FormatFixed(sea.n, 4) + " +- " + FormatFixed(sea.sigma, 4),
            "1.3415 +- 0.0034");
}

TEST(MediumPrior, ExplicitIndexAndSigma) {
  const MediumPrior medium = ParseMediumPrior("1.338:0.002").value();
  EXPECT_EQ(medium.n, 1.338);
  EXPECT_EQ(medium.sigma, 0.002);
  EXPECT_NEAR(medium.min_n, 1.332, 1e-12);
  EXPECT_NEAR(medium.max_n, 1.344, 1e-12);
}

TEST(MediumPrior, MalformedTextIsOneLineError) {
  for (const std::string text :
       {"", "salt", "1.34", "1.34:", ":0.01", "1.34:0", "1.34:-1", "2.5:0.1",
        "0.9:0.1", "1.34:0.01x", "nan:0.01", "1.34:inf"}) {
    const StatusOr<MediumPrior> medium = ParseMediumPrior(text);
    ASSERT_FALSE(medium.ok()) << text;
    EXPECT_EQ(medium.status().message().find('\n'), std::string::npos);
  }
}

TEST(MediumPrior, ContradictionBeyondThreeSigma) {
  const MediumPrior medium = ParseMediumPrior("1.340:0.003").value();
  // sqrt(0.003^2 + 0.004^2) = 0.005.
  EXPECT_NEAR(CheckAgainstMedium(1.355, 0.004, medium).z, 3.0, 1e-9);
  EXPECT_FALSE(CheckAgainstMedium(1.3549, 0.004, medium).contradicts);
  const MediumCheck far = CheckAgainstMedium(1.250, 0.004, medium);
  EXPECT_TRUE(far.contradicts);
  EXPECT_NE(far.message.find("contradicts n 1.3400 +- 0.0030"),
            std::string::npos)
      << far.message;
}

// Exact matches of a rig that turned 0.5 degree since its calibration, a
// narrow field at one depth (n and the rotation correlate with R ~ 0.99):
// with the medium's prior centred on the true n and the rotation free,
// the least squares is zero at the truth, whatever the prior's width.
TEST(MediumDrift, ExactDataGiveTheTurnOfANarrowRig) {
  constexpr double kExactTolerance = 1e-9;
  constexpr double kTrueN = 1.342;
  const StereoRig nominal = test::NarrowRadtanRig();
  const Eigen::Vector3d drift = Eigen::Vector3d(0.3, 0.4, 0.0) * kDegree;
  const std::vector<StereoCorrespondence> exact =
      AtOneDepth(nominal.WithCam1Moved(drift).value(), kTrueN,
                 StereoSamplerOptions().seed);
  const MediumDrift turned =
      EstimateDriftAssumingMedium(nominal, exact, RefinementOptions(),
                                  ParseMediumPrior("1.342:0.003").value())
          .value();
  EXPECT_NEAR(turned.assuming_medium.n, kTrueN, kExactTolerance);
  EXPECT_LT((turned.assuming_medium.rotation->angle_axis - drift).norm(),
            kExactTolerance);
  EXPECT_NEAR(turned.angle, 0.5 * kDegree, kExactTolerance);
  EXPECT_TRUE(turned.turned);
  EXPECT_NE(turned.message.find("cam1 has turned by 0.500"), std::string::npos)
      << turned.message;
}

// Monte Carlo: rigs turned by a drift drawn with 0.3 degree per axis, 0.3
// px of pixel noise, the true n drawn from the medium's prior (so the
// prior is right on average, as the physics is for the water a rig dives
// in): the z-scores of the turn's components about x and y (the ones a
// narrow field at one depth confuses with n) and of n under the prior have
// rms (bias included) within [0.7, 1.3] (100 draws of N(0, 1): 1 +- 0.15
// at 2 sigma).
TEST(MediumDrift, MonteCarloTurnSigmaIsHonestOnANarrowRig) {
  const StereoRig nominal = test::NarrowRadtanRig();
  const MediumPrior medium = ParseMediumPrior("sea").value();
  const int trials = test::Trials(100);
  std::mt19937_64 rng(41);
  std::normal_distribution<double> gaussian(0.0, 1.0);
  double sum2[3] = {0.0, 0.0, 0.0};
  int used = 0;
  for (int t = 0; t < trials; ++t) {
    const Eigen::Vector3d drift(0.3 * kDegree * gaussian(rng),
                                0.3 * kDegree * gaussian(rng),
                                0.3 * kDegree * gaussian(rng));
    const double n = medium.n + medium.sigma * gaussian(rng);
    std::vector<StereoCorrespondence> data =
        AtOneDepth(nominal.WithCam1Moved(drift).value(), n, 100 + t);
    AddPixelNoise(0.3, 1000 + t, &data);
    const StatusOr<MediumDrift> turned =
        EstimateDriftAssumingMedium(nominal, data, RefinementOptions(), medium);
    ASSERT_TRUE(turned.ok()) << turned.status().message();
    const RefinementSummary& s = turned->assuming_medium;
    const double z[3] = {
        (s.rotation->angle_axis.x() - drift.x()) / s.rotation->sigma.x(),
        (s.rotation->angle_axis.y() - drift.y()) / s.rotation->sigma.y(),
        (s.n - n) / s.sigma_n};
    for (int k = 0; k < 3; ++k) sum2[k] += z[k] * z[k];
    ++used;
  }
  const char* names[3] = {"turn about x", "turn about y", "n under the prior"};
  for (int k = 0; k < 3; ++k) {
    const double rms = std::sqrt(sum2[k] / used);
    std::printf("%s: rms z %.2f over %d trials\n", names[k], rms, used);
    if (!test::ChecksStatistics()) continue;
    EXPECT_GE(rms, 0.7) << names[k];
    EXPECT_LE(rms, 1.3) << names[k];
  }
}

}  // namespace
}  // namespace rcm::medium_prior_test
