#include "rcm/io/image_file.h"

#include <opencv2/imgcodecs.hpp>
#include <vector>

#include "rcm/io/atomic_file.h"

namespace rcm {

Status WritePng(const cv::Mat& image, const std::string& path) {
  if (image.empty()) {
    return Status::Error(path + ": cannot write an empty image");
  }
  const int depth = image.depth();
  const int channels = image.channels();
  if ((depth != CV_8U && depth != CV_16U) ||
      (channels != 1 && channels != 3 && channels != 4)) {
    return Status::Error(path + ": PNG holds 8- or 16-bit images with 1, 3 " +
                         "or 4 channels, got " +
                         cv::typeToString(image.type()));
  }
  std::vector<uchar> encoded;
  try {
    if (!cv::imencode(".png", image, encoded)) {
      return Status::Error(path + ": PNG encoding failed");
    }
  } catch (const cv::Exception& error) {
    return Status::Error(path + ": PNG encoding failed: " + error.msg);
  }
  return WriteFileAtomically(path, std::string(encoded.begin(), encoded.end()));
}

namespace {

StatusOr<cv::Mat> DecodeFile(const std::string& path, int flags) {
  StatusOr<std::string> contents = ReadFileToString(path);
  if (!contents.ok()) return contents.status();
  const std::string& bytes = *contents;
  cv::Mat image;
  if (!bytes.empty()) {
    try {
      const cv::Mat buffer(1, static_cast<int>(bytes.size()), CV_8UC1,
                           const_cast<char*>(bytes.data()));
      image = cv::imdecode(buffer, flags);
    } catch (const cv::Exception&) {
      image = cv::Mat();
    }
  }
  if (image.empty()) {
    return Status::Error(
        path +
        ": not an image OpenCV can decode (corrupt or unsupported format)");
  }
  return image;
}

}  // namespace

StatusOr<cv::Mat> ReadImage(const std::string& path, bool grayscale) {
  return DecodeFile(path,
                    grayscale ? cv::IMREAD_GRAYSCALE : cv::IMREAD_COLOR);
}

StatusOr<cv::Mat> ReadImageAsStored(const std::string& path) {
  return DecodeFile(path, cv::IMREAD_UNCHANGED);
}

}  // namespace rcm
