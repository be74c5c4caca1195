#include "rcm/plot/figure.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <opencv2/imgproc.hpp>

namespace rcm {
namespace {

constexpr int kSupersample = 3;
constexpr int kShift = 4;  // fractional bits of cv drawing coordinates
constexpr double kShiftScale = 1 << kShift;

}  // namespace

const cv::Scalar kWhite(255, 255, 255);
const cv::Scalar kInk(34, 34, 34);
const cv::Scalar kFrame(80, 80, 80);
const cv::Scalar kPanel(246, 246, 246);
const cv::Scalar kGridLine(215, 215, 215);
const cv::Scalar kMuted(110, 110, 110);
const cv::Scalar kNoData(200, 200, 200);

const FigureFont kTitleFont{cv::FONT_HERSHEY_DUPLEX, 0.62};
const FigureFont kTextFont{cv::FONT_HERSHEY_SIMPLEX, 0.50};
const FigureFont kSmallFont{cv::FONT_HERSHEY_SIMPLEX, 0.40};

Figure::Figure(int width, int height, double z)
    : width_(width),
      height_(height),
      z_(z),
      canvas_(height * kSupersample, width * kSupersample, CV_8UC3, kWhite),
      target_(canvas_) {}

void Figure::Clip(double x0, double y0, double x1, double y1) {
  const cv::Rect rect(cv::Point(Edge(x0), Edge(y0)),
                      cv::Point(Edge(x1), Edge(y1)));
  const cv::Rect clip = rect & cv::Rect(0, 0, canvas_.cols, canvas_.rows);
  target_ = canvas_(clip);
  offset_ = clip.tl();
}

void Figure::Unclip() {
  target_ = canvas_;
  offset_ = cv::Point(0, 0);
}

void Figure::Line(const cv::Point2d& a, const cv::Point2d& b,
                  const cv::Scalar& color, double width) {
  cv::line(target_, At(a), At(b), color, Thickness(width), cv::LINE_AA, kShift);
}

void Figure::Polyline(const std::vector<cv::Point2d>& points, bool closed,
                      const cv::Scalar& color, double width) {
  if (points.size() < 2) return;
  std::vector<cv::Point> fixed;
  fixed.reserve(points.size());
  for (const cv::Point2d& point : points) fixed.push_back(At(point));
  cv::polylines(target_, std::vector<std::vector<cv::Point>>{fixed}, closed,
                color, Thickness(width), cv::LINE_AA, kShift);
}

void Figure::Disc(const cv::Point2d& center, double radius,
                  const cv::Scalar& color) {
  cv::circle(target_, At(center),
             static_cast<int>(std::lround(radius * kSupersample * kShiftScale)),
             color, cv::FILLED, cv::LINE_AA, kShift);
}

void Figure::Arrow(const cv::Point2d& from, const cv::Point2d& to,
                   const cv::Scalar& color, double width) {
  const cv::Point2d d = to - from;
  const double length = std::hypot(d.x, d.y);
  if (!(length > 0.0) || !std::isfinite(length)) return;
  Line(from, to, color, width);
  const double head = std::min(0.4 * length, (2.5 + 1.5 * width) * z_);
  const cv::Point2d back = -d * (head / length);
  const double c = std::cos(0.45);
  const double s = std::sin(0.45);
  Line(to, to + cv::Point2d(c * back.x - s * back.y, s * back.x + c * back.y),
       color, width);
  Line(to, to + cv::Point2d(c * back.x + s * back.y, -s * back.x + c * back.y),
       color, width);
}

void Figure::ArrowedLine(const cv::Point2d& from, const cv::Point2d& to,
                         double head, const cv::Scalar& color, double width) {
  const double length = std::hypot(to.x - from.x, to.y - from.y);
  if (!(length > 0.0)) return;
  cv::arrowedLine(target_, At(from), At(to), color, Thickness(width),
                  cv::LINE_AA, kShift, std::min(1.0, head / length));
}

void Figure::FillRect(int x0, int y0, int x1, int y1, const cv::Scalar& color) {
  cv::rectangle(
      target_,
      cv::Rect(cv::Point(x0 * kSupersample, y0 * kSupersample) - offset_,
               cv::Point(x1 * kSupersample, y1 * kSupersample) - offset_),
      color, cv::FILLED);
}

void Figure::FillArea(double x0, double y0, double x1, double y1,
                      const cv::Scalar& color) {
  cv::rectangle(target_,
                cv::Rect(cv::Point(Edge(x0), Edge(y0)) - offset_,
                         cv::Point(Edge(x1), Edge(y1)) - offset_),
                color, cv::FILLED);
}

cv::Size2d Figure::Measure(const std::string& text, const FigureFont& font,
                           double shrink) const {
  int baseline = 0;
  const cv::Size size = cv::getTextSize(
      text, font.face, FontScale(font) * shrink, FontThickness(), &baseline);
  return cv::Size2d(static_cast<double>(size.width) / kSupersample,
                    static_cast<double>(size.height) / kSupersample);
}

double Figure::Text(const std::string& text, const cv::Point2d& origin,
                    const FigureFont& font, const cv::Scalar& color,
                    double max_width) {
  if (text.empty()) return 0.0;
  double shrink = 1.0;
  const double width = Measure(text, font).width;
  if (width > max_width && max_width > 0.0) shrink = max_width / width;
  cv::putText(
      target_, text,
      cv::Point(static_cast<int>(std::lround(origin.x * kSupersample + 1.0)),
                static_cast<int>(std::lround(origin.y * kSupersample + 1.0))) -
          offset_,
      font.face, FontScale(font) * shrink, color, FontThickness(), cv::LINE_AA);
  return width * shrink;
}

void Figure::Label(const std::string& text, const cv::Point2d& center,
                   const FigureFont& font, const cv::Scalar& color,
                   const cv::Scalar& box) {
  const cv::Size2d size = Measure(text, font);
  const double pad = 2.0 * z_;
  FillArea(center.x - 0.5 * size.width - pad,
           center.y - 0.5 * size.height - pad,
           center.x + 0.5 * size.width + pad,
           center.y + 0.5 * size.height + pad, box);
  Text(text,
       cv::Point2d(center.x - 0.5 * size.width, center.y + 0.5 * size.height),
       font, color);
}

void Figure::Paste(const cv::Mat& image, int x, int y) {
  cv::Mat big;
  cv::resize(image, big, cv::Size(), kSupersample, kSupersample,
             cv::INTER_NEAREST);
  big.copyTo(canvas_(
      cv::Rect(x * kSupersample, y * kSupersample, big.cols, big.rows)));
}

cv::Mat Figure::Finish() const {
  cv::Mat output;
  cv::resize(canvas_, output, cv::Size(width_, height_), 0, 0, cv::INTER_AREA);
  return output;
}

cv::Point Figure::At(const cv::Point2d& p) const {
  return cv::Point(static_cast<int>(std::lround(
                       (p.x * kSupersample + 1.0 - offset_.x) * kShiftScale)),
                   static_cast<int>(std::lround(
                       (p.y * kSupersample + 1.0 - offset_.y) * kShiftScale)));
}

int Figure::Thickness(double width) {
  return std::max(1, static_cast<int>(std::lround(width * kSupersample)));
}

double Figure::FontScale(const FigureFont& font) const {
  return font.scale * z_ * kSupersample;
}

int Figure::FontThickness() const {
  return static_cast<int>(std::lround(std::max(0.75, z_) * kSupersample));
}

int Figure::Edge(double x) {
  return static_cast<int>(std::lround((x + 0.5) * kSupersample));
}

double NiceFloor(double x) {
  const double power = std::pow(10.0, std::floor(std::log10(x)));
  for (const double m : {5.0, 2.0, 1.0}) {
    if (m * power <= x * (1.0 + 1e-12)) return m * power;
  }
  return power;
}

double NiceCeil(double x) {
  const double power = std::pow(10.0, std::floor(std::log10(x)));
  for (const double m : {1.0, 2.0, 5.0, 10.0}) {
    if (m * power >= x * (1.0 - 1e-12)) return m * power;
  }
  return 10.0 * power;
}

double NiceNearest(double x) {
  const double low = NiceFloor(x);
  const double high = NiceCeil(x);
  return x / low <= high / x ? low : high;
}

std::string FormatShort(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%g", value);
  return buffer;
}

}  // namespace rcm
