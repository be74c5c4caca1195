// Closed-form refractive index of one correspondence of an ideal rectified
// pair (R = I, t = [tx, 0, 0]), paper eq. 14:
//
//   n^2 = (yl^2 rr^2 - rl^2 yr^2) / (yl^2 rr^2 + yl^2 - rl^2 yr^2 - yr^2)
//
// in lens-undistorted normalized coordinates of each camera. Since
// yl^2 rr^2 - rl^2 yr^2 = yl^2 xr^2 - xl^2 yr^2, this is evaluated as
//
//   a = (yl xr - xl yr)(yl xr + xl yr),   n^2 = a / (a + (yl - yr)(yl + yr)),
//
// the same value with less cancellation. It is exact on exact data, but ill
// conditioned near the image axes and for distant points (a -> 0 and
// yl -> yr), so noisy data give heavy tails and undefined values: it is a
// seed and the paper's baseline, not the estimator of record
// (docs/design.md, "The estimator of record").
#ifndef RCM_ESTIMATION_CLOSED_FORM_H_
#define RCM_ESTIMATION_CLOSED_FORM_H_

#include <optional>

#include "rcm/geometry/stereo_correspondence.h"

namespace rcm {

// n^2 of eq. 14; may be negative, infinite or NaN on noisy data.
template <typename T>
T ClosedFormNSquared(const T& xl, const T& yl, const T& xr, const T& yr) {
  const T a = (yl * xr - xl * yr) * (yl * xr + xl * yr);
  return a / (a + (yl - yr) * (yl + yr));
}

// n of eq. 14; nullopt when n^2 is not a positive finite number.
std::optional<double> ClosedFormN(const NormalizedCorrespondence& match);

}  // namespace rcm

#endif  // RCM_ESTIMATION_CLOSED_FORM_H_
