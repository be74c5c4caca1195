// The stereo front end at 720x540, per stage and end to end, against the
// issue's acceptance: at least 20 stereo pairs per second with the default
// front end on the 2-core machine while |n - n_true| <= 2e-3 from 10 pairs,
// and at least 5x the pairs per second of the straightforward pipeline.
//
// Data (built once, outside timing): 10 consecutive pairs of the simulated
// pool (SequenceSimulator, default scene and trajectory, 16 degrees down)
// seen by the rectified dataset rig behind exact flat ports in water,
// n_true = 1.333, each image PNG-encoded in memory so that the end-to-end
// runs decode them as a run from files does.
//
// Per stage (pair 0 of the sequence):
//   BM_Decode            cv::imdecode of both PNGs of the pair
//   BM_Preprocess        gray + CLAHE (on) of both images
//   BM_Detect/<type>     keypoints + descriptors of one image (2000 kept)
//   BM_BandKeys          LocusBand keys of the left image's ORB keypoints
//                        (the front end computes them for both images)
//   BM_GuidedMatch/<i>   MatchInLocusBand (2 threads, keys precomputed) in
//                        the prior interval [1.0, 1.6] or the guided one
//                        1.333 +- 0.01
//   BM_SubpixelRefine/<fit>
//                        subpixel refinement (2 threads) of the prior
//                        band's matches: the default affine fit, or the
//                        translation alone
//   BM_Estimate/<t>      RefineRefractiveIndex on one pair's front-end
//                        matches, 1 thread (the per-frame guide) or 2
//   BM_EstimateSequence  RefineRefractiveIndex (2 threads) over all 10
//                        pairs' matches: the final estimate end to end
//   BM_FrontEndMatch/<i> StereoFrontEnd::Match of one decoded pair (default
//                        options, 2 threads), prior or guided interval
//
// End to end, per iteration the whole 10-pair sequence from the PNGs
// (pairs_per_second = pairs / wall time; n, n_error = n - 1.333, sigma_n of
// the final estimate; matches_per_pair):
//   BM_EndToEnd_Default        per pair: decode both PNGs at once,
//                              StereoFrontEnd::Match (ORB, default options,
//                              2 threads) guided by the previous pair's own
//                              RefineRefractiveIndex estimate (n +- max(6
//                              sigma, 0.01); prior interval for the first
//                              pair); then RefineRefractiveIndex over all
//                              pairs' matches
//   BM_EndToEnd_PriorBand      the same, every pair in the prior interval
//                              (no guide)
//   BM_EndToEnd_SiftFrontEnd   BM_EndToEnd_Default with FeatureType::kSift
//   BM_EndToEnd_Straightforward  per pair, sequentially as a plain script
//                              would: decode, cv::SIFT::create()
//                              detectAndCompute on each full image (no
//                              keypoint limit), cv::BFMatcher(NORM_L2)
//                              knnMatch k = 2, Lowe's ratio 0.8; then the
//                              paper's closed form (PaperOnlineEstimator,
//                              eta = 0.3, radially weighted mean) fed every
//                              match
//
// Measured (Release, the 2-core machine with nothing else running: CPUs
// 100 % idle before each run, load average 0.9-1.4 from earlier builds):
//   per stage, ms: decode 4.9 (both PNGs, 247 kB each, one after the other);
//   CLAHE 1.4 (both images); detect one image: ORB 3.1, SIFT 90, AKAZE 37
//   (487 keypoints); band keys 0.34 (2000 keypoints); band matching 8.6 in
//   the prior interval, 1.3 guided (1240 matches of 2000 x 2000 keypoints);
//   subpixel 8.5 affine, 6.5 translation only (1240 matches); estimate 5.8
//   (1 thread), 4.9 (2 threads) for 1190 matches; front end per pair 20.9
//   prior, 13.8-15.6 guided (detect 3.4, match 2.2, refine 9); final
//   estimate over 12027 matches of 10 pairs 45-53.
//   end to end, 10 pairs (n_error from the 10 pairs):
//     default front end (ORB, guided)  34 pairs/s  n_error -6.1e-5  (sigma_n
//                                      1.1e-4, 1203 matches per pair)
//     prior band, no guide             34 pairs/s  n_error -5.1e-5
//     SIFT front end                   5.5 pairs/s n_error +3.2e-4
//     straightforward                  4.1 pairs/s n_error +3.8e-3  (sigma_n
//                                      2.2e-3, 1659 matches per pair)
//   default / straightforward: 8.4x (7.3x-8.6x over runs).
//   BM_EndToEnd_Engine         the sequence engine as `rcm estimate` runs it
//                              (the rig with the default drift priors, the
//                              field test on), window_matches 100/200/400:
//                              0.94/0.88/0.92 s for the 10 pairs; 0.71/0.75/
//                              0.80 s with the refinement's Jacobian written
//                              out (2026-12-05)
//   BM_EndToEnd_RcmProcess     the whole `rcm estimate` process on the PNG
//                              folders: 1.06-1.15 s, 3.7-5.5x one
//                              straightforward run of the same benchmark
//                              over three runs; 1.05 s, 4.1x with the
//                              Jacobian written out; 0.73 s, 5.3x with the
//                              heap padded too. Since 2026-12-05 each of 5
//                              iterations times the process and then one
//                              straightforward run (the machine's speed
//                              drifts by tens of percent from minute to
//                              minute), compared by their fastest runs and
//                              by their medians: with the refinement's
//                              blocks of matches and the next pair detected
//                              on the reader thread, fastest 0.59 s against
//                              4.39 s (7.4x), medians 7.2x, in a slow
//                              phase of the machine; 0.46-0.48 s in a fast
//                              one, where the straightforward run took
//                              2.9-3.8 s. On 2026-12-06 (no line search in
//                              the solves, the preparations threaded, the
//                              subpixel sampling vectorized, the frames'
//                              rows taken once): 0.40-0.51 s against
//                              1.9-4.7 s, 4.8-9.3x over four runs
//                              (docs/numbers.md)
//
// Run e.g.
//   build/bin/frontend_benchmark
//   build/bin/frontend_benchmark --benchmark_filter=EndToEnd
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <future>
#include <iterator>
#include <memory>
#include <opencv2/features2d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <optional>
#include <string>
#include <vector>

#include "rcm/estimation/batch_refinement.h"
#include "rcm/estimation/paper_online_estimator.h"
#include "rcm/frontend/feature_detector.h"
#include "rcm/frontend/guided_matcher.h"
#include "rcm/frontend/image_preprocessing.h"
#include "rcm/frontend/locus_band.h"
#include "rcm/frontend/stereo_front_end.h"
#include "rcm/frontend/subpixel_refinement.h"
#include "rcm/io/camchain.h"
#include "rcm/io/stereo_rig_file.h"
#include "rcm/live/sequence_estimator.h"
#include "rcm/sim/reference_rigs.h"
#include "rcm/sim/sequence_simulator.h"

namespace rcm {
namespace {

constexpr int kPairs = 10;
constexpr double kTrueN = 1.333;
constexpr double kFrameRate = 20.0;  // Hz, the simulator's trajectory

// The guide of a pair from the previous pair's estimate (stereo_front_end.h).
constexpr double kGuideSigmas = 6.0;
constexpr double kGuideMinHalfWidth = 0.01;

struct EncodedPair {
  std::vector<uchar> left;  // PNG
  std::vector<uchar> right;
};

struct Sequence {
  StereoRig rig;
  std::vector<EncodedPair> pairs;
};

// The 10 pairs, rendered and PNG-encoded on first use.
const Sequence& Data() {
  static const Sequence* const data = [] {
    auto* sequence = new Sequence{AlphasenseFrontRectifiedRig(), {}};
    SequenceOptions options;
    options.media = {MediaSegment{kTrueN, kPairs}};
    std::unique_ptr<SequenceSimulator> simulator =
        SequenceSimulator::Create(sequence->rig, options).value();
    for (int i = 0; i < kPairs; ++i) {
      const SequenceFrame frame = simulator->Frame(i).value();
      EncodedPair pair;
      CHECK(cv::imencode(".png", frame.left, pair.left));
      CHECK(cv::imencode(".png", frame.right, pair.right));
      sequence->pairs.push_back(std::move(pair));
    }
    return sequence;
  }();
  return *data;
}

cv::Mat Decode(const std::vector<uchar>& png) {
  return cv::imdecode(png, cv::IMREAD_UNCHANGED);
}

// Pair 0 decoded, and the front end's intermediate results on it, for the
// per-stage benchmarks.
struct StageInputs {
  cv::Mat left;  // CV_8UC1, as decoded
  cv::Mat right;
  Features left_features;  // ORB, default options
  Features right_features;
  std::vector<LocusKey> left_keys;  // in the prior interval
  std::vector<LocusKey> right_keys;
  std::vector<KeypointMatch> prior_matches;
  std::vector<StereoCorrespondence> front_end_matches;  // prior interval
};

RefractiveIndexInterval PriorInterval() {
  return StereoFrontEndOptions().search_range;
}

RefractiveIndexInterval GuidedInterval() {
  return RefractiveIndexInterval::Around(kTrueN, 0.0, kGuideSigmas,
                                         kGuideMinHalfWidth);
}

const StageInputs& Stage() {
  static const StageInputs* const inputs = [] {
    const Sequence& data = Data();
    auto* stage = new StageInputs;
    stage->left = Decode(data.pairs[0].left);
    stage->right = Decode(data.pairs[0].right);
    const StereoFrontEndOptions defaults;
    FeatureDetector detector =
        FeatureDetector::Create(defaults.features).value();
    stage->left_features =
        detector.Detect(PreprocessImage(stage->left, defaults.clahe));
    stage->right_features =
        detector.Detect(PreprocessImage(stage->right, defaults.clahe));
    const LocusBand band =
        LocusBand::Create(data.rig, PriorInterval(), defaults.band).value();
    stage->left_keys = band.LeftKeys(stage->left_features.keypoints);
    stage->right_keys = band.RightKeys(stage->right_features.keypoints);
    stage->prior_matches = MatchInLocusBand(
        stage->left_features, stage->left_keys, stage->right_features,
        stage->right_keys, band, defaults.matching);
    StereoFrontEnd front_end =
        StereoFrontEnd::Create(data.rig, defaults).value();
    stage->front_end_matches =
        front_end.Match(stage->left, stage->right).value().matches;
    return stage;
  }();
  return *inputs;
}

// ---------------------------------------------------------------- stages

void BM_Decode(benchmark::State& state) {
  const EncodedPair& pair = Data().pairs[0];
  for (auto _ : state) {
    benchmark::DoNotOptimize(Decode(pair.left));
    benchmark::DoNotOptimize(Decode(pair.right));
  }
  state.counters["png_kB_per_image"] =
      (pair.left.size() + pair.right.size()) / 2.0 / 1000.0;
}
BENCHMARK(BM_Decode)->Unit(benchmark::kMillisecond);

void BM_Preprocess(benchmark::State& state) {
  const StageInputs& stage = Stage();
  ClaheOptions clahe;
  clahe.enabled = true;
  for (auto _ : state) {
    benchmark::DoNotOptimize(PreprocessImage(stage.left, clahe));
    benchmark::DoNotOptimize(PreprocessImage(stage.right, clahe));
  }
}
BENCHMARK(BM_Preprocess)->Unit(benchmark::kMillisecond);

void BM_Detect(benchmark::State& state, FeatureType type) {
  const StageInputs& stage = Stage();
  FeatureOptions options;
  options.type = type;
  FeatureDetector detector = FeatureDetector::Create(options).value();
  size_t keypoints = 0;
  for (auto _ : state) {
    const Features features = detector.Detect(stage.left);
    keypoints = features.keypoints.size();
    benchmark::DoNotOptimize(features.descriptors.data);
  }
  state.counters["keypoints"] = static_cast<double>(keypoints);
}
BENCHMARK_CAPTURE(BM_Detect, orb, FeatureType::kOrb)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Detect, sift, FeatureType::kSift)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Detect, akaze, FeatureType::kAkaze)
    ->Unit(benchmark::kMillisecond);

void BM_BandKeys(benchmark::State& state) {
  const StageInputs& stage = Stage();
  const LocusBand band =
      LocusBand::Create(Data().rig, PriorInterval(), LocusBandOptions())
          .value();
  for (auto _ : state) {
    benchmark::DoNotOptimize(band.LeftKeys(stage.left_features.keypoints));
  }
  state.counters["keypoints"] =
      static_cast<double>(stage.left_features.keypoints.size());
  state.SetItemsProcessed(state.iterations() *
                          stage.left_features.keypoints.size());
}
BENCHMARK(BM_BandKeys)->Unit(benchmark::kMillisecond);

void BM_GuidedMatch(benchmark::State& state, RefractiveIndexInterval interval) {
  const StageInputs& stage = Stage();
  const LocusBand band =
      LocusBand::Create(Data().rig, interval, LocusBandOptions()).value();
  const std::vector<LocusKey> left_keys =
      band.LeftKeys(stage.left_features.keypoints);
  const std::vector<LocusKey> right_keys =
      band.RightKeys(stage.right_features.keypoints);
  const GuidedMatchOptions options;
  size_t matches = 0;
  for (auto _ : state) {
    matches = MatchInLocusBand(stage.left_features, left_keys,
                               stage.right_features, right_keys, band, options)
                  .size();
    benchmark::DoNotOptimize(matches);
  }
  state.counters["left_keypoints"] =
      static_cast<double>(stage.left_features.keypoints.size());
  state.counters["right_keypoints"] =
      static_cast<double>(stage.right_features.keypoints.size());
  state.counters["matches"] = static_cast<double>(matches);
}
BENCHMARK_CAPTURE(BM_GuidedMatch, prior, PriorInterval())
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_GuidedMatch, guided, GuidedInterval())
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

void BM_SubpixelRefine(benchmark::State& state, bool affine) {
  const StageInputs& stage = Stage();
  std::vector<cv::Point2f> left;
  std::vector<cv::Point2f> right_start;
  for (const KeypointMatch& match : stage.prior_matches) {
    left.push_back(stage.left_features.keypoints[match.left].pt);
    right_start.push_back(stage.right_features.keypoints[match.right].pt);
  }
  SubpixelOptions options;
  options.affine = affine;
  std::vector<cv::Point2f> right;
  std::vector<unsigned char> kept;
  for (auto _ : state) {
    right = right_start;
    RefineRightPixels(stage.left, stage.right, left, &right, &kept, options);
    benchmark::DoNotOptimize(kept.data());
  }
  int num_kept = 0;
  for (unsigned char k : kept) num_kept += k;
  state.counters["matches"] = static_cast<double>(left.size());
  state.counters["kept"] = num_kept;
}
BENCHMARK_CAPTURE(BM_SubpixelRefine, affine, true)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_SubpixelRefine, translation, false)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

void BM_Estimate(benchmark::State& state) {
  const StageInputs& stage = Stage();
  RefinementOptions options;
  options.num_threads = static_cast<int>(state.range(0));
  double n = 0.0;
  for (auto _ : state) {
    const StatusOr<RefinementSummary> summary =
        RefineRefractiveIndex(Data().rig, stage.front_end_matches, options);
    if (!summary.ok()) {
      state.SkipWithError(summary.status().message().c_str());
      break;
    }
    n = summary->n;
  }
  state.counters["matches"] =
      static_cast<double>(stage.front_end_matches.size());
  state.counters["n_error"] = n - kTrueN;
}
BENCHMARK(BM_Estimate)
    ->ArgName("threads")
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

void BM_FrontEndMatch(benchmark::State& state,
                      std::optional<RefractiveIndexInterval> guide) {
  const StageInputs& stage = Stage();
  StereoFrontEnd front_end =
      StereoFrontEnd::Create(Data().rig, StereoFrontEndOptions()).value();
  StereoMatches last;
  FrontEndTimings sum;
  for (auto _ : state) {
    StatusOr<StereoMatches> matched =
        front_end.Match(stage.left, stage.right, 0, std::nullopt, guide);
    if (!matched.ok()) {
      state.SkipWithError(matched.status().message().c_str());
      break;
    }
    last = std::move(*matched);
    sum.preprocess_ms += last.timings.preprocess_ms;
    sum.detect_ms += last.timings.detect_ms;
    sum.match_ms += last.timings.match_ms;
    sum.refine_ms += last.timings.refine_ms;
  }
  const double iterations = static_cast<double>(state.iterations());
  state.counters["left_keypoints"] = last.left_keypoints;
  state.counters["right_keypoints"] = last.right_keypoints;
  state.counters["descriptor_matches"] = last.descriptor_matches;
  state.counters["matches"] = static_cast<double>(last.matches.size());
  state.counters["detect_ms"] = sum.detect_ms / iterations;
  state.counters["match_ms"] = sum.match_ms / iterations;
  state.counters["refine_ms"] = sum.refine_ms / iterations;
}
BENCHMARK_CAPTURE(BM_FrontEndMatch, prior,
                  std::optional<RefractiveIndexInterval>())
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_FrontEndMatch, guided,
                  std::optional<RefractiveIndexInterval>(GuidedInterval()))
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// ------------------------------------------------------------ end to end

struct RunResult {
  std::optional<double> n;
  double sigma_n = 0.0;
  int64_t matches = 0;
  int64_t keypoints = 0;  // both images of all pairs
  int reacquired = 0;
  std::string error;
};

void ReportEndToEnd(benchmark::State& state, const RunResult& result) {
  if (!result.error.empty()) {
    state.SkipWithError(result.error.c_str());
    return;
  }
  state.counters["pairs_per_second"] =
      benchmark::Counter(static_cast<double>(state.iterations() * kPairs),
                         benchmark::Counter::kIsRate);
  state.counters["n"] = result.n.value_or(0.0);
  state.counters["n_error"] = result.n ? *result.n - kTrueN : 1.0;
  state.counters["sigma_n"] = result.sigma_n;
  state.counters["matches_per_pair"] =
      static_cast<double>(result.matches) / kPairs;
  state.counters["keypoints_per_image"] =
      static_cast<double>(result.keypoints) / (2 * kPairs);
}

// The front end pipeline of BM_EndToEnd_Default; `guided` false matches
// every pair in the prior interval.
RunResult RunFrontEndPipeline(
    const StereoFrontEndOptions& options, bool guided,
    std::vector<StereoCorrespondence>* all_matches = nullptr) {
  const Sequence& data = Data();
  RunResult result;
  StatusOr<StereoFrontEnd> front_end =
      StereoFrontEnd::Create(data.rig, options);
  if (!front_end.ok()) {
    result.error = front_end.status().message();
    return result;
  }
  RefinementOptions per_pair;
  per_pair.num_threads = 1;
  std::vector<StereoCorrespondence> all;
  std::optional<RefractiveIndexInterval> guide;
  for (int i = 0; i < kPairs; ++i) {
    const EncodedPair& pair = data.pairs[i];
    std::future<cv::Mat> left =
        std::async(std::launch::async, [&pair] { return Decode(pair.left); });
    const cv::Mat right = Decode(pair.right);
    StatusOr<StereoMatches> matched =
        front_end->Match(left.get(), right, i, i / kFrameRate, guide);
    if (!matched.ok()) {
      result.error = matched.status().message();
      return result;
    }
    result.keypoints += matched->left_keypoints + matched->right_keypoints;
    result.reacquired += matched->reacquired ? 1 : 0;
    if (guided) {
      const StatusOr<RefinementSummary> estimate =
          RefineRefractiveIndex(data.rig, matched->matches, per_pair);
      if (estimate.ok()) {
        guide = RefractiveIndexInterval::Around(
            estimate->n, estimate->sigma_n, kGuideSigmas, kGuideMinHalfWidth);
      }
    }
    all.insert(all.end(), matched->matches.begin(), matched->matches.end());
  }
  result.matches = static_cast<int64_t>(all.size());
  const StatusOr<RefinementSummary> summary =
      RefineRefractiveIndex(data.rig, all, RefinementOptions());
  if (!summary.ok()) {
    result.error = summary.status().message();
    return result;
  }
  result.n = summary->n;
  result.sigma_n = summary->sigma_n;
  if (all_matches != nullptr) *all_matches = std::move(all);
  return result;
}

// The final estimate of BM_EndToEnd_Default alone: RefineRefractiveIndex
// (2 threads) over the front end's matches of all 10 pairs.
void BM_EstimateSequence(benchmark::State& state) {
  std::vector<StereoCorrespondence> matches;
  const RunResult run =
      RunFrontEndPipeline(StereoFrontEndOptions(), /*guided=*/true, &matches);
  if (!run.error.empty()) {
    state.SkipWithError(run.error.c_str());
    return;
  }
  double n = 0.0;
  for (auto _ : state) {
    n = RefineRefractiveIndex(Data().rig, matches, RefinementOptions())
            .value()
            .n;
  }
  state.counters["matches"] = static_cast<double>(matches.size());
  state.counters["n_error"] = n - kTrueN;
}
BENCHMARK(BM_EstimateSequence)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_EndToEnd_Default(benchmark::State& state) {
  Data();
  RunResult result;
  for (auto _ : state) {
    result = RunFrontEndPipeline(StereoFrontEndOptions(), /*guided=*/true);
  }
  ReportEndToEnd(state, result);
  state.counters["reacquired"] = result.reacquired;
}
BENCHMARK(BM_EndToEnd_Default)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(5)
    ->UseRealTime();

void BM_EndToEnd_PriorBand(benchmark::State& state) {
  Data();
  RunResult result;
  for (auto _ : state) {
    result = RunFrontEndPipeline(StereoFrontEndOptions(), /*guided=*/false);
  }
  ReportEndToEnd(state, result);
}
BENCHMARK(BM_EndToEnd_PriorBand)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(5)
    ->UseRealTime();

void BM_EndToEnd_SiftFrontEnd(benchmark::State& state) {
  Data();
  StereoFrontEndOptions options;
  options.features.type = FeatureType::kSift;
  RunResult result;
  for (auto _ : state) {
    result = RunFrontEndPipeline(options, /*guided=*/true);
  }
  ReportEndToEnd(state, result);
  state.counters["reacquired"] = result.reacquired;
}
BENCHMARK(BM_EndToEnd_SiftFrontEnd)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(3)
    ->UseRealTime();

// OpenCV SIFT on the full images, brute-force ratio matching, the paper's
// closed form: what a plain script does.
RunResult RunStraightforwardPipeline() {
  const Sequence& data = Data();
  RunResult result;
  cv::Ptr<cv::SIFT> sift = cv::SIFT::create();
  cv::BFMatcher matcher(cv::NORM_L2);
  PaperOnlineEstimator estimator(data.rig, PaperOnlineEstimatorOptions());
  for (int i = 0; i < kPairs; ++i) {
    const cv::Mat left = Decode(data.pairs[i].left);
    const cv::Mat right = Decode(data.pairs[i].right);
    std::vector<cv::KeyPoint> left_keypoints;
    std::vector<cv::KeyPoint> right_keypoints;
    cv::Mat left_descriptors;
    cv::Mat right_descriptors;
    sift->detectAndCompute(left, cv::noArray(), left_keypoints,
                           left_descriptors);
    sift->detectAndCompute(right, cv::noArray(), right_keypoints,
                           right_descriptors);
    result.keypoints +=
        static_cast<int64_t>(left_keypoints.size() + right_keypoints.size());
    std::vector<std::vector<cv::DMatch>> knn;
    matcher.knnMatch(left_descriptors, right_descriptors, knn, 2);
    for (const std::vector<cv::DMatch>& candidates : knn) {
      if (candidates.size() < 2 ||
          !(candidates[0].distance < 0.8f * candidates[1].distance)) {
        continue;
      }
      const cv::Point2f& l = left_keypoints[candidates[0].queryIdx].pt;
      const cv::Point2f& r = right_keypoints[candidates[0].trainIdx].pt;
      StereoCorrespondence correspondence;
      correspondence.frame = i;
      correspondence.timestamp = i / kFrameRate;
      correspondence.left_pixel = Eigen::Vector2d(l.x, l.y);
      correspondence.right_pixel = Eigen::Vector2d(r.x, r.y);
      estimator.Add(correspondence);
      ++result.matches;
    }
  }
  const std::optional<PaperOnlineEstimator::Estimate> estimate =
      estimator.Current();
  if (!estimate) {
    result.error = "no match passed the paper's mask";
    return result;
  }
  result.n = estimate->n;
  result.sigma_n = estimate->standard_error;
  return result;
}

void BM_EndToEnd_Straightforward(benchmark::State& state) {
  Data();
  RunResult result;
  for (auto _ : state) result = RunStraightforwardPipeline();
  ReportEndToEnd(state, result);
}
BENCHMARK(BM_EndToEnd_Straightforward)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(3)
    ->UseRealTime();

// The sequence engine (rcm/live/sequence_estimator.h) on the 10 pairs as
// `rcm estimate` runs it on images: each pair decoded (both PNGs at once)
// and added, the final estimate solved once. The rig as `rcm` reads a
// camchain without a sidecar: the default drift priors, so that the window
// self-calibrates cam1's rotation and the focal scales.
RunResult RunEnginePipeline(int window_matches) {
  const Sequence& data = Data();
  RunResult result;
  const StereoRig rig = WithDefaultCalibrationUncertainty(data.rig).value();
  SequenceEstimatorOptions options;
  options.estimation.refinement.detect_systematic = true;  // rcm estimate's
  options.window_matches = window_matches;
  std::unique_ptr<SequenceEstimator> sequence =
      SequenceEstimator::Create(rig, options).value();
  for (int i = 0; i < kPairs; ++i) {
    const EncodedPair& pair = data.pairs[i];
    std::future<cv::Mat> left =
        std::async(std::launch::async, [&pair] { return Decode(pair.left); });
    const cv::Mat right = Decode(pair.right);
    StatusOr<SequencePair> added =
        sequence->AddPair(left.get(), right, i, i / kFrameRate);
    if (!added.ok()) {
      result.error = added.status().message();
      return result;
    }
    result.matches += static_cast<int64_t>(added->matches.size());
    result.reacquired += added->reacquired ? 1 : 0;
  }
  const StatusOr<RefractiveIndexEstimate> estimate = sequence->Estimate();
  if (!estimate.ok()) {
    result.error = estimate.status().message();
    return result;
  }
  result.n = estimate->n;
  result.sigma_n = estimate->sigma_n;
  return result;
}

void BM_EndToEnd_Engine(benchmark::State& state) {
  Data();
  RunResult result;
  for (auto _ : state) {
    result = RunEnginePipeline(static_cast<int>(state.range(0)));
  }
  ReportEndToEnd(state, result);
}
BENCHMARK(BM_EndToEnd_Engine)
    ->ArgName("window_matches")
    ->Arg(100)
    ->Arg(200)
    ->Arg(400)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(3)
    ->UseRealTime();

// The rcm executable next to this benchmark's, or empty.
std::filesystem::path RcmNextToThisBenchmark() {
  const std::filesystem::path rcm =
      std::filesystem::read_symlink("/proc/self/exe").parent_path() / "rcm";
  return std::filesystem::exists(rcm) ? rcm : std::filesystem::path();
}

// A new temporary folder `prefix`<pid> with empty left/ and right/.
std::filesystem::path PairFolders(const std::string& prefix) {
  const std::filesystem::path folder = std::filesystem::temp_directory_path() /
                                       (prefix + std::to_string(getpid()));
  std::filesystem::create_directories(folder / "left");
  std::filesystem::create_directories(folder / "right");
  return folder;
}

// The whole `rcm estimate --calib camchain.yaml --left L --right R --json`
// process (the executable next to this benchmark) on the 10 pairs written
// as PNG folders, wall time per run, and its ratio to one run of the
// straightforward pipeline measured in the same benchmark
// (x_straightforward: how many times as fast the whole process is).
void BM_EndToEnd_RcmProcess(benchmark::State& state) {
  const Sequence& data = Data();
  const std::filesystem::path rcm = RcmNextToThisBenchmark();
  if (rcm.empty()) {
    state.SkipWithError("the rcm executable is not next to the benchmark");
    return;
  }
  const std::filesystem::path folder = PairFolders("rcm_process_benchmark_");
  for (int i = 0; i < kPairs; ++i) {
    char name[32];
    std::snprintf(name, sizeof(name), "%06d.png", i);
    std::ofstream(folder / "left" / name, std::ios::binary)
        .write(reinterpret_cast<const char*>(data.pairs[i].left.data()),
               data.pairs[i].left.size());
    std::ofstream(folder / "right" / name, std::ios::binary)
        .write(reinterpret_cast<const char*>(data.pairs[i].right.data()),
               data.pairs[i].right.size());
  }
  const std::string camchain = (folder / "camchain.yaml").string();
  CHECK(WriteCamchain(camchain, CamchainFromStereoRig(data.rig)).ok());
  const std::string command =
      rcm.string() + " estimate --calib " + camchain + " --left " +
      (folder / "left").string() + " --right " + (folder / "right").string() +
      " --json > " + (folder / "estimate.json").string() + " 2> /dev/null";
  // Each iteration times the process, then one straightforward run: the
  // machine's speed drifts by tens of percent over minutes (other guests
  // on its host), so the two are timed side by side and compared by their
  // fastest runs (the least disturbed) and by their medians.
  const auto seconds_since = [](std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() -
                                         start)
        .count();
  };
  std::vector<double> process_seconds;
  std::vector<double> straightforward_seconds;
  int failures = 0;
  for (auto _ : state) {
    const auto start = std::chrono::steady_clock::now();
    failures += std::system(command.c_str()) != 0 ? 1 : 0;
    process_seconds.push_back(seconds_since(start));
    state.PauseTiming();
    const auto straightforward_start = std::chrono::steady_clock::now();
    const RunResult straightforward = RunStraightforwardPipeline();
    straightforward_seconds.push_back(seconds_since(straightforward_start));
    failures += straightforward.error.empty() ? 0 : 1;
    state.ResumeTiming();
  }
  std::filesystem::remove_all(folder);
  if (failures > 0) {
    state.SkipWithError("rcm estimate or the straightforward pipeline failed");
    return;
  }
  const auto median = [](std::vector<double> values) {
    std::sort(values.begin(), values.end());
    const size_t n = values.size();
    return n % 2 == 1 ? values[n / 2]
                      : 0.5 * (values[n / 2 - 1] + values[n / 2]);
  };
  const double fastest =
      *std::min_element(process_seconds.begin(), process_seconds.end());
  const double fastest_straightforward = *std::min_element(
      straightforward_seconds.begin(), straightforward_seconds.end());
  state.counters["process_s_min"] = fastest;
  state.counters["process_s_median"] = median(process_seconds);
  state.counters["straightforward_s_min"] = fastest_straightforward;
  state.counters["straightforward_s_median"] = median(straightforward_seconds);
  state.counters["x_straightforward"] = fastest_straightforward / fastest;
  state.counters["x_straightforward_median"] =
      median(straightforward_seconds) / median(process_seconds);
}
BENCHMARK(BM_EndToEnd_RcmProcess)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(5)
    ->UseRealTime();

// The bundle estimator's whole process (issue 32: 40 pairs of 720x540
// under 10 s on 2 cores): `rcm estimate --estimator bundle` on 40 rendered
// pairs of a loop dive (a 5 m x 5 m pool at 4 Hz, 14 cm and up to 10 deg
// between pairs, cam1 turned 0.5 deg since the calibration), PNG folders
// as a user has them. Counters: the process's wall clock (fastest and
// median of 3) and the n it printed. 2026-12-06: 5.8-6.0 s, n 1.33321;
// with the focal scales estimated and the systematic floor, 7.1-7.2 s,
// n 1.33311 (7.6-8.2 s in a slow phase of the machine).
constexpr int kBundlePairs = 40;

void BM_EndToEnd_RcmBundleProcess(benchmark::State& state) {
  const std::filesystem::path rcm = RcmNextToThisBenchmark();
  if (rcm.empty()) {
    state.SkipWithError("the rcm executable is not next to the benchmark");
    return;
  }
  const std::filesystem::path folder = PairFolders("rcm_bundle_benchmark_");
  const StereoRig rig = AlphasenseFrontRectifiedRig();
  SequenceOptions options;
  options.media = {MediaSegment{kTrueN, kBundlePairs}};
  options.scene.length = 5.0;
  options.scene.width = 5.0;
  options.trajectory.loops = 1;
  options.trajectory.frame_rate = 4.0;
  options.cam1_drift.rotation =
      0.5 * M_PI / 180.0 * Eigen::Vector3d(0.3, 1.0, 0.2).normalized();
  std::unique_ptr<SequenceSimulator> simulator =
      SequenceSimulator::Create(rig, options).value();
  for (int i = 0; i < kBundlePairs; ++i) {
    const SequenceFrame frame = simulator->Frame(i).value();
    char name[32];
    std::snprintf(name, sizeof(name), "%06d.png", i);
    CHECK(cv::imwrite((folder / "left" / name).string(), frame.left));
    CHECK(cv::imwrite((folder / "right" / name).string(), frame.right));
  }
  const std::string camchain = (folder / "camchain.yaml").string();
  CHECK(WriteCamchain(camchain, CamchainFromStereoRig(rig)).ok());
  const std::string json = (folder / "estimate.json").string();
  const std::string command =
      rcm.string() + " estimate --estimator bundle --calib " + camchain +
      " --left " + (folder / "left").string() + " --right " +
      (folder / "right").string() + " --json > " + json + " 2> /dev/null";
  std::vector<double> seconds;
  int failures = 0;
  for (auto _ : state) {
    const auto start = std::chrono::steady_clock::now();
    failures += std::system(command.c_str()) != 0 ? 1 : 0;
    seconds.push_back(
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
            .count());
  }
  std::ifstream printed(json);
  const std::string text((std::istreambuf_iterator<char>(printed)),
                         std::istreambuf_iterator<char>());
  std::filesystem::remove_all(folder);
  if (failures > 0) {
    state.SkipWithError("rcm estimate --estimator bundle failed");
    return;
  }
  std::sort(seconds.begin(), seconds.end());
  state.counters["process_s_min"] = seconds.front();
  state.counters["process_s_median"] = seconds[seconds.size() / 2];
  const size_t at = text.find("\"n\":");
  state.counters["n"] =
      at == std::string::npos ? 0.0 : std::atof(text.c_str() + at + 4);
}
BENCHMARK(BM_EndToEnd_RcmBundleProcess)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(3)
    ->UseRealTime();

}  // namespace
}  // namespace rcm
