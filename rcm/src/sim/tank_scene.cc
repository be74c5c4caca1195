#include "rcm/sim/tank_scene.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "rcm/util/splitmix64.h"

namespace rcm {
namespace {

// Mip levels of every texture; level sizes are exact halvings, so texture
// sizes are multiples of 2^(kNumLevels - 1) texels.
constexpr int kNumLevels = 8;
constexpr int kLevelAlignment = 1 << (kNumLevels - 1);
// Points this far outside the box still count as inside (rounding of a
// caller's transform).
constexpr double kInsideTolerance = 1e-9;
// Anisotropic lookups treat rays more grazing than this (|cos theta|) as
// this grazing: the footprint is capped at 64 times its width.
constexpr double kMinFootprintCosine = 1.0 / 64.0;

int AlignedSize(double meters, double texel_size) {
  const int texels = static_cast<int>(std::ceil(meters / texel_size));
  return (texels + kLevelAlignment - 1) / kLevelAlignment * kLevelAlignment;
}

float Smoothstep(float edge0, float edge1, float x) {
  const float t = std::clamp((x - edge0) / (edge1 - edge0), 0.0f, 1.0f);
  return t * t * (3.0f - 2.0f * t);
}

uint8_t ToByte(float value) {
  return static_cast<uint8_t>(std::clamp(value * 255.0f + 0.5f, 0.0f, 255.0f));
}
cv::Scalar Grey(double value) { return cv::Scalar(value * 255.0); }

// Random draws for texture content, from one cv::RNG (deterministic).
class Draws {
 public:
  explicit Draws(uint64_t seed) : rng_(seed) {}
  cv::RNG& rng() { return rng_; }
  double Uniform(double lo, double hi) { return rng_.uniform(lo, hi); }
  // Log-uniform in [lo, hi]: as many small things per octave as large.
  double LogUniform(double lo, double hi) {
    return std::exp(rng_.uniform(std::log(lo), std::log(hi)));
  }
  bool Chance(double p) { return rng_.uniform(0.0, 1.0) < p; }
  int Int(int lo, int hi_exclusive) { return rng_.uniform(lo, hi_exclusive); }

 private:
  cv::RNG rng_;
};

// Band-limited fractal noise over a texture of `size` texels: uniform white
// noise on a pyramid of grids of 2^coarsest down to 2^finest texels, each
// level interpolated up to the next (Gaussian pyrUp) and added with
// amplitude gain^(coarsest - k); interpolated further up to level `output`
// (<= finest) and returned there, size / 2^output, with zero mean and unit
// standard deviation.
cv::Mat NoiseField(cv::Size size, int output, int finest, int coarsest,
                   double gain, cv::RNG* rng) {
  std::vector<cv::Size> sizes(coarsest + 1);
  sizes[0] = size;
  for (int k = 1; k <= coarsest; ++k) {
    sizes[k] =
        cv::Size((sizes[k - 1].width + 1) / 2, (sizes[k - 1].height + 1) / 2);
  }
  cv::Mat field(sizes[coarsest], CV_32F);
  rng->fill(field, cv::RNG::UNIFORM, -1.0, 1.0);
  double amplitude = 1.0;
  cv::Mat up, noise;
  for (int k = coarsest - 1; k >= output; --k) {
    cv::pyrUp(field, up, sizes[k]);
    if (k >= finest) {
      amplitude *= gain;
      noise.create(sizes[k], CV_32F);
      rng->fill(noise, cv::RNG::UNIFORM, -amplitude, amplitude);
      cv::add(up, noise, field);
    } else {
      std::swap(field, up);
    }
  }
  cv::Scalar mean, stddev;
  cv::meanStdDev(field, mean, stddev);
  const double scale = 1.0 / std::max(stddev[0], 1e-12);
  field.convertTo(field, CV_32F, scale, -mean[0] * scale);
  return field;
}

// A field stored at 1 / 2^level of a texture's resolution (1 / 2^level_y
// along the rows if given), read back at full resolution one row at a time
// by bilinear interpolation (no full-size copy: textures are tens of
// megatexels).
class FieldRows {
 public:
  FieldRows(cv::Mat field, int level, int full_width)
      : FieldRows(std::move(field), level, level, full_width) {}
  FieldRows(cv::Mat field, int level, int level_y, int full_width)
      : field_(std::move(field)),
        scale_(1.0f / (1 << level)),
        scale_y_(1.0f / (1 << level_y)) {
    x0_.resize(full_width);
    x1_.resize(full_width);
    fx_.resize(full_width);
    for (int x = 0; x < full_width; ++x) {
      const float fx = std::clamp((x + 0.5f) * scale_ - 0.5f, 0.0f,
                                  static_cast<float>(field_.cols - 1));
      x0_[x] = static_cast<int>(fx);
      x1_[x] = std::min(x0_[x] + 1, field_.cols - 1);
      fx_[x] = fx - x0_[x];
    }
  }
  // Writes row y (full resolution) into `out` (full_width floats).
  void Row(int y, float* out) const {
    const float fy = std::clamp((y + 0.5f) * scale_y_ - 0.5f, 0.0f,
                                static_cast<float>(field_.rows - 1));
    const int y0 = static_cast<int>(fy);
    const int y1 = std::min(y0 + 1, field_.rows - 1);
    const float wy = fy - y0;
    const float* r0 = field_.ptr<float>(y0);
    const float* r1 = field_.ptr<float>(y1);
    const int width = static_cast<int>(x0_.size());
    for (int x = 0; x < width; ++x) {
      const float a = r0[x0_[x]] + fx_[x] * (r0[x1_[x]] - r0[x0_[x]]);
      const float b = r1[x0_[x]] + fx_[x] * (r1[x1_[x]] - r1[x0_[x]]);
      out[x] = a + wy * (b - a);
    }
  }

 private:
  cv::Mat field_;
  float scale_;
  float scale_y_;
  std::vector<int> x0_, x1_;
  std::vector<float> fx_;
};

// Square tiles of `tile` meters separated by grout lines `grout` meters
// wide, over a texture of texels `texel` meters: per column and per row
// the tile index and the fraction of the texel the grout covers (box
// filtered, so lines thinner than a texel stay smooth).
struct TileGrid {
  int tiles_x = 0;
  int tiles_y = 0;
  std::vector<int> tile_of_column, tile_of_row;
  std::vector<float> grout_of_column, grout_of_row;
};

void TileAxis(int texels, double texel, double tile, double grout,
              std::vector<int>* tile_of, std::vector<float>* grout_of) {
  tile_of->resize(texels);
  grout_of->resize(texels);
  for (int i = 0; i < texels; ++i) {
    const double u = (i + 0.5) * texel;
    const double line = std::round(u / tile) * tile;
    const double overlap = std::min(u + 0.5 * texel, line + 0.5 * grout) -
                           std::max(u - 0.5 * texel, line - 0.5 * grout);
    (*tile_of)[i] = static_cast<int>(std::floor(u / tile));
    (*grout_of)[i] = static_cast<float>(std::clamp(overlap / texel, 0.0, 1.0));
  }
}

TileGrid MakeTileGrid(cv::Size size, double texel, double tile, double grout) {
  TileGrid grid;
  TileAxis(size.width, texel, tile, grout, &grid.tile_of_column,
           &grid.grout_of_column);
  TileAxis(size.height, texel, tile, grout, &grid.tile_of_row,
           &grid.grout_of_row);
  grid.tiles_x = grid.tile_of_column.back() + 1;
  grid.tiles_y = grid.tile_of_row.back() + 1;
  return grid;
}

// Sub-pixel drawing: OpenCV's `shift` of 4 fractional bits.
constexpr int kShift = 4;
constexpr double kShiftScale = 1 << kShift;
cv::Point Fixed(double x, double y) {
  return cv::Point(static_cast<int>(std::lround(x * kShiftScale)),
                   static_cast<int>(std::lround(y * kShiftScale)));
}

// A filled, anti-aliased ellipse; center and semi-axes in texels.
void FillEllipse(cv::Mat* image, double cx, double cy, double a, double b,
                 double angle_deg, double grey) {
  cv::ellipse(*image, Fixed(cx, cy),
              cv::Size(std::max(1, static_cast<int>(a * kShiftScale)),
                       std::max(1, static_cast<int>(b * kShiftScale))),
              angle_deg, 0.0, 360.0, Grey(grey), cv::FILLED, cv::LINE_AA,
              kShift);
}

void FillPolygon(cv::Mat* image, const std::vector<cv::Point2d>& corners,
                 double grey) {
  std::vector<cv::Point> fixed;
  fixed.reserve(corners.size());
  for (const cv::Point2d& p : corners) fixed.push_back(Fixed(p.x, p.y));
  cv::fillPoly(*image, std::vector<std::vector<cv::Point>>{fixed}, Grey(grey),
               cv::LINE_AA, kShift);
}

// A rotated rectangle (center, half sizes in texels, angle).
void FillBox(cv::Mat* image, double cx, double cy, double half_w, double half_h,
             double angle_rad, double grey) {
  const double c = std::cos(angle_rad), s = std::sin(angle_rad);
  std::vector<cv::Point2d> corners;
  for (const auto& [dx, dy] : {std::pair{-1.0, -1.0}, std::pair{1.0, -1.0},
                               std::pair{1.0, 1.0}, std::pair{-1.0, 1.0}}) {
    const double x = dx * half_w, y = dy * half_h;
    corners.emplace_back(cx + c * x - s * y, cy + s * x + c * y);
  }
  FillPolygon(image, corners, grey);
}

// A random blob: `corners` points at radius r (jittered by `jag`) around
// (cx, cy), squashed by `aspect` and turned by `angle`.
std::vector<cv::Point2d> Blob(double cx, double cy, double r, double aspect,
                              double angle, int corners, double jag,
                              Draws* draws) {
  std::vector<cv::Point2d> polygon;
  const double c = std::cos(angle), s = std::sin(angle);
  for (int k = 0; k < corners; ++k) {
    const double t = 2.0 * M_PI * (k + draws->Uniform(-0.3, 0.3)) / corners;
    const double rr = r * (1.0 + draws->Uniform(-jag, jag));
    const double x = rr * std::cos(t), y = aspect * rr * std::sin(t);
    polygon.emplace_back(cx + c * x - s * y, cy + s * x + c * y);
  }
  return polygon;
}

// Blends the 8-bit `grey` patch into `image` through `alpha` (255 =
// opaque) times `opacity`, turned by `angle_deg` about its center, which
// lands at (cx, cy) texels.
void PaintPatch(cv::Mat* image, const cv::Mat& grey, const cv::Mat& alpha,
                double cx, double cy, double angle_deg, double opacity) {
  const int side =
      static_cast<int>(std::ceil(std::hypot(grey.cols, grey.rows))) + 4;
  cv::Mat canvas_grey(side, side, CV_8U, cv::Scalar(0));
  cv::Mat canvas_alpha(side, side, CV_8U, cv::Scalar(0));
  const cv::Rect inner((side - grey.cols) / 2, (side - grey.rows) / 2,
                       grey.cols, grey.rows);
  grey.copyTo(canvas_grey(inner));
  alpha.copyTo(canvas_alpha(inner));
  // Rotation about the canvas center, moved to the target position.
  cv::Mat transform = cv::getRotationMatrix2D(
      cv::Point2f(0.5f * (side - 1), 0.5f * (side - 1)), angle_deg, 1.0);
  const int x0 = static_cast<int>(std::floor(cx - 0.5 * (side - 1)));
  const int y0 = static_cast<int>(std::floor(cy - 0.5 * (side - 1)));
  transform.at<double>(0, 2) += cx - 0.5 * (side - 1) - x0;
  transform.at<double>(1, 2) += cy - 0.5 * (side - 1) - y0;
  cv::warpAffine(canvas_grey, canvas_grey, transform, canvas_grey.size(),
                 cv::INTER_LINEAR, cv::BORDER_CONSTANT);
  cv::warpAffine(canvas_alpha, canvas_alpha, transform, canvas_alpha.size(),
                 cv::INTER_LINEAR, cv::BORDER_CONSTANT);
  const cv::Rect target =
      cv::Rect(x0, y0, side, side) & cv::Rect(0, 0, image->cols, image->rows);
  const float scale = static_cast<float>(opacity) / 255.0f;
  for (int y = target.y; y < target.y + target.height; ++y) {
    uint8_t* row = image->ptr<uint8_t>(y);
    const uint8_t* g = canvas_grey.ptr<uint8_t>(y - y0) - x0;
    const uint8_t* a = canvas_alpha.ptr<uint8_t>(y - y0) - x0;
    for (int x = target.x; x < target.x + target.width; ++x) {
      const float weight = a[x] * scale;
      row[x] = static_cast<uint8_t>(row[x] + weight * (g[x] - row[x]) + 0.5f);
    }
  }
}

// Text painted on a texture whose rows run along +v (world up on the
// walls, +y on the floor): drawn upright, flipped so that it reads
// correctly from inside the tank, `height` texels tall.
void PaintText(cv::Mat* image, const std::string& text, double cx, double cy,
               double height, double angle_deg, double grey, double opacity) {
  const int font = cv::FONT_HERSHEY_DUPLEX;
  int baseline = 0;
  const cv::Size unit = cv::getTextSize(text, font, 1.0, 2, &baseline);
  const double scale = height / std::max(1, unit.height);
  const int thickness = std::max(1, static_cast<int>(std::lround(2 * scale)));
  const cv::Size box = cv::getTextSize(text, font, scale, thickness, &baseline);
  cv::Mat mask(box.height + baseline + 2 * thickness + 2,
               box.width + 2 * thickness + 2, CV_8U, cv::Scalar(0));
  cv::putText(mask, text, cv::Point(thickness + 1, box.height + thickness + 1),
              font, scale, cv::Scalar(255), thickness, cv::LINE_AA);
  cv::flip(mask, mask, 0);
  const cv::Mat paint(mask.size(), CV_8U, Grey(grey));
  PaintPatch(image, paint, mask, cx, cy, angle_deg, opacity);
}

// A square fiducial-like marker `side` texels wide: a white margin, a
// black border and a random 4 x 4 grid of black and white cells, as test
// tanks are strewn with.
void PaintTag(cv::Mat* image, double cx, double cy, double side,
              double angle_deg, Draws* draws) {
  cv::Mat cells(8, 8, CV_8U, cv::Scalar(235));  // the white margin
  for (int i = 1; i < 7; ++i) {
    for (int j = 1; j < 7; ++j) {
      const bool border = i == 1 || j == 1 || i == 6 || j == 6;
      cells.at<uint8_t>(i, j) = border || draws->Chance(0.5) ? 20 : 235;
    }
  }
  const int pixels = std::max(8, static_cast<int>(std::lround(side)));
  cv::Mat grey;
  cv::resize(cells, grey, cv::Size(pixels, pixels), 0.0, 0.0,
             cv::INTER_NEAREST);
  const cv::Mat alpha(grey.size(), CV_8U, cv::Scalar(255));
  PaintPatch(image, grey, alpha, cx, cy, angle_deg, 1.0);
}

// A random label as painted in a test tank: digits, letters, signs.
std::string RandomLabel(Draws* draws) {
  static const char* const kWords[] = {"A",  "B",  "C",  "7",    "12", "X3",
                                       "K9", "R2", "05", "N",    "E",  "S",
                                       "W",  "+",  "L4", "DEEP", "19", "Q"};
  constexpr int kNumWords = sizeof(kWords) / sizeof(kWords[0]);
  std::string label = kWords[draws->Int(0, kNumWords)];
  if (draws->Chance(0.4)) label += std::to_string(draws->Int(0, 100));
  return label;
}

// Pebbles, leaves and fragments with inner detail: blobs of every size,
// `density` per square meter, radii log-uniform up to `max_radius` meters.
void ScatterDebris(cv::Mat* image, double texel, double density,
                   double max_radius, Draws* draws) {
  const double area = image->cols * texel * image->rows * texel;
  const int count = static_cast<int>(density * area);
  for (int i = 0; i < count; ++i) {
    const double cx = draws->Uniform(0.0, image->cols);
    const double cy = draws->Uniform(0.0, image->rows);
    const double r = draws->LogUniform(0.005, max_radius) / texel;
    const double angle = draws->Uniform(0.0, M_PI);
    const double kind = draws->Uniform(0.0, 1.0);
    if (kind < 0.6) {
      // A pebble: rounded, dark or light, with a lighter or darker core.
      const bool dark = draws->Chance(0.6);
      const double grey =
          dark ? draws->Uniform(0.15, 0.4) : draws->Uniform(0.75, 0.95);
      const double aspect = draws->Uniform(0.55, 0.95);
      FillPolygon(image, Blob(cx, cy, r, aspect, angle, 9, 0.12, draws), grey);
      if (r > 2.5) {
        FillPolygon(image,
                    Blob(cx + 0.15 * r, cy - 0.1 * r, 0.55 * r, aspect, angle,
                         7, 0.15, draws),
                    grey + (dark ? 0.1 : -0.1));
      }
    } else if (kind < 0.85) {
      // A leaf: elongated, with a midrib.
      const double grey = draws->Uniform(0.15, 0.45);
      FillEllipse(image, cx, cy, 1.6 * r, 0.5 * r, angle * 180.0 / M_PI, grey);
      if (r > 3.0) {
        const double c = std::cos(angle), s = std::sin(angle);
        cv::line(*image, Fixed(cx - 1.5 * r * c, cy - 1.5 * r * s),
                 Fixed(cx + 1.9 * r * c, cy + 1.9 * r * s), Grey(grey + 0.2),
                 std::max(1, static_cast<int>(0.08 * r)), cv::LINE_AA, kShift);
      }
    } else {
      // A fragment: an angular shard. (Draws are sequenced one per
      // statement: argument evaluation order is unspecified.)
      const double aspect = draws->Uniform(0.3, 1.0);
      const int corners = draws->Int(3, 6);
      const std::vector<cv::Point2d> shard =
          Blob(cx, cy, r, aspect, angle, corners, 0.4, draws);
      const double grey = draws->Chance(0.5) ? draws->Uniform(0.1, 0.3)
                                             : draws->Uniform(0.8, 1.0);
      FillPolygon(image, shard, grey);
    }
  }
}

// Marks painted or stuck on a surface: labels, tags, rings, crosses,
// patches; `density` per square meter, sizes log-uniform in [lo, hi]
// meters; `upright` keeps labels within 20 degrees of upright (walls).
void PaintMarks(cv::Mat* image, double texel, double density, double lo,
                double hi, bool upright, Draws* draws) {
  const double area = image->cols * texel * image->rows * texel;
  const int count = static_cast<int>(density * area);
  for (int i = 0; i < count; ++i) {
    const double cx = draws->Uniform(0.0, image->cols);
    const double cy = draws->Uniform(0.0, image->rows);
    const double r = draws->LogUniform(lo, hi) / texel;
    const double grey = draws->Chance(0.6) ? draws->Uniform(0.05, 0.3)
                                           : draws->Uniform(0.85, 1.0);
    const double angle_deg =
        upright ? draws->Uniform(-20.0, 20.0) : draws->Uniform(0.0, 360.0);
    const double kind = draws->Uniform(0.0, 1.0);
    if (kind < 0.35) {
      const std::string label = RandomLabel(draws);
      const double opacity = draws->Uniform(0.6, 1.0);
      PaintText(image, label, cx, cy, r, angle_deg, grey, opacity);
    } else if (kind < 0.55) {
      PaintTag(image, cx, cy, 1.5 * r, angle_deg, draws);
    } else if (kind < 0.7) {
      const double aspect = draws->Uniform(0.6, 1.0);
      const double arc = draws->Uniform(200.0, 360.0);
      cv::ellipse(*image, Fixed(cx, cy),
                  cv::Size(static_cast<int>(r * kShiftScale),
                           static_cast<int>(r * kShiftScale * aspect)),
                  angle_deg, 0.0, arc, Grey(grey),
                  std::max(1, static_cast<int>(0.15 * r)), cv::LINE_AA, kShift);
    } else if (kind < 0.85) {
      const double arm = 0.12 * r;
      const double angle = angle_deg * M_PI / 180.0;
      FillBox(image, cx, cy, r, arm, angle, grey);
      FillBox(image, cx, cy, arm, r * draws->Uniform(0.5, 1.0), angle, grey);
    } else {
      const double aspect = draws->Uniform(0.4, 1.0);
      const int corners = draws->Int(3, 6);
      FillPolygon(image,
                  Blob(cx, cy, r, aspect, angle_deg * M_PI / 180.0, corners,
                       0.3, draws),
                  grey);
    }
  }
}

// The lanes of a pool 8 m or more wide, in meters across it.
std::vector<double> LaneCenters(double width) {
  std::vector<double> lanes;
  for (double y : {0.5 * width - 2.5, 0.5 * width, 0.5 * width + 2.5}) {
    if (y >= 1.0 && y <= width - 1.0) lanes.push_back(y);
  }
  return lanes;
}

// Grey of a mosaic tile: a blend of four tones as pool mosaics are laid,
// a few darker accent tiles.
float MosaicTone(uint64_t hash, float base) {
  const float u = static_cast<float>(hash >> 40) * 0x1.0p-24f;
  const float jitter = static_cast<float>(hash & 0xFF) / 255.0f - 0.5f;
  float tone =
      u < 0.25f ? -0.08f : (u < 0.6f ? 0.0f : (u < 0.9f ? 0.08f : 0.15f));
  if ((hash & 0xF00) < 0x080) tone = -0.25f;  // about 3%
  return base + tone + 0.03f * jitter;
}

// Paints a tile mosaic: each tile its tone (tones[tile_y * tiles_x +
// tile_x]), blended toward `grout_tone` by the anti-aliased grout coverage
// of the texel, times (1 + grain * uniform noise in [-1, 1]).
void PaintMosaic(const TileGrid& grid, const std::vector<float>& tones,
                 float grout_tone, float grain, Draws* draws, cv::Mat* albedo) {
  const cv::Size size = albedo->size();
  std::vector<float> white(size.width);
  cv::Mat white_row(1, size.width, CV_32F, white.data());
  cv::RNG* rng = &draws->rng();
  for (int y = 0; y < size.height; ++y) {
    uint8_t* row = albedo->ptr<uint8_t>(y);
    rng->fill(white_row, cv::RNG::UNIFORM, -1.0, 1.0);
    const float* tone_row =
        tones.data() + static_cast<size_t>(grid.tile_of_row[y]) * grid.tiles_x;
    const float grout_v = grid.grout_of_row[y];
    for (int x = 0; x < size.width; ++x) {
      const float grout_u = grid.grout_of_column[x];
      const float grout = grout_u + grout_v - grout_u * grout_v;
      const float tile = tone_row[grid.tile_of_column[x]];
      row[x] = ToByte((tile + (grout_tone - tile) * grout) *
                      (1.0f + grain * white[x]));
    }
  }
}

// Floor: a mosaic of 5 cm tiles in a random blend with dark lane lines,
// painted marks and tags, then sand drifts, algae stains, grime and the
// caustic network of sunlight, then debris on top.
void FloorTexture(const TankSceneOptions& options, double texel,
                  cv::Mat* albedo) {
  const cv::Size size = albedo->size();
  Draws draws(SplitMix64(options.seed ^ 0xF100Full));
  const TileGrid grid = MakeTileGrid(size, texel, 0.05, 0.004);
  std::vector<float> tones(static_cast<size_t>(grid.tiles_x) * grid.tiles_y);
  const uint64_t tile_seed = SplitMix64(options.seed ^ 0x711Eull);
  const std::vector<double> lanes = LaneCenters(options.width);
  // The blend drifts in patches of 2-30 tiles (0.1-1.5 m): crisp-edged
  // random shapes at the scales a detector sees from meters away.
  const cv::Mat patches = NoiseField(cv::Size(grid.tiles_x, grid.tiles_y), 0, 1,
                                     5, 0.8, &draws.rng());
  for (int j = 0; j < grid.tiles_y; ++j) {
    for (int i = 0; i < grid.tiles_x; ++i) {
      const size_t index = static_cast<size_t>(j) * grid.tiles_x + i;
      const float patch = patches.at<float>(j, i);
      float tone = MosaicTone(SplitMix64(tile_seed + index),
                              0.66f + 0.12f * std::clamp(patch, -2.0f, 2.0f));
      const double u = (i + 0.5) * 0.05, v = (j + 0.5) * 0.05;
      for (double lane : lanes) {
        const bool stripe =
            std::abs(v - lane) < 0.125 && u > 2.0 && u < options.length - 2.0;
        const bool bar = std::abs(v - lane) < 0.5 &&
                         (std::abs(u - 2.0) < 0.125 ||
                          std::abs(u - (options.length - 2.0)) < 0.125);
        if (stripe || bar) tone = 0.16f + 0.02f * (tone - 0.68f);
      }
      tones[index] = tone;
    }
  }
  PaintMosaic(grid, tones, 0.42f, 0.04f, &draws, albedo);
  std::vector<float> white(size.width);
  cv::Mat white_row(1, size.width, CV_32F, white.data());
  cv::RNG* rng = &draws.rng();
  PaintMarks(albedo, texel, 0.5, 0.06, 0.4, false, &draws);

  // Sand grain 1-10 cm, drifts 0.2-2 m, algae stains 2 cm-0.5 m, grime
  // 0.3-4 m, caustics 5-40 cm.
  const FieldRows sand(NoiseField(size, 1, 1, 4, 0.7, rng), 1, size.width);
  const FieldRows drift(NoiseField(size, 5, 5, 9, 0.6, rng), 5, size.width);
  const FieldRows stain(NoiseField(size, 2, 2, 7, 0.75, rng), 2, size.width);
  const FieldRows grime(NoiseField(size, 4, 4, 9, 0.7, rng), 4, size.width);
  cv::Mat caustic = NoiseField(size, 2, 3, 6, 0.45, rng);
  for (int y = 0; y < caustic.rows; ++y) {
    float* c = caustic.ptr<float>(y);
    for (int x = 0; x < caustic.cols; ++x) {
      const float ridge = std::max(0.0f, 1.0f - 1.1f * std::abs(c[x]));
      const float r2 = ridge * ridge;
      c[x] = r2 * r2 * r2;
    }
  }
  const FieldRows caustics(caustic, 2, size.width);
  std::vector<float> sand_row(size.width), drift_row(size.width),
      stain_row(size.width), grime_row(size.width), caustic_row(size.width);
  for (int y = 0; y < size.height; ++y) {
    uint8_t* row = albedo->ptr<uint8_t>(y);
    rng->fill(white_row, cv::RNG::UNIFORM, -1.0, 1.0);
    sand.Row(y, sand_row.data());
    drift.Row(y, drift_row.data());
    stain.Row(y, stain_row.data());
    grime.Row(y, grime_row.data());
    caustics.Row(y, caustic_row.data());
    for (int x = 0; x < size.width; ++x) {
      const float painted = row[x] * (1.0f / 255.0f);
      const float cover = Smoothstep(0.5f, 1.4f, drift_row[x]);
      const float sand_grey = 0.56f + 0.1f * sand_row[x] + 0.05f * white[x];
      float value = painted + (sand_grey - painted) * cover;
      value *= 1.0f - 0.45f * Smoothstep(1.0f, 1.15f, stain_row[x]);
      value *= std::clamp(0.92f + 0.1f * grime_row[x], 0.6f, 1.15f);
      value *= 0.85f + 0.35f * caustic_row[x];
      row[x] = ToByte(value);
    }
  }
  ScatterDebris(albedo, texel, 10.0, 0.12, &draws);
}

// Walls: a lighter mosaic of 5 cm tiles, a dark band below the waterline, lane
// targets on the end walls, depth markings, signs and tags, algae heavier
// towards the floor, biofouling spots.
void WallTexture(const TankSceneOptions& options, double texel,
                 cv::Mat* albedo) {
  const cv::Size size = albedo->size();
  const double perimeter = 2.0 * (options.length + options.width);
  Draws draws(SplitMix64(options.seed ^ 0x3A11ull));
  const TileGrid grid = MakeTileGrid(size, texel, 0.05, 0.004);
  const uint64_t tile_seed = SplitMix64(options.seed ^ 0x3A1Full);
  const double waterline = options.depth - 0.35;
  // Lane targets: on the wall x = 0 at u = y, on the wall x = length at
  // u = 2 width + length - y.
  std::vector<double> targets;
  for (double lane : LaneCenters(options.width)) {
    targets.push_back(lane);
    targets.push_back(2.0 * options.width + options.length - lane);
  }
  const double target_top = std::min(options.depth - 0.7, 2.0);
  const cv::Mat patches = NoiseField(cv::Size(grid.tiles_x, grid.tiles_y), 0, 1,
                                     5, 0.8, &draws.rng());
  std::vector<float> tones(static_cast<size_t>(grid.tiles_x) * grid.tiles_y);
  for (int j = 0; j < grid.tiles_y; ++j) {
    const double z = (j + 0.5) * 0.05;
    for (int i = 0; i < grid.tiles_x; ++i) {
      const size_t index = static_cast<size_t>(j) * grid.tiles_x + i;
      const float patch = std::clamp(patches.at<float>(j, i), -2.0f, 2.0f);
      float tone =
          MosaicTone(SplitMix64(tile_seed + index), 0.74f + 0.1f * patch);
      if (z > waterline && z < waterline + 0.2) tone = 0.3f;
      if (z < 0.1) tone = 0.55f;
      const double u = (i + 0.5) * 0.05;
      for (double target : targets) {
        const bool stem =
            std::abs(u - target) < 0.15 && z > 0.3 && z < target_top;
        const bool bar =
            std::abs(u - target) < 0.35 && std::abs(z - target_top) < 0.1;
        if (stem || bar) tone = 0.16f;
      }
      tones[index] = tone;
    }
  }
  PaintMosaic(grid, tones, 0.5f, 0.03f, &draws, albedo);
  cv::RNG* rng = &draws.rng();
  for (double u = draws.Uniform(0.8, 1.6); u < perimeter - 0.5;
       u += draws.Uniform(1.8, 3.2)) {
    std::ostringstream label;
    label.precision(1);
    label << std::fixed << options.depth - draws.Int(0, 4) * 0.5 << " m";
    PaintText(albedo, label.str(), u / texel, (options.depth - 0.6) / texel,
              0.15 / texel, 0.0, 0.1, 0.95);
  }
  PaintMarks(albedo, texel, 0.6, 0.05, 0.3, true, &draws);

  // Algae: streaks long along z, narrow along u, and stains; grime.
  cv::Mat streak_field(cv::Size(size.width / 8, std::max(2, size.height / 64)),
                       CV_32F);
  rng->fill(streak_field, cv::RNG::UNIFORM, -1.0, 1.0);
  cv::GaussianBlur(streak_field, streak_field, cv::Size(5, 1), 1.0);
  const FieldRows streaks(streak_field, 3, 6, size.width);
  const FieldRows stain(NoiseField(size, 2, 2, 6, 0.75, rng), 2, size.width);
  const FieldRows grime(NoiseField(size, 3, 3, 7, 0.7, rng), 3, size.width);
  std::vector<float> streak_row(size.width), stain_row(size.width),
      grime_row(size.width);
  for (int y = 0; y < size.height; ++y) {
    uint8_t* row = albedo->ptr<uint8_t>(y);
    streaks.Row(y, streak_row.data());
    stain.Row(y, stain_row.data());
    grime.Row(y, grime_row.data());
    const float z = static_cast<float>((y + 0.5) * texel / options.depth);
    const float low = (1.0f - std::min(z, 1.0f)) * (1.0f - std::min(z, 1.0f));
    for (int x = 0; x < size.width; ++x) {
      const float algae =
          Smoothstep(-0.1f, 0.6f, streak_row[x]) * (0.1f + 0.5f * low);
      const float stained =
          0.4f * Smoothstep(1.1f, 1.35f, stain_row[x] + 0.8f * low);
      const float factor = std::clamp(
          0.95f + 0.08f * grime_row[x] - 0.4f * algae - stained, 0.25f, 1.2f);
      row[x] = ToByte(row[x] * (1.0f / 255.0f) * factor);
    }
  }
  ScatterDebris(albedo, texel, 5.0, 0.04, &draws);
}

// Seen from below the surface is bright, with the network of bright lines
// that refracted sunlight draws (ridges of band-limited noise).
void SurfaceTexture(const TankSceneOptions& options, cv::Mat* radiance) {
  const cv::Size size = radiance->size();
  Draws draws(SplitMix64(options.seed ^ 0x5DFull));
  cv::RNG* rng = &draws.rng();
  const FieldRows coarse(NoiseField(size, 1, 3, 5, 0.5, rng), 1, size.width);
  const FieldRows medium(NoiseField(size, 1, 2, 4, 0.5, rng), 1, size.width);
  const FieldRows glow(NoiseField(size, 5, 5, 8, 0.6, rng), 5, size.width);
  std::vector<float> a(size.width), b(size.width), g(size.width);
  for (int y = 0; y < size.height; ++y) {
    uint8_t* row = radiance->ptr<uint8_t>(y);
    coarse.Row(y, a.data());
    medium.Row(y, b.data());
    glow.Row(y, g.data());
    for (int x = 0; x < size.width; ++x) {
      const float ra = std::max(0.0f, 1.0f - 1.2f * std::abs(a[x]));
      const float rb = std::max(0.0f, 1.0f - 1.2f * std::abs(b[x]));
      const float ra2 = ra * ra, rb2 = rb * rb;
      row[x] = ToByte(0.55f + 0.08f * g[x] + 0.3f * ra2 * ra2 * ra2 +
                      0.15f * rb2 * rb2 * rb2);
    }
  }
}

}  // namespace

Status TankSceneOptions::Check() const {
  std::ostringstream message;
  const auto in = [](double value, double lo, double hi) {
    return std::isfinite(value) && value >= lo && value <= hi;
  };
  if (!in(length, 2.0, 100.0) || !in(width, 2.0, 100.0)) {
    message << "tank length = " << length << " m and width = " << width
            << " m must be in [2, 100]";
  } else if (!in(depth, 1.0, 20.0)) {
    message << "tank depth = " << depth << " m is outside [1, 20]";
  } else if (!in(texel_size, 0.002, 0.05)) {
    message << "texel_size = " << texel_size << " m is outside [0.002, 0.05]";
  } else if (std::isnan(constant_albedo) || constant_albedo > 1.0) {
    message << "constant_albedo = " << constant_albedo
            << " must be < 0 (textured) or in [0, 1]";
  } else {
    return Status::Ok();
  }
  return Status::Error(message.str());
}

StatusOr<TankScene> TankScene::Create(const TankSceneOptions& options) {
  RCM_RETURN_IF_ERROR(options.Check());
  TankScene scene(options);
  if (options.constant_albedo >= 0.0) return scene;
  for (TankSurface surface :
       {TankSurface::kFloor, TankSurface::kWall, TankSurface::kSurface}) {
    MipTexture& texture = scene.textures_[static_cast<int>(surface)];
    texture.texel_size = surface == TankSurface::kSurface
                             ? 2.0 * options.texel_size
                             : options.texel_size;
    const double extent_u = surface == TankSurface::kWall
                                ? 2.0 * (options.length + options.width)
                                : options.length;
    const double extent_v =
        surface == TankSurface::kWall ? options.depth : options.width;
    texture.levels.resize(kNumLevels);
    for (int l = 0; l < kNumLevels; ++l) {
      MipLevel& level = texture.levels[l];
      level.width = AlignedSize(extent_u, texture.texel_size) >> l;
      level.height = AlignedSize(extent_v, texture.texel_size) >> l;
      level.texels_per_meter =
          static_cast<float>(1.0 / (texture.texel_size * (1 << l)));
      level.texels.resize(static_cast<size_t>(level.width) * level.height);
    }
    // Level 0 is generated in place, each further level is the box average
    // of the one before (an exact halving).
    const auto view = [&texture](int l) {
      MipLevel& level = texture.levels[l];
      return cv::Mat(level.height, level.width, CV_8U, level.texels.data());
    };
    cv::Mat level0 = view(0);
    switch (surface) {
      case TankSurface::kFloor:
        FloorTexture(options, texture.texel_size, &level0);
        break;
      case TankSurface::kWall:
        WallTexture(options, texture.texel_size, &level0);
        break;
      case TankSurface::kSurface:
        SurfaceTexture(options, &level0);
        break;
    }
    for (int l = 1; l < kNumLevels; ++l) {
      cv::Mat finer = view(l - 1);
      cv::Mat coarser = view(l);
      cv::resize(finer, coarser, coarser.size(), 0.0, 0.0, cv::INTER_AREA);
      CHECK(coarser.data == texture.levels[l].texels.data());
    }
  }
  return scene;
}

bool TankScene::Contains(const Eigen::Vector3d& point_in_world,
                         double margin) const {
  const Eigen::Vector3d& p = point_in_world;
  return p.x() >= margin && p.x() <= length() - margin && p.y() >= margin &&
         p.y() <= width() - margin && p.z() >= margin &&
         p.z() <= depth() - margin;
}

std::optional<SurfaceHit> TankScene::Intersect(
    const Eigen::Vector3d& origin_in_world,
    const Eigen::Vector3d& unit_direction_in_world) const {
  const Eigen::Vector3d& o = origin_in_world;
  const Eigen::Vector3d& v = unit_direction_in_world;
  if (!o.allFinite() || !v.allFinite() || !Contains(o, -kInsideTolerance)) {
    return std::nullopt;
  }
  const double norm = v.norm();
  if (!(norm > 0.0)) return std::nullopt;
  const double upper[3] = {length(), width(), depth()};
  double t_hit = std::numeric_limits<double>::infinity();
  int axis = -1;
  bool at_upper = false;
  for (int k = 0; k < 3; ++k) {
    if (v[k] == 0.0) continue;
    const bool up = v[k] > 0.0;
    const double t = ((up ? upper[k] : 0.0) - o[k]) / v[k];
    if (t < t_hit) {
      t_hit = t;
      axis = k;
      at_upper = up;
    }
  }
  t_hit = std::max(t_hit, 0.0);
  SurfaceHit hit;
  hit.distance = t_hit * norm;
  hit.point = o + t_hit * v;
  for (int k = 0; k < 3; ++k) {
    hit.point[k] = std::clamp(hit.point[k], 0.0, upper[k]);
  }
  hit.point[axis] = at_upper ? upper[axis] : 0.0;
  hit.normal = Eigen::Vector3d::Zero();
  hit.normal[axis] = at_upper ? -1.0 : 1.0;
  const double x = hit.point.x(), y = hit.point.y(), z = hit.point.z();
  const double l = length(), w = width();
  if (axis == 2) {
    hit.surface = at_upper ? TankSurface::kSurface : TankSurface::kFloor;
    hit.texture = Eigen::Vector2d(x, y);
  } else {
    hit.surface = TankSurface::kWall;
    double u = 0.0;
    if (axis == 0) {
      u = at_upper ? w + l + (w - y) : y;
    } else {
      u = at_upper ? w + x : 2.0 * w + l + (l - x);
    }
    hit.texture = Eigen::Vector2d(u, z);
  }
  return hit;
}

namespace {

// Bilinear lookup in one mip level at texture coordinates in meters; texel
// centers at (i + 0.5) / texels_per_meter, clamped at the borders.
float Bilinear(const std::vector<uint8_t>& texels, int width, int height,
               float texels_per_meter, float u, float v) {
  const float x = std::clamp(u * texels_per_meter - 0.5f, 0.0f,
                             static_cast<float>(width - 1));
  const float y = std::clamp(v * texels_per_meter - 0.5f, 0.0f,
                             static_cast<float>(height - 1));
  const int x0 = static_cast<int>(x), y0 = static_cast<int>(y);
  const int x1 = std::min(x0 + 1, width - 1);
  const int y1 = std::min(y0 + 1, height - 1);
  const float fx = x - x0, fy = y - y0;
  const uint8_t* r0 = texels.data() + static_cast<size_t>(y0) * width;
  const uint8_t* r1 = texels.data() + static_cast<size_t>(y1) * width;
  const float a = r0[x0] + fx * (r0[x1] - r0[x0]);
  const float b = r1[x0] + fx * (r1[x1] - r1[x0]);
  return a + fy * (b - a);
}

}  // namespace

float TankScene::LevelOfDetail(const MipTexture& texture, double footprint) {
  if (!(footprint > texture.texel_size)) return 0.0f;
  return std::min(std::log2(static_cast<float>(footprint / texture.texel_size)),
                  static_cast<float>(texture.levels.size() - 1));
}

float TankScene::SampleTrilinear(const MipTexture& texture, float u, float v,
                                 float lambda) {
  const int l0 = static_cast<int>(lambda);
  const float blend = lambda - static_cast<float>(l0);
  const MipLevel& fine = texture.levels[l0];
  float value = Bilinear(fine.texels, fine.width, fine.height,
                         fine.texels_per_meter, u, v);
  if (blend > 0.0f && l0 + 1 < static_cast<int>(texture.levels.size())) {
    const MipLevel& coarse = texture.levels[l0 + 1];
    value += blend * (Bilinear(coarse.texels, coarse.width, coarse.height,
                               coarse.texels_per_meter, u, v) -
                      value);
  }
  return value * (1.0f / 255.0f);
}

float TankScene::Shade(const SurfaceHit& hit, double footprint) const {
  if (options_.constant_albedo >= 0.0) {
    return static_cast<float>(options_.constant_albedo);
  }
  const MipTexture& texture = Texture(hit.surface);
  return SampleTrilinear(texture, static_cast<float>(hit.texture.x()),
                         static_cast<float>(hit.texture.y()),
                         LevelOfDetail(texture, footprint));
}

float TankScene::ShadeAnisotropic(
    const SurfaceHit& hit, const Eigen::Vector3d& unit_direction_in_world,
    double footprint) const {
  if (options_.constant_albedo >= 0.0) {
    return static_cast<float>(options_.constant_albedo);
  }
  const Eigen::Vector3d& d = unit_direction_in_world;
  const double cosine =
      std::max(std::abs(d.dot(hit.normal)), kMinFootprintCosine);
  const double ratio = 1.0 / cosine;
  const double major = footprint * ratio;
  const int taps =
      std::clamp(static_cast<int>(ratio + 0.5), 1, kMaxAnisotropicTaps);
  const MipTexture& texture = Texture(hit.surface);
  const float u = static_cast<float>(hit.texture.x());
  const float v = static_cast<float>(hit.texture.y());
  // The ray's direction projected onto the surface, in texture axes.
  const double axis_u = hit.surface == TankSurface::kWall
                            ? -hit.normal.y() * d.x() + hit.normal.x() * d.y()
                            : d.x();
  const double axis_v = hit.surface == TankSurface::kWall ? d.z() : d.y();
  const double axis_norm = std::sqrt(axis_u * axis_u + axis_v * axis_v);
  if (taps == 1 || !(axis_norm > 0.0)) {
    return SampleTrilinear(texture, u, v, LevelOfDetail(texture, major));
  }
  const float lambda =
      LevelOfDetail(texture, std::max(footprint, major / taps));
  const double scale = major / (axis_norm * taps);
  const float step_u = static_cast<float>(axis_u * scale);
  const float step_v = static_cast<float>(axis_v * scale);
  float sum = 0.0f;
  for (int k = 0; k < taps; ++k) {
    const float offset = k + 0.5f - 0.5f * taps;
    sum += SampleTrilinear(texture, u + offset * step_u, v + offset * step_v,
                           lambda);
  }
  return sum / taps;
}

double TankScene::TexelSize(TankSurface surface) const {
  return Texture(surface).texel_size;
}

int TankScene::NumTextureLevels(TankSurface surface) const {
  return static_cast<int>(Texture(surface).levels.size());
}

}  // namespace rcm
