#include "rcm/io/image_file.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <string>

#include "support/temp_file.h"

namespace rcm {
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
  EXPECT_EQ(truncated.status().message(), cut + expected);
  std::remove(path.c_str());
  std::remove(text.c_str());
  std::remove(empty.c_str());
  std::remove(cut.c_str());
}

}  // namespace
}  // namespace rcm
