#include "rcm/camera/flat_port.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

namespace rcm {
namespace {

constexpr double kMaxIndex = 2.0;
// Far more than the solve needs (see AirDirectionFromPoint); a guard only.
constexpr int kMaxNewtonIterations = 100;

// tan(theta_k) in a layer of index eta of a ray whose tangent in air is t,
// g = t / sqrt(eta^2 + (eta^2 - 1) t^2), and dg/dt = eta^2 / (...)^(3/2).
// Both are exact at eta = 1 (g = t). g is concave in t >= 0 for eta >= 1.
double LayerTangent(double t, double eta) {
  return t / std::sqrt(eta * eta + (eta * eta - 1.0) * t * t);
}
double LayerTangentDerivative(double t, double eta) {
  const double q = eta * eta + (eta * eta - 1.0) * t * t;
  return eta * eta / (q * std::sqrt(q));
}

}  // namespace

std::optional<Eigen::Vector3d> Refract(const Eigen::Vector3d& incident,
                                       const Eigen::Vector3d& normal,
                                       double eta) {
  const double cos_i = normal.dot(incident);
  const double cos_t_squared = 1.0 - eta * eta * (1.0 - cos_i * cos_i);
  if (!(cos_t_squared >= 0.0)) return std::nullopt;
  return Eigen::Vector3d(eta * incident +
                         (std::sqrt(cos_t_squared) - eta * cos_i) * normal);
}

StatusOr<ExactFlatPort> ExactFlatPort::Create(const FlatPort& port, double n) {
  RCM_RETURN_IF_ERROR(port.Check());
  if (!std::isfinite(n) || n < 1.0 || n > kMaxIndex) {
    std::ostringstream message;
    message << "n = " << n << " is outside [1, " << kMaxIndex << "]";
    return Status::Error(message.str());
  }
  FlatPort unit = port;
  // stableNormalize: a normal of tiny components (1e-158) squares into the
  // subnormals, where normalize() keeps a few digits (found by
  // fuzz_camera_model: the back map of such a port was 1.9e-6 px off).
  unit.normal.stableNormalize();
  return ExactFlatPort(unit, n);
}

std::optional<RayInMedium> ExactFlatPort::RayFromNormalized(
    const Eigen::Vector2d& normalized) const {
  if (!normalized.allFinite()) return std::nullopt;
  const Eigen::Vector3d& normal = port_.normal;
  const Eigen::Vector3d in_air =
      Eigen::Vector3d(normalized.x(), normalized.y(), 1.0).normalized();
  const double cos_air = normal.dot(in_air);
  if (!(cos_air > 0.0)) return std::nullopt;
  const Eigen::Vector3d on_inner_face = in_air * (port_.air_gap / cos_air);
  const std::optional<Eigen::Vector3d> in_glass =
      Refract(in_air, normal, 1.0 / port_.glass_index);
  if (!in_glass) return std::nullopt;
  const Eigen::Vector3d on_outer_face =
      on_inner_face +
      *in_glass * (port_.glass_thickness / normal.dot(*in_glass));
  const std::optional<Eigen::Vector3d> in_medium =
      Refract(*in_glass, normal, port_.glass_index / n_);
  if (!in_medium) return std::nullopt;
  return RayInMedium{on_outer_face, in_medium->normalized()};
}

std::optional<Eigen::Vector3d> ExactFlatPort::AirDirectionFromPoint(
    const Eigen::Vector3d& point) const {
  if (!point.allFinite()) return std::nullopt;
  const Eigen::Vector3d& normal = port_.normal;
  const double d = port_.air_gap;
  const double tg = port_.glass_thickness;
  const double ng = port_.glass_index;
  const double along = normal.dot(point);
  const double in_medium = along - d - tg;  // length of the last leg's axis
  if (!(in_medium > 0.0)) return std::nullopt;
  const Eigen::Vector3d lateral = point - along * normal;
  const double rho = lateral.norm();
  // On the normal axis (to rounding) the ray is the normal itself.
  if (!(rho > 1e-300)) return normal;

  // f(t) = d t + tg g(t, n_glass) + L g(t, n) - rho, t = tan(theta_air):
  // strictly increasing and concave on [0, inf) (see the header).
  const auto f = [&](double t) {
    return d * t + tg * LayerTangent(t, ng) + in_medium * LayerTangent(t, n_) -
           rho;
  };
  const auto df = [&](double t) {
    return d + tg * LayerTangentDerivative(t, ng) +
           in_medium * LayerTangentDerivative(t, n_);
  };
  // Visible only when f reaches zero: its limit for t -> inf (the grazing
  // ray in air) is infinite when a layer of index 1 has nonzero length.
  const bool unbounded = d > 0.0 || (tg > 0.0 && ng == 1.0) || n_ == 1.0;
  if (!unbounded) {
    const double f_limit = (tg > 0.0 ? tg / std::sqrt(ng * ng - 1.0) : 0.0) +
                           in_medium / std::sqrt(n_ * n_ - 1.0) - rho;
    if (!(f_limit > 0.0)) return std::nullopt;
  }

  // Newton from t = 0, where f(0) = -rho < 0. A concave f lies below its
  // tangents, so every Newton iterate stays left of the root and the
  // iterates increase monotonically to it (quadratically once close). It
  // stops when the step reaches rounding or rounding puts f at >= 0.
  double t = 0.0;
  for (int iteration = 0; iteration < kMaxNewtonIterations; ++iteration) {
    const double value = f(t);
    if (value >= 0.0) break;
    const double step = -value / df(t);
    t += step;
    if (step <= 2.0 * std::numeric_limits<double>::epsilon() * t) break;
  }
  const double c = 1.0 / std::sqrt(1.0 + t * t);
  const double s = t * c;
  return Eigen::Vector3d(c * normal + s * (lateral / rho));
}

std::optional<Eigen::Vector2d> ExactFlatPort::NormalizedFromPoint(
    const Eigen::Vector3d& point) const {
  const std::optional<Eigen::Vector3d> in_air = AirDirectionFromPoint(point);
  if (!in_air || !(in_air->z() > 0.0)) return std::nullopt;
  const Eigen::Vector2d normalized(in_air->x() / in_air->z(),
                                   in_air->y() / in_air->z());
  // A solution that grazes the port can round to a ray in air that no
  // longer reaches the glass.
  if (!normalized.allFinite() || !RayFromNormalized(normalized)) {
    return std::nullopt;
  }
  return normalized;
}

}  // namespace rcm
