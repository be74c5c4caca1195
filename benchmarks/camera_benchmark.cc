// Per-pixel cost of the lens models and the refractive camera: the inner
// loop of undistortion maps, feature normalization and the estimators.
#include <benchmark/benchmark.h>

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "rcm/camera/camera.h"
#include "rcm/camera/refractive_camera.h"
#include "rcm/camera/virtual_pinhole_remap.h"
#include "rcm/sim/reference_rigs.h"
#include "rcm/stereo/virtual_pinhole_rig.h"

namespace rcm {
namespace {

Camera CameraFor(LensModelId model) {
  switch (model) {
    case LensModelId::kPinhole:
      return Camera::Create(LensModelId::kPinhole, 640, 480,
                            {400.0, 400.0, 319.5, 239.5}, {})
          .value();
    case LensModelId::kRadTan:
      return EurocCam0();
    case LensModelId::kEquidistant:
      return AlphasenseFrontCam0();
    // The three of issue 21 on the sizes of the tests' cameras
    // (tests/support/test_rigs.cc).
    case LensModelId::kRational:
      return Camera::Create(
                 LensModelId::kRational, 752, 480, {461.3, 460.8, 371.9, 243.6},
                 {0.5, 0.1, 9.0e-4, -6.0e-4, 0.001, 0.75, 0.2, 0.001})
          .value();
    case LensModelId::kDoubleSphere:
      return Camera::Create(LensModelId::kDoubleSphere, 640, 480,
                            {300.2, 299.7, 318.4, 241.9}, {-0.18, 0.59})
          .value();
    case LensModelId::kEucm:
      return Camera::Create(LensModelId::kEucm, 640, 480,
                            {320.4, 319.8, 321.1, 238.6}, {0.63, 1.04})
          .value();
  }
  return AlphasenseFrontCam0();
}

// A fixed grid of pixels over the image (so every run does the same work).
std::vector<Eigen::Vector2d> Pixels(const Camera& camera) {
  std::vector<Eigen::Vector2d> pixels;
  for (int v = 0; v < camera.height(); v += 17) {
    for (int u = 0; u < camera.width(); u += 13) pixels.emplace_back(u, v);
  }
  return pixels;
}

void BM_Undistort(benchmark::State& state) {
  const Camera camera = CameraFor(static_cast<LensModelId>(state.range(0)));
  const std::vector<Eigen::Vector2d> pixels = Pixels(camera);
  size_t i = 0;
  for (auto _ : state) {
    Eigen::Vector2d normalized;
    benchmark::DoNotOptimize(
        camera.NormalizedFromImage(pixels[i].data(), normalized.data()));
    benchmark::DoNotOptimize(normalized);
    i = (i + 1 == pixels.size()) ? 0 : i + 1;
  }
  state.SetItemsProcessed(state.iterations());
  state.SetLabel(std::string(LensModelName(camera.model())));
}
BENCHMARK(BM_Undistort)->DenseRange(0, kNumLensModels - 1);

void BM_Distort(benchmark::State& state) {
  const Camera camera = CameraFor(static_cast<LensModelId>(state.range(0)));
  std::vector<Eigen::Vector2d> normalized;
  for (const Eigen::Vector2d& pixel : Pixels(camera)) {
    normalized.push_back(*camera.NormalizedFromImage(pixel));
  }
  size_t i = 0;
  for (auto _ : state) {
    Eigen::Vector2d pixel;
    camera.ImageFromNormalized(normalized[i].data(), pixel.data());
    benchmark::DoNotOptimize(pixel);
    i = (i + 1 == normalized.size()) ? 0 : i + 1;
  }
  state.SetItemsProcessed(state.iterations());
  state.SetLabel(std::string(LensModelName(camera.model())));
}
BENCHMARK(BM_Distort)->DenseRange(0, kNumLensModels - 1);

void BM_BearingInWaterFromImage(benchmark::State& state) {
  const RefractiveCamera camera =
      RefractiveCamera::Create(AlphasenseFrontCam0(), 1.333).value();
  const std::vector<Eigen::Vector2d> pixels = Pixels(camera.camera());
  size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(camera.BearingInWaterFromImage(pixels[i]));
    i = (i + 1 == pixels.size()) ? 0 : i + 1;
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_BearingInWaterFromImage);

void BM_ImageFromPointInWater(benchmark::State& state) {
  const RefractiveCamera camera =
      RefractiveCamera::Create(AlphasenseFrontCam0(), 1.333).value();
  std::vector<Eigen::Vector3d> points;
  for (const Eigen::Vector2d& pixel : Pixels(camera.camera())) {
    points.push_back(2.0 * *camera.BearingInWaterFromImage(pixel));
  }
  size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(camera.ImageFromPointInWater(points[i]));
    i = (i + 1 == points.size()) ? 0 : i + 1;
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_ImageFromPointInWater);

// Virtual pinhole maps of the 720x540 Alphasense camera: n = range(0) /
// 1000 on range(1) threads, for the K_n view.
void BM_BuildVirtualPinholeMaps(benchmark::State& state) {
  const RefractiveCamera camera =
      RefractiveCamera::Create(AlphasenseFrontCam0(), state.range(0) / 1000.0)
          .value();
  const VirtualPinholeView view = ChooseVirtualPinholeView(camera).value();
  const int num_threads = static_cast<int>(state.range(1));
  for (auto _ : state) {
    benchmark::DoNotOptimize(
        BuildVirtualPinholeMaps(camera, view, num_threads).value());
  }
  state.SetItemsProcessed(state.iterations() * view.width * view.height);
}
BENCHMARK(BM_BuildVirtualPinholeMaps)
    ->ArgsProduct({{1000, 1333, 1500}, {1, 2}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// The bisection for the view without black borders (n = 1.333).
void BM_NoBorderVirtualPinholeView(benchmark::State& state) {
  const RefractiveCamera camera =
      RefractiveCamera::Create(AlphasenseFrontCam0(), 1.333).value();
  for (auto _ : state) {
    benchmark::DoNotOptimize(
        ChooseVirtualPinholeView(camera, VirtualPinholeFit::kNoBorder).value());
  }
}
BENCHMARK(BM_NoBorderVirtualPinholeView)->Unit(benchmark::kMillisecond);

// The bisection for the view that keeps the whole field of view (n =
// 1.333).
void BM_FullFieldOfViewVirtualPinholeView(benchmark::State& state) {
  const RefractiveCamera camera =
      RefractiveCamera::Create(AlphasenseFrontCam0(), 1.333).value();
  for (auto _ : state) {
    benchmark::DoNotOptimize(
        ChooseVirtualPinholeView(camera, VirtualPinholeFit::kFullFieldOfView)
            .value());
  }
}
BENCHMARK(BM_FullFieldOfViewVirtualPinholeView)->Unit(benchmark::kMillisecond);

// Everything `rcm undistort` does once per n: both cameras' views of the
// 720x540 dataset rig (0.5 degrees from rectified) chosen by fit range(0)
// (0 virtual-pinhole, 1 no-border, 2 full), rectified when range(1), and
// both cameras' float and fixed-point maps built on two threads. n = 1.333.
void BM_BuildVirtualPinholeRig(benchmark::State& state) {
  const StereoRig rig = AlphasenseFrontUnrectifiedRig();
  VirtualPinholeRigOptions options;
  options.fit = static_cast<VirtualPinholeFit>(state.range(0));
  options.rectify = state.range(1) != 0;
  options.num_threads = 2;
  for (auto _ : state) {
    benchmark::DoNotOptimize(
        VirtualPinholeRig::Create(rig, 1.333, options).value());
  }
  state.SetLabel(std::string(VirtualPinholeFitName(options.fit)) +
                 (options.rectify ? ", rectified" : ""));
}
BENCHMARK(BM_BuildVirtualPinholeRig)
    ->ArgsProduct({{0, 1, 2}, {0, 1}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// Correcting one 720x540 stereo pair with a built rig (both images, the
// fixed-point maps): the per-pair cost of `rcm undistort` before decoding
// and encoding.
void BM_CorrectStereoPair(benchmark::State& state) {
  const VirtualPinholeRig rig =
      VirtualPinholeRig::Create(AlphasenseFrontUnrectifiedRig(), 1.333).value();
  cv::Mat left(540, 720, CV_8UC1);
  cv::Mat right(540, 720, CV_8UC1);
  cv::RNG rng(1);
  rng.fill(left, cv::RNG::UNIFORM, 0, 256);
  rng.fill(right, cv::RNG::UNIFORM, 0, 256);
  for (auto _ : state) {
    benchmark::DoNotOptimize(rig.left().Correct(left));
    benchmark::DoNotOptimize(rig.right().Correct(right));
  }
}
BENCHMARK(BM_CorrectStereoPair)->Unit(benchmark::kMicrosecond)->UseRealTime();

// Remapping one 720x540 CV_8UC1 image (n = 1.333): range(0) = 1 with the
// fixed-point maps, 0 with the float maps.
void BM_RemapToVirtualPinhole(benchmark::State& state) {
  const RefractiveCamera camera =
      RefractiveCamera::Create(AlphasenseFrontCam0(), 1.333).value();
  const VirtualPinholeView view = ChooseVirtualPinholeView(camera).value();
  const RemapMaps maps =
      BuildVirtualPinholeMaps(camera, view, 2, state.range(0) != 0).value();
  cv::Mat raw(540, 720, CV_8UC1);
  cv::RNG rng(1);
  rng.fill(raw, cv::RNG::UNIFORM, 0, 256);
  for (auto _ : state) {
    benchmark::DoNotOptimize(RemapToVirtualPinhole(raw, maps));
  }
  state.SetLabel(state.range(0) != 0 ? "fixed-point maps" : "float maps");
}
BENCHMARK(BM_RemapToVirtualPinhole)
    ->Arg(0)
    ->Arg(1)
    ->Unit(benchmark::kMicrosecond)
    ->UseRealTime();

}  // namespace
}  // namespace rcm
