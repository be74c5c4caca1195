#include "rcm/estimation/sampson_residual_batch.h"

#include <ceres/jet.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "rcm/estimation/locus_cost_function.h"
#include "rcm/estimation/prepared_correspondence.h"
#include "rcm/estimation/sampson_coplanarity_error.h"
#include "rcm/sim/stereo_sampler.h"
#include "rcm/stereo/epipolar.h"
#include "support/test_rigs.h"

namespace rcm::sampson_residual_batch_test {
namespace {

using Jet = ceres::Jet<double, 1>;

// The batch regroups the Jet form's sums (header); each is a sum of a few
// products of terms of size |e| and |de/dp|, rounded at 1.1e-16 relative,
// so the two differ by a few ulps of the largest term, not of the result.
// Measured worst: ~1e-15 px of r, ~1e-13 px per unit n of dr/dn; scaled by
// the size of the gradient (r = e / |de/dp| is in pixels, as large as the
// match is off its locus) the bar is 1e-12 relative plus 1e-12 px.
constexpr double kRelativeTolerance = 1e-12;
constexpr double kAbsoluteTolerancePx = 1e-12;

// Every node of the locus cost function, and n at 1, just above it and at 2.
std::vector<double> TestIndices() {
  const auto& nodes = LocusCostFunction::Nodes();
  std::vector<double> n(nodes.begin(), nodes.end());
  for (const double extra : {1.0 + 1e-15, 1.0 + 1e-12, 1.333, 1.5}) {
    n.push_back(extra);
  }
  return n;
}

// The worst error of the batch against SampsonCoplanarityResidual<Jet>,
// in units of the tolerance (<= 1 passes), over every test index.
double WorstAgainstJet(const Eigen::Matrix3d& essential,
                       const std::vector<PreparedCorrespondence>& matches) {
  const SampsonResidualBatch batch(essential, matches);
  EXPECT_EQ(batch.size(), static_cast<int64_t>(matches.size()));
  SampsonResidualBatch::Workspace workspace;
  Eigen::ArrayXd r, dr;
  double worst = 0.0;
  for (const double n : TestIndices()) {
    batch.Evaluate(n, &workspace, &r, &dr);
    for (size_t i = 0; i < matches.size(); ++i) {
      Jet reference;
      if (!SampsonCoplanarityResidual<Jet>(essential, matches[i], Jet(n, 0),
                                           nullptr, &reference)) {
        ADD_FAILURE() << "match " << i << " undefined at n = " << n;
        continue;
      }
      const double r_scale =
          kAbsoluteTolerancePx + kRelativeTolerance * std::abs(reference.a);
      const double dr_scale =
          kAbsoluteTolerancePx + kRelativeTolerance * std::abs(reference.v[0]);
      worst = std::max({worst, std::abs(r[i] - reference.a) / r_scale,
                        std::abs(dr[i] - reference.v[0]) / dr_scale});
    }
  }
  return worst;
}

TEST(SampsonResidualBatch, MatchesTheJetFormOnDatasetRig) {
  const StereoRig rig = test::AlphasenseRealisticRig();
  const double worst =
      WorstAgainstJet(EssentialMatrix(rig.right_from_left()),
                      test::NoisyPreparedMatches(rig, 1.333, 300, 0.5, 3));
  std::printf("worst error against the Jet form: %.3g of the tolerance\n",
              worst);
  EXPECT_LE(worst, 1.0);
}

TEST(SampsonResidualBatch, MatchesTheJetFormOnEveryTestCamera) {
  // Radtan, pinhole, a fisheye to 89.5 degrees, rational, double sphere,
  // EUCM: rays near grazing, where m's derivatives are largest.
  for (const Camera& camera : test::AllTestCameras()) {
    const StereoRig rig = test::IdealRig(camera, camera, 0.2);
    const double worst =
        WorstAgainstJet(EssentialMatrix(rig.right_from_left()),
                        test::NoisyPreparedMatches(rig, 1.1, 200, 0.5, 5));
    EXPECT_LE(worst, 1.0) << camera.width() << "x" << camera.height();
  }
}

TEST(SampsonResidualBatch, ExactMatchesHaveZeroResidualAtTheirIndex) {
  const StereoRig rig = test::AlphasenseRealisticRig();
  const std::vector<PreparedCorrespondence> matches =
      PrepareCorrespondences(rig, test::ExactMatches(rig, 1.333, 200, 9))
          .prepared;
  const SampsonResidualBatch batch(EssentialMatrix(rig.right_from_left()),
                                   matches);
  SampsonResidualBatch::Workspace workspace;
  Eigen::ArrayXd r, dr;
  batch.Evaluate(1.333, &workspace, &r, &dr);
  // The undistortion's 1e-14 in normalized coordinates, times f ~ 350 px.
  EXPECT_LT(r.abs().maxCoeff(), 1e-9);
  EXPECT_GT(dr.abs().maxCoeff(), 0.0);
}

TEST(SampsonResidualBatch, EmptyAndUndefinedMatches) {
  const StereoRig rig = test::AlphasenseIdealRig();
  const Eigen::Matrix3d essential = EssentialMatrix(rig.right_from_left());
  const SampsonResidualBatch empty(essential, {});
  SampsonResidualBatch::Workspace workspace;
  Eigen::ArrayXd r, dr;
  empty.Evaluate(1.2, &workspace, &r, &dr);
  EXPECT_EQ(r.size(), 0);
  // A match whose gradient vanishes: both pixels at the ideal rig's epipole
  // direction with zero lens Jacobians. The Jet form fails; the batch gives
  // a value that is not finite.
  PreparedCorrespondence degenerate;
  const SampsonResidualBatch batch(essential, {degenerate});
  Jet reference;
  EXPECT_FALSE(SampsonCoplanarityResidual<Jet>(
      essential, degenerate, Jet(1.2, 0), nullptr, &reference));
  batch.Evaluate(1.2, &workspace, &r, &dr);
  ASSERT_EQ(r.size(), 1);
  EXPECT_FALSE(std::isfinite(r[0]) && std::isfinite(dr[0]));
}

}  // namespace
}  // namespace rcm::sampson_residual_batch_test
