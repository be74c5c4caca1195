#include "rcm/estimation/match_refractive_index.h"

#include <cmath>

#include "rcm/camera/refractive_camera.h"
#include "rcm/estimation/sampson_coplanarity_error.h"

namespace rcm {
namespace {

// Samples of [1, 2] that bracket the root; the residual is smooth and has
// at most one root in the interval for matches that observe n.
constexpr int kSamples = 11;
constexpr double kTolerance = 1e-9;

std::optional<double> Residual(const Eigen::Matrix3d& essential,
                               const PreparedCorrespondence& match, double n) {
  double residual = 0.0;
  if (!SampsonCoplanarityResidual<double>(essential, match, n, nullptr,
                                          &residual) ||
      !std::isfinite(residual)) {
    return std::nullopt;
  }
  return residual;
}

}  // namespace

std::optional<double> RefractiveIndexOfMatch(
    const Eigen::Matrix3d& essential, const PreparedCorrespondence& match) {
  constexpr double kLow = RefractiveCamera::kMinIndex;
  constexpr double kHigh = RefractiveCamera::kMaxIndex;
  double a = kLow;
  std::optional<double> ra = Residual(essential, match, a);
  if (!ra) return std::nullopt;
  if (*ra == 0.0) return a;
  for (int k = 1; k < kSamples; ++k) {
    const double b = kLow + (kHigh - kLow) * k / (kSamples - 1);
    const std::optional<double> rb = Residual(essential, match, b);
    if (!rb) return std::nullopt;
    if (*rb == 0.0) return b;
    if ((*ra < 0.0) != (*rb < 0.0)) {
      double lo = a, hi = b, r_lo = *ra;
      while (hi - lo > kTolerance) {
        const double mid = 0.5 * (lo + hi);
        const std::optional<double> r_mid = Residual(essential, match, mid);
        if (!r_mid) return std::nullopt;
        if ((*r_mid < 0.0) == (r_lo < 0.0)) {
          lo = mid;
          r_lo = *r_mid;
        } else {
          hi = mid;
        }
      }
      return 0.5 * (lo + hi);
    }
    a = b;
    ra = rb;
  }
  return std::nullopt;
}

}  // namespace rcm
