// Reading correspondence files: a 20 Hz run of an hour with 200 matches a
// frame is 14 million rows, so parsing must run at millions of rows/s.
#include <benchmark/benchmark.h>

#include <string>
#include <vector>

#include "rcm/io/correspondence_csv.h"
#include "rcm/sim/reference_rigs.h"
#include "rcm/sim/stereo_sampler.h"

namespace rcm {
namespace {

void BM_ParseCorrespondenceCsv(benchmark::State& state) {
  StereoSamplerOptions options;
  options.num_frames = 50;
  options.per_frame = 200;
  std::vector<StereoCorrespondence> matches =
      SampleStereoCorrespondences(AlphasenseFrontRectifiedRig(), options)
          .value();
  AddPixelNoise(0.3, 1, &matches);
  const std::string text = FormatCorrespondenceCsv(matches);
  for (auto _ : state) {
    benchmark::DoNotOptimize(ParseCorrespondenceCsv(text, "bench.csv"));
  }
  state.SetItemsProcessed(state.iterations() * matches.size());
  state.SetBytesProcessed(state.iterations() * text.size());
}
BENCHMARK(BM_ParseCorrespondenceCsv);

}  // namespace
}  // namespace rcm
