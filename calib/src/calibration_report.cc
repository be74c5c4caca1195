#include "rcm/calib/calibration_report.h"

#include <ceres/jet.h>
#include <glog/logging.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <utility>

#include "rcm/calib/projection_uncertainty.h"
#include "rcm/io/atomic_file.h"
#include "rcm/io/image_file.h"
#include "rcm/plot/color_map.h"
#include "rcm/plot/figure.h"
#include "rcm/plot/line_plot.h"
#include "rcm/util/number_format.h"

namespace rcm::calib {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// ---------------------------------------------------------------------------
// Numbers.

bool Finite(double value) { return std::isfinite(value); }

// The q-quantile of the finite values (linear between order statistics);
// NaN when there are none.
double Quantile(std::vector<double> values, double q) {
  values.erase(std::remove_if(values.begin(), values.end(),
                              [](double v) { return !Finite(v); }),
               values.end());
  if (values.empty()) return kNaN;
  std::sort(values.begin(), values.end());
  const double position = q * static_cast<double>(values.size() - 1);
  const size_t below = static_cast<size_t>(std::floor(position));
  const size_t above = std::min(below + 1, values.size() - 1);
  const double t = position - static_cast<double>(below);
  return values[below] + t * (values[above] - values[below]);
}

// A 1-2-5 number with as many decimals as it needs.
std::string FormatNice(double value) {
  return FormatTick(value, TickDecimals(value));
}

std::string Fixed(double value, int digits) {
  return FormatFixed(value, digits);
}

std::string Percent(double fraction) {
  return std::to_string(static_cast<int>(std::lround(100.0 * fraction))) + " %";
}

std::string CameraName(int camera) { return "cam" + std::to_string(camera); }

// Cell of a pixel in a cols x rows grid over the image (file comment of
// the header); false outside the image.
bool CellOf(const Eigen::Vector2d& pixel, const ImageSize& size, int cols,
            int rows, int* col, int* row) {
  const double x = (pixel.x() + 0.5) / size.width;
  const double y = (pixel.y() + 0.5) / size.height;
  if (!(x >= 0.0 && x <= 1.0 && y >= 0.0 && y <= 1.0)) return false;
  *col = std::min(cols - 1, static_cast<int>(std::floor(x * cols)));
  *row = std::min(rows - 1, static_cast<int>(std::floor(y * rows)));
  return true;
}

// Inlier corners of a camera per cell, row-major.
std::vector<int> CellCounts(const StereoCalibration& calibration, int camera,
                            const ImageSize& size, int cols, int rows) {
  std::vector<int> counts(static_cast<size_t>(cols * rows), 0);
  for (const CornerResidual& corner : calibration.corners) {
    if (corner.camera != camera || !corner.inlier) continue;
    int col, row;
    if (CellOf(corner.pixel, size, cols, rows, &col, &row)) {
      ++counts[static_cast<size_t>(row * cols + col)];
    }
  }
  return counts;
}

// The uncertainty sample grid: centers of n_u x n_v cells of about
// kUncertaintySpacingPx, u_i = -0.5 + (i + 0.5) width / n_u.
struct SampleGrid {
  int cols = 1;
  int rows = 1;
  double width = 1.0;
  double height = 1.0;

  explicit SampleGrid(const ImageSize& size)
      : cols(std::max(1, static_cast<int>(
                             std::ceil(size.width / kUncertaintySpacingPx)))),
        rows(std::max(1, static_cast<int>(
                             std::ceil(size.height / kUncertaintySpacingPx)))),
        width(size.width),
        height(size.height) {}
  double U(int i) const { return -0.5 + (i + 0.5) * width / cols; }
  double V(int j) const { return -0.5 + (j + 0.5) * height / rows; }
};

// `sigma(pixel)` at the sample grid's centers (CV_64F, rows x cols).
template <typename Sigma>
cv::Mat SampleOverImage(const ImageSize& size, const Sigma& sigma) {
  const SampleGrid grid(size);
  cv::Mat samples(grid.rows, grid.cols, CV_64F);
  for (int j = 0; j < grid.rows; ++j) {
    for (int i = 0; i < grid.cols; ++i) {
      samples.at<double>(j, i) = sigma(Eigen::Vector2d(grid.U(i), grid.V(j)));
    }
  }
  return samples;
}

// ProjectionUncertainty at the sample grid's centers.
cv::Mat UncertaintySamples(const CameraCalibration& calibration,
                           const ImageSize& size) {
  return SampleOverImage(size, [&](const Eigen::Vector2d& pixel) {
    return ProjectionUncertainty(calibration, pixel);
  });
}

// MeanFramesProjectionUncertainty at the sample grid's centers (NaN
// everywhere without the full covariance).
cv::Mat MeanFramesSamples(const StereoCalibration& calibration, int camera,
                          double distance) {
  const Camera& c =
      camera == 0 ? calibration.cam0.camera : calibration.cam1.camera;
  return SampleOverImage({c.width(), c.height()},
                         [&](const Eigen::Vector2d& pixel) {
                           return MeanFramesProjectionUncertainty(
                               calibration, camera, pixel, distance);
                         });
}

std::vector<double> Values(const cv::Mat& samples) {
  return std::vector<double>(samples.begin<double>(), samples.end<double>());
}

// ---------------------------------------------------------------------------
// Drawing, on an rcm::Figure (rcm/plot/figure.h).

// An image-sized panel with a title strip above, a legend strip of
// `legend_lines` lines below and `extra_right` z-scaled pixels on the right.
struct PanelLayout {
  double z = 1.0;
  int width = 0;
  int height = 0;
  int margin = 0;
  // Output pixel of image pixel (0, 0).
  int panel_x = 0;
  int panel_y = 0;
  int image_width = 0;
  int image_height = 0;
  double title_baseline = 0.0;
  double legend_baseline = 0.0;  // of the first legend line
  double line_height = 0.0;

  cv::Point2d FromImage(const Eigen::Vector2d& pixel) const {
    return cv::Point2d(panel_x + pixel.x(), panel_y + pixel.y());
  }
  cv::Point2d FromImage(double u, double v) const {
    return cv::Point2d(panel_x + u, panel_y + v);
  }
  double TextWidth() const { return width - 2.0 * margin; }
  // Edges of the panel in output coordinates.
  double Left() const { return panel_x - 0.5; }
  double Top() const { return panel_y - 0.5; }
  double Right() const { return panel_x + image_width - 0.5; }
  double Bottom() const { return panel_y + image_height - 0.5; }
};

constexpr double kMinFigureWidth = 660.0;

PanelLayout MakePanelLayout(const ImageSize& size, double extra_right,
                            int legend_lines) {
  PanelLayout layout;
  layout.z = std::clamp(
      std::sqrt(static_cast<double>(size.width) * size.height / 6e5), 1.0, 2.5);
  const double z = layout.z;
  layout.margin = static_cast<int>(std::lround(14 * z));
  layout.line_height = std::round(22 * z);
  const int title = static_cast<int>(std::lround(38 * z));
  layout.panel_y = title;
  layout.image_width = size.width;
  layout.image_height = size.height;
  // At least kMinFigureWidth wide so that the text fits; a narrower panel
  // is centered.
  const int extra = static_cast<int>(std::lround(extra_right * z));
  const int natural = layout.margin + size.width + layout.margin + extra;
  layout.width =
      std::max(natural, static_cast<int>(std::lround(kMinFigureWidth * z)));
  layout.panel_x = layout.margin + (layout.width - natural) / 2;
  layout.title_baseline = std::round(25 * z);
  layout.legend_baseline = title + size.height + std::round(24 * z);
  layout.height = static_cast<int>(layout.legend_baseline +
                                   (legend_lines - 1) * layout.line_height +
                                   std::round(12 * z));
  return layout;
}

// The panel's background.
void DrawPanel(const PanelLayout& layout, Figure* figure) {
  figure->FillRect(layout.panel_x, layout.panel_y,
                   layout.panel_x + layout.image_width,
                   layout.panel_y + layout.image_height, kPanel);
}

// A cols x rows grid over the panel and its frame.
void DrawGridAndFrame(const PanelLayout& layout, int cols, int rows,
                      const cv::Scalar& grid_color, Figure* figure) {
  const double w = layout.image_width;
  const double h = layout.image_height;
  for (int i = 1; i < cols; ++i) {
    const double u = -0.5 + i * w / cols;
    figure->Line(layout.FromImage(u, -0.5), layout.FromImage(u, h - 0.5),
                 grid_color, 1.0);
  }
  for (int j = 1; j < rows; ++j) {
    const double v = -0.5 + j * h / rows;
    figure->Line(layout.FromImage(-0.5, v), layout.FromImage(w - 0.5, v),
                 grid_color, 1.0);
  }
  figure->Polyline(
      {layout.FromImage(-0.5, -0.5), layout.FromImage(w - 0.5, -0.5),
       layout.FromImage(w - 0.5, h - 0.5), layout.FromImage(-0.5, h - 0.5)},
      true, kFrame, 1.0);
}

// The viridis color of t in [0, 1] (that of 0 when t is not finite).
cv::Scalar Viridis(double t) {
  const cv::Vec3b c = ColorMapColor(cv::COLORMAP_VIRIDIS, t);
  return cv::Scalar(c[0], c[1], c[2]);
}

// Linear blend of two colors, t in [0, 1].
cv::Scalar Mix(const cv::Scalar& a, const cv::Scalar& b, double t) {
  return a * (1.0 - t) + b * t;
}

// The colour scale of the uncertainty map: logarithmic from `low` to
// `high`, where high = max_px or, for max_px = 0, the 1-2-5 number at or
// above the largest value, and low = the 1-2-5 number at or below the
// smallest positive value, at least high / 10^4 (uncertainty maps span
// decades: the center of the image is known far better than its corners).
struct UncertaintyScale {
  double low = 1e-3;
  double high = 1.0;
  // The 1-2-5 numbers in [low, high]; only the powers of ten and the ends
  // when there are more than 7.
  std::vector<double> ticks;

  UncertaintyScale(const std::vector<double>& values, double max_px) {
    double smallest = std::numeric_limits<double>::infinity();
    double largest = 0.0;
    for (const double value : values) {
      if (!Finite(value) || value <= 0.0) continue;
      smallest = std::min(smallest, value);
      largest = std::max(largest, value);
    }
    high = max_px > 0.0 ? max_px : (largest > 0.0 ? NiceCeil(largest) : 1.0);
    low = largest > 0.0 ? std::max(NiceFloor(smallest), 1e-4 * high)
                        : 1e-3 * high;
    if (!(low < high)) low = 0.1 * high;
    std::vector<double> nice;
    for (double power = std::pow(10.0, std::floor(std::log10(low)));
         power <= high * 1.000001; power *= 10.0) {
      for (const double m : {1.0, 2.0, 5.0}) {
        const double value = m * power;
        if (value >= low * 0.999999 && value <= high * 1.000001) {
          nice.push_back(value);
        }
      }
    }
    if (nice.size() > 7) {
      for (const double value : nice) {
        const double mantissa =
            value / std::pow(10.0, std::floor(std::log10(value) + 1e-9));
        if (std::abs(mantissa - 1.0) < 1e-6) ticks.push_back(value);
      }
      if (ticks.empty() || ticks.back() < high * 0.999999) {
        ticks.push_back(high);
      }
      // And low, unless its label would touch the next one.
      if (T(ticks.front()) > 0.06) ticks.insert(ticks.begin(), low);
    } else {
      ticks = nice;
    }
  }
  // Position of a value on the scale, clamped to [0, 1].
  double T(double value) const {
    if (!(value > low)) return 0.0;
    return std::min(1.0, std::log(value / low) / std::log(high / low));
  }
};

void CheckSize(const ImageSize& size) {
  CHECK_GT(size.width, 0);
  CHECK_GT(size.height, 0);
}

}  // namespace

// ---------------------------------------------------------------------------
// Uncertainty.

Eigen::Matrix<double, 2, kMaxLensParams> PixelFromParamsJacobian(
    const Camera& camera, const Eigen::Vector2d& normalized) {
  using Jet = ceres::Jet<double, kMaxLensParams>;
  Jet params[kMaxLensParams];
  for (int k = 0; k < kMaxLensParams; ++k) {
    params[k] = k < camera.num_params() ? Jet(camera.params()[k], k)
                                        : Jet(camera.params()[k]);
  }
  const Jet x(normalized.x());
  const Jet y(normalized.y());
  Jet u, v;
  RCM_LENS_MODEL_SWITCH(
      camera.model(), LensModel::ImgFromCam(params, x, y, &u, &v); break;)
  Eigen::Matrix<double, 2, kMaxLensParams> jacobian;
  jacobian.row(0) = u.v.transpose();
  jacobian.row(1) = v.v.transpose();
  return jacobian;
}

std::optional<Eigen::Matrix2d> ProjectionCovariance(
    const CameraCalibration& calibration, const Eigen::Vector2d& pixel) {
  const Camera& camera = calibration.camera;
  const std::optional<Eigen::Vector2d> normalized =
      camera.NormalizedFromImage(pixel);
  if (!normalized) return std::nullopt;
  const int n = camera.num_params();
  const Eigen::Matrix<double, 2, Eigen::Dynamic> jacobian =
      PixelFromParamsJacobian(camera, *normalized).leftCols(n);
  const Eigen::Matrix2d covariance =
      jacobian * calibration.covariance.topLeftCorner(n, n) *
      jacobian.transpose();
  return Eigen::Matrix2d(0.5 * (covariance + covariance.transpose()));
}

double ProjectionUncertainty(const CameraCalibration& calibration,
                             const Eigen::Vector2d& pixel) {
  const std::optional<Eigen::Matrix2d> covariance =
      ProjectionCovariance(calibration, pixel);
  if (!covariance) return kNaN;
  // Largest eigenvalue of [[a, b], [b, c]].
  const double a = (*covariance)(0, 0);
  const double b = (*covariance)(0, 1);
  const double c = (*covariance)(1, 1);
  const double largest = 0.5 * (a + c) + std::hypot(0.5 * (a - c), b);
  return std::sqrt(std::max(largest, 0.0));
}

// ---------------------------------------------------------------------------
// Summary.

Status CalibrationReportOptions::Check() const {
  if (!(uncertainty_distance_m > 0.0)) {
    return Status::Error("uncertainty_distance_m must be positive, got " +
                         FormatDouble(uncertainty_distance_m));
  }
  if (coverage_cols < 1 || coverage_rows < 1) {
    return Status::Error("coverage grid needs at least 1x1 cells, got " +
                         std::to_string(coverage_cols) + "x" +
                         std::to_string(coverage_rows));
  }
  if (!(min_coverage >= 0.0 && min_coverage <= 1.0)) {
    return Status::Error("min_coverage must lie in [0, 1], got " +
                         FormatDouble(min_coverage));
  }
  if (min_views < 0 || min_stereo_views < 0) {
    return Status::Error("min_views and min_stereo_views must be >= 0");
  }
  if (!(max_uncertainty_px > 0.0 && Finite(max_uncertainty_px))) {
    return Status::Error(
        "max_uncertainty_px must be positive and finite, got " +
        FormatDouble(max_uncertainty_px));
  }
  if (!(max_view_rms_factor > 0.0 && Finite(max_view_rms_factor))) {
    return Status::Error(
        "max_view_rms_factor must be positive and finite, got " +
        FormatDouble(max_view_rms_factor));
  }
  return Status::Ok();
}

CalibrationReport SummarizeCalibration(
    const StereoCalibration& calibration, const std::vector<StereoView>& views,
    const ImageSize& cam0_size, const ImageSize& cam1_size,
    const CalibrationReportOptions& options) {
  const Status valid = options.Check();
  CHECK(valid.ok()) << valid.message();
  const int num_cameras = calibration.num_cameras;
  CheckSize(cam0_size);
  if (num_cameras == 2) CheckSize(cam1_size);
  CHECK_EQ(calibration.cam0_from_target.size(), views.size())
      << "cam0_from_target has one entry per input view";
  const ImageSize sizes[2] = {cam0_size, cam1_size};
  const CameraCalibration* cameras[2] = {&calibration.cam0, &calibration.cam1};

  CalibrationReport report;
  report.num_cameras = num_cameras;
  const int num_views = static_cast<int>(views.size());
  report.views.resize(views.size());
  std::vector<std::array<double, 2>> view_ssr(views.size(), {0.0, 0.0});
  double ssr[2] = {0.0, 0.0};
  double inlier_ssr[2] = {0.0, 0.0};
  for (const CornerResidual& corner : calibration.corners) {
    CHECK(corner.camera >= 0 && corner.camera < num_cameras) << corner.camera;
    CHECK(corner.view >= 0 && corner.view < num_views) << corner.view;
    const int c = corner.camera;
    const double squared = corner.residual.squaredNorm();
    CalibrationReport::View& view = report.views[corner.view];
    ++view.corners[c];
    view_ssr[corner.view][c] += squared;
    ++report.cameras[c].corners;
    ssr[c] += squared;
    if (corner.inlier) {
      inlier_ssr[c] += squared;
    } else {
      ++view.outliers[c];
      ++report.cameras[c].outliers;
    }
  }

  for (int c = 0; c < num_cameras; ++c) {
    CalibrationReport::CameraStats& stats = report.cameras[c];
    const int inliers = stats.corners - stats.outliers;
    stats.rms_px = stats.corners > 0 ? std::sqrt(ssr[c] / stats.corners) : kNaN;
    stats.inlier_rms_px =
        inliers > 0 ? std::sqrt(inlier_ssr[c] / inliers) : kNaN;
    const std::vector<int> counts = CellCounts(
        calibration, c, sizes[c], options.coverage_cols, options.coverage_rows);
    stats.coverage =
        static_cast<double>(std::count_if(counts.begin(), counts.end(),
                                          [](int n) { return n > 0; })) /
        static_cast<double>(counts.size());
    const std::vector<double> samples =
        Values(UncertaintySamples(*cameras[c], sizes[c]));
    stats.intrinsics_only_uncertainty_median_px = Quantile(samples, 0.5);
    stats.intrinsics_only_uncertainty_p95_px = Quantile(samples, 0.95);
    stats.intrinsics_only_uncertainty_max_px = Quantile(samples, 1.0);
    const std::vector<double> mean_frames = Values(
        MeanFramesSamples(calibration, c, options.uncertainty_distance_m));
    stats.projection_uncertainty_median_px = Quantile(mean_frames, 0.5);
    stats.projection_uncertainty_p95_px = Quantile(mean_frames, 0.95);
    stats.projection_uncertainty_max_px = Quantile(mean_frames, 1.0);
    stats.view_rms_limit_px = options.max_view_rms_factor * stats.rms_px;
  }

  for (int v = 0; v < num_views; ++v) {
    CalibrationReport::View& view = report.views[v];
    view.view = v;
    view.left_name = views[v].left_name;
    view.right_name = views[v].right_name;
    view.used = calibration.cam0_from_target[v].has_value();
    for (int c = 0; c < 2; ++c) {
      view.rms_px[c] = view.corners[c] > 0
                           ? std::sqrt(view_ssr[v][c] / view.corners[c])
                           : kNaN;
      if (view.used && view.rms_px[c] > report.cameras[c].view_rms_limit_px) {
        view.flagged = true;
      }
    }
    if (view.used) {
      ++report.num_views_used;
      if (view.corners[0] > 0 && view.corners[1] > 0) {
        ++report.num_stereo_views_used;
      }
    }
  }

  // Warnings, in plain words.
  std::vector<std::string>& warnings = report.warnings;
  if (!calibration.full_covariance_note.empty()) {
    warnings.push_back(calibration.full_covariance_note);
  }
  if (report.num_views_used < options.min_views) {
    warnings.push_back("only " + std::to_string(report.num_views_used) +
                       " views used (" + std::to_string(options.min_views) +
                       " or more recommended); add views of the target at " +
                       "other distances, positions and tilts");
  }
  if (num_cameras == 2 &&
      report.num_stereo_views_used < options.min_stereo_views) {
    warnings.push_back(
        "only " + std::to_string(report.num_stereo_views_used) +
        " used views show the target in both cameras (" +
        std::to_string(options.min_stereo_views) +
        " or more recommended); the extrinsics rest on them: add views both " +
        "cameras see");
  }
  const std::string grid = std::to_string(options.coverage_cols) + "x" +
                           std::to_string(options.coverage_rows);
  for (int c = 0; c < num_cameras; ++c) {
    const CalibrationReport::CameraStats& stats = report.cameras[c];
    if (stats.coverage < options.min_coverage) {
      warnings.push_back(CameraName(c) + ": corners cover " +
                         Percent(stats.coverage) + " of the image (" + grid +
                         " grid); add views near the corners and edges");
    }
  }
  for (int c = 0; c < num_cameras; ++c) {
    const CalibrationReport::CameraStats& stats = report.cameras[c];
    if (stats.intrinsics_only_uncertainty_p95_px > options.max_uncertainty_px) {
      warnings.push_back(
          CameraName(c) + ": intrinsics-only projection uncertainty " +
          Fixed(stats.intrinsics_only_uncertainty_p95_px, 2) +
          " px over 95 % of the image (max " +
          Fixed(stats.intrinsics_only_uncertainty_max_px, 2) + " px), above " +
          FormatDouble(options.max_uncertainty_px) +
          " px; the intrinsics are poorly constrained: add views that fill " +
          "the image, closer and tilted");
    }
  }
  for (const CalibrationReport::View& view : report.views) {
    if (!view.flagged) continue;
    std::string line = "view " + std::to_string(view.view);
    if (num_cameras == 1 && !view.left_name.empty()) {
      line += " (" + view.left_name + ")";
    } else if (!view.left_name.empty() || !view.right_name.empty()) {
      line += " (" + view.left_name + ", " + view.right_name + ")";
    }
    line += ":";
    bool first = true;
    for (int c = 0; c < num_cameras; ++c) {
      const CalibrationReport::CameraStats& stats = report.cameras[c];
      if (!(view.rms_px[c] > stats.view_rms_limit_px)) continue;
      const std::string outliers =
          view.outliers[c] == 0
              ? ""
              : " (" + std::to_string(view.outliers[c]) +
                    (view.outliers[c] == 1 ? " outlier)" : " outliers)");
      line += std::string(first ? "" : ",") + " RMS " +
              Fixed(view.rms_px[c], 2) + " px in " + CameraName(c) + outliers +
              ", " + Fixed(view.rms_px[c] / stats.rms_px, 1) +
              " times the camera's " + Fixed(stats.rms_px, 2) + " px";
      first = false;
    }
    line += "; check its detection or drop the view";
    warnings.push_back(line);
  }
  return report;
}

// ---------------------------------------------------------------------------
// Pictures.

cv::Mat DrawResidualField(const StereoCalibration& calibration, int camera,
                          const ImageSize& size, double arrow_scale, int cols,
                          int rows) {
  CHECK(camera == 0 || camera == 1) << camera;
  CheckSize(size);
  CHECK(Finite(arrow_scale) && arrow_scale >= 0.0) << arrow_scale;
  CHECK_GT(cols, 0);
  CHECK_GT(rows, 0);

  std::vector<const CornerResidual*> corners;
  std::vector<double> inlier_norms, all_norms;
  double ssr = 0.0, inlier_ssr = 0.0;
  int outliers = 0;
  for (const CornerResidual& corner : calibration.corners) {
    if (corner.camera != camera) continue;
    corners.push_back(&corner);
    const double norm = corner.residual.norm();
    all_norms.push_back(norm);
    ssr += norm * norm;
    if (corner.inlier) {
      inlier_norms.push_back(norm);
      inlier_ssr += norm * norm;
    } else {
      ++outliers;
    }
  }
  const double p95 =
      Quantile(inlier_norms.empty() ? all_norms : inlier_norms, 0.95);
  if (arrow_scale == 0.0) {
    arrow_scale = p95 > 0.0 ? NiceFloor(0.03 * size.width / p95) : 1.0;
  }
  // The scale bar: a 1-2-5 residual drawn about 4 % of the width long.
  const double bar_value = NiceNearest(0.04 * size.width / arrow_scale);
  const double bar_length = bar_value * arrow_scale;

  const PanelLayout layout = MakePanelLayout(size, 0.0, 2);
  Figure figure(layout.width, layout.height, layout.z);
  const double z = layout.z;
  DrawPanel(layout, &figure);
  DrawGridAndFrame(layout, cols, rows, kGridLine, &figure);

  const cv::Scalar inlier_color = PaletteColor(0);
  const cv::Scalar outlier_color = PaletteColor(3);
  const cv::Scalar mean_color = PaletteColor(1);
  const cv::Scalar dot_color(70, 70, 70);
  figure.Clip(layout.Left(), layout.Top(), layout.Right(), layout.Bottom());
  // Inliers first, outliers on top.
  for (const bool inliers : {true, false}) {
    for (const CornerResidual* corner : corners) {
      if (corner->inlier != inliers) continue;
      const cv::Point2d at = layout.FromImage(corner->pixel);
      const cv::Point2d tip =
          layout.FromImage(corner->pixel + arrow_scale * corner->residual);
      if (inliers) {
        figure.Arrow(at, tip, inlier_color, 1.0);
        figure.Disc(at, 1.3 * z, dot_color);
      } else {
        figure.Arrow(at, tip, outlier_color, 1.3);
        figure.Disc(at, 2.0 * z, outlier_color);
      }
    }
  }
  // Mean inlier residual per cell.
  std::vector<Eigen::Vector2d> sums(static_cast<size_t>(cols * rows),
                                    Eigen::Vector2d::Zero());
  std::vector<int> counts(sums.size(), 0);
  for (const CornerResidual* corner : corners) {
    int col, row;
    if (!corner->inlier ||
        !CellOf(corner->pixel, size, cols, rows, &col, &row)) {
      continue;
    }
    sums[row * cols + col] += corner->residual;
    ++counts[row * cols + col];
  }
  // Means average the noise down: they get their own magnification, at
  // which the largest draws 40 % of a cell long (never below arrow_scale).
  constexpr int kMinCellCorners = 3;
  double largest_mean = 0.0;
  for (size_t k = 0; k < sums.size(); ++k) {
    if (counts[k] >= kMinCellCorners) {
      largest_mean = std::max(largest_mean, sums[k].norm() / counts[k]);
    }
  }
  const double cell_px = std::min(static_cast<double>(size.width) / cols,
                                  static_cast<double>(size.height) / rows);
  const double mean_scale =
      largest_mean > 0.0
          ? std::max(arrow_scale, NiceFloor(0.4 * cell_px / largest_mean))
          : arrow_scale;
  for (int row = 0; row < rows; ++row) {
    for (int col = 0; col < cols; ++col) {
      const int n = counts[row * cols + col];
      if (n < kMinCellCorners) continue;
      const Eigen::Vector2d center(-0.5 + (col + 0.5) * size.width / cols,
                                   -0.5 + (row + 0.5) * size.height / rows);
      const Eigen::Vector2d mean = sums[row * cols + col] / n;
      figure.Arrow(layout.FromImage(center),
                   layout.FromImage(center + mean_scale * mean), kWhite, 4.6);
      figure.Arrow(layout.FromImage(center),
                   layout.FromImage(center + mean_scale * mean), mean_color,
                   2.6);
      figure.Disc(layout.FromImage(center), 2.2 * z, mean_color);
    }
  }

  figure.Unclip();
  const int inliers = static_cast<int>(inlier_norms.size());
  const std::string title =
      CameraName(camera) +
      " residuals (projected - measured): " + std::to_string(corners.size()) +
      " corners, " + std::to_string(outliers) + " outliers; RMS " +
      Fixed(corners.empty() ? kNaN : std::sqrt(ssr / corners.size()), 3) +
      " px, inliers " +
      Fixed(inliers > 0 ? std::sqrt(inlier_ssr / inliers) : kNaN, 3) + " px";
  figure.Text(title, cv::Point2d(layout.margin, layout.title_baseline),
              kTitleFont, kInk, layout.TextWidth());

  // Legend: glyphs, then the scale bar.
  const double y0 = layout.legend_baseline;
  const double mid = -5.0 * z;  // glyph center above the baseline
  double x = layout.margin;
  const double glyph = 18.0 * z;
  const auto entry = [&](const cv::Scalar& color, double width, double dot,
                         const cv::Scalar& dot_fill, const std::string& text) {
    figure.Arrow(cv::Point2d(x, y0 + mid), cv::Point2d(x + glyph, y0 + mid),
                 color, width);
    figure.Disc(cv::Point2d(x, y0 + mid), dot, dot_fill);
    x += glyph + 6.0 * z;
    x += figure.Text(text, cv::Point2d(x, y0), kTextFont, kInk) + 16.0 * z;
  };
  entry(inlier_color, 1.0, 1.3 * z, dot_color, "inlier corner");
  entry(outlier_color, 1.3, 2.0 * z, outlier_color, "outlier");
  entry(mean_color, 2.6, 2.2 * z, mean_color,
        "mean of a cell (" + std::to_string(kMinCellCorners) + "+ inliers), x" +
            FormatNice(mean_scale));
  const double y1 = y0 + layout.line_height;
  x = layout.margin;
  figure.Line(cv::Point2d(x, y1 + mid), cv::Point2d(x + bar_length, y1 + mid),
              kInk, 2.0);
  figure.Line(cv::Point2d(x, y1 + mid - 4 * z),
              cv::Point2d(x, y1 + mid + 4 * z), kInk, 1.0);
  figure.Line(cv::Point2d(x + bar_length, y1 + mid - 4 * z),
              cv::Point2d(x + bar_length, y1 + mid + 4 * z), kInk, 1.0);
  x += bar_length + 8.0 * z;
  const std::string length_text =
      bar_length >= 10.0 ? Fixed(bar_length, 0) : Fixed(bar_length, 1);
  figure.Text(
      "arrows x" + FormatNice(arrow_scale) + ": " + length_text +
          " px = " + FormatNice(bar_value) +
          " px of residual; 95 % of the inliers below " + Fixed(p95, 3) + " px",
      cv::Point2d(x, y1), kTextFont, kInk, layout.width - layout.margin - x);
  return figure.Finish();
}

cv::Mat DrawCoverage(const StereoCalibration& calibration,
                     const std::vector<StereoView>& views, int camera,
                     const ImageSize& size, int cols, int rows) {
  CHECK(camera == 0 || camera == 1) << camera;
  CheckSize(size);
  CHECK_GT(cols, 0);
  CHECK_GT(rows, 0);
  const int num_views = static_cast<int>(views.size());
  const auto used = [&](int v) {
    return v < static_cast<int>(calibration.cam0_from_target.size()) &&
           calibration.cam0_from_target[v].has_value();
  };

  const std::vector<int> counts =
      CellCounts(calibration, camera, size, cols, rows);
  const int max_count = *std::max_element(counts.begin(), counts.end());
  const int covered = static_cast<int>(
      std::count_if(counts.begin(), counts.end(), [](int n) { return n > 0; }));

  const PanelLayout layout = MakePanelLayout(size, 0.0, 2);
  Figure figure(layout.width, layout.height, layout.z);
  const double z = layout.z;
  DrawPanel(layout, &figure);
  // Cells: empty ones tinted red, the others from white to light blue by
  // count.
  const cv::Scalar empty_cell(232, 232, 252);
  const cv::Scalar low_cell(252, 252, 252);
  const cv::Scalar high_cell(228, 196, 150);
  for (int row = 0; row < rows; ++row) {
    for (int col = 0; col < cols; ++col) {
      const int n = counts[row * cols + col];
      const cv::Scalar color =
          n == 0 ? empty_cell
                 : Mix(low_cell, high_cell,
                       std::sqrt(static_cast<double>(n) / max_count));
      figure.FillArea(layout.panel_x - 0.5 + col * size.width / cols,
                      layout.panel_y - 0.5 + row * size.height / rows,
                      layout.panel_x - 0.5 + (col + 1) * size.width / cols,
                      layout.panel_y - 0.5 + (row + 1) * size.height / rows,
                      color);
    }
  }
  DrawGridAndFrame(layout, cols, rows, kGridLine, &figure);

  figure.Clip(layout.Left(), layout.Top(), layout.Right(), layout.Bottom());
  // Views: detections the calibration did not use in gray, the used ones'
  // corners (as the solve saw them) in the palette.
  const auto hull = [&](const std::vector<Eigen::Vector2d>& pixels,
                        const cv::Scalar& color, double width) {
    if (pixels.empty()) return;
    std::vector<cv::Point2f> points;
    for (const Eigen::Vector2d& p : pixels) {
      const cv::Point2d at = layout.FromImage(p);
      points.emplace_back(static_cast<float>(at.x), static_cast<float>(at.y));
    }
    std::vector<cv::Point2f> outline;
    cv::convexHull(points, outline);
    std::vector<cv::Point2d> polygon(outline.begin(), outline.end());
    figure.Polyline(polygon, true, color, width);
  };
  int unused_with_target = 0;
  for (int v = 0; v < num_views; ++v) {
    if (used(v)) continue;
    const std::optional<TargetObservation>& observation =
        camera == 0 ? views[v].left : views[v].right;
    if (!observation || observation->pixels.empty()) continue;
    ++unused_with_target;
    hull(observation->pixels, cv::Scalar(150, 150, 150), 1.0);
  }
  std::vector<std::vector<Eigen::Vector2d>> per_view(
      static_cast<size_t>(std::max(num_views, 0)));
  for (const CornerResidual& corner : calibration.corners) {
    if (corner.camera != camera || corner.view < 0 ||
        corner.view >= num_views) {
      continue;
    }
    per_view[corner.view].push_back(corner.pixel);
  }
  int drawn_views = 0;
  for (int v = 0; v < num_views; ++v) {
    if (per_view[v].empty()) continue;
    ++drawn_views;
    const cv::Scalar color = PaletteColor(v);
    hull(per_view[v], color, 1.4);
    for (const Eigen::Vector2d& p : per_view[v]) {
      figure.Disc(layout.FromImage(p), 1.2 * z, color);
    }
  }
  // Counts on top.
  for (int row = 0; row < rows; ++row) {
    for (int col = 0; col < cols; ++col) {
      const cv::Point2d center =
          layout.FromImage(-0.5 + (col + 0.5) * size.width / cols,
                           -0.5 + (row + 0.5) * size.height / rows);
      figure.Label(std::to_string(counts[row * cols + col]), center, kSmallFont,
                   kInk, cv::Scalar(255, 255, 255));
    }
  }

  figure.Unclip();
  const double fraction = static_cast<double>(covered) / counts.size();
  figure.Text(CameraName(camera) + " coverage: " + std::to_string(covered) +
                  " of " + std::to_string(counts.size()) + " cells (" +
                  Percent(fraction) + ") hold an inlier corner, " +
                  std::to_string(cols) + "x" + std::to_string(rows) + " grid",
              cv::Point2d(layout.margin, layout.title_baseline), kTitleFont,
              kInk, layout.TextWidth());
  figure.Text(
      "cells: inlier corners, count printed (red: none); outlines: "
      "each used view's corners, colour by view index",
      cv::Point2d(layout.margin, layout.legend_baseline), kTextFont, kInk,
      layout.TextWidth());
  figure.Text(
      std::to_string(drawn_views) +
          (drawn_views == 1 ? " used view" : " used views") +
          (unused_with_target > 0
               ? "; gray: the target in " + std::to_string(unused_with_target) +
                     (unused_with_target == 1 ? " view" : " views") +
                     " the calibration did not use"
               : "; every view showing the target in this camera was "
                 "used"),
      cv::Point2d(layout.margin, layout.legend_baseline + layout.line_height),
      kTextFont, kMuted, layout.TextWidth());
  return figure.Finish();
}

namespace {

// The heat map of DrawProjectionUncertainty for any samples over the
// image: `what` follows the camera's name in the title ("<what>: median
// ..."), `legend` is the legend's first words.
cv::Mat DrawUncertaintyMap(const cv::Mat& samples, const ImageSize& size,
                           double max_px, const std::string& camera_name,
                           const std::string& what, const std::string& legend) {
  CHECK(Finite(max_px) && max_px >= 0.0) << max_px;
  CheckSize(size);
  const std::vector<double> values = Values(samples);
  const double largest = Quantile(values, 1.0);
  const UncertaintyScale scale(values, max_px);

  // Bilinear interpolation of the samples at every pixel; NaN next to a
  // sample without a value.
  const SampleGrid grid(size);
  cv::Mat field(size.height, size.width, CV_64F);
  const auto axis = [](double pixel, double extent, int n, int* i0, double* t) {
    const double s = std::clamp((pixel + 0.5) * n / extent - 0.5, 0.0, n - 1.0);
    *i0 = std::min(static_cast<int>(std::floor(s)), std::max(n - 2, 0));
    *t = n > 1 ? s - *i0 : 0.0;
  };
  for (int v = 0; v < size.height; ++v) {
    int j0;
    double tv;
    axis(v, size.height, grid.rows, &j0, &tv);
    const int j1 = std::min(j0 + 1, grid.rows - 1);
    for (int u = 0; u < size.width; ++u) {
      int i0;
      double tu;
      axis(u, size.width, grid.cols, &i0, &tu);
      const int i1 = std::min(i0 + 1, grid.cols - 1);
      double value = 0.0;
      const double weights[4] = {(1 - tu) * (1 - tv), tu * (1 - tv),
                                 (1 - tu) * tv, tu * tv};
      const double corners[4] = {
          samples.at<double>(j0, i0), samples.at<double>(j0, i1),
          samples.at<double>(j1, i0), samples.at<double>(j1, i1)};
      for (int k = 0; k < 4; ++k) {
        if (weights[k] > 0.0) value += weights[k] * corners[k];
      }
      field.at<double>(v, u) = value;
    }
  }
  cv::Mat heat(size.height, size.width, CV_8UC3);
  cv::Mat valid(size.height, size.width, CV_8UC1);
  for (int v = 0; v < size.height; ++v) {
    for (int u = 0; u < size.width; ++u) {
      const double value = field.at<double>(v, u);
      const bool finite = Finite(value);
      valid.at<unsigned char>(v, u) = finite ? 255 : 0;
      const cv::Scalar color = finite ? Viridis(scale.T(value)) : kNoData;
      heat.at<cv::Vec3b>(v, u) =
          cv::Vec3b(static_cast<unsigned char>(color[0]),
                    static_cast<unsigned char>(color[1]),
                    static_cast<unsigned char>(color[2]));
    }
  }

  const PanelLayout layout = MakePanelLayout(size, 90.0, 1);
  Figure figure(layout.width, layout.height, layout.z);
  const double z = layout.z;
  figure.Paste(heat, layout.panel_x, layout.panel_y);

  figure.Clip(layout.Left(), layout.Top(), layout.Right(), layout.Bottom());
  // Iso-lines at the interior ticks: boundaries of {field >= level},
  // without the stretches along the image border or next to pixels
  // without a value.
  cv::Mat invalid_near;
  cv::erode(valid, invalid_near, cv::Mat::ones(3, 3, CV_8UC1));
  const auto drawable = [&](const cv::Point& p) {
    return p.x > 0 && p.y > 0 && p.x < size.width - 1 &&
           p.y < size.height - 1 && invalid_near.at<unsigned char>(p) != 0;
  };
  const cv::Scalar iso_color(255, 255, 255);
  std::vector<std::pair<std::string, cv::Point2d>> labels;
  for (const double level : scale.ticks) {
    if (!(level > scale.low && level < scale.high)) continue;
    cv::Mat mask = cv::Mat::zeros(size.height, size.width, CV_8UC1);
    for (int v = 0; v < size.height; ++v) {
      for (int u = 0; u < size.width; ++u) {
        if (field.at<double>(v, u) >= level) mask.at<unsigned char>(v, u) = 255;
      }
    }
    std::vector<std::vector<cv::Point>> contours;
    cv::findContours(mask, contours, cv::RETR_LIST, cv::CHAIN_APPROX_NONE);
    // The label goes where the line crosses the ray from the image center
    // to its top-left corner (labels of nested lines line up along it), or
    // failing that at the line's first point away from the border.
    const Eigen::Vector2d center(0.5 * (size.width - 1),
                                 0.5 * (size.height - 1));
    const Eigen::Vector2d ray = (-center).normalized();
    const double label_margin = 14.0 * z;
    double best_cost = std::numeric_limits<double>::infinity();
    std::optional<cv::Point> label_at;
    for (const std::vector<cv::Point>& contour : contours) {
      // The closed contour, split where it is not drawable.
      std::vector<cv::Point2d> piece;
      const size_t n = contour.size();
      for (size_t k = 0; k <= n; ++k) {
        const cv::Point& p = contour[k % n];
        if (!drawable(p)) {
          figure.Polyline(piece, false, iso_color, 1.0);
          piece.clear();
          continue;
        }
        piece.push_back(layout.FromImage(p.x, p.y));
        if (p.x < label_margin || p.y < label_margin ||
            p.x > size.width - label_margin ||
            p.y > size.height - label_margin) {
          continue;
        }
        const Eigen::Vector2d d = Eigen::Vector2d(p.x, p.y) - center;
        const double along = d.dot(ray);
        const double cost = along > 0.0
                                ? std::abs(d.x() * ray.y() - d.y() * ray.x())
                                : 1e6 + d.norm();
        if (cost < best_cost) {
          best_cost = cost;
          label_at = p;
        }
      }
      figure.Polyline(piece, false, iso_color, 1.0);
    }
    if (label_at) {
      labels.emplace_back(FormatShort(level),
                          layout.FromImage(label_at->x, label_at->y));
    }
  }
  // Labels over every line.
  for (const auto& [text, at] : labels) {
    figure.Label(text, at, kSmallFont, kInk, cv::Scalar(255, 255, 255));
  }
  figure.Unclip();
  DrawGridAndFrame(layout, 1, 1, kGridLine, &figure);

  // Color bar, high values on top.
  const double bar_x = layout.panel_x + size.width + 16.0 * z;
  const double bar_w = 18.0 * z;
  const double bar_top = layout.panel_y + 18.0 * z;
  const double bar_bottom = layout.panel_y + size.height - 1.0;
  const int bar_rows = static_cast<int>(std::lround(bar_bottom - bar_top));
  for (int k = 0; k <= bar_rows; ++k) {
    const double y = bar_top + k;
    figure.FillArea(bar_x, y - 0.5, bar_x + bar_w, y + 0.5,
                    Viridis(1.0 - static_cast<double>(k) / bar_rows));
  }
  figure.Polyline({{bar_x, bar_top},
                   {bar_x + bar_w, bar_top},
                   {bar_x + bar_w, bar_bottom},
                   {bar_x, bar_bottom}},
                  true, kFrame, 1.0);
  for (const double tick : scale.ticks) {
    const double y = bar_bottom - scale.T(tick) * (bar_bottom - bar_top);
    figure.Line({bar_x + bar_w, y}, {bar_x + bar_w + 4.0 * z, y}, kFrame, 1.0);
    figure.Text(FormatShort(tick), {bar_x + bar_w + 7.0 * z, y + 5.0 * z},
                kTextFont, kInk);
  }
  figure.Text("px", {bar_x, bar_top - 7.0 * z}, kTextFont, kInk);

  const double median = Quantile(values, 0.5);
  const double p95 = Quantile(values, 0.95);
  figure.Text((camera_name.empty() ? "" : camera_name + " ") + what +
                  ": median " + Fixed(median, 3) + ", 95 % " + Fixed(p95, 3) +
                  ", max " + Fixed(largest, 3) + " px",
              cv::Point2d(layout.margin, layout.title_baseline), kTitleFont,
              kInk, layout.TextWidth());
  figure.Text(legend + "; log scale" +
                  std::string(values.size() > 0 &&
                                      std::any_of(values.begin(), values.end(),
                                                  [](double value) {
                                                    return !Finite(value);
                                                  })
                                  ? "; gray: no ray"
                                  : ""),
              cv::Point2d(layout.margin, layout.legend_baseline), kTextFont,
              kInk, layout.TextWidth());
  return figure.Finish();
}

}  // namespace

std::string DistanceName(double distance_m) {
  return std::isinf(distance_m) ? "infinity" : FormatDouble(distance_m) + " m";
}

cv::Mat DrawProjectionUncertainty(const CameraCalibration& calibration,
                                  double max_px,
                                  const std::string& camera_name) {
  const ImageSize size{calibration.camera.width(), calibration.camera.height()};
  CheckSize(size);
  return DrawUncertaintyMap(
      UncertaintySamples(calibration, size), size, max_px, camera_name,
      "intrinsics-only projection uncertainty (1 sigma, the ray held fixed "
      "in the camera)",
      "per pixel: sqrt of the largest eigenvalue of J C J^T, J = d pixel / d "
      "intrinsics at the pixel's ray, C the intrinsics' covariance");
}

cv::Mat DrawMeanFramesUncertainty(const StereoCalibration& calibration,
                                  int camera, double distance_m, double max_px,
                                  const std::string& camera_name) {
  CHECK(camera == 0 || camera == 1) << camera;
  const Camera& c =
      camera == 0 ? calibration.cam0.camera : calibration.cam1.camera;
  return DrawUncertaintyMap(
      MeanFramesSamples(calibration, camera, distance_m),
      {c.width(), c.height()}, max_px, camera_name,
      "projection uncertainty at " + DistanceName(distance_m) +
          " (1 sigma, mrcal's mean-frames)",
      "per pixel: sqrt of the largest eigenvalue of J Var(b) J^T, q(b) = the "
      "point at that distance held fixed to the mean of the board poses, b "
      "every unknown");
}

cv::Mat DrawPerViewRms(const CalibrationReport& report) {
  constexpr double kCameraOffset = 0.15;
  // One camera: its markers on the view's number.
  const double offset = report.num_cameras == 2 ? kCameraOffset : 0.0;
  LinePlot plot;
  const int num_views = static_cast<int>(report.views.size());
  int flagged = 0;
  std::vector<double> x;
  std::vector<double> rms[2];
  std::vector<double> flagged_x, flagged_y, unused_x, unused_y;
  double top = 0.0;
  for (const CalibrationReport::View& view : report.views) {
    x.push_back(view.view);
    for (int c = 0; c < report.num_cameras; ++c) {
      const double value = view.used ? view.rms_px[c] : kNaN;
      rms[c].push_back(value);
      if (Finite(value)) top = std::max(top, value);
      if (view.flagged && value > report.cameras[c].view_rms_limit_px) {
        flagged_x.push_back(view.view + (c == 0 ? -offset : offset));
        flagged_y.push_back(value);
      }
    }
    if (view.flagged) ++flagged;
    if (!view.used) {
      unused_x.push_back(view.view);
      unused_y.push_back(0.0);
    }
  }
  for (int c = 0; c < report.num_cameras; ++c) {
    const double limit = report.cameras[c].view_rms_limit_px;
    if (Finite(limit)) top = std::max(top, limit);
  }
  plot.SetTitle("RMS reprojection error per view: " +
                std::to_string(report.num_views_used) + " of " +
                std::to_string(num_views) + " views used, " +
                std::to_string(flagged) + " flagged");
  plot.SetXLabel("view");
  plot.SetYLabel("RMS [px]");
  // At least 20 views wide, so that the ticks are whole view numbers.
  const int span = std::max(num_views, 20);
  plot.SetXRange(-0.5 - 0.02 * span, span - 0.5 + 0.02 * span);
  plot.SetYRange(0.0, top > 0.0 ? 1.12 * top : 1.0);
  plot.SetLegendPosition(LegendPosition::kBelow);
  for (int c = 0; c < report.num_cameras; ++c) {
    MarkerStyle style;
    style.color = PaletteColor(c);
    style.shape = c == 0 ? MarkerShape::kCircle : MarkerShape::kSquare;
    style.radius = 4.0;
    if (!x.empty()) {
      // cam0 a little left of the view's number, cam1 right, so that equal
      // values do not hide each other.
      std::vector<double> shifted = x;
      for (double& value : shifted) value += c == 0 ? -offset : offset;
      plot.AddMarkers(shifted, rms[c], c == 0 ? "cam0 (left)" : "cam1 (right)",
                      style);
    }
  }
  for (int c = 0; c < report.num_cameras; ++c) {
    const CalibrationReport::CameraStats& stats = report.cameras[c];
    LineStyle overall;
    overall.color = PaletteColor(c);
    overall.width = 1.2;
    if (Finite(stats.rms_px)) {
      plot.AddHorizontalLine(
          stats.rms_px,
          CameraName(c) + " overall " + Fixed(stats.rms_px, 3) + " px",
          overall);
    }
    LineStyle limit = overall;
    limit.dash = 8.0;
    if (Finite(stats.view_rms_limit_px)) {
      plot.AddHorizontalLine(stats.view_rms_limit_px,
                             CameraName(c) + " flag limit " +
                                 Fixed(stats.view_rms_limit_px, 3) + " px",
                             limit);
    }
  }
  if (!flagged_x.empty()) {
    MarkerStyle style;
    style.color = PaletteColor(3);
    style.shape = MarkerShape::kCross;
    style.radius = 8.0;
    plot.AddMarkers(flagged_x, flagged_y, "flagged", style);
  }
  if (!unused_x.empty()) {
    MarkerStyle style;
    style.color = cv::Scalar(150, 150, 150);
    style.shape = MarkerShape::kDiamond;
    style.radius = 4.0;
    plot.AddMarkers(unused_x, unused_y, "not used", style);
  }
  return plot.Render(1000, 600);
}

// ---------------------------------------------------------------------------
// Files.

namespace {

std::string CsvField(const std::string& text) {
  if (text.find_first_of(",\"\n\r") == std::string::npos) return text;
  std::string quoted = "\"";
  for (const char c : text) {
    if (c == '"') quoted += '"';
    quoted += c;
  }
  return quoted + "\"";
}

}  // namespace

std::string FormatPerViewCsv(const CalibrationReport& report) {
  std::string csv =
      "view,left,right,corners0,corners1,outliers0,outliers1,rms0_px,rms1_px,"
      "used,flagged\n";
  for (const CalibrationReport::View& view : report.views) {
    csv += std::to_string(view.view) + "," + CsvField(view.left_name) + "," +
           CsvField(view.right_name) + "," + std::to_string(view.corners[0]) +
           "," + std::to_string(view.corners[1]) + "," +
           std::to_string(view.outliers[0]) + "," +
           std::to_string(view.outliers[1]) + "," +
           FormatDouble(view.rms_px[0]) + "," + FormatDouble(view.rms_px[1]) +
           "," + (view.used ? "1" : "0") + "," + (view.flagged ? "1" : "0") +
           "\n";
  }
  return csv;
}

Status WriteCalibrationReport(const std::string& directory,
                              const CalibrationReport& report,
                              const StereoCalibration& calibration,
                              const std::vector<StereoView>& views,
                              const ImageSize& cam0_size,
                              const ImageSize& cam1_size,
                              const CalibrationReportOptions& options) {
  RCM_RETURN_IF_ERROR(options.Check().WithContext("report options"));
  std::error_code error;
  std::filesystem::create_directories(directory, error);
  if (error) {
    return Status::Error("cannot create folder " + directory + ": " +
                         error.message());
  }
  const std::filesystem::path folder(directory);
  const ImageSize sizes[2] = {cam0_size, cam1_size};
  const CameraCalibration* cameras[2] = {&calibration.cam0, &calibration.cam1};
  // Each picture is drawn and written before the next is drawn.
  const auto write_png = [&](const std::string& name,
                             const auto& draw) -> Status {
    const std::string path = (folder / name).string();
    cv::Mat image;
    try {
      image = draw();
    } catch (const cv::Exception& exception) {
      return Status::Error(path + ": drawing failed: " + exception.msg);
    }
    return WritePng(image, path);
  };
  for (int c = 0; c < calibration.num_cameras; ++c) {
    const std::string suffix = "_cam" + std::to_string(c) + ".png";
    RCM_RETURN_IF_ERROR(write_png("residuals" + suffix, [&] {
      return DrawResidualField(calibration, c, sizes[c], 0.0,
                               options.coverage_cols, options.coverage_rows);
    }));
    RCM_RETURN_IF_ERROR(write_png("coverage" + suffix, [&] {
      return DrawCoverage(calibration, views, c, sizes[c],
                          options.coverage_cols, options.coverage_rows);
    }));
    RCM_RETURN_IF_ERROR(write_png("intrinsics_only_uncertainty" + suffix, [&] {
      return DrawProjectionUncertainty(*cameras[c], 0.0, CameraName(c));
    }));
    if (calibration.full_covariance.size() > 0) {
      RCM_RETURN_IF_ERROR(write_png("projection_uncertainty" + suffix, [&] {
        return DrawMeanFramesUncertainty(
            calibration, c, options.uncertainty_distance_m, 0.0, CameraName(c));
      }));
    }
  }
  RCM_RETURN_IF_ERROR(
      write_png("per_view_rms.png", [&] { return DrawPerViewRms(report); }));
  return WriteFileAtomically((folder / "per_view.csv").string(),
                             FormatPerViewCsv(report));
}

}  // namespace rcm::calib
