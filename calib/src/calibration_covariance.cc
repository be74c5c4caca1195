#include "rcm/calib/calibration_covariance.h"

#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

namespace rcm::calib {

double LeaveOutScale(const std::optional<CrossValidation>& cross_validation,
                     int camera) {
  double scale = 1.0;
  if (!cross_validation) return scale;
  const std::string prefix =
      camera == 2 ? "baseline" : "cam" + std::to_string(camera) + " ";
  for (const ParameterSpread& spread : cross_validation->parameters) {
    if (spread.name.rfind(prefix, 0) != 0 || !(spread.reported_sigma > 0.0)) {
      continue;
    }
    scale = std::max(scale, spread.jackknife_sigma / spread.reported_sigma);
  }
  return scale;
}

CalibrationCovarianceFile AirCalibrationCovariance(
    const StereoCalibration& calibration,
    const std::optional<CrossValidation>& cross_validation) {
  CalibrationCovarianceFile file;
  file.medium = "air";
  file.drift_rotation_sigma =
      CalibrationUncertainty::kDefaultDriftDegrees * M_PI / 180.0;
  file.drift_translation_sigma =
      1e-3 * CalibrationUncertainty::kDefaultDriftMillimeters;
  // The lenses may change between the air and the water.
  file.drift_focal_sigma =
      1e-2 * CalibrationUncertainty::kDefaultFocalDriftPercent;
  file.cameras.resize(calibration.num_cameras);
  const CameraCalibration* cameras[2] = {&calibration.cam0, &calibration.cam1};
  for (int c = 0; c < calibration.num_cameras; ++c) {
    const int size = cameras[c]->camera.num_params();
    const double scale = LeaveOutScale(cross_validation, c);
    file.cameras[c].intrinsics_covariance =
        scale * scale * cameras[c]->covariance.topLeftCorner(size, size);
  }
  if (calibration.num_cameras == 1) return file;
  const double scale = LeaveOutScale(cross_validation, 2);
  file.cameras[1].from_previous_covariance =
      scale * scale * calibration.extrinsics_covariance;
  return file;
}

std::vector<std::string> HeldGeometryBlocks(
    const UnderwaterCalibration& result) {
  std::vector<std::string> names;
  for (const std::string name :
       {"cam1_from_cam0", "cam0 air_gap", "cam0 port_tilt", "cam1 air_gap",
        "cam1 port_tilt"}) {
    if (result.covariance.Find(name) != nullptr) names.push_back(name);
  }
  return names;
}

double GeometryLeaveOutScale(const UnderwaterCalibration& result) {
  if (!result.leave_out || result.leave_out->covariance.size() == 0) {
    return 1.0;
  }
  const Eigen::MatrixXd& fit = result.covariance.matrix;
  const Eigen::MatrixXd& spread = result.leave_out->covariance;
  if (spread.rows() != fit.rows()) return 1.0;
  // h's indices in the covariance, then the lenses' (held by the
  // replicates).
  std::vector<int> held;
  for (const std::string& name : HeldGeometryBlocks(result)) {
    const UnderwaterParameterBlock& block = *result.covariance.Find(name);
    for (int k = 0; k < block.size; ++k) held.push_back(block.offset + k);
  }
  std::vector<int> lenses;
  for (const char* name : {"cam0 lens", "cam1 lens"}) {
    if (const UnderwaterParameterBlock* block = result.covariance.Find(name)) {
      for (int k = 0; k < block->size; ++k) lenses.push_back(block->offset + k);
    }
  }
  const int h = static_cast<int>(held.size());
  if (h == 0) return 1.0;
  std::vector<int> order = held;
  order.insert(order.end(), lenses.begin(), lenses.end());
  Eigen::MatrixXd joint(order.size(), order.size());
  for (size_t r = 0; r < order.size(); ++r) {
    for (size_t c = 0; c < order.size(); ++c) {
      joint(r, c) = fit(order[r], order[c]);
    }
  }
  const Eigen::MatrixXd given = ConditionalCovariance(joint, h);
  Eigen::MatrixXd replicates(h, h);
  for (int r = 0; r < h; ++r) {
    for (int c = 0; c < h; ++c) replicates(r, c) = spread(held[r], held[c]);
  }
  // trace(C^+ J) / rank C in C's correlation form.
  Eigen::VectorXd scale(h);
  for (int i = 0; i < h; ++i) {
    scale[i] = given(i, i) > 0.0 ? 1.0 / std::sqrt(given(i, i)) : 0.0;
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(
      scale.asDiagonal() * given * scale.asDiagonal());
  const Eigen::MatrixXd whitened = eigen.eigenvectors().transpose() *
                                   scale.asDiagonal() * replicates *
                                   scale.asDiagonal() * eigen.eigenvectors();
  const double largest = eigen.eigenvalues().maxCoeff();
  double sum = 0.0;
  int rank = 0;
  for (int i = 0; i < h; ++i) {
    if (!(eigen.eigenvalues()[i] > 1e-12 * largest)) continue;
    sum += whitened(i, i) / eigen.eigenvalues()[i];
    ++rank;
  }
  return rank > 0 ? std::max(1.0, sum / rank) : 1.0;
}

CalibrationCovarianceFile UnderwaterCalibrationCovariance(
    const UnderwaterCalibration& result, const StereoRig& air_rig) {
  CalibrationCovarianceFile file;
  file.medium = "water";
  file.cameras.resize(2);
  if (result.lenses_estimated) {
    // The joint fit's lenses and their covariance (it counts the air views
    // and the water's).
    file.cameras[0].intrinsics_covariance = result.lens_covariance[0];
    file.cameras[1].intrinsics_covariance = result.lens_covariance[1];
    file.cameras[1].previous_intrinsics_covariance =
        result.lens_cross_covariance;
  } else if (const std::optional<CalibrationUncertainty>& air =
                 air_rig.calibration_uncertainty()) {
    file.cameras[0].intrinsics_covariance = air->left_lens_covariance;
    file.cameras[1].intrinsics_covariance = air->right_lens_covariance;
    if (!result.extrinsics_estimated) {
      file.cameras[1].from_previous_covariance = air->extrinsics_covariance;
    }
  }
  const bool ports = result.ports_estimated;
  if (!result.extrinsics_estimated && !ports) return file;

  // The held geometry h = [w; dt; q] (q the ports' parameters when they
  // were estimated) and its covariance G.
  const int size = ports ? 12 : 6;
  Eigen::MatrixXd geometry = Eigen::MatrixXd::Zero(size, size);
  if (result.extrinsics_estimated) {
    geometry.topLeftCorner<6, 6>() = result.extrinsic_change.covariance;
  } else if (file.cameras[1].from_previous_covariance) {
    geometry.topLeftCorner<6, 6>() = *file.cameras[1].from_previous_covariance;
  }
  if (ports) {
    geometry.topRightCorner<6, 6>() = result.extrinsics_port_covariance;
    geometry.bottomLeftCorner<6, 6>() =
        result.extrinsics_port_covariance.transpose();
    geometry.bottomRightCorner<6, 6>() = result.port_covariance;
  }
  const double widening = GeometryLeaveOutScale(result);
  // h was fitted through the lenses: its covariance with them, X, and the
  // lenses' share of its own (zero for the joint fit, whose covariance
  // counts them).
  const Eigen::MatrixXd& lens0 = file.cameras[0].intrinsics_covariance;
  const Eigen::MatrixXd& lens1 = file.cameras[1].intrinsics_covariance;
  const int p0 = static_cast<int>(lens0.rows());
  const int p1 = static_cast<int>(lens1.rows());
  Eigen::MatrixXd response;  // X, size x (p0 + p1)
  if (p0 > 0 && p1 > 0) {
    const bool extrinsics_response =
        result.extrinsics_estimated &&
        result.extrinsics_lens_covariance.cols() == p0 + p1;
    const bool port_response =
        ports && result.port_lens_covariance.cols() == p0 + p1;
    if (extrinsics_response || port_response) {
      response = Eigen::MatrixXd::Zero(size, p0 + p1);
      if (extrinsics_response) {
        response.topRows<6>() = result.extrinsics_lens_covariance;
        geometry.topLeftCorner<6, 6>() +=
            result.extrinsics_covariance_from_lenses;
      }
      if (port_response) {
        response.bottomRows<6>() = result.port_lens_covariance;
        const Eigen::Matrix<double, 6, 12>& from =
            result.port_covariance_from_lenses;
        geometry.bottomRows<6>() += from;
        geometry.topRightCorner<6, 6>() += from.leftCols<6>().transpose();
      }
    }
  }
  if (response.size() > 0) {
    // Only the part the water views measured with the lenses given is
    // widened to the leave-out spread (which holds the lenses too); the
    // response to a lens error stays as the fit has it (header).
    const int lenses = p0 + p1;
    Eigen::MatrixXd joint = Eigen::MatrixXd::Zero(size + lenses, size + lenses);
    joint.topLeftCorner(size, size) = geometry;
    joint.topRightCorner(size, lenses) = response;
    joint.bottomLeftCorner(lenses, size) = response.transpose();
    joint.block(size, size, p0, p0) = lens0;
    joint.block(size + p0, size + p0, p1, p1) = lens1;
    const Eigen::MatrixXd& cross =
        file.cameras[1].previous_intrinsics_covariance;
    if (cross.rows() == p0 && cross.cols() == p1) {
      joint.block(size, size + p0, p0, p1) = cross;
      joint.block(size + p0, size, p1, p0) = cross.transpose();
    }
    const Eigen::MatrixXd given_lenses = ConditionalCovariance(joint, size);
    geometry += (widening - 1.0) * given_lenses;
  } else {
    geometry *= widening;
  }
  if (result.extrinsics_estimated) {
    file.cameras[1].from_previous_covariance = geometry.topLeftCorner<6, 6>();
    if (response.size() > 0) {
      file.cameras[1].from_previous_intrinsics_covariance =
          response.topRows<6>();
    }
  }
  if (ports) {
    file.port_covariance = geometry.bottomRightCorner<6, 6>();
    file.port_cross_covariance = Eigen::MatrixXd::Zero(6 + p0 + p1, 6);
    file.port_cross_covariance.topRows<6>() = geometry.topRightCorner<6, 6>();
    if (response.size() > 0) {
      file.port_cross_covariance.bottomRows(p0 + p1) =
          response.bottomRows<6>().transpose();
    }
  }
  return file;
}

}  // namespace rcm::calib
