// The colour of a value on one of OpenCV's colour maps (cv::COLORMAP_*),
// for figures that colour data by value (matches by n, uncertainty maps).
#ifndef RCM_PLOT_COLOR_MAP_H_
#define RCM_PLOT_COLOR_MAP_H_

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

namespace rcm {

// The BGR colour of t in [0, 1] on `colormap` (cv::ColormapTypes), from
// its 256-entry table; t outside [0, 1] is clamped, and a t that is not
// finite gives the colour of 0.
cv::Vec3b ColorMapColor(cv::ColormapTypes colormap, double t);

}  // namespace rcm

#endif  // RCM_PLOT_COLOR_MAP_H_
