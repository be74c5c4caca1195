#include "rcm/calib/underwater_calibration.h"

#include <ceres/ceres.h>
#include <ceres/rotation.h>
#include <glog/logging.h>

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include "board_bundle_adjustment.h"
#include "rcm/calib/board_warp.h"
#include "rcm/calib/calibration_initialization.h"
#include "rcm/calib/underwater_reprojection_error.h"
#include "rcm/camera/refractive_model.h"
#include "rcm/geometry/calibration_uncertainty.h"
#include "rcm/util/number_format.h"

namespace rcm::calib {
namespace {

// The two refusals of an n on a bound (IsIndexOnBoundError).
constexpr char kUpperBoundText[] = " ends at the upper bound of [1, 2]";
constexpr char kLowerBoundText[] = "n ends at the lower bound 1 of [1, 2]";

using internal::Corner;
using internal::Pose;
using internal::PoseFromRigid;
using internal::RigidFromPose;

constexpr double kDegreesPerRadian = 180.0 / M_PI;
constexpr double kMinIndex = 1.0;
constexpr double kMaxIndex = 2.0;
// n within this of a bound of [1, 2] sits on it (Ceres projects a step
// that crosses a bound onto it exactly; 1e-9 is far below any sigma_n).
constexpr double kOnBound = 1e-9;
// n at the lower bound is refused when the unconstrained Gauss-Newton step
// from it, -C_nn g_n, points below 1 by more than this many sigma_n: the
// data then want n < 1, which no water gives. Within it, n = 1 (air) is a
// valid answer.
constexpr double kMaxPullBelowAir = 3.0;
// The box on each tilt parameter (a, b): beyond tan(30 deg) a port is
// refused anyway (FlatPort::kMaxTiltDegrees).
const double kMaxTiltParameter =
    std::tan(FlatPort::kMaxTiltDegrees * M_PI / 180.0);

// What the problem holds fixed: the target, the lenses and the glass.
// With air views (joint), views [0, num_water_views) are under water and
// the rest in air, and the water residuals take the lens as a block.
struct Model {
  std::vector<Eigen::Vector3d> target_points;
  std::vector<Eigen::Vector2d> warp_basis;  // per point (board_warp.h)
  std::array<LensModelId, 2> lens_models{};
  std::array<UnderwaterCameraConstants, 2> constants{};
  bool joint = false;
  int num_water_views = 0;
  std::vector<Eigen::Vector3d> air_target_points;
  std::vector<Eigen::Vector2d> air_warp_basis;
  bool same_board = false;

  bool InAir(const Corner& corner) const {
    return joint && corner.view >= num_water_views;
  }
};

// The unknowns, as Ceres sees them.
struct Parameters {
  double n = 1.34;
  Pose cam1_from_cam0{};
  std::array<double, 2> air_gap{};              // per camera
  std::array<std::array<double, 2>, 2> tilt{};  // per camera: (a, b)
  std::vector<Pose> cam0_from_target;  // per input view (water, then air)
  std::array<double, 2> board_warp{};  // [warp_x, warp_y] (m)
  // The joint calibration's (Model::joint): the lenses (Camera::params()
  // order), the air extrinsics and the air board's warp.
  std::array<std::array<double, kMaxLensParams>, 2> lens{};
  Pose air_cam1_from_cam0{};
  std::array<double, 2> air_board_warp{};

  // The warp block of the board a corner lies on.
  double* WarpOf(const Model& model, const Corner& corner) {
    return model.InAir(corner) && !model.same_board ? air_board_warp.data()
                                                    : board_warp.data();
  }
  const double* WarpOf(const Model& model, const Corner& corner) const {
    return const_cast<Parameters*>(this)->WarpOf(model, corner);
  }
};

// Which of them are estimated (the poses always are).
struct FreeParameters {
  bool extrinsics = false;
  std::array<bool, 2> air_gap{};
  std::array<bool, 2> tilt{};
  bool board_warp = false;
  // The joint calibration's.
  std::array<bool, 2> lens{};
  bool air_extrinsics = false;
  bool air_board_warp = false;
};

template <typename LensModel>
ceres::CostFunction* MakeCost(const Model& model, const Corner& corner) {
  const UnderwaterCameraConstants& constants = model.constants[corner.camera];
  const Eigen::Vector3d& point = model.target_points[corner.point_id];
  const Eigen::Vector2d& basis = model.warp_basis[corner.point_id];
  if (corner.camera == 0) {
    return Cam0UnderwaterReprojectionError<LensModel>::Create(
        constants, point, basis, corner.pixel);
  }
  return Cam1UnderwaterReprojectionError<LensModel>::Create(
      constants, point, basis, corner.pixel);
}

// The joint calibration's costs: a water corner with the lens as a block,
// an air corner (board_reprojection_error.h).
template <typename LensModel>
ceres::CostFunction* MakeJointCost(const Model& model, const Corner& corner) {
  if (model.InAir(corner)) {
    const Eigen::Vector3d& point = model.air_target_points[corner.point_id];
    const Eigen::Vector2d& basis = model.air_warp_basis[corner.point_id];
    if (corner.camera == 0) {
      return Cam0WarpedBoardReprojectionError<LensModel>::Create(point, basis,
                                                                 corner.pixel);
    }
    return Cam1WarpedBoardReprojectionError<LensModel>::Create(point, basis,
                                                               corner.pixel);
  }
  const UnderwaterCameraConstants& constants = model.constants[corner.camera];
  const Eigen::Vector3d& point = model.target_points[corner.point_id];
  const Eigen::Vector2d& basis = model.warp_basis[corner.point_id];
  if (corner.camera == 0) {
    return Cam0UnderwaterLensReprojectionError<LensModel>::Create(
        constants, point, basis, corner.pixel);
  }
  return Cam1UnderwaterLensReprojectionError<LensModel>::Create(
      constants, point, basis, corner.pixel);
}

ceres::CostFunction* CostFor(const Model& model, const Corner& corner) {
  RCM_LENS_MODEL_SWITCH(model.lens_models[corner.camera],
                        return model.joint
                                   ? MakeJointCost<LensModel>(model, corner)
                                   : MakeCost<LensModel>(model, corner);)
  LOG(FATAL) << "unknown lens model";
  return nullptr;
}

// Holds `block` constant unless `free` (when the problem has it).
void HoldUnlessFree(bool free, double* block, ceres::Problem* problem) {
  if (!free && problem->HasParameterBlock(block)) {
    problem->SetParameterBlockConstant(block);
  }
}

// Adds the inliers' residuals to `problem` (Huber at huber_px, none for 0),
// the bounds, and holds the parameters that are not estimated constant.
void AddResiduals(const Model& model, const std::vector<Corner>& corners,
                  const FreeParameters& free, double huber_px,
                  Parameters* parameters, ceres::Problem* problem) {
  for (const Corner& corner : corners) {
    if (!corner.inlier) continue;
    ceres::LossFunction* loss =
        huber_px > 0.0 ? new ceres::HuberLoss(huber_px) : nullptr;
    const int c = corner.camera;
    double* pose = parameters->cam0_from_target[corner.view].data();
    double* warp = parameters->WarpOf(model, corner);
    double* lens = parameters->lens[c].data();
    if (model.InAir(corner)) {
      if (c == 0) {
        problem->AddResidualBlock(CostFor(model, corner), loss, lens, pose,
                                  warp);
      } else {
        problem->AddResidualBlock(CostFor(model, corner), loss, lens, pose,
                                  parameters->air_cam1_from_cam0.data(), warp);
      }
    } else if (model.joint) {
      if (c == 0) {
        problem->AddResidualBlock(CostFor(model, corner), loss, lens,
                                  &parameters->n, pose, &parameters->air_gap[0],
                                  parameters->tilt[0].data(), warp);
      } else {
        problem->AddResidualBlock(
            CostFor(model, corner), loss, lens, &parameters->n, pose,
            parameters->cam1_from_cam0.data(), &parameters->air_gap[1],
            parameters->tilt[1].data(), warp);
      }
    } else if (c == 0) {
      problem->AddResidualBlock(CostFor(model, corner), loss, &parameters->n,
                                pose, &parameters->air_gap[0],
                                parameters->tilt[0].data(), warp);
    } else {
      problem->AddResidualBlock(CostFor(model, corner), loss, &parameters->n,
                                pose, parameters->cam1_from_cam0.data(),
                                &parameters->air_gap[1],
                                parameters->tilt[1].data(), warp);
    }
  }
  HoldUnlessFree(free.board_warp, parameters->board_warp.data(), problem);
  HoldUnlessFree(free.air_board_warp, parameters->air_board_warp.data(),
                 problem);
  HoldUnlessFree(free.air_extrinsics, parameters->air_cam1_from_cam0.data(),
                 problem);
  for (int c = 0; c < 2; ++c) {
    HoldUnlessFree(free.lens[c], parameters->lens[c].data(), problem);
  }
  if (!problem->HasParameterBlock(&parameters->n)) return;
  problem->SetParameterLowerBound(&parameters->n, 0, kMinIndex);
  problem->SetParameterUpperBound(&parameters->n, 0, kMaxIndex);
  if (problem->HasParameterBlock(parameters->cam1_from_cam0.data()) &&
      !free.extrinsics) {
    problem->SetParameterBlockConstant(parameters->cam1_from_cam0.data());
  }
  for (int c = 0; c < 2; ++c) {
    double* gap = &parameters->air_gap[c];
    if (problem->HasParameterBlock(gap)) {
      if (free.air_gap[c]) {
        problem->SetParameterLowerBound(gap, 0, 0.0);
        problem->SetParameterUpperBound(gap, 0, FlatPort::kMaxAirGap);
      } else {
        problem->SetParameterBlockConstant(gap);
      }
    }
    double* tilt = parameters->tilt[c].data();
    if (problem->HasParameterBlock(tilt)) {
      if (free.tilt[c]) {
        for (int i = 0; i < 2; ++i) {
          problem->SetParameterLowerBound(tilt, i, -kMaxTiltParameter);
          problem->SetParameterUpperBound(tilt, i, kMaxTiltParameter);
        }
      } else {
        problem->SetParameterBlockConstant(tilt);
      }
    }
  }
}

// The residual of one corner at the current parameters; false when the
// port cannot image it.
template <typename LensModel>
bool EvaluateResidual(const Model& model, const Corner& corner,
                      const Parameters& parameters, double* residual) {
  const UnderwaterCameraConstants& constants = model.constants[corner.camera];
  const double* pose = parameters.cam0_from_target[corner.view].data();
  const double* warp = parameters.WarpOf(model, corner);
  const double* lens = parameters.lens[corner.camera].data();
  if (model.InAir(corner)) {
    const Eigen::Vector3d& point = model.air_target_points[corner.point_id];
    const Eigen::Vector2d& basis = model.air_warp_basis[corner.point_id];
    if (corner.camera == 0) {
      return Cam0WarpedBoardReprojectionError<LensModel>(
          point, basis, corner.pixel)(lens, pose, warp, residual);
    }
    return Cam1WarpedBoardReprojectionError<LensModel>(point, basis,
                                                       corner.pixel)(
        lens, pose, parameters.air_cam1_from_cam0.data(), warp, residual);
  }
  const Eigen::Vector3d& point = model.target_points[corner.point_id];
  const Eigen::Vector2d& basis = model.warp_basis[corner.point_id];
  if (model.joint) {
    if (corner.camera == 0) {
      return Cam0UnderwaterLensReprojectionError<LensModel>(
          constants, point, basis, corner.pixel)(
          lens, &parameters.n, pose, &parameters.air_gap[0],
          parameters.tilt[0].data(), warp, residual);
    }
    return Cam1UnderwaterLensReprojectionError<LensModel>(constants, point,
                                                          basis, corner.pixel)(
        lens, &parameters.n, pose, parameters.cam1_from_cam0.data(),
        &parameters.air_gap[1], parameters.tilt[1].data(), warp, residual);
  }
  if (corner.camera == 0) {
    return Cam0UnderwaterReprojectionError<LensModel>(constants, point, basis,
                                                      corner.pixel)(
        &parameters.n, pose, &parameters.air_gap[0], parameters.tilt[0].data(),
        warp, residual);
  }
  return Cam1UnderwaterReprojectionError<LensModel>(constants, point, basis,
                                                    corner.pixel)(
      &parameters.n, pose, parameters.cam1_from_cam0.data(),
      &parameters.air_gap[1], parameters.tilt[1].data(), warp, residual);
}

// The same; NaN when the port cannot image the corner.
Eigen::Vector2d Residual(const Model& model, const Corner& corner,
                         const Parameters& parameters) {
  Eigen::Vector2d residual;
  bool ok = false;
  RCM_LENS_MODEL_SWITCH(model.lens_models[corner.camera],
                        ok = EvaluateResidual<LensModel>(
                            model, corner, parameters, residual.data());
                        break;)
  if (!ok) residual.setConstant(std::numeric_limits<double>::quiet_NaN());
  return residual;
}

// camera_from_target of one view through the thin port at n0 (header):
// PnP on the normalized points (xb, yb) / m(n0, rb) of the corners' rays
// in the water.
std::optional<Rigid3d> ThinPortTargetPose(
    const Camera& camera, double n0,
    const std::vector<Eigen::Vector3d>& target_points,
    const TargetObservation& observation) {
  std::vector<std::optional<Eigen::Vector2d>> rays;
  for (const Eigen::Vector2d& pixel : observation.pixels) {
    std::optional<Eigen::Vector2d> normalized =
        camera.NormalizedFromImage(pixel);
    if (normalized) {
      *normalized /=
          FlatPortRefraction::RadialFactor(n0, normalized->squaredNorm());
    }
    rays.push_back(normalized);
  }
  return TargetPoseFromNormalized(target_points, observation, rays);
}

// The views of one medium, posed by ThinPortTargetPose at n0 (1 in air)
// and their corners appended as views first_view + v: each view's
// cam0_from_target from cam0's corners, else from cam1's through
// cam1_from_cam0; a view that gets no pose is not used.
struct PosedViews {
  std::vector<bool> used;  // per view of the medium
  std::array<bool, 2> camera_seen = {false, false};
  int num_used = 0;
  int num_stereo = 0;  // used views with corners in both cameras
};
PosedViews PoseViews(const std::array<const Camera*, 2>& cameras, double n0,
                     const std::vector<Eigen::Vector3d>& target_points,
                     const internal::UsedObservations& observations,
                     const Rigid3d& cam1_from_cam0, int first_view,
                     std::vector<Pose>* poses, std::vector<Corner>* corners) {
  PosedViews posed;
  posed.used.assign(observations.size(), false);
  for (size_t v = 0; v < observations.size(); ++v) {
    const std::array<const TargetObservation*, 2>& observed = observations[v];
    std::optional<Rigid3d> camera_from_target[2];
    for (int c = 0; c < 2; ++c) {
      if (observed[c] == nullptr) continue;
      camera_from_target[c] =
          ThinPortTargetPose(*cameras[c], n0, target_points, *observed[c]);
    }
    std::optional<Rigid3d> cam0_from_target = camera_from_target[0];
    if (!cam0_from_target && camera_from_target[1]) {
      cam0_from_target = cam1_from_cam0.Inverse() * *camera_from_target[1];
    }
    if (!cam0_from_target) continue;
    const int view = first_view + static_cast<int>(v);
    posed.used[v] = true;
    ++posed.num_used;
    (*poses)[view] = PoseFromRigid(*cam0_from_target);
    for (int c = 0; c < 2; ++c) {
      if (observed[c] == nullptr) continue;
      posed.camera_seen[c] = true;
      for (int k = 0; k < observed[c]->size(); ++k) {
        corners->push_back(
            {view, c, observed[c]->point_ids[k], observed[c]->pixels[k], true});
      }
    }
    if (observed[0] != nullptr && observed[1] != nullptr) ++posed.num_stereo;
  }
  return posed;
}

// The port normal of tilt parameters (a, b).
Eigen::Vector3d NormalFromTilt(const std::array<double, 2>& tilt) {
  return Eigen::Vector3d(tilt[0], tilt[1], 1.0).normalized();
}

// The blocks of the covariance (header order) and their parameter arrays.
struct CovarianceLayout {
  std::vector<UnderwaterParameterBlock> blocks;
  std::vector<internal::CovarianceBlockRef> refs;
  int size = 0;

  void Add(const std::string& name, const double* block, int block_size) {
    blocks.push_back({name, size, block_size});
    refs.push_back({block, block_size});
    size += block_size;
  }
};

std::string CameraName(int c) { return "cam" + std::to_string(c); }

// lens_sizes: each camera's Camera::num_params() (the lens blocks' sizes).
CovarianceLayout LayoutOf(const FreeParameters& free,
                          const Parameters& parameters,
                          const std::array<int, 2>& lens_sizes) {
  CovarianceLayout layout;
  layout.Add("n", &parameters.n, 1);
  if (free.extrinsics) {
    layout.Add("cam1_from_cam0", parameters.cam1_from_cam0.data(), 6);
  }
  for (int c = 0; c < 2; ++c) {
    if (free.air_gap[c]) {
      layout.Add("cam" + std::to_string(c) + " air_gap", &parameters.air_gap[c],
                 1);
    }
  }
  for (int c = 0; c < 2; ++c) {
    if (free.tilt[c]) {
      layout.Add("cam" + std::to_string(c) + " port_tilt",
                 parameters.tilt[c].data(), 2);
    }
  }
  if (free.board_warp) {
    layout.Add("board_warp", parameters.board_warp.data(), 2);
  }
  for (int c = 0; c < 2; ++c) {
    if (free.lens[c]) {
      layout.Add(CameraName(c) + " lens", parameters.lens[c].data(),
                 lens_sizes[c]);
    }
  }
  return layout;
}

// The estimated parameters in the covariance's layout, the extrinsics'
// rotation as the left perturbation w = log(R R_reference^T).
Eigen::VectorXd ParameterVector(const FreeParameters& free,
                                const Parameters& parameters,
                                const std::array<int, 2>& lens_sizes,
                                const Eigen::Matrix3d& reference_rotation) {
  const CovarianceLayout layout = LayoutOf(free, parameters, lens_sizes);
  Eigen::VectorXd x(layout.size);
  for (size_t b = 0; b < layout.blocks.size(); ++b) {
    const UnderwaterParameterBlock& block = layout.blocks[b];
    const double* values = layout.refs[b].block;
    if (block.name == "cam1_from_cam0") {
      const Rigid3d rigid = RigidFromPose(values);
      const Eigen::Matrix3d delta =
          rigid.rotation * reference_rotation.transpose();
      Eigen::Vector3d w;
      ceres::RotationMatrixToAngleAxis(delta.data(), w.data());
      x.segment<3>(block.offset) = w;
      x.segment<3>(block.offset + 3) = rigid.translation;
    } else {
      for (int i = 0; i < block.size; ++i) x[block.offset + i] = values[i];
    }
  }
  return x;
}

// The change of the extrinsics from the air calibration's (header) when
// the underwater extrinsics are moved by the left perturbation
// delta = [r (rad); u (m)], R = exp([r]x) R_water, t = t_water + u:
//   [w; dt] = [log(R R_air^T); t - R R_air^T t_air].
// Templated so that Jets give its Jacobian in delta.
template <typename T>
void PerturbedChange(const Rigid3d& air, const Rigid3d& water, const T* delta,
                     T* change) {
  Eigen::Matrix<T, 3, 3> turn;
  ceres::AngleAxisToRotationMatrix(delta, turn.data());
  const Eigen::Matrix<T, 3, 3> rotation =
      turn * (water.rotation * air.rotation.transpose()).cast<T>();
  ceres::RotationMatrixToAngleAxis(rotation.data(), change);
  const Eigen::Matrix<T, 3, 1> shift =
      water.translation.cast<T>() +
      Eigen::Matrix<T, 3, 1>(delta[3], delta[4], delta[5]) -
      rotation * air.translation.cast<T>();
  for (int i = 0; i < 3; ++i) change[3 + i] = shift[i];
}

// [w (rad); dt (m)] and, when `jacobian` is given, d[w; dt] / d delta at
// delta = 0 (autodiff).
Eigen::Matrix<double, 6, 1> ChangeFromAir(
    const Rigid3d& air, const Rigid3d& water,
    Eigen::Matrix<double, 6, 6>* jacobian = nullptr) {
  using Jet = ceres::Jet<double, 6>;
  Jet delta[6];
  for (int i = 0; i < 6; ++i) delta[i] = Jet(0.0, i);
  Jet change[6];
  PerturbedChange(air, water, delta, change);
  Eigen::Matrix<double, 6, 1> value;
  for (int i = 0; i < 6; ++i) {
    value[i] = change[i].a;
    if (jacobian != nullptr) jacobian->row(i) = change[i].v.transpose();
  }
  return value;
}

// [w (deg); |w| (deg); dt (mm)]: the change as reported.
Eigen::Matrix<double, 7, 1> ReportedChange(
    const Eigen::Matrix<double, 6, 1>& change) {
  Eigen::Matrix<double, 7, 1> reported;
  reported.head<3>() = kDegreesPerRadian * change.head<3>();
  reported[3] = kDegreesPerRadian * change.head<3>().norm();
  reported.tail<3>() = 1e3 * change.tail<3>();
  return reported;
}

// One refit of sigma_n_lenses (header): camera `camera`'s lens moved by
// `delta` = sqrt(l_i) e_i.
struct LensPerturbation {
  int camera = 0;
  Eigen::VectorXd delta;
};

// The perturbations of the used cameras' lens covariances: the eigenpairs
// whose variance exceeds 1e-12 of the largest (the rest is rounding, or a
// parameter the air calibration held).
std::vector<LensPerturbation> LensPerturbations(
    const StereoRig& air_rig, const std::array<bool, 2>& camera_used) {
  std::vector<LensPerturbation> steps;
  const std::optional<CalibrationUncertainty>& uncertainty =
      air_rig.calibration_uncertainty();
  if (!uncertainty) return steps;
  const Camera* cameras[2] = {&air_rig.left(), &air_rig.right()};
  const Eigen::MatrixXd* covariances[2] = {&uncertainty->left_lens_covariance,
                                           &uncertainty->right_lens_covariance};
  for (int c = 0; c < 2; ++c) {
    const Eigen::MatrixXd& covariance = *covariances[c];
    const int size = cameras[c]->num_params();
    if (!camera_used[c] || covariance.rows() != size ||
        covariance.cols() != size || !covariance.allFinite()) {
      continue;
    }
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(
        0.5 * (covariance + covariance.transpose()));
    const double largest = eigen.eigenvalues().maxCoeff();
    if (!(largest > 0.0)) continue;
    for (int i = 0; i < size; ++i) {
      const double variance = eigen.eigenvalues()[i];
      if (!(variance > 1e-12 * largest)) continue;
      steps.push_back({c, std::sqrt(variance) * eigen.eigenvectors().col(i)});
    }
  }
  return steps;
}

// The held-out errors of the views of group `group` (UnderwaterLeaveOut):
// the parameters of `replicate` held, each view's pose fitted to its inlier
// corners, from the full solution's pose.
void HeldOutErrors(const Model& model, const std::vector<Corner>& corners,
                   const std::vector<int>& group_of, int group,
                   const Parameters& replicate,
                   const ceres::Solver::Options& solver_options,
                   UnderwaterLeaveOut* leave_out) {
  std::vector<Corner> held_out;
  for (const Corner& corner : corners) {
    if (group_of[corner.view] == group && corner.inlier) {
      held_out.push_back(corner);
    }
  }
  if (held_out.empty()) return;
  Parameters held = replicate;
  ceres::Problem problem;
  AddResiduals(model, held_out, FreeParameters{}, /*huber_px=*/0.0, &held,
               &problem);
  problem.SetParameterBlockConstant(&held.n);
  ceres::Solver::Summary summary;
  ceres::Solve(solver_options, &problem, &summary);
  if (!summary.IsSolutionUsable()) return;
  std::vector<double> ssr(held.cam0_from_target.size(), 0.0);
  std::vector<int> count(held.cam0_from_target.size(), 0);
  std::vector<bool> bad(held.cam0_from_target.size(), false);
  for (const Corner& corner : held_out) {
    const Eigen::Vector2d e = Residual(model, corner, held);
    if (!e.allFinite()) {
      bad[corner.view] = true;
      continue;
    }
    ssr[corner.view] += e.squaredNorm();
    ++count[corner.view];
  }
  for (size_t v = 0; v < ssr.size(); ++v) {
    if (count[v] == 0 || bad[v]) continue;
    leave_out->held_out_ssr[v] = ssr[v];
    leave_out->held_out_corners[v] = count[v];
  }
}

}  // namespace

Status UnderwaterCalibrationOptions::Check() const {
  if (!(initial_n >= kMinIndex && initial_n <= kMaxIndex)) {
    return Status::Error("initial_n must be in [1, 2]");
  }
  RCM_RETURN_IF_ERROR(internal::CheckSharedFitSettings(
      {huber_px, outlier_sigmas, min_outlier_threshold_px, max_outlier_rounds,
       max_num_iterations, min_corners_per_view, num_threads}));
  if (folds < 0 || folds == 1) {
    return Status::Error("folds must be 0 (no leave-out) or at least 2");
  }
  return Status::Ok();
}

const UnderwaterParameterBlock* UnderwaterCovariance::Find(
    std::string_view name) const {
  for (const UnderwaterParameterBlock& block : blocks) {
    if (block.name == name) return &block;
  }
  return nullptr;
}

Eigen::MatrixXd UnderwaterCovariance::Block(std::string_view row,
                                            std::string_view col) const {
  const UnderwaterParameterBlock* r = Find(row);
  const UnderwaterParameterBlock* c = Find(col);
  CHECK(r != nullptr && c != nullptr)
      << "no covariance block " << (r == nullptr ? row : col);
  return matrix.block(r->offset, c->offset, r->size, c->size);
}

StatusOr<UnderwaterCalibration> CalibrateUnderwater(
    const CalibrationTarget& target, const std::vector<StereoView>& views,
    const ImageSize& cam0_size, const ImageSize& cam1_size,
    const StereoRig& air_rig, const UnderwaterCalibrationOptions& options,
    const std::function<void(int, int)>& progress, const AirTargetViews* air) {
  RCM_RETURN_IF_ERROR(options.Check());
  const Camera* cameras[2] = {&air_rig.left(), &air_rig.right()};
  const int num_views = static_cast<int>(views.size());
  // Each medium's images must be the air rig's cameras'.
  const auto check_sizes = [&](const std::vector<StereoView>& medium_views,
                               const ImageSize& size0, const ImageSize& size1,
                               const std::string& what) {
    const ImageSize sizes[2] = {size0, size1};
    for (int c = 0; c < 2; ++c) {
      bool seen = false;
      for (const StereoView& view : medium_views) {
        seen |= (c == 0 ? view.left : view.right).has_value();
      }
      const bool none = sizes[c].width == 0 && sizes[c].height == 0;
      if ((seen || !none) && (sizes[c].width != cameras[c]->width() ||
                              sizes[c].height != cameras[c]->height())) {
        return Status::Error(
            CameraName(c) + what + " images are " +
            std::to_string(sizes[c].width) + "x" +
            std::to_string(sizes[c].height) + " but the air calibration's " +
            CameraName(c) + " is " + std::to_string(cameras[c]->width()) + "x" +
            std::to_string(cameras[c]->height()) +
            ": the air rig is not these cameras' (or the images were scaled)");
      }
    }
    return Status::Ok();
  };
  RCM_RETURN_IF_ERROR(check_sizes(views, cam0_size, cam1_size, ""));
  if (air != nullptr) {
    RCM_RETURN_IF_ERROR(
        check_sizes(air->views, air->cam0_size, air->cam1_size, " air"));
    if (air->same_board && !SameTarget(target, air->target)) {
      return Status::Error(
          "same board: the air board (" + DescribeTarget(air->target) +
          ") is not the water board (" + DescribeTarget(target) + ")");
    }
  }

  Model model;
  model.target_points = TargetPoints(target);
  model.warp_basis = BoardWarpBasis(target);
  const int num_points = static_cast<int>(model.target_points.size());
  StatusOr<internal::UsedObservations> selected = internal::SelectObservations(
      views, num_points, options.min_corners_per_view,
      options.use_single_camera_views);
  if (!selected.ok()) return selected.status();
  const internal::UsedObservations& used = *selected;

  // The ports: the air rig's blocks, or thin ports.
  std::array<FlatPort, 2> ports = {FlatPort(), FlatPort()};
  if (air_rig.ports()) ports = {air_rig.ports()->left, air_rig.ports()->right};
  std::array<int, 2> lens_sizes{};
  for (int c = 0; c < 2; ++c) {
    lens_sizes[c] = cameras[c]->num_params();
    model.lens_models[c] = cameras[c]->model();
    std::copy(cameras[c]->params(),
              cameras[c]->params() + cameras[c]->num_params(),
              model.constants[c].lens.begin());
    model.constants[c].glass_thickness = ports[c].glass_thickness;
    model.constants[c].glass_index = ports[c].glass_index;
  }

  // Target poses through the thin port at initial_n (header).
  const Rigid3d& air_extrinsics = air_rig.right_from_left();
  Parameters parameters;
  parameters.n = options.initial_n;
  parameters.cam1_from_cam0 = PoseFromRigid(air_extrinsics);
  for (int c = 0; c < 2; ++c) {
    parameters.air_gap[c] = ports[c].air_gap;
    const Eigen::Vector3d normal = ports[c].normal.normalized();
    parameters.tilt[c] = {normal.x() / normal.z(), normal.y() / normal.z()};
    parameters.lens[c] = model.constants[c].lens;  // (joint: the start)
  }
  parameters.cam0_from_target.resize(num_views);
  std::vector<Corner> corners;
  const std::array<const Camera*, 2> camera_pair = {cameras[0], cameras[1]};
  const PosedViews water =
      PoseViews(camera_pair, options.initial_n, model.target_points, used,
                air_extrinsics, 0, &parameters.cam0_from_target, &corners);
  const std::vector<bool>& view_used = water.used;
  const std::array<bool, 2>& camera_used = water.camera_seen;
  const int num_stereo_views = water.num_stereo;
  const int num_views_used = water.num_used;

  // The air views (joint): posed through the air lenses, their corners
  // after the water's, views num_views + a.
  int num_air_views_used = 0;
  int num_air_stereo_views = 0;
  std::array<bool, 2> camera_in_air = {false, false};
  if (air != nullptr) {
    model.joint = true;
    model.num_water_views = num_views;
    model.air_target_points = TargetPoints(air->target);
    model.air_warp_basis = BoardWarpBasis(air->target);
    model.same_board = air->same_board;
    parameters.air_cam1_from_cam0 = PoseFromRigid(air_extrinsics);
    StatusOr<internal::UsedObservations> air_used =
        internal::SelectObservations(
            air->views, static_cast<int>(model.air_target_points.size()),
            options.min_corners_per_view, options.use_single_camera_views);
    if (!air_used.ok()) return air_used.status().WithContext("air views");
    parameters.cam0_from_target.resize(num_views + air->views.size());
    const PosedViews posed = PoseViews(
        camera_pair, /*n0=*/1.0, model.air_target_points, *air_used,
        air_extrinsics, num_views, &parameters.cam0_from_target, &corners);
    num_air_views_used = posed.num_used;
    num_air_stereo_views = posed.num_stereo;
    camera_in_air = posed.camera_seen;
    if (num_air_views_used == 0) {
      return Status::Error("no air view shows the target with at least " +
                           std::to_string(options.min_corners_per_view) +
                           " corners (and a pose)");
    }
  }
  if (num_views_used == 0) {
    return Status::Error("no view shows the target with at least " +
                         std::to_string(options.min_corners_per_view) +
                         " corners (and a pose)");
  }
  if (num_views_used < kMinUnderwaterViews) {
    return Status::Error("the target is seen with at least " +
                         std::to_string(options.min_corners_per_view) +
                         " corners (and a pose) in " +
                         std::to_string(num_views_used) +
                         " view(s); at least " +
                         std::to_string(kMinUnderwaterViews) + " are needed");
  }

  FreeParameters free;
  free.extrinsics = num_stereo_views > 0;
  for (int c = 0; c < 2; ++c) {
    free.air_gap[c] = options.estimate_air_gap && camera_used[c];
    free.tilt[c] = options.estimate_port_tilt && camera_used[c];
  }
  free.board_warp = options.estimate_board_warp;
  if (model.joint) {
    for (int c = 0; c < 2; ++c) {
      free.lens[c] = camera_used[c] || camera_in_air[c];
    }
    free.air_extrinsics = num_air_stereo_views > 0;
    free.air_board_warp = !air->same_board && air->estimate_board_warp;
  }
  const CovarianceLayout layout = LayoutOf(free, parameters, lens_sizes);
  const int num_parameters =
      layout.size + 6 * (num_views_used + num_air_views_used) +
      (free.air_extrinsics ? 6 : 0) + (free.air_board_warp ? 2 : 0);

  const auto residual = [&](const Corner& corner) {
    return Residual(model, corner, parameters);
  };
  // A corner the start cannot image (past the critical angle at initial_n
  // through poses from the thin-port approximation) would fail the first
  // solve: it starts as an outlier, and the outlier rounds, which judge
  // every corner at each round's solution, take it back when it fits.
  double initial_sum = 0.0;
  int num_initial = 0;
  for (Corner& corner : corners) {
    const Eigen::Vector2d start = residual(corner);
    corner.inlier = start.allFinite();
    if (corner.inlier) {
      initial_sum += start.squaredNorm();
      ++num_initial;
    }
  }

  // Robust solves with outlier rejection, then least squares on the
  // inliers (board_bundle_adjustment.h).
  const ceres::Solver::Options solver_options = internal::BoardSolverOptions(
      options.max_num_iterations, options.num_threads);
  ceres::Problem problem;
  RCM_RETURN_IF_ERROR(internal::FitWithOutlierRejection(
      {options.huber_px, options.outlier_sigmas,
       options.min_outlier_threshold_px, options.max_outlier_rounds},
      solver_options,
      [&](double huber_px, ceres::Problem* problem) {
        AddResiduals(model, corners, free, huber_px, &parameters, problem);
      },
      residual, &corners, &problem));

  const auto upper_bound_error = [&] {
    return Status::Error(
        "n = " + FormatFixed(parameters.n, 4) + kUpperBoundText +
        ", which is not a physical answer: "
        "the air calibration probably does not describe these cameras under "
        "water (another rig's file, a lens refocused or zoomed since, a dome "
        "rather than a flat port), or the corners are not the target's");
  };
  if (!std::isfinite(parameters.n) || parameters.n >= kMaxIndex - kOnBound) {
    return upper_bound_error();
  }
  for (int c = 0; c < 2; ++c) {
    if (free.air_gap[c] &&
        parameters.air_gap[c] >= FlatPort::kMaxAirGap - kOnBound) {
      return Status::Error(
          CameraName(c) + " air gap ends at the upper bound " +
          FormatDouble(FlatPort::kMaxAirGap) +
          " m: the flat-port model does not explain these images");
    }
  }

  // The result, from the solution.
  UnderwaterCalibration result(air_rig);
  result.n = parameters.n;
  result.extrinsics_estimated = free.extrinsics;
  const Rigid3d water_extrinsics =
      free.extrinsics ? RigidFromPose(parameters.cam1_from_cam0.data())
                      : air_extrinsics;
  std::array<FlatPort, 2> estimated_ports = ports;
  for (int c = 0; c < 2; ++c) {
    if (free.air_gap[c]) {
      // FlatPort takes a gap of 0 or >= kMinLayerThickness.
      estimated_ports[c].air_gap =
          parameters.air_gap[c] < FlatPort::kMinLayerThickness
              ? 0.0
              : parameters.air_gap[c];
      if (parameters.air_gap[c] < FlatPort::kMinLayerThickness) {
        result.notes.push_back(
            CameraName(c) + " air gap estimated at " +
            FormatDouble(parameters.air_gap[c]) +
            " m, the lower bound: a thin port (the lens at the glass)");
      }
    }
    if (free.tilt[c]) {
      estimated_ports[c].normal = NormalFromTilt(parameters.tilt[c]);
    }
    if (Status status = estimated_ports[c].Check(); !status.ok()) {
      return Status::Error("the estimated " + CameraName(c) + " " +
                           status.message());
    }
  }
  {
    std::array<Camera, 2> lenses = {air_rig.left(), air_rig.right()};
    for (int c = 0; c < 2; ++c) {
      if (!free.lens[c]) continue;
      StatusOr<Camera> lens = cameras[c]->WithParams(parameters.lens[c].data());
      if (!lens.ok()) {
        return Status::Error(
            "the joint fit's " + CameraName(c) +
            " lens is not a valid camera: " + lens.status().message());
      }
      lenses[c] = *std::move(lens);
    }
    StatusOr<StereoRig> rig =
        StereoRig::Create(lenses[0], lenses[1], water_extrinsics);
    if (!rig.ok()) {
      return Status::Error("bundle adjustment diverged: " +
                           rig.status().message());
    }
    const bool ports_changed =
        free.air_gap[0] || free.air_gap[1] || free.tilt[0] || free.tilt[1];
    if (air_rig.ports() || ports_changed) {
      rig = rig->WithPorts(estimated_ports[0], estimated_ports[1]);
      if (!rig.ok()) return rig.status();
    }
    result.rig = *rig;
  }

  result.cam0_from_target = internal::UsedViewPoses(
      std::vector<Pose>(parameters.cam0_from_target.begin(),
                        parameters.cam0_from_target.begin() + num_views),
      view_used);
  // The statistics of the water corners; the air corners' beside them,
  // and both in the pixel noise.
  std::vector<Corner> water_corners;
  std::vector<Corner> air_corners;
  for (const Corner& corner : corners) {
    (model.InAir(corner) ? air_corners : water_corners).push_back(corner);
  }
  internal::ResidualStatistics statistics =
      internal::SummarizeResiduals(water_corners, residual);
  double inlier_ssr = statistics.inlier_ssr;
  int num_all_inliers = statistics.num_inliers;
  internal::StoreResidualStatistics(std::move(statistics), &result);
  if (model.joint) {
    const internal::ResidualStatistics air_statistics =
        internal::SummarizeResiduals(air_corners, residual);
    inlier_ssr += air_statistics.inlier_ssr;
    num_all_inliers += air_statistics.num_inliers;
    result.air_rms_px = air_statistics.rms_px;
    result.num_air_views_used = num_air_views_used;
    result.air_cam1_from_cam0 =
        free.air_extrinsics
            ? RigidFromPose(parameters.air_cam1_from_cam0.data())
            : air_extrinsics;
    const std::array<double, 2>& air_warp =
        air->same_board ? parameters.board_warp : parameters.air_board_warp;
    result.air_board_warp = Eigen::Vector2d(air_warp[0], air_warp[1]);
  }
  result.initial_rms_px =
      num_initial == 0 ? 0.0 : std::sqrt(initial_sum / num_initial);
  result.num_views_used = num_views_used;
  result.num_stereo_views = num_stereo_views;
  result.num_parameters = num_parameters;
  result.views.resize(num_views);
  std::vector<std::array<int, 2>> num_projected(num_views, {0, 0});
  for (const CornerResidual& corner : result.corners) {
    UnderwaterViewResidual& view = result.views[corner.view];
    ++view.num_corners[corner.camera];
    if (!corner.residual.allFinite()) continue;
    ++num_projected[corner.view][corner.camera];
    view.rms_px[corner.camera] += corner.residual.squaredNorm();
  }
  for (int v = 0; v < num_views; ++v) {
    for (int c = 0; c < 2; ++c) {
      if (num_projected[v][c] > 0) {
        result.views[v].rms_px[c] =
            std::sqrt(result.views[v].rms_px[c] / num_projected[v][c]);
      }
    }
  }
  // A fit that leaves many corners out is not a calibration of these
  // cameras: said, not refused (the residuals show it too).
  constexpr double kSuspectOutlierFraction = 0.1;
  if (result.num_outliers > kSuspectOutlierFraction * water_corners.size()) {
    result.notes.push_back(
        FormatFixed(100.0 * result.num_outliers / water_corners.size(), 0) +
        " % of the corners are outliers (" +
        std::to_string(result.num_outliers) + " of " +
        std::to_string(water_corners.size()) +
        "): the air calibration may not describe these cameras, or the "
        "detector confused corners");
  }
  const int redundancy = 2 * num_all_inliers - num_parameters;
  if (redundancy <= 0) {
    return Status::Error("too few corners: " + std::to_string(num_all_inliers) +
                         " inlier corners for " +
                         std::to_string(num_parameters) +
                         " unknowns (2 per corner must exceed them)");
  }
  result.pixel_sigma = std::sqrt(inlier_ssr / redundancy);

  // Covariance: sigma^2 (J^T J)^-1, the extrinsics' rotation moved to the
  // left perturbation, w = G a for the angle-axis parameters a.
  Eigen::MatrixXd unscaled;
  if (!internal::JointCovariance(layout.refs, /*cross_blocks=*/true,
                                 options.num_threads, &problem, &unscaled)) {
    return Status::Error(
        "the underwater calibration is degenerate: its covariance cannot be "
        "computed (the views do not constrain every unknown; add views with "
        "the target tilted, near the image corners and at several "
        "distances)");
  }
  result.covariance.blocks = layout.blocks;
  Eigen::MatrixXd to_left = Eigen::MatrixXd::Identity(layout.size, layout.size);
  if (const UnderwaterParameterBlock* block =
          result.covariance.Find("cam1_from_cam0")) {
    to_left.block<3, 3>(block->offset, block->offset) =
        internal::LeftPerturbationFromAngleAxis(
            parameters.cam1_from_cam0.data());
  }
  const double variance = result.pixel_sigma * result.pixel_sigma;
  result.covariance.matrix =
      variance * to_left * unscaled * to_left.transpose();
  if (!result.covariance.matrix.allFinite() ||
      !(result.covariance.matrix.diagonal().minCoeff() >= 0.0)) {
    return Status::Error(
        "the underwater calibration is degenerate: its covariance has a "
        "negative or non-finite variance");
  }
  result.sigma_n = std::sqrt(result.covariance.matrix(0, 0));
  // The joint calibration: the lenses' share of n's variance (header).
  std::vector<int> lens_rows;
  for (int c = 0; c < 2; ++c) {
    if (const UnderwaterParameterBlock* block =
            result.covariance.Find(CameraName(c) + " lens")) {
      for (int i = 0; i < block->size; ++i) {
        lens_rows.push_back(block->offset + i);
      }
    }
  }
  if (!lens_rows.empty()) {
    const int k = static_cast<int>(lens_rows.size());
    Eigen::MatrixXd c_ll(k, k);
    Eigen::VectorXd c_ln(k);
    for (int i = 0; i < k; ++i) {
      c_ln[i] = result.covariance.matrix(lens_rows[i], 0);
      for (int j = 0; j < k; ++j) {
        c_ll(i, j) = result.covariance.matrix(lens_rows[i], lens_rows[j]);
      }
    }
    const double share = std::max(0.0, c_ln.dot(c_ll.ldlt().solve(c_ln)));
    const double total = result.covariance.matrix(0, 0);
    result.sigma_n_lenses = std::sqrt(std::min(share, total));
    result.sigma_n = std::sqrt(std::max(0.0, total - share));
    result.lenses_estimated = true;
    for (int c = 0; c < 2; ++c) {
      const std::string name = CameraName(c) + " lens";
      if (result.covariance.Find(name) != nullptr) {
        result.lens_covariance[c] = result.covariance.Block(name, name);
      }
    }
    if (free.lens[0] && free.lens[1]) {
      result.lens_cross_covariance =
          result.covariance.Block("cam0 lens", "cam1 lens");
    }
  }
  // Within one sigma of the upper bound is the bound too: the data cannot
  // tell the estimate from 2.
  if (parameters.n >= kMaxIndex - result.sigma_n) return upper_bound_error();

  // At the lower bound, n = 1 is an answer when the data do not pull below
  // it (kMaxPullBelowAir).
  if (parameters.n <= kMinIndex + kOnBound) {
    ceres::Problem::EvaluateOptions evaluate;
    evaluate.parameter_blocks = {&parameters.n};
    evaluate.num_threads = options.num_threads;
    std::vector<double> gradient;
    double cost = 0.0;
    problem.Evaluate(evaluate, &cost, nullptr, &gradient, nullptr);
    const double step = -unscaled(0, 0) * gradient[0];
    // (A pull of less than kOnBound is rounding: exact corners of a target
    // in air give 1e-13 against a sigma_n of 1e-16.)
    if (step < -kMaxPullBelowAir * result.sigma_n && step < -kOnBound) {
      return Status::Error(
          std::string(kLowerBoundText) + " and the corners pull it below by " +
          FormatFixed(-step / result.sigma_n, 1) +
          " sigma, which no medium does: the air calibration probably does "
          "not describe these cameras (focal lengths too long, another "
          "rig's file), or the corners are not the target's");
    }
  }

  // The board's warp.
  result.board_warp_estimated = free.board_warp;
  result.board_warp =
      Eigen::Vector2d(parameters.board_warp[0], parameters.board_warp[1]);
  if (free.board_warp) {
    result.board_warp_covariance =
        result.covariance.Block("board_warp", "board_warp");
    result.board_warp_sigma =
        result.board_warp_covariance.diagonal().cwiseSqrt();
  }

  // The extrinsics and their change from the air calibration.
  if (free.extrinsics) {
    const UnderwaterParameterBlock& block =
        *result.covariance.Find("cam1_from_cam0");
    result.extrinsics_covariance =
        result.covariance.matrix.block<6, 6>(block.offset, block.offset);
    Eigen::Matrix<double, 6, 6> jacobian;
    const Eigen::Matrix<double, 6, 1> change =
        ChangeFromAir(air_extrinsics, water_extrinsics, &jacobian);
    const Eigen::Matrix<double, 7, 1> reported = ReportedChange(change);
    ExtrinsicChange& out = result.extrinsic_change;
    out.rotation_deg = reported.head<3>();
    out.angle_deg = reported[3];
    out.translation_mm = reported.tail<3>();
    out.covariance =
        jacobian * result.extrinsics_covariance * jacobian.transpose();
    // The joint calibration: the change's covariance with the lenses.
    if (free.lens[0] && free.lens[1]) {
      result.extrinsics_lens_covariance =
          jacobian *
          (Eigen::MatrixXd(6, lens_sizes[0] + lens_sizes[1])
               << result.covariance.Block("cam1_from_cam0", "cam0 lens"),
           result.covariance.Block("cam1_from_cam0", "cam1 lens"))
              .finished();
    }
    for (int i = 0; i < 3; ++i) {
      out.rotation_sigma_deg[i] =
          kDegreesPerRadian * std::sqrt(out.covariance(i, i));
      out.translation_sigma_mm[i] =
          1e3 * std::sqrt(out.covariance(3 + i, 3 + i));
    }
    const Eigen::Vector3d w = change.head<3>();
    // |w| to first order: the variance along w's direction (the largest
    // axis' when w is 0).
    Eigen::Vector3d direction = w;
    if (!(direction.norm() > 0.0)) {
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(
          out.covariance.topLeftCorner<3, 3>());
      direction = eigen.eigenvectors().col(2);
    }
    direction.normalize();
    out.angle_sigma_deg =
        kDegreesPerRadian *
        std::sqrt(
            direction.dot(out.covariance.topLeftCorner<3, 3>() * direction));
  }

  // The ports.
  for (int c = 0; c < 2; ++c) {
    PortEstimate& port = result.ports[c];
    // The rig's port, bit for bit (its normal is unit).
    port.port = !result.rig.ports() ? estimated_ports[c]
                : c == 0            ? result.rig.ports()->left
                                    : result.rig.ports()->right;
    port.tilt = Eigen::Vector2d(port.port.normal.x() / port.port.normal.z(),
                                port.port.normal.y() / port.port.normal.z());
    port.tilt_deg = kDegreesPerRadian *
                    std::acos(std::clamp(port.port.normal.z(), -1.0, 1.0));
    port.air_gap_estimated = free.air_gap[c];
    port.tilt_estimated = free.tilt[c];
    if (free.air_gap[c]) {
      const std::string name = CameraName(c) + " air_gap";
      port.air_gap_sigma = std::sqrt(result.covariance.Block(name, name)(0, 0));
    }
    if (free.tilt[c]) {
      const std::string name = CameraName(c) + " port_tilt";
      port.tilt_sigma =
          result.covariance.Block(name, name).diagonal().cwiseSqrt();
    }
  }

  // The ports' covariance in q's order (header), with the extrinsics' and,
  // in the joint fit, the lenses'.
  {
    // Rows of q against the block `column` (zero rows for what was not
    // estimated).
    const auto port_rows = [&](std::string_view column, int size) {
      Eigen::MatrixXd rows = Eigen::MatrixXd::Zero(6, size);
      for (int c = 0; c < 2; ++c) {
        if (free.air_gap[c]) {
          rows.row(3 * c) =
              result.covariance.Block(CameraName(c) + " air_gap", column);
        }
        if (free.tilt[c]) {
          rows.middleRows(3 * c + 1, 2) =
              result.covariance.Block(CameraName(c) + " port_tilt", column);
        }
      }
      return rows;
    };
    for (int c = 0; c < 2; ++c) {
      result.ports_estimated |= free.air_gap[c] || free.tilt[c];
    }
    for (int c = 0; c < 2 && result.ports_estimated; ++c) {
      if (free.air_gap[c]) {
        result.port_covariance.col(3 * c) =
            port_rows(CameraName(c) + " air_gap", 1);
      }
      if (free.tilt[c]) {
        result.port_covariance.middleCols(3 * c + 1, 2) =
            port_rows(CameraName(c) + " port_tilt", 2);
      }
    }
    if (result.ports_estimated && free.extrinsics) {
      Eigen::Matrix<double, 6, 6> jacobian;
      ChangeFromAir(air_extrinsics, water_extrinsics, &jacobian);
      result.extrinsics_port_covariance =
          jacobian * port_rows("cam1_from_cam0", 6).transpose();
    }
    if (result.ports_estimated && free.lens[0] && free.lens[1]) {
      result.port_lens_covariance =
          (Eigen::MatrixXd(6, lens_sizes[0] + lens_sizes[1])
               << port_rows("cam0 lens", lens_sizes[0]),
           port_rows("cam1 lens", lens_sizes[1]))
              .finished();
    }
  }

  // The refits below (leave-out replicates, lens perturbations) start at
  // the solution; an air gap that ended on its lower bound 0 stays there
  // (the active set of the solution: Ceres' projected steps would take
  // 50-70 iterations to confirm it, against 4 for the free unknowns).
  FreeParameters refit_free = free;
  for (int c = 0; c < 2; ++c) {
    refit_free.air_gap[c] &= parameters.air_gap[c] > kOnBound;
    // (Joint: the leave-out replicates hold the lenses, header.)
    refit_free.lens[c] = false;
  }

  // Leave views out (header): each replicate re-solves the inliers' least
  // squares without its views, from the full solution.
  std::vector<int> used_views;
  for (int v = 0; v < num_views; ++v) {
    if (view_used[v]) used_views.push_back(v);
  }
  const int groups = std::min(options.folds, num_views_used);
  // The lens refits (header, sigma_n_lenses): one per eigenpair of each
  // used camera's air lens covariance that carries variance.
  std::vector<LensPerturbation> lens_steps;
  if (options.propagate_lens_covariance && !model.joint) {
    lens_steps = LensPerturbations(air_rig, camera_used);
  }
  const int fold_steps = groups >= 2 ? groups : 0;
  const int total_steps = 1 + fold_steps + static_cast<int>(lens_steps.size());
  if (progress) progress(1, total_steps);
  if (options.folds > 0 && groups < 2) {
    result.notes.push_back("leave-out: fewer than 2 views to leave out");
  }
  if (groups >= 2) {
    std::vector<int> group_of(parameters.cam0_from_target.size(), -1);
    for (size_t k = 0; k < used_views.size(); ++k) {
      group_of[used_views[k]] = static_cast<int>(k) % groups;
    }
    UnderwaterLeaveOut leave_out;
    leave_out.folds = groups;
    leave_out.held_out_ssr.assign(num_views,
                                  std::numeric_limits<double>::quiet_NaN());
    leave_out.held_out_corners.assign(num_views, 0);
    std::vector<Eigen::VectorXd> samples;
    std::vector<Eigen::VectorXd> changes;
    const Eigen::Matrix3d reference = water_extrinsics.rotation;
    for (int k = 0; k < groups; ++k) {
      std::vector<Corner> kept;
      std::array<bool, 2> camera_kept = {false, false};
      bool stereo_kept = false;
      for (const Corner& corner : corners) {
        if (group_of[corner.view] == k || !corner.inlier) continue;
        // With the lenses held, only a shared board ties the air corners
        // to the water's unknowns.
        if (model.InAir(corner) && !model.same_board) continue;
        kept.push_back(corner);
        camera_kept[corner.camera] = true;
      }
      for (int v : used_views) {
        stereo_kept |=
            group_of[v] != k && used[v][0] != nullptr && used[v][1] != nullptr;
      }
      bool observable = !free.extrinsics || stereo_kept;
      for (int c = 0; c < 2; ++c) {
        observable &= !(free.air_gap[c] || free.tilt[c]) || camera_kept[c];
      }
      Parameters replicate = parameters;
      ceres::Problem fold_problem;
      AddResiduals(model, kept, refit_free, /*huber_px=*/0.0, &replicate,
                   &fold_problem);
      ceres::Solver::Summary summary;
      if (observable && !kept.empty()) {
        ceres::Solve(solver_options, &fold_problem, &summary);
      }
      // (A replicate at n = 1 is an answer, as for the full solution; one
      // at 2 is not.)
      if (!observable || kept.empty() || !summary.IsSolutionUsable() ||
          replicate.n >= kMaxIndex - kOnBound) {
        ++leave_out.failed_folds;
      } else {
        HeldOutErrors(model, corners, group_of, k, replicate, solver_options,
                      &leave_out);
        samples.push_back(
            ParameterVector(free, replicate, lens_sizes, reference));
        if (free.extrinsics) {
          changes.push_back(ReportedChange(ChangeFromAir(
              air_extrinsics, RigidFromPose(replicate.cam1_from_cam0.data()))));
        }
      }
      if (progress) progress(2 + k, total_steps);
    }
    if (samples.size() >= 2) {
      leave_out.sigma = internal::JackknifeSigma(samples);
      leave_out.covariance = internal::JackknifeCovariance(samples);
      result.sigma_n_leave_out = leave_out.sigma[0];
      if (free.extrinsics) {
        const Eigen::VectorXd sigma = internal::JackknifeSigma(changes);
        result.extrinsic_change.rotation_leave_out_sigma_deg = sigma.head<3>();
        result.extrinsic_change.angle_leave_out_sigma_deg = sigma[3];
        result.extrinsic_change.translation_leave_out_sigma_mm =
            sigma.tail<3>();
      }
      result.leave_out = std::move(leave_out);
    } else {
      result.notes.push_back("leave-out: only " +
                             std::to_string(samples.size()) + " of " +
                             std::to_string(groups) + " replicates succeeded");
    }
  }

  // The air lenses' share (header): the final least squares again with
  // each lens perturbation, from the solution.
  if (!lens_steps.empty()) {
    double sum = 0.0;
    int failed = 0;
    const int left_size = cameras[0]->num_params();
    const int lens_size = left_size + cameras[1]->num_params();
    Eigen::MatrixXd extrinsics_lens = Eigen::MatrixXd::Zero(6, lens_size);
    Eigen::Matrix<double, 6, 6> extrinsics_from_lenses =
        Eigen::Matrix<double, 6, 6>::Zero();
    Eigen::MatrixXd port_lens = Eigen::MatrixXd::Zero(6, lens_size);
    Eigen::Matrix<double, 6, 12> port_from_lenses =
        Eigen::Matrix<double, 6, 12>::Zero();
    for (size_t i = 0; i < lens_steps.size(); ++i) {
      const LensPerturbation& step = lens_steps[i];
      Model perturbed = model;
      for (int j = 0; j < cameras[step.camera]->num_params(); ++j) {
        perturbed.constants[step.camera].lens[j] += step.delta[j];
      }
      Parameters refit = parameters;
      ceres::Problem refit_problem;
      AddResiduals(perturbed, corners, refit_free, /*huber_px=*/0.0, &refit,
                   &refit_problem);
      ceres::Solver::Summary summary;
      ceres::Solve(solver_options, &refit_problem, &summary);
      if (summary.IsSolutionUsable() && std::isfinite(refit.n)) {
        sum += (refit.n - parameters.n) * (refit.n - parameters.n);
        if (free.extrinsics) {
          // The extrinsics' move with the lens, about the solution.
          const Eigen::Matrix<double, 6, 1> moved = ChangeFromAir(
              water_extrinsics, RigidFromPose(refit.cam1_from_cam0.data()));
          extrinsics_lens.block(0, step.camera == 0 ? 0 : left_size, 6,
                                step.delta.size()) +=
              moved * step.delta.transpose();
          extrinsics_from_lenses += moved * moved.transpose();
        }
        if (result.ports_estimated) {
          // The ports' move, q's order (what was not estimated stays).
          Eigen::Matrix<double, 6, 1> port_move;
          for (int c = 0; c < 2; ++c) {
            port_move[3 * c] = refit.air_gap[c] - parameters.air_gap[c];
            port_move[3 * c + 1] = refit.tilt[c][0] - parameters.tilt[c][0];
            port_move[3 * c + 2] = refit.tilt[c][1] - parameters.tilt[c][1];
          }
          port_lens.middleCols(step.camera == 0 ? 0 : left_size,
                               step.delta.size()) +=
              port_move * step.delta.transpose();
          Eigen::Matrix<double, 12, 1> held;
          held << (free.extrinsics
                       ? ChangeFromAir(
                             water_extrinsics,
                             RigidFromPose(refit.cam1_from_cam0.data()))
                       : Eigen::Matrix<double, 6, 1>::Zero()),
              port_move;
          port_from_lenses += port_move * held.transpose();
        }
      } else {
        ++failed;
      }
      if (progress) {
        progress(2 + fold_steps + static_cast<int>(i), total_steps);
      }
    }
    if (failed == 0) {
      result.sigma_n_lenses = std::sqrt(sum);
      if (free.extrinsics) {
        result.extrinsics_lens_covariance = extrinsics_lens;
        result.extrinsics_covariance_from_lenses = extrinsics_from_lenses;
      }
      if (result.ports_estimated) {
        result.port_lens_covariance = port_lens;
        result.port_covariance_from_lenses = port_from_lenses;
      }
    } else {
      result.notes.push_back("lens uncertainty: " + std::to_string(failed) +
                             " of " + std::to_string(lens_steps.size()) +
                             " refits failed; sigma_n leaves the lenses out");
    }
  }

  // The conventional model on the same corners.
  if (options.fit_conventional_model) {
    ConventionalFit& fit = result.conventional;
    fit.model = air_rig.left().model();
    if (air_rig.right().model() != fit.model) {
      result.notes.push_back(
          "conventional fit: both cameras use cam0's lens model (" +
          std::string(LensModelName(fit.model)) + ")");
    }
    StereoCalibrationOptions conventional = internal::ConventionalFitOptions(
        fit.model, options, options.estimate_board_warp);
    conventional.use_single_camera_views = options.use_single_camera_views;
    const StatusOr<StereoCalibration> calibration = CalibrateStereo(
        target, views, {cameras[0]->width(), cameras[0]->height()},
        {cameras[1]->width(), cameras[1]->height()}, conventional);
    if (calibration.ok()) {
      fit.ok = true;
      fit.rms_px = calibration->rms_px;
      fit.inlier_rms_px = calibration->inlier_rms_px;
      fit.pixel_sigma = calibration->pixel_sigma;
      fit.num_parameters = calibration->num_parameters;
    } else {
      fit.error = calibration.status().message();
      result.notes.push_back("conventional fit: " + fit.error);
    }
  }
  return result;
}

bool SameTarget(const CalibrationTarget& a, const CalibrationTarget& b) {
  return a.type == b.type && a.cols == b.cols && a.rows == b.rows &&
         a.row_spacing == b.row_spacing && a.col_spacing == b.col_spacing &&
         a.tag_size == b.tag_size && a.tag_spacing == b.tag_spacing &&
         a.square_size == b.square_size && a.marker_size == b.marker_size &&
         a.dictionary == b.dictionary;
}

bool IsIndexOnBoundError(const Status& status) {
  const std::string& message = status.message();
  return (message.rfind("n = ", 0) == 0 &&
          message.find(kUpperBoundText) != std::string::npos) ||
         message.rfind(kLowerBoundText, 0) == 0;
}

}  // namespace rcm::calib
