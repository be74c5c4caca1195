#include "rcm/estimation/generalized_epipolar_error.h"

#include <ceres/ceres.h>
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <vector>

#include "rcm/estimation/prepared_correspondence.h"
#include "rcm/estimation/sampson_coplanarity_error.h"
#include "rcm/sim/stereo_sampler.h"
#include "rcm/stereo/epipolar.h"
#include "support/test_rigs.h"

namespace rcm::generalized_epipolar_error_test {
namespace {

// The housing: 8 mm of air, 6 mm of acrylic.
FlatPort HousingPort() {
  FlatPort port;
  port.air_gap = 0.008;
  port.glass_thickness = 0.006;
  port.glass_index = 1.49;
  return port;
}

ThickPortStereo Stereo(const StereoRig& rig, const FlatPort& port) {
  return {port, port, rig.right_from_left()};
}

std::vector<PreparedCorrespondence> ThickPortMatches(const StereoRig& rig,
                                                     const FlatPort& port,
                                                     double n,
                                                     double noise_px = 0.0) {
  StereoSamplerOptions options;
  options.n = n;
  options.per_frame = 300;
  options.seed = 5;
  std::vector<StereoCorrespondence> matches =
      SampleFlatPortCorrespondences(rig, port, port, options).value();
  if (noise_px > 0.0) AddPixelNoise(noise_px, 6, &matches);
  return PrepareCorrespondences(rig, matches).prepared;
}

// On exact correspondences through the thick port the residual vanishes
// at the true n and port: the sampler's exact port and the templated
// back-trace agree to 1e-12 in the rays, which is ~1e-9 px here.
TEST(GeneralizedEpipolarError, ZeroOnExactThickPortCorrespondences) {
  const StereoRig rig = test::AlphasenseRealisticRig();
  const std::vector<PreparedCorrespondence> matches =
      ThickPortMatches(rig, HousingPort(), 1.335);
  ASSERT_GT(matches.size(), 250u);
  double max_residual = 0.0;
  double max_wrong_n = 0.0;
  for (const PreparedCorrespondence& match : matches) {
    double residual = 0.0;
    ASSERT_TRUE(GeneralizedEpipolarResidual(Stereo(rig, HousingPort()), match,
                                            1.335, 0.0, &residual));
    max_residual = std::max(max_residual, std::abs(residual));
    ASSERT_TRUE(GeneralizedEpipolarResidual(Stereo(rig, HousingPort()), match,
                                            1.345, 0.0, &residual));
    max_wrong_n = std::max(max_wrong_n, std::abs(residual));
  }
  EXPECT_LT(max_residual, 1e-9);
  EXPECT_GT(max_wrong_n, 0.1);  // n off by 0.01 moves matches ~1 px
}

// With a thin port the generalized residual is the thin-port Sampson
// residual up to sign and second order: both are the first-order distance
// from the same locus, of bearings scaled differently (unit vs
// (x, y, m)), which changes the normalization only by O(r^2).
TEST(GeneralizedEpipolarError, ThinPortIsTheCoplanarityResidual) {
  const StereoRig rig = test::AlphasenseRealisticRig();
  const FlatPort thin;
  const std::vector<PreparedCorrespondence> matches =
      ThickPortMatches(rig, thin, 1.333, 0.5);
  const Eigen::Matrix3d essential = EssentialMatrix(rig.right_from_left());
  for (const PreparedCorrespondence& match : matches) {
    double generalized = 0.0;
    double coplanarity = 0.0;
    ASSERT_TRUE(GeneralizedEpipolarResidual(Stereo(rig, thin), match, 1.333,
                                            0.0, &generalized));
    ASSERT_TRUE(SampsonCoplanarityResidual<double>(essential, match, 1.333,
                                                   nullptr, &coplanarity));
    EXPECT_NEAR(std::abs(generalized), std::abs(coplanarity),
                1e-3 + 0.01 * std::abs(coplanarity));
  }
}

// Autodiff derivatives in n and the gap against central differences of
// the residual. The residual itself is accurate to ~1e-10 px (its own
// central-difference denominator), so the steps are large enough for that
// to stay below 1e-5 of the derivative: 1e-5 in n, 1e-5 m in the gap
// (truncation error O(h^2) ~ 1e-10 relative).
TEST(GeneralizedEpipolarError, JacobianMatchesCentralDifferences) {
  const StereoRig rig = test::AlphasenseRealisticRig();
  const std::vector<PreparedCorrespondence> matches =
      ThickPortMatches(rig, HousingPort(), 1.335, 0.5);
  for (size_t i = 0; i < 20; ++i) {
    std::unique_ptr<ceres::CostFunction> cost(GeneralizedEpipolarError::Create(
        Stereo(rig, HousingPort()), matches[i]));
    double n = 1.335;
    double gap = 0.0;
    const double* blocks[] = {&n, &gap};
    double residual;
    double jacobian_n;
    double jacobian_gap;
    double* jacobians[] = {&jacobian_n, &jacobian_gap};
    ASSERT_TRUE(cost->Evaluate(blocks, &residual, jacobians));
    const auto value = [&](double n_value, double gap_value) {
      double r = 0.0;
      EXPECT_TRUE(GeneralizedEpipolarResidual(
          Stereo(rig, HousingPort()), matches[i], n_value, gap_value, &r));
      return r;
    };
    const double numeric_n =
        (value(n + 1e-5, 0.0) - value(n - 1e-5, 0.0)) / 2e-5;
    const double numeric_gap = (value(n, 1e-5) - value(n, -1e-5)) / 2e-5;
    EXPECT_NEAR(jacobian_n, numeric_n,
                1e-4 * std::max(1.0, std::abs(numeric_n)));
    EXPECT_NEAR(jacobian_gap, numeric_gap,
                1e-4 * std::max(1.0, std::abs(numeric_gap)));
  }
}

}  // namespace
}  // namespace rcm::generalized_epipolar_error_test
