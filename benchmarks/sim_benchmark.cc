// The image simulator: building the textured pool, and rendering a
// 720x540 stereo pair of the dataset rig (both images, supersampling 2,
// two threads) cold (tracing and caching the sample rays first) and warm
// (transform, intersect and shade only). Run e.g.
//   build/bin/sim_benchmark --benchmark_min_time=2
#include <benchmark/benchmark.h>

#include <vector>

#include "rcm/sim/reference_rigs.h"
#include "rcm/sim/stereo_renderer.h"
#include "rcm/sim/tank_scene.h"
#include "rcm/sim/trajectory.h"

namespace rcm {
namespace {

const TankScene& Pool() {
  static const TankScene* const scene =
      new TankScene(TankScene::Create(TankSceneOptions()).value());
  return *scene;
}

std::vector<TimedPose> Poses() {
  TrajectoryOptions options;
  options.frames = 200;
  return GenerateTrajectory(Pool(), options).value();
}

// The default 12 x 8 x 3 m pool with its procedural textures.
void BM_TankSceneCreate(benchmark::State& state) {
  for (auto _ : state) {
    benchmark::DoNotOptimize(TankScene::Create(TankSceneOptions()).value());
  }
}
BENCHMARK(BM_TankSceneCreate)->Unit(benchmark::kMillisecond)->UseRealTime();

// A fresh renderer per pair: traces 2 x 1.56 million sample rays through
// lens and port, then renders. n = range(0) / 1000.
void BM_RenderStereoCold(benchmark::State& state) {
  const double n = state.range(0) / 1000.0;
  const StereoRig rig = AlphasenseFrontUnrectifiedRig();
  const std::vector<TimedPose> poses = Poses();
  int64_t frame = 0;
  for (auto _ : state) {
    StereoRenderer renderer =
        StereoRenderer::Create(rig, FlatPort(), FlatPort(), &Pool(),
                               RenderOptions())
            .value();
    benchmark::DoNotOptimize(
        renderer.Render(poses[frame % poses.size()].world_from_cam0, n, frame)
            .value());
    ++frame;
  }
}
BENCHMARK(BM_RenderStereoCold)
    ->Arg(1000)
    ->Arg(1333)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// Rays cached: a pair per frame along the trajectory.
void BM_RenderStereoWarm(benchmark::State& state) {
  const double n = state.range(0) / 1000.0;
  StereoRenderer renderer =
      StereoRenderer::Create(AlphasenseFrontUnrectifiedRig(), FlatPort(),
                             FlatPort(), &Pool(), RenderOptions())
          .value();
  const std::vector<TimedPose> poses = Poses();
  if (!renderer.PrepareRays(n).ok()) state.SkipWithError("bad index");
  int64_t frame = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(
        renderer.Render(poses[frame % poses.size()].world_from_cam0, n, frame)
            .value());
    ++frame;
  }
  state.SetItemsProcessed(state.iterations() * 2 * 720 * 540);
}
BENCHMARK(BM_RenderStereoWarm)
    ->Arg(1000)
    ->Arg(1333)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace
}  // namespace rcm
