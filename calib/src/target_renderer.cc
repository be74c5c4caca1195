#include "rcm/calib/target_renderer.h"

#include <glog/logging.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <utility>

#include "rcm/util/parallel_for.h"
#include "rcm/util/splitmix64.h"

namespace rcm::calib {
namespace {

constexpr int kMaxSupersampling = 16;
// Rows per thread below which ParallelFor stays on one thread.
constexpr int64_t kMinRowsPerThread = 8;
// Threads Create undistorts the pixel corners with.
constexpr int kCreateThreads = 2;
// Newton on the ray-surface intersection (header): converged when the
// step in depth is below kWarpStep [m]; kMaxWarpIterations is far more than
// the ~4 a bow of millimetres needs.
constexpr double kWarpStep = 1e-12;
constexpr int kMaxWarpIterations = 30;

// The target point (x, y) where the camera ray d meets the bowed board,
// from the plane's hit; nullopt when Newton does not converge or the hit is
// behind the camera. target = R^T (s d - t).
// `origin` and `direction` are the ray's in the target frame.
std::optional<Eigen::Vector2d> WarpedHit(const Eigen::Vector3d& origin,
                                         const Eigen::Vector3d& direction,
                                         const BoardWarpSurface& surface) {
  if (!(std::abs(direction.z()) > 0.0)) return std::nullopt;
  double s = -origin.z() / direction.z();
  for (int i = 0; i < kMaxWarpIterations; ++i) {
    const Eigen::Vector3d p = origin + s * direction;
    const double f = p.z() - surface.Height(p.x(), p.y());
    const double slope =
        direction.z() - surface.Slope(p.x(), p.y()).dot(direction.head<2>());
    if (!(std::abs(slope) > 0.0)) return std::nullopt;
    const double step = f / slope;
    s -= step;
    if (!std::isfinite(s)) return std::nullopt;
    if (std::abs(step) < kWarpStep) {
      if (!(s > 0.0)) return std::nullopt;
      return (origin + s * direction).head<2>();
    }
  }
  return std::nullopt;
}

// Create's checks of the texture.
Status CheckTexture(const TargetImage& target_image) {
  const cv::Mat& texture = target_image.image;
  if (texture.empty() || texture.type() != CV_8UC1) {
    return Status::Error("target image must be a non-empty 8-bit gray image");
  }
  const Eigen::Matrix2d linear = target_image.target_from_texture.leftCols<2>();
  const double det = linear.determinant();
  if (!target_image.target_from_texture.allFinite() || !(std::abs(det) > 0)) {
    return Status::Error("target_from_texture is not invertible");
  }
  return Status::Ok();
}

}  // namespace

Status TargetRenderOptions::Check() const {
  std::ostringstream message;
  if (supersampling < 1 || supersampling > kMaxSupersampling) {
    message << "supersampling = " << supersampling << " must be in [1, "
            << kMaxSupersampling << "]";
  } else if (!(std::isfinite(blur_sigma_px) && blur_sigma_px >= 0.0)) {
    message << "blur_sigma_px = " << blur_sigma_px
            << " must be finite and >= 0";
  } else if (!(std::isfinite(noise_sigma) && noise_sigma >= 0.0)) {
    message << "noise_sigma = " << noise_sigma << " must be finite and >= 0";
  } else if (background < 0 || background > 255) {
    message << "background = " << background << " must be in [0, 255]";
  } else if (num_threads < 1) {
    message << "num_threads = " << num_threads << " must be >= 1";
  } else if (!board_warp.warp.allFinite() || !board_warp.origin.allFinite() ||
             !(board_warp.extent.minCoeff() > 0.0) ||
             !board_warp.extent.allFinite()) {
    message << "board_warp must be finite with a positive extent";
  } else {
    return Status::Ok();
  }
  return Status::Error(message.str());
}

StatusOr<TargetRenderer> TargetRenderer::Create(const Camera& camera,
                                                TargetImage target_image) {
  RCM_RETURN_IF_ERROR(CheckTexture(target_image));
  TargetRenderer renderer(camera, std::move(target_image));
  RCM_RETURN_IF_ERROR(renderer.TraceCorners(
      [&camera](const Eigen::Vector2d& pixel) -> std::optional<RayInMedium> {
        const std::optional<Eigen::Vector2d> normalized =
            camera.NormalizedFromImage(pixel);
        if (!normalized || !normalized->allFinite()) return std::nullopt;
        return RayInMedium{Eigen::Vector3d::Zero(),
                           normalized->homogeneous().normalized()};
      },
      /*central=*/true));
  return renderer;
}

StatusOr<TargetRenderer> TargetRenderer::Create(const DomePortCamera& camera,
                                                TargetImage target_image) {
  RCM_RETURN_IF_ERROR(CheckTexture(target_image));
  TargetRenderer renderer(camera.camera(), std::move(target_image));
  renderer.dome_camera_ = camera;
  RCM_RETURN_IF_ERROR(renderer.TraceCorners(
      [&camera](const Eigen::Vector2d& pixel) -> std::optional<RayInMedium> {
        std::optional<RayInMedium> ray = camera.RayFromImage(pixel);
        if (ray) ray->direction.normalize();
        return ray;
      },
      /*central=*/false));
  return renderer;
}

Status TargetRenderer::TraceCorners(
    const std::function<std::optional<RayInMedium>(const Eigen::Vector2d&)>&
        trace,
    bool central) {
  const int columns = camera_.width() + 1;
  const int rows = camera_.height() + 1;
  constexpr float kNan = std::numeric_limits<float>::quiet_NaN();
  corner_rays_.assign(static_cast<size_t>(columns) * rows,
                      Eigen::Vector3f::Constant(kNan));
  if (central) {
    corner_origins_.clear();
  } else {
    corner_origins_.assign(corner_rays_.size(),
                           Eigen::Vector3f::Constant(kNan));
  }
  ParallelFor(
      rows, kCreateThreads, kMinRowsPerThread, [&](int64_t begin, int64_t end) {
        for (int64_t y = begin; y < end; ++y) {
          for (int x = 0; x < columns; ++x) {
            const std::optional<RayInMedium> ray =
                trace(Eigen::Vector2d(x - 0.5, y - 0.5));
            if (!ray) continue;
            corner_rays_[y * columns + x] = ray->direction.cast<float>();
            if (!central) {
              corner_origins_[y * columns + x] = ray->origin.cast<float>();
            }
          }
        }
      });
  const bool any_valid =
      std::any_of(corner_rays_.begin(), corner_rays_.end(),
                  [](const Eigen::Vector3f& ray) { return ray.allFinite(); });
  if (!any_valid) {
    return Status::Error(central
                             ? "the camera's lens cannot undistort any pixel"
                             : "no pixel's ray leaves the dome");
  }
  return Status::Ok();
}

cv::Mat TargetRenderer::Render(const Rigid3d& cam_from_target,
                               const TargetRenderOptions& options) const {
  const Status valid = options.Check();
  CHECK(valid.ok()) << "TargetRenderOptions: " << valid.message();
  const int width = camera_.width();
  const int height = camera_.height();
  const int columns = width + 1;
  const int s = options.supersampling;
  const float background = static_cast<float>(options.background);
  cv::Mat mean(height, width, CV_32FC1, cv::Scalar(background));

  // texture_from_camera_ray: [u w, v w, w] = T [r1 r2 t]^-1 d.
  Eigen::Matrix3d plane;
  plane << cam_from_target.rotation.col(0), cam_from_target.rotation.col(1),
      cam_from_target.translation;
  const double plane_det = plane.determinant();
  if (std::isfinite(plane_det) && std::abs(plane_det) > 1e-12) {
    const Eigen::Matrix2d linear =
        target_image_.target_from_texture.leftCols<2>();
    const Eigen::Matrix2d linear_inverse = linear.inverse();
    Eigen::Matrix3d texture_from_target = Eigen::Matrix3d::Identity();
    texture_from_target.topLeftCorner<2, 2>() = linear_inverse;
    texture_from_target.topRightCorner<2, 1>() =
        -linear_inverse * target_image_.target_from_texture.col(2);
    const Eigen::Matrix3d texture_from_ray =
        texture_from_target * plane.inverse();

    // Homogeneous texture points of the pixel corners (NaN where invalid).
    const bool warped = options.board_warp.warp.squaredNorm() > 0.0;
    const Eigen::Matrix3d target_from_cam =
        cam_from_target.rotation.transpose();
    const Eigen::Vector3d origin =
        -(target_from_cam * cam_from_target.translation);
    constexpr double kNan = std::numeric_limits<double>::quiet_NaN();
    const bool central = corner_origins_.empty();
    std::vector<Eigen::Vector3d> corners(corner_rays_.size());
    ParallelFor(
        static_cast<int64_t>(height) + 1, options.num_threads,
        kMinRowsPerThread, [&](int64_t begin, int64_t end) {
          for (int64_t k = begin * columns; k < end * columns; ++k) {
            const Eigen::Vector3d ray = corner_rays_[k].cast<double>();
            Eigen::Vector3d ray_origin = origin;
            if (central) {
              corners[k] = texture_from_ray * ray;
            } else {
              // P(s) = o_t + s d_t meets z = 0 at s; T (P_x, P_y, 1) / s.
              ray_origin =
                  target_from_cam * (corner_origins_[k].cast<double>() -
                                     cam_from_target.translation);
              const double direction_z = target_from_cam.row(2).dot(ray);
              const double s = -ray_origin.z() / direction_z;
              corners[k] = std::isfinite(s) && s != 0.0
                               ? Eigen::Vector3d(
                                     texture_from_target *
                                     (ray_origin + s * (target_from_cam * ray))
                                         .head<2>()
                                         .homogeneous() /
                                     s)
                               : Eigen::Vector3d::Constant(kNan);
            }
            if (!warped || !(corners[k].z() > 0.0)) continue;
            const std::optional<Eigen::Vector2d> hit = WarpedHit(
                ray_origin, target_from_cam * ray, options.board_warp);
            corners[k] =
                hit ? Eigen::Vector3d(corners[k].z() * (texture_from_target *
                                                        hit->homogeneous()))
                    : Eigen::Vector3d::Constant(kNan);
          }
        });

    const cv::Mat& texture = target_image_.image;
    const int texture_cols = texture.cols;
    const int texture_rows = texture.rows;
    const int background_level = options.background;
    std::vector<double> fractions(s);
    for (int i = 0; i < s; ++i) fractions[i] = (i + 0.5) / s;
    const float inverse_count = 1.0f / static_cast<float>(s * s);
    ParallelFor(height, options.num_threads, kMinRowsPerThread,
                [&](int64_t begin, int64_t end) {
                  for (int64_t y = begin; y < end; ++y) {
                    float* out = mean.ptr<float>(static_cast<int>(y));
                    const Eigen::Vector3d* top = &corners[y * columns];
                    const Eigen::Vector3d* bottom = top + columns;
                    for (int x = 0; x < width; ++x) {
                      const Eigen::Vector3d& c00 = top[x];
                      const Eigen::Vector3d& c10 = top[x + 1];
                      const Eigen::Vector3d& c01 = bottom[x];
                      const Eigen::Vector3d& c11 = bottom[x + 1];
                      if (!(c00.allFinite() && c10.allFinite() &&
                            c01.allFinite() && c11.allFinite())) {
                        continue;  // stays background
                      }
                      int sum = 0;
                      for (int j = 0; j < s; ++j) {
                        const double fy = fractions[j];
                        const Eigen::Vector3d left = c00 + fy * (c01 - c00);
                        const Eigen::Vector3d step =
                            c10 + fy * (c11 - c10) - left;
                        for (int i = 0; i < s; ++i) {
                          const Eigen::Vector3d h = left + fractions[i] * step;
                          if (!(h.z() > 0.0)) {
                            sum += background_level;
                            continue;
                          }
                          const double inverse_w = 1.0 / h.z();
                          const double u = std::floor(h.x() * inverse_w + 0.5);
                          const double v = std::floor(h.y() * inverse_w + 0.5);
                          if (u >= 0.0 && v >= 0.0 && u < texture_cols &&
                              v < texture_rows) {
                            sum += texture.ptr<uint8_t>(
                                static_cast<int>(v))[static_cast<int>(u)];
                          } else {
                            sum += background_level;
                          }
                        }
                      }
                      out[x] = static_cast<float>(sum) * inverse_count;
                    }
                  }
                });
  }

  if (options.blur_sigma_px > 0.0) {
    cv::GaussianBlur(mean, mean, cv::Size(0, 0), options.blur_sigma_px,
                     options.blur_sigma_px, cv::BORDER_REPLICATE);
  }
  cv::Mat image(height, width, CV_8UC1);
  const uint64_t noise_key = SplitMix64(options.seed);
  ParallelFor(
      height, options.num_threads, kMinRowsPerThread,
      [&](int64_t begin, int64_t end) {
        for (int64_t y = begin; y < end; ++y) {
          const float* in = mean.ptr<float>(static_cast<int>(y));
          uint8_t* out = image.ptr<uint8_t>(static_cast<int>(y));
          for (int x = 0; x < width; ++x) {
            double value = in[x];
            if (options.noise_sigma > 0.0) {
              const uint64_t pixel = static_cast<uint64_t>(y) * width + x;
              value += options.noise_sigma *
                       GaussianFromHash(SplitMix64(noise_key + pixel));
            }
            out[x] =
                static_cast<uint8_t>(std::clamp(std::lround(value), 0L, 255L));
          }
        }
      });
  return image;
}

std::vector<std::optional<Eigen::Vector2d>> ProjectTargetPoints(
    const Camera& camera, const Rigid3d& cam_from_target,
    const CalibrationTarget& target, const Eigen::Vector2d& board_warp) {
  std::vector<std::optional<Eigen::Vector2d>> pixels;
  for (const Eigen::Vector3d& point : WarpedTargetPoints(target, board_warp)) {
    const Eigen::Vector3d in_camera = cam_from_target * point;
    std::optional<Eigen::Vector2d> pixel;
    if (in_camera.z() > 0.0) {
      pixel = camera.ProjectNormalized(in_camera.hnormalized());
      if (pixel && !camera.InImage(*pixel)) pixel.reset();
    }
    pixels.push_back(pixel);
  }
  return pixels;
}

std::vector<std::optional<Eigen::Vector2d>> ProjectTargetPoints(
    const DomePortCamera& camera, const Rigid3d& cam_from_target,
    const CalibrationTarget& target, const Eigen::Vector2d& board_warp) {
  std::vector<std::optional<Eigen::Vector2d>> pixels;
  for (const Eigen::Vector3d& point : WarpedTargetPoints(target, board_warp)) {
    std::optional<Eigen::Vector2d> pixel =
        camera.ImageFromPoint(cam_from_target * point);
    if (pixel && !camera.camera().InImage(*pixel)) pixel.reset();
    pixels.push_back(pixel);
  }
  return pixels;
}

}  // namespace rcm::calib
