// The back-trace of the exact flat port (flat_port.h) as a function
// templated on the scalar, so that Ceres differentiates a pixel's ray in
// the medium with respect to n and the port's dimensions (the thick-port
// residual, generalized_epipolar_error.h). Same physics as
// ExactFlatPort::RayFromNormalized, written for Jets; the tests hold the
// two together to 1e-12.
//
// With N the unit port normal (N_z > 0), d the air gap, tg the glass
// thickness, n_g the glass index and n the medium's index, a ray leaving
// the camera center along v0 = (xb, yb, 1) / |(xb, yb, 1)|:
//
//   p1 = v0 d / (N . v0)                 meets the inner glass face
//   v1 = refract(v0, N, 1 / n_g)         into the glass
//   p2 = p1 + v1 tg / (N . v1)           meets the outer glass face
//   v2 = refract(v1, N, n_g / n)         into the medium
//
// origin p2, unit direction v2, where for a unit v, c = N . v > 0 and
// eta = n_from / n_to (vector Snell's law):
//
//   refract(v, N, eta) = eta v + (sqrt(1 - eta^2 (1 - c^2)) - eta c) N.
//
// Going outward (n, n_g >= 1) there is no total internal reflection: the
// invariant n_k sin(theta_k) = sin(theta_air) <= 1 holds in every layer.
// With d = tg = 0 and N = z it is the paper's thin port: origin 0 and
// direction (xb, yb, m(n, rb)) / |.| (refractive_model.h).
#ifndef RCM_CAMERA_THICK_PORT_REFRACTION_H_
#define RCM_CAMERA_THICK_PORT_REFRACTION_H_

#include <Eigen/Core>
#include <cmath>

#include "rcm/camera/flat_port_geometry.h"
#include "rcm/util/scalar.h"

namespace rcm {

struct ThickPortRefraction {
  // Vector Snell's law for a unit `v`; false when the ray does not cross
  // the face forward (c <= 0) or is totally reflected.
  template <typename T>
  static bool Refract(const T v[3], const Eigen::Vector3d& normal,
                      const T& eta, T refracted[3]) {
    using std::sqrt;
    const T c = T(normal.x()) * v[0] + T(normal.y()) * v[1] +
                T(normal.z()) * v[2];
    if (!(ScalarPart(c) > 0.0)) return false;
    const T root = T(1.0) - eta * eta * (T(1.0) - c * c);
    if (!(ScalarPart(root) >= 0.0)) return false;
    const T along_normal = sqrt(root) - eta * c;
    for (int i = 0; i < 3; ++i) {
      refracted[i] = eta * v[i] + along_normal * T(normal[i]);
    }
    return true;
  }

  // The ray in the medium of the lens-undistorted normalized point
  // (xb, yb): `origin` on the outer glass face, unit `direction`.
  // `normal` is the port's unit normal. False when the ray in air does not
  // reach the glass (N . v0 <= 0), and for an air gap outside
  // [0, FlatPort::kMaxAirGap] (an estimated gap can be stepped there; a
  // huge one overflows the ray's origin).
  template <typename T>
  static bool RayInMedium(const T& n, const T& air_gap,
                          const T& glass_thickness, const T& glass_index,
                          const Eigen::Vector3d& normal, const T& xb,
                          const T& yb, T origin[3], T direction[3]) {
    using std::sqrt;
    if (!(ScalarPart(air_gap) >= 0.0 &&
          ScalarPart(air_gap) <= FlatPort::kMaxAirGap)) {
      return false;
    }
    const T length = sqrt(xb * xb + yb * yb + T(1.0));
    const T v0[3] = {xb / length, yb / length, T(1.0) / length};
    const T c0 = T(normal.x()) * v0[0] + T(normal.y()) * v0[1] +
                 T(normal.z()) * v0[2];
    if (!(ScalarPart(c0) > 0.0)) return false;
    T v1[3];
    if (!Refract(v0, normal, T(1.0) / glass_index, v1)) return false;
    const T c1 = T(normal.x()) * v1[0] + T(normal.y()) * v1[1] +
                 T(normal.z()) * v1[2];
    if (!Refract(v1, normal, glass_index / n, direction)) return false;
    for (int i = 0; i < 3; ++i) {
      origin[i] = v0[i] * (air_gap / c0) + v1[i] * (glass_thickness / c1);
    }
    return true;
  }
};

}  // namespace rcm

#endif  // RCM_CAMERA_THICK_PORT_REFRACTION_H_
