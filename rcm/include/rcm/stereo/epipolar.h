// Epipolar geometry of a refractive stereo pair (paper Sec. III-B).
//
// With the virtual pinholes K_n of both cameras, the fundamental matrix is
// F = K_r^-T [t]x R K_l^-1 (eq. 11) and, by eq. 10, the epipolar
// constraint on the lens-undistorted normalized coordinates is
//
//   e(n) = b_r(n)^T E b_l(n) = 0,   E = [t]x R,   b = (xb, yb, m(n, rb)),
//
// with (R, t) = right_from_left. Unlike the paper's rectified derivation it
// needs no rectification, so each port normal stays on its optical axis.
// For the ideal pair (R = I, t = [tx, 0, 0]) it reduces to eq. 13:
// yl m_r - yr m_l = 0.
#ifndef RCM_STEREO_EPIPOLAR_H_
#define RCM_STEREO_EPIPOLAR_H_

#include <Eigen/Core>

#include "rcm/camera/refractive_model.h"
#include "rcm/geometry/rigid3d.h"

namespace rcm {

// E = [t / |t|]x R for (R, t) = right_from_left; unit translation so that
// residuals do not scale with the baseline. CHECK-fails on a zero baseline
// (StereoRig::Create rejects those).
Eigen::Matrix3d EssentialMatrix(const Rigid3d& right_from_left);

// e(n) above for one correspondence (left/right normalized coordinates).
template <typename T>
T CoplanarityResidual(const Eigen::Matrix3d& essential, const T& n,
                      const T* left_normalized, const T* right_normalized) {
  T left[3], right[3];
  FlatPortRefraction::BearingInWater(n, left_normalized[0], left_normalized[1],
                                     left);
  FlatPortRefraction::BearingInWater(n, right_normalized[0],
                                     right_normalized[1], right);
  T residual(0.0);
  for (int i = 0; i < 3; ++i) {
    const T row = T(essential(i, 0)) * left[0] + T(essential(i, 1)) * left[1] +
                  T(essential(i, 2)) * left[2];
    residual += right[i] * row;
  }
  return residual;
}

}  // namespace rcm

#endif  // RCM_STEREO_EPIPOLAR_H_
