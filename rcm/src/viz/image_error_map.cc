#include "rcm/viz/image_error_map.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <utility>

#include "rcm/plot/color_map.h"
#include "rcm/plot/figure.h"
#include "rcm/plot/line_plot.h"
#include "rcm/util/number_format.h"

namespace rcm {
namespace {

// ---------------------------------------------------------------------------
// Numbers.

bool Finite(double value) { return std::isfinite(value); }

std::string Int(long long value) { return std::to_string(value); }

// " px", or nothing without units.
std::string WithUnits(const std::string& number, const std::string& units) {
  return units.empty() ? number : number + " " + units;
}

// The magnitudes of the present errors, RMS, median and max over them.
struct Statistics {
  long long present = 0;
  long long absent = 0;
  double rms = 0.0;
  double median = 0.0;
  double max = 0.0;

  explicit Statistics(const std::vector<double>& magnitudes) {
    std::vector<double> values;
    values.reserve(magnitudes.size());
    for (const double value : magnitudes) {
      if (Finite(value)) values.push_back(value);
    }
    present = static_cast<long long>(values.size());
    absent = static_cast<long long>(magnitudes.size()) - present;
    if (values.empty()) return;
    std::sort(values.begin(), values.end());
    const size_t n = values.size();
    max = values.back();
    median =
        n % 2 == 1 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
    // Scaled by the max so that the squares cannot overflow.
    if (max > 0.0) {
      double sum = 0.0;
      for (const double value : values) sum += (value / max) * (value / max);
      rms = max * std::sqrt(sum / static_cast<double>(n));
    }
  }

  // `value` with the decimals that give the max three significant digits;
  // in "%.3g" when the max is very large or small.
  std::string Format(double value) const {
    if (!(max > 0.0)) return FormatFixed(value, 3);
    const int exponent = static_cast<int>(std::floor(std::log10(max)));
    if (exponent < -4 || exponent > 6) {
      char buffer[32];
      std::snprintf(buffer, sizeof(buffer), "%.3g", value);
      return buffer;
    }
    return FormatFixed(value, std::max(0, 2 - exponent));
  }
};

// The colour scale: 0 to `top` on viridis, with its tick labels.
struct ColorScale {
  double top = 1.0;
  std::vector<std::pair<double, std::string>> ticks;

  explicit ColorScale(double top_value) : top(top_value) {
    // NiceTicks needs a step that is a normal double.
    if (top > 1e-200 && top < 1e200) {
      const AxisTicks nice = NiceTicks(0.0, top, 6);
      const bool fixed = nice.decimals <= 6 && top < 1e7;
      for (const double value : nice.values) {
        ticks.emplace_back(value, fixed ? FormatTick(value, nice.decimals)
                                        : FormatShort(value));
      }
    } else {
      ticks = {{0.0, "0"}, {top, FormatShort(top)}};
    }
  }
  double T(double value) const { return value / top; }
  cv::Scalar Color(double value) const {
    const cv::Vec3b c = ColorMapColor(cv::COLORMAP_VIRIDIS, T(value));
    return cv::Scalar(c[0], c[1], c[2]);
  }
};

// ---------------------------------------------------------------------------
// Drawing, on an rcm::Figure (rcm/plot/figure.h).

// The dashes of the closed polygon `corners`: pieces `dash` long with
// `gap` (> 0) between them, the pattern running on round the corners.
std::vector<std::vector<cv::Point2d>> Dashes(
    const std::vector<cv::Point2d>& corners, double dash, double gap) {
  std::vector<std::vector<cv::Point2d>> pieces;
  std::vector<cv::Point2d> piece;
  bool on = true;
  double left = dash;  // of the current dash or gap
  for (size_t i = 0; i < corners.size(); ++i) {
    const cv::Point2d a = corners[i];
    const cv::Point2d b = corners[(i + 1) % corners.size()];
    const double length = cv::norm(b - a);
    double done = 0.0;
    while (done < length) {
      const double step = std::min(left, length - done);
      const cv::Point2d from = a + (b - a) * (done / length);
      done += step;
      left -= step;
      if (on) {
        if (piece.empty()) piece.push_back(from);
        piece.push_back(a + (b - a) * (done / length));
      }
      if (left <= 1e-9) {
        if (on) pieces.push_back(std::move(piece));
        piece.clear();
        on = !on;
        left = on ? dash : gap;
      }
    }
  }
  if (piece.size() >= 2) pieces.push_back(std::move(piece));
  return pieces;
}

// Where things go, in output pixels.
struct Layout {
  double z = 1.0;  // size factor of text and spacing
  int width = 0;
  int height = 0;
  int margin = 0;
  // The frame: output pixels frame_x .. frame_x + frame_width - 1.
  int frame_x = 0;
  int frame_y = 0;
  int frame_width = 0;
  int frame_height = 0;
  double scale = 1.0;  // output pixels per image pixel
  double title_baseline = 0.0;
  double stats_baseline = 0.0;
  double legend_baseline = 0.0;

  // Output coordinates of image coordinates (both with pixel centers at
  // integers).
  cv::Point2d FromImage(double u, double v) const {
    return cv::Point2d(frame_x - 0.5 + (u + 0.5) * scale,
                       frame_y - 0.5 + (v + 0.5) * scale);
  }
  cv::Point2d FromImage(const Eigen::Vector2d& pixel) const {
    return FromImage(pixel.x(), pixel.y());
  }
  double Left() const { return frame_x - 0.5; }
  double Top() const { return frame_y - 0.5; }
  double Right() const { return frame_x + frame_width - 0.5; }
  double Bottom() const { return frame_y + frame_height - 0.5; }
};

// An item of the legend line: a glyph `glyph_width` wide drawn with its
// left end at the given point of the text's middle height, then its text.
struct LegendItem {
  double glyph_width = 0.0;
  std::function<void(const cv::Point2d&, Figure*)> draw_glyph;
  std::string text;
};

// The error arrows: a subsample of the samples, every `stride`-th column
// and row, and the magnification that makes the largest about one arrow
// spacing long.
struct ArrowPlan {
  std::vector<std::pair<Eigen::Vector2d, Eigen::Vector2d>> arrows;  // at, e
  double magnification = 0.0;  // 0: no arrows to draw
  double spacing = 0.0;        // image pixels
  double key = 0.0;            // error of the arrow in the legend

  ArrowPlan(const ImageErrorField& field, int arrows_across) {
    if (arrows_across <= 0) return;
    const double wanted =
        static_cast<double>(field.image_width) / arrows_across / field.step;
    const int cells = std::max(field.cols, field.rows);
    const int stride = static_cast<int>(
        std::clamp(std::round(wanted), 1.0, static_cast<double>(cells)));
    spacing = stride * field.step;
    // The subsample centered on the grid.
    const int col0 = ((field.cols - 1) % stride) / 2;
    const int row0 = ((field.rows - 1) % stride) / 2;
    double largest = 0.0;
    for (int row = row0; row < field.rows; row += stride) {
      for (int col = col0; col < field.cols; col += stride) {
        const auto& error =
            field.errors[static_cast<size_t>(row) * field.cols + col];
        const Eigen::Vector2d at = field.Pixel(col, row);
        if (!error || !(at.x() >= -0.5 && at.x() <= field.image_width - 0.5 &&
                        at.y() >= -0.5 && at.y() <= field.image_height - 0.5)) {
          continue;
        }
        arrows.emplace_back(at, *error);
        largest = std::max(largest, std::hypot(error->x(), error->y()));
      }
    }
    if (!(largest > 0.0)) return;
    // The largest arrow (0.5, 1.25] spacings long.
    const double magnification_wanted = 1.25 * spacing / largest;
    if (!Finite(magnification_wanted)) return;
    magnification = NiceFloor(magnification_wanted);
    key = NiceFloor(largest);
    if (!Finite(magnification) || !Finite(key) || !(key > 0.0)) {
      magnification = 0.0;
    }
  }
};

}  // namespace

// ---------------------------------------------------------------------------

Status ImageErrorMapOptions::Check() const {
  const auto error = [](const std::string& what) {
    return Status::Error("image error map options: " + what);
  };
  if (frame_width < 100) {
    return error("frame width " + Int(frame_width) + " is below 100");
  }
  if (!Finite(color_max)) {
    return error("color max " + FormatDouble(color_max) + " is not finite");
  }
  if (arrows_across < 0) {
    return error("arrows across " + Int(arrows_across) + " is negative");
  }
  if (region) {
    const Eigen::Vector4d& r = *region;
    const std::string text = "region [" + FormatDouble(r[0]) + ", " +
                             FormatDouble(r[1]) + ", " + FormatDouble(r[2]) +
                             ", " + FormatDouble(r[3]) + "]";
    if (!r.allFinite()) return error(text + " is not finite");
    if (!(r[0] < r[2] && r[1] < r[3])) {
      return error(text + " is empty: needs x0 < x1 and y0 < y1");
    }
  }
  return Status::Ok();
}

StatusOr<cv::Mat> DrawImageErrorMap(const ImageErrorField& field,
                                    const ImageErrorMapOptions& options) {
  RCM_RETURN_IF_ERROR(field.Check());
  RCM_RETURN_IF_ERROR(options.Check());
  std::vector<double> magnitudes(field.errors.size(),
                                 std::numeric_limits<double>::quiet_NaN());
  for (size_t i = 0; i < field.errors.size(); ++i) {
    if (field.errors[i]) {
      magnitudes[i] = std::hypot(field.errors[i]->x(), field.errors[i]->y());
    }
  }
  const Statistics stats(magnitudes);
  if (stats.present == 0) {
    return Status::Error("image error field: no sample has a value (all " +
                         std::to_string(field.errors.size()) + " absent)");
  }
  double top = options.color_max;
  if (!(top > 0.0)) top = stats.max > 0.0 ? NiceCeil(stats.max) : 1.0;
  if (!Finite(top)) top = stats.max;
  const ColorScale scale(top);
  const ArrowPlan plan(field, options.arrows_across);
  const std::string& units = options.units;

  // Text below the frame.
  std::string stats_text =
      "RMS " + WithUnits(stats.Format(stats.rms), units) + "  median " +
      WithUnits(stats.Format(stats.median), units) + "  max " +
      WithUnits(stats.Format(stats.max), units) + "  (" + Int(stats.present) +
      (stats.present == 1 ? " sample" : " samples");
  if (stats.absent > 0)
    stats_text += ", " + Int(stats.absent) + " without value";
  stats_text += ")";

  // Layout.
  Layout layout;
  layout.frame_width = options.frame_width;
  layout.scale = static_cast<double>(options.frame_width) / field.image_width;
  layout.frame_height = std::max(
      1, static_cast<int>(std::lround(field.image_height * layout.scale)));
  layout.z = std::clamp(std::sqrt(static_cast<double>(layout.frame_width) *
                                  layout.frame_height / 6e5),
                        1.0, 2.5);
  const double z = layout.z;
  Figure measure(1, 1, z);  // for text widths only
  layout.margin = static_cast<int>(std::lround(14 * z));
  const int title_height = options.title.empty()
                               ? static_cast<int>(std::lround(24 * z))
                               : static_cast<int>(std::lround(38 * z));
  layout.title_baseline = std::round(25 * z);
  layout.frame_y = title_height;
  // Colour bar right of the frame, labels right of the bar.
  const double bar_gap = std::round(16 * z);
  const double bar_width = std::round(18 * z);
  double label_width = measure.Measure(units, kTextFont).width;
  for (const auto& tick : scale.ticks) {
    label_width = std::max(
        label_width, 7.0 * z + measure.Measure(tick.second, kTextFont).width);
  }
  const int natural =
      static_cast<int>(std::ceil(layout.margin + layout.frame_width + bar_gap +
                                 bar_width + label_width + layout.margin));

  std::vector<LegendItem> legend;
  if (plan.magnification > 0.0) {
    double key = plan.key;
    const double per_unit = plan.magnification * layout.scale;
    while (key * per_unit > 90.0 * z) key = NiceFloor(key / 1.5);
    const double length = key * per_unit;
    legend.push_back({length,
                      [length, z](const cv::Point2d& at, Figure* figure) {
                        figure->ArrowedLine(at, at + cv::Point2d(length, 0.0),
                                            std::min(0.45 * length, 6.0 * z),
                                            kInk, 1.2);
                      },
                      WithUnits(FormatShort(key), units) + " (arrows x " +
                          FormatShort(plan.magnification) + ")"});
  }
  if (options.region) {
    const double length = std::round(30 * z);
    legend.push_back(
        {length,
         [length, z](const cv::Point2d& at, Figure* figure) {
           figure->Line(at, at + cv::Point2d(length, 0.0), kWhite, 1.5);
           for (double x = 0.0; x < length; x += 10.0 * z) {
             figure->Line(at + cv::Point2d(x, 0.0),
                          at + cv::Point2d(std::min(x + 6.0 * z, length), 0.0),
                          kInk, 1.5);
           }
         },
         options.region_label.empty() ? "region" : options.region_label});
  }
  if (stats.absent > 0) {
    const double size = std::round(12 * z);
    legend.push_back({size,
                      [size](const cv::Point2d& at, Figure* figure) {
                        figure->FillArea(at.x, at.y - 0.5 * size, at.x + size,
                                         at.y + 0.5 * size, kNoData);
                      },
                      "no value"});
  }
  const double glyph_gap = std::round(6 * z);
  const double item_gap = std::round(20 * z);
  double legend_width = 0.0;
  for (const LegendItem& item : legend) {
    if (legend_width > 0.0) legend_width += item_gap;
    legend_width += item.glyph_width + glyph_gap +
                    measure.Measure(item.text, kTextFont).width;
  }
  const double text_width =
      std::max(measure.Measure(stats_text, kTextFont).width, legend_width);
  layout.width = std::max(
      natural, static_cast<int>(std::ceil(text_width)) + 2 * layout.margin);
  layout.frame_x = layout.margin + (layout.width - natural) / 2;
  const double line_height = std::round(22 * z);
  layout.stats_baseline =
      layout.frame_y + layout.frame_height + std::round(24 * z);
  layout.legend_baseline = layout.stats_baseline + line_height;
  layout.height = static_cast<int>(
      (legend.empty() ? layout.stats_baseline : layout.legend_baseline) +
      std::round(12 * z));

  Figure figure(layout.width, layout.height, z);

  // The heat map: each sample's cell, clipped to the image.
  figure.FillArea(layout.Left(), layout.Top(), layout.Right(), layout.Bottom(),
                  kPanel);
  const double half = 0.5 * field.step;
  const auto clamp_u = [&](double u) {
    return std::clamp(u, -0.5, field.image_width - 0.5);
  };
  const auto clamp_v = [&](double v) {
    return std::clamp(v, -0.5, field.image_height - 0.5);
  };
  for (int row = 0; row < field.rows; ++row) {
    for (int col = 0; col < field.cols; ++col) {
      const Eigen::Vector2d at = field.Pixel(col, row);
      const double u0 = clamp_u(at.x() - half);
      const double u1 = clamp_u(at.x() + half);
      const double v0 = clamp_v(at.y() - half);
      const double v1 = clamp_v(at.y() + half);
      if (!(u0 < u1 && v0 < v1)) continue;
      const double value =
          magnitudes[static_cast<size_t>(row) * field.cols + col];
      const cv::Point2d p0 = layout.FromImage(u0, v0);
      const cv::Point2d p1 = layout.FromImage(u1, v1);
      figure.FillArea(p0.x, p0.y, p1.x, p1.y,
                      Finite(value) ? scale.Color(value) : kNoData);
    }
  }

  figure.Clip(layout.Left(), layout.Top(), layout.Right(), layout.Bottom());
  // Arrows from the samples.
  if (plan.magnification > 0.0) {
    for (const auto& [at, error] : plan.arrows) {
      const cv::Point2d from = layout.FromImage(at);
      const cv::Point2d to = layout.FromImage(at + plan.magnification * error);
      const double length = cv::norm(to - from);
      if (!(length >= 0.75)) continue;
      figure.ArrowedLine(from, to, std::min(0.45 * length, 6.0 * z), kInk, 1.2);
    }
  }
  // The region: ink dashes over a white line, seen on any colour.
  if (options.region) {
    const Eigen::Vector4d& r = *options.region;
    // Far outside the frame is as good as just outside it.
    const double pad_u = 8.0 / layout.scale;
    const auto u = [&](double x) {
      return std::clamp(x, -0.5 - pad_u, field.image_width - 0.5 + pad_u);
    };
    const auto v = [&](double y) {
      return std::clamp(y, -0.5 - pad_u, field.image_height - 0.5 + pad_u);
    };
    const std::vector<cv::Point2d> corners = {
        layout.FromImage(u(r[0]), v(r[1])), layout.FromImage(u(r[2]), v(r[1])),
        layout.FromImage(u(r[2]), v(r[3])), layout.FromImage(u(r[0]), v(r[3]))};
    figure.Polyline(corners, true, kWhite, 1.5);
    for (const auto& piece : Dashes(corners, 6.0 * z, 4.0 * z)) {
      figure.Polyline(piece, false, kInk, 1.5);
    }
  }
  figure.Unclip();
  figure.Polyline({{layout.Left(), layout.Top()},
                   {layout.Right(), layout.Top()},
                   {layout.Right(), layout.Bottom()},
                   {layout.Left(), layout.Bottom()}},
                  true, kFrame, 1.0);

  // Colour bar, high values on top.
  const double bar_x = layout.Right() + bar_gap;
  const double bar_top = layout.frame_y + std::round(18 * z);
  const double bar_bottom = std::max(layout.Bottom(), bar_top + 20 * z);
  const int bar_rows = static_cast<int>(std::lround(bar_bottom - bar_top));
  for (int k = 0; k < bar_rows; ++k) {
    const double y = bar_top + k;
    const cv::Vec3b c =
        ColorMapColor(cv::COLORMAP_VIRIDIS, 1.0 - (k + 0.5) / bar_rows);
    figure.FillArea(bar_x, y, bar_x + bar_width, y + 1.0,
                    cv::Scalar(c[0], c[1], c[2]));
  }
  figure.Polyline({{bar_x, bar_top},
                   {bar_x + bar_width, bar_top},
                   {bar_x + bar_width, bar_bottom},
                   {bar_x, bar_bottom}},
                  true, kFrame, 1.0);
  for (const auto& [value, label] : scale.ticks) {
    const double y = bar_bottom - scale.T(value) * (bar_bottom - bar_top);
    figure.Line({bar_x + bar_width, y}, {bar_x + bar_width + 4.0 * z, y},
                kFrame, 1.0);
    figure.Text(label, {bar_x + bar_width + 7.0 * z, y + 5.0 * z}, kTextFont,
                kInk);
  }
  figure.Text(units, {bar_x, bar_top - 7.0 * z}, kTextFont, kInk);

  // Title, statistics, legend.
  const double text_room = layout.width - 2.0 * layout.margin;
  figure.Text(options.title,
              {static_cast<double>(layout.margin), layout.title_baseline},
              kTitleFont, kInk, text_room);
  // Under the frame, or from the margin when wider than the frame.
  const double text_x =
      layout.frame_x + text_width <= layout.width - layout.margin
          ? layout.frame_x
          : layout.margin;
  figure.Text(stats_text, {text_x, layout.stats_baseline}, kTextFont, kInk,
              text_room);
  double x = text_x;
  for (const LegendItem& item : legend) {
    item.draw_glyph({x, layout.legend_baseline - 5.0 * z}, &figure);
    x += item.glyph_width + glyph_gap;
    x += figure.Text(item.text, {x, layout.legend_baseline}, kTextFont, kInk) +
         item_gap;
  }
  return figure.Finish();
}

}  // namespace rcm
