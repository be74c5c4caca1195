// What `rcm estimate` prints of a RefractiveIndexEstimate beside its JSON
// (rcm/estimation/estimate_json.h): the text report's lines and the plot of
// n per frame. Formatting only; the estimate and its warnings come from the
// library.
#ifndef RCM_EXAMPLES_CLI_ESTIMATE_REPORT_H_
#define RCM_EXAMPLES_CLI_ESTIMATE_REPORT_H_

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "rcm/estimation/refractive_index_estimate.h"

namespace rcm::cli {

// The estimator's own lines (seeds, air gap, rotation, lenses; skipped
// frames; switches and the window; the closed form's mask).
std::vector<std::string> EstimatorLines(const RefractiveIndexEstimate& e);

// The n line, the pixel noise and what the estimate says of the
// calibration and the frames.
std::vector<std::string> UncertaintyLines(const RefractiveIndexEstimate& e);

// n per frame with its 1-sigma band, and the final estimate.
cv::Mat PlotPerFrame(const RefractiveIndexEstimate& e);
// The bundle's trajectory seen from above (x and z of the left camera in
// the first keyframe's frame), its title n and cam1's turn.
cv::Mat PlotTrajectory(const RefractiveIndexEstimate& e);

}  // namespace rcm::cli

#endif  // RCM_EXAMPLES_CLI_ESTIMATE_REPORT_H_
