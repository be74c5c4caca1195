// LinePlot: small 2-D plots (estimates per frame, sigma bands, reference
// values) rendered with OpenCV drawing into an 8-bit BGR image, for the
// figures the demo and the tools write as PNG (rcm/io/image_file.h).
//
// A plot maps data to pixels affinely inside its plot area
// [left, left + width] x [top, top + height] (output pixels, pixel centers
// at integers, y down):
//
//   u = left + (x - x_min) / (x_max - x_min) * width
//   v = top  + (y_max - y) / (y_max - y_min) * height
//
// The data range is the extent of every finite value with a margin (5 % of
// the span in y, 2 % in x) unless set explicitly. Ticks are "nice" numbers:
// multiples of a step s = m 10^k with m in {1, 2, 5}, as many as fit with
// two digits of space between x labels and 4.5 text heights between y
// labels, printed with max(0, -k) decimals (step 0.005 -> "1.335"). NaN
// (or infinite) values are not drawn: they break a line or a band in two
// and a marker is skipped.
//
// Text is OpenCV's Hershey font; everything is drawn at 3x the output size
// with cv::LINE_AA and averaged down, and text and strokes scale with the
// image (sqrt of its area over 1000 x 600).
//
// Colors are BGR, as everywhere in OpenCV; a series without a color takes
// the next one of a ten-color palette (matplotlib's "tab10").
#ifndef RCM_PLOT_LINE_PLOT_H_
#define RCM_PLOT_LINE_PLOT_H_

#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace rcm {

// The palette, index taken modulo 10: blue, orange, green, red, purple,
// brown, pink, gray, olive, cyan.
cv::Scalar PaletteColor(int index);

// Tick marks of an axis.
struct AxisTicks {
  std::vector<double> values;  // consecutive multiples of step, ascending
  double step = 1.0;           // m 10^k, m in {1, 2, 5}
  int decimals = 0;            // TickDecimals(step)
};

// The ticks inside [lo, hi] (finite, lo < hi) with the smallest nice step
// that gives at most max_ticks (>= 2) of them. There is at least one; the
// first lies within one step of lo, the last within one step of hi.
AxisTicks NiceTicks(double lo, double hi, int max_ticks);
// Decimals that print every multiple of `step` exactly: max(0, -k).
int TickDecimals(double step);
// "%.*f" with `decimals`, without a minus sign on zero.
std::string FormatTick(double value, int decimals);

struct LineStyle {
  // Unset: the next palette color.
  std::optional<cv::Scalar> color;
  // Stroke width in output pixels; > 0.
  double width = 2.0;
  // Dash and gap lengths in output pixels; dash = 0 draws a solid line.
  double dash = 0.0;
  double gap = 5.0;
};

enum class MarkerShape { kCircle, kSquare, kDiamond, kCross };

struct MarkerStyle {
  // Unset: the next palette color.
  std::optional<cv::Scalar> color;
  MarkerShape shape = MarkerShape::kCircle;
  // Half the marker's size in output pixels; > 0.
  double radius = 3.0;
};

enum class LegendPosition {
  // The first free corner or edge of the plot area (top right, top left,
  // bottom right, bottom left, then the edge centers and the center) where
  // the legend hides no line, marker or reference line and as little of a
  // band as possible; below the plot when none is free.
  kBest,
  kTopRight,
  kTopLeft,
  kBottomRight,
  kBottomLeft,
  // Centered under the x-axis label, the entries in as many columns as
  // fit the image width.
  kBelow,
  kNone,
};

// Where the data lie in an image of a given size.
struct PlotAxes {
  double x_min = 0.0;
  double x_max = 1.0;
  double y_min = 0.0;
  double y_max = 1.0;
  // The plot area in output pixels.
  cv::Rect2d area;
  AxisTicks x_ticks;
  AxisTicks y_ticks;

  // (u, v) of the formula at the top of this file.
  cv::Point2d PixelFromData(double x, double y) const;
};

class LinePlot {
 public:
  void SetTitle(std::string title) { title_ = std::move(title); }
  void SetXLabel(std::string label) { x_label_ = std::move(label); }
  void SetYLabel(std::string label) { y_label_ = std::move(label); }
  // Explicit data ranges (lo < hi, finite; CHECKed), drawn without margin.
  void SetXRange(double lo, double hi);
  void SetYRange(double lo, double hi);
  void SetLegendPosition(LegendPosition position) { legend_ = position; }

  // Series. x and y (and y_low, y_high) have equal lengths (CHECKed); an
  // empty label keeps the series out of the legend. Series are drawn in
  // layers whatever the order of the calls: bands, then reference lines
  // (horizontal and vertical), then lines, then markers; within a layer in
  // the order added. Legend entries follow the order of the calls.
  // A polyline through (x_i, y_i).
  void AddLine(std::vector<double> x, std::vector<double> y, std::string label,
               const LineStyle& style = LineStyle());
  // A marker at each (x_i, y_i).
  void AddMarkers(std::vector<double> x, std::vector<double> y,
                  std::string label, const MarkerStyle& style = MarkerStyle());
  // The region between y_low and y_high filled with `color` at `opacity`
  // (in (0, 1]) over whatever lies below it.
  void AddBand(std::vector<double> x, std::vector<double> y_low,
               std::vector<double> y_high, std::string label,
               std::optional<cv::Scalar> color = std::nullopt,
               double opacity = 0.25);
  // y = value across the whole plot (e.g. the truth).
  void AddHorizontalLine(double y, std::string label,
                         const LineStyle& style = LineStyle());
  // x = value across the whole plot, with `label` written above the plot
  // area at the line (e.g. "switch"); not in the legend.
  void AddVerticalMarker(double x, std::string label,
                         const LineStyle& style = LineStyle());

  // The layout Render uses for an image of this size (>= 200 x 150).
  PlotAxes Axes(int width = 1000, int height = 600) const;
  // The plot on a white CV_8UC3 image; deterministic.
  cv::Mat Render(int width = 1000, int height = 600) const;

 private:
  enum class SeriesKind { kLine, kMarkers, kBand, kHorizontal, kVertical };
  struct Series {
    SeriesKind kind;
    std::vector<double> x;
    std::vector<double> y;       // y, or y_low of a band
    std::vector<double> y_high;  // bands only
    std::string label;
    cv::Scalar color;
    LineStyle line;
    MarkerStyle marker;
    double opacity = 1.0;
  };
  struct Layout;
  class Canvas;

  // What DrawData draws: the plot, or where a legend would hide lines
  // (markers, reference lines) or bands.
  enum class DataPass { kColor, kLinesMask, kBandsMask };

  cv::Scalar NextColor(const std::optional<cv::Scalar>& color);
  bool HasLegendEntries() const;
  // The layout without the legend inside the plot area placed.
  Layout ComputeLayout(int width, int height, bool legend_below) const;
  // The layout with the legend placed (LegendPosition resolved).
  Layout ResolveLayout(int width, int height) const;
  void DrawData(const Layout& layout, DataPass pass, Canvas* canvas) const;
  void DrawLegend(const Layout& layout, Canvas* canvas) const;

  std::string title_;
  std::string x_label_;
  std::string y_label_;
  std::optional<std::pair<double, double>> x_range_;
  std::optional<std::pair<double, double>> y_range_;
  LegendPosition legend_ = LegendPosition::kBest;
  std::vector<Series> series_;
  int num_colors_used_ = 0;
};

}  // namespace rcm

#endif  // RCM_PLOT_LINE_PLOT_H_
