#include "rcm/plot/line_plot.h"

#include <glog/logging.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <utility>

namespace rcm {
namespace {

// Everything is drawn at kSupersample times the output size and averaged
// down (cv::INTER_AREA): strokes and text get half-pixel resolution and
// smoother edges than cv::LINE_AA alone gives.
constexpr int kSupersample = 3;
// Fractional bits of the coordinates handed to cv drawing functions.
constexpr int kShift = 4;
constexpr double kShiftScale = 1 << kShift;

const cv::Scalar kWhite(255, 255, 255);
const cv::Scalar kTextColor(34, 34, 34);
const cv::Scalar kFrameColor(80, 80, 80);
const cv::Scalar kGridColor(232, 232, 232);
const cv::Scalar kLegendBorder(200, 200, 200);

bool Finite(double value) { return std::isfinite(value); }

// A Hershey font at a size in output pixels (scale 1 is about 22 output
// pixels from baseline to cap height at size factor 1).
struct Font {
  int face;
  double scale;
  double stroke;  // output pixels at size factor 1
};
const Font kTitleFont{cv::FONT_HERSHEY_DUPLEX, 0.72, 1.0};
const Font kLabelFont{cv::FONT_HERSHEY_SIMPLEX, 0.60, 1.0};
const Font kTickFont{cv::FONT_HERSHEY_SIMPLEX, 0.50, 1.0};
const Font kLegendFont{cv::FONT_HERSHEY_SIMPLEX, 0.52, 1.0};

struct TextSize {
  double width = 0.0;
  double height = 0.0;    // baseline to top
  double baseline = 0.0;  // baseline to bottom of descenders
};

// Strokes scale with the text but stay at least one output pixel wide, so
// that small text does not fade.
int CvFontThickness(const Font& font, double z) {
  return static_cast<int>(
      std::lround(std::max(0.75, font.stroke * z) * kSupersample));
}

double CvFontScale(const Font& font, double z) {
  return font.scale * z * kSupersample;
}

TextSize MeasureText(const std::string& text, const Font& font, double z) {
  if (text.empty()) return TextSize();
  int baseline = 0;
  const cv::Size size = cv::getTextSize(text, font.face, CvFontScale(font, z),
                                        CvFontThickness(font, z), &baseline);
  return TextSize{static_cast<double>(size.width) / kSupersample,
                  static_cast<double>(size.height) / kSupersample,
                  static_cast<double>(baseline) / kSupersample};
}

// Dash pattern of a polyline: the pieces of the path drawn, in the same
// coordinates as the path.
std::vector<std::vector<cv::Point2d>> DashPieces(
    const std::vector<cv::Point2d>& path, double dash, double gap) {
  std::vector<std::vector<cv::Point2d>> pieces;
  if (path.size() < 2) return pieces;
  if (dash <= 0.0) return {path};
  const double period = dash + std::max(gap, 0.0);
  double phase = 0.0;  // distance into the current period
  std::vector<cv::Point2d> piece = {path[0]};
  for (size_t i = 1; i < path.size(); ++i) {
    const cv::Point2d a = path[i - 1];
    const cv::Point2d b = path[i];
    const double length = cv::norm(b - a);
    double done = 0.0;
    while (done < length) {
      const bool on = phase < dash;
      const double boundary = on ? dash : period;
      const double step = std::min(boundary - phase, length - done);
      done += step;
      phase += step;
      const cv::Point2d point = a + (b - a) * (done / length);
      if (on) piece.push_back(point);
      if (phase >= boundary - 1e-9) {
        if (on) {
          if (piece.size() >= 2) pieces.push_back(piece);
          piece.clear();
        } else {
          phase = 0.0;
          piece = {point};
        }
      }
    }
  }
  if (phase < dash && piece.size() >= 2) pieces.push_back(piece);
  return pieces;
}

// Runs of consecutive indices where keep(i) holds.
template <typename Keep>
std::vector<std::pair<size_t, size_t>> Runs(size_t count, const Keep& keep) {
  std::vector<std::pair<size_t, size_t>> runs;
  size_t i = 0;
  while (i < count) {
    while (i < count && !keep(i)) ++i;
    const size_t begin = i;
    while (i < count && keep(i)) ++i;
    if (i > begin) runs.emplace_back(begin, i);
  }
  return runs;
}

}  // namespace

// ---------------------------------------------------------------------------
// Ticks.

cv::Scalar PaletteColor(int index) {
  // tab10, RGB.
  static constexpr std::array<std::array<int, 3>, 10> kPalette = {{
      {31, 119, 180},
      {255, 127, 14},
      {44, 160, 44},
      {214, 39, 40},
      {148, 103, 189},
      {140, 86, 75},
      {227, 119, 194},
      {127, 127, 127},
      {188, 189, 34},
      {23, 190, 207},
  }};
  const auto& rgb = kPalette[((index % 10) + 10) % 10];
  return cv::Scalar(rgb[2], rgb[1], rgb[0]);
}

AxisTicks NiceTicks(double lo, double hi, int max_ticks) {
  CHECK(Finite(lo) && Finite(hi) && lo < hi) << "[" << lo << ", " << hi << "]";
  CHECK_GE(max_ticks, 2);
  // Candidate steps m 10^e in increasing order, from well below the span
  // over max_ticks; the count of multiples of the step in [lo, hi] falls
  // as the step grows. The first step with at most max_ticks ticks has at
  // least one: the step before had three or more, and any three
  // consecutive multiples of 1, 2, 5 10^e bracket a multiple of the next
  // step (2, 5, 10 10^e).
  int exponent =
      static_cast<int>(std::floor(std::log10((hi - lo) / max_ticks))) - 1;
  for (;; ++exponent) {
    for (const int mantissa : {1, 2, 5}) {
      // step = mantissa 10^exponent; values as (k mantissa) / 10^-exponent
      // so that decimal steps give correctly rounded ticks.
      const double power = std::pow(10.0, std::abs(exponent));
      const double step = exponent >= 0 ? mantissa * power : mantissa / power;
      const double tolerance = 1e-9;
      const double first = std::ceil(lo / step - tolerance);
      const double last = std::floor(hi / step + tolerance);
      if (last - first + 1.0 > max_ticks) continue;
      AxisTicks ticks;
      ticks.step = step;
      ticks.decimals = TickDecimals(step);
      for (double k = first; k <= last; k += 1.0) {
        const double value =
            exponent >= 0 ? k * mantissa * power : k * mantissa / power;
        ticks.values.push_back(value == 0.0 ? 0.0 : value);  // no -0
      }
      return ticks;
    }
  }
}

int TickDecimals(double step) {
  CHECK(Finite(step) && step > 0.0);
  // step = m 10^k; the rounding absorbs 0.1 + 0.2 style noise.
  const int k = static_cast<int>(std::floor(std::log10(step) + 1e-9));
  return std::max(0, -k);
}

std::string FormatTick(double value, int decimals) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), "%.*f", std::clamp(decimals, 0, 17),
                value);
  std::string text = buffer;
  // "-0.000" -> "0.000".
  if (text[0] == '-' && text.find_first_not_of("-0.") == std::string::npos) {
    text.erase(0, 1);
  }
  return text;
}

cv::Point2d PlotAxes::PixelFromData(double x, double y) const {
  return cv::Point2d(area.x + (x - x_min) / (x_max - x_min) * area.width,
                     area.y + (y_max - y) / (y_max - y_min) * area.height);
}

// ---------------------------------------------------------------------------
// Drawing.

// An image with the map from output pixels to its own pixels, p * scale +
// offset (pixel centers of the output map to the center of the block of
// supersampled pixels they average), and optionally a clip rectangle.
class LinePlot::Canvas {
 public:
  Canvas(cv::Mat image, int scale) : image_(std::move(image)), scale_(scale) {}

  cv::Mat& image() { return image_; }
  int scale() const { return scale_; }

  double ToImage(double output) const {
    return output * scale_ + 0.5 * (scale_ - 1);
  }
  // The image rectangle covering output rectangle `area` (edges at pixel
  // centers, inclusive).
  cv::Rect ImageRect(const cv::Rect2d& area) const {
    const int x0 = static_cast<int>(std::floor(ToImage(area.x)));
    const int y0 = static_cast<int>(std::floor(ToImage(area.y)));
    const int x1 = static_cast<int>(std::ceil(ToImage(area.x + area.width)));
    const int y1 = static_cast<int>(std::ceil(ToImage(area.y + area.height)));
    return cv::Rect(x0, y0, x1 - x0 + 1, y1 - y0 + 1) &
           cv::Rect(0, 0, image_.cols, image_.rows);
  }
  // Drawing goes into `area` only (output pixels) until Unclip.
  void Clip(const cv::Rect2d& area) { clip_ = ImageRect(area); }
  void Unclip() { clip_ = cv::Rect(0, 0, image_.cols, image_.rows); }

  cv::Mat Target() { return image_(clip_); }
  cv::Point Fixed(const cv::Point2d& output) const {
    return cv::Point(static_cast<int>(std::lround(
                         (ToImage(output.x) - clip_.x) * kShiftScale)),
                     static_cast<int>(std::lround(
                         (ToImage(output.y) - clip_.y) * kShiftScale)));
  }
  int Thickness(double width) const {
    return std::max(1, static_cast<int>(std::lround(width * scale_)));
  }

  void Polyline(const std::vector<cv::Point2d>& points, const cv::Scalar& color,
                double width) {
    if (points.size() < 2) return;
    std::vector<cv::Point> fixed;
    fixed.reserve(points.size());
    for (const cv::Point2d& point : points) fixed.push_back(Fixed(point));
    cv::Mat target = Target();
    cv::polylines(target, std::vector<std::vector<cv::Point>>{fixed}, false,
                  color, Thickness(width), cv::LINE_AA, kShift);
  }

  void StyledPolyline(const std::vector<cv::Point2d>& points,
                      const cv::Scalar& color, const LineStyle& style) {
    for (const auto& piece : DashPieces(points, style.dash, style.gap)) {
      Polyline(piece, color, style.width);
    }
  }

  void Marker(const cv::Point2d& center, const cv::Scalar& color,
              const MarkerStyle& style) {
    const double r = style.radius;
    cv::Mat target = Target();
    switch (style.shape) {
      case MarkerShape::kCircle:
        cv::circle(target, Fixed(center),
                   static_cast<int>(std::lround(r * scale_ * kShiftScale)),
                   color, cv::FILLED, cv::LINE_AA, kShift);
        return;
      case MarkerShape::kSquare:
      case MarkerShape::kDiamond: {
        const double d = style.shape == MarkerShape::kSquare ? r : 1.35 * r;
        std::vector<cv::Point2d> corners =
            style.shape == MarkerShape::kSquare
                ? std::vector<cv::Point2d>{{-d, -d}, {d, -d}, {d, d}, {-d, d}}
                : std::vector<cv::Point2d>{{0, -d}, {d, 0}, {0, d}, {-d, 0}};
        std::vector<cv::Point> fixed;
        for (const cv::Point2d& corner : corners) {
          fixed.push_back(Fixed(center + corner));
        }
        cv::fillConvexPoly(target, fixed, color, cv::LINE_AA, kShift);
        return;
      }
      case MarkerShape::kCross:
        Polyline({center + cv::Point2d(-r, -r), center + cv::Point2d(r, r)},
                 color, std::max(1.0, 0.5 * r));
        Polyline({center + cv::Point2d(-r, r), center + cv::Point2d(r, -r)},
                 color, std::max(1.0, 0.5 * r));
        return;
    }
  }

  // Fills the polygons with `color` at `opacity` over the image.
  void Fill(const std::vector<std::vector<cv::Point2d>>& polygons,
            const cv::Scalar& color, double opacity) {
    cv::Mat target = Target();
    cv::Mat coverage = cv::Mat::zeros(target.size(), CV_8UC1);
    std::vector<std::vector<cv::Point>> fixed;
    for (const auto& polygon : polygons) {
      if (polygon.size() < 3) continue;
      fixed.emplace_back();
      for (const cv::Point2d& point : polygon) {
        fixed.back().push_back(Fixed(point));
      }
    }
    if (fixed.empty()) return;
    cv::fillPoly(coverage, fixed, cv::Scalar(255), cv::LINE_AA, kShift);
    Blend(coverage, color, opacity, &target);
  }

  void Rectangle(const cv::Rect2d& rect, const cv::Scalar& color,
                 double opacity) {
    Fill({{rect.tl(),
           {rect.x + rect.width, rect.y},
           rect.br(),
           {rect.x, rect.y + rect.height}}},
         color, opacity);
  }

  // Text with its left end of the baseline at `origin` (output pixels).
  void Text(const std::string& text, const cv::Point2d& origin,
            const Font& font, double z, const cv::Scalar& color) {
    if (text.empty()) return;
    cv::Mat target = Target();
    const cv::Point fixed = Fixed(origin);
    cv::putText(target, text,
                cv::Point(static_cast<int>(std::lround(fixed.x / kShiftScale)),
                          static_cast<int>(std::lround(fixed.y / kShiftScale))),
                font.face, CvFontScale(font, z), color,
                CvFontThickness(font, z), cv::LINE_AA);
  }

  // Text rotated 90 degrees counterclockwise (reading upwards), centered at
  // `center`; dark text on the white canvas only.
  void VerticalText(const std::string& text, const cv::Point2d& center,
                    const Font& font, double z, const cv::Scalar& color) {
    if (text.empty()) return;
    int baseline = 0;
    const cv::Size size = cv::getTextSize(text, font.face, CvFontScale(font, z),
                                          CvFontThickness(font, z), &baseline);
    const int pad = CvFontThickness(font, z) + 1;
    cv::Mat patch(size.height + baseline + 2 * pad, size.width + 2 * pad,
                  image_.type(), kWhite);
    cv::putText(patch, text, cv::Point(pad, pad + size.height), font.face,
                CvFontScale(font, z), color, CvFontThickness(font, z),
                cv::LINE_AA);
    cv::Mat rotated;
    cv::rotate(patch, rotated, cv::ROTATE_90_COUNTERCLOCKWISE);
    const int x =
        static_cast<int>(std::lround(ToImage(center.x))) - rotated.cols / 2;
    const int y =
        static_cast<int>(std::lround(ToImage(center.y))) - rotated.rows / 2;
    const cv::Rect where = cv::Rect(x, y, rotated.cols, rotated.rows) &
                           cv::Rect(0, 0, image_.cols, image_.rows);
    if (where.empty()) return;
    cv::Mat destination = image_(where);
    cv::min(
        destination,
        rotated(cv::Rect(where.x - x, where.y - y, where.width, where.height)),
        destination);
  }

 private:
  static void Blend(const cv::Mat& coverage, const cv::Scalar& color,
                    double opacity, cv::Mat* target) {
    const int channels = target->channels();
    for (int r = 0; r < target->rows; ++r) {
      const uchar* weight = coverage.ptr<uchar>(r);
      uchar* pixel = target->ptr<uchar>(r);
      for (int c = 0; c < target->cols; ++c) {
        if (weight[c] == 0) continue;
        const double a = opacity * weight[c] / 255.0;
        for (int k = 0; k < channels; ++k) {
          const double value =
              (1.0 - a) * pixel[c * channels + k] + a * color[k];
          pixel[c * channels + k] =
              static_cast<uchar>(std::clamp(std::lround(value), 0L, 255L));
        }
      }
    }
  }

  cv::Mat image_;
  int scale_;
  cv::Rect clip_ = cv::Rect(0, 0, image_.cols, image_.rows);
};

// ---------------------------------------------------------------------------
// Layout.

struct LinePlot::Layout {
  PlotAxes axes;
  double z = 1.0;  // size factor: text and spacing scale with the image
  double tick_length = 5.0;
  // Baselines (output pixels).
  double title_baseline = 0.0;
  double x_label_baseline = 0.0;
  double y_label_center_x = 0.0;
  double marker_row_height = 0.0;
  // Row of each vertical marker's label (in series order of the markers).
  std::vector<int> marker_rows;
  // Legend: resolved position (never kBest), box, entry rows.
  LegendPosition legend = LegendPosition::kNone;
  cv::Rect2d legend_box;
  std::vector<cv::Point2d> legend_entries;  // top-left of each entry
  double legend_row_height = 0.0;
};

namespace {

constexpr double kSwatchWidth = 30.0;
constexpr double kSwatchGap = 8.0;
constexpr double kLegendPad = 9.0;
constexpr double kLegendEntryGap = 22.0;  // between entries side by side

// Greedy rows for labels centered at x with half widths: each label goes
// into the first row where it does not touch the previous label.
std::vector<int> AssignRows(const std::vector<double>& centers,
                            const std::vector<double>& half_widths,
                            double gap) {
  std::vector<size_t> order(centers.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(),
                   [&](size_t a, size_t b) { return centers[a] < centers[b]; });
  std::vector<int> rows(centers.size(), 0);
  std::vector<double> row_end;
  for (size_t i : order) {
    const double left = centers[i] - half_widths[i];
    size_t row = 0;
    while (row < row_end.size() && left < row_end[row] + gap) ++row;
    if (row == row_end.size()) row_end.push_back(0.0);
    row_end[row] = centers[i] + half_widths[i];
    rows[i] = static_cast<int>(row);
  }
  return rows;
}

}  // namespace

void LinePlot::SetXRange(double lo, double hi) {
  CHECK(Finite(lo) && Finite(hi) && lo < hi) << "[" << lo << ", " << hi << "]";
  x_range_ = std::make_pair(lo, hi);
}

void LinePlot::SetYRange(double lo, double hi) {
  CHECK(Finite(lo) && Finite(hi) && lo < hi) << "[" << lo << ", " << hi << "]";
  y_range_ = std::make_pair(lo, hi);
}

cv::Scalar LinePlot::NextColor(const std::optional<cv::Scalar>& color) {
  if (color) return *color;
  return PaletteColor(num_colors_used_++);
}

void LinePlot::AddLine(std::vector<double> x, std::vector<double> y,
                       std::string label, const LineStyle& style) {
  CHECK_EQ(x.size(), y.size());
  CHECK_GT(style.width, 0.0);
  Series series;
  series.kind = SeriesKind::kLine;
  series.x = std::move(x);
  series.y = std::move(y);
  series.label = std::move(label);
  series.color = NextColor(style.color);
  series.line = style;
  series_.push_back(std::move(series));
}

void LinePlot::AddMarkers(std::vector<double> x, std::vector<double> y,
                          std::string label, const MarkerStyle& style) {
  CHECK_EQ(x.size(), y.size());
  CHECK_GT(style.radius, 0.0);
  Series series;
  series.kind = SeriesKind::kMarkers;
  series.x = std::move(x);
  series.y = std::move(y);
  series.label = std::move(label);
  series.color = NextColor(style.color);
  series.marker = style;
  series_.push_back(std::move(series));
}

void LinePlot::AddBand(std::vector<double> x, std::vector<double> y_low,
                       std::vector<double> y_high, std::string label,
                       std::optional<cv::Scalar> color, double opacity) {
  CHECK_EQ(x.size(), y_low.size());
  CHECK_EQ(x.size(), y_high.size());
  CHECK(opacity > 0.0 && opacity <= 1.0) << "opacity " << opacity;
  Series series;
  series.kind = SeriesKind::kBand;
  series.x = std::move(x);
  series.y = std::move(y_low);
  series.y_high = std::move(y_high);
  series.label = std::move(label);
  series.color = NextColor(color);
  series.opacity = opacity;
  series_.push_back(std::move(series));
}

void LinePlot::AddHorizontalLine(double y, std::string label,
                                 const LineStyle& style) {
  CHECK_GT(style.width, 0.0);
  Series series;
  series.kind = SeriesKind::kHorizontal;
  series.y = {y};
  series.label = std::move(label);
  series.color = NextColor(style.color);
  series.line = style;
  series_.push_back(std::move(series));
}

void LinePlot::AddVerticalMarker(double x, std::string label,
                                 const LineStyle& style) {
  CHECK_GT(style.width, 0.0);
  Series series;
  series.kind = SeriesKind::kVertical;
  series.x = {x};
  series.label = std::move(label);
  series.color = NextColor(style.color);
  series.line = style;
  series_.push_back(std::move(series));
}

LinePlot::Layout LinePlot::ComputeLayout(int width, int height,
                                         bool legend_below) const {
  CHECK_GE(width, 200);
  CHECK_GE(height, 150);
  Layout layout;
  const double z = std::clamp(
      std::sqrt(static_cast<double>(width) * height / (1000.0 * 600.0)), 0.7,
      3.0);
  layout.z = z;
  layout.tick_length = 5.0 * z;
  const double pad = 14.0 * z;

  // Data ranges.
  double x_lo = std::numeric_limits<double>::infinity();
  double x_hi = -x_lo;
  double y_lo = x_lo;
  double y_hi = -x_lo;
  auto extend = [](double value, double* lo, double* hi) {
    if (!Finite(value)) return;
    *lo = std::min(*lo, value);
    *hi = std::max(*hi, value);
  };
  for (const Series& series : series_) {
    for (double x : series.x) extend(x, &x_lo, &x_hi);
    if (series.kind == SeriesKind::kVertical) continue;
    for (double y : series.y) extend(y, &y_lo, &y_hi);
    for (double y : series.y_high) extend(y, &y_lo, &y_hi);
  }
  auto finish_range = [](double lo, double hi, double margin,
                         const std::optional<std::pair<double, double>>& set) {
    if (set) return *set;
    if (!(lo <= hi)) return std::make_pair(0.0, 1.0);
    if (hi - lo <= 1e-12 * std::max(1.0, std::abs(lo))) {
      const double half = lo != 0.0 ? 0.05 * std::abs(lo) : 0.5;
      return std::make_pair(lo - half, hi + half);
    }
    const double span = hi - lo;
    return std::make_pair(lo - margin * span, hi + margin * span);
  };
  std::tie(layout.axes.x_min, layout.axes.x_max) =
      finish_range(x_lo, x_hi, 0.02, x_range_);
  std::tie(layout.axes.y_min, layout.axes.y_max) =
      finish_range(y_lo, y_hi, 0.05, y_range_);

  // Vertical space: title, marker labels, plot, ticks, x label, legend.
  const TextSize title = MeasureText(title_, kTitleFont, z);
  const TextSize tick = MeasureText("0123456789", kTickFont, z);
  const TextSize label = MeasureText("Xg", kLabelFont, z);
  const TextSize legend_text = MeasureText("Xg", kLegendFont, z);
  double top = pad;
  if (!title_.empty()) {
    layout.title_baseline = top + title.height;
    top = layout.title_baseline + title.baseline + 10.0 * z;
  }
  std::vector<const Series*> markers;
  for (const Series& series : series_) {
    if (series.kind == SeriesKind::kVertical && !series.label.empty() &&
        Finite(series.x[0])) {
      markers.push_back(&series);
    }
  }
  layout.marker_row_height = tick.height + tick.baseline + 4.0 * z;
  layout.legend_row_height =
      std::max(legend_text.height + legend_text.baseline, 10.0 * z) + 7.0 * z;

  // Legend entries, measured once.
  std::vector<double> entry_widths;
  for (const Series& series : series_) {
    if (series.label.empty() || series.kind == SeriesKind::kVertical) continue;
    entry_widths.push_back(kSwatchWidth * z + kSwatchGap * z +
                           MeasureText(series.label, kLegendFont, z).width);
  }
  // The marker rows and the below-legend rows depend on the horizontal
  // layout, which depends on the y ticks, which depend on the height: two
  // passes reach the fixed point in practice.
  int num_marker_rows = markers.empty() ? 0 : 1;
  int num_legend_rows = legend_below && !entry_widths.empty() ? 1 : 0;
  for (int pass = 0; pass < 3; ++pass) {
    const double plot_top = top + num_marker_rows * layout.marker_row_height +
                            (num_marker_rows > 0 ? 2.0 * z : 4.0 * z);
    // From the bottom up: legend, x label, tick labels.
    const double legend_bottom = height - pad;
    double plot_bottom = legend_bottom;
    if (num_legend_rows > 0) {
      plot_bottom -= num_legend_rows * layout.legend_row_height +
                     2.0 * kLegendPad * z + 8.0 * z;
    }
    if (!x_label_.empty()) {
      layout.x_label_baseline = plot_bottom - label.baseline;
      plot_bottom = layout.x_label_baseline - label.height - 8.0 * z;
    }
    plot_bottom -= layout.tick_length + 6.0 * z + tick.height + tick.baseline;
    const double plot_height = std::max(20.0, plot_bottom - plot_top);

    // y ticks: about 4.5 tick heights apart at most.
    const int max_y_ticks =
        std::clamp(static_cast<int>(plot_height / (4.5 * tick.height)), 2, 8);
    layout.axes.y_ticks =
        NiceTicks(layout.axes.y_min, layout.axes.y_max, max_y_ticks);
    double y_label_width = 0.0;
    for (double value : layout.axes.y_ticks.values) {
      y_label_width =
          std::max(y_label_width,
                   MeasureText(FormatTick(value, layout.axes.y_ticks.decimals),
                               kTickFont, z)
                       .width);
    }
    double left = pad;
    if (!y_label_.empty()) {
      layout.y_label_center_x = left + 0.5 * (label.height + label.baseline);
      left += label.height + label.baseline + 10.0 * z;
    }
    left += y_label_width + 6.0 * z + layout.tick_length;

    // x ticks: as many as fit with two digits of space between labels.
    const double right_reserve = std::max(
        20.0 * z,
        0.5 *
            MeasureText(FormatTick(layout.axes.x_max, 6), kTickFont, z).width);
    const double plot_left = std::round(left);
    const double plot_right = std::round(width - pad - right_reserve);
    const double plot_width = std::max(20.0, plot_right - plot_left);
    const double digit = MeasureText("0", kTickFont, z).width;
    int max_x_ticks =
        std::clamp(static_cast<int>(plot_width / (70.0 * z)), 2, 12);
    for (;; --max_x_ticks) {
      layout.axes.x_ticks =
          NiceTicks(layout.axes.x_min, layout.axes.x_max, max_x_ticks);
      if (max_x_ticks == 2 || layout.axes.x_ticks.values.size() < 2) break;
      double widest = 0.0;
      for (double value : layout.axes.x_ticks.values) {
        widest = std::max(
            widest, MeasureText(FormatTick(value, layout.axes.x_ticks.decimals),
                                kTickFont, z)
                        .width);
      }
      const double spacing = layout.axes.x_ticks.step /
                             (layout.axes.x_max - layout.axes.x_min) *
                             plot_width;
      if (spacing >= widest + 2.0 * digit) break;
    }

    layout.axes.area =
        cv::Rect2d(plot_left, std::round(plot_top), plot_width,
                   std::round(plot_top + plot_height) - std::round(plot_top));

    // Marker label rows.
    std::vector<double> centers;
    std::vector<double> half_widths;
    for (const Series* series : markers) {
      centers.push_back(layout.axes.PixelFromData(series->x[0], 0.0).x);
      half_widths.push_back(0.5 *
                            MeasureText(series->label, kTickFont, z).width);
    }
    layout.marker_rows = AssignRows(centers, half_widths, 8.0 * z);
    int needed_marker_rows = 0;
    for (int row : layout.marker_rows) {
      needed_marker_rows = std::max(needed_marker_rows, row + 1);
    }

    // Legend below: a grid of entries, row by row, with as many columns as
    // fit the image width (columns as wide as their widest entry).
    int needed_legend_rows = 0;
    layout.legend_entries.clear();
    if (legend_below && !entry_widths.empty()) {
      const double available = width - 2.0 * pad - 2.0 * kLegendPad * z;
      const int count = static_cast<int>(entry_widths.size());
      std::vector<double> columns;
      for (int num_columns = count; num_columns >= 1; --num_columns) {
        columns.assign(num_columns, 0.0);
        for (int i = 0; i < count; ++i) {
          columns[i % num_columns] =
              std::max(columns[i % num_columns], entry_widths[i]);
        }
        double total = kLegendEntryGap * z * (num_columns - 1);
        for (double column : columns) total += column;
        if (total <= available) break;
      }
      const int num_columns = static_cast<int>(columns.size());
      needed_legend_rows = (count + num_columns - 1) / num_columns;
      double box_width = kLegendEntryGap * z * (num_columns - 1);
      for (double column : columns) box_width += column;
      box_width = std::round(box_width + 2.0 * kLegendPad * z);
      const double box_height = std::round(
          needed_legend_rows * layout.legend_row_height + 2.0 * kLegendPad * z);
      // Centered under the plot area, inside the image.
      const double box_left = std::round(std::clamp(
          layout.axes.area.x + 0.5 * (layout.axes.area.width - box_width), pad,
          std::max(pad, width - pad - box_width)));
      const double box_top = std::round(legend_bottom - box_height);
      layout.legend_box = cv::Rect2d(box_left, box_top, box_width, box_height);
      for (int i = 0; i < count; ++i) {
        double x = box_left + kLegendPad * z;
        for (int c = 0; c < i % num_columns; ++c) {
          x += columns[c] + kLegendEntryGap * z;
        }
        layout.legend_entries.emplace_back(
            x, box_top + kLegendPad * z +
                   (i / num_columns) * layout.legend_row_height);
      }
      layout.legend = LegendPosition::kBelow;
    }
    if (needed_marker_rows == num_marker_rows &&
        needed_legend_rows == num_legend_rows) {
      break;
    }
    num_marker_rows = needed_marker_rows;
    num_legend_rows = needed_legend_rows;
  }
  return layout;
}

namespace {

// Candidate legend boxes inside the plot area, in order of preference: the
// corners, the edge centers, the center.
std::vector<cv::Rect2d> InsideLegendBoxes(const cv::Rect2d& area,
                                          double box_width, double box_height,
                                          double inset) {
  const double left = area.x + inset;
  const double right = area.x + area.width - inset - box_width;
  const double center_x = area.x + 0.5 * (area.width - box_width);
  const double top = area.y + inset;
  const double bottom = area.y + area.height - inset - box_height;
  const double center_y = area.y + 0.5 * (area.height - box_height);
  std::vector<cv::Rect2d> boxes;
  for (const auto& [x, y] :
       std::vector<std::pair<double, double>>{{right, top},
                                              {left, top},
                                              {right, bottom},
                                              {left, bottom},
                                              {center_x, top},
                                              {right, center_y},
                                              {center_x, bottom},
                                              {left, center_y},
                                              {center_x, center_y}}) {
    boxes.emplace_back(std::round(x), std::round(y), box_width, box_height);
  }
  return boxes;
}

}  // namespace

bool LinePlot::HasLegendEntries() const {
  for (const Series& series : series_) {
    if (!series.label.empty() && series.kind != SeriesKind::kVertical) {
      return true;
    }
  }
  return false;
}

LinePlot::Layout LinePlot::ResolveLayout(int width, int height) const {
  if (!HasLegendEntries() || legend_ == LegendPosition::kNone) {
    return ComputeLayout(width, height, false);
  }
  if (legend_ == LegendPosition::kBelow) {
    return ComputeLayout(width, height, true);
  }
  Layout layout = ComputeLayout(width, height, false);
  const double z = layout.z;

  // The legend box, entries one per row.
  double widest = 0.0;
  int num_entries = 0;
  for (const Series& series : series_) {
    if (series.label.empty() || series.kind == SeriesKind::kVertical) continue;
    widest =
        std::max(widest, kSwatchWidth * z + kSwatchGap * z +
                             MeasureText(series.label, kLegendFont, z).width);
    ++num_entries;
  }
  const double box_width = std::round(widest + 2.0 * kLegendPad * z);
  const double box_height =
      std::round(num_entries * layout.legend_row_height + 2.0 * kLegendPad * z);
  const std::vector<cv::Rect2d> boxes =
      InsideLegendBoxes(layout.axes.area, box_width, box_height, 10.0 * z);

  std::optional<cv::Rect2d> chosen;
  switch (legend_) {
    case LegendPosition::kTopRight:
      chosen = boxes[0];
      break;
    case LegendPosition::kTopLeft:
      chosen = boxes[1];
      break;
    case LegendPosition::kBottomRight:
      chosen = boxes[2];
      break;
    case LegendPosition::kBottomLeft:
      chosen = boxes[3];
      break;
    default: {
      // kBest: the first box hiding no line, marker or reference line, and
      // among those the one hiding the least band; below the plot if none.
      Canvas lines(cv::Mat::zeros(height, width, CV_8UC1), 1);
      Canvas bands(cv::Mat::zeros(height, width, CV_8UC1), 1);
      DrawData(layout, DataPass::kLinesMask, &lines);
      DrawData(layout, DataPass::kBandsMask, &bands);
      int least_band = std::numeric_limits<int>::max();
      for (const cv::Rect2d& box : boxes) {
        const cv::Rect rect = lines.ImageRect(box);
        if (rect.area() < box.area() ||
            cv::countNonZero(lines.image()(rect)) > 0) {
          continue;  // too large for the plot, or hides a line
        }
        const int band = cv::countNonZero(bands.image()(rect));
        if (band < least_band) {
          least_band = band;
          chosen = box;
        }
      }
      if (!chosen) return ComputeLayout(width, height, true);
    }
  }
  layout.legend =
      legend_ == LegendPosition::kBest ? LegendPosition::kTopRight : legend_;
  layout.legend_box = *chosen;
  for (int i = 0; i < num_entries; ++i) {
    layout.legend_entries.emplace_back(
        chosen->x + kLegendPad * z,
        chosen->y + kLegendPad * z + i * layout.legend_row_height);
  }
  return layout;
}

PlotAxes LinePlot::Axes(int width, int height) const {
  return ResolveLayout(width, height).axes;
}

void LinePlot::DrawData(const Layout& layout, DataPass pass,
                        Canvas* canvas) const {
  const PlotAxes& axes = layout.axes;
  const double z = layout.z;
  // Masks keep 3 px of clearance around lines and markers.
  const bool color_pass = pass == DataPass::kColor;
  const double clearance = color_pass ? 0.0 : 6.0 * z;
  const cv::Scalar mask_value(255, 255, 255);
  auto color_of = [&](const Series& series) {
    return color_pass ? series.color : mask_value;
  };
  auto line_style = [&](const LineStyle& style) {
    LineStyle scaled = style;
    scaled.width = style.width * z + clearance;
    scaled.dash = color_pass ? style.dash * z : 0.0;
    scaled.gap *= z;
    return scaled;
  };
  canvas->Clip(axes.area);
  if (pass != DataPass::kLinesMask) {
    for (const Series& series : series_) {
      if (series.kind != SeriesKind::kBand) continue;
      std::vector<std::vector<cv::Point2d>> polygons;
      const auto runs = Runs(series.x.size(), [&](size_t i) {
        return Finite(series.x[i]) && Finite(series.y[i]) &&
               Finite(series.y_high[i]);
      });
      for (const auto& [begin, end] : runs) {
        std::vector<cv::Point2d> polygon;
        for (size_t i = begin; i < end; ++i) {
          polygon.push_back(axes.PixelFromData(series.x[i], series.y_high[i]));
        }
        for (size_t i = end; i-- > begin;) {
          polygon.push_back(axes.PixelFromData(series.x[i], series.y[i]));
        }
        if (end - begin == 1) {
          // A lone sample: a sliver two pixels wide.
          const double half = 1.0 * z;
          polygon = {polygon[0] + cv::Point2d(-half, 0),
                     polygon[0] + cv::Point2d(half, 0),
                     polygon[1] + cv::Point2d(half, 0),
                     polygon[1] + cv::Point2d(-half, 0)};
        }
        polygons.push_back(std::move(polygon));
      }
      canvas->Fill(polygons, color_of(series),
                   color_pass ? series.opacity : 1.0);
    }
  }
  if (pass == DataPass::kBandsMask) {
    canvas->Unclip();
    return;
  }
  for (const Series& series : series_) {
    if (series.kind == SeriesKind::kHorizontal && Finite(series.y[0])) {
      const double v = axes.PixelFromData(0.0, series.y[0]).y;
      canvas->StyledPolyline(
          {{axes.area.x, v}, {axes.area.x + axes.area.width, v}},
          color_of(series), line_style(series.line));
    } else if (series.kind == SeriesKind::kVertical && Finite(series.x[0])) {
      const double u = axes.PixelFromData(series.x[0], 0.0).x;
      canvas->StyledPolyline(
          {{u, axes.area.y}, {u, axes.area.y + axes.area.height}},
          color_of(series), line_style(series.line));
    }
  }
  for (const Series& series : series_) {
    if (series.kind != SeriesKind::kLine) continue;
    const auto runs = Runs(series.x.size(), [&](size_t i) {
      return Finite(series.x[i]) && Finite(series.y[i]);
    });
    for (const auto& [begin, end] : runs) {
      std::vector<cv::Point2d> path;
      for (size_t i = begin; i < end; ++i) {
        path.push_back(axes.PixelFromData(series.x[i], series.y[i]));
      }
      if (path.size() == 1) {
        // An isolated finite sample still shows, as a dot.
        MarkerStyle dot;
        dot.radius = 0.5 * series.line.width * z + 0.5 * clearance;
        canvas->Marker(path[0], color_of(series), dot);
        continue;
      }
      canvas->StyledPolyline(path, color_of(series), line_style(series.line));
    }
  }
  for (const Series& series : series_) {
    if (series.kind != SeriesKind::kMarkers) continue;
    MarkerStyle style = series.marker;
    style.radius = style.radius * z + 0.5 * clearance;
    if (!color_pass) style.shape = MarkerShape::kCircle;
    for (size_t i = 0; i < series.x.size(); ++i) {
      if (!Finite(series.x[i]) || !Finite(series.y[i])) continue;
      canvas->Marker(axes.PixelFromData(series.x[i], series.y[i]),
                     color_of(series), style);
    }
  }
  canvas->Unclip();
}

void LinePlot::DrawLegend(const Layout& layout, Canvas* canvas) const {
  if (layout.legend == LegendPosition::kNone || layout.legend_entries.empty()) {
    return;
  }
  const double z = layout.z;
  // Inside the plot the box is nearly opaque, so that what it covers (at
  // most a band) stays faintly visible.
  const bool inside = layout.legend != LegendPosition::kBelow;
  canvas->Rectangle(layout.legend_box, kWhite, inside ? 0.88 : 1.0);
  const cv::Rect2d& box = layout.legend_box;
  canvas->Polyline({box.tl(),
                    {box.x + box.width, box.y},
                    box.br(),
                    {box.x, box.y + box.height},
                    box.tl()},
                   kLegendBorder, 1.0 * z);
  const TextSize text = MeasureText("Xg", kLegendFont, z);
  const double row = layout.legend_row_height;
  size_t entry = 0;
  for (const Series& series : series_) {
    if (series.label.empty() || series.kind == SeriesKind::kVertical) continue;
    const cv::Point2d corner = layout.legend_entries[entry++];
    const double middle = corner.y + 0.5 * row;
    const double swatch_left = corner.x;
    const double swatch_right = corner.x + kSwatchWidth * z;
    switch (series.kind) {
      case SeriesKind::kLine:
      case SeriesKind::kHorizontal: {
        LineStyle style = series.line;
        style.width *= z;
        style.dash *= z;
        style.gap *= z;
        canvas->StyledPolyline({{swatch_left, middle}, {swatch_right, middle}},
                               series.color, style);
        break;
      }
      case SeriesKind::kMarkers: {
        MarkerStyle style = series.marker;
        style.radius *= z;
        canvas->Marker({0.5 * (swatch_left + swatch_right), middle},
                       series.color, style);
        break;
      }
      case SeriesKind::kBand: {
        const double half = 0.32 * row;
        canvas->Rectangle(cv::Rect2d(swatch_left, middle - half,
                                     kSwatchWidth * z, 2.0 * half),
                          series.color, series.opacity);
        break;
      }
      case SeriesKind::kVertical:
        break;
    }
    canvas->Text(series.label,
                 {swatch_right + kSwatchGap * z, middle + 0.5 * text.height},
                 kLegendFont, z, kTextColor);
  }
}

cv::Mat LinePlot::Render(int width, int height) const {
  const Layout layout = ResolveLayout(width, height);
  const double z = layout.z;
  const PlotAxes& axes = layout.axes;
  Canvas canvas(
      cv::Mat(height * kSupersample, width * kSupersample, CV_8UC3, kWhite),
      kSupersample);

  // Grid, then the data over it.
  for (double x : axes.x_ticks.values) {
    const double u = axes.PixelFromData(x, 0.0).x;
    canvas.Polyline({{u, axes.area.y}, {u, axes.area.y + axes.area.height}},
                    kGridColor, 1.0 * z);
  }
  for (double y : axes.y_ticks.values) {
    const double v = axes.PixelFromData(0.0, y).y;
    canvas.Polyline({{axes.area.x, v}, {axes.area.x + axes.area.width, v}},
                    kGridColor, 1.0 * z);
  }
  DrawData(layout, DataPass::kColor, &canvas);

  // Frame, ticks and tick labels.
  const double right = axes.area.x + axes.area.width;
  const double bottom = axes.area.y + axes.area.height;
  canvas.Polyline({axes.area.tl(),
                   {right, axes.area.y},
                   axes.area.br(),
                   {axes.area.x, bottom},
                   axes.area.tl()},
                  kFrameColor, 1.0 * z);
  const TextSize digits = MeasureText("0123456789", kTickFont, z);
  for (double x : axes.x_ticks.values) {
    const double u = axes.PixelFromData(x, 0.0).x;
    canvas.Polyline({{u, bottom}, {u, bottom + layout.tick_length}},
                    kFrameColor, 1.0 * z);
    const std::string text = FormatTick(x, axes.x_ticks.decimals);
    const TextSize size = MeasureText(text, kTickFont, z);
    canvas.Text(text,
                {u - 0.5 * size.width,
                 bottom + layout.tick_length + 6.0 * z + digits.height},
                kTickFont, z, kTextColor);
  }
  for (double y : axes.y_ticks.values) {
    const double v = axes.PixelFromData(0.0, y).y;
    canvas.Polyline({{axes.area.x - layout.tick_length, v}, {axes.area.x, v}},
                    kFrameColor, 1.0 * z);
    const std::string text = FormatTick(y, axes.y_ticks.decimals);
    const TextSize size = MeasureText(text, kTickFont, z);
    canvas.Text(text,
                {axes.area.x - layout.tick_length - 6.0 * z - size.width,
                 v + 0.5 * digits.height},
                kTickFont, z, kTextColor);
  }

  // Title and axis labels, centered on the plot area.
  if (!title_.empty()) {
    const TextSize size = MeasureText(title_, kTitleFont, z);
    canvas.Text(title_,
                {axes.area.x + 0.5 * (axes.area.width - size.width),
                 layout.title_baseline},
                kTitleFont, z, kTextColor);
  }
  if (!x_label_.empty()) {
    const TextSize size = MeasureText(x_label_, kLabelFont, z);
    canvas.Text(x_label_,
                {axes.area.x + 0.5 * (axes.area.width - size.width),
                 layout.x_label_baseline},
                kLabelFont, z, kTextColor);
  }
  if (!y_label_.empty()) {
    canvas.VerticalText(
        y_label_,
        {layout.y_label_center_x, axes.area.y + 0.5 * axes.area.height},
        kLabelFont, z, kTextColor);
  }

  // Labels of the vertical markers, above the plot area at their line.
  size_t marker_index = 0;
  for (const Series& series : series_) {
    if (series.kind != SeriesKind::kVertical || series.label.empty() ||
        !Finite(series.x[0])) {
      continue;
    }
    const int row = layout.marker_rows[marker_index++];
    const double u = axes.PixelFromData(series.x[0], 0.0).x;
    const TextSize size = MeasureText(series.label, kTickFont, z);
    const double baseline =
        axes.area.y - 4.0 * z - size.baseline - row * layout.marker_row_height;
    const double x =
        std::clamp(u - 0.5 * size.width, 2.0, width - 2.0 - size.width);
    canvas.Text(series.label, {x, baseline}, kTickFont, z, series.color);
  }

  DrawLegend(layout, &canvas);

  cv::Mat output;
  cv::resize(canvas.image(), output, cv::Size(width, height), 0.0, 0.0,
             cv::INTER_AREA);
  return output;
}

}  // namespace rcm
