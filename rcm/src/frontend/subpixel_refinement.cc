#include "rcm/frontend/subpixel_refinement.h"

#include <cmath>
#include <opencv2/video/tracking.hpp>

namespace rcm {

Status SubpixelOptions::Check() const {
  if (window < 5 || window % 2 == 0) {
    return Status::Error("subpixel window must be odd and at least 5, got " +
                         std::to_string(window));
  }
  if (max_iterations < 1) {
    return Status::Error("subpixel refinement needs at least 1 iteration");
  }
  if (!(min_step_px > 0.0) || !(max_shift_px > 0.0)) {
    return Status::Error("subpixel step and shift limits must be positive");
  }
  return Status::Ok();
}

void RefineRightPixels(const cv::Mat& left_gray, const cv::Mat& right_gray,
                       const std::vector<cv::Point2f>& left,
                       std::vector<cv::Point2f>* right,
                       std::vector<unsigned char>* kept,
                       const SubpixelOptions& options) {
  CHECK_EQ(left.size(), right->size());
  CHECK(options.Check().ok()) << options.Check().message();
  kept->assign(left.size(), 1);
  if (!options.enabled || left.empty()) return;
  const std::vector<cv::Point2f> start = *right;
  std::vector<float> errors;
  cv::calcOpticalFlowPyrLK(
      left_gray, right_gray, left, *right, *kept, errors,
      cv::Size(options.window, options.window), /*maxLevel=*/0,
      cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS,
                       options.max_iterations, options.min_step_px),
      cv::OPTFLOW_USE_INITIAL_FLOW);
  for (size_t i = 0; i < left.size(); ++i) {
    const cv::Point2f shift = (*right)[i] - start[i];
    if (!(std::hypot(shift.x, shift.y) <= options.max_shift_px)) {
      (*kept)[i] = 0;
    }
    if (!(*kept)[i]) (*right)[i] = start[i];
  }
}

}  // namespace rcm
