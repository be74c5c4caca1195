// The refractive camera model of the paper (Sec. III-A, eqs. 1-10): a
// camera behind a thin flat port whose normal is the optical axis, the port
// and the lens center at negligible distance.
//
// Notation (docs/design.md, "The refractive model"): (xb, yb) are the
// lens-undistorted normalized coordinates of a pixel, i.e. the tangent of
// the ray in air, rb^2 = xb^2 + yb^2 = tan^2(theta_a); theta_w is the
// angle of the same ray in the medium of refractive index n.
//
//   Snell (eq. 1):         sin(theta_a) = n sin(theta_w)
//   Radial factor (eq. 5): m(n, rb) = tan(theta_a) / tan(theta_w)
//                                   = sqrt(n^2 rb^2 + n^2 - rb^2)
//                          evaluated here as sqrt(n^2 + (n^2 - 1) rb^2),
//                          which is exactly 1 at n = 1.
//   Unprojection:          bearing in the medium ~ (xb, yb, m(n, rb))
//   Projection of P = (X, Y, Z) in the medium, R^2 = (X^2 + Y^2) / Z^2:
//                          rb = n R / sqrt(1 + R^2 - n^2 R^2), so
//                          (xb, yb) = n (X, Y) / sqrt(Z^2 - (n^2 - 1)(X^2 +
//                          Y^2)) valid for Z > 0 and below the critical angle,
//                          (n^2 - 1)(X^2 + Y^2) < Z^2 (otherwise no ray in
//                          air reaches the camera: total internal reflection).
//   Virtual pinhole (eqs. 9, 10): K_n = diag(n fx, n fy, 1) images the medium
//                          as an ideal pinhole: u = n fx X/Z + cx, and
//                          [u, v, 1] ~ [x, y, m/n] (eq. 10).
//
// At n = 1 every function here is the plain pinhole camera.
//
// All functions are templated on the scalar (double or ceres::Jet) and do
// not check n; callers validate n (RefractiveCamera::Create takes [1, 2]).
#ifndef RCM_CAMERA_REFRACTIVE_MODEL_H_
#define RCM_CAMERA_REFRACTIVE_MODEL_H_

#include <cmath>

#include "rcm/util/scalar.h"

namespace rcm {

struct FlatPortRefraction {
  // m(n, rb) of eq. 5 from rb^2 (no square root of rb needed, so the
  // derivative is finite on the optical axis).
  template <typename T>
  static T RadialFactor(const T& n, const T& rb_squared) {
    using std::sqrt;
    const T n2 = n * n;
    return sqrt(n2 + (n2 - T(1.0)) * rb_squared);
  }

  // Bearing of a lens-undistorted normalized point in the medium, not unit
  // length: (xb, yb, m(n, rb)). Its direction makes the angle theta_w of
  // eq. 1 with the optical axis. Exists for every point of the image plane.
  template <typename T>
  static void BearingInWater(const T& n, const T& xb, const T& yb, T* bearing) {
    bearing[0] = xb;
    bearing[1] = yb;
    bearing[2] = RadialFactor(n, xb * xb + yb * yb);
  }

  // Lens-undistorted normalized point (xb, yb) of a point in the medium
  // given in the camera frame. False behind the camera (Z <= 0) and at or
  // past the critical angle (total internal reflection).
  template <typename T>
  static bool NormalizedFromPointInWater(const T& n, const T* point, T* xb,
                                         T* yb) {
    using std::sqrt;
    const T& x = point[0];
    const T& y = point[1];
    const T& z = point[2];
    if (!(ScalarPart(z) > 0.0)) return false;
    const T squared_denominator = z * z - (n * n - T(1.0)) * (x * x + y * y);
    if (!(ScalarPart(squared_denominator) > 0.0)) return false;
    const T scale = n / sqrt(squared_denominator);
    *xb = scale * x;
    *yb = scale * y;
    return true;
  }

  // Virtual pinhole coordinates (u, v) / (fx, fy) - (cx, cy) of eq. 10 of a
  // lens-undistorted normalized point: (n xb / m, n yb / m), which is
  // n (X/Z, Y/Z) of the point in the medium.
  template <typename T>
  static void VirtualFromNormalized(const T& n, const T& xb, const T& yb, T* xv,
                                    T* yv) {
    const T scale = n / RadialFactor(n, xb * xb + yb * yb);
    *xv = scale * xb;
    *yv = scale * yb;
  }

  // Inverse of VirtualFromNormalized: the point (xv, yv) of the virtual
  // pinhole is the ray (xv, yv, n) in the medium. False past the critical
  // angle (the virtual image extends beyond what the camera can see).
  template <typename T>
  static bool NormalizedFromVirtual(const T& n, const T& xv, const T& yv, T* xb,
                                    T* yb) {
    const T ray[3] = {xv, yv, n};
    return NormalizedFromPointInWater(n, ray, xb, yb);
  }
};

}  // namespace rcm

#endif  // RCM_CAMERA_REFRACTIVE_MODEL_H_
