#include "rcm/estimation/sequence_bundle_adjustment.h"

#include <ceres/covariance.h>
#include <ceres/manifold.h>
#include <ceres/ordered_groups.h>
#include <ceres/problem.h>
#include <ceres/product_manifold.h>
#include <ceres/rotation.h>
#include <ceres/solver.h>
#include <ceres/sphere_manifold.h>
#include <glog/logging.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <memory>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <optional>
#include <utility>

#include "rcm/camera/camera.h"
#include "rcm/camera/refractive_camera.h"
#include "rcm/util/number_format.h"

namespace rcm {
namespace {

constexpr double kPi = 3.14159265358979323846;
// The reference depth at which a thick port's camera is made central for
// the initial bearings, metres (RefractiveCamera::CreateWithPort): the
// bundle then projects through the exact port.
constexpr double kInitialReferenceDepth = 2.0;
// n this close to the upper bound is pinned there.
constexpr double kBoundTolerance = 1e-9;
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

ceres::CostFunction* CostFor(const RigConstants& constants,
                             const StereoTrackObservation& observation) {
  const int c = observation.camera;
  RCM_LENS_MODEL_SWITCH(
      constants.models[c],
      if (c == 0) {
        return Cam0TrackReprojectionError<LensModel>::Create(
            constants.cameras[0], observation.pixel);
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
};

StageResult SolveStage(const RigConstants& constants,
                       const StereoTracks& tracks, const std::vector<bool>& use,
                       const SequenceBundleOptions& options, bool robust,
                       int max_iterations, bool covariance, Blocks* blocks,
                       bool gauss_newton = false) {
  ceres::Problem problem;
  bool any_cam1 = false;
  std::vector<bool> pose_used(blocks->poses.size(), false);
  for (size_t i = 0; i < tracks.observations.size(); ++i) {
    if (!use[i]) continue;
    const StereoTrackObservation& o = tracks.observations[i];
    ceres::LossFunction* loss =
        robust ? NewLossFunction(options.loss, options.loss_scale_px) : nullptr;
    double* pose = blocks->poses[o.frame].data();
    double* landmark = blocks->landmarks[o.landmark].data();
    pose_used[o.frame] = true;
    if (o.camera == 0) {
      problem.AddResidualBlock(CostFor(constants, o), loss, &blocks->n, pose,
                               landmark);
    } else {
      any_cam1 = true;
      problem.AddResidualBlock(CostFor(constants, o), loss, &blocks->n, pose,
                               landmark, blocks->rotation.data(),
                               blocks->direction.data());
    }
  }
  StageResult result;
  if (problem.NumResidualBlocks() == 0) return result;
  problem.SetParameterLowerBound(&blocks->n, 0, RefractiveCamera::kMinIndex);
  problem.SetParameterUpperBound(&blocks->n, 0, RefractiveCamera::kMaxIndex);
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
    } else {
      problem.SetParameterBlockConstant(blocks->direction.data());
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
  for (size_t f = 0; f < blocks->poses.size(); ++f) {
    if (pose_used[f]) ordering->AddElementToGroup(blocks->poses[f].data(), 1);
  }
  if (any_cam1) {
    ordering->AddElementToGroup(blocks->rotation.data(), 1);
    ordering->AddElementToGroup(blocks->direction.data(), 1);
  }
  solver.linear_solver_ordering = ordering;
  solver.max_num_iterations = max_iterations;
  if (gauss_newton) {
    // Steps from a solution to the nearby one of a moved rig: undamped.
    solver.initial_trust_region_radius = 1e16;
  }
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

  if (covariance && result.summary.IsSolutionUsable()) {
    ceres::Covariance::Options covariance_options;
    covariance_options.algorithm_type = ceres::SPARSE_QR;
    if (!ceres::IsSparseLinearAlgebraLibraryTypeAvailable(
            ceres::SUITE_SPARSE)) {
      covariance_options.sparse_linear_algebra_library_type =
          ceres::EIGEN_SPARSE;
    }
    covariance_options.num_threads = options.num_threads;
    ceres::Covariance estimator(covariance_options);
    const bool rotation = any_cam1 && options.refine_rotation;
    std::vector<std::pair<const double*, const double*>> pairs = {
        {&blocks->n, &blocks->n}};
    if (rotation) {
      pairs.push_back({&blocks->n, blocks->rotation.data()});
      pairs.push_back({blocks->rotation.data(), blocks->rotation.data()});
    }
    if (estimator.Compute(pairs, &problem)) {
      result.covariance_ok =
          estimator.GetCovarianceBlock(&blocks->n, &blocks->n, &result.c_nn);
      if (rotation) {
        Eigen::Matrix<double, 3, 3, Eigen::RowMajor> ww;
        result.covariance_ok =
            result.covariance_ok &&
            estimator.GetCovarianceBlock(&blocks->n, blocks->rotation.data(),
                                         result.c_nw.data()) &&
            estimator.GetCovarianceBlock(blocks->rotation.data(),
                                         blocks->rotation.data(), ww.data());
        result.c_ww = ww;
      }
    }
  }
  return result;
}

// Residual norm (pixels) of one observation at `blocks`; nullopt where the
// port cannot image the landmark.
std::optional<double> ResidualNorm(const RigConstants& constants,
                                   const StereoTrackObservation& o,
                                   Blocks* blocks) {
  std::unique_ptr<ceres::CostFunction> cost(CostFor(constants, o));
  const double* parameters[5] = {&blocks->n, blocks->poses[o.frame].data(),
                                 blocks->landmarks[o.landmark].data(),
                                 blocks->rotation.data(),
                                 blocks->direction.data()};
  double residuals[2];
  if (!cost->Evaluate(parameters, residuals, nullptr)) return std::nullopt;
  return std::hypot(residuals[0], residuals[1]);
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
  if (rig.ports())
    return moved->WithPorts(rig.ports()->left, rig.ports()->right);
  return moved;
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
  if (min_shared_landmarks < 6) {
    return Status::Error(
        "min shared landmarks = " + std::to_string(min_shared_landmarks) +
        " must be at least 6 (the PnP's)");
  }
  if (max_iterations < 1 || max_propagation_iterations < 1) {
    return Status::Error("the iteration limits must be at least 1");
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
  // Bearings in the water at the initial n.
  std::array<std::optional<RefractiveCamera>, 2> cameras;
  for (int c = 0; c < 2; ++c) {
    const Camera& camera = c == 0 ? rig_.left() : rig_.right();
    std::optional<FlatPort> port;
    if (rig_.ports()) port = c == 0 ? rig_.ports()->left : rig_.ports()->right;
    StatusOr<RefractiveCamera> refractive =
        port && !port->IsThin()
            ? RefractiveCamera::CreateWithPort(camera, options_.initial_n,
                                               *port, kInitialReferenceDepth)
            : RefractiveCamera::Create(camera, options_.initial_n);
    if (!refractive.ok()) return refractive.status();
    cameras[c] = *refractive;
  }
  const Eigen::Matrix3d R10 = rig_.right_from_left().rotation;
  const Eigen::Vector3d t10 = rig_.right_from_left().translation;
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
  state.n = options_.initial_n;
  state.cam1_direction = t10.normalized();
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
      // keyframes); RANSAC at 2 px of the left focal length.
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
      const double threshold = 2.0 / rig_.left().fx();
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
  // The observations of placed landmarks that the initial state can
  // image (Ceres starts from a point where every residual is defined).
  for (size_t i = 0; i < count; ++i) {
    use[i] =
        blocks.placed[tracks.observations[i].landmark] &&
        ResidualNorm(constants, tracks.observations[i], &blocks).has_value();
  }

  SequenceBundleResult result;
  result.num_observations = static_cast<int64_t>(count);
  result.num_frames = tracks.num_frames;

  // Stage 1: robust.
  const StageResult stage1 =
      SolveStage(constants, tracks, use, options_, /*robust=*/true,
                 options_.max_iterations, /*covariance=*/false, &blocks);
  if (!stage1.summary.IsSolutionUsable()) {
    return Status::Error("the bundle's robust stage failed: " +
                         stage1.summary.message);
  }
  result.iterations += static_cast<int>(stage1.summary.iterations.size());

  // Stage 2: least squares over the inliers, of landmarks seen from two
  // viewpoints at least.
  std::vector<int> inlier_views(tracks.num_landmarks, 0);
  for (size_t i = 0; i < count; ++i) {
    if (!use[i]) continue;
    const std::optional<double> norm =
        ResidualNorm(constants, tracks.observations[i], &blocks);
    use[i] = norm && *norm <= options_.inlier_threshold_px;
    if (use[i]) ++inlier_views[tracks.observations[i].landmark];
  }
  for (size_t i = 0; i < count; ++i) {
    if (use[i] && inlier_views[tracks.observations[i].landmark] < 2) {
      use[i] = false;
    }
  }
  for (int l = 0; l < tracks.num_landmarks; ++l) {
    if (inlier_views[l] < 2) blocks.placed[l] = false;
  }
  const StageResult stage2 =
      SolveStage(constants, tracks, use, options_, /*robust=*/false,
                 options_.max_iterations, /*covariance=*/true, &blocks);
  if (!stage2.summary.IsSolutionUsable()) {
    return Status::Error("the bundle's least squares failed: " +
                         stage2.summary.message);
  }
  result.iterations += static_cast<int>(stage2.summary.iterations.size());
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
  const int64_t unknowns = 1 + (options_.refine_rotation ? 3 : 0) +
                           (options_.refine_translation_direction ? 2 : 0) +
                           6 * std::max(0, used_frames - 1) +
                           3 * int64_t{result.num_landmarks};
  const int64_t residuals = 2 * result.num_inliers;
  if (residuals <= unknowns) {
    return Status::Error("the bundle has " + std::to_string(residuals) +
                         " inlier residuals for " + std::to_string(unknowns) +
                         " unknowns: too few tracks");
  }
  if (blocks.n >= RefractiveCamera::kMaxIndex - kBoundTolerance) {
    return Status::Error(
        "n is pinned at the upper bound 2, which no medium reaches: the "
        "tracks do not fit a refractive rig (wrong calibration or tracks)");
  }
  if (!stage2.covariance_ok || !(stage2.c_nn > 0.0)) {
    return Status::Error(
        "the bundle's covariance is singular: the tracks do not observe n "
        "(a rig that does not move, or one plane at one depth)");
  }
  result.pixel_sigma = std::sqrt(2.0 * stage2.summary.final_cost /
                                 static_cast<double>(residuals - unknowns));
  const double s2 = result.pixel_sigma * result.pixel_sigma;
  result.n = blocks.n;
  result.sigma_n_noise = std::sqrt(s2 * stage2.c_nn);
  if (options_.refine_rotation) {
    result.rotation_covariance = s2 * stage2.c_ww;
    const Eigen::Matrix3d c_ww = stage2.c_ww;
    const double explained =
        stage2.c_nw.dot(c_ww.ldlt().solve(stage2.c_nw)) / stage2.c_nn;
    result.correlation_n_rotation = std::sqrt(std::clamp(explained, 0.0, 1.0));
  }
  result.state = StateOf(blocks);

  // The calibration's remaining uncertainty (header).
  double calibration_variance = 0.0;
  const std::optional<CalibrationUncertainty>& uncertainty =
      rig_.calibration_uncertainty();
  if (options_.propagate_calibration && uncertainty) {
    const Eigen::MatrixXd joint = uncertainty->JointCovariance();
    const int p_l = rig_.left().num_params();
    const int p_r = rig_.right().num_params();
    // x = [w; dt; left params; right params]: the joint covariance's rows
    // of those that it has (a lens without a covariance is exact; the
    // ports' rows, when given, are held exact here).
    std::vector<int> index;
    for (int i = 0; i < 6; ++i) index.push_back(i);
    if (uncertainty->left_lens_covariance.size() > 0) {
      for (int i = 0; i < p_l; ++i) index.push_back(6 + i);
    }
    if (uncertainty->right_lens_covariance.size() > 0) {
      for (int i = 0; i < p_r; ++i) index.push_back(6 + p_l + i);
    }
    Eigen::MatrixXd held = Eigen::MatrixXd::Zero(6 + p_l + p_r, 6 + p_l + p_r);
    for (size_t a = 0; a < index.size(); ++a) {
      for (size_t b = 0; b < index.size(); ++b) {
        held(index[a], index[b]) = joint(a, b);
      }
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
      double moved_n[2];
      for (int sign = 0; sign < 2; ++sign) {
        StatusOr<StereoRig> moved = MovedRig(
            rig_, sign == 0 ? Eigen::VectorXd(step) : Eigen::VectorXd(-step));
        if (!moved.ok()) {
          return moved.status().WithContext(
              "the calibration propagation's moved rig");
        }
        const RigConstants moved_constants = ConstantsOf(*moved);
        Blocks moved_blocks = blocks;
        if (!options_.refine_translation_direction) {
          for (int i = 0; i < 3; ++i) {
            moved_blocks.direction[i] = moved_constants.direction[i];
          }
        }
        const StageResult solve = SolveStage(
            moved_constants, tracks, use, options_, /*robust=*/false,
            options_.max_propagation_iterations, /*covariance=*/false,
            &moved_blocks, /*gauss_newton=*/true);
        if (!solve.summary.IsSolutionUsable()) {
          return Status::Error(
              "the calibration propagation's re-solve failed: " +
              solve.summary.message);
        }
        moved_n[sign] = moved_blocks.n;
      }
      const double dn = 0.5 * (moved_n[0] - moved_n[1]);
      calibration_variance += dn * dn;
      ++result.propagation_directions;
    }
  }
  result.sigma_n_calibration = std::sqrt(calibration_variance);
  result.sigma_n = std::sqrt(result.sigma_n_noise * result.sigma_n_noise +
                             calibration_variance);
  return result;
}

}  // namespace rcm
