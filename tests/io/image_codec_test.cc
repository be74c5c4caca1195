#include "rcm/io/image_codec.h"

#include <gtest/gtest.h>
#include <png.h>

#include <cstdint>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

namespace rcm::image_codec_test {
namespace {

// The modes and the imread flags they stand for.
struct Mode {
  ImageReadMode mode;
  int flags;
  const char* name;
};
const Mode kModes[] = {
    {ImageReadMode::kGray, cv::IMREAD_GRAYSCALE, "gray"},
    {ImageReadMode::kColor, cv::IMREAD_COLOR, "color"},
    {ImageReadMode::kAsStored, cv::IMREAD_UNCHANGED, "as stored"}};

cv::Mat OpenCvDecode(const std::string& bytes, int flags) {
  return cv::imdecode(std::vector<uchar>(bytes.begin(), bytes.end()), flags);
}

std::string OpenCvEncode(const std::string& extension, const cv::Mat& image,
                         const std::vector<int>& parameters = {}) {
  std::vector<uchar> bytes;
  EXPECT_TRUE(cv::imencode(extension, image, bytes, parameters));
  return std::string(bytes.begin(), bytes.end());
}

cv::Mat Noise(int type, int rows = 29, int cols = 37) {
  cv::Mat image(rows, cols, type);
  cv::RNG rng(11);
  rng.fill(image, cv::RNG::UNIFORM, 0,
           CV_MAT_DEPTH(type) == CV_16U ? 65536 : 256);
  return image;
}

// Every mode decodes `bytes` to exactly the pixels of cv::imdecode, and
// prints nothing.
void ExpectOpenCvPixels(const std::string& bytes, const std::string& what) {
  for (const Mode& mode : kModes) {
    SCOPED_TRACE(what + ", " + mode.name);
    const cv::Mat expected = OpenCvDecode(bytes, mode.flags);
    ASSERT_FALSE(expected.empty());
    ::testing::internal::CaptureStderr();
    const StatusOr<cv::Mat> decoded = DecodeImage(bytes, mode.mode);
    EXPECT_EQ(::testing::internal::GetCapturedStderr(), "");
    ASSERT_TRUE(decoded.ok()) << decoded.status().message();
    ASSERT_EQ(decoded->type(), expected.type());
    ASSERT_EQ(decoded->size(), expected.size());
    EXPECT_EQ(cv::norm(*decoded, expected, cv::NORM_INF), 0.0);
  }
}

// A PNG that libpng writes from `samples` (CV_16UC(channels), values below
// 2^bit_depth): any color type, bit depth, interlacing, and a tRNS chunk.
void AppendBytes(png_structp png, png_bytep data, png_size_t size) {
  static_cast<std::string*>(png_get_io_ptr(png))
      ->append(reinterpret_cast<const char*>(data), size);
}

std::string LibpngFile(const cv::Mat& samples, int bit_depth, int color_type,
                       bool interlaced, bool transparency) {
  png_structp png =
      png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png_create_info_struct(png);
  std::string bytes;
  png_set_write_fn(png, &bytes, AppendBytes, nullptr);
  png_set_IHDR(png, info, samples.cols, samples.rows, bit_depth, color_type,
               interlaced ? PNG_INTERLACE_ADAM7 : PNG_INTERLACE_NONE,
               PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  std::vector<png_color> palette(1 << std::min(bit_depth, 8));
  if (color_type == PNG_COLOR_TYPE_PALETTE) {
    for (size_t i = 0; i < palette.size(); ++i) {
      palette[i] = {static_cast<png_byte>(i * 7),
                    static_cast<png_byte>(255 - i),
                    static_cast<png_byte>(i * 3 + 1)};
    }
    png_set_PLTE(png, info, palette.data(), static_cast<int>(palette.size()));
  }
  std::vector<png_byte> alphas(palette.size());
  png_color_16 transparent{};
  if (transparency) {
    for (size_t i = 0; i < alphas.size(); ++i) alphas[i] = png_byte(i * 5);
    transparent.gray = transparent.red = 1;
    transparent.green = transparent.blue = 2;
    png_set_tRNS(png, info, alphas.data(),
                 color_type == PNG_COLOR_TYPE_PALETTE
                     ? static_cast<int>(alphas.size())
                     : 0,
                 &transparent);
  }
  png_write_info(png, info);
  if (bit_depth < 8) png_set_packing(png);
  if (bit_depth == 16) png_set_swap(png);
  // Rows of bytes (bit depth up to 8) or 16-bit samples.
  cv::Mat rows;
  samples.convertTo(rows, bit_depth == 16 ? CV_16U : CV_8U);
  const int passes = png_set_interlace_handling(png);
  for (int pass = 0; pass < passes; ++pass) {
    for (int y = 0; y < rows.rows; ++y) png_write_row(png, rows.ptr(y));
  }
  png_write_end(png, info);
  png_destroy_write_struct(&png, &info);
  return bytes;
}

int ChannelsOf(int color_type) {
  switch (color_type) {
    case PNG_COLOR_TYPE_RGB:
      return 3;
    case PNG_COLOR_TYPE_GRAY_ALPHA:
      return 2;
    case PNG_COLOR_TYPE_RGB_ALPHA:
      return 4;
  }
  return 1;  // gray, palette
}

TEST(ImageCodec, PngPixelsAreOpenCvsForEveryColorTypeAndDepth) {
  struct Case {
    int color_type;
    std::vector<int> bit_depths;
  };
  const Case cases[] = {
      {PNG_COLOR_TYPE_GRAY, {1, 2, 4, 8, 16}},
      {PNG_COLOR_TYPE_RGB, {8, 16}},
      {PNG_COLOR_TYPE_PALETTE, {1, 2, 4, 8}},
      {PNG_COLOR_TYPE_GRAY_ALPHA, {8, 16}},
      {PNG_COLOR_TYPE_RGB_ALPHA, {8, 16}},
  };
  int files = 0;
  for (const Case& c : cases) {
    for (int bit_depth : c.bit_depths) {
      cv::Mat samples(13, 17, CV_16UC(ChannelsOf(c.color_type)));
      cv::RNG rng(bit_depth + 10 * c.color_type);
      rng.fill(samples, cv::RNG::UNIFORM, 0, 1 << bit_depth);
      for (bool interlaced : {false, true}) {
        for (bool transparency : {false, true}) {
          if (transparency && (c.color_type & PNG_COLOR_MASK_ALPHA) != 0) {
            continue;  // tRNS is for the types without alpha
          }
          const std::string what = "color type " +
                                   std::to_string(c.color_type) + ", " +
                                   std::to_string(bit_depth) + " bits" +
                                   (interlaced ? ", interlaced" : "") +
                                   (transparency ? ", tRNS" : "");
          ExpectOpenCvPixels(LibpngFile(samples, bit_depth, c.color_type,
                                        interlaced, transparency),
                             what);
          ++files;
        }
      }
    }
  }
  EXPECT_EQ(files, 2 * (5 * 2 + 2 * 2 + 4 * 2 + 2 + 2));
}

TEST(ImageCodec, JpegPixelsAreOpenCvs) {
  const cv::Mat color = Noise(CV_8UC3, 40, 56);
  const cv::Mat gray = Noise(CV_8UC1, 40, 56);
  cv::Mat smooth;
  cv::GaussianBlur(color, smooth, cv::Size(7, 7), 2.0);
  ExpectOpenCvPixels(OpenCvEncode(".jpg", color), "color");
  ExpectOpenCvPixels(OpenCvEncode(".jpg", gray), "gray");
  ExpectOpenCvPixels(
      OpenCvEncode(".jpg", smooth, {cv::IMWRITE_JPEG_QUALITY, 40}),
      "quality 40");
  ExpectOpenCvPixels(
      OpenCvEncode(".jpg", color, {cv::IMWRITE_JPEG_PROGRESSIVE, 1}),
      "progressive");
  ExpectOpenCvPixels(
      OpenCvEncode(".jpg", color, {cv::IMWRITE_JPEG_OPTIMIZE, 1}), "optimized");
  ExpectOpenCvPixels(
      OpenCvEncode(".jpg", gray, {cv::IMWRITE_JPEG_RST_INTERVAL, 2}),
      "restart markers");
}

// OpenCV turns a JPEG upright by its Exif orientation when it reads it as
// gray or color: such files go to OpenCV, and are read as it reads them.
TEST(ImageCodec, JpegWithExifOrientationIsTurnedAsOpenCvTurnsIt) {
  const std::string jpeg = OpenCvEncode(".jpg", Noise(CV_8UC3, 24, 40));
  // APP1: "Exif\0\0", a little-endian TIFF header, one IFD of one entry:
  // Orientation (0x0112), SHORT, 1 value, 6 (turned 90 degrees clockwise).
  const std::string tiff =
      std::string("II*\0\x08\0\0\0", 8) + std::string("\x01\0", 2) +
      std::string("\x12\x01\x03\0\x01\0\0\0\x06\0\0\0", 12) +
      std::string("\0\0\0\0", 4);
  const std::string payload = std::string("Exif\0\0", 6) + tiff;
  const size_t length = payload.size() + 2;
  const std::string app1 = std::string("\xff\xe1", 2) +
                           static_cast<char>(length >> 8) +
                           static_cast<char>(length & 0xff) + payload;
  const std::string turned = jpeg.substr(0, 2) + app1 + jpeg.substr(2);
  ASSERT_EQ(OpenCvDecode(turned, cv::IMREAD_COLOR).cols, 24);  // upright
  ExpectOpenCvPixels(turned, "Exif orientation 6");
}

// Formats other than PNG and JPEG are read by OpenCV, loaded on first use.
TEST(ImageCodec, OtherFormatsAreReadByOpenCv) {
  ExpectOpenCvPixels(OpenCvEncode(".bmp", Noise(CV_8UC3)), "BMP");
  ExpectOpenCvPixels(OpenCvEncode(".ppm", Noise(CV_8UC3)), "PPM");
  ExpectOpenCvPixels(OpenCvEncode(".pgm", Noise(CV_8UC1)), "PGM");
  ExpectOpenCvPixels(OpenCvEncode(".tiff", Noise(CV_16UC1)), "16-bit TIFF");
}

TEST(ImageCodec, PngBytesAreOpenCvs) {
  for (int type : {CV_8UC1, CV_8UC3, CV_8UC4, CV_16UC1, CV_16UC3, CV_16UC4}) {
    SCOPED_TRACE(cv::typeToString(type));
    const cv::Mat image = Noise(type);
    const StatusOr<std::string> png = EncodePng(image);
    ASSERT_TRUE(png.ok()) << png.status().message();
    EXPECT_EQ(*png, OpenCvEncode(".png", image));
    // And back: the same pixels.
    const StatusOr<cv::Mat> decoded =
        DecodeImage(*png, ImageReadMode::kAsStored);
    ASSERT_TRUE(decoded.ok());
    EXPECT_EQ(cv::norm(*decoded, image, cv::NORM_INF), 0.0);
  }
}

TEST(ImageCodec, JpegBytesAreOpenCvs) {
  for (int type : {CV_8UC1, CV_8UC3}) {
    for (int quality : {1, 50, 95, 100}) {
      SCOPED_TRACE(cv::typeToString(type) + ", quality " +
                   std::to_string(quality));
      const cv::Mat image = Noise(type, 33, 50);
      const StatusOr<std::string> jpeg = EncodeJpeg(image, quality);
      ASSERT_TRUE(jpeg.ok()) << jpeg.status().message();
      EXPECT_EQ(*jpeg, OpenCvEncode(".jpg", image,
                                    {cv::IMWRITE_JPEG_QUALITY, quality}));
    }
  }
}

TEST(ImageCodec, EncodersRefuseWhatTheFormatCannotHold) {
  EXPECT_EQ(EncodePng(cv::Mat()).status().message(),
            "cannot encode an empty image");
  EXPECT_EQ(EncodePng(Noise(CV_32FC1)).status().message(),
            "PNG holds 8- or 16-bit images with 1, 3 or 4 channels, got "
            "CV_32FC1");
  EXPECT_EQ(EncodePng(Noise(CV_8UC2)).status().message(),
            "PNG holds 8- or 16-bit images with 1, 3 or 4 channels, got "
            "CV_8UC2");
  EXPECT_EQ(EncodeJpeg(cv::Mat(), 95).status().message(),
            "cannot encode an empty image");
  EXPECT_EQ(EncodeJpeg(Noise(CV_16UC1), 95).status().message(),
            "JPEG holds CV_8UC1 or CV_8UC3 images, got CV_16UC1");
  EXPECT_EQ(EncodeJpeg(Noise(CV_8UC1), 0).status().message(),
            "JPEG quality 0 is not 1 to 100");
  EXPECT_EQ(EncodeJpeg(Noise(CV_8UC1), 101).status().message(),
            "JPEG quality 101 is not 1 to 100");
}

// Bytes that are no image, or a cut one: an error, nothing printed (libpng
// and libjpeg print by default).
TEST(ImageCodec, UndecodableBytesAreAnErrorAndPrintNothing) {
  const std::string png = OpenCvEncode(".png", Noise(CV_8UC3));
  const std::string jpeg = OpenCvEncode(".jpg", Noise(CV_8UC3));
  const std::string kNot =
      "not an image OpenCV can decode (corrupt or unsupported format)";
  for (const std::string& bytes :
       {std::string(), std::string("hello, world"), png.substr(0, 60),
        png.substr(0, png.size() / 2), jpeg.substr(0, 20),
        std::string("\xff\xd8\xff\xe0", 4)}) {
    for (const Mode& mode : kModes) {
      ::testing::internal::CaptureStderr();
      const StatusOr<cv::Mat> decoded = DecodeImage(bytes, mode.mode);
      EXPECT_EQ(::testing::internal::GetCapturedStderr(), "");
      ASSERT_FALSE(decoded.ok()) << bytes.size() << " bytes";
      EXPECT_EQ(decoded.status().message(), kNot);
    }
  }
}

}  // namespace
}  // namespace rcm::image_codec_test
