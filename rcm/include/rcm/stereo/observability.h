// How well one correspondence observes n (paper Sec. III-D).
//
// Tangent angle. Every locus of eq. 16 passes through (xl, yl) (the match
// of a point at infinity). Differentiating h = 0 there gives its slope
//
//   dyr/dxr = (n^2 - 1) xl yl / ((n^2 - 1) xl^2 + n^2),
//
// so the tangent makes the angle phi(n) = atan2((n^2 - 1) xl yl,
// (n^2 - 1) xl^2 + n^2) with the x axis. The paper's beta is the angle
// between the tangents of the loci for n0 - dn and n0 + dn:
// beta = |phi(n0 + dn) - phi(n0 - dn)|. It vanishes on both image axes
// (xl = 0 or yl = 0), where n is unobservable; hence the paper's mask.
//
// First-order sigma. For pixel noise of standard deviation sigma_px on each
// of the four pixel coordinates p = (ul, vl, ur, vr), the n that solves
// the coplanarity e(n, p) = 0 (epipolar.h) varies, to first order, as
// dn = -(de/dp) dp / (de/dn) (implicit function theorem), so
//
//   sigma_n = sigma_px |de/dp| / |de/dn|,
//
// with de/dp chained through the lens undistortion. On the ideal rig this
// is the first-order spread of the closed form (eq. 14) of that match.
#ifndef RCM_STEREO_OBSERVABILITY_H_
#define RCM_STEREO_OBSERVABILITY_H_

#include <cmath>
#include <optional>

#include "rcm/geometry/stereo_correspondence.h"
#include "rcm/stereo/stereo_rig.h"

namespace rcm {

// phi(n) above, in radians.
template <typename T>
T LocusTangentAngle(const T& n, const T& xl, const T& yl) {
  using std::atan2;
  const T excess = n * n - T(1.0);
  return atan2(excess * xl * yl, excess * xl * xl + n * n);
}

// beta above, in radians; dn > 0.
double LocusTangentSeparation(double n0, double dn, double xl, double yl);

// sigma_n above for the correspondence at refractive index n. nullopt when
// a pixel cannot be undistorted, de/dn vanishes (n unobservable from this
// correspondence) or sigma_px is negative or not finite.
std::optional<double> FirstOrderSigmaN(const StereoRig& rig,
                                       const StereoCorrespondence& match,
                                       double n, double sigma_px);

}  // namespace rcm

#endif  // RCM_STEREO_OBSERVABILITY_H_
