// Cost per correspondence of the closed form and the paper's estimator,
// and of the first-order sigma (a Jet pass through both undistortions);
// the Sampson residual of the refinement, and its Jacobian in n, cam1's
// rotation and the focal scales by autodiff and written out; the
// refinement's run time against the number of correspondences, which must
// grow linearly (the complexity fit reported as
// BM_RefineRefractiveIndex_BigO), and with the drift priors of a camchain
// without a sidecar (rcm estimate's final estimate); the thick-port
// residual and refinement.
#include <benchmark/benchmark.h>
#include <ceres/cost_function.h>

#include <algorithm>
#include <memory>
#include <vector>

#include "rcm/estimation/batch_refinement.h"
#include "rcm/estimation/closed_form.h"
#include "rcm/estimation/generalized_epipolar_error.h"
#include "rcm/estimation/locus_cost_function.h"
#include "rcm/estimation/online_estimator.h"
#include "rcm/estimation/paper_online_estimator.h"
#include "rcm/estimation/prepared_correspondence.h"
#include "rcm/estimation/sampson_coplanarity_cost_function.h"
#include "rcm/estimation/sampson_coplanarity_error.h"
#include "rcm/estimation/sliding_window_estimator.h"
#include "rcm/estimation/thick_port_refinement.h"
#include "rcm/io/stereo_rig_file.h"
#include "rcm/sim/reference_rigs.h"
#include "rcm/sim/stereo_sampler.h"
#include "rcm/stereo/epipolar.h"
#include "rcm/stereo/observability.h"

namespace rcm {
namespace {

std::vector<StereoCorrespondence> Matches(const StereoRig& rig,
                                          int count = 4096) {
  StereoSamplerOptions options;
  options.num_frames = std::max(1, count / 200);
  options.per_frame = count / options.num_frames;
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

void BM_PrepareCorrespondence(benchmark::State& state) {
  // Both undistortions and lens Jacobians: once per match and refinement.
  const StereoRig rig = AlphasenseFrontUnrectifiedRig();
  const std::vector<StereoCorrespondence> matches = Matches(rig);
  size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(PrepareCorrespondence(rig, matches[i]));
    i = (i + 1 == matches.size()) ? 0 : i + 1;
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_PrepareCorrespondence);

void BM_SampsonResidual(benchmark::State& state) {
  // One evaluation of r(n) in double: the inner loop of the scan.
  const StereoRig rig = AlphasenseFrontUnrectifiedRig();
  const std::vector<PreparedCorrespondence> matches =
      PrepareCorrespondences(rig, Matches(rig)).prepared;
  const Eigen::Matrix3d essential = EssentialMatrix(rig.right_from_left());
  size_t i = 0;
  double residual = 0.0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(SampsonCoplanarityResidual<double>(
        essential, matches[i], 1.333, nullptr, &residual));
    benchmark::DoNotOptimize(residual);
    i = (i + 1 == matches.size()) ? 0 : i + 1;
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_SampsonResidual);

// One residual and its Jacobian in n, cam1's rotation and the focal
// scales, as the batch refinement's Ceres solves evaluate it when the rig
// carries drift priors (rcm estimate's default): the autodiff functor
// (Jet<double, 6>) against the Jacobian written out
// (sampson_coplanarity_cost_function.h), at one solve's parameters.
void BM_SampsonJacobian(benchmark::State& state, bool analytic) {
  const StereoRig rig = AlphasenseFrontUnrectifiedRig();
  const std::vector<StereoCorrespondence> raw = Matches(rig);
  std::vector<PreparedCorrespondence> matches =
      PrepareCorrespondences(rig, raw).prepared;
  const FocalStepRigs steps = FocalStepRigs::Of(rig).value();
  for (size_t i = 0; i < matches.size(); ++i) {
    PrepareFocalDerivatives(steps, raw[i], &matches[i]);
  }
  const Eigen::Matrix3d essential = EssentialMatrix(rig.right_from_left());
  std::vector<std::unique_ptr<ceres::CostFunction>> costs;
  for (const PreparedCorrespondence& match : matches) {
    costs.emplace_back(
        analytic
            ? SampsonCoplanarityCostFunction::Create(essential, match, true)
            : SampsonCoplanarityError::CreateWithRotationAndFocal(essential,
                                                                  match));
  }
  const double n = 1.333;
  const double rotation[3] = {1e-3, -2e-3, 5e-4};
  const double focal[2] = {1e-3, -1e-3};
  const double* blocks[3] = {&n, rotation, focal};
  double residual = 0.0;
  double jacobian[6];
  double* jacobians[3] = {jacobian, jacobian + 1, jacobian + 4};
  size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(costs[i]->Evaluate(blocks, &residual, jacobians));
    benchmark::DoNotOptimize(jacobian);
    i = (i + 1 == costs.size()) ? 0 : i + 1;
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK_CAPTURE(BM_SampsonJacobian, autodiff, false);
BENCHMARK_CAPTURE(BM_SampsonJacobian, analytic, true);

// A frame's matches into the locus cost function on one thread: each match
// at the 577 nodes, r and dr/dn vectorized over the matches
// (sampson_residual_batch.h); per match, against 577 x BM_SampsonResidual's
// Jet twin.
void BM_LocusCostFunctionAddMatches(benchmark::State& state) {
  const StereoRig rig = AlphasenseFrontUnrectifiedRig();
  const std::vector<PreparedCorrespondence> matches =
      PrepareCorrespondences(rig, Matches(rig)).prepared;
  const Eigen::Matrix3d essential = EssentialMatrix(rig.right_from_left());
  for (auto _ : state) {
    LocusCostFunction cost;
    benchmark::DoNotOptimize(cost.AddMatches(essential, matches, 1));
  }
  state.SetItemsProcessed(state.iterations() *
                          static_cast<int64_t>(matches.size()));
}
BENCHMARK(BM_LocusCostFunctionAddMatches)->Unit(benchmark::kMillisecond);

// The thick-port residual (generalized epipolar constraint, Sampson-
// normalized by central differences: nine evaluations of both rays),
// against BM_SampsonResidual of the thin port.
void BM_GeneralizedEpipolarResidual(benchmark::State& state) {
  const StereoRig rig = AlphasenseFrontRectifiedRig();
  FlatPort port;
  port.air_gap = 0.008;
  port.glass_thickness = 0.006;
  const std::vector<PreparedCorrespondence> prepared =
      PrepareCorrespondences(rig, Matches(rig)).prepared;
  const ThickPortStereo stereo{port, port, rig.right_from_left()};
  size_t i = 0;
  for (auto _ : state) {
    double residual = 0.0;
    benchmark::DoNotOptimize(GeneralizedEpipolarResidual(
        stereo, prepared[i], 1.333, 0.0, &residual));
    benchmark::DoNotOptimize(residual);
    i = (i + 1 == prepared.size()) ? 0 : i + 1;
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_GeneralizedEpipolarResidual);

// The whole thick-port refinement (scan, robust and least-squares stages,
// covariance) on correspondences traced through an 8 mm + 6 mm port with
// 0.3 px noise, with the air gap known (0) or estimated (1).
void BM_RefineRefractiveIndexThickPort(benchmark::State& state) {
  const StereoRig rig = AlphasenseFrontUnrectifiedRig();
  FlatPort port;
  port.air_gap = 0.008;
  port.glass_thickness = 0.006;
  StereoSamplerOptions sampler;
  sampler.per_frame = static_cast<int>(state.range(0));
  std::vector<StereoCorrespondence> matches =
      SampleFlatPortCorrespondences(rig, port, port, sampler).value();
  AddPixelNoise(0.3, 2, &matches);
  ThickPortRefinementOptions options;
  options.estimate_air_gap = state.range(1) != 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(
        RefineRefractiveIndexThickPort(rig, port, port, matches, options));
  }
  state.SetItemsProcessed(state.iterations() * state.range(0));
}
BENCHMARK(BM_RefineRefractiveIndexThickPort)
    ->Args({300, 0})
    ->Args({2000, 0})
    ->Args({2000, 1})
    ->Unit(benchmark::kMillisecond);

// The whole batch refinement (prepare, scan, robust and least-squares
// Ceres stages, covariance) of state.range(0) matches of `rig` with 0.5 px
// noise and 20 % outliers, on two threads.
void RunRefinement(benchmark::State& state, const StereoRig& rig) {
  std::vector<StereoCorrespondence> matches =
      Matches(rig, static_cast<int>(state.range(0)));
  AddPixelNoise(0.5, 2, &matches);
  AddOutliers(rig, 0.2, 3, &matches);
  const RefinementOptions options;
  for (auto _ : state) {
    benchmark::DoNotOptimize(RefineRefractiveIndex(rig, matches, options));
  }
  state.SetItemsProcessed(state.iterations() * state.range(0));
  state.SetComplexityN(state.range(0));
}

void BM_RefineRefractiveIndex(benchmark::State& state) {
  RunRefinement(state, AlphasenseFrontUnrectifiedRig());
}
BENCHMARK(BM_RefineRefractiveIndex)
    ->RangeMultiplier(10)
    ->Range(1000, 100000)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Complexity(benchmark::oN);

// The same on a rig with the default drift priors, as rcm reads a camchain
// without a sidecar: n with cam1's rotation and the focal scales under
// their priors (the robust stage, stage 2 until the prior's weight
// settles, the focal passes), what `rcm estimate`'s final estimate solves.
void BM_RefineRefractiveIndexSelfCalibrating(benchmark::State& state) {
  RunRefinement(state, WithDefaultCalibrationUncertainty(
                           AlphasenseFrontUnrectifiedRig(), RigFileOptions())
                           .value());
}
BENCHMARK(BM_RefineRefractiveIndexSelfCalibrating)
    ->Arg(2000)
    ->Arg(12000)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// One frame of 200 matches (0.5 px noise, 10 % outliers) into the online
// estimator: the frame's robust fit, its inliers' cost function at the
// Chebyshev nodes, the cumulative minimization. Time and memory per frame
// do not depend on how many frames came before.
std::vector<std::vector<StereoCorrespondence>> Frames(const StereoRig& rig,
                                                      int count) {
  std::vector<std::vector<StereoCorrespondence>> frames;
  for (int f = 0; f < count; ++f) {
    StereoSamplerOptions options;
    options.per_frame = 200;
    options.seed = 10 + f;
    std::vector<StereoCorrespondence> matches =
        SampleStereoCorrespondences(rig, options).value();
    AddPixelNoise(0.5, 100 + f, &matches);
    AddOutliers(rig, 0.1, 200 + f, &matches);
    frames.push_back(std::move(matches));
  }
  return frames;
}

void BM_OnlineEstimatorAddFrame(benchmark::State& state) {
  const StereoRig rig = AlphasenseFrontUnrectifiedRig();
  const auto frames = Frames(rig, 16);
  OnlineRefractiveIndexEstimator estimator =
      OnlineRefractiveIndexEstimator::Create(rig, RefinementOptions()).value();
  size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(estimator.AddFrame(frames[i]));
    i = (i + 1 == frames.size()) ? 0 : i + 1;
  }
  state.SetItemsProcessed(state.iterations());
  state.counters["bytes"] = static_cast<double>(estimator.MemoryBytes());
}
BENCHMARK(BM_OnlineEstimatorAddFrame)->Unit(benchmark::kMillisecond);

void BM_SlidingWindowAddFrame(benchmark::State& state) {
  const StereoRig rig = AlphasenseFrontUnrectifiedRig();
  const auto frames = Frames(rig, 16);
  SlidingWindowRefractiveIndexEstimator estimator =
      SlidingWindowRefractiveIndexEstimator::Create(rig, RefinementOptions(),
                                                    SlidingWindowOptions())
          .value();
  int64_t frame = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(
        estimator.AddFrame(frame, frames[frame % frames.size()]));
    ++frame;
  }
  state.SetItemsProcessed(state.iterations());
  state.counters["bytes"] = static_cast<double>(estimator.MemoryBytes());
}
BENCHMARK(BM_SlidingWindowAddFrame)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace rcm
