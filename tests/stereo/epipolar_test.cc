#include "rcm/stereo/epipolar.h"

#include <gtest/gtest.h>

#include <cmath>

#include "rcm/sim/stereo_sampler.h"
#include "support/test_rigs.h"

namespace rcm::epipolar_test {
namespace {

// e is a triple product of O(1) bearings (unit baseline): exact data give
// zero up to rounding of the undistortion (1e-14) and the products.
constexpr double kResidualTolerance = 1e-12;

std::vector<NormalizedCorrespondence> Sample(const StereoRig& rig, double n) {
  std::vector<NormalizedCorrespondence> normalized;
  for (const StereoCorrespondence& c : test::ExactMatches(rig, n, 300)) {
    normalized.push_back(rig.Normalize(c).value());
  }
  return normalized;
}

TEST(Epipolar, ResidualVanishesOnExactDataOfAnyRig) {
  for (const StereoRig& rig :
       {test::AlphasenseIdealRig(), test::AlphasenseRealisticRig()}) {
    for (double n : {1.0, 1.333, 1.5}) {
      const Eigen::Matrix3d essential = EssentialMatrix(rig.right_from_left());
      for (const NormalizedCorrespondence& c : Sample(rig, n)) {
        EXPECT_NEAR(
            CoplanarityResidual(essential, n, c.left.data(), c.right.data()),
            0.0, kResidualTolerance);
      }
    }
  }
}

TEST(Epipolar, ResidualDetectsWrongIndex) {
  const StereoRig rig = test::AlphasenseRealisticRig();
  const Eigen::Matrix3d essential = EssentialMatrix(rig.right_from_left());
  double sum_squares = 0.0;
  const std::vector<NormalizedCorrespondence> data = Sample(rig, 1.333);
  for (const NormalizedCorrespondence& c : data) {
    const double e =
        CoplanarityResidual(essential, 1.2, c.left.data(), c.right.data());
    sum_squares += e * e;
  }
  EXPECT_GT(std::sqrt(sum_squares / data.size()), 1e-4);
}

TEST(Epipolar, IdealRigReducesToEquationThirteen) {
  // e = b_r^T [t]x b_l with t = (-1, 0, 0) is yr m_l - yl m_r.
  const StereoRig rig = test::AlphasenseIdealRig();
  const Eigen::Matrix3d essential = EssentialMatrix(rig.right_from_left());
  const double n = 1.4;
  const Eigen::Vector2d left(0.3, -0.2), right(0.25, -0.21);
  const double m_l = FlatPortRefraction::RadialFactor(n, left.squaredNorm());
  const double m_r = FlatPortRefraction::RadialFactor(n, right.squaredNorm());
  EXPECT_NEAR(CoplanarityResidual(essential, n, left.data(), right.data()),
              right.y() * m_l - left.y() * m_r, 1e-15);
}

TEST(Epipolar, EssentialMatrixHasUnitTranslation) {
  const StereoRig rig = test::AlphasenseRealisticRig();
  const Eigen::Matrix3d essential = EssentialMatrix(rig.right_from_left());
  // E^T E has eigenvalues 0, |t|^2, |t|^2 = 0, 1, 1: trace 2.
  EXPECT_NEAR((essential.transpose() * essential).trace(), 2.0, 1e-14);
  // t^T E = 0.
  EXPECT_LT((rig.right_from_left().translation.transpose() * essential).norm(),
            1e-15);
}

}  // namespace
}  // namespace rcm::epipolar_test
