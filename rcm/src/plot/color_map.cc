#include "rcm/plot/color_map.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <mutex>

namespace rcm {
namespace {

// The 256 colours of a map, made once per map.
const cv::Mat& ColorMapTable(cv::ColormapTypes colormap) {
  static std::mutex mutex;
  static std::map<int, cv::Mat> tables;
  const std::lock_guard<std::mutex> lock(mutex);
  cv::Mat& table = tables[colormap];
  if (table.empty()) {
    cv::Mat ramp(1, 256, CV_8UC1);
    for (int i = 0; i < 256; ++i) ramp.at<unsigned char>(0, i) = i;
    cv::applyColorMap(ramp, table, colormap);
  }
  return table;
}

}  // namespace

cv::Vec3b ColorMapColor(cv::ColormapTypes colormap, double t) {
  const double clamped = std::clamp(std::isfinite(t) ? t : 0.0, 0.0, 1.0);
  const int index = static_cast<int>(std::lround(clamped * 255));
  return ColorMapTable(colormap).at<cv::Vec3b>(0, index);
}

}  // namespace rcm
