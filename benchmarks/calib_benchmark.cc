// The underwater refinement (rcm/calib/underwater_calibration.h): one
// corner's residual and Jacobian through the flat port (thin and thick),
// and the whole refinement of 30 stereo views of a 9x6 board on the
// dataset rig, without and with the default leave-out (10 groups), on the
// 2 threads it is given. Target: under 2 s each. And the joint calibration
// of air and water (AirTargetViews) on 30 + 30 views, the lenses free:
// target under 5 s (issue 30), with the default leave-out.
#include <benchmark/benchmark.h>

#include <memory>
#include <vector>

#include "calib/synthetic_target_views.h"
#include "rcm/calib/underwater_calibration.h"
#include "rcm/calib/underwater_reprojection_error.h"
#include "rcm/sim/reference_rigs.h"

namespace rcm::calib {
namespace {

CalibrationTarget Checkerboard() {
  return MakeCheckerboardTarget(9, 6, 0.04).value();
}

constexpr double kN = 1.342;

// The dataset rig in air, and 30 views at 0.25 px of noise through its
// ports drifted by 0.5 degrees.
struct Dive {
  StereoRig air;
  std::vector<StereoView> views;
};

Dive MakeDive(bool thick) {
  StereoRig air = AlphasenseFrontUnrectifiedRig();
  if (thick) {
    FlatPort port;
    port.air_gap = 0.008;
    port.glass_thickness = 0.006;
    air = air.WithPorts(port, port).value();
  }
  const StereoRig truth =
      air.WithCam1Moved(0.5 * M_PI / 180.0 *
                        Eigen::Vector3d(0.3, -1.0, 0.2).normalized())
          .value();
  const std::vector<Rigid3d> poses = test::BoardPoses(
      truth.left(), Checkerboard(), 30, /*seed=*/7, 0.45, 0.9, 35.0, kN);
  return {air, test::ObserveStereoUnderwater(truth, kN, Checkerboard(), poses,
                                             0.25, /*seed=*/1)};
}

// Residual and Jacobian of one cam1 corner (18 parameters).
void BM_UnderwaterResidualAndJacobian(benchmark::State& state) {
  const bool thick = state.range(0) != 0;
  const Dive dive = MakeDive(thick);
  UnderwaterCameraConstants constants;
  const Camera& camera = dive.air.right();
  std::copy(camera.params(), camera.params() + camera.num_params(),
            constants.lens.begin());
  constants.glass_thickness = thick ? 0.006 : 0.0;
  const TargetObservation& observation = *dive.views[0].right;
  const std::unique_ptr<ceres::CostFunction> cost(
      Cam1UnderwaterReprojectionError<EquidistantLens>::Create(
          constants, TargetPoints(Checkerboard())[observation.point_ids[0]],
          Eigen::Vector2d(0.5, 0.5), observation.pixels[0]));
  double n = kN;
  double pose[6] = {0.1, -0.2, 0.05, 0.02, -0.01, 0.7};
  double extrinsics[6] = {0.0, 0.01, 0.0, -0.11, 0.0, 0.0};
  double gap = thick ? 0.008 : 0.0;
  double tilt[2] = {0.0, 0.0};
  double warp[2] = {4e-4, 3e-4};
  const double* parameters[6] = {&n, pose, extrinsics, &gap, tilt, warp};
  double residuals[2];
  double j_n[2], j_pose[12], j_extrinsics[12], j_gap[2], j_tilt[4], j_warp[4];
  double* jacobians[6] = {j_n, j_pose, j_extrinsics, j_gap, j_tilt, j_warp};
  for (auto _ : state) {
    benchmark::DoNotOptimize(cost->Evaluate(parameters, residuals, jacobians));
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_UnderwaterResidualAndJacobian)->ArgName("thick")->Arg(0)->Arg(1);

// The refinement of 30 stereo views (3200 corners): folds 0 (no leave-out)
// or 10 (the default), thin or thick (8 mm gap + 6 mm glass) ports, with
// the conventional model's fit as by default.
void BM_CalibrateUnderwater(benchmark::State& state) {
  const Dive dive = MakeDive(state.range(1) != 0);
  UnderwaterCalibrationOptions options;
  options.folds = static_cast<int>(state.range(0));
  options.num_threads = 2;
  for (auto _ : state) {
    const StatusOr<UnderwaterCalibration> result = CalibrateUnderwater(
        Checkerboard(), dive.views, {720, 540}, {720, 540}, dive.air, options);
    if (!result.ok()) {
      state.SkipWithError(result.status().message().c_str());
      return;
    }
    benchmark::DoNotOptimize(result->n);
  }
}
BENCHMARK(BM_CalibrateUnderwater)
    ->ArgNames({"folds", "thick"})
    ->Args({0, 0})
    ->Args({10, 0})
    ->Args({0, 1})
    ->Args({10, 1})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// The joint calibration of 30 underwater views and 30 air views (6400
// corners, the lenses, both extrinsics, the board's bow shared by the two
// media): folds 0 or 10, thin ports, with the conventional fit.
void BM_CalibrateAirAndWater(benchmark::State& state) {
  const Dive dive = MakeDive(/*thick=*/false);
  AirTargetViews air;
  air.target = Checkerboard();
  air.views = test::ObserveStereo(
      dive.air, Checkerboard(),
      test::BoardPoses(dive.air.left(), Checkerboard(), 30, /*seed=*/11), 0.25,
      /*seed=*/2);
  air.cam0_size = {720, 540};
  air.cam1_size = {720, 540};
  air.same_board = true;
  UnderwaterCalibrationOptions options;
  options.folds = static_cast<int>(state.range(0));
  options.num_threads = 2;
  for (auto _ : state) {
    const StatusOr<UnderwaterCalibration> result =
        CalibrateUnderwater(Checkerboard(), dive.views, {720, 540}, {720, 540},
                            dive.air, options, nullptr, &air);
    if (!result.ok()) {
      state.SkipWithError(result.status().message().c_str());
      return;
    }
    benchmark::DoNotOptimize(result->n);
  }
}
BENCHMARK(BM_CalibrateAirAndWater)
    ->ArgNames({"folds"})
    ->Arg(0)
    ->Arg(10)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace
}  // namespace rcm::calib
