// Cost per correspondence of the closed form and the paper's estimator,
// and of the first-order sigma (a Jet pass through both undistortions).
#include <benchmark/benchmark.h>

#include <vector>

#include "rcm/estimation/closed_form.h"
#include "rcm/estimation/paper_online_estimator.h"
#include "rcm/geometry/observability.h"
#include "rcm/sim/reference_rigs.h"
#include "rcm/sim/stereo_sampler.h"

namespace rcm {
namespace {

std::vector<StereoCorrespondence> Matches(const StereoRig& rig) {
  StereoSamplerOptions options;
  options.per_frame = 4096;
  std::vector<StereoCorrespondence> matches =
      SampleStereoCorrespondences(rig, options).value();
  AddPixelNoise(0.3, 1, &matches);
  return matches;
}

void BM_ClosedFormFromPixels(benchmark::State& state) {
  const StereoRig rig = AlphasenseFrontRectifiedRig();
  const std::vector<StereoCorrespondence> matches = Matches(rig);
  size_t i = 0;
  for (auto _ : state) {
    const std::optional<NormalizedCorrespondence> normalized =
        rig.Normalize(matches[i]);
    benchmark::DoNotOptimize(ClosedFormN(*normalized));
    i = (i + 1 == matches.size()) ? 0 : i + 1;
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_ClosedFormFromPixels);

void BM_PaperOnlineEstimatorAdd(benchmark::State& state) {
  const StereoRig rig = AlphasenseFrontRectifiedRig();
  const std::vector<StereoCorrespondence> matches = Matches(rig);
  PaperOnlineEstimator estimator(rig, PaperOnlineEstimatorOptions());
  size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(estimator.Add(matches[i]));
    i = (i + 1 == matches.size()) ? 0 : i + 1;
  }
  benchmark::DoNotOptimize(estimator.Current());
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_PaperOnlineEstimatorAdd);

void BM_FirstOrderSigmaN(benchmark::State& state) {
  const StereoRig rig = AlphasenseFrontRectifiedRig();
  const std::vector<StereoCorrespondence> matches = Matches(rig);
  size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(FirstOrderSigmaN(rig, matches[i], 1.333, 0.5));
    i = (i + 1 == matches.size()) ? 0 : i + 1;
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_FirstOrderSigmaN);

}  // namespace
}  // namespace rcm
