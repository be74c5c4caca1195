#include "rcm/stereo/observability.h"

#include <ceres/jet.h>

#include "rcm/stereo/epipolar.h"

namespace rcm {

double LocusTangentSeparation(double n0, double dn, double xl, double yl) {
  return std::abs(LocusTangentAngle(n0 + dn, xl, yl) -
                  LocusTangentAngle(n0 - dn, xl, yl));
}

std::optional<double> FirstOrderSigmaN(const StereoRig& rig,
                                       const StereoCorrespondence& match,
                                       double n, double sigma_px) {
  if (!std::isfinite(sigma_px) || !(sigma_px >= 0.0)) return std::nullopt;
  // Derivative slots: 0 = n, 1..2 = left pixel, 3..4 = right pixel.
  using Jet = ceres::Jet<double, 5>;
  const Jet n_jet(n, 0);
  const Jet left_pixel[2] = {Jet(match.left_pixel.x(), 1),
                             Jet(match.left_pixel.y(), 2)};
  const Jet right_pixel[2] = {Jet(match.right_pixel.x(), 3),
                              Jet(match.right_pixel.y(), 4)};
  Jet left[2], right[2];
  if (!rig.left().NormalizedFromImage(left_pixel, left) ||
      !rig.right().NormalizedFromImage(right_pixel, right)) {
    return std::nullopt;
  }
  const Jet residual = CoplanarityResidual(
      EssentialMatrix(rig.right_from_left()), n_jet, left, right);
  const double de_dn = residual.v[0];
  const double de_dp = residual.v.tail<4>().norm();
  if (!(std::abs(de_dn) > 0.0) || !std::isfinite(de_dp)) return std::nullopt;
  const double sigma = sigma_px * de_dp / std::abs(de_dn);
  if (!std::isfinite(sigma)) return std::nullopt;
  return sigma;
}

}  // namespace rcm
