#include "rcm/camera/virtual_pinhole_remap.h"

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <sstream>
#include <string>
#include <variant>
#include <vector>

#include "rcm/util/parallel_for.h"

namespace rcm {
namespace {

// H = K_n R K'^-1: output pixel to (homogeneous) virtual pinhole pixel of
// the camera.
Eigen::Matrix3d VirtualFromOutput(const RefractiveCamera& camera,
                                  const VirtualPinholeView& view) {
  return camera.VirtualPinholeMatrix() * view.camera_from_view *
         view.k.inverse();
}

// Output pixel (u, v) of the border of a w x h image: calls
// `visit(u, v, edge)` for every pixel center on the four edges, edge 0 top
// (v = 0), 1 bottom, 2 left (u = 0), 3 right; corners on two edges. Stops
// and returns false as soon as `visit` does.
template <typename Visit>
bool ForEachBorderPixel(int width, int height, Visit visit) {
  for (int u = 0; u < width; ++u) {
    if (!visit(u, 0, 0) || !visit(u, height - 1, 1)) return false;
  }
  for (int v = 0; v < height; ++v) {
    if (!visit(0, v, 2) || !visit(width - 1, v, 3)) return false;
  }
  return true;
}

// Inside [0, width - 1] x [0, height - 1], up to kVirtualPinholeFitSlackPx.
bool InsideCenters(const Eigen::Vector2d& pixel, int width, int height) {
  constexpr double kSlack = kVirtualPinholeFitSlackPx;
  return pixel.x() >= -kSlack && pixel.x() <= width - 1.0 + kSlack &&
         pixel.y() >= -kSlack && pixel.y() <= height - 1.0 + kSlack;
}

// True when every border pixel of `view` samples the raw image of `camera`
// inside [0, w - 1] x [0, h - 1], computed exactly as the maps are.
bool OutputBorderInsideRaw(const RefractiveCamera& camera,
                           const VirtualPinholeView& view) {
  const Camera& lens = camera.camera();
  const Eigen::Matrix3d virtual_from_output = VirtualFromOutput(camera, view);
  return ForEachBorderPixel(view.width, view.height, [&](int u, int v, int) {
    const Eigen::Vector3d virtual_point =
        virtual_from_output * Eigen::Vector3d(u, v, 1.0);
    if (!(virtual_point.z() > 0.0)) return false;
    const std::optional<Eigen::Vector2d> raw =
        camera.ImageFromVirtualPinhole(virtual_point.hnormalized());
    return raw && InsideCenters(*raw, lens.width(), lens.height());
  });
}

// View-frame directions (not normalized, z > 0) of the rays of a camera's
// raw border pixels that the lens can unproject; nullopt when one of them
// points 90 degrees or more off the view axis (`behind` then names it).
std::optional<std::vector<Eigen::Vector3d>> BorderRaysInView(
    const RotatedCamera& rotated, Eigen::Vector2d* behind) {
  const Camera& lens = rotated.camera.camera();
  const Eigen::Matrix3d view_from_camera = rotated.camera_from_view.transpose();
  std::vector<Eigen::Vector3d> rays;
  rays.reserve(2 * (lens.width() + lens.height()));
  const bool all_in_front =
      ForEachBorderPixel(lens.width(), lens.height(), [&](int u, int v, int) {
        const std::optional<Eigen::Vector3d> bearing =
            rotated.camera.BearingInWaterFromImage(Eigen::Vector2d(u, v));
        if (!bearing) return true;  // not unprojectable: not seen
        const Eigen::Vector3d in_view = view_from_camera * *bearing;
        if (!(in_view.z() > 0.0)) {
          *behind = Eigen::Vector2d(u, v);
          return false;
        }
        rays.push_back(in_view);
        return true;
      });
  if (!all_in_front) return std::nullopt;
  return rays;
}

constexpr double kMinScale = 1e-3;
constexpr double kMaxScale = 1e3;
constexpr double kScaleTolerance = 1e-6;

enum class BisectionFailure { kHoldsEverywhere, kHoldsNowhere };

// The boundary of a predicate `holds(s)` that is monotone in s: it holds
// for s >= s* when `larger_holds`, else for s <= s*. Returns an s that
// holds within a relative kScaleTolerance of s*, searching
// [kMinScale, kMaxScale] from s = 1 by halving or doubling, then bisecting.
template <typename Holds>
std::variant<double, BisectionFailure> BisectScale(Holds holds,
                                                   bool larger_holds) {
  // From a valid scale toward the invalid side.
  const double step = larger_holds ? 0.5 : 2.0;
  const auto out_of_range = [](double s) {
    return s < kMinScale || s > kMaxScale;
  };
  double valid = 1.0;
  double invalid = 1.0;
  if (holds(1.0)) {
    while (holds(invalid)) {
      invalid *= step;
      if (out_of_range(invalid)) return BisectionFailure::kHoldsEverywhere;
    }
    valid = invalid / step;
  } else {
    while (!holds(valid)) {
      valid /= step;
      if (out_of_range(valid)) return BisectionFailure::kHoldsNowhere;
    }
    invalid = valid * step;
  }
  while (std::abs(valid - invalid) > kScaleTolerance * valid) {
    const double middle = 0.5 * (valid + invalid);
    (holds(middle) ? valid : invalid) = middle;
  }
  return valid;
}

// One row of cv::convertMaps(map_x, map_y, xy, table, CV_16SC2, false):
// the position rounded to 1/INTER_TAB_SIZE px, split into the integer
// pixel and the index of the fraction in OpenCV's interpolation table.
void FixedPointRow(const float* map_x, const float* map_y, int width,
                   int16_t* xy, uint16_t* table) {
  for (int u = 0; u < width; ++u) {
    const int x = cv::saturate_cast<int>(map_x[u] * cv::INTER_TAB_SIZE);
    const int y = cv::saturate_cast<int>(map_y[u] * cv::INTER_TAB_SIZE);
    xy[2 * u] = cv::saturate_cast<int16_t>(x >> cv::INTER_BITS);
    xy[2 * u + 1] = cv::saturate_cast<int16_t>(y >> cv::INTER_BITS);
    table[u] = static_cast<uint16_t>((y & (cv::INTER_TAB_SIZE - 1)) *
                                         cv::INTER_TAB_SIZE +
                                     (x & (cv::INTER_TAB_SIZE - 1)));
  }
}

}  // namespace

Status VirtualPinholeView::Check() const {
  if (width <= 0 || height <= 0) {
    std::ostringstream message;
    message << "virtual pinhole view: size " << width << " x " << height
            << " is not positive";
    return Status::Error(message.str());
  }
  if (!k.allFinite() || !(k(0, 0) > 0.0) || !(k(1, 1) > 0.0) ||
      k(0, 1) != 0.0 || k(1, 0) != 0.0 || k(2, 0) != 0.0 || k(2, 1) != 0.0 ||
      k(2, 2) != 1.0) {
    std::ostringstream message;
    message << "virtual pinhole view: k must be [fx, 0, cx; 0, fy, cy; 0, "
               "0, 1] with finite entries and fx, fy > 0, got ["
            << k.row(0) << "; " << k.row(1) << "; " << k.row(2) << "]";
    return Status::Error(message.str());
  }
  constexpr double kRotationTolerance = 1e-9;
  if (!camera_from_view.allFinite() ||
      !(camera_from_view.transpose() * camera_from_view)
           .isIdentity(kRotationTolerance) ||
      std::abs(camera_from_view.determinant() - 1.0) > kRotationTolerance) {
    return Status::Error(
        "virtual pinhole view: camera_from_view is not a rotation");
  }
  return Status::Ok();
}

const char* VirtualPinholeFitName(VirtualPinholeFit fit) {
  switch (fit) {
    case VirtualPinholeFit::kVirtualPinhole:
      return "virtual-pinhole";
    case VirtualPinholeFit::kNoBorder:
      return "no-border";
    case VirtualPinholeFit::kFullFieldOfView:
      return "full";
  }
  return "virtual-pinhole";
}

std::optional<VirtualPinholeFit> VirtualPinholeFitFromName(
    std::string_view name) {
  for (VirtualPinholeFit fit :
       {VirtualPinholeFit::kVirtualPinhole, VirtualPinholeFit::kNoBorder,
        VirtualPinholeFit::kFullFieldOfView}) {
    if (name == VirtualPinholeFitName(fit)) return fit;
  }
  return std::nullopt;
}

VirtualPinholeView ZoomedViewFamily::At(
    double scale, const Eigen::Matrix3d& camera_from_view) const {
  const double fx = scale * base_focal.x();
  const double fy = scale * base_focal.y();
  VirtualPinholeView view;
  view.k << fx, 0.0, anchor_pixel.x() - fx * anchor_direction.x(), 0.0, fy,
      anchor_pixel.y() - fy * anchor_direction.y(), 0.0, 0.0, 1.0;
  view.width = width;
  view.height = height;
  view.camera_from_view = camera_from_view;
  return view;
}

Status ZoomedViewFamily::Check() const {
  if (width <= 0 || height <= 0) {
    std::ostringstream message;
    message << "zoomed view family: size " << width << " x " << height
            << " is not positive";
    return Status::Error(message.str());
  }
  if (!base_focal.allFinite() || !(base_focal.x() > 0.0) ||
      !(base_focal.y() > 0.0) || !anchor_pixel.allFinite() ||
      !anchor_direction.allFinite()) {
    return Status::Error(
        "zoomed view family: the base focal lengths must be finite and "
        "positive, the anchor finite");
  }
  return Status::Ok();
}

ZoomedViewFamily VirtualPinholeFamily(const RefractiveCamera& camera) {
  const Eigen::Matrix3d k_n = camera.VirtualPinholeMatrix();
  ZoomedViewFamily family;
  family.base_focal = Eigen::Vector2d(k_n(0, 0), k_n(1, 1));
  family.anchor_pixel = Eigen::Vector2d(k_n(0, 2), k_n(1, 2));
  family.width = camera.camera().width();
  family.height = camera.camera().height();
  return family;
}

StatusOr<double> FitFocalScale(const std::vector<RotatedCamera>& cameras,
                               const ZoomedViewFamily& family,
                               VirtualPinholeFit fit) {
  if (cameras.empty()) return Status::Error("no camera to fit a view to");
  RCM_RETURN_IF_ERROR(family.Check());
  for (const RotatedCamera& rotated : cameras) {
    // The view's own check covers the rotation.
    RCM_RETURN_IF_ERROR(family.At(1.0, rotated.camera_from_view).Check());
  }
  if (fit == VirtualPinholeFit::kVirtualPinhole) return 1.0;
  const std::string what =
      fit == VirtualPinholeFit::kNoBorder
          ? "no virtual pinhole view without black borders: "
          : "no virtual pinhole view with the whole field of view: ";
  if (!InsideCenters(family.anchor_pixel, family.width, family.height)) {
    return Status::Error(what + "the principal point lies outside the image");
  }
  std::variant<double, BisectionFailure> scale;
  if (fit == VirtualPinholeFit::kNoBorder) {
    scale = BisectScale(
        [&](double s) {
          for (const RotatedCamera& rotated : cameras) {
            if (!OutputBorderInsideRaw(
                    rotated.camera, family.At(s, rotated.camera_from_view))) {
              return false;
            }
          }
          return true;
        },
        /*larger_holds=*/true);
  } else {
    std::vector<std::vector<Eigen::Vector3d>> rays;
    for (const RotatedCamera& rotated : cameras) {
      Eigen::Vector2d behind;
      std::optional<std::vector<Eigen::Vector3d>> in_view =
          BorderRaysInView(rotated, &behind);
      if (!in_view) {
        std::ostringstream message;
        message << what << "raw pixel (" << behind.x() << ", " << behind.y()
                << ") sees a ray 90 degrees or more off the view axis";
        return Status::Error(message.str());
      }
      rays.push_back(std::move(*in_view));
    }
    scale = BisectScale(
        [&](double s) {
          // K(s) is the same matrix for every camera.
          const Eigen::Matrix3d k = family.At(s).k;
          for (const std::vector<Eigen::Vector3d>& camera_rays : rays) {
            for (const Eigen::Vector3d& ray : camera_rays) {
              if (!InsideCenters((k * ray).hnormalized(), family.width,
                                 family.height)) {
                return false;
              }
            }
          }
          return true;
        },
        /*larger_holds=*/false);
  }
  if (const double* found = std::get_if<double>(&scale)) return *found;
  const bool everywhere =
      std::get<BisectionFailure>(scale) == BisectionFailure::kHoldsEverywhere;
  if (fit == VirtualPinholeFit::kNoBorder) {
    // Not seen: far off axis every lens folds or refraction cuts off.
    return Status::Error(
        what + (everywhere ? "the border stays inside the image down to a "
                             "focal 1/1000 of K_n"
                           : "even a focal 1000 times K_n samples outside "
                             "the image"));
  }
  return Status::Error(
      what + (everywhere ? "the raw border stays inside the output up to a "
                           "focal 1000 times K_n"
                         : "even a focal 1/1000 of K_n leaves raw border "
                           "pixels outside the output"));
}

ViewFieldOfView FieldOfViewInView(const RotatedCamera& rotated) {
  const Camera& lens = rotated.camera.camera();
  const Eigen::Matrix3d view_from_camera = rotated.camera_from_view.transpose();
  constexpr double kInf = std::numeric_limits<double>::infinity();
  // Innermost coordinate of each edge: top (largest y), bottom (smallest
  // y), left (largest x), right (smallest x).
  std::array<double, 4> innermost = {-kInf, kInf, -kInf, kInf};
  ViewFieldOfView field;
  bool bounded = true;
  ForEachBorderPixel(lens.width(), lens.height(), [&](int u, int v, int edge) {
    const std::optional<Eigen::Vector3d> bearing =
        rotated.camera.BearingInWaterFromImage(Eigen::Vector2d(u, v));
    if (!bearing) return true;
    const Eigen::Vector3d in_view = view_from_camera * *bearing;
    if (!(in_view.z() > 0.0)) {
      bounded = false;
      return true;
    }
    const Eigen::Vector2d direction = in_view.hnormalized();
    field.outer.extend(direction);
    switch (edge) {
      case 0:
        innermost[0] = std::max(innermost[0], direction.y());
        break;
      case 1:
        innermost[1] = std::min(innermost[1], direction.y());
        break;
      case 2:
        innermost[2] = std::max(innermost[2], direction.x());
        break;
      default:
        innermost[3] = std::min(innermost[3], direction.x());
        break;
    }
    return true;
  });
  field.inner =
      Eigen::AlignedBox2d(Eigen::Vector2d(innermost[2], innermost[0]),
                          Eigen::Vector2d(innermost[3], innermost[1]));
  if (!bounded) field.outer.setEmpty();
  return field;
}

StatusOr<VirtualPinholeView> ChooseVirtualPinholeView(
    const RefractiveCamera& camera, VirtualPinholeFit fit) {
  const ZoomedViewFamily family = VirtualPinholeFamily(camera);
  const StatusOr<double> scale = FitFocalScale({{camera}}, family, fit);
  if (!scale.ok()) return scale.status();
  return family.At(*scale);
}

double VirtualPinholeFocalScale(const RefractiveCamera& camera,
                                const VirtualPinholeView& view) {
  return view.k(0, 0) / camera.VirtualPinholeMatrix()(0, 0);
}

StatusOr<RemapMaps> BuildVirtualPinholeMaps(const RefractiveCamera& camera,
                                            const VirtualPinholeView& view,
                                            int num_threads, bool fixed_point) {
  RCM_RETURN_IF_ERROR(view.Check());
  if (num_threads < 1) {
    return Status::Error("num_threads = " + std::to_string(num_threads) +
                         " must be at least 1");
  }
  const Camera& lens = camera.camera();
  const Eigen::Matrix3d virtual_from_output = VirtualFromOutput(camera, view);
  RemapMaps maps;
  maps.raw_size = cv::Size(lens.width(), lens.height());
  maps.map_x.create(view.height, view.width, CV_32FC1);
  maps.map_y.create(view.height, view.width, CV_32FC1);
  if (fixed_point) {
    maps.fixed_xy.create(view.height, view.width, CV_16SC2);
    maps.fixed_table.create(view.height, view.width, CV_16UC1);
  }
  std::vector<int64_t> invalid_per_row(view.height, 0);
  ParallelFor(view.height, num_threads, 16, [&](int64_t begin, int64_t end) {
    for (int64_t row = begin; row < end; ++row) {
      const int v = static_cast<int>(row);
      float* map_x = maps.map_x.ptr<float>(v);
      float* map_y = maps.map_y.ptr<float>(v);
      for (int u = 0; u < view.width; ++u) {
        const Eigen::Vector3d virtual_point =
            virtual_from_output * Eigen::Vector3d(u, v, 1.0);
        std::optional<Eigen::Vector2d> raw;
        if (virtual_point.z() > 0.0) {
          raw = camera.ImageFromVirtualPinhole(virtual_point.hnormalized());
        }
        if (raw && lens.InImage(*raw)) {
          map_x[u] = static_cast<float>(raw->x());
          map_y[u] = static_cast<float>(raw->y());
        } else {
          map_x[u] = -1.0f;
          map_y[u] = -1.0f;
          ++invalid_per_row[v];
        }
      }
      if (fixed_point) {
        // cv::convertMaps(..., CV_16SC2, false) row by row, here rather
        // than after the loop: it would start OpenCV's thread pool, whose
        // spinning workers then slow down these threads.
        FixedPointRow(map_x, map_y, view.width, maps.fixed_xy.ptr<int16_t>(v),
                      maps.fixed_table.ptr<uint16_t>(v));
      }
    }
  });
  for (int64_t count : invalid_per_row) maps.num_invalid += count;
  return maps;
}

cv::Mat RemapToVirtualPinhole(const cv::Mat& raw, const RemapMaps& maps) {
  cv::Mat output;
  RemapToVirtualPinhole(raw, maps, &output);
  return output;
}

void RemapToVirtualPinhole(const cv::Mat& raw, const RemapMaps& maps,
                           cv::Mat* output) {
  CHECK(raw.size() == maps.raw_size)
      << "raw image " << raw.cols << " x " << raw.rows << ", maps sample "
      << maps.raw_size.width << " x " << maps.raw_size.height;
  if (!maps.fixed_xy.empty()) {
    cv::remap(raw, *output, maps.fixed_xy, maps.fixed_table, cv::INTER_LINEAR,
              cv::BORDER_CONSTANT, cv::Scalar::all(0));
  } else {
    cv::remap(raw, *output, maps.map_x, maps.map_y, cv::INTER_LINEAR,
              cv::BORDER_CONSTANT, cv::Scalar::all(0));
  }
}

}  // namespace rcm
