// The image simulator: building the textured pool, and rendering a
// 720x540 stereo pair of the dataset rig (both images, supersampling 2,
// two threads) cold (tracing and caching the sample rays first) and warm
// (transform, intersect and shade only). Run e.g.
//   build/bin/sim_benchmark --benchmark_min_time=2
#include <benchmark/benchmark.h>

#include <cmath>
#include <vector>

#include "rcm/camera/flat_port.h"
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

// The exact flat port: back-trace (two vector refractions) and forward
// projection (Newton on the plane of refraction), per call. Argument 0 is
// the thin port, 1 a 10 mm air gap behind 5 mm of glass, tilted 2 degrees.
FlatPort BenchmarkPort(int thick) {
  FlatPort port;
  if (thick != 0) {
    port.air_gap = 0.01;
    port.glass_thickness = 0.005;
    port.normal = TiltedPortNormal(2.0 * M_PI / 180.0, 0.3);
  }
  return port;
}

std::vector<Eigen::Vector2d> BenchmarkNormalizedPoints() {
  std::vector<Eigen::Vector2d> points;
  for (int i = 0; i < 1024; ++i) {
    const double angle = 1.3 * ((i * 37) % 1024) / 1024.0;  // up to 74 deg
    const double azimuth = 2.0 * M_PI * ((i * 101) % 1024) / 1024.0;
    points.emplace_back(std::tan(angle) * std::cos(azimuth),
                        std::tan(angle) * std::sin(azimuth));
  }
  return points;
}

void BM_FlatPortRayFromNormalized(benchmark::State& state) {
  const ExactFlatPort port =
      ExactFlatPort::Create(BenchmarkPort(state.range(0)), 1.333).value();
  const std::vector<Eigen::Vector2d> points = BenchmarkNormalizedPoints();
  size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(port.RayFromNormalized(points[i++ & 1023]));
  }
}
BENCHMARK(BM_FlatPortRayFromNormalized)->Arg(0)->Arg(1);

void BM_FlatPortNormalizedFromPoint(benchmark::State& state) {
  const ExactFlatPort port =
      ExactFlatPort::Create(BenchmarkPort(state.range(0)), 1.333).value();
  std::vector<Eigen::Vector3d> points;
  for (const Eigen::Vector2d& xb : BenchmarkNormalizedPoints()) {
    const RayInMedium ray = port.RayFromNormalized(xb).value();
    points.push_back(ray.origin + 3.0 * ray.direction);
  }
  size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(port.NormalizedFromPoint(points[i++ & 1023]));
  }
}
BENCHMARK(BM_FlatPortNormalizedFromPoint)->Arg(0)->Arg(1);

}  // namespace
}  // namespace rcm
