// The forward projection of the exact flat port (flat_port.h) templated on
// the scalar, so that Ceres differentiates the image of a point in the
// medium with respect to n, the port (air gap, glass, normal) and the point
// itself: the residual of the underwater target calibration
// (rcm/calib/underwater_reprojection_error.h). Same physics as
// ExactFlatPort::NormalizedFromPoint, solved for another unknown so that
// it is smooth through the optical axis; the tests hold the two together
// to 1e-12.
//
// Geometry (camera frame, flat_port_geometry.h): N the unit port normal
// (N_z > 0), d the air gap, tg the glass thickness, n_g the glass index,
// n the medium's index. For a point P in the medium let
//   a = N . P                 its distance along the normal,
//   L = P - a N               its offset from the normal axis, rho = |L|,
//   l = a - d - tg > 0        the length of the last leg along N.
// The ray in air leaves the center at the angle theta from N in the plane
// of N and P (the plane of refraction). With t = tan(theta) the lateral
// offsets of the three legs add up to rho (flat_port.h):
//   d t + tg g(t, n_g) + l g(t, n) = rho,
//   g(t, eta) = t / sqrt(eta^2 + (eta^2 - 1) t^2).
// Solved for t, the ray in air is cos(theta) N + sin(theta) L / rho, which
// is 0/0 on the axis (rho = 0). Here the unknown is s = t / rho instead;
// dividing by rho,
//   F(s) = s (d + tg h(s, n_g) + l h(s, n)) - 1 = 0,
//   h(s, eta) = 1 / sqrt(eta^2 + (eta^2 - 1) s^2 rho^2),
// which depends on P through rho^2 = L . L only, and the ray in air is
//   v0 = N + s L      (N . v0 = 1: it always meets the glass forward),
//   (xb, yb) = (v0_x / v0_z, v0_y / v0_z).
// Every step is smooth at rho = 0, where F is linear and
// s = 1 / (d + tg / n_g + l / n) (paraxial). For the thin port (d = tg = 0,
// N = z): s = n / sqrt(Z^2 - (n^2 - 1) rho^2) and (xb, yb) = s (X, Y), the
// paper's closed form (refractive_model.h).
//
// F is strictly increasing and concave in s >= 0, from F(0) = -1:
//   F'(s) = d + tg n_g^2 / q(n_g)^(3/2) + l n^2 / q(n)^(3/2) > 0,
//   q(eta) = eta^2 + (eta^2 - 1) s^2 rho^2.
// Newton's method from s = 0 therefore increases monotonically to the root
// (every iterate stays left of it) and converges quadratically. The root
// exists unless the point lies past the critical angle: when no layer of
// index 1 has nonzero length, F(s) tends to
//   (tg / sqrt(n_g^2 - 1) + l / sqrt(n^2 - 1)) / rho - 1,
// which must be positive.
//
// Derivatives (as the lens undistortion of lens_models.h): s is solved in
// double precision to machine precision, then ONE Newton step is taken in
// the scalar type T from the converged value,
//   s_T = s - F_T(s) / F'_T(s),
// which leaves the value where it was (F(s) is zero to rounding) and gives
// a Jet the implicit-function derivatives ds/dtheta = -F_theta / F_s for
// every input theta in (n, d, tg, n_g, N, P).
#ifndef RCM_CAMERA_FLAT_PORT_PROJECTION_H_
#define RCM_CAMERA_FLAT_PORT_PROJECTION_H_

#include <cmath>
#include <limits>

#include "rcm/camera/flat_port_geometry.h"
#include "rcm/util/scalar.h"

namespace rcm {

struct FlatPortProjection {
  // Newton iterations of the double solve: from s = 0 it takes 3-6 to
  // machine precision, up to ~20 near the critical angle, where F flattens
  // out (measured over n in [1, 2], thin and 8 + 6 mm ports); the guard
  // fails the projection of points closer still.
  static constexpr int kMaxNewtonIterations = 100;

  // F(s) of the header and, when `derivative` is given, F'(s), for the
  // quantities a point and a port define: rho^2, the last leg l and the
  // port's d, tg, n_g and the medium's n.
  template <typename T>
  static T Residual(const T& s, const T& rho_squared, const T& last_leg,
                    const T& air_gap, const T& glass_thickness,
                    const T& glass_index, const T& n, T* derivative = nullptr) {
    using std::sqrt;
    const T s2_rho2 = s * s * rho_squared;
    const T q_glass = glass_index * glass_index +
                      (glass_index * glass_index - T(1.0)) * s2_rho2;
    const T q_medium = n * n + (n * n - T(1.0)) * s2_rho2;
    const T h_glass = T(1.0) / sqrt(q_glass);
    const T h_medium = T(1.0) / sqrt(q_medium);
    if (derivative != nullptr) {
      *derivative = air_gap +
                    glass_thickness * glass_index * glass_index * h_glass *
                        h_glass * h_glass +
                    last_leg * n * n * h_medium * h_medium * h_medium;
    }
    return s * (air_gap + glass_thickness * h_glass + last_leg * h_medium) -
           T(1.0);
  }

  // The root s of F (double precision, safeguarded Newton from s = 0);
  // false when the point is past the critical angle or the solve does not
  // converge. Requires last_leg > 0, rho_squared >= 0, d, tg >= 0 and
  // n, n_g >= 1 (NormalizedFromPoint checks).
  static bool SolveScale(double rho_squared, double last_leg, double air_gap,
                         double glass_thickness, double glass_index, double n,
                         double* scale) {
    // Visible only when F reaches zero: its limit for s -> inf is infinite
    // when a layer of index 1 has nonzero length, or on the axis.
    const bool unbounded = air_gap > 0.0 ||
                           (glass_thickness > 0.0 && glass_index == 1.0) ||
                           n == 1.0 || rho_squared == 0.0;
    if (!unbounded) {
      const double limit =
          (glass_thickness > 0.0
               ? glass_thickness / std::sqrt(glass_index * glass_index - 1.0)
               : 0.0) +
          last_leg / std::sqrt(n * n - 1.0);
      if (!(limit * limit > rho_squared)) return false;
    }
    // Monotone Newton (header): it stops when the step reaches rounding or
    // rounding puts F at >= 0, i.e. on the root.
    double s = 0.0;
    for (int iteration = 0; iteration < kMaxNewtonIterations; ++iteration) {
      double derivative;
      const double value =
          Residual(s, rho_squared, last_leg, air_gap, glass_thickness,
                   glass_index, n, &derivative);
      if (value >= 0.0) break;
      if (!(derivative > 0.0)) return false;
      const double step = -value / derivative;
      s += step;
      if (!(step > 2.0 * std::numeric_limits<double>::epsilon() * s)) break;
      if (iteration + 1 == kMaxNewtonIterations) return false;
    }
    if (!std::isfinite(s) || !(s > 0.0)) return false;
    *scale = s;
    return true;
  }

  // The lens-undistorted normalized point (xb, yb) in air whose ray passes
  // through `point` (camera frame, meters) behind the port
  // (normal: unit, normal_z > 0). False when the point is not beyond the
  // outer glass face (l <= 0), lies past the critical angle, its ray in
  // air does not point forward (v0_z <= 0), or a port value is out of the
  // model's domain (d outside [0, FlatPort::kMaxAirGap], tg outside
  // [0, FlatPort::kMaxGlassThickness], n or n_g below 1, non-finite; a
  // huge gap would overflow the arithmetic): a solver that steps there
  // sees a failed residual and shortens the step.
  template <typename T>
  static bool NormalizedFromPoint(const T& n, const T& air_gap,
                                  const T& glass_thickness,
                                  const T& glass_index, const T normal[3],
                                  const T point[3], T normalized[2]) {
    const double d = ScalarPart(air_gap);
    const double tg = ScalarPart(glass_thickness);
    const double ng = ScalarPart(glass_index);
    const double n_value = ScalarPart(n);
    if (!(d >= 0.0 && d <= FlatPort::kMaxAirGap && tg >= 0.0 &&
          tg <= FlatPort::kMaxGlassThickness && ng >= 1.0 && n_value >= 1.0) ||
        !std::isfinite(ng + n_value)) {
      return false;
    }
    const T along =
        normal[0] * point[0] + normal[1] * point[1] + normal[2] * point[2];
    const T lateral[3] = {point[0] - along * normal[0],
                          point[1] - along * normal[1],
                          point[2] - along * normal[2]};
    const T rho_squared = lateral[0] * lateral[0] + lateral[1] * lateral[1] +
                          lateral[2] * lateral[2];
    const T last_leg = along - air_gap - glass_thickness;
    if (!(ScalarPart(last_leg) > 0.0) ||
        !std::isfinite(ScalarPart(rho_squared))) {
      return false;
    }
    double s;
    if (!SolveScale(ScalarPart(rho_squared), ScalarPart(last_leg), d, tg, ng,
                    n_value, &s)) {
      return false;
    }
    // One Newton step in T from the converged root (see the header).
    T derivative;
    const T value = Residual(T(s), rho_squared, last_leg, air_gap,
                             glass_thickness, glass_index, n, &derivative);
    const T scale = T(s) - value / derivative;
    const T in_air[3] = {normal[0] + scale * lateral[0],
                         normal[1] + scale * lateral[1],
                         normal[2] + scale * lateral[2]};
    if (!(ScalarPart(in_air[2]) > 0.0)) return false;
    normalized[0] = in_air[0] / in_air[2];
    normalized[1] = in_air[1] / in_air[2];
    return std::isfinite(ScalarPart(normalized[0])) &&
           std::isfinite(ScalarPart(normalized[1]));
  }
};

}  // namespace rcm

#endif  // RCM_CAMERA_FLAT_PORT_PROJECTION_H_
