#include "rcm/estimation/cramer_rao_bound.h"

#include <ceres/jet.h>

#include <cmath>

#include "rcm/estimation/sampson_coplanarity_error.h"
#include "rcm/stereo/epipolar.h"

namespace rcm {

double LocusInformation(const Eigen::Matrix3d& essential,
                        const std::vector<PreparedCorrespondence>& matches,
                        double n) {
  using Jet = ceres::Jet<double, 1>;
  const Jet n_jet(n, 0);
  double information = 0.0;
  for (const PreparedCorrespondence& match : matches) {
    Jet residual;
    if (SampsonCoplanarityResidual<Jet>(essential, match, n_jet, nullptr,
                                        &residual) &&
        std::isfinite(residual.v[0])) {
      information += residual.v[0] * residual.v[0];
    }
  }
  return information;
}

std::optional<double> CramerRaoBoundN(
    const StereoRig& rig,
    const std::vector<StereoCorrespondence>& correspondences, double n,
    double sigma_px) {
  const PreparedCorrespondences prepared =
      PrepareCorrespondences(rig, correspondences);
  const double information = LocusInformation(
      EssentialMatrix(rig.right_from_left()), prepared.prepared, n);
  if (!(information > 0.0)) return std::nullopt;
  return sigma_px / std::sqrt(information);
}

}  // namespace rcm
