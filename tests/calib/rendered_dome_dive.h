// A rendered dome dive (issue 33) for the calibration tests and
// benchmarks/dome_monte_carlo.cc: a 9x6 chessboard of 40 mm squares at
// 0.4-1.4 m (the axial decentering needs distances), rendered through each
// camera's decentered dome in water (TargetRenderer from a DomePortCamera,
// a 0.5 px blur and 2 gray levels of noise: a sharp, well-exposed image),
// detected by the library's detector, and the decentering calibrated with
// the true air lenses and n held, the board's bow estimated as on a real
// dive.
#ifndef RCM_TESTS_CALIB_RENDERED_DOME_DIVE_H_
#define RCM_TESTS_CALIB_RENDERED_DOME_DIVE_H_

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <utility>
#include <vector>

#include "calib/synthetic_target_views.h"
#include "rcm/calib/calibration_target.h"
#include "rcm/calib/dome_calibration.h"
#include "rcm/calib/target_detector.h"
#include "rcm/calib/target_image.h"
#include "rcm/calib/target_observation.h"
#include "rcm/calib/target_renderer.h"
#include "rcm/camera/dome_port_camera.h"
#include "rcm/camera/dome_port_geometry.h"
#include "rcm/stereo/stereo_rig.h"
#include "rcm/util/status.h"

namespace rcm::calib::test {

constexpr double kDomeDiveWaterIndex = 1.333;

struct DomeDiveOptions {
  int num_poses = 16;
  // The board poses' seed (BoardPoses).
  unsigned pose_seed = 0;
  // View v of camera c is rendered with noise seed noise_seed + 2 v + c.
  uint64_t noise_seed = 0;
  // The renderer's threads (CalibrateDomeDive takes its own).
  int num_threads = 2;
};

struct DomeDive {
  CalibrationTarget target;
  std::vector<StereoView> views;
  // The calibration's inputs: the air lenses, the domes' glass centred
  // (the start).
  std::vector<DomeCameraInput> inputs;
  int corners = 0;  // detected, over all views and cameras
};

// Renders and detects a dive through `domes` (one: the left camera alone;
// two: the pair, cam1 at rig.right_from_left()).
inline DomeDive RenderDomeDive(const StereoRig& rig,
                               const std::vector<DomePort>& domes,
                               const DomeDiveOptions& options) {
  DomeDive dive;
  dive.target = MakeCheckerboardTarget(9, 6, 0.04).value();
  const TargetImage texture = DrawTargetImage(dive.target, 4000.0);
  const int num_cameras = static_cast<int>(domes.size());
  const Camera* lenses[2] = {&rig.left(), &rig.right()};
  std::vector<TargetRenderer> renderers;
  for (int c = 0; c < num_cameras; ++c) {
    const DomePortCamera through =
        DomePortCamera::Create(*lenses[c], domes[c], kDomeDiveWaterIndex)
            .value();
    renderers.push_back(TargetRenderer::Create(through, texture).value());
    DomePort centred = domes[c];
    centred.decentering.setZero();
    dive.inputs.push_back({*lenses[c], centred});
  }
  TargetRenderOptions render;
  render.noise_sigma = 2.0;
  render.blur_sigma_px = 0.5;
  render.num_threads = options.num_threads;
  const std::vector<Rigid3d> poses =
      BoardPoses(rig.left(), dive.target, options.num_poses, options.pose_seed,
                 0.4, 1.4, 35.0, kDomeDiveWaterIndex);
  for (size_t v = 0; v < poses.size(); ++v) {
    StereoView view;
    std::optional<TargetObservation>* sides[2] = {&view.left, &view.right};
    for (int c = 0; c < num_cameras; ++c) {
      render.seed = options.noise_seed + 2 * v + c;
      const Rigid3d pose = c == 0 ? poses[v] : rig.right_from_left() * poses[v];
      *sides[c] = DetectTarget(renderers[c].Render(pose, render), dive.target);
      dive.corners += *sides[c] ? static_cast<int>((*sides[c])->size()) : 0;
    }
    dive.views.push_back(std::move(view));
  }
  return dive;
}

// The decentering of `dive`'s domes, n held at the truth (default options
// otherwise: the flat and bowed board candidates), without the
// conventional fit; `folds` and `weigh_views` as DomeCalibrationOptions.
inline StatusOr<DomeCalibration> CalibrateDomeDive(const DomeDive& dive,
                                                   const StereoRig& rig,
                                                   int num_threads = 2,
                                                   int folds = 10,
                                                   bool weigh_views = true) {
  DomeCalibrationOptions options;
  options.folds = folds;
  options.weigh_views = weigh_views;
  options.n = kDomeDiveWaterIndex;
  options.fit_conventional_model = false;
  options.num_threads = num_threads;
  return CalibrateDome(dive.views, dive.inputs, rig.right_from_left(),
                       dive.target, options);
}

}  // namespace rcm::calib::test

#endif  // RCM_TESTS_CALIB_RENDERED_DOME_DIVE_H_
