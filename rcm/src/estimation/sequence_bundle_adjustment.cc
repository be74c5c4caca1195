#include "rcm/estimation/sequence_bundle_adjustment.h"

#include <ceres/manifold.h>
#include <ceres/normal_prior.h>
#include <ceres/ordered_groups.h>
#include <ceres/problem.h>
#include <ceres/product_manifold.h>
#include <ceres/rotation.h>
#include <ceres/solver.h>
#include <ceres/sphere_manifold.h>
#include <glog/logging.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <Eigen/SparseCore>
#include <algorithm>
#include <cmath>
#include <memory>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <optional>
#include <tuple>
#include <utility>

#include "rcm/camera/camera.h"
#include "rcm/camera/refractive_camera.h"
#include "rcm/estimation/batch_refinement.h"
#include "rcm/util/number_format.h"

namespace rcm {
namespace {

constexpr double kPi = 3.14159265358979323846;
// The reference depth at which a thick port's camera is made central for
// the initial bearings, metres (RefractiveCamera::CreateWithPort): the
// bundle then projects through the exact port.
constexpr double kInitialReferenceDepth = 2.0;
// The initial PnP's RANSAC threshold, pixels: the landmarks it places are
// triangulated with the stale calibration at the initial n, which puts
// them off by metres on a narrow rig whose cam1 turned a degree (2 px lost
// keyframes there); a mistracked point is off by tens of pixels.
constexpr double kPnpThresholdPx = 8.0;
// Up to this many keyframes the Schur complement is solved dense.
constexpr int kMaxDenseSchurFrames = 100;

// What every residual holds fixed: the rig's lenses, ports, rotation and
// baseline.
struct RigConstants {
  std::array<LensModelId, 2> models{};
  std::array<TrackCameraConstants, 2> cameras;
  std::array<double, 9> rotation{};
  double baseline = 0.0;
  Eigen::Vector3d direction = Eigen::Vector3d::UnitX();
};

TrackCameraConstants CameraConstants(const Camera& camera,
                                     const std::optional<FlatPort>& port) {
  TrackCameraConstants constants;
  for (int i = 0; i < camera.num_params(); ++i) {
    constants.lens[i] = camera.params()[i];
  }
  if (port && !port->IsThin()) {
    constants.thin_port = false;
    constants.air_gap = port->air_gap;
    constants.glass_thickness = port->glass_thickness;
    constants.glass_index = port->glass_index;
    const Eigen::Vector3d normal = port->normal.normalized();
    constants.normal = {normal.x(), normal.y(), normal.z()};
  }
  return constants;
}

RigConstants ConstantsOf(const StereoRig& rig) {
  RigConstants constants;
  constants.models = {rig.left().model(), rig.right().model()};
  std::optional<FlatPort> left_port;
  std::optional<FlatPort> right_port;
  if (rig.ports()) {
    left_port = rig.ports()->left;
    right_port = rig.ports()->right;
  }
  constants.cameras = {CameraConstants(rig.left(), left_port),
                       CameraConstants(rig.right(), right_port)};
  const Rigid3d& right_from_left = rig.right_from_left();
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      constants.rotation[3 * i + j] = right_from_left.rotation(i, j);
    }
  }
  constants.baseline = right_from_left.translation.norm();
  constants.direction = right_from_left.translation / constants.baseline;
  return constants;
}

// The observation's cost; a cam1 observation's with the translation's
// direction a block of its own, or held at `held_direction`.
ceres::CostFunction* CostFor(
    const RigConstants& constants, const StereoTrackObservation& observation,
    const std::optional<std::array<double, 3>>& held_direction) {
  const int c = observation.camera;
  RCM_LENS_MODEL_SWITCH(
      constants.models[c],
      if (c == 0) {
        return Cam0TrackReprojectionError<LensModel>::Create(
            constants.cameras[0], observation.pixel);
      } if (held_direction) {
        return Cam1HeldDirectionTrackReprojectionError<LensModel>::Create(
            constants.cameras[1], constants.rotation, constants.baseline,
            *held_direction, observation.pixel);
      } return Cam1TrackReprojectionError<LensModel>::
          Create(constants.cameras[1], constants.rotation, constants.baseline,
                 observation.pixel);)
  LOG(FATAL) << "unknown lens model";
  return nullptr;
}

// The bundle's unknowns as Ceres' blocks.
struct Blocks {
  double n = 1.333;
  std::array<double, 3> rotation{};
  std::array<double, 3> direction{1.0, 0.0, 0.0};
  std::array<double, 2> focal{};  // e0, e1
  std::vector<std::array<double, 7>> poses;
  std::vector<std::array<double, 3>> landmarks;
  std::vector<bool> placed;
};

Blocks BlocksOf(const SequenceBundleState& state) {
  Blocks blocks;
  blocks.n = state.n;
  for (int i = 0; i < 3; ++i) {
    blocks.rotation[i] = state.cam1_rotation[i];
    blocks.direction[i] = state.cam1_direction[i];
  }
  blocks.focal = {state.focal_scales[0], state.focal_scales[1]};
  for (const Rigid3d& pose : state.cam0_from_world) {
    const Eigen::Quaterniond q(pose.rotation);
    blocks.poses.push_back({q.w(), q.x(), q.y(), q.z(), pose.translation.x(),
                            pose.translation.y(), pose.translation.z()});
  }
  for (const Eigen::Vector3d& point : state.landmarks) {
    blocks.landmarks.push_back({point.x(), point.y(), point.z()});
    blocks.placed.push_back(point.allFinite());
  }
  return blocks;
}

SequenceBundleState StateOf(const Blocks& blocks) {
  SequenceBundleState state;
  state.n = blocks.n;
  state.cam1_rotation = Eigen::Vector3d(blocks.rotation.data());
  state.cam1_direction = Eigen::Vector3d(blocks.direction.data());
  state.focal_scales = Eigen::Vector2d(blocks.focal[0], blocks.focal[1]);
  for (const std::array<double, 7>& pose : blocks.poses) {
    Eigen::Quaterniond q(pose[0], pose[1], pose[2], pose[3]);
    q.normalize();
    state.cam0_from_world.push_back(Rigid3d{
        q.toRotationMatrix(), Eigen::Vector3d(pose[4], pose[5], pose[6])});
  }
  for (size_t l = 0; l < blocks.landmarks.size(); ++l) {
    state.landmarks.push_back(
        blocks.placed[l] ? Eigen::Vector3d(blocks.landmarks[l].data())
                         : Eigen::Vector3d::Constant(
                               std::numeric_limits<double>::quiet_NaN()));
  }
  return state;
}

// One solve of the bundle over the observations marked `use`.
struct StageResult {
  ceres::Solver::Summary summary;
  bool covariance_ok = false;
  double c_nn = 0.0;
  Eigen::Vector3d c_nw = Eigen::Vector3d::Zero();
  Eigen::Matrix3d c_ww = Eigen::Matrix3d::Zero();
  // With the focal scales estimated: their covariance and with n.
  Eigen::Matrix2d c_ff = Eigen::Matrix2d::Zero();
  Eigen::Vector2d c_nf = Eigen::Vector2d::Zero();
  // c_nn with the focal scales held at the solution: the pixel noise's
  // share; c_nn - c_nn_focal_held is what the focal prior leaves.
  double c_nn_focal_held = 0.0;
  // v = J (J^T J)^-1 e_n, one entry per residual row in the order the
  // observations were added: n moves by -v . dr when the residuals move
  // by dr at the solution (the linear response of the least squares).
  Eigen::VectorXd n_influence;
};

// The covariance of n and cam1's turn at the solution, (J^T J)^-1's
// entries, with the landmarks eliminated exactly: with the columns ordered
// [landmarks; p], p = [n; w; u; poses 1..F-1] (tangent spaces), and
// H = J^T J,
//
//   S = H_pp - sum_l H_pl H_ll^-1 H_lp       (each H_ll a 3 x 3 block)
//
// is the information of p with the landmarks unknown, and S^-1 their
// marginal covariance. S is small (4 + 6 (F - 1)), so it is factored
// densely (LDLT) and refused as singular where its reciprocal condition is
// below 1e-14; a landmark's own block below that is a landmark without
// depth. (Ceres' Covariance with SPARSE_QR decides the rank over all of J
// at once, and called a Monte Carlo trial with a lens change rank
// deficient by one whose S is well conditioned.)
void ReducedCovariance(ceres::Problem& problem, Blocks& blocks, bool rotation,
                       bool direction, bool focal, int num_threads,
                       StageResult* result) {
  std::vector<double*> order;
  for (size_t l = 0; l < blocks.landmarks.size(); ++l) {
    double* landmark = blocks.landmarks[l].data();
    if (problem.HasParameterBlock(landmark)) order.push_back(landmark);
  }
  const int num_landmark_columns = 3 * static_cast<int>(order.size());
  order.push_back(&blocks.n);
  int p = 1;
  const int rotation_column = p;
  if (rotation) {
    order.push_back(blocks.rotation.data());
    p += 3;
  }
  if (direction) {
    order.push_back(blocks.direction.data());
    p += 2;  // the sphere's tangent
  }
  const int focal_column = p;
  if (focal) {
    order.push_back(blocks.focal.data());
    p += 2;
  }
  for (size_t f = 1; f < blocks.poses.size(); ++f) {
    double* pose = blocks.poses[f].data();
    if (problem.HasParameterBlock(pose)) {
      order.push_back(pose);
      p += 6;
    }
  }
  ceres::Problem::EvaluateOptions evaluate;
  evaluate.parameter_blocks = order;
  evaluate.num_threads = num_threads;
  ceres::CRSMatrix jacobian;
  if (!problem.Evaluate(evaluate, nullptr, nullptr, nullptr, &jacobian)) {
    return;
  }
  const Eigen::Map<const Eigen::SparseMatrix<double, Eigen::RowMajor, int>> j(
      jacobian.num_rows, jacobian.num_cols,
      static_cast<int>(jacobian.values.size()), jacobian.rows.data(),
      jacobian.cols.data(), jacobian.values.data());
  // H = J^T J by blocks, row by row of J: each row holds one landmark's
  // columns (< m) and some of p's. (Eigen's sparse J^T J over all columns
  // took a minute on 30000 landmarks, single-threaded.)
  const int m = num_landmark_columns;
  Eigen::MatrixXd s = Eigen::MatrixXd::Zero(p, p);
  // Each landmark's block and its coupling to p, for the back-substitution
  // of the covariance's column of n below.
  struct LandmarkBlock {
    Eigen::Matrix3d h_ll = Eigen::Matrix3d::Zero();
    Eigen::LDLT<Eigen::Matrix3d> factor;
    std::vector<int> columns;  // p's columns it couples to, ascending
    Eigen::MatrixXd h_lp;
  };
  std::vector<LandmarkBlock> landmark_blocks(m / 3);
  {
    // Pass 1: each landmark's p columns.
    for (int r = 0; r < jacobian.num_rows; ++r) {
      int landmark = -1;
      for (int k = jacobian.rows[r]; k < jacobian.rows[r + 1]; ++k) {
        if (jacobian.cols[k] < m) landmark = jacobian.cols[k] / 3;
      }
      if (landmark < 0) continue;
      std::vector<int>& columns = landmark_blocks[landmark].columns;
      for (int k = jacobian.rows[r]; k < jacobian.rows[r + 1]; ++k) {
        if (jacobian.cols[k] >= m) columns.push_back(jacobian.cols[k] - m);
      }
    }
    for (LandmarkBlock& block : landmark_blocks) {
      std::sort(block.columns.begin(), block.columns.end());
      block.columns.erase(
          std::unique(block.columns.begin(), block.columns.end()),
          block.columns.end());
      block.h_lp = Eigen::MatrixXd::Zero(3, block.columns.size());
    }
    // Pass 2: the products of each row's entries.
    std::vector<std::pair<int, double>> landmark_entries;
    std::vector<std::pair<int, double>> p_entries;
    for (int r = 0; r < jacobian.num_rows; ++r) {
      landmark_entries.clear();
      p_entries.clear();
      for (int k = jacobian.rows[r]; k < jacobian.rows[r + 1]; ++k) {
        const int col = jacobian.cols[k];
        if (col < m) {
          landmark_entries.emplace_back(col, jacobian.values[k]);
        } else {
          p_entries.emplace_back(col - m, jacobian.values[k]);
        }
      }
      for (const auto& [a, va] : p_entries) {
        for (const auto& [b, vb] : p_entries) s(a, b) += va * vb;
      }
      if (landmark_entries.empty()) continue;
      LandmarkBlock& block = landmark_blocks[landmark_entries[0].first / 3];
      for (const auto& [a, va] : landmark_entries) {
        for (const auto& [b, vb] : landmark_entries) {
          block.h_ll(a % 3, b % 3) += va * vb;
        }
        for (const auto& [b, vb] : p_entries) {
          const auto at =
              std::lower_bound(block.columns.begin(), block.columns.end(), b);
          block.h_lp(a % 3, at - block.columns.begin()) += va * vb;
        }
      }
    }
  }
  // S = H_pp - sum_l H_lp^T H_ll^-1 H_lp.
  for (LandmarkBlock& block : landmark_blocks) {
    const std::vector<int>& columns = block.columns;
    const Eigen::MatrixXd& h_lp = block.h_lp;
    Eigen::LDLT<Eigen::Matrix3d>& landmark = block.factor;
    landmark.compute(block.h_ll);
    if (landmark.info() != Eigen::Success || !landmark.isPositive() ||
        !(landmark.rcond() > 1e-14)) {
      return;  // a landmark without depth: singular
    }
    const Eigen::MatrixXd reduced = h_lp.transpose() * landmark.solve(h_lp);
    for (size_t a = 0; a < columns.size(); ++a) {
      for (size_t b = 0; b < columns.size(); ++b) {
        s(columns[a], columns[b]) -= reduced(a, b);
      }
    }
  }
  const Eigen::LDLT<Eigen::MatrixXd> factor(s);
  if (factor.info() != Eigen::Success || !factor.isPositive() ||
      !(factor.rcond() > 1e-14)) {
    return;
  }
  // The columns of n, the turn and the focal scales.
  std::vector<int> columns = {0};
  if (rotation) {
    for (int k = 0; k < 3; ++k) columns.push_back(rotation_column + k);
  }
  if (focal) {
    for (int k = 0; k < 2; ++k) columns.push_back(focal_column + k);
  }
  Eigen::MatrixXd unit = Eigen::MatrixXd::Zero(p, columns.size());
  for (size_t k = 0; k < columns.size(); ++k) unit(columns[k], k) = 1.0;
  const Eigen::MatrixXd covariance = factor.solve(unit);
  if (focal) {
    // S without the focal scales' rows and columns.
    std::vector<int> kept;
    for (int k = 0; k < p; ++k) {
      if (k != focal_column && k != focal_column + 1) kept.push_back(k);
    }
    Eigen::MatrixXd s_held(p - 2, p - 2);
    for (int a = 0; a < p - 2; ++a) {
      for (int b = 0; b < p - 2; ++b) s_held(a, b) = s(kept[a], kept[b]);
    }
    const Eigen::LDLT<Eigen::MatrixXd> held(s_held);
    if (held.info() != Eigen::Success || !held.isPositive()) return;
    Eigen::VectorXd e_n = Eigen::VectorXd::Zero(p - 2);
    e_n[0] = 1.0;
    result->c_nn_focal_held = held.solve(e_n)[0];
    const int f = rotation ? 4 : 1;  // the focal scales' columns in unit
    for (int a = 0; a < 2; ++a) {
      result->c_nf[a] = covariance(focal_column + a, 0);
      for (int b = 0; b < 2; ++b) {
        result->c_ff(a, b) = covariance(focal_column + a, f + b);
      }
    }
    result->c_ff = 0.5 * (result->c_ff + result->c_ff.transpose()).eval();
  }
  result->c_nn = covariance(0, 0);
  if (rotation) {
    for (int k = 0; k < 3; ++k) {
      result->c_nw[k] = covariance(rotation_column + k, 0);
      for (int i = 0; i < 3; ++i) {
        result->c_ww(i, k) = covariance(rotation_column + i, k + 1);
      }
    }
    result->c_ww = 0.5 * (result->c_ww + result->c_ww.transpose()).eval();
  }
  // The whole column c = (J^T J)^-1 e_n: p's part solved above, each
  // landmark's c_l = -H_ll^-1 H_lp c_p; then v = J c.
  Eigen::VectorXd column(m + p);
  column.tail(p) = covariance.col(0);
  for (int l = 0; 3 * l < m; ++l) {
    const LandmarkBlock& block = landmark_blocks[l];
    Eigen::VectorXd c_p(block.columns.size());
    for (size_t a = 0; a < block.columns.size(); ++a) {
      c_p[a] = covariance(block.columns[a], 0);
    }
    column.segment<3>(3 * l) = -block.factor.solve(block.h_lp * c_p);
  }
  result->n_influence = j * column;
  result->covariance_ok = true;
}

// `focal_prior_sigma` > 0: the focal scales estimated under their prior
// N(0, s_f^2), weighted as a residual of `focal_weight_px` pixels (the
// pixel noise: ceres::NormalPrior with root information
// focal_weight_px / s_f), its block added after the observations'; 0:
// the focal scales held.
StageResult SolveStage(const RigConstants& constants,
                       const StereoTracks& tracks, const std::vector<bool>& use,
                       const SequenceBundleOptions& options, bool robust,
                       int max_iterations, bool covariance,
                       double focal_prior_sigma, double focal_weight_px,
                       Blocks* blocks) {
  ceres::Problem problem;
  bool any_cam1 = false;
  // A held direction is a constant of the cam1 residuals (a smaller
  // Jacobian), a refined one their block.
  std::optional<std::array<double, 3>> held_direction;
  if (!options.refine_translation_direction) held_direction = blocks->direction;
  std::vector<bool> pose_used(blocks->poses.size(), false);
  for (size_t i = 0; i < tracks.observations.size(); ++i) {
    if (!use[i]) continue;
    const StereoTrackObservation& o = tracks.observations[i];
    ceres::LossFunction* loss =
        robust ? NewLossFunction(options.loss, options.loss_scale_px) : nullptr;
    double* pose = blocks->poses[o.frame].data();
    double* landmark = blocks->landmarks[o.landmark].data();
    pose_used[o.frame] = true;
    ceres::CostFunction* cost = CostFor(constants, o, held_direction);
    double* focal = blocks->focal.data();
    if (o.camera == 0) {
      problem.AddResidualBlock(cost, loss, &blocks->n, pose, landmark, focal);
    } else if (held_direction) {
      any_cam1 = true;
      problem.AddResidualBlock(cost, loss, &blocks->n, pose, landmark, focal,
                               blocks->rotation.data());
    } else {
      any_cam1 = true;
      problem.AddResidualBlock(cost, loss, &blocks->n, pose, landmark, focal,
                               blocks->rotation.data(),
                               blocks->direction.data());
    }
  }
  StageResult result;
  if (problem.NumResidualBlocks() == 0) return result;
  const bool focal = focal_prior_sigma > 0.0;
  if (focal) {
    const ceres::Matrix root_information =
        focal_weight_px / focal_prior_sigma * ceres::Matrix::Identity(2, 2);
    problem.AddResidualBlock(
        new ceres::NormalPrior(root_information, ceres::Vector::Zero(2)),
        nullptr, blocks->focal.data());
  } else {
    problem.SetParameterBlockConstant(blocks->focal.data());
  }
  if (options.refine_n) {
    problem.SetParameterLowerBound(&blocks->n, 0, RefractiveCamera::kMinIndex);
    problem.SetParameterUpperBound(&blocks->n, 0, RefractiveCamera::kMaxIndex);
  } else {
    problem.SetParameterBlockConstant(&blocks->n);
  }
  for (size_t f = 0; f < blocks->poses.size(); ++f) {
    if (!pose_used[f]) continue;
    problem.SetManifold(
        blocks->poses[f].data(),
        new ceres::ProductManifold<ceres::QuaternionManifold,
                                   ceres::EuclideanManifold<3>>());
    if (f == 0) problem.SetParameterBlockConstant(blocks->poses[f].data());
  }
  if (any_cam1) {
    if (!options.refine_rotation) {
      problem.SetParameterBlockConstant(blocks->rotation.data());
    }
    if (options.refine_translation_direction) {
      problem.SetManifold(blocks->direction.data(),
                          new ceres::SphereManifold<3>());
    }
  }

  ceres::Solver::Options solver;
  // The reduced system over the poses, n and the turn is dense where the
  // keyframes are few (n and the turn couple every pose); sparse beyond.
  if (static_cast<int>(blocks->poses.size()) <= kMaxDenseSchurFrames) {
    solver.linear_solver_type = ceres::DENSE_SCHUR;
  } else {
    solver.linear_solver_type = ceres::SPARSE_SCHUR;
    if (!ceres::IsSparseLinearAlgebraLibraryTypeAvailable(
            ceres::SUITE_SPARSE)) {
      solver.sparse_linear_algebra_library_type = ceres::EIGEN_SPARSE;
    }
  }
  auto ordering = std::make_shared<ceres::ParameterBlockOrdering>();
  for (size_t l = 0; l < blocks->landmarks.size(); ++l) {
    double* landmark = blocks->landmarks[l].data();
    if (problem.HasParameterBlock(landmark)) {
      ordering->AddElementToGroup(landmark, 0);
    }
  }
  ordering->AddElementToGroup(&blocks->n, 1);
  ordering->AddElementToGroup(blocks->focal.data(), 1);
  for (size_t f = 0; f < blocks->poses.size(); ++f) {
    if (pose_used[f]) ordering->AddElementToGroup(blocks->poses[f].data(), 1);
  }
  if (any_cam1) {
    ordering->AddElementToGroup(blocks->rotation.data(), 1);
    if (!held_direction) {
      ordering->AddElementToGroup(blocks->direction.data(), 1);
    }
  }
  solver.linear_solver_ordering = ordering;
  solver.max_num_iterations = max_iterations;
  // The least squares converge to rounding (quadratically: 4-7 iterations
  // from stage 1's solution), so the noise-free bundle recovers its
  // unknowns to 1e-9 (sequence_bundle_adjustment_test.cc). The robust
  // stage only sorts the inliers (2 px): under Cauchy's loss Ceres'
  // corrected Gauss-Newton converges linearly, creeping by 1e-6 of the
  // cost per iteration for 100 iterations on a rendered dive, so it ends
  // at Ceres' default relative decrease of 1e-6 (~10 iterations).
  solver.function_tolerance = robust ? 1e-6 : 1e-12;
  solver.gradient_tolerance = 1e-15;
  solver.parameter_tolerance = robust ? 1e-8 : 1e-12;
  solver.num_threads = options.num_threads;
  solver.logging_type = ceres::SILENT;
  ceres::Solve(solver, &problem, &result.summary);

  if (covariance && options.refine_n && result.summary.IsSolutionUsable()) {
    ReducedCovariance(problem, *blocks, any_cam1 && options.refine_rotation,
                      any_cam1 && options.refine_translation_direction, focal,
                      options.num_threads, &result);
  }
  return result;
}

// The residual of one observation at `blocks` with `constants` and the
// translation direction `direction`; false where the port cannot image
// the landmark.
bool EvaluateResidual(const RigConstants& constants,
                      const StereoTrackObservation& o, const Blocks& blocks,
                      const double* direction, double residual[2]) {
  const double* pose = blocks.poses[o.frame].data();
  const double* landmark = blocks.landmarks[o.landmark].data();
  RCM_LENS_MODEL_SWITCH(
      constants.models[o.camera],
      if (o.camera == 0) {
        return Cam0TrackReprojectionError<LensModel>(
            constants.cameras[0], o.pixel)(&blocks.n, pose, landmark,
                                           blocks.focal.data(), residual);
      } return Cam1TrackReprojectionError<LensModel>(constants.cameras[1],
                                                     constants.rotation,
                                                     constants.baseline,
                                                     o.pixel)(
          &blocks.n, pose, landmark, blocks.focal.data(),
          blocks.rotation.data(), direction, residual);)
  return false;
}

// Residual norm (pixels) of one observation at `blocks`; nullopt where the
// port cannot image the landmark.
std::optional<double> ResidualNorm(const RigConstants& constants,
                                   const StereoTrackObservation& o,
                                   const Blocks& blocks) {
  double residual[2];
  if (!EvaluateResidual(constants, o, blocks, blocks.direction.data(),
                        residual)) {
    return std::nullopt;
  }
  return std::hypot(residual[0], residual[1]);
}

// The midpoint of two rays (origins, unit directions) when they meet in
// front of both at an angle of at least `min_angle` radians.
std::optional<Eigen::Vector3d> Triangulate(const Eigen::Vector3d& origin_a,
                                           const Eigen::Vector3d& ray_a,
                                           const Eigen::Vector3d& origin_b,
                                           const Eigen::Vector3d& ray_b,
                                           double min_angle) {
  const double b = ray_a.dot(ray_b);
  if (!(std::acos(std::clamp(b, -1.0, 1.0)) >= min_angle)) return std::nullopt;
  const Eigen::Vector3d w = origin_b - origin_a;
  const double d = ray_a.dot(w);
  const double e = ray_b.dot(w);
  const double denominator = 1.0 - b * b;
  const double s_a = (d - b * e) / denominator;
  const double s_b = (b * d - e) / denominator;
  if (!(s_a > 0.0 && s_b > 0.0)) return std::nullopt;
  return 0.5 * (origin_a + s_a * ray_a + origin_b + s_b * ray_b);
}

// A rig moved by `delta` = [w; dt; left params; right params] (the joint
// covariance's order, calibration_uncertainty.h).
StatusOr<StereoRig> MovedRig(const StereoRig& rig,
                             const Eigen::VectorXd& delta) {
  const int p_l = rig.left().num_params();
  const int p_r = rig.right().num_params();
  const int q = 6 + p_l + p_r;  // the ports' parameters, when delta has them
  std::vector<double> left(rig.left().params(), rig.left().params() + p_l);
  std::vector<double> right(rig.right().params(), rig.right().params() + p_r);
  for (int i = 0; i < p_l && 6 + i < delta.size(); ++i) left[i] += delta[6 + i];
  for (int i = 0; i < p_r && 6 + p_l + i < delta.size(); ++i) {
    right[i] += delta[6 + p_l + i];
  }
  StatusOr<Camera> left_camera = rig.left().WithParams(left.data());
  if (!left_camera.ok()) return left_camera.status();
  StatusOr<Camera> right_camera = rig.right().WithParams(right.data());
  if (!right_camera.ok()) return right_camera.status();
  StatusOr<StereoRig> lenses =
      StereoRig::Create(*left_camera, *right_camera, rig.right_from_left());
  if (!lenses.ok()) return lenses.status();
  StatusOr<StereoRig> moved =
      lenses->WithCam1Moved(delta.segment<3>(0), delta.segment<3>(3));
  if (!moved.ok()) return moved.status();
  if (!rig.ports()) return moved;
  // q = [d_l, a_l, b_l, d_r, a_r, b_r]: each side's air gap and the tilt
  // (N_x / N_z, N_y / N_z) of its normal (calibration_uncertainty.h).
  std::array<FlatPort, 2> ports = {rig.ports()->left, rig.ports()->right};
  if (delta.size() >= q + CalibrationUncertainty::kNumPortParams) {
    for (int c = 0; c < 2; ++c) {
      FlatPort& port = ports[c];
      port.air_gap += delta[q + 3 * c];
      const Eigen::Vector2d tilt =
          Eigen::Vector2d(port.normal.x() / port.normal.z(),
                          port.normal.y() / port.normal.z()) +
          delta.segment<2>(q + 3 * c + 1);
      port.normal = Eigen::Vector3d(tilt.x(), tilt.y(), 1.0).normalized();
    }
  }
  return moved->WithPorts(ports[0], ports[1]);
}

}  // namespace

Status SequenceBundleOptions::Check() const {
  if (!(initial_n >= RefractiveCamera::kMinIndex &&
        initial_n <= RefractiveCamera::kMaxIndex)) {
    return Status::Error("initial n = " + FormatDouble(initial_n) +
                         " is outside [1, 2]");
  }
  if (!(loss_scale_px > 0.0) || !std::isfinite(loss_scale_px)) {
    return Status::Error("loss scale = " + FormatDouble(loss_scale_px) +
                         " px must be positive and finite");
  }
  if (!(systematic_px >= 0.0) || !std::isfinite(systematic_px)) {
    return Status::Error("systematic = " + FormatDouble(systematic_px) +
                         " px must be >= 0 and finite");
  }
  if (!(inlier_threshold_px > 0.0)) {
    return Status::Error(
        "inlier threshold = " + FormatDouble(inlier_threshold_px) +
        " px must be positive");
  }
  if (!(min_triangulation_angle_deg >= 0.0 &&
        min_triangulation_angle_deg < 90.0)) {
    return Status::Error("min triangulation angle = " +
                         FormatDouble(min_triangulation_angle_deg) +
                         " deg must be in [0, 90)");
  }
  for (const auto& [name, value] :
       {std::pair<const char*, double>{"min translation fraction",
                                       min_translation_fraction},
        {"min rotation", min_rotation_deg},
        {"axial cone", axial_cone_deg},
        {"plane thickness", plane_thickness},
        {"plane distance spread", plane_distance_spread}}) {
    if (!(value >= 0.0) || !std::isfinite(value)) {
      return Status::Error(std::string(name) + " = " + FormatDouble(value) +
                           " must be >= 0 and finite");
    }
  }
  if (min_shared_landmarks < 6) {
    return Status::Error(
        "min shared landmarks = " + std::to_string(min_shared_landmarks) +
        " must be at least 6 (the PnP's)");
  }
  if (min_landmark_keyframes < 1) {
    return Status::Error(
        "min landmark keyframes = " + std::to_string(min_landmark_keyframes) +
        " must be >= 1");
  }
  if (max_iterations < 1) {
    return Status::Error("max iterations = " + std::to_string(max_iterations) +
                         " must be at least 1");
  }
  if (!(propagation_eigenvalue_floor >= 0.0 &&
        propagation_eigenvalue_floor < 1.0)) {
    return Status::Error("propagation eigenvalue floor = " +
                         FormatDouble(propagation_eigenvalue_floor) +
                         " must be in [0, 1)");
  }
  if (num_threads < 1) {
    return Status::Error("threads = " + std::to_string(num_threads) +
                         " must be at least 1");
  }
  return Status::Ok();
}

BundleMotionSummary ClassifyBundleMotion(const SequenceBundleState& state,
                                         const SequenceBundleOptions& options) {
  BundleMotionSummary summary;
  const size_t frames = state.cam0_from_world.size();
  if (frames == 0) return summary;
  std::vector<Eigen::Vector3d> centres;
  for (const Rigid3d& pose : state.cam0_from_world) {
    centres.push_back(pose.Inverse().translation);
  }
  const Rigid3d& first = state.cam0_from_world[0];
  const Eigen::Vector3d axis = first.rotation.transpose().col(2);
  summary.translation_span_m = 0.0;
  summary.rotation_span_deg = 0.0;
  for (size_t f = 0; f < frames; ++f) {
    summary.translation_span_m =
        std::max(summary.translation_span_m, (centres[f] - centres[0]).norm());
    summary.rotation_span_deg = std::max(
        summary.rotation_span_deg,
        Eigen::AngleAxisd(first.rotation *
                          state.cam0_from_world[f].rotation.transpose())
                .angle() *
            180.0 / kPi);
  }
  summary.axis_angle_deg = 0.0;
  for (size_t f = 1; f < frames; ++f) {
    const Eigen::Vector3d displacement = centres[f] - centres[0];
    // Displacements of a tenth of the span or more (shorter ones point
    // anywhere at the noise's whim).
    if (!(displacement.norm() >= 0.1 * summary.translation_span_m) ||
        !(displacement.norm() > 0.0)) {
      continue;
    }
    const double cosine = std::abs(displacement.normalized().dot(axis));
    summary.axis_angle_deg = std::max(
        summary.axis_angle_deg, std::acos(std::min(1.0, cosine)) * 180.0 / kPi);
  }
  std::vector<Eigen::Vector3d> points;
  for (const Eigen::Vector3d& point : state.landmarks) {
    if (point.allFinite()) points.push_back(point);
  }
  if (points.size() >= 3) {
    std::vector<double> distances;
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (const Eigen::Vector3d& point : points) {
      distances.push_back((point - centres[0]).norm());
      mean += point;
    }
    mean /= static_cast<double>(points.size());
    std::nth_element(distances.begin(),
                     distances.begin() + distances.size() / 2, distances.end());
    summary.median_distance_m = distances[distances.size() / 2];
    Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
    for (const Eigen::Vector3d& point : points) {
      scatter += (point - mean) * (point - mean).transpose();
    }
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> principal(scatter);
    const Eigen::Vector3d spreads =
        principal.eigenvalues().cwiseMax(0.0).cwiseSqrt();
    summary.plane_thickness = spreads[2] > 0.0 ? spreads[0] / spreads[2] : 0.0;
    const Eigen::Vector3d normal = principal.eigenvectors().col(0);
    double nearest = std::numeric_limits<double>::infinity();
    double farthest = 0.0;
    double sum = 0.0;
    for (const Eigen::Vector3d& centre : centres) {
      const double distance = std::abs(normal.dot(centre - mean));
      nearest = std::min(nearest, distance);
      farthest = std::max(farthest, distance);
      sum += distance;
    }
    const double mean_distance = sum / static_cast<double>(frames);
    summary.plane_distance_spread =
        mean_distance > 0.0 ? (farthest - nearest) / mean_distance : 0.0;
  }
  if (!(summary.rotation_span_deg < options.min_rotation_deg)) {
    return summary;  // a turning rig: kMoving
  }
  if (summary.translation_span_m <
      options.min_translation_fraction * summary.median_distance_m) {
    summary.kind = BundleMotion::kStatic;
  } else if (summary.axis_angle_deg < options.axial_cone_deg) {
    summary.kind = BundleMotion::kAlongAxis;
  } else if (summary.plane_thickness < options.plane_thickness &&
             summary.plane_distance_spread < options.plane_distance_spread) {
    summary.kind = BundleMotion::kOnePlane;
  }
  return summary;
}

std::string BundleMotionSummary::Describe() const {
  const std::string turn =
      "turns by " + FormatFixed(rotation_span_deg, 1) + " deg";
  switch (kind) {
    case BundleMotion::kStatic:
      return "the rig does not move: its keyframes lie within " +
             FormatFixed(1000.0 * translation_span_m, 0) +
             " mm of the first (landmarks " +
             FormatFixed(median_distance_m, 1) + " m away) and it " + turn;
    case BundleMotion::kAlongAxis:
      return "the rig moves only along its optical axis (within " +
             FormatFixed(axis_angle_deg, 1) + " deg, over " +
             FormatFixed(translation_span_m, 2) + " m) and " + turn;
    case BundleMotion::kOnePlane:
      return "the rig sees one plane from one distance (plane thickness " +
             FormatFixed(100.0 * plane_thickness, 1) +
             " % of its extent, distance spread " +
             FormatFixed(100.0 * plane_distance_spread, 1) + " %) and " + turn;
    case BundleMotion::kMoving:
      break;
  }
  return "the rig moves " + FormatFixed(translation_span_m, 2) + " m and " +
         turn;
}

StatusOr<SequenceBundleAdjustment> SequenceBundleAdjustment::Create(
    const StereoRig& rig, const SequenceBundleOptions& options) {
  RCM_RETURN_IF_ERROR(options.Check().WithContext("bundle options"));
  if (!(rig.Baseline() > 0.0)) {
    return Status::Error("the rig has no baseline: nothing gives the scale");
  }
  return SequenceBundleAdjustment(rig, options);
}

StatusOr<SequenceBundleState> SequenceBundleAdjustment::Initialize(
    const StereoTracks& tracks) const {
  RCM_RETURN_IF_ERROR(tracks.Check());
  // The epipolar seed (options), thin ports.
  double n0 = options_.initial_n;
  Eigen::Vector3d w0 = Eigen::Vector3d::Zero();
  if (options_.epipolar_seed && !rig_.HasThickPort()) {
    // Each keyframe's left and right observation of one landmark, next to
    // each other once sorted by (keyframe, landmark, camera).
    std::vector<const StereoTrackObservation*> sorted;
    for (const StereoTrackObservation& o : tracks.observations) {
      sorted.push_back(&o);
    }
    std::sort(
        sorted.begin(), sorted.end(),
        [](const StereoTrackObservation* a, const StereoTrackObservation* b) {
          return std::tie(a->frame, a->landmark, a->camera) <
                 std::tie(b->frame, b->landmark, b->camera);
        });
    std::vector<StereoCorrespondence> pairs;
    for (size_t k = 0; k + 1 < sorted.size(); ++k) {
      const StereoTrackObservation& left = *sorted[k];
      const StereoTrackObservation& right = *sorted[k + 1];
      if (left.camera != 0 || right.camera != 1 || left.frame != right.frame ||
          left.landmark != right.landmark) {
        continue;
      }
      StereoCorrespondence pair;
      pair.frame = left.frame;
      pair.left_pixel = left.pixel;
      pair.right_pixel = right.pixel;
      pairs.push_back(pair);
    }
    // The calibration as given, without its uncertainty: a free turn.
    StatusOr<StereoRig> plain =
        StereoRig::Create(rig_.left(), rig_.right(), rig_.right_from_left());
    RefinementOptions seed;
    seed.refine_rotation = true;
    seed.num_threads = options_.num_threads;
    if (plain.ok()) {
      const StatusOr<RefinementSummary> epipolar =
          RefineRefractiveIndex(*plain, pairs, seed);
      if (epipolar.ok() && epipolar->rotation) {
        if (options_.refine_n) n0 = epipolar->n;
        w0 = epipolar->rotation->angle_axis;
      }
    }
  }
  StatusOr<StereoRig> seeded = rig_.WithCam1Moved(w0);
  if (!seeded.ok()) return seeded.status();
  // Bearings in the water at n0.
  std::array<std::optional<RefractiveCamera>, 2> cameras;
  for (int c = 0; c < 2; ++c) {
    const Camera& camera = c == 0 ? rig_.left() : rig_.right();
    std::optional<FlatPort> port;
    if (rig_.ports()) port = c == 0 ? rig_.ports()->left : rig_.ports()->right;
    StatusOr<RefractiveCamera> refractive =
        port && !port->IsThin() ? RefractiveCamera::CreateWithPort(
                                      camera, n0, *port, kInitialReferenceDepth)
                                : RefractiveCamera::Create(camera, n0);
    if (!refractive.ok()) return refractive.status();
    cameras[c] = *refractive;
  }
  const Eigen::Matrix3d R10 = seeded->right_from_left().rotation;
  const Eigen::Vector3d t10 = seeded->right_from_left().translation;
  const Eigen::Vector3d cam1_in_cam0 = -R10.transpose() * t10;
  const double min_angle = options_.min_triangulation_angle_deg * kPi / 180.0;

  // Each observation's bearing in its camera (NaN where the lens cannot
  // undistort it), and the observations by keyframe.
  const size_t count = tracks.observations.size();
  std::vector<Eigen::Vector3d> bearings(count);
  std::vector<std::vector<int>> by_frame(tracks.num_frames);
  for (size_t i = 0; i < count; ++i) {
    const StereoTrackObservation& o = tracks.observations[i];
    const std::optional<Eigen::Vector3d> bearing =
        cameras[o.camera]->BearingInWaterFromImage(o.pixel);
    bearings[i] = bearing ? bearing->normalized()
                          : Eigen::Vector3d::Constant(
                                std::numeric_limits<double>::quiet_NaN());
    by_frame[o.frame].push_back(static_cast<int>(i));
  }

  SequenceBundleState state;
  state.n = n0;
  state.cam1_rotation = w0;
  state.cam1_direction = rig_.right_from_left().translation.normalized();
  state.cam0_from_world.assign(tracks.num_frames, Rigid3d());
  state.landmarks.assign(
      tracks.num_landmarks,
      Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN()));
  // The rays of each landmark seen from placed keyframes, in the world.
  struct Ray {
    Eigen::Vector3d origin;
    Eigen::Vector3d direction;
  };
  std::vector<std::vector<Ray>> rays(tracks.num_landmarks);

  for (int f = 0; f < tracks.num_frames; ++f) {
    if (f > 0) {
      // The PnP of the placed landmarks this keyframe's left camera sees.
      std::vector<cv::Point3d> object;
      std::vector<cv::Point2d> image;
      for (int i : by_frame[f]) {
        const StereoTrackObservation& o = tracks.observations[i];
        const Eigen::Vector3d& bearing = bearings[i];
        if (o.camera != 0 || !bearing.allFinite() || !(bearing.z() > 0.0)) {
          continue;
        }
        const Eigen::Vector3d& point = state.landmarks[o.landmark];
        if (!point.allFinite()) continue;
        object.emplace_back(point.x(), point.y(), point.z());
        image.emplace_back(bearing.x() / bearing.z(),
                           bearing.y() / bearing.z());
      }
      if (static_cast<int>(object.size()) < options_.min_shared_landmarks) {
        return Status::Error(
            "keyframe " + std::to_string(f) + " sees " +
            std::to_string(object.size()) +
            " landmarks of the keyframes before it (at least " +
            std::to_string(options_.min_shared_landmarks) +
            " place it): the tracks are broken there");
      }
      // Seeded by the previous keyframe's pose (a rig moves little between
      // keyframes); RANSAC at kPnpThresholdPx of the left focal length.
      const Rigid3d& previous = state.cam0_from_world[f - 1];
      cv::Mat rotation_matrix(3, 3, CV_64F);
      for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c) {
          rotation_matrix.at<double>(r, c) = previous.rotation(r, c);
        }
      }
      cv::Mat rvec;
      cv::Rodrigues(rotation_matrix, rvec);
      cv::Mat tvec = (cv::Mat_<double>(3, 1) << previous.translation.x(),
                      previous.translation.y(), previous.translation.z());
      const cv::Mat identity = cv::Mat::eye(3, 3, CV_64F);
      std::vector<int> inliers;
      const double threshold = kPnpThresholdPx / rig_.left().fx();
      const bool found = cv::solvePnPRansac(
          object, image, identity, cv::noArray(), rvec, tvec,
          /*useExtrinsicGuess=*/true, /*iterationsCount=*/200, threshold,
          /*confidence=*/0.999, inliers, cv::SOLVEPNP_ITERATIVE);
      if (!found ||
          static_cast<int>(inliers.size()) < options_.min_shared_landmarks) {
        return Status::Error("keyframe " + std::to_string(f) +
                             ": no pose agrees with the landmarks it shares "
                             "with the keyframes before it");
      }
      std::vector<cv::Point3d> inlier_object;
      std::vector<cv::Point2d> inlier_image;
      for (int k : inliers) {
        inlier_object.push_back(object[k]);
        inlier_image.push_back(image[k]);
      }
      cv::solvePnP(inlier_object, inlier_image, identity, cv::noArray(), rvec,
                   tvec, /*useExtrinsicGuess=*/true, cv::SOLVEPNP_ITERATIVE);
      cv::Rodrigues(rvec, rotation_matrix);
      Rigid3d pose;
      for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c) {
          pose.rotation(r, c) = rotation_matrix.at<double>(r, c);
        }
        pose.translation[r] = tvec.at<double>(r);
      }
      state.cam0_from_world[f] = pose;
    }
    // This keyframe's rays, then the landmarks they place: each from the
    // two of its rays at the widest angle (a stereo pair, or two left
    // views once their poses are known).
    const Rigid3d world_from_cam0 = state.cam0_from_world[f].Inverse();
    std::vector<int> seen;
    for (int i : by_frame[f]) {
      const StereoTrackObservation& o = tracks.observations[i];
      if (!bearings[i].allFinite()) continue;
      Ray ray;
      if (o.camera == 0) {
        ray.origin = world_from_cam0.translation;
        ray.direction = world_from_cam0.rotation * bearings[i];
      } else {
        ray.origin = world_from_cam0 * cam1_in_cam0;
        ray.direction =
            world_from_cam0.rotation * (R10.transpose() * bearings[i]);
      }
      rays[o.landmark].push_back(ray);
      seen.push_back(o.landmark);
    }
    for (int l : seen) {
      if (state.landmarks[l].allFinite()) continue;
      const std::vector<Ray>& r = rays[l];
      double widest = -1.0;
      std::optional<Eigen::Vector3d> point;
      for (size_t a = 0; a < r.size(); ++a) {
        for (size_t b = a + 1; b < r.size(); ++b) {
          const double angle = std::acos(
              std::clamp(r[a].direction.dot(r[b].direction), -1.0, 1.0));
          if (angle <= widest) continue;
          const std::optional<Eigen::Vector3d> candidate =
              Triangulate(r[a].origin, r[a].direction, r[b].origin,
                          r[b].direction, min_angle);
          if (candidate) {
            widest = angle;
            point = candidate;
          }
        }
      }
      if (point) state.landmarks[l] = *point;
    }
  }
  return state;
}

StatusOr<SequenceBundleResult> SequenceBundleAdjustment::Solve(
    const StereoTracks& tracks) const {
  StatusOr<SequenceBundleState> initial = Initialize(tracks);
  if (!initial.ok()) return initial.status();
  return Solve(tracks, *initial);
}

StatusOr<SequenceBundleResult> SequenceBundleAdjustment::Solve(
    const StereoTracks& tracks, const SequenceBundleState& initial) const {
  RCM_RETURN_IF_ERROR(tracks.Check());
  if (static_cast<int>(initial.cam0_from_world.size()) != tracks.num_frames ||
      static_cast<int>(initial.landmarks.size()) != tracks.num_landmarks) {
    return Status::Error(
        "the initial state has " +
        std::to_string(initial.cam0_from_world.size()) + " poses and " +
        std::to_string(initial.landmarks.size()) + " landmarks, the tracks " +
        std::to_string(tracks.num_frames) + " and " +
        std::to_string(tracks.num_landmarks));
  }
  if (!(initial.n >= RefractiveCamera::kMinIndex &&
        initial.n <= RefractiveCamera::kMaxIndex)) {
    return Status::Error("the initial n = " + FormatDouble(initial.n) +
                         " is outside [1, 2]");
  }
  const RigConstants constants = ConstantsOf(rig_);
  Blocks blocks = BlocksOf(initial);
  if (!options_.refine_translation_direction) {
    for (int i = 0; i < 3; ++i) blocks.direction[i] = constants.direction[i];
  }
  const size_t count = tracks.observations.size();
  std::vector<bool> use(count, false);
  // Landmarks seen from too few keyframes are left out (the options).
  if (options_.min_landmark_keyframes > 1) {
    std::vector<std::pair<int, int>> seen;  // (landmark, keyframe)
    seen.reserve(count);
    for (const StereoTrackObservation& o : tracks.observations) {
      seen.emplace_back(o.landmark, o.frame);
    }
    std::sort(seen.begin(), seen.end());
    seen.erase(std::unique(seen.begin(), seen.end()), seen.end());
    std::vector<int> keyframes(tracks.num_landmarks, 0);
    for (const auto& [landmark, frame] : seen) ++keyframes[landmark];
    for (int l = 0; l < tracks.num_landmarks; ++l) {
      if (keyframes[l] < options_.min_landmark_keyframes) {
        blocks.placed[l] = false;
      }
    }
  }
  // The observations of placed landmarks that the initial state can
  // image (Ceres starts from a point where every residual is defined).
  for (size_t i = 0; i < count; ++i) {
    use[i] =
        blocks.placed[tracks.observations[i].landmark] &&
        ResidualNorm(constants, tracks.observations[i], blocks).has_value();
  }

  SequenceBundleResult result;
  result.num_observations = static_cast<int64_t>(count);
  result.num_frames = tracks.num_frames;

  // The focal scales, estimated under the calibration's focal drift prior
  // s_f (the options), weighted in pixels of the noise: the loss scale in
  // stage 1, then the noise stage 1's inliers show.
  const std::optional<CalibrationUncertainty>& uncertainty =
      rig_.calibration_uncertainty();
  const double focal_prior_sigma = options_.self_calibrate_focal && uncertainty
                                       ? uncertainty->focal_drift_sigma
                                       : 0.0;
  double focal_weight_px = options_.loss_scale_px;

  // Stage 1: robust.
  const StageResult stage1 =
      SolveStage(constants, tracks, use, options_, /*robust=*/true,
                 options_.max_iterations, /*covariance=*/false,
                 focal_prior_sigma, focal_weight_px, &blocks);
  if (!stage1.summary.IsSolutionUsable()) {
    return Status::Error("the bundle's robust stage failed: " +
                         stage1.summary.message);
  }
  result.iterations += static_cast<int>(stage1.summary.iterations.size());
  result.motion = ClassifyBundleMotion(StateOf(blocks), options_);
  if (result.motion.kind != BundleMotion::kMoving && options_.refine_n &&
      !options_.allow_degenerate_motion) {
    return Status::Error(result.motion.Describe() +
                         ": motion cannot separate n from cam1's turn, use "
                         "the epipolar estimate");
  }

  // Stage 2: least squares over the inliers, of landmarks seen from two
  // viewpoints at least ...
  std::vector<int> inlier_views(tracks.num_landmarks, 0);
  double inlier_squares = 0.0;
  int64_t inliers = 0;
  for (size_t i = 0; i < count; ++i) {
    if (!use[i]) continue;
    const std::optional<double> norm =
        ResidualNorm(constants, tracks.observations[i], blocks);
    use[i] = norm && *norm <= options_.inlier_threshold_px;
    if (use[i]) {
      ++inlier_views[tracks.observations[i].landmark];
      inlier_squares += *norm * *norm;
      ++inliers;
    }
  }
  {
    // The pixel noise they show, per coordinate, over their degrees of
    // freedom (each landmark takes 3, each keyframe but the first 6).
    int64_t landmarks = 0;
    for (int l = 0; l < tracks.num_landmarks; ++l) {
      landmarks += inlier_views[l] > 0 ? 1 : 0;
    }
    const double dof =
        2.0 * inliers - 3.0 * landmarks - 6.0 * (tracks.num_frames - 1) - 4.0;
    if (dof > 0.0 && inlier_squares > 0.0) {
      focal_weight_px = std::sqrt(inlier_squares / dof);
    }
  }
  // ... and under an angle of at least min_triangulation_angle_deg: a
  // landmark whose rays are parallel has no depth, and the covariance no
  // rank. The least squares can send a landmark of little parallax off
  // to thousands of kilometres (a Monte Carlo trial with a lens change
  // did), so the angles are checked again after each solve, and the solve
  // repeated without the landmarks that failed (at most 3 rounds).
  const auto drop_narrow = [&]() {
    const SequenceBundleState current = StateOf(blocks);
    const Eigen::Matrix3d R10 = rig_.right_from_left().rotation;
    const Eigen::Vector3d cam1_in_cam0 =
        -constants.baseline * R10.transpose() * current.cam1_direction;
    std::vector<std::vector<Eigen::Vector3d>> rays(tracks.num_landmarks);
    for (size_t i = 0; i < count; ++i) {
      if (!use[i]) continue;
      const StereoTrackObservation& o = tracks.observations[i];
      const Rigid3d world_from_cam0 =
          current.cam0_from_world[o.frame].Inverse();
      const Eigen::Vector3d centre = o.camera == 0
                                         ? world_from_cam0.translation
                                         : world_from_cam0 * cam1_in_cam0;
      rays[o.landmark].push_back(
          (current.landmarks[o.landmark] - centre).normalized());
    }
    const double min_cosine =
        std::cos(options_.min_triangulation_angle_deg * kPi / 180.0);
    for (int l = 0; l < tracks.num_landmarks; ++l) {
      bool wide = false;
      for (size_t a = 0; a < rays[l].size() && !wide; ++a) {
        for (size_t b = a + 1; b < rays[l].size() && !wide; ++b) {
          wide = rays[l][a].dot(rays[l][b]) <= min_cosine;
        }
      }
      if (!wide) inlier_views[l] = 0;
    }
    int dropped = 0;
    for (size_t i = 0; i < count; ++i) {
      if (use[i] && inlier_views[tracks.observations[i].landmark] < 2) {
        use[i] = false;
      }
    }
    for (int l = 0; l < tracks.num_landmarks; ++l) {
      if (inlier_views[l] < 2 && blocks.placed[l]) {
        blocks.placed[l] = false;
        ++dropped;
      }
    }
    return dropped;
  };
  drop_narrow();
  StageResult stage2;
  // Stage 2's least squares over the current inliers, with the covariance.
  const auto solve_least_squares = [&]() {
    stage2 = SolveStage(constants, tracks, use, options_, /*robust=*/false,
                        options_.max_iterations, /*covariance=*/true,
                        focal_prior_sigma, focal_weight_px, &blocks);
    if (!stage2.summary.IsSolutionUsable()) {
      return Status::Error("the bundle's least squares failed: " +
                           stage2.summary.message);
    }
    result.iterations += static_cast<int>(stage2.summary.iterations.size());
    return Status::Ok();
  };
  for (int round = 0;; ++round) {
    RCM_RETURN_IF_ERROR(solve_least_squares());
    if (round == 2 || drop_narrow() == 0) break;
  }
  result.num_inliers = std::count(use.begin(), use.end(), true);
  result.num_landmarks = static_cast<int>(
      std::count(blocks.placed.begin(), blocks.placed.end(), true));

  // Counts and the pixel noise.
  int used_frames = 0;
  {
    std::vector<bool> frame_used(tracks.num_frames, false);
    for (size_t i = 0; i < count; ++i) {
      if (use[i]) frame_used[tracks.observations[i].frame] = true;
    }
    used_frames = static_cast<int>(
        std::count(frame_used.begin(), frame_used.end(), true));
  }
  const int64_t unknowns =
      (options_.refine_n ? 1 : 0) + (options_.refine_rotation ? 3 : 0) +
      (options_.refine_translation_direction ? 2 : 0) +
      6 * std::max(0, used_frames - 1) + 3 * int64_t{result.num_landmarks};
  const int64_t residuals = 2 * result.num_inliers;
  if (residuals <= unknowns) {
    return Status::Error("the bundle has " + std::to_string(residuals) +
                         " inlier residuals for " + std::to_string(unknowns) +
                         " unknowns: too few tracks");
  }
  // The observations' share of the cost: the focal prior's taken out (its
  // two residuals and the two scales they hold cancel in the count).
  const auto pixel_sigma = [&]() {
    const double prior_cost =
        focal_prior_sigma > 0.0
            ? 0.5 * std::pow(focal_weight_px / focal_prior_sigma, 2) *
                  (blocks.focal[0] * blocks.focal[0] +
                   blocks.focal[1] * blocks.focal[1])
            : 0.0;
    return std::sqrt(2.0 *
                     std::max(0.0, stage2.summary.final_cost - prior_cost) /
                     static_cast<double>(residuals - unknowns));
  };
  result.pixel_sigma = pixel_sigma();
  // The focal prior weighs as a residual of the pixel noise: stage 1's
  // inliers undercount it (their landmarks' degrees of freedom), so the
  // least squares run once more at the noise they showed, and the
  // covariance is taken there.
  if (focal_prior_sigma > 0.0 &&
      std::abs(result.pixel_sigma / focal_weight_px - 1.0) > 0.01) {
    focal_weight_px = result.pixel_sigma;
    RCM_RETURN_IF_ERROR(solve_least_squares());
    result.pixel_sigma = pixel_sigma();
  }
  if (!options_.refine_n) {
    // n held (the options): the trajectory and the turn, nothing of n.
    result.n = blocks.n;
    result.sigma_n = result.sigma_n_noise = result.sigma_n_calibration = 0.0;
    result.state = StateOf(blocks);
    result.motion = ClassifyBundleMotion(result.state, options_);
    return result;
  }
  // n at the upper bound 2 (the estimators' one rule and message,
  // refinement_options.h); with sigma_n below, once it is known.
  RCM_RETURN_IF_ERROR(CheckNotPinnedAtUpperBound(blocks.n));
  if (!stage2.covariance_ok || !(stage2.c_nn > 0.0)) {
    return Status::Error(
        "the bundle's covariance is singular: the tracks do not observe n "
        "(a rig that does not move, or one plane at one depth)");
  }
  const double s2 = result.pixel_sigma * result.pixel_sigma;
  result.n = blocks.n;
  // With the focal scales estimated, the noise's share is n's variance
  // with them held, and the rest (what the focal prior leaves) joins the
  // calibration's share below.
  const bool focal = focal_prior_sigma > 0.0;
  result.sigma_n_noise =
      std::sqrt(s2 * (focal ? stage2.c_nn_focal_held : stage2.c_nn));
  const double focal_variance =
      focal ? std::max(0.0, s2 * (stage2.c_nn - stage2.c_nn_focal_held)) : 0.0;
  if (focal) {
    result.focal_scales_estimated = true;
    result.focal_scale_covariance = s2 * stage2.c_ff;
    result.n_focal_scale_covariance = s2 * stage2.c_nf;
    for (int c = 0; c < 2; ++c) {
      const double product = stage2.c_nn * stage2.c_ff(c, c);
      result.correlation_n_focal_scales[c] =
          product > 0.0 ? stage2.c_nf[c] / std::sqrt(product) : 0.0;
    }
  }
  if (options_.refine_rotation) {
    result.rotation_covariance = s2 * stage2.c_ww;
    result.n_rotation_covariance = s2 * stage2.c_nw;
    const Eigen::Matrix3d c_ww = stage2.c_ww;
    const double explained =
        stage2.c_nw.dot(c_ww.ldlt().solve(stage2.c_nw)) / stage2.c_nn;
    result.correlation_n_rotation = std::sqrt(std::clamp(explained, 0.0, 1.0));
    for (int i = 0; i < 3; ++i) {
      const double product = stage2.c_nn * stage2.c_ww(i, i);
      result.correlation_n_rotation_components[i] =
          product > 0.0 ? stage2.c_nw[i] / std::sqrt(product) : 0.0;
    }
  }
  result.state = StateOf(blocks);
  result.motion = ClassifyBundleMotion(result.state, options_);

  // The calibration's remaining uncertainty (header).
  double calibration_variance = focal_variance;
  if (options_.propagate_calibration && uncertainty) {
    const int p_l = rig_.left().num_params();
    const int p_r = rig_.right().num_params();
    // The focal prior is the bundle's own when it estimates the scales:
    // taken back out of the lenses' covariances it propagates.
    const Eigen::MatrixXd joint =
        focal ? uncertainty
                    ->WithoutFocalDrift(Eigen::Map<const Eigen::VectorXd>(
                                            rig_.left().params(), p_l),
                                        Eigen::Map<const Eigen::VectorXd>(
                                            rig_.right().params(), p_r))
                    .JointCovariance()
              : uncertainty->JointCovariance();
    // x = [w; dt; left params; right params; q]: the joint covariance's
    // rows of those that it has (a lens without a covariance is exact; the
    // ports' q of a thick port's rig, as the refine estimator's
    // propagation has them).
    std::vector<int> index;
    for (int i = 0; i < 6; ++i) index.push_back(i);
    if (uncertainty->left_lens_covariance.size() > 0) {
      for (int i = 0; i < p_l; ++i) index.push_back(6 + i);
    }
    if (uncertainty->right_lens_covariance.size() > 0) {
      for (int i = 0; i < p_r; ++i) index.push_back(6 + p_l + i);
    }
    const bool ports =
        uncertainty->port_covariance.size() > 0 && rig_.HasThickPort() &&
        joint.rows() ==
            static_cast<Eigen::Index>(index.size() +
                                      CalibrationUncertainty::kNumPortParams);
    const int size =
        6 + p_l + p_r + (ports ? CalibrationUncertainty::kNumPortParams : 0);
    if (ports) {
      for (int k = 0; k < CalibrationUncertainty::kNumPortParams; ++k) {
        index.push_back(6 + p_l + p_r + k);
      }
    }
    Eigen::MatrixXd held = Eigen::MatrixXd::Zero(size, size);
    for (size_t a = 0; a < index.size(); ++a) {
      for (size_t b = 0; b < index.size(); ++b) {
        held(index[a], index[b]) = joint(a, b);
      }
    }
    // The observations' rows, then the focal prior's two (which no move of
    // the rig changes).
    const Eigen::Index prior_rows = focal ? 2 : 0;
    if (stage2.n_influence.size() !=
        2 * static_cast<Eigen::Index>(result.num_inliers) + prior_rows) {
      return Status::Error(
          "the calibration propagation lost the residuals' order");
    }
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(held);
    const double largest = eigen.eigenvalues().maxCoeff();
    for (int k = 0; k < held.rows(); ++k) {
      const double lambda = eigen.eigenvalues()[k];
      if (!(lambda > options_.propagation_eigenvalue_floor * largest) ||
          !(lambda > 0.0)) {
        continue;
      }
      const Eigen::VectorXd step =
          std::sqrt(lambda) * eigen.eigenvectors().col(k);
      // dr = (r(+k) - r(-k)) / 2 over the inliers, at the solution.
      Eigen::VectorXd moved_residuals[2];
      for (int sign = 0; sign < 2; ++sign) {
        StatusOr<StereoRig> moved = MovedRig(
            rig_, sign == 0 ? Eigen::VectorXd(step) : Eigen::VectorXd(-step));
        if (!moved.ok()) {
          return moved.status().WithContext(
              "the calibration propagation's moved rig");
        }
        const RigConstants moved_constants = ConstantsOf(*moved);
        // A held direction is the moved rig's; a refined one the solution's.
        const double* direction = options_.refine_translation_direction
                                      ? blocks.direction.data()
                                      : moved_constants.direction.data();
        Eigen::VectorXd& residuals = moved_residuals[sign];
        residuals = Eigen::VectorXd::Zero(stage2.n_influence.size());
        Eigen::Index row = 0;
        for (size_t i = 0; i < count; ++i) {
          if (!use[i]) continue;
          double residual[2];
          if (!EvaluateResidual(moved_constants, tracks.observations[i], blocks,
                                direction, residual)) {
            return Status::Error(
                "the calibration propagation's moved rig cannot image "
                "landmark " +
                std::to_string(tracks.observations[i].landmark));
          }
          residuals[row++] = residual[0];
          residuals[row++] = residual[1];
        }
      }
      const double dn = -stage2.n_influence.dot(
          0.5 * (moved_residuals[0] - moved_residuals[1]));
      calibration_variance += dn * dn;
      ++result.propagation_directions;
    }
  }
  result.sigma_n_calibration = std::sqrt(calibration_variance);

  // The tracks' systematic floor (header): dn_k = -systematic_px v . phi_k
  // for each coefficient of each camera's field on u and on v.
  double systematic_variance = 0.0;
  if (options_.systematic_px > 0.0) {
    // sum_i v_i phi_k(x_i, y_i), per camera and pixel coordinate.
    double sums[2][2][6] = {};
    const double scale[2][2] = {
        {2.0 / rig_.left().width(), 2.0 / rig_.left().height()},
        {2.0 / rig_.right().width(), 2.0 / rig_.right().height()}};
    Eigen::Index row = 0;
    for (size_t i = 0; i < count; ++i) {
      if (!use[i]) continue;
      const StereoTrackObservation& o = tracks.observations[i];
      const double x = o.pixel.x() * scale[o.camera][0] - 1.0;
      const double y = o.pixel.y() * scale[o.camera][1] - 1.0;
      const double phi[6] = {1.0, x, y, x * x, x * y, y * y};
      for (int j = 0; j < 2; ++j) {
        const double v = stage2.n_influence[row++];
        for (int k = 0; k < 6; ++k) sums[o.camera][j][k] += v * phi[k];
      }
    }
    for (const auto& camera : sums) {
      for (const auto& coordinate : camera) {
        for (const double sum : coordinate) {
          systematic_variance += std::pow(options_.systematic_px * sum, 2);
        }
      }
    }
  }
  result.sigma_n_systematic = std::sqrt(systematic_variance);
  result.sigma_n = std::sqrt(result.sigma_n_noise * result.sigma_n_noise +
                             calibration_variance + systematic_variance);
  RCM_RETURN_IF_ERROR(CheckNotPinnedAtUpperBound(result.n, result.sigma_n));
  return result;
}

}  // namespace rcm
