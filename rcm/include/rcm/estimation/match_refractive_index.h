// The refractive index one correspondence asks for: the n in [1, 2] at
// which it lies exactly on its refractive epipolar locus, i.e. the root of
// its Sampson coplanarity residual (sampson_coplanarity_error.h)
//
//   r_i(n) = b_r(n)^T E b_l(n) / |grad r|    = 0.
//
// On the ideal rectified rig this is the paper's per-feature closed form
// (eq. 14); the root exists for any calibrated rig. It is what the paper's
// Fig. 6b colors each feature by: noisy per match (a 0.1 px error moves it
// by ~0.01 at the image border and without bound near the image axes,
// where r_i hardly depends on n), informative in the aggregate, and a
// quick look at where in the image the data observe n.
//
// Method: r_i is sampled at kSamples points of [1, 2]; the first sign
// change is bracketed and bisected to 1e-9.
#ifndef RCM_ESTIMATION_MATCH_REFRACTIVE_INDEX_H_
#define RCM_ESTIMATION_MATCH_REFRACTIVE_INDEX_H_

#include <Eigen/Core>
#include <optional>

#include "rcm/estimation/prepared_correspondence.h"

namespace rcm {

// nullopt when r_i has no sign change in [1, 2] (no n explains the match,
// or it does not observe n) or cannot be evaluated.
std::optional<double> RefractiveIndexOfMatch(
    const Eigen::Matrix3d& essential, const PreparedCorrespondence& match);

}  // namespace rcm

#endif  // RCM_ESTIMATION_MATCH_REFRACTIVE_INDEX_H_
