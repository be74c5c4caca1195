#include "rcm/estimation/dome_port_error.h"

#include <ceres/jet.h>

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <sstream>
#include <thread>

#include "rcm/camera/dome_port_refraction.h"
#include "rcm/estimation/image_sample_grid.h"
#include "rcm/util/parallel_for.h"

namespace rcm {
namespace {

constexpr char kDomeErrorWhat[] = "dome-port error";
// Newton's method of the central camera: h is within a few percent of the
// identity, so 2-3 steps reach rounding; beyond this it has no root.
constexpr int kDomeNewtonIterations = 20;
constexpr double kDomeNewtonTolerance = 1e-14;
// The most grid samples: 1e7 (a 20000 px square image every 6 px).
constexpr int64_t kDomeErrorMaxSamples = 10000000;

// The point at depth `depth` on the ray, as a normalized point (X_x / Z,
// X_y / Z); false when the ray does not reach the depth ahead of its
// origin.
bool DomeRayNormalizedAtDepth(const RayInMedium& ray, double depth,
                              Eigen::Vector2d* normalized) {
  if (!(ray.direction.z() > 0.0)) return false;
  const double s = (depth - ray.origin.z()) / ray.direction.z();
  if (!(s > 0.0)) return false;
  const Eigen::Vector3d point = ray.origin + s * ray.direction;
  *normalized = point.head<2>() / depth;
  return normalized->allFinite();
}

// h(u) of the header and its Jacobian.
bool DomeCentralBearing(const DomePortCamera& camera, const Eigen::Vector2d& u,
                        double reference_depth, Eigen::Vector2d* h,
                        Eigen::Matrix2d* jacobian) {
  using Dual = ceres::Jet<double, 2>;
  const DomePort& dome = camera.dome();
  const Dual n(camera.n());
  const Dual centre[3] = {Dual(dome.decentering.x()),
                          Dual(dome.decentering.y()),
                          Dual(dome.decentering.z())};
  Dual origin[3], direction[3];
  if (!DomePortRefraction::RayInMedium(n, centre, dome, Dual(u.x(), 0),
                                       Dual(u.y(), 1), origin, direction) ||
      !(direction[2].a > 0.0)) {
    return false;
  }
  const Dual s = (Dual(reference_depth) - origin[2]) / direction[2];
  if (!(s.a > 0.0)) return false;
  for (int r = 0; r < 2; ++r) {
    const Dual value = (origin[r] + s * direction[r]) / reference_depth;
    (*h)[r] = value.a;
    jacobian->row(r) = value.v.transpose();
  }
  return h->allFinite() && jacobian->allFinite();
}

// e (or e_c with a reference depth) for a pixel with normalized point `u`
// and dome ray `ray`.
std::optional<Eigen::Vector2d> DomeErrorOfRay(
    const DomePortCamera& camera, const Eigen::Vector2d& u,
    const RayInMedium& ray, double depth,
    const std::optional<double>& reference_depth) {
  const Camera& lens = camera.camera();
  // A(u) rather than the raw pixel: the error is the dome's, not the lens
  // undistortion's round trip.
  const std::optional<Eigen::Vector2d> pixel = lens.ProjectNormalized(u);
  Eigen::Vector2d target;
  if (!pixel || !DomeRayNormalizedAtDepth(ray, depth, &target))
    return std::nullopt;
  Eigen::Vector2d seen = target;
  if (reference_depth) {
    seen = u;
    bool converged = false;
    for (int i = 0; i < kDomeNewtonIterations; ++i) {
      Eigen::Vector2d h;
      Eigen::Matrix2d jacobian;
      if (!DomeCentralBearing(camera, seen, *reference_depth, &h, &jacobian)) {
        return std::nullopt;
      }
      const Eigen::Vector2d step = jacobian.inverse() * (target - h);
      if (!step.allFinite()) return std::nullopt;
      seen += step;
      if (step.norm() <= kDomeNewtonTolerance * (1.0 + seen.norm())) {
        converged = true;
        break;
      }
    }
    if (!converged) return std::nullopt;
  }
  const std::optional<Eigen::Vector2d> modelled = lens.ProjectNormalized(seen);
  if (!modelled) return std::nullopt;
  return Eigen::Vector2d(*modelled - *pixel);
}

std::optional<Eigen::Vector2d> DomeErrorOfPixel(
    const DomePortCamera& camera, const Eigen::Vector2d& pixel, double depth,
    const std::optional<double>& reference_depth) {
  const std::optional<Eigen::Vector2d> u =
      camera.camera().NormalizedFromImage(pixel);
  if (!u) return std::nullopt;
  const std::optional<RayInMedium> ray = camera.RayFromNormalized(*u);
  if (!ray) return std::nullopt;
  return DomeErrorOfRay(camera, *u, *ray, depth, reference_depth);
}

Status CheckDomeErrorDepth(std::string_view name, double depth) {
  if (std::isfinite(depth) && depth > 0.0 &&
      depth <= DomePortErrorOptions::kMaxDepth) {
    return Status::Ok();
  }
  std::ostringstream message;
  message << kDomeErrorWhat << ": " << name << " " << depth
          << " m is outside (0, " << DomePortErrorOptions::kMaxDepth << "]";
  return Status::Error(message.str());
}

Status CheckBeyondDome(const DomePort& dome, double depth) {
  const double surface = DomeOuterSurfaceMaxDepth(dome);
  if (depth >= surface + DomePortErrorOptions::kMinDepthBeyondDome) {
    return Status::Ok();
  }
  std::ostringstream message;
  message << kDomeErrorWhat << ": depth " << depth
          << " m is not beyond the dome: its outer surface reaches z = "
          << surface << " m";
  return Status::Error(message.str());
}

struct DomeSampleRay {
  Eigen::Vector2d normalized;
  RayInMedium ray;
};

// The errors over the grid at one depth.
std::vector<std::optional<Eigen::Vector2d>> DomeErrorsAtDepth(
    const DomePortCamera& camera,
    const std::vector<std::optional<DomeSampleRay>>& rays, double depth,
    const std::optional<double>& reference_depth) {
  std::vector<std::optional<Eigen::Vector2d>> errors(rays.size());
  const int threads =
      static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  ParallelFor(static_cast<int64_t>(rays.size()), threads, 2048,
              [&](int64_t begin, int64_t end) {
                for (int64_t i = begin; i < end; ++i) {
                  if (!rays[i]) continue;
                  errors[i] =
                      DomeErrorOfRay(camera, rays[i]->normalized, rays[i]->ray,
                                     depth, reference_depth);
                }
              });
  return errors;
}

PixelErrorStats DomeErrorStats(
    const std::vector<std::optional<Eigen::Vector2d>>& errors,
    int64_t* num_unusable) {
  std::vector<double> lengths;
  lengths.reserve(errors.size());
  for (const std::optional<Eigen::Vector2d>& error : errors) {
    if (error) lengths.push_back(error->norm());
  }
  if (num_unusable != nullptr) {
    *num_unusable = static_cast<int64_t>(errors.size() - lengths.size());
  }
  return ComputePixelErrorStats(std::move(lengths));
}

}  // namespace

Status DomePortErrorOptions::Check() const {
  RCM_RETURN_IF_ERROR(CheckDomeErrorDepth("min_depth", min_depth));
  RCM_RETURN_IF_ERROR(CheckDomeErrorDepth("max_depth", max_depth));
  if (max_depth < min_depth) {
    std::ostringstream message;
    message << kDomeErrorWhat << ": max_depth " << max_depth
            << " m is below min_depth " << min_depth << " m";
    return Status::Error(message.str());
  }
  if (min_depth < max_depth && (num_depths < 2 || num_depths > kMaxNumDepths)) {
    std::ostringstream message;
    message << kDomeErrorWhat << ": num_depths " << num_depths
            << " is outside [2, " << kMaxNumDepths << "]";
    return Status::Error(message.str());
  }
  RCM_RETURN_IF_ERROR(CheckGridStep(kDomeErrorWhat, grid_step));
  if (reference_depth) {
    RCM_RETURN_IF_ERROR(
        CheckDomeErrorDepth("reference_depth", *reference_depth));
  }
  return Status::Ok();
}

std::vector<double> DomePortErrorDepths(const DomePortErrorOptions& options) {
  if (options.min_depth == options.max_depth) return {options.min_depth};
  std::vector<double> depths(options.num_depths);
  const double ratio = options.max_depth / options.min_depth;
  for (int i = 0; i < options.num_depths; ++i) {
    depths[i] =
        options.min_depth *
        std::pow(ratio, static_cast<double>(i) / (options.num_depths - 1));
  }
  // The ends exactly as given.
  depths.front() = options.min_depth;
  depths.back() = options.max_depth;
  return depths;
}

double DomeOuterSurfaceMaxDepth(const DomePort& dome) {
  return dome.decentering.z() + dome.outer_radius();
}

std::optional<Eigen::Vector2d> IgnoredDomeError(const DomePortCamera& camera,
                                                const Eigen::Vector2d& pixel,
                                                double depth) {
  return DomeErrorOfPixel(camera, pixel, depth, std::nullopt);
}

std::optional<Eigen::Vector2d> CentralDomeError(const DomePortCamera& camera,
                                                const Eigen::Vector2d& pixel,
                                                double depth,
                                                double reference_depth) {
  return DomeErrorOfPixel(camera, pixel, depth, reference_depth);
}

StatusOr<DomePortError> EvaluateDomePortError(
    const DomePortCamera& camera, const DomePortErrorOptions& options) {
  RCM_RETURN_IF_ERROR(options.Check());
  const DomePort& dome = camera.dome();
  RCM_RETURN_IF_ERROR(CheckBeyondDome(dome, options.min_depth));
  if (options.reference_depth) {
    RCM_RETURN_IF_ERROR(CheckBeyondDome(dome, *options.reference_depth));
  }
  const Camera& lens = camera.camera();
  // CenteredSampleGrid's size, before it allocates.
  const double samples =
      (std::floor((lens.width() - 1) / options.grid_step) + 1) *
      (std::floor((lens.height() - 1) / options.grid_step) + 1);
  if (samples > static_cast<double>(kDomeErrorMaxSamples)) {
    std::ostringstream message;
    message << kDomeErrorWhat << ": grid_step " << options.grid_step
            << " gives " << samples << " samples, more than "
            << kDomeErrorMaxSamples;
    return Status::Error(message.str());
  }
  ImageErrorField grid =
      CenteredSampleGrid(lens.width(), lens.height(), options.grid_step);

  // Each pixel's ray, once: it does not depend on the depth.
  std::vector<std::optional<DomeSampleRay>> rays(grid.errors.size());
  for (int row = 0; row < grid.rows; ++row) {
    for (int col = 0; col < grid.cols; ++col) {
      const std::optional<Eigen::Vector2d> u =
          lens.NormalizedFromImage(grid.Pixel(col, row));
      if (!u) continue;
      const std::optional<RayInMedium> ray = camera.RayFromNormalized(*u);
      if (ray) rays[static_cast<size_t>(row) * grid.cols + col] = {*u, *ray};
    }
  }

  DomePortError result;
  double sum_squares = 0.0;
  int64_t count = 0;
  std::vector<std::optional<Eigen::Vector2d>> worst_errors;
  for (const double depth : DomePortErrorDepths(options)) {
    DomePortErrorAtDepth at;
    at.depth = depth;
    std::vector<std::optional<Eigen::Vector2d>> errors =
        DomeErrorsAtDepth(camera, rays, depth, std::nullopt);
    at.ignored = DomeErrorStats(errors, &at.num_unusable);
    if (at.ignored.num_samples == 0) {
      std::ostringstream message;
      message << kDomeErrorWhat << ": no pixel of the image sees depth "
              << depth << " m through the dome";
      return Status::Error(message.str());
    }
    if (options.reference_depth) {
      at.central = DomeErrorStats(
          DomeErrorsAtDepth(camera, rays, depth, options.reference_depth),
          nullptr);
      result.central_max_px =
          std::max(result.central_max_px.value_or(0.0), at.central->max_px);
    }
    sum_squares += at.ignored.rms_px * at.ignored.rms_px *
                   static_cast<double>(at.ignored.num_samples);
    count += at.ignored.num_samples;
    if (result.depths.empty() || at.ignored.max_px > result.max_px) {
      result.max_px = at.ignored.max_px;
      result.worst_index = static_cast<int>(result.depths.size());
      worst_errors = std::move(errors);
    }
    result.depths.push_back(at);
  }
  result.rms_px = std::sqrt(sum_squares / static_cast<double>(count));
  grid.errors = std::move(worst_errors);
  result.worst_field = std::move(grid);

  if (options.reference_depth) {
    DomePortErrorAtDepth at;
    at.depth = *options.reference_depth;
    at.ignored =
        DomeErrorStats(DomeErrorsAtDepth(camera, rays, at.depth, std::nullopt),
                       &at.num_unusable);
    at.central = DomeErrorStats(
        DomeErrorsAtDepth(camera, rays, at.depth, options.reference_depth),
        nullptr);
    result.at_reference = at;
  }
  return result;
}

}  // namespace rcm
