#include "rcm/io/image_file.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <initializer_list>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <utility>
#include <vector>

#include "support/temp_file.h"

namespace rcm::image_file_test {
namespace {

cv::Mat TestImage(int type) {
  cv::Mat image(37, 53, type);
  cv::RNG rng(3);
  rng.fill(image, cv::RNG::UNIFORM, 0, 256);
  return image;
}

TEST(ImageFile, ColorRoundTrip) {
  const std::string path = test::TempFilePath("color.png");
  const cv::Mat image = TestImage(CV_8UC3);
  ASSERT_TRUE(WritePng(image, path).ok());
  const StatusOr<cv::Mat> read = ReadImage(path, /*grayscale=*/false);
  ASSERT_TRUE(read.ok()) << read.status().message();
  ASSERT_EQ(read->type(), CV_8UC3);
  EXPECT_EQ(cv::norm(*read, image, cv::NORM_INF), 0.0);
  // The same file as gray: one channel of the same size.
  const StatusOr<cv::Mat> gray = ReadImage(path, /*grayscale=*/true);
  ASSERT_TRUE(gray.ok());
  EXPECT_EQ(gray->type(), CV_8UC1);
  EXPECT_EQ(gray->size(), image.size());
  std::remove(path.c_str());
}

TEST(ImageFile, GrayRoundTripReplacesFile) {
  const std::string path = test::TempFilePath("gray.png");
  ASSERT_TRUE(WritePng(cv::Mat(5, 5, CV_8UC1, cv::Scalar(9)), path).ok());
  const cv::Mat image = TestImage(CV_8UC1);
  ASSERT_TRUE(WritePng(image, path).ok());
  const StatusOr<cv::Mat> read = ReadImage(path, /*grayscale=*/true);
  ASSERT_TRUE(read.ok()) << read.status().message();
  EXPECT_EQ(cv::norm(*read, image, cv::NORM_INF), 0.0);
  std::remove(path.c_str());
}

TEST(ImageFile, WriteIntoMissingDirectoryFails) {
  const std::string directory = test::TempFilePath("no_such_dir");
  const std::string path = directory + "/plot.png";
  const Status status = WritePng(TestImage(CV_8UC3), path);
  ASSERT_FALSE(status.ok());
  EXPECT_EQ(status.message(),
            path + ": cannot write: No such file or directory");
  EXPECT_FALSE(std::filesystem::exists(directory));
}

TEST(ImageFile, WriteOverDirectoryFails) {
  const std::string directory = test::TempFilePath("a_directory");
  std::filesystem::create_directories(directory);
  const Status status = WritePng(TestImage(CV_8UC3), directory);
  ASSERT_FALSE(status.ok());
  EXPECT_EQ(status.message().rfind(directory + ": cannot write: ", 0), 0u)
      << status.message();
  EXPECT_TRUE(std::filesystem::is_directory(directory));
  std::filesystem::remove_all(directory);
}

TEST(ImageFile, WriteRejectsImagesPngCannotHold) {
  const std::string path = test::TempFilePath("bad.png");
  const Status empty = WritePng(cv::Mat(), path);
  ASSERT_FALSE(empty.ok());
  EXPECT_EQ(empty.message(), path + ": cannot write an empty image");
  const Status floating = WritePng(cv::Mat(4, 4, CV_32FC1), path);
  ASSERT_FALSE(floating.ok());
  EXPECT_EQ(floating.message(),
            path +
                ": PNG holds 8- or 16-bit images with 1, 3 or 4 "
                "channels, got CV_32FC1");
  EXPECT_FALSE(std::filesystem::exists(path));
}

TEST(ImageFile, ReadAsStoredKeepsDepthAndChannels) {
  // ReadImage converts to 8-bit gray or BGR; ReadImageAsStored does not.
  cv::Mat deep(6, 8, CV_16UC1);
  cv::randu(deep, 0, 65535);
  const std::string deep_path = test::TempFilePath("deep.png");
  ASSERT_TRUE(WritePng(deep, deep_path).ok());
  const StatusOr<cv::Mat> stored = ReadImageAsStored(deep_path);
  ASSERT_TRUE(stored.ok()) << stored.status().message();
  EXPECT_EQ(stored->type(), CV_16UC1);
  EXPECT_EQ(cv::norm(*stored, deep, cv::NORM_INF), 0.0);
  EXPECT_EQ(ReadImage(deep_path, true)->type(), CV_8UC1);

  cv::Mat bgra(6, 8, CV_8UC4);
  cv::randu(bgra, 0, 255);
  const std::string bgra_path = test::TempFilePath("bgra.png");
  ASSERT_TRUE(WritePng(bgra, bgra_path).ok());
  EXPECT_EQ(ReadImageAsStored(bgra_path)->type(), CV_8UC4);
  EXPECT_EQ(ReadImage(bgra_path, false)->type(), CV_8UC3);

  const std::string text = test::WriteTempFile("text.png", "not an image\n");
  EXPECT_EQ(ReadImageAsStored(text).status().message(),
            text +
                ": not an image OpenCV can decode (corrupt or unsupported "
                "format)");
}

TEST(ImageFile, ReadMissingFile) {
  const std::string path = test::TempFilePath("missing.png");
  const StatusOr<cv::Mat> read = ReadImage(path, true);
  ASSERT_FALSE(read.ok());
  EXPECT_EQ(read.status().message(),
            path + ": cannot open: No such file or directory");
}

TEST(ImageFile, ReadCorruptOrEmptyFile) {
  const std::string expected =
      ": not an image OpenCV can decode (corrupt or unsupported format)";
  const std::string text = test::WriteTempFile("text.png", "not an image\n");
  const StatusOr<cv::Mat> read = ReadImage(text, false);
  ASSERT_FALSE(read.ok());
  EXPECT_EQ(read.status().message(), text + expected);

  const std::string empty = test::WriteTempFile("empty.png", "");
  ASSERT_FALSE(ReadImage(empty, true).ok());
  EXPECT_EQ(ReadImage(empty, true).status().message(), empty + expected);

  // A PNG cut in half.
  const std::string path = test::TempFilePath("whole.png");
  ASSERT_TRUE(WritePng(TestImage(CV_8UC3), path).ok());
  std::string bytes;
  {
    std::FILE* file = std::fopen(path.c_str(), "rb");
    ASSERT_NE(file, nullptr);
    char buffer[4096];
    size_t got;
    while ((got = std::fread(buffer, 1, sizeof(buffer), file)) > 0) {
      bytes.append(buffer, got);
    }
    std::fclose(file);
  }
  const std::string cut =
      test::WriteTempFile("cut.png", bytes.substr(0, bytes.size() / 2));
  const StatusOr<cv::Mat> truncated = ReadImage(cut, false);
  ASSERT_FALSE(truncated.ok());
  EXPECT_EQ(truncated.status().message().rfind(cut + ": truncated PNG (", 0),
            0u)
      << truncated.status().message();
  std::remove(path.c_str());
  std::remove(text.c_str());
  std::remove(empty.c_str());
  std::remove(cut.c_str());
}

// CheckImageFileStructure.

std::string Encode(const std::string& extension, const cv::Mat& image,
                   const std::vector<int>& parameters = {}) {
  std::vector<uchar> bytes;
  EXPECT_TRUE(cv::imencode(extension, image, bytes, parameters));
  return std::string(bytes.begin(), bytes.end());
}

std::string StructureError(const std::string& bytes) {
  return CheckImageFileStructure(bytes).message();
}

std::string Bytes(std::initializer_list<int> values) {
  std::string bytes;
  for (int value : values) bytes.push_back(static_cast<char>(value));
  return bytes;
}

bool StartsWith(const std::string& text, const std::string& prefix) {
  return text.rfind(prefix, 0) == 0;
}

TEST(ImageFileStructure, AcceptsWhatOpenCvWrites) {
  const std::vector<std::string> files = {
      Encode(".png", TestImage(CV_8UC1)),
      Encode(".png", TestImage(CV_8UC3)),
      Encode(".png", TestImage(CV_16UC1)),
      Encode(".png", cv::Mat(600, 800, CV_8UC1, cv::Scalar(7))),
      Encode(".jpg", TestImage(CV_8UC1)),
      Encode(".jpg", TestImage(CV_8UC3), {cv::IMWRITE_JPEG_QUALITY, 100}),
      Encode(".jpg", TestImage(CV_8UC3), {cv::IMWRITE_JPEG_PROGRESSIVE, 1}),
      Encode(".jpg", TestImage(CV_8UC3), {cv::IMWRITE_JPEG_OPTIMIZE, 1}),
      Encode(".jpg", TestImage(CV_8UC1), {cv::IMWRITE_JPEG_RST_INTERVAL, 2}),
  };
  for (size_t i = 0; i < files.size(); ++i) {
    EXPECT_TRUE(CheckImageFileStructure(files[i]).ok())
        << i << ": " << StructureError(files[i]);
  }
  // Bytes after the end are not part of the image (some cameras pad).
  EXPECT_TRUE(CheckImageFileStructure(files[0] + "padding").ok());
  EXPECT_TRUE(CheckImageFileStructure(files[4] + std::string(16, '\0')).ok());
  // Other formats and other bytes are left to the decoder.
  EXPECT_TRUE(CheckImageFileStructure(Encode(".bmp", TestImage(CV_8UC1))).ok());
  EXPECT_TRUE(CheckImageFileStructure("").ok());
  EXPECT_TRUE(CheckImageFileStructure("not an image").ok());
}

// The JPEG and PNG files of OpenCV's samples: real cameras' JPEGs (EXIF,
// thumbnails) and PNGs of other encoders.
TEST(ImageFileStructure, AcceptsOpenCvSampleImages) {
  const std::string folder = "/usr/share/doc/opencv-doc/examples/data";
  if (!std::filesystem::is_directory(folder)) {
    GTEST_SKIP() << folder << " is missing (Debian package opencv-doc)";
  }
  int checked = 0;
  for (const auto& entry : std::filesystem::directory_iterator(folder)) {
    const std::string extension = entry.path().extension().string();
    if (extension != ".jpg" && extension != ".png") continue;
    ::testing::internal::CaptureStderr();
    const StatusOr<cv::Mat> image = ReadImageAsStored(entry.path().string());
    EXPECT_EQ(::testing::internal::GetCapturedStderr(), "") << entry.path();
    EXPECT_TRUE(image.ok()) << image.status().message();
    ++checked;
  }
  EXPECT_GT(checked, 20);
}

TEST(ImageFileStructure, RefusesCutPng) {
  const std::string png = Encode(".png", TestImage(CV_8UC3));
  const size_t iend = png.size() - 12;
  // Inside the IHDR chunk, inside IDAT, before IEND, inside IEND.
  for (size_t size : {size_t{20}, png.size() / 2, iend, png.size() - 1}) {
    const std::string error = StructureError(png.substr(0, size));
    EXPECT_TRUE(StartsWith(error, "truncated PNG (")) << size << ": " << error;
  }
  EXPECT_EQ(StructureError(png.substr(0, iend)),
            "truncated PNG (the file ends at byte " + std::to_string(iend) +
                ", before its IEND chunk)");
}

TEST(ImageFileStructure, RefusesDamagedPng) {
  const std::string png = Encode(".png", TestImage(CV_8UC3));
  const size_t idat = png.find("IDAT") - 4;
  std::string flipped = png;
  flipped[idat + 20] = static_cast<char>(flipped[idat + 20] ^ 1);
  EXPECT_EQ(StructureError(flipped), "corrupt PNG (chunk IDAT at byte " +
                                         std::to_string(idat) +
                                         ": CRC mismatch)");
  // A chunk length of 2^31 or more.
  std::string long_chunk = png;
  long_chunk[idat] = static_cast<char>(0x80);
  EXPECT_TRUE(StartsWith(
      StructureError(long_chunk),
      "corrupt PNG (chunk IDAT at byte " + std::to_string(idat) + ": length"))
      << StructureError(long_chunk);
  // Not a chunk type where one should be.
  std::string no_type = png;
  no_type[idat + 4] = '\x01';
  EXPECT_EQ(StructureError(no_type), "corrupt PNG (no chunk type at byte " +
                                         std::to_string(idat + 4) + ")");
  // The signature, then the end chunk only.
  const std::string iend = png.substr(png.size() - 12);
  EXPECT_EQ(StructureError(png.substr(0, 8) + iend),
            "corrupt PNG (the first chunk is IEND, expected IHDR)");
  // IHDR, then IEND: no pixels.
  EXPECT_EQ(StructureError(png.substr(0, 33) + iend),
            "corrupt PNG (no IDAT chunk before IEND)");
}

TEST(ImageFileStructure, RefusesCutJpeg) {
  const std::string jpeg = Encode(".jpg", TestImage(CV_8UC3));
  const size_t scan = jpeg.find("\xff\xda");
  ASSERT_NE(scan, std::string::npos);
  // After SOI, inside a header segment, inside the scan, without EOI.
  for (size_t size : {size_t{3}, size_t{30}, scan + (jpeg.size() - scan) / 2,
                      jpeg.size() - 2, jpeg.size() - 1}) {
    const std::string error = StructureError(jpeg.substr(0, size));
    EXPECT_TRUE(StartsWith(error, "truncated JPEG (")) << size << ": " << error;
  }
}

TEST(ImageFileStructure, RefusesDamagedJpeg) {
  const std::string jpeg = Encode(".jpg", TestImage(CV_8UC1));
  // A reserved marker code right after SOI.
  EXPECT_EQ(StructureError("\xff\xd8\xff\x7a" + jpeg.substr(4)),
            "corrupt JPEG (marker 0x7A at byte 2 is not a JPEG marker)");
  // The end before any pixels.
  EXPECT_EQ(StructureError(jpeg.substr(0, 2) + "\xff\xd9"),
            "corrupt JPEG (end-of-image marker before any scan)");
  // SOI and a comment segment (COM, 2 bytes of text), then a byte that is
  // no marker where a segment should start, or a second SOI.
  const std::string after_soi =
      jpeg.substr(0, 2) + Bytes({0xff, 0xfe, 0x00, 0x04, 'a', 'b'});
  EXPECT_EQ(StructureError(after_soi + "x" + jpeg.substr(2)),
            "corrupt JPEG (byte 8 is 0x78, expected a marker)");
  EXPECT_EQ(StructureError(after_soi + jpeg),
            "corrupt JPEG (a second start-of-image marker 0xD8 at byte 8)");
  EXPECT_TRUE(CheckImageFileStructure(after_soi + jpeg.substr(2)).ok());
  // A segment length below 2.
  EXPECT_EQ(StructureError(jpeg.substr(0, 2) + Bytes({0xff, 0xfe, 0x00, 0x01}) +
                           jpeg.substr(2)),
            "corrupt JPEG (segment of marker 0xFE at byte 2 has length 1)");
}

// What libpng and libjpeg would print on their own for these files stays
// unprinted: the one error is the status.
TEST(ImageFileStructure, ReadImageOfCutFilesPrintsNothing) {
  const std::string png = Encode(".png", TestImage(CV_8UC3));
  const std::string jpeg = Encode(".jpg", TestImage(CV_8UC3));
  const std::string cut_png =
      test::WriteTempFile("cut.png", png.substr(0, png.size() / 2));
  const std::string cut_jpeg =
      test::WriteTempFile("cut.jpg", jpeg.substr(0, jpeg.size() / 2));
  ::testing::internal::CaptureStderr();
  const StatusOr<cv::Mat> png_read = ReadImage(cut_png, false);
  const StatusOr<cv::Mat> jpeg_read = ReadImage(cut_jpeg, false);
  EXPECT_EQ(::testing::internal::GetCapturedStderr(), "");
  ASSERT_FALSE(png_read.ok());
  EXPECT_TRUE(StartsWith(png_read.status().message(),
                         cut_png + ": truncated PNG (the file ends inside "
                                   "chunk IDAT at byte "))
      << png_read.status().message();
  ASSERT_FALSE(jpeg_read.ok());
  EXPECT_TRUE(StartsWith(jpeg_read.status().message(),
                         cut_jpeg + ": truncated JPEG (the file ends inside "
                                    "the scan of marker 0xDA at byte "))
      << jpeg_read.status().message();
  std::remove(cut_png.c_str());
  std::remove(cut_jpeg.c_str());
}

// The pixel data: the zlib stream of PNG files and the entropy-coded scans
// of JPEG files.

std::string BigEndian32(uint32_t value) {
  return Bytes(
      {static_cast<int>(value >> 24), static_cast<int>(value >> 16 & 0xff),
       static_cast<int>(value >> 8 & 0xff), static_cast<int>(value & 0xff)});
}

uint32_t Crc32(const std::string& data) {
  uint32_t crc = 0xffffffffu;
  for (char byte : data) {
    crc ^= static_cast<uint8_t>(byte);
    for (int k = 0; k < 8; ++k) {
      crc = (crc & 1) ? 0xedb88320u ^ (crc >> 1) : crc >> 1;
    }
  }
  return crc ^ 0xffffffffu;
}

std::string PngChunk(const std::string& type, const std::string& data) {
  return BigEndian32(static_cast<uint32_t>(data.size())) + type + data +
         BigEndian32(Crc32(type + data));
}

// A zlib stream (RFC 1950) of `data` in stored (uncompressed) deflate
// blocks, with its Adler-32.
std::string ZlibStored(const std::string& data) {
  std::string stream = Bytes({0x78, 0x01});
  size_t at = 0;
  do {
    const size_t size = std::min<size_t>(data.size() - at, 65535);
    const bool last = at + size == data.size();
    stream +=
        Bytes({last ? 1 : 0, static_cast<int>(size & 0xff),
               static_cast<int>(size >> 8), static_cast<int>(~size & 0xff),
               static_cast<int>(~size >> 8 & 0xff)});
    stream += data.substr(at, size);
    at += size;
  } while (at < data.size());
  uint32_t a = 1;
  uint32_t b = 0;
  for (char byte : data) {
    a = (a + static_cast<uint8_t>(byte)) % 65521;
    b = (b + a) % 65521;
  }
  return stream + BigEndian32(b << 16 | a);
}

// A PNG file: IHDR, `before_idat` (whole chunks), one IDAT chunk of
// `idat`, IEND.
std::string MakePng(int width, int height, int bit_depth, int color_type,
                    bool interlaced, const std::string& idat,
                    const std::string& before_idat = "") {
  const std::string ihdr =
      BigEndian32(width) + BigEndian32(height) +
      Bytes({bit_depth, color_type, 0, 0, interlaced ? 1 : 0});
  return "\x89PNG\r\n\x1a\n" + PngChunk("IHDR", ihdr) + before_idat +
         PngChunk("IDAT", idat) + PngChunk("IEND", "");
}

// The image data of one-channel `samples` (CV_16UC1, values below
// 2^bit_depth) as PNG stores them before compression: rows of a filter
// type byte (0: none) and the samples packed, first bit highest, in the
// order of Adam7's 7 passes when `interlaced`.
std::string PngImageData(const cv::Mat& samples, int bit_depth,
                         bool interlaced) {
  struct Pass {
    int x0, y0, dx, dy;
  };
  const std::vector<Pass> passes =
      interlaced ? std::vector<Pass>{{0, 0, 8, 8}, {4, 0, 8, 8}, {0, 4, 4, 8},
                                     {2, 0, 4, 4}, {0, 2, 2, 4}, {1, 0, 2, 2},
                                     {0, 1, 1, 2}}
                 : std::vector<Pass>{{0, 0, 1, 1}};
  std::string data;
  for (const Pass& pass : passes) {
    if (pass.x0 >= samples.cols) continue;  // an empty pass: no rows at all
    for (int y = pass.y0; y < samples.rows; y += pass.dy) {
      data.push_back('\0');
      uint32_t bits = 0;
      int count = 0;
      for (int x = pass.x0; x < samples.cols; x += pass.dx) {
        bits = bits << bit_depth | samples.at<uint16_t>(y, x);
        count += bit_depth;
        while (count >= 8) {
          count -= 8;
          data.push_back(static_cast<char>(bits >> count & 0xff));
        }
      }
      if (count > 0) data.push_back(static_cast<char>(bits << (8 - count)));
    }
  }
  return data;
}

cv::Mat Samples(int width, int height, int bit_depth) {
  cv::Mat samples(height, width, CV_16UC1);
  cv::RNG rng(5);
  rng.fill(samples, cv::RNG::UNIFORM, 0, 1 << bit_depth);
  return samples;
}

// PNG files libpng writes and OpenCV cannot (interlaced, 1 to 4 bits per
// pixel, palettes) are read and checked: the checked sizes of their image
// data are right.
TEST(ImageFileStructure, ReadsInterlacedAndPackedPngs) {
  struct Case {
    int width, height, bit_depth, color_type;
  };
  const Case cases[] = {{13, 11, 8, 0}, {1, 1, 8, 0},   {3, 2, 8, 0},
                        {5, 9, 1, 0},   {13, 11, 2, 0}, {17, 3, 4, 3},
                        {9, 10, 16, 0}, {37, 29, 1, 3}};
  // Palette entry i: blue i, green 255 - i, red 7.
  std::string palette;
  for (int i = 0; i < 16; ++i) palette += Bytes({7, 255 - i, i});
  for (const Case& c : cases) {
    for (bool interlaced : {false, true}) {
      SCOPED_TRACE(std::to_string(c.width) + "x" + std::to_string(c.height) +
                   ", bit depth " + std::to_string(c.bit_depth) +
                   ", color type " + std::to_string(c.color_type) +
                   (interlaced ? ", interlaced" : ""));
      const cv::Mat samples = Samples(c.width, c.height, c.bit_depth);
      const std::string png =
          MakePng(c.width, c.height, c.bit_depth, c.color_type, interlaced,
                  ZlibStored(PngImageData(samples, c.bit_depth, interlaced)),
                  c.color_type == 3 ? PngChunk("PLTE", palette) : "");
      EXPECT_TRUE(CheckImageFileStructure(png).ok()) << StructureError(png);
      const std::string path = test::WriteTempFile("made.png", png);
      ::testing::internal::CaptureStderr();
      const StatusOr<cv::Mat> read = ReadImageAsStored(path);
      EXPECT_EQ(::testing::internal::GetCapturedStderr(), "");
      ASSERT_TRUE(read.ok()) << read.status().message();
      cv::Mat expected;
      if (c.color_type == 3) {
        expected.create(samples.size(), CV_8UC3);
        for (int y = 0; y < samples.rows; ++y) {
          for (int x = 0; x < samples.cols; ++x) {
            const int i = samples.at<uint16_t>(y, x);
            expected.at<cv::Vec3b>(y, x) = cv::Vec3b(i, 255 - i, 7);  // BGR
          }
        }
      } else if (c.bit_depth == 16) {
        expected = samples;
      } else {  // gray scaled to 8 bits
        samples.convertTo(expected, CV_8U, 255.0 / ((1 << c.bit_depth) - 1));
      }
      ASSERT_EQ(read->type(), expected.type());
      EXPECT_EQ(cv::norm(*read, expected, cv::NORM_INF), 0.0);
      // One byte of image data more or less is refused.
      const std::string data = PngImageData(samples, c.bit_depth, interlaced);
      for (const std::string& wrong : {data.substr(1), data + '\0'}) {
        EXPECT_TRUE(
            StartsWith(StructureError(MakePng(
                           c.width, c.height, c.bit_depth, c.color_type,
                           interlaced, ZlibStored(wrong),
                           c.color_type == 3 ? PngChunk("PLTE", palette) : "")),
                       "corrupt PNG (IDAT data holds "));
      }
      std::remove(path.c_str());
    }
  }
}

TEST(ImageFileStructure, RefusesPngWithBadDeflateData) {
  // Damaged compressed data under a CRC that matches them.
  const std::string png = Encode(".png", TestImage(CV_8UC3));
  const size_t idat = png.find("IDAT") - 4;
  const uint32_t length = static_cast<uint8_t>(png[idat + 2]) << 8 |
                          static_cast<uint8_t>(png[idat + 3]);
  ASSERT_GT(length, 400u);
  std::string damaged = png;
  for (size_t k = 50; k < 80; ++k) damaged[idat + 8 + k] ^= '\xa5';
  damaged.replace(idat + 8 + length, 4,
                  BigEndian32(Crc32(damaged.substr(idat + 4, 4 + length))));
  const std::string error = StructureError(damaged);
  EXPECT_TRUE(StartsWith(error, "corrupt PNG (IDAT data: ")) << error;

  // Read: one error, nothing from libpng.
  const std::string path = test::WriteTempFile("bad_deflate.png", damaged);
  ::testing::internal::CaptureStderr();
  const StatusOr<cv::Mat> read = ReadImage(path, false);
  EXPECT_EQ(::testing::internal::GetCapturedStderr(), "");
  ASSERT_FALSE(read.ok());
  EXPECT_EQ(read.status().message(), path + ": " + error);
  std::remove(path.c_str());

  // zlib's messages.
  const std::string data = PngImageData(Samples(13, 11, 8), 8, false);
  std::string bad_check = ZlibStored(data);
  bad_check.back() ^= 1;
  EXPECT_EQ(StructureError(MakePng(13, 11, 8, 0, false, bad_check)),
            "corrupt PNG (IDAT data: incorrect data check)");
  std::string bad_header = ZlibStored(data);
  bad_header[1] ^= 1;
  EXPECT_EQ(StructureError(MakePng(13, 11, 8, 0, false, bad_header)),
            "corrupt PNG (IDAT data: incorrect header check)");
}

TEST(ImageFileStructure, RefusesPngWhoseDataDoNotFitTheHeader) {
  // 13 x 11 8-bit gray: 11 rows of a filter byte and 13 pixels.
  const std::string data = PngImageData(Samples(13, 11, 8), 8, false);
  ASSERT_EQ(data.size(), 154u);
  const std::string stream = ZlibStored(data);
  EXPECT_TRUE(
      CheckImageFileStructure(MakePng(13, 11, 8, 0, false, stream)).ok());
  EXPECT_EQ(
      StructureError(MakePng(13, 11, 8, 0, false, ZlibStored(data.substr(1)))),
      "corrupt PNG (IDAT data holds 153 bytes, the header implies 154)");
  EXPECT_EQ(StructureError(MakePng(13, 11, 8, 0, false,
                                   ZlibStored(data + std::string(40000, 'x')))),
            "corrupt PNG (IDAT data holds more than the 154 bytes the header "
            "implies)");
  // The stream without its Adler-32, or cut in its data.
  EXPECT_EQ(StructureError(MakePng(13, 11, 8, 0, false,
                                   stream.substr(0, stream.size() - 4))),
            "corrupt PNG (IDAT data ends inside its zlib stream, after 154 of "
            "the 154 bytes the header implies)");
  EXPECT_EQ(StructureError(MakePng(13, 11, 8, 0, false, stream.substr(0, 107))),
            "corrupt PNG (IDAT data ends inside its zlib stream, after 100 of "
            "the 154 bytes the header implies)");
  // Bytes after the end of the stream, in its chunk or in the next.
  EXPECT_EQ(StructureError(MakePng(13, 11, 8, 0, false, stream + "abc")),
            "corrupt PNG (IDAT data has 3 bytes after the end of its zlib "
            "stream)");
  const std::string png = MakePng(13, 11, 8, 0, false, stream);
  const size_t iend = png.size() - 12;
  EXPECT_EQ(StructureError(png.substr(0, iend) + PngChunk("IDAT", "ab") +
                           png.substr(iend)),
            "corrupt PNG (IDAT data has 2 bytes after the end of its zlib "
            "stream)");
  // The stream over several IDAT chunks, one of them empty: fine.
  const size_t idat = png.find("IDAT") - 4;
  const std::string split =
      png.substr(0, idat) + PngChunk("IDAT", stream.substr(0, 9)) +
      PngChunk("IDAT", "") + PngChunk("IDAT", stream.substr(9)) +
      png.substr(iend);
  EXPECT_TRUE(CheckImageFileStructure(split).ok()) << StructureError(split);
}

TEST(ImageFileStructure, RefusesPngChunksLibpngRefuses) {
  const std::string stream =
      ZlibStored(PngImageData(Samples(4, 3, 8), 8, false));
  const std::string png = MakePng(4, 3, 8, 0, false, stream);
  const size_t idat = png.find("IDAT") - 4;
  const size_t iend = png.size() - 12;
  const auto with_ihdr = [&png](std::initializer_list<int> fields) {
    const std::string ihdr = png.substr(16, 8) + Bytes(fields);
    return png.substr(0, 8) + PngChunk("IHDR", ihdr) + png.substr(33);
  };
  EXPECT_EQ(StructureError(with_ihdr({16, 3, 0, 0, 0})),
            "corrupt PNG (IHDR: bit depth 16 is not one of color type 3)");
  EXPECT_EQ(StructureError(with_ihdr({8, 5, 0, 0, 0})),
            "corrupt PNG (IHDR: color type 5 is not a PNG color type)");
  EXPECT_EQ(StructureError(with_ihdr({8, 0, 0, 0, 2})),
            "corrupt PNG (IHDR: interlace method 2, expected 0 or 1)");
  EXPECT_EQ(StructureError(with_ihdr({8, 0, 1, 0, 0})),
            "corrupt PNG (IHDR: compression method 1, expected 0)");
  EXPECT_EQ(StructureError(MakePng(0, 3, 8, 0, false, stream)),
            "corrupt PNG (IHDR: width 0 is not 1 to 1000000 (libpng's limit))");
  EXPECT_EQ(StructureError(MakePng(4, 1000001, 8, 0, false, stream)),
            "corrupt PNG (IHDR: height 1000001 is not 1 to 1000000 (libpng's "
            "limit))");
  // A palette image without its palette.
  EXPECT_EQ(StructureError(MakePng(4, 3, 8, 3, false, stream)),
            "corrupt PNG (chunk IDAT at byte 33: no PLTE chunk before it)");
  // IDAT chunks apart, an unknown critical chunk.
  const std::string text = PngChunk("tEXt", std::string("a\0b", 3));
  EXPECT_EQ(StructureError(png.substr(0, iend) + text + PngChunk("IDAT", "") +
                           png.substr(iend)),
            "corrupt PNG (chunk IDAT at byte " + std::to_string(iend + 15) +
                ": other chunks between IDAT chunks)");
  EXPECT_TRUE(
      CheckImageFileStructure(png.substr(0, idat) + text + png.substr(idat))
          .ok());
  EXPECT_EQ(StructureError(png.substr(0, idat) + PngChunk("ABCD", "") +
                           png.substr(idat)),
            "corrupt PNG (chunk ABCD at byte 33: an unknown critical chunk)");
}

// A noise image's JPEG with its entropy-coded data damaged, as
// tests/cli/bad_input_table_test.cc damages it: no 0xFF written or
// changed, so the markers stay whole.
std::string JpegWithDamagedScan() {
  cv::Mat noise(240, 320, CV_8UC1);
  cv::RNG rng(1);
  rng.fill(noise, cv::RNG::UNIFORM, 0, 256);
  std::string bytes = Encode(".jpg", noise);
  const size_t scan = bytes.find("\xff\xda");
  EXPECT_NE(scan, std::string::npos);
  for (size_t k = scan + 400; k < scan + 2000; k += 7) {
    const auto byte = static_cast<uint8_t>(bytes[k]);
    if (byte != 0xff && (byte ^ 0x5a) != 0xff &&
        static_cast<uint8_t>(bytes[k - 1]) != 0xff) {
      bytes[k] = static_cast<char>(byte ^ 0x5a);
    }
  }
  return bytes;
}

TEST(ImageFileStructure, RefusesJpegWithDamagedScan) {
  const std::string jpeg = JpegWithDamagedScan();
  const std::string error = StructureError(jpeg);
  EXPECT_TRUE(StartsWith(error, "corrupt JPEG (libjpeg: ")) << error;
  // OpenCV alone decodes it, printing libjpeg's warning.
  const std::string path = test::WriteTempFile("damaged.jpg", jpeg);
  ::testing::internal::CaptureStderr();
  const StatusOr<cv::Mat> read = ReadImage(path, true);
  EXPECT_EQ(::testing::internal::GetCapturedStderr(), "");
  ASSERT_FALSE(read.ok());
  EXPECT_EQ(read.status().message(), path + ": " + error);
  std::remove(path.c_str());
}

TEST(ImageFileStructure, RefusesJpegLibjpegCannotRead) {
  // Sample precision 12 in the frame header (SOF0: length, precision).
  std::string jpeg = Encode(".jpg", TestImage(CV_8UC1));
  const size_t frame = jpeg.find("\xff\xc0");
  ASSERT_NE(frame, std::string::npos);
  jpeg[frame + 4] = 12;
  EXPECT_EQ(StructureError(jpeg),
            "corrupt JPEG (libjpeg: unsupported JPEG data precision 12)");
}

// The images OpenCV writes read as OpenCV decodes them, without a word on
// stderr.
TEST(ImageFileStructure, ReadsWhatOpenCvWritesSilently) {
  const std::vector<std::pair<std::string, std::string>> files = {
      {"gray.png", Encode(".png", TestImage(CV_8UC1))},
      {"color.png", Encode(".png", TestImage(CV_8UC3))},
      {"deep.png", Encode(".png", TestImage(CV_16UC1))},
      {"deep_color.png", Encode(".png", TestImage(CV_16UC3))},
      {"bgra.png", Encode(".png", TestImage(CV_8UC4))},
      {"gray.jpg", Encode(".jpg", TestImage(CV_8UC1))},
      {"color.jpg", Encode(".jpg", TestImage(CV_8UC3))},
      {"progressive.jpg",
       Encode(".jpg", TestImage(CV_8UC3), {cv::IMWRITE_JPEG_PROGRESSIVE, 1})},
      {"optimized.jpg",
       Encode(".jpg", TestImage(CV_8UC3), {cv::IMWRITE_JPEG_OPTIMIZE, 1})},
      {"restart.jpg",
       Encode(".jpg", TestImage(CV_8UC1), {cv::IMWRITE_JPEG_RST_INTERVAL, 2})},
  };
  for (const auto& [name, bytes] : files) {
    const std::string path = test::WriteTempFile(name, bytes);
    ::testing::internal::CaptureStderr();
    const StatusOr<cv::Mat> read = ReadImageAsStored(path);
    EXPECT_EQ(::testing::internal::GetCapturedStderr(), "") << name;
    ASSERT_TRUE(read.ok()) << read.status().message();
    const cv::Mat decoded = cv::imdecode(
        std::vector<uchar>(bytes.begin(), bytes.end()), cv::IMREAD_UNCHANGED);
    EXPECT_EQ(cv::norm(*read, decoded, cv::NORM_INF), 0.0) << name;
    std::remove(path.c_str());
  }
}

}  // namespace
}  // namespace rcm::image_file_test
