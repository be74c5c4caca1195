// The air calibration of rcm calibrate, by part, on the narrow-field rig
// (640x480, radtan) and a 9x6 board with 25 mm squares at 0.3-0.7 m:
//
//   - DetectTargetPair on one rendered pair, with the pair's two images on
//     one thread and on two (rcm calibrate runs two pairs at once, one
//     thread each);
//   - CalibrateStereo of 32 stereo views at 0.2 px of corner noise, with
//     its covariance, and the default 10-fold leave-out
//     (CrossValidateStereo, two folds at a time), both on 2 threads.
//
// 32 pairs cost 32 detections of a pair plus one calibration and its
// folds; the target for the whole run is 10 s on 2 cores.
// benchmarks/calibrate_32_pairs.sh times the rcm calibrate command itself
// on 32 rendered pairs.
#include <benchmark/benchmark.h>

#include <vector>

#include "calib/synthetic_target_views.h"
#include "rcm/calib/calibration_target.h"
#include "rcm/calib/cross_validation.h"
#include "rcm/calib/stereo_calibration.h"
#include "rcm/calib/target_detector.h"
#include "rcm/calib/target_image.h"
#include "rcm/calib/target_renderer.h"
#include "rcm/sim/reference_rigs.h"

namespace rcm::calib {
namespace {

constexpr int kViews = 32;

CalibrationTarget Board() { return MakeCheckerboardTarget(9, 6, 0.025).value(); }

std::vector<Rigid3d> Poses(const StereoRig& rig) {
  return test::BoardPoses(rig.left(), Board(), kViews, /*seed=*/3, 0.3, 0.7,
                          35.0);
}

void BM_DetectTargetPair(benchmark::State& state) {
  const StereoRig rig = NarrowFieldRig();
  const TargetImage texture = DrawTargetImage(Board(), 3000.0);
  const TargetRenderer left = TargetRenderer::Create(rig.left(), texture).value();
  const TargetRenderer right =
      TargetRenderer::Create(rig.right(), texture).value();
  TargetRenderOptions render;
  render.noise_sigma = 2.0;
  // The first pose with the whole board in both images.
  const std::vector<Rigid3d> poses = Poses(rig);
  const std::vector<StereoView> exact =
      test::ObserveStereo(rig, Board(), poses, 0.0, /*seed=*/1);
  const int points = NumTargetPoints(Board());
  size_t first = 0;
  while (first + 1 < poses.size() &&
         !(exact[first].stereo() && exact[first].left->size() == points &&
           exact[first].right->size() == points)) {
    ++first;
  }
  const Rigid3d pose = poses[first];
  const cv::Mat left_image = left.Render(pose, render);
  const cv::Mat right_image = right.Render(rig.right_from_left() * pose, render);
  TargetDetectorOptions options;
  options.num_threads = static_cast<int>(state.range(0));
  for (auto _ : state) {
    const StereoView view =
        DetectTargetPair(left_image, right_image, Board(), options);
    if (!view.stereo()) {
      state.SkipWithError("the board was not found in both images");
      return;
    }
    benchmark::DoNotOptimize(view.left->pixels.data());
  }
}
BENCHMARK(BM_DetectTargetPair)
    ->ArgName("threads")
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

void BM_CalibrateStereo(benchmark::State& state) {
  const StereoRig rig = NarrowFieldRig();
  const std::vector<StereoView> views =
      test::ObserveStereo(rig, Board(), Poses(rig), 0.2, /*seed=*/1);
  const ImageSize size{rig.left().width(), rig.left().height()};
  StereoCalibrationOptions options;
  options.num_threads = 2;
  const int folds = static_cast<int>(state.range(0));
  for (auto _ : state) {
    const StatusOr<StereoCalibration> calibration =
        CalibrateStereo(Board(), views, size, size, options);
    if (!calibration.ok()) {
      state.SkipWithError(calibration.status().message().c_str());
      return;
    }
    if (folds > 0) {
      CrossValidationOptions cv_options;
      cv_options.folds = folds;
      const StatusOr<CrossValidation> spread = CrossValidateStereo(
          Board(), views, size, size, *calibration, options, cv_options);
      if (!spread.ok()) {
        state.SkipWithError(spread.status().message().c_str());
        return;
      }
      benchmark::DoNotOptimize(spread->parameters.data());
    }
    benchmark::DoNotOptimize(calibration->rms_px);
  }
}
BENCHMARK(BM_CalibrateStereo)
    ->ArgName("folds")
    ->Arg(0)
    ->Arg(10)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace
}  // namespace rcm::calib
