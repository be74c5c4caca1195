#include "rcm/viz/image_error_map.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <string>
#include <vector>

#include "rcm/plot/color_map.h"

namespace rcm::image_error_map_test {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

using ErrorAt = std::function<std::optional<Eigen::Vector2d>(int col, int row)>;

// A grid of step x step cells tiling a width x height image, samples at the
// cell centers.
ImageErrorField MakeField(int width, int height, int step,
                          const ErrorAt& error_at) {
  ImageErrorField field;
  field.image_width = width;
  field.image_height = height;
  field.cols = width / step;
  field.rows = height / step;
  field.step = step;
  field.origin = Eigen::Vector2d(0.5 * step - 0.5, 0.5 * step - 0.5);
  for (int row = 0; row < field.rows; ++row) {
    for (int col = 0; col < field.cols; ++col) {
      field.errors.push_back(error_at(col, row));
    }
  }
  return field;
}

ImageErrorField UniformField(int width, int height, int step,
                             const Eigen::Vector2d& error) {
  return MakeField(width, height, step,
                   [&](int, int) { return std::make_optional(error); });
}

cv::Mat Draw(const ImageErrorField& field,
             const ImageErrorMapOptions& options) {
  const StatusOr<cv::Mat> figure = DrawImageErrorMap(field, options);
  EXPECT_TRUE(figure.ok()) << figure.status().message();
  if (!figure.ok()) return cv::Mat();
  EXPECT_EQ(figure->type(), CV_8UC3);
  return *figure;
}

// The drawn image frame: the bounding box of the largest 8-connected set of
// pixels that are not white (the frame and everything inside it; the
// colour bar and the letters stand apart).
cv::Rect FrameRect(const cv::Mat& figure) {
  cv::Mat gray;
  cv::cvtColor(figure, gray, cv::COLOR_BGR2GRAY);
  cv::Mat ink = gray < 250;
  cv::Mat labels, stats, centroids;
  const int n = cv::connectedComponentsWithStats(ink, labels, stats, centroids,
                                                 8, CV_32S);
  int best = -1;
  for (int i = 1; i < n; ++i) {
    if (best < 0 || stats.at<int>(i, cv::CC_STAT_AREA) >
                        stats.at<int>(best, cv::CC_STAT_AREA)) {
      best = i;
    }
  }
  if (best < 0) return cv::Rect();
  return cv::Rect(stats.at<int>(best, cv::CC_STAT_LEFT),
                  stats.at<int>(best, cv::CC_STAT_TOP),
                  stats.at<int>(best, cv::CC_STAT_WIDTH),
                  stats.at<int>(best, cv::CC_STAT_HEIGHT));
}

// The figure pixel at image pixel (u, v) of `field`'s image.
cv::Vec3b PixelAt(const cv::Mat& figure, const cv::Rect& frame,
                  const ImageErrorField& field, double u, double v) {
  const double x = frame.x - 0.5 + (u + 0.5) * frame.width / field.image_width;
  const double y =
      frame.y - 0.5 + (v + 0.5) * frame.height / field.image_height;
  return figure.at<cv::Vec3b>(static_cast<int>(std::lround(y)),
                              static_cast<int>(std::lround(x)));
}

cv::Vec3b CellCenter(const cv::Mat& figure, const cv::Rect& frame,
                     const ImageErrorField& field, int col, int row) {
  const Eigen::Vector2d pixel = field.Pixel(col, row);
  return PixelAt(figure, frame, field, pixel.x(), pixel.y());
}

// Largest difference of one channel.
int ColorDistance(const cv::Vec3b& a, const cv::Vec3b& b) {
  int distance = 0;
  for (int k = 0; k < 3; ++k)
    distance = std::max(distance, std::abs(a[k] - b[k]));
  return distance;
}

cv::Vec3b Viridis(double t) { return ColorMapColor(cv::COLORMAP_VIRIDIS, t); }

// The t in [0, 1] whose viridis colour is nearest to `color`.
double NearestT(const cv::Vec3b& color) {
  int best = 0;
  int best_distance = 1 << 30;
  for (int i = 0; i < 256; ++i) {
    const cv::Vec3b c = Viridis(i / 255.0);
    int distance = 0;
    for (int k = 0; k < 3; ++k)
      distance += (c[k] - color[k]) * (c[k] - color[k]);
    if (distance < best_distance) {
      best_distance = distance;
      best = i;
    }
  }
  return best / 255.0;
}

bool IsDark(const cv::Vec3b& pixel) {
  return std::max({pixel[0], pixel[1], pixel[2]}) < 110;
}

// Dark pixels of the frame's inside, `inset` pixels away from its border.
cv::Mat DarkInside(const cv::Mat& figure, const cv::Rect& frame, int inset) {
  const cv::Rect inside(frame.x + inset, frame.y + inset,
                        frame.width - 2 * inset, frame.height - 2 * inset);
  cv::Mat dark(inside.size(), CV_8UC1, cv::Scalar(0));
  for (int y = 0; y < inside.height; ++y) {
    for (int x = 0; x < inside.width; ++x) {
      if (IsDark(figure.at<cv::Vec3b>(inside.y + y, inside.x + x))) {
        dark.at<unsigned char>(y, x) = 255;
      }
    }
  }
  return dark;
}

// Runs of consecutive columns of `mask` with a set pixel.
int ColumnRuns(const cv::Mat& mask) {
  int runs = 0;
  bool in_run = false;
  for (int x = 0; x < mask.cols; ++x) {
    const bool set = cv::countNonZero(mask.col(x)) > 0;
    if (set && !in_run) ++runs;
    in_run = set;
  }
  return runs;
}

double MeanX(const cv::Mat& mask) {
  cv::Mat points;
  cv::findNonZero(mask, points);
  if (points.empty()) return kNaN;
  return cv::mean(points)[0];
}

ImageErrorMapOptions NoArrows() {
  ImageErrorMapOptions options;
  options.title = "test";
  options.arrows_across = 0;
  return options;
}

// ---------------------------------------------------------------------------

TEST(ImageErrorMap, FigureSizeFollowsFrameWidthAndAspect) {
  struct Case {
    int width, height, step, frame_width;
  };
  for (const Case& c : {Case{720, 540, 45, 720}, Case{1280, 720, 40, 500},
                        Case{640, 480, 40, 1000}, Case{400, 800, 50, 300},
                        Case{200, 100, 20, 100}}) {
    SCOPED_TRACE(::testing::Message()
                 << c.width << " x " << c.height << " at " << c.frame_width);
    ImageErrorMapOptions options = NoArrows();
    options.frame_width = c.frame_width;
    const cv::Mat figure =
        Draw(UniformField(c.width, c.height, c.step, Eigen::Vector2d(0.3, 0.1)),
             options);
    ASSERT_FALSE(figure.empty());
    const int frame_height = static_cast<int>(
        std::lround(static_cast<double>(c.height) * c.frame_width / c.width));
    const cv::Rect frame = FrameRect(figure);
    EXPECT_GE(frame.width, c.frame_width - 1);
    EXPECT_LE(frame.width, c.frame_width + 2);
    EXPECT_GE(frame.height, frame_height - 1);
    EXPECT_LE(frame.height, frame_height + 2);
    // Margins, the colour bar and the text lines around it.
    EXPECT_GE(figure.cols, c.frame_width + 60);
    EXPECT_GE(figure.rows, frame_height + 40);
    EXPECT_LE(figure.rows, frame_height + 200);
  }
}

TEST(ImageErrorMap, UniformFieldColoursEveryCellTheSame) {
  // |error| 0.3: the automatic top of the scale is 0.5, t = 0.6.
  const ImageErrorField field =
      UniformField(720, 540, 45, Eigen::Vector2d(0.18, -0.24));
  const cv::Mat figure = Draw(field, NoArrows());
  ASSERT_FALSE(figure.empty());
  const cv::Rect frame = FrameRect(figure);
  const cv::Vec3b expected = Viridis(0.6);
  const cv::Vec3b first = CellCenter(figure, frame, field, 0, 0);
  for (int row = 0; row < field.rows; ++row) {
    for (int col = 0; col < field.cols; ++col) {
      SCOPED_TRACE(::testing::Message() << "cell " << col << ", " << row);
      const cv::Vec3b center = CellCenter(figure, frame, field, col, row);
      EXPECT_LE(ColorDistance(center, expected), 3);
      EXPECT_LE(ColorDistance(center, first), 1);
      // Off the center too: the whole cell.
      const Eigen::Vector2d corner =
          field.Pixel(col, row) + Eigen::Vector2d(-15.0, 15.0);
      EXPECT_LE(
          ColorDistance(PixelAt(figure, frame, field, corner.x(), corner.y()),
                        expected),
          3);
    }
  }
}

TEST(ImageErrorMap, CellColoursFollowTheColourMap) {
  // |error| = 0.1 (col + 1) + 0.01 row in varying directions: t = |error|
  // on a scale to 1 (set, or chosen from the max 0.85).
  const auto magnitude = [](int col, int row) {
    return 0.1 * (col + 1) + 0.01 * row;
  };
  const ImageErrorField field = MakeField(640, 480, 80, [&](int col, int row) {
    const double angle = 0.7 * col + 1.3 * row;
    return std::make_optional<Eigen::Vector2d>(
        magnitude(col, row) *
        Eigen::Vector2d(std::cos(angle), std::sin(angle)));
  });
  for (const double color_max : {1.0, 0.0}) {
    SCOPED_TRACE(::testing::Message() << "color_max " << color_max);
    ImageErrorMapOptions options = NoArrows();
    options.color_max = color_max;
    const cv::Mat figure = Draw(field, options);
    ASSERT_FALSE(figure.empty());
    const cv::Rect frame = FrameRect(figure);
    for (int row = 0; row < field.rows; ++row) {
      double previous = -1.0;
      for (int col = 0; col < field.cols; ++col) {
        const double t = NearestT(CellCenter(figure, frame, field, col, row));
        EXPECT_NEAR(t, magnitude(col, row), 0.015)
            << "cell " << col << ", " << row;
        EXPECT_GT(t, previous) << "cell " << col << ", " << row;
        previous = t;
      }
    }
  }
  // A lower top: larger errors saturate at the top colour.
  ImageErrorMapOptions options = NoArrows();
  options.color_max = 0.4;
  const cv::Mat figure = Draw(field, options);
  ASSERT_FALSE(figure.empty());
  const cv::Rect frame = FrameRect(figure);
  EXPECT_NEAR(NearestT(CellCenter(figure, frame, field, 1, 0)), 0.5, 0.015);
  EXPECT_NEAR(NearestT(CellCenter(figure, frame, field, 5, 0)), 1.0, 0.005);
  EXPECT_NEAR(NearestT(CellCenter(figure, frame, field, 7, 5)), 1.0, 0.005);
}

TEST(ImageErrorMap, AbsentSamplesAreGrey) {
  const auto absent = [](int col, int row) { return (col + 2 * row) % 5 == 0; };
  const ImageErrorField field = MakeField(640, 480, 80, [&](int col, int row) {
    return absent(col, row) ? std::nullopt
                            : std::make_optional<Eigen::Vector2d>(
                                  0.05 * (col + row + 1), 0.0);
  });
  const cv::Mat figure = Draw(field, NoArrows());
  ASSERT_FALSE(figure.empty());
  const cv::Rect frame = FrameRect(figure);
  const cv::Vec3b grey(200, 200, 200);
  int absent_cells = 0;
  for (int row = 0; row < field.rows; ++row) {
    for (int col = 0; col < field.cols; ++col) {
      SCOPED_TRACE(::testing::Message() << "cell " << col << ", " << row);
      const cv::Vec3b center = CellCenter(figure, frame, field, col, row);
      if (absent(col, row)) {
        ++absent_cells;
        EXPECT_LE(ColorDistance(center, grey), 3);
      } else {
        EXPECT_GT(ColorDistance(center, grey), 40);
      }
    }
  }
  EXPECT_GE(absent_cells, 5);
}

TEST(ImageErrorMap, ZeroErrorsTakeTheBottomColour) {
  const ImageErrorField field =
      UniformField(320, 240, 40, Eigen::Vector2d::Zero());
  ImageErrorMapOptions options;
  options.arrows_across = 8;  // nothing to draw
  const cv::Mat figure = Draw(field, options);
  ASSERT_FALSE(figure.empty());
  const cv::Rect frame = FrameRect(figure);
  for (int row = 0; row < field.rows; ++row) {
    for (int col = 0; col < field.cols; ++col) {
      EXPECT_LE(ColorDistance(CellCenter(figure, frame, field, col, row),
                              Viridis(0.0)),
                3);
    }
  }
}

TEST(ImageErrorMap, RegionRectangleIsDrawnDashed) {
  // Yellow (t = 1) everywhere, so that the ink stands out; scale 1.
  const ImageErrorField field =
      UniformField(640, 480, 40, Eigen::Vector2d(0.0, 0.5));
  ImageErrorMapOptions options = NoArrows();
  options.frame_width = 640;
  const cv::Mat plain = Draw(field, options);
  options.region = Eigen::Vector4d(100.0, 80.0, 500.0, 400.0);
  options.region_label = "5 % inset";
  const cv::Mat figure = Draw(field, options);
  ASSERT_FALSE(plain.empty());
  ASSERT_FALSE(figure.empty());
  const cv::Rect frame = FrameRect(figure);
  ASSERT_EQ(frame, FrameRect(plain));

  // Dark within a pixel of an edge of the rectangle at (u, v).
  const auto dark_near = [&](const cv::Mat& image, double u, double v) {
    const double x = frame.x - 0.5 + (u + 0.5) * frame.width / 640.0;
    const double y = frame.y - 0.5 + (v + 0.5) * frame.height / 480.0;
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dx = -1; dx <= 1; ++dx) {
        const int px = static_cast<int>(std::lround(x)) + dx;
        const int py = static_cast<int>(std::lround(y)) + dy;
        if (IsDark(image.at<cv::Vec3b>(py, px))) return true;
      }
    }
    return false;
  };
  // Along each edge, dark pixels on the dashes only.
  const auto dark_fraction = [&](const cv::Mat& image, double u0, double v0,
                                 double u1, double v1) {
    int dark = 0;
    const int n = 200;
    for (int i = 0; i < n; ++i) {
      const double s = (i + 0.5) / n;
      dark += dark_near(image, u0 + s * (u1 - u0), v0 + s * (v1 - v0)) ? 1 : 0;
    }
    return static_cast<double>(dark) / n;
  };
  const double edges[4][4] = {{110, 80, 490, 80},
                              {500, 90, 500, 390},
                              {110, 400, 490, 400},
                              {100, 90, 100, 390}};
  for (const auto& e : edges) {
    SCOPED_TRACE(::testing::Message() << "edge " << e[0] << ", " << e[1]
                                      << " - " << e[2] << ", " << e[3]);
    const double fraction = dark_fraction(figure, e[0], e[1], e[2], e[3]);
    EXPECT_GT(fraction, 0.4);
    EXPECT_LT(fraction, 0.95);  // dashed, not solid
    EXPECT_EQ(dark_fraction(plain, e[0], e[1], e[2], e[3]), 0.0);
  }
  // Not inside or outside it.
  EXPECT_EQ(dark_fraction(figure, 150, 240, 450, 240), 0.0);
  EXPECT_EQ(dark_fraction(figure, 20, 40, 620, 40), 0.0);
  EXPECT_EQ(dark_fraction(figure, 560, 40, 560, 440), 0.0);
}

TEST(ImageErrorMap, ArrowsPresentOnlyWhenAsked) {
  const ImageErrorField field = MakeField(720, 540, 15, [](int col, int row) {
    const Eigen::Vector2d d =
        Eigen::Vector2d(15.0 * col - 352.5, 15.0 * row - 262.5);
    return std::make_optional<Eigen::Vector2d>(0.002 * d);
  });
  ImageErrorMapOptions options;
  options.arrows_across = 16;
  const cv::Mat with = Draw(field, options);
  options.arrows_across = 0;
  const cv::Mat without = Draw(field, options);
  ASSERT_FALSE(with.empty());
  ASSERT_FALSE(without.empty());
  const cv::Rect frame = FrameRect(with);
  ASSERT_EQ(frame, FrameRect(without));
  cv::Mat difference;
  cv::absdiff(with(frame), without(frame), difference);
  EXPECT_GT(cv::countNonZero(difference.reshape(1)), 1000);
  // Dark ink on the light (large error) part of the map: outside a
  // central ellipse, where the colours are light.
  const auto dark_outer = [&](const cv::Mat& figure) {
    const cv::Mat dark = DarkInside(figure, frame, 3);
    int count = 0;
    for (int y = 0; y < dark.rows; ++y) {
      for (int x = 0; x < dark.cols; ++x) {
        const double a = (x - 0.5 * dark.cols) / (0.5 * dark.cols);
        const double b = (y - 0.5 * dark.rows) / (0.5 * dark.rows);
        if (a * a + b * b > 0.6 && dark.at<unsigned char>(y, x) != 0) ++count;
      }
    }
    return count;
  };
  EXPECT_GT(dark_outer(with), 300);
  EXPECT_EQ(dark_outer(without), 0);
}

TEST(ImageErrorMap, AboutArrowsAcrossPerRowPointingAlongTheError) {
  // Yellow (t = 1) everywhere; vertical arrows stand in columns.
  const ImageErrorField up = UniformField(720, 540, 15, {0.0, 0.5});
  for (const int across : {16, 8, 4}) {
    SCOPED_TRACE(::testing::Message() << across << " across");
    ImageErrorMapOptions options;
    options.arrows_across = across;
    const cv::Mat figure = Draw(up, options);
    ASSERT_FALSE(figure.empty());
    const cv::Rect frame = FrameRect(figure);
    const int columns = ColumnRuns(DarkInside(figure, frame, 3));
    EXPECT_GE(columns, across - 2);
    EXPECT_LE(columns, across + 2);
  }
  // Right and left: the ink lies right of the samples, then left.
  ImageErrorMapOptions options;
  const cv::Mat right = Draw(UniformField(720, 540, 15, {0.5, 0.0}), options);
  const cv::Mat left = Draw(UniformField(720, 540, 15, {-0.5, 0.0}), options);
  ASSERT_FALSE(right.empty());
  ASSERT_FALSE(left.empty());
  const cv::Rect frame = FrameRect(right);
  EXPECT_GT(MeanX(DarkInside(right, frame, 3)),
            MeanX(DarkInside(left, frame, 3)) + 10.0);
}

TEST(ImageErrorMap, CheckFailuresAreOneLineErrors) {
  const ImageErrorField good_field =
      UniformField(320, 240, 40, Eigen::Vector2d(0.1, 0.2));
  const ImageErrorMapOptions good_options;
  ASSERT_TRUE(good_field.Check().ok()) << good_field.Check().message();
  ASSERT_TRUE(good_options.Check().ok()) << good_options.Check().message();
  ASSERT_TRUE(DrawImageErrorMap(good_field, good_options).ok());

  const auto expect_error = [](const Status& status, const std::string& what) {
    SCOPED_TRACE(what);
    EXPECT_FALSE(status.ok());
    EXPECT_FALSE(status.message().empty());
    EXPECT_EQ(status.message().find('\n'), std::string::npos)
        << status.message();
  };
  using FieldChange = std::function<void(ImageErrorField*)>;
  const std::vector<std::pair<std::string, FieldChange>> field_changes = {
      {"zero width", [](ImageErrorField* f) { f->image_width = 0; }},
      {"negative height", [](ImageErrorField* f) { f->image_height = -1; }},
      {"no columns",
       [](ImageErrorField* f) {
         f->cols = 0;
         f->errors.clear();
       }},
      {"negative rows", [](ImageErrorField* f) { f->rows = -2; }},
      {"zero step", [](ImageErrorField* f) { f->step = 0.0; }},
      {"NaN step", [](ImageErrorField* f) { f->step = kNaN; }},
      {"infinite origin", [](ImageErrorField* f) { f->origin.y() = kInf; }},
      {"one error too few", [](ImageErrorField* f) { f->errors.pop_back(); }},
      {"one error too many",
       [](ImageErrorField* f) { f->errors.push_back(std::nullopt); }},
      {"NaN error",
       [](ImageErrorField* f) { f->errors[7] = Eigen::Vector2d(kNaN, 0.0); }},
      {"infinite error",
       [](ImageErrorField* f) { f->errors[0] = Eigen::Vector2d(0.0, -kInf); }},
  };
  for (const auto& [what, change] : field_changes) {
    ImageErrorField field = good_field;
    change(&field);
    expect_error(field.Check(), what + ": Check");
    const StatusOr<cv::Mat> figure = DrawImageErrorMap(field, good_options);
    expect_error(figure.status(), what + ": Draw");
    EXPECT_EQ(figure.status().message(), field.Check().message());
  }

  using OptionsChange = std::function<void(ImageErrorMapOptions*)>;
  const std::vector<std::pair<std::string, OptionsChange>> options_changes = {
      {"frame width 99", [](ImageErrorMapOptions* o) { o->frame_width = 99; }},
      {"NaN color max", [](ImageErrorMapOptions* o) { o->color_max = kNaN; }},
      {"infinite color max",
       [](ImageErrorMapOptions* o) { o->color_max = kInf; }},
      {"negative arrows",
       [](ImageErrorMapOptions* o) { o->arrows_across = -1; }},
      {"NaN region",
       [](ImageErrorMapOptions* o) {
         o->region = Eigen::Vector4d(0.0, 0.0, kNaN, 10.0);
       }},
      {"x0 == x1",
       [](ImageErrorMapOptions* o) {
         o->region = Eigen::Vector4d(10.0, 0.0, 10.0, 10.0);
       }},
      {"y0 > y1",
       [](ImageErrorMapOptions* o) {
         o->region = Eigen::Vector4d(0.0, 20.0, 10.0, 10.0);
       }},
  };
  for (const auto& [what, change] : options_changes) {
    ImageErrorMapOptions options = good_options;
    change(&options);
    expect_error(options.Check(), what + ": Check");
    const StatusOr<cv::Mat> figure = DrawImageErrorMap(good_field, options);
    expect_error(figure.status(), what + ": Draw");
    EXPECT_EQ(figure.status().message(), options.Check().message());
  }

  // Valid, but nothing to draw.
  ImageErrorField empty = good_field;
  std::fill(empty.errors.begin(), empty.errors.end(), std::nullopt);
  EXPECT_TRUE(empty.Check().ok());
  expect_error(DrawImageErrorMap(empty, good_options).status(),
               "all samples absent");
  // The limits themselves are fine; a color_max <= 0 means automatic.
  ImageErrorMapOptions edge = good_options;
  edge.frame_width = 100;
  edge.color_max = -1.0;
  edge.arrows_across = 0;
  edge.region = Eigen::Vector4d(-1e6, 0.0, 1e6, 1e-3);
  EXPECT_TRUE(edge.Check().ok()) << edge.Check().message();
  EXPECT_TRUE(DrawImageErrorMap(good_field, edge).ok());
}

}  // namespace
}  // namespace rcm::image_error_map_test
