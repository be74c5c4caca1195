#include "rcm/frontend/image_preprocessing.h"

#include <opencv2/imgproc.hpp>
#include <sstream>
#include <string>

namespace rcm {
namespace {

Status CheckImage(const cv::Mat& image, const char* name) {
  if (image.empty()) {
    return Status::Error(std::string(name) + " image is empty");
  }
  if (image.depth() != CV_8U ||
      (image.channels() != 1 && image.channels() != 3 &&
       image.channels() != 4)) {
    return Status::Error(std::string(name) + " image is " +
                         cv::typeToString(image.type()) +
                         ": expected 8-bit gray, BGR or BGRA (CV_8UC1, "
                         "CV_8UC3, CV_8UC4)");
  }
  return Status::Ok();
}

}  // namespace

Status ClaheOptions::Check() const {
  if (!(clip_limit > 0.0)) {
    return Status::Error("CLAHE clip limit must be positive, got " +
                         std::to_string(clip_limit));
  }
  if (tiles < 1) {
    return Status::Error("CLAHE needs at least 1 tile per side, got " +
                         std::to_string(tiles));
  }
  return Status::Ok();
}

Status CheckStereoImages(const cv::Mat& left, const cv::Mat& right) {
  RCM_RETURN_IF_ERROR(CheckImage(left, "left"));
  RCM_RETURN_IF_ERROR(CheckImage(right, "right"));
  if (left.size() != right.size()) {
    std::ostringstream message;
    message << "left image is " << left.cols << " x " << left.rows
            << ", right image " << right.cols << " x " << right.rows
            << ": a stereo pair needs images of one size";
    return Status::Error(message.str());
  }
  return Status::Ok();
}

cv::Mat PreprocessImage(const cv::Mat& image, const ClaheOptions& options) {
  cv::Mat gray = image;
  if (image.channels() != 1) {
    cv::cvtColor(
        image, gray,
        image.channels() == 3 ? cv::COLOR_BGR2GRAY : cv::COLOR_BGRA2GRAY);
  }
  if (!options.enabled) return gray;
  cv::Mat equalized;
  cv::createCLAHE(options.clip_limit, cv::Size(options.tiles, options.tiles))
      ->apply(gray, equalized);
  return equalized;
}

}  // namespace rcm
