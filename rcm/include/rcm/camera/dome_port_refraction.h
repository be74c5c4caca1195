// Exact ray tracing through a dome port (dome_port_geometry.h), templated
// on the scalar so that Ceres differentiates a pixel's ray in the medium,
// or a point's image, with respect to the medium's index n, the dome's
// decentering C and the point: the residual of the underwater calibration
// through a dome (rcm/calib/dome_calibration.h).
//
// Back-trace (normalized point in air -> ray in the medium). The ray
// leaves the camera centre along v0 = (xb, yb, 1) / |(xb, yb, 1)|. With
// r1, r2 = r1 + tg the inner and outer radii, n_g the glass index:
//
//   p1 = t1 v0,  t1 = b + sqrt(b^2 + r1^2 - |C|^2),  b = v0 . C
//                                       meets the inner sphere
//   N1 = (p1 - C) / r1,  v1 = refract(v0, N1, 1 / n_g)
//   p2 = p1 + t2 v1,  t2 = -r1 c1 + sqrt(r1^2 c1^2 + r2^2 - r1^2),
//        c1 = N1 . v1                   meets the outer sphere
//   N2 = (p2 - C) / r2,  v2 = refract(v1, N2, n_g / n)
//
// origin p2, unit direction v2, with Snell's law in vector form for a
// unit v and the unit normal N along the propagation (c = N . v > 0),
// eta = n_from / n_to:
//
//   refract(v, N, eta) = eta v + (sqrt(1 - eta^2 (1 - c^2)) - eta c) N.
//
// Inside the inner sphere (|C| < r1) the root of t1 is real and every
// ray meets the glass going outwards (c > 0). Into the glass there is no
// total internal reflection; out of it there is when n < n_g and the ray
// meets the outer surface beyond the critical angle, which a dome
// decentered by a fraction of its radius does not reach (the trace
// reports it). For C = 0 every normal is along the ray: no bending, the
// ray leaves the camera centre (the air camera). For tg = 0 the two
// refractions at one surface compose to refract(v0, N1, 1 / n).
//
// Forward projection (point P in the medium -> normalized point). The
// dome is not a central camera: the unknown is the ray in air whose traced
// ray passes through P, parametrized in the tangent plane of the start
// d0 = (P - C) / |P - C| (the ray of a centred dome) by x = (a, b):
//
//   v0(x) = (d0 + a t1 + b t2) / |d0 + a t1 + b t2|,
//
// t1, t2 orthonormal to d0 (well conditioned at any angle from the
// optical axis, beyond 90 degrees too). Its residual is the difference
// between the traced ray's direction and the direction from its origin to
// P,
//
//   e(x) = v2 - (P - p2) / |P - p2|,
//
// zero only when P lies on the ray ahead of its origin (P's perpendicular
// offset from the ray also vanishes behind the origin, where a solve once
// converged). Gauss-Newton in double from x = 0, with the 3x2 Jacobian
// J = de/dx from ceres::Jet<double, 2> and steps of at most 0.5,
// converges quadratically (a zero-residual problem). Derivatives as in
// flat_port_projection.h: ONE Gauss-Newton step in the scalar type T from
// the converged x,
//
//   x_T = x - (J^T J)^-1 J^T e_T(x),
//
// leaves the value where it was (e(x) is zero to rounding) and gives a Jet
// the implicit-function derivatives dx/dtheta = -(J^T J)^-1 J^T de/dtheta
// for every input theta in (n, C, P): e(x(theta), theta) = 0 puts
// de/dtheta in J's range (d0, t1, t2 are constants, taken from the double
// values). The normalized point is (v0_x / v0_z, v0_y / v0_z), v0_z > 0.
#ifndef RCM_CAMERA_DOME_PORT_REFRACTION_H_
#define RCM_CAMERA_DOME_PORT_REFRACTION_H_

#include <Eigen/Core>
#include <Eigen/LU>
#include <cmath>
#include <limits>
#include <type_traits>

#include "rcm/camera/dome_port_geometry.h"
#include "rcm/util/scalar.h"

namespace rcm {

struct DomePortRefraction {
  // Gauss-Newton iterations of the double solve: 2-4 to machine
  // precision for decenterings of millimetres, more when a ray passes
  // near the critical angle; beyond, the projection fails.
  static constexpr int kMaxIterations = 50;
  // The relative step at which the solve has converged (see below), and
  // the largest step, in the tangent plane of the start (~radians).
  static constexpr double kStepTolerance = 1e-12;
  static constexpr double kMaxStep = 0.5;

  // Vector Snell's law for a unit `v` and unit `normal`; false when the
  // ray does not cross the surface forward (c <= 0) or is totally
  // reflected.
  template <typename T>
  static bool Refract(const T v[3], const T normal[3], const T& eta,
                      T refracted[3]) {
    using std::sqrt;
    const T c = normal[0] * v[0] + normal[1] * v[1] + normal[2] * v[2];
    if (!(ScalarPart(c) > 0.0)) return false;
    const T root = T(1.0) - eta * eta * (T(1.0) - c * c);
    if (!(ScalarPart(root) >= 0.0)) return false;
    const T along_normal = sqrt(root) - eta * c;
    for (int i = 0; i < 3; ++i) {
      refracted[i] = eta * v[i] + along_normal * normal[i];
    }
    return true;
  }

  // The ray in the medium of the lens-undistorted normalized point
  // (xb, yb): `origin` on the outer glass surface, unit `direction`.
  // `dome` gives r1, tg and n_g (its decentering is not read: C is
  // `centre`, so that it can be estimated). False when the camera centre
  // is not inside the inner sphere (|C| >= r1) or the ray is totally
  // reflected out of the glass.
  template <typename T>
  static bool RayInMedium(const T& n, const T centre[3], const DomePort& dome,
                          const T& xb, const T& yb, T origin[3],
                          T direction[3]) {
    using std::sqrt;
    const T length = sqrt(xb * xb + yb * yb + T(1.0));
    const T v0[3] = {xb / length, yb / length, T(1.0) / length};
    return RayInMediumFromAir(n, centre, dome, v0, origin, direction);
  }

  // The same for the unit direction v0 of the ray in air (any direction:
  // a dome sees beyond 90 degrees).
  template <typename T>
  static bool RayInMediumFromAir(const T& n, const T centre[3],
                                 const DomePort& dome, const T v0[3],
                                 T origin[3], T direction[3]) {
    using std::sqrt;
    const T r1(dome.inner_radius);
    const T r2(dome.outer_radius());
    const T b = v0[0] * centre[0] + v0[1] * centre[1] + v0[2] * centre[2];
    const T centre_squared =
        centre[0] * centre[0] + centre[1] * centre[1] + centre[2] * centre[2];
    const T inside = r1 * r1 - centre_squared;
    if (!(ScalarPart(inside) > 0.0)) return false;
    const T t1 = b + sqrt(b * b + inside);
    T p1[3], normal1[3];
    for (int i = 0; i < 3; ++i) {
      p1[i] = t1 * v0[i];
      normal1[i] = (p1[i] - centre[i]) / r1;
    }
    T v1[3];
    if (!Refract(v0, normal1, T(1.0 / dome.glass_index), v1)) return false;
    const T c1 = normal1[0] * v1[0] + normal1[1] * v1[1] + normal1[2] * v1[2];
    const T t2 = -r1 * c1 + sqrt(r1 * r1 * c1 * c1 + r2 * r2 - r1 * r1);
    T normal2[3];
    for (int i = 0; i < 3; ++i) {
      origin[i] = p1[i] + t2 * v1[i];
      normal2[i] = (origin[i] - centre[i]) / r2;
    }
    return Refract(v1, normal2, T(dome.glass_index) / n, direction);
  }

  // e(x) of the header: the ray's direction less the unit direction from
  // its origin to `point`.
  //   v0(a, b) = (d0 + a t1 + b t2) / |.|,
  // the ray in air in the tangent plane of the unit direction d0 (the
  // start) with the orthonormal t1, t2 (`frame` = [d0 t1 t2]).
  template <typename T, typename X>
  static bool Offset(const T& n, const T centre[3], const DomePort& dome,
                     const T point[3], const Eigen::Matrix3d& frame, const X& a,
                     const X& b, X offset[3]) {
    using std::sqrt;
    // The ray's scalar is X (the unknowns'), which carries T's or the
    // unknowns' derivatives.
    X v0[3];
    for (int i = 0; i < 3; ++i) {
      v0[i] = X(frame(i, 0)) + a * frame(i, 1) + b * frame(i, 2);
    }
    const X length = sqrt(v0[0] * v0[0] + v0[1] * v0[1] + v0[2] * v0[2]);
    for (int i = 0; i < 3; ++i) v0[i] = v0[i] / length;
    X origin[3], direction[3];
    const X n_x = Promote<X>(n);
    const X centre_x[3] = {Promote<X>(centre[0]), Promote<X>(centre[1]),
                           Promote<X>(centre[2])};
    if (!RayInMediumFromAir(n_x, centre_x, dome, v0, origin, direction)) {
      return false;
    }
    using std::sqrt;
    X to_point[3];
    for (int i = 0; i < 3; ++i) to_point[i] = Promote<X>(point[i]) - origin[i];
    const X distance =
        sqrt(to_point[0] * to_point[0] + to_point[1] * to_point[1] +
             to_point[2] * to_point[2]);
    if (!(ScalarPart(distance) > 0.0)) return false;
    for (int i = 0; i < 3; ++i) {
      offset[i] = direction[i] - to_point[i] / distance;
    }
    return true;
  }

  // The normalized point (xb, yb) in air whose ray passes through `point`
  // (camera frame, meters, in the medium). False when the point is not
  // outside the outer sphere, its image would not lie in front of the
  // camera (v0_z <= 0), a ray on the way is totally reflected, or the
  // solve does not converge.
  template <typename T>
  static bool NormalizedFromPoint(const T& n, const T centre[3],
                                  const DomePort& dome, const T point[3],
                                  T normalized[2]) {
    const double r2 = dome.outer_radius();
    double c[3], p[3];
    for (int i = 0; i < 3; ++i) {
      c[i] = ScalarPart(centre[i]);
      p[i] = ScalarPart(point[i]);
    }
    const double n_value = ScalarPart(n);
    const Eigen::Vector3d from_centre(p[0] - c[0], p[1] - c[1], p[2] - c[2]);
    if (!(from_centre.squaredNorm() > r2 * r2) || !(p[2] > 0.0) ||
        !(n_value >= 1.0) || !std::isfinite(n_value + p[0] + p[1])) {
      return false;
    }
    // The tangent frame of the start, the direction from the dome's
    // centre to the point (the ray of a centred dome).
    Eigen::Matrix3d frame;
    frame.col(0) = from_centre.normalized();
    frame.col(1) = frame.col(0).unitOrthogonal();
    frame.col(2) = frame.col(0).cross(frame.col(1));
    Eigen::Vector2d x = Eigen::Vector2d::Zero();
    Eigen::Matrix<double, 3, 2> jacobian;
    Eigen::Vector3d residual;
    bool converged = false;
    for (int iteration = 0; iteration < kMaxIterations; ++iteration) {
      if (!Linearize(n_value, c, dome, p, frame, x, &residual, &jacobian)) {
        return false;
      }
      const Eigen::Matrix2d normal_matrix = jacobian.transpose() * jacobian;
      Eigen::Vector2d step =
          -normal_matrix.inverse() * (jacobian.transpose() * residual);
      if (!step.allFinite()) return false;
      // At most ~0.5 rad at a time: far from the root the linearization
      // of a ray bent by both surfaces can overshoot.
      if (step.norm() > kMaxStep) step *= kMaxStep / step.norm();
      x += step;
      // Quadratic convergence: after a step of 1e-12 the error is
      // ~1e-24 (times the curvature), below rounding.
      if (step.norm() <= kStepTolerance * (1.0 + x.norm())) {
        converged = true;
        break;
      }
    }
    if (!converged) return false;
    // The step in T (header), then v0 as a normalized point.
    if (!Linearize(n_value, c, dome, p, frame, x, &residual, &jacobian)) {
      return false;
    }
    const Eigen::Matrix<double, 2, 3> pseudo_inverse =
        (jacobian.transpose() * jacobian).inverse() * jacobian.transpose();
    T offset[3];
    if (!Offset(n, centre, dome, point, frame, T(x.x()), T(x.y()), offset)) {
      return false;
    }
    T ab[2];
    for (int r = 0; r < 2; ++r) {
      ab[r] = T(x[r]) - (T(pseudo_inverse(r, 0)) * offset[0] +
                         T(pseudo_inverse(r, 1)) * offset[1] +
                         T(pseudo_inverse(r, 2)) * offset[2]);
    }
    T v0[3];
    for (int i = 0; i < 3; ++i) {
      v0[i] = T(frame(i, 0)) + ab[0] * frame(i, 1) + ab[1] * frame(i, 2);
    }
    if (!(ScalarPart(v0[2]) > 0.0)) return false;
    normalized[0] = v0[0] / v0[2];
    normalized[1] = v0[1] / v0[2];
    return std::isfinite(ScalarPart(normalized[0])) &&
           std::isfinite(ScalarPart(normalized[1]));
  }

 private:
  // A double, or a Jet's value part, as the scalar X.
  template <typename X, typename T>
  static X Promote(const T& value) {
    if constexpr (std::is_same_v<X, T>) {
      return value;
    } else {
      return X(ScalarPart(value));
    }
  }

  // e(x) and de/dx in double (Jet<double, 2>).
  static bool Linearize(double n, const double centre[3], const DomePort& dome,
                        const double point[3], const Eigen::Matrix3d& frame,
                        const Eigen::Vector2d& x, Eigen::Vector3d* residual,
                        Eigen::Matrix<double, 3, 2>* jacobian) {
    using Dual = ceres::Jet<double, 2>;
    Dual offset[3];
    if (!Offset(n, centre, dome, point, frame, Dual(x.x(), 0), Dual(x.y(), 1),
                offset)) {
      return false;
    }
    for (int i = 0; i < 3; ++i) {
      (*residual)[i] = offset[i].a;
      (*jacobian)(i, 0) = offset[i].v[0];
      (*jacobian)(i, 1) = offset[i].v[1];
    }
    return residual->allFinite() && jacobian->allFinite();
  }
};

}  // namespace rcm

#endif  // RCM_CAMERA_DOME_PORT_REFRACTION_H_
