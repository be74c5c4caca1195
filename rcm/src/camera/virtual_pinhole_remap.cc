#include "rcm/camera/virtual_pinhole_remap.h"

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <cmath>
#include <cstdint>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <sstream>
#include <string>
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

// The view K_n with both focal lengths scaled by `scale`.
VirtualPinholeView ScaledView(const RefractiveCamera& camera, double scale) {
  VirtualPinholeView view;
  view.k = camera.VirtualPinholeMatrix();
  view.k(0, 0) *= scale;
  view.k(1, 1) *= scale;
  view.width = camera.camera().width();
  view.height = camera.camera().height();
  return view;
}

// True when every border pixel of the scaled view samples the raw image
// inside [0, w - 1] x [0, h - 1].
bool BorderInsideRaw(const RefractiveCamera& camera, double scale) {
  const Camera& lens = camera.camera();
  const int width = lens.width();
  const int height = lens.height();
  const double cx = lens.cx();
  const double cy = lens.cy();
  auto inside = [&](int u, int v) {
    // K_n K'^-1 p' = c + (p' - c) / scale.
    const std::optional<Eigen::Vector2d> raw = camera.ImageFromVirtualPinhole(
        Eigen::Vector2d(cx + (u - cx) / scale, cy + (v - cy) / scale));
    return raw && raw->x() >= 0.0 && raw->x() <= width - 1.0 &&
           raw->y() >= 0.0 && raw->y() <= height - 1.0;
  };
  for (int u = 0; u < width; ++u) {
    if (!inside(u, 0) || !inside(u, height - 1)) return false;
  }
  for (int v = 1; v + 1 < height; ++v) {
    if (!inside(0, v) || !inside(width - 1, v)) return false;
  }
  return true;
}

StatusOr<double> NoBorderFocalScale(const RefractiveCamera& camera) {
  const Camera& lens = camera.camera();
  if (lens.cx() < 0.0 || lens.cx() > lens.width() - 1.0 || lens.cy() < 0.0 ||
      lens.cy() > lens.height() - 1.0) {
    return Status::Error(
        "no virtual pinhole view without black borders: the principal point "
        "lies outside the image");
  }
  constexpr double kMinScale = 1e-3;
  constexpr double kMaxScale = 1e3;
  // Bracket: `valid` has every border pixel inside, `invalid` not.
  double valid = 1.0;
  double invalid = 1.0;
  if (BorderInsideRaw(camera, 1.0)) {
    while (BorderInsideRaw(camera, invalid)) {
      invalid *= 0.5;
      if (invalid < kMinScale) {
        // Not seen: far off axis every lens folds or refraction cuts off.
        return Status::Error(
            "no virtual pinhole view without black borders: the border stays "
            "inside the image down to a focal 1/1000 of K_n");
      }
    }
    valid = 2.0 * invalid;
  } else {
    while (!BorderInsideRaw(camera, valid)) {
      valid *= 2.0;
      if (valid > kMaxScale) {
        return Status::Error(
            "no virtual pinhole view without black borders: even a focal "
            "1000 times K_n samples outside the image");
      }
    }
    invalid = 0.5 * valid;
  }
  while (valid - invalid > 1e-6 * valid) {
    const double middle = 0.5 * (valid + invalid);
    (BorderInsideRaw(camera, middle) ? valid : invalid) = middle;
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

StatusOr<VirtualPinholeView> ChooseVirtualPinholeView(
    const RefractiveCamera& camera, VirtualPinholeFit fit) {
  switch (fit) {
    case VirtualPinholeFit::kVirtualPinhole:
      return ScaledView(camera, 1.0);
    case VirtualPinholeFit::kNoBorder: {
      const StatusOr<double> scale = NoBorderFocalScale(camera);
      if (!scale.ok()) return scale.status();
      return ScaledView(camera, *scale);
    }
  }
  return ScaledView(camera, 1.0);
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
  CHECK(raw.size() == maps.raw_size)
      << "raw image " << raw.cols << " x " << raw.rows << ", maps sample "
      << maps.raw_size.width << " x " << maps.raw_size.height;
  cv::Mat output;
  if (!maps.fixed_xy.empty()) {
    cv::remap(raw, output, maps.fixed_xy, maps.fixed_table, cv::INTER_LINEAR,
              cv::BORDER_CONSTANT, cv::Scalar::all(0));
  } else {
    cv::remap(raw, output, maps.map_x, maps.map_y, cv::INTER_LINEAR,
              cv::BORDER_CONSTANT, cv::Scalar::all(0));
  }
  return output;
}

}  // namespace rcm
