// A frame's matches colored by the refractive index each one asks for
// (estimation/match_refractive_index.h), drawn on the left image with a
// color bar: the picture of the paper's Fig. 6b. Matches near the image
// axes, which do not observe n, scatter widely; those toward the corners
// agree. A match with no n of its own is drawn as a gray ring.
#ifndef RCM_VIZ_MATCH_INDEX_IMAGE_H_
#define RCM_VIZ_MATCH_INDEX_IMAGE_H_

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

namespace rcm {

struct MatchIndexImageOptions {
  // The color scale spans center +- half_range (turbo colormap: blue low,
  // red high); values beyond it take the end colors.
  double center = 1.333;
  double half_range = 0.05;
  // Dot radius, pixels of the input image.
  int radius = 3;
  // Printed above the image.
  std::string title;
};

// `image`: 8-bit gray or BGR; `pixels` and `n` one entry per match (left
// raw pixels). Returns a BGR image: a title strip, the image with the
// dots, and a color bar with tick labels on the right.
cv::Mat DrawMatchesByRefractiveIndex(
    const cv::Mat& image, const std::vector<Eigen::Vector2d>& pixels,
    const std::vector<std::optional<double>>& n,
    const MatchIndexImageOptions& options);

}  // namespace rcm

#endif  // RCM_VIZ_MATCH_INDEX_IMAGE_H_
