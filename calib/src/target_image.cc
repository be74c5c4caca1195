#include "rcm/calib/target_image.h"

#include <glog/logging.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <opencv2/aruco/dictionary.hpp>
#include <opencv2/imgproc.hpp>

namespace rcm::calib {
namespace {

constexpr uint8_t kBlack = 0;
constexpr uint8_t kWhite = 255;
// Largest texture drawn: 2^28 pixels (256 MB).
constexpr int64_t kMaxTexturePixels = int64_t{1} << 28;
// AprilTag 36h11 as Kalibr prints it: 6 x 6 data bits in a 2-bit black
// border, 10 bits along an edge.
constexpr int kTagDataBits = 6;
constexpr int kTagBorderBits = 2;
constexpr int kTagBits = kTagDataBits + 2 * kTagBorderBits;
// Kalibr's tags may take up to this factor more pixels per bit than asked
// for, to put every tag on whole pixels.
constexpr int kMaxBitScale = 4;

int RoundToInt(double value) { return static_cast<int>(std::lround(value)); }

cv::Mat WhiteImage(int64_t width, int64_t height) {
  CHECK(width > 0 && height > 0 && width * height <= kMaxTexturePixels)
      << "target texture of " << width << " x " << height
      << " pixels is too large; lower pixels_per_metre";
  return cv::Mat(static_cast<int>(height), static_cast<int>(width), CV_8UC1,
                 cv::Scalar(kWhite));
}

// Fills texture columns [x0, x1) and rows [y0, y1) (clipped) with `value`.
void FillRect(cv::Mat* image, int x0, int y0, int x1, int y1, uint8_t value) {
  x0 = std::max(x0, 0);
  y0 = std::max(y0, 0);
  x1 = std::min(x1, image->cols);
  y1 = std::min(y1, image->rows);
  if (x0 >= x1 || y0 >= y1) return;
  (*image)(cv::Rect(x0, y0, x1 - x0, y1 - y0)).setTo(cv::Scalar(value));
}

TargetImage DrawCheckerboard(const CalibrationTarget& target,
                             double pixels_per_metre) {
  const int qx = std::max(2, RoundToInt(target.col_spacing * pixels_per_metre));
  const int qy = std::max(2, RoundToInt(target.row_spacing * pixels_per_metre));
  const int squares_x = target.cols + 1;
  const int squares_y = target.rows + 1;
  TargetImage out;
  out.image =
      WhiteImage(int64_t{squares_x + 2} * qx, int64_t{squares_y + 2} * qy);
  for (int y = 0; y < squares_y; ++y) {
    for (int x = 0; x < squares_x; ++x) {
      if ((x + y) % 2 != 0) continue;
      FillRect(&out.image, (x + 1) * qx, (y + 1) * qy, (x + 2) * qx,
               (y + 2) * qy, kBlack);
    }
  }
  // Point 0 (the first inner corner) is on the pixel edges 2 qx, 2 qy, at
  // texture position (2 qx - 0.5, 2 qy - 0.5).
  const double sx = target.col_spacing / qx;
  const double sy = target.row_spacing / qy;
  out.target_from_texture << sx, 0.0, sx * (0.5 - 2 * qx),  //
      0.0, sy, sy * (0.5 - 2 * qy);
  return out;
}

TargetImage DrawAprilGrid(const CalibrationTarget& target,
                          double pixels_per_metre) {
  const int b0 =
      std::max(1, RoundToInt(target.tag_size * pixels_per_metre / kTagBits));
  const double spacing_bits = target.tag_spacing * kTagBits;
  // Pixels per bit that make the gap whole, if any.
  int bit = b0;
  bool exact = false;
  for (int b = b0; b <= kMaxBitScale * b0 && !exact; ++b) {
    const double gap = spacing_bits * b;
    if (gap >= 0.5 && std::abs(gap - std::round(gap)) < 1e-9 * gap) {
      bit = b;
      exact = true;
    }
  }
  const int tag = kTagBits * bit;
  const double pitch = tag * (1.0 + target.tag_spacing);  // pixels
  const int gap = std::max(1, RoundToInt(spacing_bits * bit));
  const int margin = gap + tag;
  // Offset of tag i (or row j) from tag 0, in pixels.
  const auto offset = [&](int i) {
    return exact ? i * (tag + gap) : RoundToInt(i * pitch);
  };
  const int64_t width = 2 * int64_t{margin} + offset(target.cols - 1) + tag;
  const int64_t height = 2 * int64_t{margin} + offset(target.rows - 1) + tag;
  TargetImage out;
  out.image = WhiteImage(width, height);
  const int rows = out.image.rows;

  const cv::Ptr<cv::aruco::Dictionary> dictionary =
      cv::aruco::getPredefinedDictionary(cv::aruco::DICT_APRILTAG_36h11);
  CHECK_LE(target.cols * target.rows, dictionary->bytesList.rows)
      << "aprilgrid has more tags than tag36h11 has codes";
  for (int j = 0; j < target.rows; ++j) {
    for (int i = 0; i < target.cols; ++i) {
      const int id = j * target.cols + i;
      // The tag's pixel columns [x0, x0 + tag) and rows [y0, y0 + tag):
      // its lower-left corner is `margin + offset` from the bottom-left.
      const int x0 = margin + offset(i);
      const int y0 = rows - (margin + offset(j)) - tag;
      FillRect(&out.image, x0, y0, x0 + tag, y0 + tag, kBlack);
      // OpenCV's bits (1 white) are the upright tag turned by 180 degrees.
      const cv::Mat bits = cv::aruco::Dictionary::getBitsFromByteList(
          dictionary->bytesList.row(id), kTagDataBits);
      for (int r = 0; r < kTagDataBits; ++r) {
        for (int c = 0; c < kTagDataBits; ++c) {
          if (bits.at<uint8_t>(kTagDataBits - 1 - r, kTagDataBits - 1 - c) ==
              0) {
            continue;
          }
          const int cx = x0 + (kTagBorderBits + c) * bit;
          const int cy = y0 + (kTagBorderBits + r) * bit;
          FillRect(&out.image, cx, cy, cx + bit, cy + bit, kWhite);
        }
      }
      // Kalibr's corner squares, touching the tag at its corners.
      for (const int sx : {x0 - gap, x0 + tag}) {
        for (const int sy : {y0 - gap, y0 + tag}) {
          FillRect(&out.image, sx, sy, sx + gap, sy + gap, kBlack);
        }
      }
    }
  }
  const double s = target.tag_size / tag;
  out.target_from_texture << s, 0.0, s * (0.5 - margin),  //
      0.0, -s, s * (rows - 0.5 - margin);
  return out;
}

TargetImage DrawCharuco(const CalibrationTarget& target,
                        double pixels_per_metre) {
  const int q = std::max(4, RoundToInt(target.square_size * pixels_per_metre));
  const double scale = q / target.square_size;  // pixels per metre
  TargetImage out;
  out.image =
      WhiteImage(int64_t{target.cols + 2} * q, int64_t{target.rows + 2} * q);
  const std::optional<ArucoDictionaryInfo> info =
      FindArucoDictionary(target.dictionary);
  CHECK(info.has_value()) << "unknown dictionary " << target.dictionary;
  const cv::Ptr<cv::aruco::Dictionary> dictionary =
      cv::aruco::getPredefinedDictionary(info->opencv_id);
  const int n = dictionary->markerSize;
  const double marker = target.marker_size * scale;
  const double inset = 0.5 * (q - marker);
  // Cell edge k (0 .. n + 2) of a marker, in pixels from its square.
  const auto edge = [&](int k) {
    return RoundToInt(inset + k * marker / (n + 2));
  };
  int id = 0;
  // CharucoBoard::create: squares with x + y even are black, the others
  // hold markers 0, 1, ... in row-major order.
  for (int y = 0; y < target.rows; ++y) {
    for (int x = 0; x < target.cols; ++x) {
      const int x0 = (x + 1) * q;
      const int y0 = (y + 1) * q;
      if ((x + y) % 2 == 0) {
        FillRect(&out.image, x0, y0, x0 + q, y0 + q, kBlack);
        continue;
      }
      const cv::Mat bits = cv::aruco::Dictionary::getBitsFromByteList(
          dictionary->bytesList.row(id), n);
      ++id;
      for (int r = 0; r < n + 2; ++r) {
        for (int c = 0; c < n + 2; ++c) {
          const bool border = r == 0 || c == 0 || r == n + 1 || c == n + 1;
          if (!border && bits.at<uint8_t>(r - 1, c - 1) != 0) continue;
          FillRect(&out.image, x0 + edge(c), y0 + edge(r), x0 + edge(c + 1),
                   y0 + edge(r + 1), kBlack);
        }
      }
    }
  }
  const double s = 1.0 / scale;
  out.target_from_texture << s, 0.0, s * (0.5 - q),  //
      0.0, s, s * (0.5 - q);
  return out;
}

}  // namespace

TargetImage DrawTargetImage(const CalibrationTarget& target,
                            double pixels_per_metre) {
  CHECK(std::isfinite(pixels_per_metre) && pixels_per_metre > 0.0)
      << "pixels_per_metre must be positive, got " << pixels_per_metre;
  NumTargetPoints(target);  // CHECKs that the target is valid
  switch (target.type) {
    case TargetType::kCheckerboard:
      return DrawCheckerboard(target, pixels_per_metre);
    case TargetType::kAprilGrid:
      return DrawAprilGrid(target, pixels_per_metre);
    case TargetType::kCharuco:
      return DrawCharuco(target, pixels_per_metre);
  }
  LOG(FATAL) << "unknown target type";
  return {};
}

}  // namespace rcm::calib
