// Lens models: the in-air part of the camera, calibrated before the dive.
//
// Written in the style of COLMAP's sensor/models.h: one struct per model,
// static functions templated on the scalar so that they run on double and
// on ceres::Jet, raw parameter arrays, failure reported by a bool.
//
// Coordinates:
//   normalized (x, y)  a point on the plane z = 1 of the camera frame
//                      (x right, y down, z forward), before lens distortion;
//   distorted (xd, yd) the same ray after lens distortion, still divided by
//                      the focal length;
//   pixel (u, v)       u = fx * xd + cx, v = fy * yd + cy; pixel centers at
//                      integer coordinates (OpenCV, Kalibr).
//
// Parameter order of every model (a raw array):
//   params = [fx, fy, cx, cy, d_0, ..., d_{kNumDistortionParams - 1}]
// and `dist` below points at params + 4.
//
//   PinholeLens       no distortion                    (Kalibr "none")
//   RadTanLens        k1, k2, p1, p2                    (Kalibr "radtan",
//                                                        OpenCV plumb bob k3=0)
//   EquidistantLens   k1, k2, k3, k4                    (Kalibr "equidistant",
//                                                        OpenCV fisheye)
//   RationalLens      k1, k2, p1, p2, k3, k4, k5, k6    (OpenCV
//                                                        CALIB_RATIONAL_MODEL,
//                                                        mrcal OPENCV8)
//   DoubleSphereLens  xi, alpha                         (Kalibr "ds", basalt)
//   EucmLens          alpha, beta                       (Kalibr "eucm", basalt)
//
// Undistortion is iterative. It is solved in double precision (safeguarded
// Newton), then one Newton step is taken in the scalar type T from the
// converged point; for a Jet that step makes the derivative parts exact
// (the implicit-function derivative), for a double it changes nothing.
#ifndef RCM_CAMERA_LENS_MODELS_H_
#define RCM_CAMERA_LENS_MODELS_H_

#include <algorithm>
#include <cmath>
#include <limits>

#include "rcm/util/scalar.h"

namespace rcm {

enum class LensModelId {
  kPinhole = 0,
  kRadTan = 1,
  kEquidistant = 2,
  kRational = 3,
  kDoubleSphere = 4,
  kEucm = 5,
};

// The number of lens models; LensModelId values are 0 .. kNumLensModels - 1.
inline constexpr int kNumLensModels = 6;

// The largest number of parameters of any lens model (fx, fy, cx, cy + 8,
// the rational model), rounded up to 12 so that a model of up to 8
// distortion coefficients more does not change the parameter blocks'
// size again.
inline constexpr int kMaxLensParams = 12;

namespace lens_internal {

// Residual (in normalized units) below which undistortion has converged.
// Floating-point evaluation of the distortion polynomials carries a few ulp
// of error, so ~1e-15 is the floor; 1e-14 leaves margin and is 1e-11 px at
// a 1000 px focal length.
inline constexpr double kUndistortTolerance = 1e-14;
inline constexpr int kMaxUndistortIterations = 100;

// Solves a * x = b for a 2x2 row-major a; false when a is singular.
template <typename T>
bool Solve2x2(const T a[4], const T b[2], T x[2]) {
  const T det = a[0] * a[3] - a[1] * a[2];
  const double scale = std::abs(ScalarPart(a[0])) + std::abs(ScalarPart(a[1])) +
                       std::abs(ScalarPart(a[2])) + std::abs(ScalarPart(a[3]));
  if (!(std::abs(ScalarPart(det)) > 1e-12 * scale * scale)) return false;
  x[0] = (a[3] * b[0] - a[1] * b[1]) / det;
  x[1] = (a[0] * b[1] - a[2] * b[0]) / det;
  return true;
}

// The first normalized radius r = tan(theta) at which `increasing(r)`
// stops holding, scanning theta in (0, pi/2) in `steps` steps and then
// bisecting 60 times on the angle; infinity when it holds all the way. A
// coarse scan can step over a failure narrower than its step.
template <typename Predicate>
double FirstRadiusWhereFalse(const Predicate& increasing, int steps) {
  constexpr double kHalfPi = 1.5707963267948966;
  for (int k = 1; k < steps; ++k) {
    const double theta = kHalfPi * k / steps;
    if (increasing(std::tan(theta))) continue;
    double good = kHalfPi * (k - 1) / steps;
    double bad = theta;
    for (int it = 0; it < 60; ++it) {
      const double middle = 0.5 * (good + bad);
      if (increasing(std::tan(middle))) {
        good = middle;
      } else {
        bad = middle;
      }
    }
    return std::tan(good);
  }
  return std::numeric_limits<double>::infinity();
}

}  // namespace lens_internal

// What every model shares: pixel <-> distorted normalized, and the 2-D
// Newton undistortion used by models that have no cheaper inverse.
template <typename Derived>
struct BaseLens {
  // Pixel of a normalized point.
  template <typename T>
  static void ImgFromCam(const T* params, const T& x, const T& y, T* u, T* v) {
    T xd, yd;
    Derived::Distort(params + 4, x, y, &xd, &yd);
    *u = params[0] * xd + params[2];
    *v = params[1] * yd + params[3];
  }

  // Normalized point of a pixel; false when undistortion does not converge
  // (a pixel outside the region where the lens model is invertible).
  template <typename T>
  static bool CamFromImg(const T* params, const T& u, const T& v, T* x, T* y) {
    const T xd = (u - params[2]) / params[0];
    const T yd = (v - params[3]) / params[1];
    return Derived::Undistort(params + 4, xd, yd, x, y);
  }

  // Inverse of Distort by Newton's method on the 2x2 Jacobian of
  // Derived::DistortWithJacobian, with step halving when a step does not
  // reduce the residual.
  template <typename T>
  static bool Undistort(const T* dist, const T& xd, const T& yd, T* x, T* y) {
    constexpr int kNumDist = Derived::kNumDistortionParams;
    double dist_value[kNumDist > 0 ? kNumDist : 1] = {0.0};
    for (int i = 0; i < kNumDist; ++i) dist_value[i] = ScalarPart(dist[i]);
    const double target[2] = {ScalarPart(xd), ScalarPart(yd)};
    double point[2];
    if (!Derived::UndistortScalar(dist_value, target, point)) return false;

    // One Newton step in T from the converged point (see file comment).
    T fx, fy, jacobian[4];
    Derived::DistortWithJacobian(dist, T(point[0]), T(point[1]), &fx, &fy,
                                 jacobian);
    const T residual[2] = {xd - fx, yd - fy};
    T step[2];
    if (!lens_internal::Solve2x2(jacobian, residual, step)) return false;
    *x = T(point[0]) + step[0];
    *y = T(point[1]) + step[1];
    return true;
  }

  // The double-precision solve behind Undistort: Newton from the distorted
  // point itself. A model with a closed-form inverse hides this with its
  // own (which may end in NewtonFrom to polish).
  static bool UndistortScalar(const double* dist, const double target[2],
                              double point[2]) {
    if (!std::isfinite(target[0]) || !std::isfinite(target[1])) return false;
    point[0] = target[0];
    point[1] = target[1];
    return NewtonFrom(dist, target, point);
  }

  // Safeguarded Newton on Distort(point) = target from the starting point
  // in `point`; true when the residual reaches the tolerance.
  static bool NewtonFrom(const double* dist, const double target[2],
                         double point[2]) {
    using lens_internal::kUndistortTolerance;
    if (!std::isfinite(point[0]) || !std::isfinite(point[1])) return false;
    const double tolerance =
        kUndistortTolerance * (1.0 + std::hypot(target[0], target[1]));
    double f[2], jacobian[4];
    Derived::DistortWithJacobian(dist, point[0], point[1], &f[0], &f[1],
                                 jacobian);
    double residual[2] = {target[0] - f[0], target[1] - f[1]};
    double norm = std::hypot(residual[0], residual[1]);
    for (int it = 0; it < lens_internal::kMaxUndistortIterations; ++it) {
      if (norm <= tolerance) return true;
      double step[2];
      if (!lens_internal::Solve2x2(jacobian, residual, step)) return false;
      // Step halving: accept the first step that reduces the residual.
      bool improved = false;
      for (int halvings = 0; halvings < 40 && !improved; ++halvings) {
        const double trial[2] = {point[0] + step[0], point[1] + step[1]};
        double trial_f[2], trial_jacobian[4];
        Derived::DistortWithJacobian(dist, trial[0], trial[1], &trial_f[0],
                                     &trial_f[1], trial_jacobian);
        const double trial_residual[2] = {target[0] - trial_f[0],
                                          target[1] - trial_f[1]};
        const double trial_norm =
            std::hypot(trial_residual[0], trial_residual[1]);
        if (trial_norm < norm) {
          point[0] = trial[0];
          point[1] = trial[1];
          residual[0] = trial_residual[0];
          residual[1] = trial_residual[1];
          for (int k = 0; k < 4; ++k) jacobian[k] = trial_jacobian[k];
          norm = trial_norm;
          improved = true;
        } else {
          step[0] *= 0.5;
          step[1] *= 0.5;
        }
      }
      if (!improved) break;  // Stalled at the floating-point floor.
    }
    return norm <= tolerance;
  }
};

// No distortion: (xd, yd) = (x, y).
struct PinholeLens : public BaseLens<PinholeLens> {
  static constexpr LensModelId kModelId = LensModelId::kPinhole;
  static constexpr int kNumDistortionParams = 0;
  static constexpr int kNumParams = 4;
  static constexpr const char* kParamsInfo = "fx, fy, cx, cy";

  template <typename T>
  static void Distort(const T* /*dist*/, const T& x, const T& y, T* xd, T* yd) {
    *xd = x;
    *yd = y;
  }
  // jacobian = d(xd, yd) / d(x, y), row-major 2x2.
  template <typename T>
  static void DistortWithJacobian(const T* dist, const T& x, const T& y, T* xd,
                                  T* yd, T jacobian[4]) {
    Distort(dist, x, y, xd, yd);
    jacobian[0] = T(1.0);
    jacobian[1] = T(0.0);
    jacobian[2] = T(0.0);
    jacobian[3] = T(1.0);
  }
  // False for a point that is not finite, as the iterative models.
  template <typename T>
  static bool Undistort(const T* /*dist*/, const T& xd, const T& yd, T* x,
                        T* y) {
    if (!std::isfinite(ScalarPart(xd)) || !std::isfinite(ScalarPart(yd))) {
      return false;
    }
    *x = xd;
    *y = yd;
    return true;
  }
};

// Radial-tangential (Brown-Conrady with k3 = 0), as OpenCV and Kalibr:
//   r^2 = x^2 + y^2,  radial = 1 + k1 r^2 + k2 r^4
//   xd = x radial + 2 p1 x y + p2 (r^2 + 2 x^2)
//   yd = y radial + p1 (r^2 + 2 y^2) + 2 p2 x y
struct RadTanLens : public BaseLens<RadTanLens> {
  static constexpr LensModelId kModelId = LensModelId::kRadTan;
  static constexpr int kNumDistortionParams = 4;
  static constexpr int kNumParams = 8;
  static constexpr const char* kParamsInfo = "fx, fy, cx, cy, k1, k2, p1, p2";

  template <typename T>
  static void Distort(const T* dist, const T& x, const T& y, T* xd, T* yd) {
    DistortWithJacobian(dist, x, y, xd, yd, static_cast<T*>(nullptr));
  }

  // Analytic jacobian = d(xd, yd) / d(x, y), row-major 2x2, skipped when
  // `jacobian` is null:
  //   with g = 2 (k1 + 2 k2 r^2) (so d radial / dx = g x),
  //   dxd/dx = radial + g x^2 + 2 p1 y + 6 p2 x
  //   dxd/dy = g x y + 2 p1 x + 2 p2 y = dyd/dx
  //   dyd/dy = radial + g y^2 + 6 p1 y + 2 p2 x
  template <typename T>
  static void DistortWithJacobian(const T* dist, const T& x, const T& y, T* xd,
                                  T* yd, T* jacobian) {
    const T& k1 = dist[0];
    const T& k2 = dist[1];
    const T& p1 = dist[2];
    const T& p2 = dist[3];
    const T x2 = x * x;
    const T y2 = y * y;
    const T xy = x * y;
    const T r2 = x2 + y2;
    const T radial = T(1.0) + r2 * (k1 + k2 * r2);
    *xd = x * radial + T(2.0) * p1 * xy + p2 * (r2 + T(2.0) * x2);
    *yd = y * radial + p1 * (r2 + T(2.0) * y2) + T(2.0) * p2 * xy;
    if (jacobian == nullptr) return;
    const T g = T(2.0) * (k1 + T(2.0) * k2 * r2);
    const T cross = g * xy + T(2.0) * (p1 * x + p2 * y);
    jacobian[0] = radial + g * x2 + T(2.0) * p1 * y + T(6.0) * p2 * x;
    jacobian[1] = cross;
    jacobian[2] = cross;
    jacobian[3] = radial + g * y2 + T(6.0) * p1 * y + T(2.0) * p2 * x;
  }
};

// Equidistant (Kannala-Brandt), as OpenCV fisheye and Kalibr:
//   r = |(x, y)|,  theta = atan(r)   (angle of the ray to the optical axis)
//   theta_d = theta (1 + k1 theta^2 + k2 theta^4 + k3 theta^6 + k4 theta^8)
//   (xd, yd) = (theta_d / r) (x, y)
// A normalized point exists only for theta < 90 degrees, so undistortion
// fails for pixels whose ray is at or beyond 90 degrees off axis.
struct EquidistantLens : public BaseLens<EquidistantLens> {
  static constexpr LensModelId kModelId = LensModelId::kEquidistant;
  static constexpr int kNumDistortionParams = 4;
  static constexpr int kNumParams = 8;
  static constexpr const char* kParamsInfo = "fx, fy, cx, cy, k1, k2, k3, k4";

  // Below this r^2 the series theta_d / r = 1 + (k1 - 1/3) r^2 + O(r^4) is
  // exact in double precision and avoids sqrt(0) in the derivative parts.
  static constexpr double kSeriesRadiusSquared = 1e-16;

  // theta_d(theta) and, optionally, d theta_d / d theta.
  template <typename T>
  static T DistortedAngle(const T* dist, const T& theta,
                          T* derivative = nullptr) {
    const T t2 = theta * theta;
    const T poly =
        T(1.0) +
        t2 * (dist[0] + t2 * (dist[1] + t2 * (dist[2] + t2 * dist[3])));
    if (derivative != nullptr) {
      *derivative =
          T(1.0) +
          t2 * (T(3.0) * dist[0] +
                t2 * (T(5.0) * dist[1] +
                      t2 * (T(7.0) * dist[2] + t2 * T(9.0) * dist[3])));
    }
    return theta * poly;
  }

  // s(r) = theta_d / r from r^2 and, when `radial_term` is given,
  // s'(r) / r (see DistortWithJacobian).
  template <typename T>
  static T Scale(const T* dist, const T& r2, T* radial_term = nullptr) {
    if (ScalarPart(r2) < kSeriesRadiusSquared) {
      const T k1_minus_third = dist[0] - T(1.0 / 3.0);
      if (radial_term != nullptr) *radial_term = T(2.0) * k1_minus_third;
      return T(1.0) + k1_minus_third * r2;
    }
    using std::atan;
    using std::sqrt;
    const T r = sqrt(r2);
    if (radial_term == nullptr) return DistortedAngle(dist, atan(r)) / r;
    T derivative;
    const T theta_d = DistortedAngle(dist, atan(r), &derivative);
    *radial_term = (derivative * r / (T(1.0) + r2) - theta_d) / (r2 * r);
    return theta_d / r;
  }

  template <typename T>
  static void Distort(const T* dist, const T& x, const T& y, T* xd, T* yd) {
    const T scale = Scale(dist, x * x + y * y);
    *xd = scale * x;
    *yd = scale * y;
  }

  // Analytic jacobian = d(xd, yd) / d(x, y), row-major 2x2:
  //   s(r) = theta_d / r,  J = s I + (s'(r) / r) (x, y)^T (x, y)
  //   s'(r) / r = (theta_d'(theta) r / (1 + r^2) - theta_d) / r^3
  //             -> 2 (k1 - 1/3) as r -> 0.
  template <typename T>
  static void DistortWithJacobian(const T* dist, const T& x, const T& y, T* xd,
                                  T* yd, T jacobian[4]) {
    T radial_term;
    const T scale = Scale(dist, x * x + y * y, &radial_term);
    *xd = scale * x;
    *yd = scale * y;
    jacobian[0] = scale + radial_term * x * x;
    jacobian[1] = radial_term * x * y;
    jacobian[2] = jacobian[1];
    jacobian[3] = scale + radial_term * y * y;
  }

  // Solves theta_d(theta) = |(xd, yd)| for theta in [0, pi/2) by Newton's
  // method safeguarded by bisection on that bracket, then returns
  // (x, y) = (tan(theta) / theta_d) (xd, yd).
  template <typename T>
  static bool Undistort(const T* dist, const T& xd, const T& yd, T* x, T* y) {
    using std::sqrt;
    using std::tan;
    const T theta_d2 = xd * xd + yd * yd;
    if (!std::isfinite(ScalarPart(theta_d2))) return false;
    if (ScalarPart(theta_d2) < kSeriesRadiusSquared) {
      // theta_d / r = 1 + O(r^2): identity to double precision; its
      // derivative d(x, y)/d(xd, yd) = I holds at the origin.
      *x = xd;
      *y = yd;
      return true;
    }
    double dist_value[4];
    for (int i = 0; i < 4; ++i) dist_value[i] = ScalarPart(dist[i]);
    const double target = std::sqrt(ScalarPart(theta_d2));
    double theta;
    if (!SolveTheta(dist_value, target, &theta)) return false;

    // One Newton step in T from the converged angle (see file comment).
    const T theta_d = sqrt(theta_d2);
    T derivative;
    const T value = DistortedAngle(dist, T(theta), &derivative);
    const T theta_t = T(theta) - (value - theta_d) / derivative;
    const T scale = tan(theta_t) / theta_d;
    *x = scale * xd;
    *y = scale * yd;
    return true;
  }

  static constexpr double kHalfPi = 1.5707963267948966;

  // The first angle in (0, pi/2) where d theta_d / d theta stops being
  // positive, i.e. where theta_d folds back (strongly negative
  // coefficients): theta is scanned upward in `steps` steps of
  // pi / (2 steps), and the fold is found by 60 bisections on the sign of
  // the derivative, on its rising side. pi/2 when theta_d rises all the
  // way, as it does for any real lens. A coarse scan can step over a fold
  // narrower than its step.
  static double FirstFoldAngle(const double* dist, int steps) {
    for (int k = 1; k <= steps; ++k) {
      const double theta = kHalfPi * k / steps;
      double derivative;
      DistortedAngle(dist, theta, &derivative);
      if (derivative > 0.0) continue;
      double rising = kHalfPi * (k - 1) / steps;
      double falling = theta;
      for (int it = 0; it < 60; ++it) {
        const double middle = 0.5 * (rising + falling);
        DistortedAngle(dist, middle, &derivative);
        if (derivative > 0.0) {
          rising = middle;
        } else {
          falling = middle;
        }
      }
      return rising;
    }
    return kHalfPi;
  }

  // The double-precision angle solve behind Undistort.
  static bool SolveTheta(const double* dist, double target, double* theta) {
    double lo = 0.0;
    double hi = kHalfPi;
    // The bracket [0, pi/2] holds a root if theta_d(pi/2) exceeds the
    // target; otherwise theta_d may still reach it before folding back
    // (found by fuzz_camera_model: k1..k4 = -0.22 folds at 0.8 rad, and
    // every pixel failed to unproject).
    if (!(DistortedAngle(dist, hi) > target)) {
      constexpr int kFoldScanSteps = 64;  // per pixel: coarse
      hi = FirstFoldAngle(dist, kFoldScanSteps);
      if (!(hi < kHalfPi) || !(DistortedAngle(dist, hi) > target)) {
        return false;
      }
    }
    double t = std::min(target, 0.5 * (lo + hi));
    if (!(t > lo)) t = 0.5 * (lo + hi);
    for (int it = 0; it < 200; ++it) {
      double derivative;
      const double f = DistortedAngle(dist, t, &derivative) - target;
      if (std::abs(f) <= lens_internal::kUndistortTolerance * (1.0 + target)) {
        *theta = t;
        return t < kHalfPi;
      }
      if (f < 0.0) {
        lo = t;
      } else {
        hi = t;
      }
      double next = t - f / derivative;
      if (!(derivative > 0.0) || !(next > lo && next < hi)) {
        next = 0.5 * (lo + hi);  // Bisection when Newton leaves the bracket.
      }
      if (next == t) break;
      t = next;
    }
    double derivative;
    const double f = DistortedAngle(dist, t, &derivative) - target;
    *theta = t;
    return std::abs(f) <=
               1e3 * lens_internal::kUndistortTolerance * (1.0 + target) &&
           t < kHalfPi;
  }
};

// Rational (OpenCV's CALIB_RATIONAL_MODEL, mrcal LENSMODEL_OPENCV8),
// coefficients in OpenCV's order d = [k1, k2, p1, p2, k3, k4, k5, k6]:
//   r^2 = x^2 + y^2
//   radial = (1 + k1 r^2 + k2 r^4 + k3 r^6) / (1 + k4 r^2 + k5 r^4 + k6 r^6)
//   xd = x radial + 2 p1 x y + p2 (r^2 + 2 x^2)
//   yd = y radial + p1 (r^2 + 2 y^2) + 2 p2 x y
// (OpenCV's documentation of cv::projectPoints, "Detailed description" of
// the calib3d module). With k3..k6 = 0 it is RadTanLens.
struct RationalLens : public BaseLens<RationalLens> {
  static constexpr LensModelId kModelId = LensModelId::kRational;
  static constexpr int kNumDistortionParams = 8;
  static constexpr int kNumParams = 12;
  static constexpr const char* kParamsInfo =
      "fx, fy, cx, cy, k1, k2, p1, p2, k3, k4, k5, k6";

  // Numerator n(s), denominator q(s) of the radial factor at s = r^2 and
  // their derivatives d/ds.
  template <typename T>
  static void RadialParts(const T* dist, const T& s, T* n, T* q, T* dn,
                          T* dq) {
    const T& k1 = dist[0];
    const T& k2 = dist[1];
    const T& k3 = dist[4];
    const T& k4 = dist[5];
    const T& k5 = dist[6];
    const T& k6 = dist[7];
    *n = T(1.0) + s * (k1 + s * (k2 + s * k3));
    *q = T(1.0) + s * (k4 + s * (k5 + s * k6));
    *dn = k1 + s * (T(2.0) * k2 + s * T(3.0) * k3);
    *dq = k4 + s * (T(2.0) * k5 + s * T(3.0) * k6);
  }

  template <typename T>
  static void Distort(const T* dist, const T& x, const T& y, T* xd, T* yd) {
    DistortWithJacobian(dist, x, y, xd, yd, static_cast<T*>(nullptr));
  }

  // Analytic jacobian = d(xd, yd) / d(x, y), row-major 2x2, skipped when
  // `jacobian` is null: as RadTanLens with
  //   g = 2 d radial / ds = 2 (n' q - n q') / q^2
  // for radial = n / q.
  template <typename T>
  static void DistortWithJacobian(const T* dist, const T& x, const T& y, T* xd,
                                  T* yd, T* jacobian) {
    const T& p1 = dist[2];
    const T& p2 = dist[3];
    const T x2 = x * x;
    const T y2 = y * y;
    const T xy = x * y;
    const T r2 = x2 + y2;
    T n, q, dn, dq;
    RadialParts(dist, r2, &n, &q, &dn, &dq);
    const T radial = n / q;
    *xd = x * radial + T(2.0) * p1 * xy + p2 * (r2 + T(2.0) * x2);
    *yd = y * radial + p1 * (r2 + T(2.0) * y2) + T(2.0) * p2 * xy;
    if (jacobian == nullptr) return;
    const T g = T(2.0) * (dn - radial * dq) / q;
    const T cross = g * xy + T(2.0) * (p1 * x + p2 * y);
    jacobian[0] = radial + g * x2 + T(2.0) * p1 * y + T(6.0) * p2 * x;
    jacobian[1] = cross;
    jacobian[2] = cross;
    jacobian[3] = radial + g * y2 + T(6.0) * p1 * y + T(2.0) * p2 * x;
  }

  // True while the radial part r radial(r^2) is rising and its denominator
  // positive (past a pole of the denominator it is not the lens any more).
  static bool RadiallyIncreasing(const double* dist, double r) {
    const double s = r * r;
    double n, q, dn, dq;
    RadialParts(dist, s, &n, &q, &dn, &dq);
    // d/dr [r n / q] = ((n + 2 s n') q - 2 s n q') / q^2.
    return q > 0.0 && (n + 2.0 * s * dn) * q - 2.0 * s * n * dq > 0.0;
  }

  // The double-precision solve behind Undistort. Newton from the distorted
  // point is kept when it converges where the lens is rising
  // (RadiallyIncreasing). Otherwise it started past the principal branch:
  // a denominator q with negative k4..k6 has a pole at radius R, and a
  // pixel whose distorted radius rd exceeds R has its preimage below R,
  // while Newton from rd sits beyond the pole (found by fuzz_camera_model:
  // k4, k5, k6 = -0.047, -0.047, -0.125, R = 1.351, rd = 1.37). Then
  // Newton restarts from (xd, yd) * r / rd, where r solves the radial part
  // alone, r n(r^2) / q(r^2) = rd, on the branch rising from the axis
  // (RadialInverse); the tangential terms move it by about p1, p2.
  static bool UndistortScalar(const double* dist, const double target[2],
                              double point[2]) {
    if (!std::isfinite(target[0]) || !std::isfinite(target[1])) return false;
    point[0] = target[0];
    point[1] = target[1];
    if (NewtonFrom(dist, target, point) &&
        RadiallyIncreasing(dist, std::hypot(point[0], point[1]))) {
      return true;
    }
    const double rd = std::hypot(target[0], target[1]);
    const double r = RadialInverse(dist, rd);
    if (!std::isfinite(r)) return false;
    const double scale = rd > 0.0 ? r / rd : 1.0;
    point[0] = target[0] * scale;
    point[1] = target[1] * scale;
    return NewtonFrom(dist, target, point) &&
           RadiallyIncreasing(dist, std::hypot(point[0], point[1]));
  }

  // The radius r on the principal branch with r n(r^2) / q(r^2) = rd, or
  // NaN when the branch ends (a fold or a pole, RadiallyIncreasing false)
  // below rd. The same scan as Camera::MaxInvertibleRadius, coarser
  // (steps of pi/1024 in the angle off axis), brackets the root; 60
  // bisections then place it to the last bit.
  static double RadialInverse(const double* dist, double rd) {
    constexpr double kHalfPi = 1.5707963267948966;
    constexpr int kScanSteps = 512;
    const auto radial = [dist](double r) {
      double n, q, dn, dq;
      RadialParts(dist, r * r, &n, &q, &dn, &dq);
      return r * n / q;
    };
    double low = 0.0;
    for (int k = 1; k < kScanSteps; ++k) {
      double high = std::tan(kHalfPi * k / kScanSteps);
      if (!RadiallyIncreasing(dist, high)) break;
      if (radial(high) < rd) {
        low = high;
        continue;
      }
      for (int it = 0; it < 60; ++it) {
        const double middle = 0.5 * (low + high);
        if (radial(middle) < rd) {
          low = middle;
        } else {
          high = middle;
        }
      }
      return 0.5 * (low + high);
    }
    return std::numeric_limits<double>::quiet_NaN();
  }
};

// Double sphere (Usenko, Demmel, Cremers, "The Double Sphere Camera
// Model", 3DV 2018; Kalibr "ds", basalt DoubleSphereCamera), d = [xi, alpha]:
//   d1 = sqrt(x^2 + y^2 + 1)
//   k  = xi d1 + 1
//   d2 = sqrt(x^2 + y^2 + k^2)
//   N  = alpha d2 + (1 - alpha) k
//   (xd, yd) = (x, y) / N
// On the plane z = 1 only rays in front of the camera exist, so the model
// here covers fields of view below 180 degrees.
// Unprojection is the paper's closed form (eq. 47-50, as basalt), with
// (mx, my) = (xd, yd), r^2 = mx^2 + my^2:
//   mz = (1 - alpha^2 r^2) / (alpha sqrt(1 - (2 alpha - 1) r^2) + 1 - alpha)
//   s  = (mz xi + sqrt(mz^2 + (1 - xi^2) r^2)) / (mz^2 + r^2)
//   ray = (s mx, s my, s mz - xi),  (x, y) = (s mx, s my) / (s mz - xi)
// defined for r^2 < 1 / (2 alpha - 1) when alpha > 1/2, and in front of
// the camera for s mz - xi > 0; then polished by Newton in double.
// Accepted ranges (Camera::CheckDistortion): alpha in [0, 1] (the paper's
// range; outside it N can vanish inside the image), xi in (-1, 1] (at
// xi = -1 the optical axis itself is singular, k = 0; beyond 1 the sqrt of
// the closed form goes negative and real lenses calibrate to |xi| < 1).
struct DoubleSphereLens : public BaseLens<DoubleSphereLens> {
  static constexpr LensModelId kModelId = LensModelId::kDoubleSphere;
  static constexpr int kNumDistortionParams = 2;
  static constexpr int kNumParams = 6;
  static constexpr const char* kParamsInfo = "fx, fy, cx, cy, xi, alpha";

  template <typename T>
  static void Distort(const T* dist, const T& x, const T& y, T* xd, T* yd) {
    DistortWithJacobian(dist, x, y, xd, yd, static_cast<T*>(nullptr));
  }

  // Analytic jacobian = d(xd, yd) / d(x, y), row-major 2x2, skipped when
  // `jacobian` is null: dN/dx = c x, dN/dy = c y with
  //   c = alpha (1 + xi k / d1) / d2 + (1 - alpha) xi / d1,
  // so J = I / N - (c / N^2) (x, y)^T (x, y).
  template <typename T>
  static void DistortWithJacobian(const T* dist, const T& x, const T& y, T* xd,
                                  T* yd, T* jacobian) {
    using std::sqrt;
    const T& xi = dist[0];
    const T& alpha = dist[1];
    const T r2 = x * x + y * y;
    const T d1 = sqrt(r2 + T(1.0));
    const T k = xi * d1 + T(1.0);
    const T d2 = sqrt(r2 + k * k);
    const T norm = alpha * d2 + (T(1.0) - alpha) * k;
    const T inverse = T(1.0) / norm;
    *xd = x * inverse;
    *yd = y * inverse;
    if (jacobian == nullptr) return;
    const T c =
        alpha * (T(1.0) + xi * k / d1) / d2 + (T(1.0) - alpha) * xi / d1;
    const T b = c * inverse * inverse;
    jacobian[0] = inverse - b * x * x;
    jacobian[1] = -b * x * y;
    jacobian[2] = jacobian[1];
    jacobian[3] = inverse - b * y * y;
  }

  // The closed form above, then Newton from it.
  static bool UndistortScalar(const double* dist, const double target[2],
                              double point[2]) {
    if (!std::isfinite(target[0]) || !std::isfinite(target[1])) return false;
    const double xi = dist[0];
    const double alpha = dist[1];
    const double mx = target[0];
    const double my = target[1];
    const double r2 = mx * mx + my * my;
    const double under = 1.0 - (2.0 * alpha - 1.0) * r2;
    if (!(under >= 0.0)) return false;
    const double mz =
        (1.0 - alpha * alpha * r2) / (alpha * std::sqrt(under) + 1.0 - alpha);
    const double inner = mz * mz + (1.0 - xi * xi) * r2;
    if (!(inner >= 0.0)) return false;
    const double s = (mz * xi + std::sqrt(inner)) / (mz * mz + r2);
    const double z = s * mz - xi;
    if (!(z > 0.0) || !std::isfinite(s)) return false;
    point[0] = s * mx / z;
    point[1] = s * my / z;
    if (!RadiallyIncreasing(dist, std::hypot(point[0], point[1]))) {
      return false;
    }
    return NewtonFrom(dist, target, point);
  }

  // True while the radial map r -> r / N(r) is rising and N positive.
  static bool RadiallyIncreasing(const double* dist, double r) {
    double xd, yd, jacobian[4];
    DistortWithJacobian(dist, r, 0.0, &xd, &yd, jacobian);
    return std::isfinite(xd) && (r == 0.0 || xd > 0.0) && jacobian[0] > 0.0;
  }
};

// Enhanced unified camera model (Khomutenko, Garcia, Martinet, "An
// Enhanced Unified Camera Model", RA-L 2016; Kalibr "eucm", basalt
// ExtendedUnifiedCamera), d = [alpha, beta]:
//   rho = sqrt(beta (x^2 + y^2) + 1)
//   N   = alpha rho + 1 - alpha
//   (xd, yd) = (x, y) / N
// r / N(r) rises for every r (its derivative is (alpha / rho + 1 - alpha)
// / N^2 > 0), so the map never folds in front of the camera.
// Unprojection in closed form (as basalt), r^2 = xd^2 + yd^2:
//   m = (1 - alpha^2 beta r^2) /
//       (alpha sqrt(1 - (2 alpha - 1) beta r^2) + 1 - alpha)
//   (x, y) = (xd, yd) / m
// (m = 1 / N), in front of the camera for m > 0, then polished by Newton.
// Accepted ranges (Camera::CheckDistortion): alpha in [0, 1] (the paper's),
// beta > 0 (at beta = 0 the ellipsoid degenerates, N = 1, and alpha is
// unobservable; negative beta has no ray beyond rho = 0).
struct EucmLens : public BaseLens<EucmLens> {
  static constexpr LensModelId kModelId = LensModelId::kEucm;
  static constexpr int kNumDistortionParams = 2;
  static constexpr int kNumParams = 6;
  static constexpr const char* kParamsInfo = "fx, fy, cx, cy, alpha, beta";

  template <typename T>
  static void Distort(const T* dist, const T& x, const T& y, T* xd, T* yd) {
    DistortWithJacobian(dist, x, y, xd, yd, static_cast<T*>(nullptr));
  }

  // Analytic jacobian = d(xd, yd) / d(x, y), row-major 2x2, skipped when
  // `jacobian` is null: dN/dx = c x with c = alpha beta / rho, and
  //   J = I / N - (c / N^2) (x, y)^T (x, y).
  template <typename T>
  static void DistortWithJacobian(const T* dist, const T& x, const T& y, T* xd,
                                  T* yd, T* jacobian) {
    using std::sqrt;
    const T& alpha = dist[0];
    const T& beta = dist[1];
    const T rho = sqrt(beta * (x * x + y * y) + T(1.0));
    const T norm = alpha * rho + T(1.0) - alpha;
    const T inverse = T(1.0) / norm;
    *xd = x * inverse;
    *yd = y * inverse;
    if (jacobian == nullptr) return;
    const T b = alpha * beta / rho * inverse * inverse;
    jacobian[0] = inverse - b * x * x;
    jacobian[1] = -b * x * y;
    jacobian[2] = jacobian[1];
    jacobian[3] = inverse - b * y * y;
  }

  // The closed form above, then Newton from it.
  static bool UndistortScalar(const double* dist, const double target[2],
                              double point[2]) {
    if (!std::isfinite(target[0]) || !std::isfinite(target[1])) return false;
    const double alpha = dist[0];
    const double beta = dist[1];
    const double r2 = target[0] * target[0] + target[1] * target[1];
    const double under = 1.0 - (2.0 * alpha - 1.0) * beta * r2;
    if (!(under >= 0.0)) return false;
    const double m = (1.0 - alpha * alpha * beta * r2) /
                     (alpha * std::sqrt(under) + 1.0 - alpha);
    if (!(m > 0.0) || !std::isfinite(m)) return false;
    point[0] = target[0] / m;
    point[1] = target[1] / m;
    return NewtonFrom(dist, target, point);
  }
};

}  // namespace rcm

#endif  // RCM_CAMERA_LENS_MODELS_H_
