#include "rcm/plot/line_plot.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

namespace rcm::line_plot_test {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
const cv::Scalar kRed(40, 40, 214);  // BGR

// The pixel of `image` at data point (x, y).
cv::Vec3b PixelAt(const cv::Mat& image, const PlotAxes& axes, double x,
                  double y) {
  const cv::Point2d pixel = axes.PixelFromData(x, y);
  return image.at<cv::Vec3b>(static_cast<int>(std::lround(pixel.y)),
                             static_cast<int>(std::lround(pixel.x)));
}

// Largest difference of one channel.
double ColorDistance(const cv::Vec3b& pixel, const cv::Scalar& color) {
  double distance = 0.0;
  for (int k = 0; k < 3; ++k) {
    distance = std::max(distance, std::abs(pixel[k] - color[k]));
  }
  return distance;
}

bool IsWhite(const cv::Vec3b& pixel) {
  return ColorDistance(pixel, cv::Scalar(255, 255, 255)) <= 2.0;
}

TEST(NiceTicks, CoverTheRangeWithOneTwoFiveSteps) {
  std::mt19937 random(5);
  std::uniform_real_distribution<double> exponent(-6.0, 6.0);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (int trial = 0; trial < 2000; ++trial) {
    const double scale = std::pow(10.0, exponent(random));
    const double a = scale * unit(random) * 5.0;
    const double span = scale * (0.01 + std::abs(unit(random)));
    const int max_ticks = 2 + trial % 11;
    const AxisTicks ticks = NiceTicks(a, a + span, max_ticks);
    SCOPED_TRACE(::testing::Message()
                 << "[" << a << ", " << a + span << "], max " << max_ticks);
    ASSERT_GE(ticks.values.size(), 1u);
    ASSERT_LE(ticks.values.size(), static_cast<size_t>(max_ticks));
    // step = m 10^k with m in {1, 2, 5}.
    const double power =
        std::pow(10.0, std::floor(std::log10(ticks.step) + 1e-9));
    const double mantissa = ticks.step / power;
    EXPECT_TRUE(std::abs(mantissa - 1.0) < 1e-9 ||
                std::abs(mantissa - 2.0) < 1e-9 ||
                std::abs(mantissa - 5.0) < 1e-9)
        << "step " << ticks.step;
    const double tolerance = 1e-9 * ticks.step;
    for (size_t i = 0; i < ticks.values.size(); ++i) {
      const double k = ticks.values[i] / ticks.step;
      EXPECT_NEAR(k, std::round(k), 1e-6);
      EXPECT_GE(ticks.values[i], a - tolerance);
      EXPECT_LE(ticks.values[i], a + span + tolerance);
      if (i > 0) {
        EXPECT_NEAR(ticks.values[i] - ticks.values[i - 1], ticks.step,
                    tolerance);
      }
    }
    EXPECT_LT(ticks.values.front() - a, ticks.step + tolerance);
    EXPECT_LT(a + span - ticks.values.back(), ticks.step + tolerance);
    // The smallest such step: the next smaller nice step gives too many.
    const double smaller = std::abs(mantissa - 1.0) < 1e-9
                               ? 0.5 * ticks.step
                               : ticks.step / (mantissa == 2.0 ? 2.0 : 2.5);
    const double count = std::floor((a + span) / smaller + 1e-9) -
                         std::ceil(a / smaller - 1e-9) + 1.0;
    EXPECT_GT(count, max_ticks) << "step " << ticks.step;
  }
}

TEST(NiceTicks, RefractiveIndexRangesGetEnoughDecimals) {
  const AxisTicks fine = NiceTicks(1.3301, 1.3399, 5);
  EXPECT_DOUBLE_EQ(fine.step, 0.002);
  EXPECT_EQ(fine.decimals, 3);
  ASSERT_EQ(fine.values.size(), 4u);
  EXPECT_EQ(FormatTick(fine.values[0], fine.decimals), "1.332");
  EXPECT_EQ(FormatTick(fine.values[3], fine.decimals), "1.338");

  const AxisTicks finer = NiceTicks(1.3325, 1.3345, 6);
  EXPECT_DOUBLE_EQ(finer.step, 0.0005);
  EXPECT_EQ(finer.decimals, 4);
  EXPECT_EQ(FormatTick(finer.values[2], finer.decimals), "1.3335");

  const AxisTicks frames = NiceTicks(-1.2, 60.2, 8);
  EXPECT_DOUBLE_EQ(frames.step, 10.0);
  EXPECT_EQ(frames.decimals, 0);
  EXPECT_EQ(frames.values.front(), 0.0);
  EXPECT_EQ(frames.values.back(), 60.0);
}

TEST(NiceTicks, FormatTick) {
  EXPECT_EQ(TickDecimals(0.005), 3);
  EXPECT_EQ(TickDecimals(0.1), 1);
  EXPECT_EQ(TickDecimals(1.0), 0);
  EXPECT_EQ(TickDecimals(500.0), 0);
  EXPECT_EQ(FormatTick(1.335, 3), "1.335");
  EXPECT_EQ(FormatTick(-1e-17, 3), "0.000");
  EXPECT_EQ(FormatTick(-0.5, 1), "-0.5");
  EXPECT_EQ(FormatTick(20.0, 0), "20");
}

TEST(LinePlot, AxesMapDataIntoThePlotArea) {
  LinePlot plot;
  plot.SetTitle("title");
  plot.SetXLabel("frame");
  plot.SetYLabel("n");
  plot.SetXRange(0.0, 10.0);
  plot.SetYRange(1.0, 2.0);
  plot.AddLine({0.0, 10.0}, {1.2, 1.8}, "");
  const PlotAxes axes = plot.Axes(800, 500);
  EXPECT_EQ(axes.x_min, 0.0);
  EXPECT_EQ(axes.x_max, 10.0);
  EXPECT_EQ(axes.y_min, 1.0);
  EXPECT_EQ(axes.y_max, 2.0);
  EXPECT_GT(axes.area.x, 20.0);  // room for tick labels and the y label
  EXPECT_LT(axes.area.x + axes.area.width, 800.0);
  EXPECT_GT(axes.area.y, 10.0);  // room for the title
  EXPECT_LT(axes.area.y + axes.area.height, 460.0);
  const cv::Point2d bottom_left = axes.PixelFromData(0.0, 1.0);
  const cv::Point2d top_right = axes.PixelFromData(10.0, 2.0);
  EXPECT_DOUBLE_EQ(bottom_left.x, axes.area.x);
  EXPECT_DOUBLE_EQ(bottom_left.y, axes.area.y + axes.area.height);
  EXPECT_DOUBLE_EQ(top_right.x, axes.area.x + axes.area.width);
  EXPECT_DOUBLE_EQ(top_right.y, axes.area.y);

  // Without an explicit range: the data with a margin.
  LinePlot automatic;
  automatic.AddLine({0.0, 59.0}, {1.0, 1.333}, "");
  const PlotAxes fitted = automatic.Axes();
  EXPECT_LT(fitted.x_min, 0.0);
  EXPECT_GT(fitted.x_max, 59.0);
  EXPECT_LT(fitted.y_min, 1.0);
  EXPECT_GT(fitted.y_max, 1.333);
  EXPECT_LT(fitted.y_max, 1.36);
}

TEST(LinePlot, RenderingIsDeterministic) {
  auto make = [] {
    LinePlot plot;
    plot.SetTitle("n per frame");
    plot.SetXLabel("frame");
    plot.SetYLabel("n");
    std::vector<double> x, y, low, high;
    for (int i = 0; i < 40; ++i) {
      x.push_back(i);
      y.push_back(1.333 + 0.003 * std::sin(i));
      low.push_back(y.back() - 0.002);
      high.push_back(y.back() + 0.002);
    }
    plot.AddBand(x, low, high, "1 sigma");
    plot.AddLine(x, y, "estimate");
    plot.AddMarkers(x, y, "");
    LineStyle dashed;
    dashed.dash = 6.0;
    plot.AddHorizontalLine(1.333, "truth", dashed);
    plot.AddVerticalMarker(20.0, "switch");
    return plot;
  };
  const cv::Mat first = make().Render(640, 400);
  const cv::Mat second = make().Render(640, 400);
  ASSERT_EQ(first.type(), CV_8UC3);
  ASSERT_EQ(first.cols, 640);
  ASSERT_EQ(first.rows, 400);
  EXPECT_EQ(cv::norm(first, second, cv::NORM_INF), 0.0);
  // Something was drawn, on white.
  EXPECT_TRUE(IsWhite(first.at<cv::Vec3b>(0, 0)));
  EXPECT_GT(
      cv::norm(first,
               cv::Mat(first.size(), first.type(), cv::Scalar(255, 255, 255)),
               cv::NORM_L1),
      1e5);
}

TEST(LinePlot, BandIsFilledWhereItLies) {
  // A band between y = 1 and y = 2 over x in [2, 8], half transparent red,
  // on axes [0, 10] x [0, 3]. Probe points off the grid lines.
  LinePlot plot;
  plot.SetXRange(0.0, 10.0);
  plot.SetYRange(0.0, 3.0);
  plot.AddBand({2.0, 8.0}, {1.0, 1.0}, {2.0, 2.0}, "", kRed, 0.5);
  const cv::Mat image = plot.Render();
  const PlotAxes axes = plot.Axes();
  const cv::Scalar blended = 0.5 * kRed + 0.5 * cv::Scalar(255, 255, 255);
  for (double x : {2.3, 4.7, 7.7}) {
    for (double y : {1.1, 1.7, 1.9}) {
      EXPECT_LE(ColorDistance(PixelAt(image, axes, x, y), blended), 3.0)
          << "inside at (" << x << ", " << y << ")";
    }
  }
  for (const auto& [x, y] : std::vector<std::pair<double, double>>{
           {1.7, 1.7}, {8.3, 1.3}, {4.7, 2.3}, {4.7, 0.7}}) {
    EXPECT_TRUE(IsWhite(PixelAt(image, axes, x, y)))
        << "outside at (" << x << ", " << y << ")";
  }
}

TEST(LinePlot, NanBreaksLinesAndSkipsMarkers) {
  LinePlot plot;
  plot.SetXRange(0.0, 4.0);
  plot.SetYRange(0.0, 2.0);
  LineStyle style;
  style.color = kRed;
  style.width = 3.0;
  plot.AddLine({0.0, 1.0, 2.0, 3.0, 4.0}, {1.1, 1.1, kNaN, 1.1, 1.1}, "",
               style);
  MarkerStyle marker;
  marker.color = kRed;
  marker.radius = 5.0;
  plot.AddMarkers({1.0, 2.0, kNaN}, {0.3, kNaN, 0.3}, "", marker);
  const cv::Mat image = plot.Render();
  const PlotAxes axes = plot.Axes();
  EXPECT_LE(ColorDistance(PixelAt(image, axes, 0.6, 1.1), kRed), 10.0);
  EXPECT_LE(ColorDistance(PixelAt(image, axes, 3.4, 1.1), kRed), 10.0);
  // The gap from x = 1 to x = 3 (the grid may cross it: not red is enough).
  EXPECT_GT(ColorDistance(PixelAt(image, axes, 1.85, 1.1), kRed), 100.0);
  EXPECT_GT(ColorDistance(PixelAt(image, axes, 2.15, 1.1), kRed), 100.0);
  EXPECT_LE(ColorDistance(PixelAt(image, axes, 1.0, 0.3), kRed), 10.0);
  EXPECT_GT(ColorDistance(PixelAt(image, axes, 2.0, 0.3), kRed), 100.0);

  // Nothing finite at all still renders (axes [0, 1]).
  LinePlot empty;
  empty.AddLine({kNaN, kNaN}, {kNaN, 1.0}, "nothing");
  empty.AddBand({kNaN}, {kNaN}, {kNaN}, "");
  const cv::Mat rendered = empty.Render(400, 300);
  EXPECT_EQ(rendered.cols, 400);
  EXPECT_EQ(empty.Axes(400, 300).x_min, 0.0);
}

TEST(LinePlot, ReferenceLinesAndDashes) {
  LinePlot plot;
  plot.SetXRange(0.0, 10.0);
  plot.SetYRange(0.0, 10.0);
  LineStyle dashed;
  dashed.color = kRed;
  dashed.width = 2.0;
  dashed.dash = 10.0;
  dashed.gap = 10.0;
  plot.AddHorizontalLine(3.3, "", dashed);
  LineStyle solid;
  solid.color = cv::Scalar(180, 119, 31);
  plot.AddVerticalMarker(6.7, "switch", solid);
  const cv::Mat image = plot.Render();
  const PlotAxes axes = plot.Axes();
  // Along the dashed line about half the pixels are red, the rest not.
  const int row = static_cast<int>(std::lround(axes.PixelFromData(0, 3.3).y));
  int red = 0;
  int other = 0;
  for (int u = static_cast<int>(axes.area.x) + 2;
       u < axes.area.x + axes.area.width - 2; ++u) {
    const double distance = ColorDistance(image.at<cv::Vec3b>(row, u), kRed);
    if (distance < 40.0) ++red;
    if (distance > 120.0) ++other;
  }
  const double length = axes.area.width;
  EXPECT_GT(red, 0.3 * length);
  EXPECT_GT(other, 0.3 * length);
  // The vertical marker runs from the top to the bottom of the plot area.
  for (double y : {0.3, 4.7, 9.7}) {
    EXPECT_LE(ColorDistance(PixelAt(image, axes, 6.7, y), *solid.color), 10.0);
  }
}

TEST(LinePlot, LegendDoesNotHideData) {
  // A rising line leaves the top left and bottom right corners free; the
  // legend takes one of them and every point of the line stays visible.
  LinePlot plot;
  LineStyle style;
  style.color = kRed;
  std::vector<double> x, y;
  for (int i = 0; i <= 100; ++i) {
    x.push_back(i);
    y.push_back(i);
  }
  plot.AddLine(x, y, "a rising line with a long label", style);
  const cv::Mat image = plot.Render();
  const PlotAxes axes = plot.Axes();
  for (int i = 0; i <= 100; i += 5) {
    EXPECT_LE(ColorDistance(PixelAt(image, axes, i, i), kRed), 10.0)
        << "at " << i;
  }

  // When the data fill the whole plot the legend goes below it, which
  // shrinks the plot area.
  LinePlot full;
  std::vector<double> low(x.size(), 0.0), high(x.size(), 100.0), zig;
  for (int i = 0; i <= 100; ++i) zig.push_back(i % 2 == 0 ? 0.0 : 100.0);
  full.AddLine(x, zig, "zigzag");
  LinePlot full_unlabeled;
  full_unlabeled.AddLine(x, zig, "");
  EXPECT_LT(full.Axes().area.height + 20.0, full_unlabeled.Axes().area.height);
  full.SetLegendPosition(LegendPosition::kTopRight);
  EXPECT_EQ(full.Axes().area.height, full_unlabeled.Axes().area.height);
}

}  // namespace
}  // namespace rcm::line_plot_test
