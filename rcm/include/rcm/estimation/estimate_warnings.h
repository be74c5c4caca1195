// What an estimate's uncertainty says of the calibration and the data, in
// one line each: the policy `rcm estimate`, Python, the demo and the node
// share (the sequence engine fills RefractiveIndexEstimate::warnings).
//
//   stale calibration   the self-calibrated rotation r of cam1 lies
//                       sqrt(r^T P^-1 r) > 3 prior sigmas out (P the drift
//                       prior's covariance; 3: a 0.3 % tail in one axis)
//   hardly separable    a free rotation correlates with n at R > 0.95
//                       (sigma_n more than 3.2x its value with it known)
//   the lenses          sigma_n > 0.007 (fresh and sea water less than one
//                       sigma apart) and the focal drift prior's share
//                       is more than half of sigma_n^2
//   systematic field    the residuals' test found a smooth field (p < 1 %)
//   frames disagree     the frames' chi^2 inflated the noise share
#ifndef RCM_ESTIMATION_ESTIMATE_WARNINGS_H_
#define RCM_ESTIMATION_ESTIMATE_WARNINGS_H_

#include <string>
#include <vector>

#include "rcm/estimation/refractive_index_estimate.h"

namespace rcm {

// Beyond this many prior sigmas the self-calibrated rotation says the
// camchain is stale.
inline constexpr double kStaleRotationSigmas = 3.0;
// Above this multiple correlation a free rotation is hardly separable from
// n.
inline constexpr double kHardlySeparableCorrelation = 0.95;
// A sigma_n above this tells fresh from sea water at less than one sigma
// (their indices differ by 0.007).
inline constexpr double kWideSigmaN = 0.007;

// The warnings of `estimate`, in the order above (empty: nothing to say).
std::vector<std::string> EstimateWarnings(
    const RefractiveIndexEstimate& estimate);

}  // namespace rcm

#endif  // RCM_ESTIMATION_ESTIMATE_WARNINGS_H_
