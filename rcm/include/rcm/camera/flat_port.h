// The exact flat port of an underwater housing (the thick-port model): a
// camera whose center sits an air gap d behind a glass plate of thickness
// tg and index n_glass, beyond which lies the medium of index n. The
// plate's normal N may be tilted slightly from the optical axis. The
// simulator's physics, and the library's model of housings the paper's
// thin port does not describe (flat_port_camera.h).
//
// It shares no code with refractive_model.h (the thin-port approximation
// d = tg = 0, N = z of paper Sec. III-A), so that data it generates can
// test that model, and the two can be checked against each other.
//
// Geometry, in the camera frame (x right, y down, z forward), N unit with
// N_z > 0, pointing out of the housing:
//   inner glass face   { p : N . p = d }
//   outer glass face   { p : N . p = d + tg }
//   medium             { p : N . p > d + tg }
//
// Back-trace (pixel -> ray in the medium): the ray in air leaves the center
// along v0 = (xb, yb, 1) / |.|, meets the inner face, is refracted into the
// glass, crosses it, and is refracted into the medium. Each refraction is
// the vector form of Snell's law, for a unit incident direction v, the unit
// normal N along the propagation (cos_i = N . v > 0) and eta = n_1 / n_2:
//   refract(v) = eta v + (sqrt(1 - eta^2 (1 - cos_i^2)) - eta cos_i) N
// (no solution when the root's argument is negative: total internal
// reflection. Going outward it cannot happen, since the invariant
// sin(theta) n_k = sin(theta_air) <= 1 holds in every layer; the check
// guards rounding.)
//
// Forward projection (point in the medium -> normalized point in air): the
// whole path lies in the plane spanned by N and the point (the plane of
// refraction). With a = N . P the point's distance along the normal,
// rho its distance from the normal axis through the center, and
// t = tan(theta_air) the unknown, the lateral offsets of the three legs add
// up to rho (Snell: sin(theta_k) = sin(theta_air) / n_k):
//   f(t) = d t + tg g(t, n_glass) + (a - d - tg) g(t, n) - rho = 0,
//   g(t, eta) = tan(theta_k) = t / sqrt(eta^2 + (eta^2 - 1) t^2).
// f is strictly increasing and concave in t >= 0 (f(0) = -rho), so the root
// is unique when it exists; it is found by safeguarded Newton to machine
// precision and the point is then visible along
//   v0 = cos(theta_air) N + sin(theta_air) u,  u = lateral unit vector.
// No root exists past the critical angle of the medium (the limit of f for
// t -> inf is below rho), which is when the point cannot be seen.
#ifndef RCM_CAMERA_FLAT_PORT_H_
#define RCM_CAMERA_FLAT_PORT_H_

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <optional>

#include "rcm/camera/flat_port_geometry.h"
#include "rcm/util/status.h"

namespace rcm {

// Vector Snell's law. `incident` and `normal` unit, normal . incident > 0,
// eta = n_from / n_to. Returns the unit refracted direction, or nullopt on
// total internal reflection.
std::optional<Eigen::Vector3d> Refract(const Eigen::Vector3d& incident,
                                       const Eigen::Vector3d& normal,
                                       double eta);

// A ray in the medium, in the camera frame: origin on the outer glass face,
// unit direction.
struct RayInMedium {
  Eigen::Vector3d origin;
  Eigen::Vector3d direction;
};

// A validated port together with the medium index behind it.
class ExactFlatPort {
 public:
  // Fails when the port fails Check() or n is not in [1, 2].
  static StatusOr<ExactFlatPort> Create(const FlatPort& port, double n);

  const FlatPort& port() const { return port_; }  // normal is unit length
  double n() const { return n_; }

  // The ray in the medium of a lens-undistorted normalized point (xb, yb)
  // (the ray in air along (xb, yb, 1)). nullopt when that ray does not reach
  // the glass (N . v0 <= 0) or is totally reflected.
  std::optional<RayInMedium> RayFromNormalized(
      const Eigen::Vector2d& normalized) const;

  // The normalized point (xb, yb) in air whose ray passes through `point`
  // (camera frame). Accurate to ~1e-15 relative. nullopt when the point is
  // not beyond the outer glass face, past the critical angle, its ray in
  // air would not point forward (v0_z <= 0, not representable as (xb, yb)),
  // or the ray grazes the port so closely that RayFromNormalized of the
  // result, rounded, misses the glass (found by fuzz_camera_model: with an
  // air gap of 1e-107 m, a point 80 degrees off a port tilted 15 degrees
  // the other way was "reached" at 90 degrees to the port's normal).
  std::optional<Eigen::Vector2d> NormalizedFromPoint(
      const Eigen::Vector3d& point) const;

  // The unit direction of the ray in air (leaving the camera center) whose
  // continuation passes through `point`; same failure cases as
  // NormalizedFromPoint except the forward requirement.
  std::optional<Eigen::Vector3d> AirDirectionFromPoint(
      const Eigen::Vector3d& point) const;

 private:
  ExactFlatPort(const FlatPort& port, double n) : port_(port), n_(n) {}

  FlatPort port_;
  double n_;
};

}  // namespace rcm

#endif  // RCM_CAMERA_FLAT_PORT_H_
