// Per-pixel cost of the lens models and the refractive camera: the inner
// loop of undistortion maps, feature normalization and the estimators.
#include <benchmark/benchmark.h>

#include <vector>

#include "rcm/camera/camera.h"
#include "rcm/camera/refractive_camera.h"
#include "rcm/sim/reference_rigs.h"

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
BENCHMARK(BM_Undistort)->DenseRange(0, 2);

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
BENCHMARK(BM_Distort)->DenseRange(0, 2);

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

}  // namespace
}  // namespace rcm
