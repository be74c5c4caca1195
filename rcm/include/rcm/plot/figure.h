// Figure: a supersampled, anti-aliased canvas for rcm's pictures: the
// calibration report's residual, coverage and uncertainty figures
// (rcm/calib/calibration_report.h) and the image error map
// (rcm/viz/image_error_map.h). Drawn in the manner of rcm::LinePlot: at 3x
// the output size with cv::LINE_AA, then averaged down with
// cv::INTER_AREA, so that strokes and text get sub-pixel positions and
// smooth edges.
//
// Output coordinates have pixel centers at integers (pixel i spans
// [i - 0.5, i + 0.5]), x right, y down. Stroke widths are in output
// pixels; text sizes scale with the size factor z given at construction
// (rcm's figures take z = sqrt(area / (1000 x 600)), clamped to [1, 2.5]).
// Colors are BGR, as everywhere in OpenCV.
//
// Also here: the colors and fonts these figures share and the 1-2-5
// numbers of their scales (the ticks of an axis are rcm::NiceTicks, in
// rcm/plot/line_plot.h).
#ifndef RCM_PLOT_FIGURE_H_
#define RCM_PLOT_FIGURE_H_

#include <limits>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace rcm {

// Colors of the figures.
extern const cv::Scalar kWhite;     // background
extern const cv::Scalar kInk;       // text, arrows
extern const cv::Scalar kFrame;     // frames, color bar ticks
extern const cv::Scalar kPanel;     // background of an image panel
extern const cv::Scalar kGridLine;  // cell grid over a panel
extern const cv::Scalar kMuted;     // secondary text
extern const cv::Scalar kNoData;    // where there is no value

// A Hershey font; `scale` is cv's font scale at z = 1.
struct FigureFont {
  int face;
  double scale;
};
extern const FigureFont kTitleFont;
extern const FigureFont kTextFont;
extern const FigureFont kSmallFont;

class Figure {
 public:
  // A white figure of width x height output pixels; z scales text (z > 0).
  Figure(int width, int height, double z);

  double z() const { return z_; }

  // Drawing (not Paste) goes into the output rectangle with edges x0, x1,
  // y0, y1 until Unclip.
  void Clip(double x0, double y0, double x1, double y1);
  void Unclip();

  void Line(const cv::Point2d& a, const cv::Point2d& b, const cv::Scalar& color,
            double width);
  // Nothing for fewer than two points.
  void Polyline(const std::vector<cv::Point2d>& points, bool closed,
                const cv::Scalar& color, double width);
  void Disc(const cv::Point2d& center, double radius, const cv::Scalar& color);
  // A shaft from `from` to `to` with a head of two strokes at `to`, at most
  // 40 % of the length long; nothing for a zero or non-finite length.
  void Arrow(const cv::Point2d& from, const cv::Point2d& to,
             const cv::Scalar& color, double width);
  // cv::arrowedLine with a head of `head` output pixels (at most the
  // length); nothing for a zero length.
  void ArrowedLine(const cv::Point2d& from, const cv::Point2d& to, double head,
                   const cv::Scalar& color, double width);

  // Fills output pixels x0..x1-1, y0..y1-1 (integer edges of pixels).
  void FillRect(int x0, int y0, int x1, int y1, const cv::Scalar& color);
  // The same with edges in continuous output coordinates; rectangles with
  // a common edge meet without a gap or an overlap.
  void FillArea(double x0, double y0, double x1, double y1,
                const cv::Scalar& color);

  // Width and cap height of a text in output pixels, at `shrink` times the
  // font's size.
  cv::Size2d Measure(const std::string& text, const FigureFont& font,
                     double shrink = 1.0) const;
  // Text with the left end of its baseline at `origin`, shrunk to fit
  // `max_width` output pixels; returns its width.
  double Text(const std::string& text, const cv::Point2d& origin,
              const FigureFont& font, const cv::Scalar& color,
              double max_width = std::numeric_limits<double>::infinity());
  // Text centered on `center` over a filled box of `box` color.
  void Label(const std::string& text, const cv::Point2d& center,
             const FigureFont& font, const cv::Scalar& color,
             const cv::Scalar& box);

  // A CV_8UC3 image at output resolution with its top-left pixel at output
  // pixel (x, y), which must fit in the figure; ignores the clip.
  void Paste(const cv::Mat& image, int x, int y);

  // The figure at output size, CV_8UC3.
  cv::Mat Finish() const;

 private:
  // Output coordinates -> supersampled, fixed point, in the clip rectangle.
  cv::Point At(const cv::Point2d& p) const;
  static int Thickness(double width);
  double FontScale(const FigureFont& font) const;
  int FontThickness() const;
  // The supersampled pixel edge of output coordinate x.
  static int Edge(double x);

  int width_;
  int height_;
  double z_;
  cv::Mat canvas_;
  cv::Mat target_;          // canvas_ or its clip rectangle
  cv::Point offset_{0, 0};  // of target_ in canvas_
};

// 1-2-5 numbers m 10^k: the largest <= x, the smallest >= x, the nearest
// in ratio (x > 0, finite).
double NiceFloor(double x);
double NiceCeil(double x);
double NiceNearest(double x);

// "%g": 50, 0.2, 0.75, 1e-05.
std::string FormatShort(double value);

}  // namespace rcm

#endif  // RCM_PLOT_FIGURE_H_
