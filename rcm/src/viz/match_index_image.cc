#include "rcm/viz/match_index_image.h"

#include <glog/logging.h>

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "rcm/plot/color_map.h"
#include "rcm/util/number_format.h"

namespace rcm {
namespace {

constexpr int kTitleHeight = 34;
constexpr int kBarWidth = 22;
constexpr int kBarMargin = 14;
constexpr int kLabelWidth = 70;
constexpr int kTicks = 5;
const cv::Scalar kInk(30, 30, 30);
const cv::Scalar kPaper(255, 255, 255);

// The turbo color of t in [0, 1].
cv::Vec3b Turbo(double t) { return ColorMapColor(cv::COLORMAP_TURBO, t); }

}  // namespace

cv::Mat DrawMatchesByRefractiveIndex(
    const cv::Mat& image, const std::vector<Eigen::Vector2d>& pixels,
    const std::vector<std::optional<double>>& n,
    const MatchIndexImageOptions& options) {
  CHECK_EQ(pixels.size(), n.size());
  CHECK(!image.empty() && image.depth() == CV_8U &&
        (image.channels() == 1 || image.channels() == 3));
  CHECK_GT(options.half_range, 0.0);
  cv::Mat picture;
  if (image.channels() == 1) {
    cv::cvtColor(image, picture, cv::COLOR_GRAY2BGR);
  } else {
    picture = image.clone();
  }
  // Dim the image so the dots stand out.
  picture = picture * 0.6 + cv::Scalar::all(40);
  const double low = options.center - options.half_range;
  const auto scale = [&](double value) {
    return (value - low) / (2.0 * options.half_range);
  };
  for (size_t i = 0; i < pixels.size(); ++i) {
    const cv::Point center(static_cast<int>(std::lround(pixels[i].x())),
                           static_cast<int>(std::lround(pixels[i].y())));
    if (!n[i]) {
      cv::circle(picture, center, options.radius, cv::Scalar(150, 150, 150), 1,
                 cv::LINE_AA);
      continue;
    }
    const cv::Vec3b color = Turbo(scale(*n[i]));
    cv::circle(picture, center, options.radius,
               cv::Scalar(color[0], color[1], color[2]), cv::FILLED,
               cv::LINE_AA);
  }

  const int width = picture.cols + kBarMargin + kBarWidth + kLabelWidth;
  const int height = picture.rows + kTitleHeight;
  cv::Mat canvas(height, width, CV_8UC3, kPaper);
  picture.copyTo(canvas(cv::Rect(0, kTitleHeight, picture.cols, picture.rows)));
  cv::putText(canvas, options.title, cv::Point(8, 23), cv::FONT_HERSHEY_SIMPLEX,
              0.55, kInk, 1, cv::LINE_AA);
  // Color bar, high values on top.
  const int bar_x = picture.cols + kBarMargin;
  const int bar_top = kTitleHeight + 10;
  const int bar_height = picture.rows - 20;
  for (int y = 0; y < bar_height; ++y) {
    const cv::Vec3b color =
        Turbo(1.0 - static_cast<double>(y) / (bar_height - 1));
    cv::line(canvas, cv::Point(bar_x, bar_top + y),
             cv::Point(bar_x + kBarWidth - 1, bar_top + y),
             cv::Scalar(color[0], color[1], color[2]));
  }
  cv::rectangle(canvas, cv::Rect(bar_x, bar_top, kBarWidth, bar_height), kInk);
  for (int k = 0; k < kTicks; ++k) {
    const double t = static_cast<double>(k) / (kTicks - 1);
    const int y =
        bar_top + static_cast<int>(std::lround((1.0 - t) * (bar_height - 1)));
    cv::line(canvas, cv::Point(bar_x + kBarWidth, y),
             cv::Point(bar_x + kBarWidth + 4, y), kInk);
    cv::putText(canvas, FormatFixed(low + t * 2.0 * options.half_range, 3),
                cv::Point(bar_x + kBarWidth + 7, y + 5),
                cv::FONT_HERSHEY_SIMPLEX, 0.42, kInk, 1, cv::LINE_AA);
  }
  return canvas;
}

}  // namespace rcm
