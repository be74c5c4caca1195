#include "reference_depth_flag.h"

#include <algorithm>
#include <optional>

#include "rcm/camera/dome_port_camera.h"
#include "rcm/estimation/dome_port_error.h"
#include "rcm/util/number_format.h"

DEFINE_double(reference_depth, 2.0,
              "with a thick port or a dome (camchain port blocks): depth in "
              "meters at which the central water-side camera is exact; "
              "nearer and farther points carry the port's parallax");

namespace rcm::cli {

extern const char kReferenceDepthFlagSource[] = __FILE__;

std::string ThickPortNote(const StereoRig& rig) {
  if (!rig.HasThickPort()) return "";
  return "thick port (camchain port blocks): exact for points " +
         FormatFixed(FLAGS_reference_depth, 2) +
         " m in front of the cameras (--reference-depth); nearer and farther "
         "points carry the port's parallax";
}

StatusOr<DomeDepthErrors> DomeErrorsAtDepths(const Camera& camera,
                                             const DomePort& dome, double n) {
  const StatusOr<DomePortCamera> through =
      DomePortCamera::Create(camera, dome, n);
  if (!through.ok()) return through.status();
  DomePortErrorOptions options;
  options.min_depth = std::max(0.3, DomeOuterSurfaceMaxDepth(dome) + 0.01);
  options.max_depth = std::max(options.min_depth, 10.0);
  options.num_depths = 6;
  options.grid_step = 16.0;
  options.reference_depth = FLAGS_reference_depth;
  const StatusOr<DomePortError> error =
      EvaluateDomePortError(*through, options);
  if (!error.ok()) return error.status();
  DomeDepthErrors result;
  for (const DomePortErrorAtDepth& at : error->depths) {
    result.depths.push_back(at.depth);
    result.max_px.push_back(at.central ? at.central->max_px : 0.0);
  }
  return result;
}

std::string DomeNote(const StereoRig& rig, const std::array<DomePort, 2>& domes,
                     double n) {
  std::string note = "dome (camchain port blocks): exact for points " +
                     FormatFixed(FLAGS_reference_depth, 2) +
                     " m in front of the cameras (--reference-depth)";
  std::optional<DomeDepthErrors> worst;
  for (int c = 0; c < 2; ++c) {
    const StatusOr<DomeDepthErrors> errors =
        DomeErrorsAtDepths(c == 0 ? rig.left() : rig.right(), domes[c], n);
    if (!errors.ok()) continue;
    if (!worst) {
      worst = *errors;
      continue;
    }
    for (size_t k = 0; k < worst->max_px.size(); ++k) {
      worst->max_px[k] = std::max(worst->max_px[k], errors->max_px[k]);
    }
  }
  if (!worst || worst->depths.empty()) return note;
  return note + "; the parallax of its rays: " +
         FormatFixed(worst->max_px.front(), 2) + " px at " +
         FormatFixed(worst->depths.front(), 2) + " m, " +
         FormatFixed(worst->max_px.back(), 2) + " px at " +
         FormatFixed(worst->depths.back(), 1) + " m";
}

nlohmann::json DomeParallaxJson(const StereoRig& rig,
                                const std::array<DomePort, 2>& domes,
                                double n) {
  nlohmann::json json = nlohmann::json::array();
  for (int c = 0; c < 2; ++c) {
    const StatusOr<DomeDepthErrors> errors =
        DomeErrorsAtDepths(c == 0 ? rig.left() : rig.right(), domes[c], n);
    if (!errors.ok()) {
      json.push_back(nullptr);
      continue;
    }
    nlohmann::json camera = nlohmann::json::array();
    for (size_t k = 0; k < errors->depths.size(); ++k) {
      camera.push_back(
          {{"depth_m", errors->depths[k]}, {"max_px", errors->max_px[k]}});
    }
    json.push_back(camera);
  }
  return json;
}

}  // namespace rcm::cli
