#include "rcm/geometry/calibration_uncertainty.h"

#include <glog/logging.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <sstream>
#include <utility>

namespace rcm {
namespace {

constexpr double kDegree = M_PI / 180.0;

}  // namespace

// Tolerances: the round-off of a covariance computed as J C J^T or read
// from 17-digit text.
Status CheckCovarianceMatrix(const Eigen::MatrixXd& matrix,
                             const std::string& name) {
  if (matrix.rows() != matrix.cols()) {
    return Status::Error(name + " is not square");
  }
  if (!matrix.allFinite()) return Status::Error(name + " is not finite");
  const double scale = matrix.cwiseAbs().maxCoeff();
  if (scale == 0.0) return Status::Ok();
  if ((matrix - matrix.transpose()).cwiseAbs().maxCoeff() > 1e-9 * scale) {
    return Status::Error(name + " is not symmetric");
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> solver(
      0.5 * (matrix + matrix.transpose()), Eigen::EigenvaluesOnly);
  if (solver.eigenvalues().minCoeff() < -1e-9 * scale) {
    return Status::Error(name + " is not positive semi-definite");
  }
  return Status::Ok();
}

CalibrationUncertainty CalibrationUncertainty::DriftPrior(
    double rotation_sigma, double translation_sigma) {
  CalibrationUncertainty uncertainty;
  uncertainty.AddDrift(rotation_sigma, translation_sigma);
  uncertainty.source = DescribeDriftPrior(rotation_sigma, translation_sigma);
  return uncertainty;
}

CalibrationUncertainty CalibrationUncertainty::DefaultDriftPrior() {
  CalibrationUncertainty uncertainty = DriftPrior(
      kDefaultDriftDegrees * kDegree, 1e-3 * kDefaultDriftMillimeters);
  uncertainty.source = "default " + uncertainty.source;
  return uncertainty;
}

std::string CalibrationUncertainty::DescribeDriftPrior(
    double rotation_sigma, double translation_sigma) {
  std::ostringstream text;
  text.precision(3);
  text << "drift prior " << rotation_sigma / kDegree << " deg, "
       << 1e3 * translation_sigma << " mm per axis";
  return text.str();
}

std::string CalibrationUncertainty::DescribeFocalDrift(double focal_sigma) {
  std::ostringstream text;
  text.precision(3);
  text << "focal drift prior " << 100.0 * focal_sigma << " %";
  return text.str();
}

namespace {

// g = [fx, fy, 0, ..., 0] of a camera's params (the header).
Eigen::VectorXd FocalDirection(const Eigen::VectorXd& params) {
  Eigen::VectorXd g = Eigen::VectorXd::Zero(params.size());
  const Eigen::Index head = std::min<Eigen::Index>(2, params.size());
  g.head(head) = params.head(head);
  return g;
}

}  // namespace

void CalibrationUncertainty::AddFocalDrift(
    double focal_sigma, const Eigen::VectorXd& left_params,
    const Eigen::VectorXd& right_params) {
  if (focal_sigma == 0.0) return;
  // A lens block that appears gets zero rows in the ports' cross-covariance
  // (its rows follow the extrinsics', cam0's lens first).
  const auto add = [this, focal_sigma](const Eigen::VectorXd& params,
                                       Eigen::MatrixXd* covariance,
                                       Eigen::Index cross_row) {
    const Eigen::Index size = params.size();
    if (covariance->size() == 0) {
      *covariance = Eigen::MatrixXd::Zero(size, size);
      if (port_cross_covariance.size() > 0) {
        Eigen::MatrixXd widened = Eigen::MatrixXd::Zero(
            port_cross_covariance.rows() + size, port_cross_covariance.cols());
        widened.topRows(cross_row) = port_cross_covariance.topRows(cross_row);
        widened.bottomRows(port_cross_covariance.rows() - cross_row) =
            port_cross_covariance.bottomRows(port_cross_covariance.rows() -
                                             cross_row);
        port_cross_covariance = std::move(widened);
      }
    }
    const Eigen::VectorXd g = FocalDirection(params);
    *covariance += focal_sigma * focal_sigma * g * g.transpose();
  };
  add(left_params, &left_lens_covariance, 6);
  add(right_params, &right_lens_covariance, 6 + left_lens_covariance.rows());
  focal_drift_sigma = std::hypot(focal_drift_sigma, focal_sigma);
  source += (source.empty() ? "" : ", ") + DescribeFocalDrift(focal_sigma);
}

CalibrationUncertainty CalibrationUncertainty::WithoutFocalDrift(
    const Eigen::VectorXd& left_params,
    const Eigen::VectorXd& right_params) const {
  CalibrationUncertainty measured = *this;
  if (focal_drift_sigma == 0.0) return measured;
  const double variance = focal_drift_sigma * focal_drift_sigma;
  const auto remove = [variance](const Eigen::VectorXd& params,
                                 Eigen::MatrixXd* covariance) {
    if (covariance->rows() != params.size()) return;
    const Eigen::VectorXd g = FocalDirection(params);
    *covariance -= variance * g * g.transpose();
  };
  remove(left_params, &measured.left_lens_covariance);
  remove(right_params, &measured.right_lens_covariance);
  measured.focal_drift_sigma = 0.0;
  return measured;
}

void CalibrationUncertainty::AddDrift(double rotation_sigma,
                                      double translation_sigma) {
  for (int k = 0; k < 3; ++k) {
    extrinsics_covariance(k, k) += rotation_sigma * rotation_sigma;
    extrinsics_covariance(3 + k, 3 + k) +=
        translation_sigma * translation_sigma;
  }
}

bool CalibrationUncertainty::IsZero() const {
  return extrinsics_covariance.isZero(0.0) &&
         (left_lens_covariance.size() == 0 ||
          left_lens_covariance.isZero(0.0)) &&
         (right_lens_covariance.size() == 0 ||
          right_lens_covariance.isZero(0.0)) &&
         (port_covariance.size() == 0 || port_covariance.isZero(0.0));
}

Eigen::MatrixXd CalibrationUncertainty::JointCovariance() const {
  const int left = static_cast<int>(left_lens_covariance.rows());
  const int right = static_cast<int>(right_lens_covariance.rows());
  const int ports = port_covariance.size() > 0 ? kNumPortParams : 0;
  const int held = 6 + left + right;
  Eigen::MatrixXd joint = Eigen::MatrixXd::Zero(held + ports, held + ports);
  joint.topLeftCorner<6, 6>() = extrinsics_covariance;
  if (left > 0) joint.block(6, 6, left, left) = left_lens_covariance;
  if (right > 0) {
    joint.block(6 + left, 6 + left, right, right) = right_lens_covariance;
  }
  if (extrinsics_lens_covariance.rows() == 6 &&
      extrinsics_lens_covariance.cols() == left + right) {
    joint.block(0, 6, 6, left + right) = extrinsics_lens_covariance;
    joint.block(6, 0, left + right, 6) = extrinsics_lens_covariance.transpose();
  }
  if (left > 0 && right > 0 && lens_cross_covariance.rows() == left &&
      lens_cross_covariance.cols() == right) {
    joint.block(6, 6 + left, left, right) = lens_cross_covariance;
    joint.block(6 + left, 6, right, left) = lens_cross_covariance.transpose();
  }
  if (ports > 0) {
    joint.bottomRightCorner(ports, ports) = port_covariance;
    if (port_cross_covariance.rows() == held &&
        port_cross_covariance.cols() == ports) {
      joint.topRightCorner(held, ports) = port_cross_covariance;
      joint.bottomLeftCorner(ports, held) = port_cross_covariance.transpose();
    }
  }
  return joint;
}

Eigen::MatrixXd ConditionalCovariance(const Eigen::MatrixXd& joint, int k) {
  CHECK_EQ(joint.rows(), joint.cols());
  CHECK(k >= 0 && k <= joint.rows());
  const int q = static_cast<int>(joint.rows()) - k;
  const Eigen::MatrixXd marginal = joint.topLeftCorner(k, k);
  const Eigen::MatrixXd sigma_xq = joint.topRightCorner(k, q);
  if (q == 0 || sigma_xq.isZero(0.0)) return marginal;
  // Sigma_qq in correlation form (its exact entries, zero variance, carry
  // no covariance with x in a positive semi-definite joint: left out).
  const Eigen::MatrixXd sigma_qq = joint.bottomRightCorner(q, q);
  Eigen::VectorXd scale(q);
  for (int i = 0; i < q; ++i) {
    const double variance = sigma_qq(i, i);
    scale[i] = variance > 0.0 ? 1.0 / std::sqrt(variance) : 0.0;
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(
      scale.asDiagonal() * sigma_qq * scale.asDiagonal());
  const Eigen::VectorXd& values = eigen.eigenvalues();
  const double largest = values.maxCoeff();
  Eigen::VectorXd inverse = Eigen::VectorXd::Zero(q);
  for (int i = 0; i < q; ++i) {
    if (values[i] > 1e-12 * largest) inverse[i] = 1.0 / values[i];
  }
  const Eigen::MatrixXd projected =
      sigma_xq * scale.asDiagonal() * eigen.eigenvectors();
  const Eigen::MatrixXd conditional =
      marginal - projected * inverse.asDiagonal() * projected.transpose();
  return 0.5 * (conditional + conditional.transpose());
}

Eigen::Matrix3d CalibrationUncertainty::RotationPriorCovariance() const {
  const Eigen::Matrix3d marginal = RotationCovariance();
  const Eigen::Matrix3d conditional =
      ConditionalCovariance(JointCovariance(), 3);
  // Floor the eigenvalues (rounding, or a rotation the lenses determine).
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> own(conditional);
  const double floor = 1e-12 * std::max(marginal.diagonal().maxCoeff(), 0.0);
  if (own.eigenvalues().minCoeff() >= floor) return conditional;
  const Eigen::Vector3d floored = own.eigenvalues().cwiseMax(floor);
  return own.eigenvectors() * floored.asDiagonal() *
         own.eigenvectors().transpose();
}

Status CalibrationUncertainty::Check(int left_num_params,
                                     int right_num_params) const {
  if (!(focal_drift_sigma >= 0.0) || !std::isfinite(focal_drift_sigma)) {
    return Status::Error("the focal drift prior is not a finite sigma >= 0");
  }
  RCM_RETURN_IF_ERROR(CheckCovarianceMatrix(extrinsics_covariance,
                                            "cam1_from_cam0 covariance"));
  const Eigen::MatrixXd* lenses[2] = {&left_lens_covariance,
                                      &right_lens_covariance};
  const int sizes[2] = {left_num_params, right_num_params};
  for (int c = 0; c < 2; ++c) {
    const std::string name =
        std::string(c == 0 ? "left" : "right") + " lens covariance";
    if (lenses[c]->size() == 0) continue;
    if (lenses[c]->rows() != sizes[c] || lenses[c]->cols() != sizes[c]) {
      std::ostringstream message;
      message << name << " is " << lenses[c]->rows() << "x" << lenses[c]->cols()
              << ", the camera has " << sizes[c] << " parameters";
      return Status::Error(message.str());
    }
    RCM_RETURN_IF_ERROR(CheckCovarianceMatrix(*lenses[c], name));
  }
  if (port_covariance.size() > 0) {
    if (port_covariance.rows() != kNumPortParams ||
        port_covariance.cols() != kNumPortParams) {
      std::ostringstream message;
      message << "port covariance is " << port_covariance.rows() << "x"
              << port_covariance.cols() << ", not " << kNumPortParams << "x"
              << kNumPortParams;
      return Status::Error(message.str());
    }
    RCM_RETURN_IF_ERROR(
        CheckCovarianceMatrix(port_covariance, "port covariance"));
  }
  if (port_cross_covariance.size() > 0) {
    const int held = 6 + static_cast<int>(left_lens_covariance.rows() +
                                          right_lens_covariance.rows());
    if (port_covariance.size() == 0) {
      return Status::Error("port cross-covariance needs the port covariance");
    }
    if (port_cross_covariance.rows() != held ||
        port_cross_covariance.cols() != kNumPortParams) {
      std::ostringstream message;
      message << "port cross-covariance is " << port_cross_covariance.rows()
              << "x" << port_cross_covariance.cols() << ", not " << held << "x"
              << kNumPortParams;
      return Status::Error(message.str());
    }
  }
  if (extrinsics_lens_covariance.size() == 0 &&
      lens_cross_covariance.size() == 0) {
    return port_cross_covariance.size() == 0
               ? Status::Ok()
               : CheckCovarianceMatrix(JointCovariance(),
                                       "joint calibration covariance");
  }
  if (left_lens_covariance.size() == 0 || right_lens_covariance.size() == 0) {
    return Status::Error(
        std::string(extrinsics_lens_covariance.size() > 0
                        ? "cam1_from_cam0-lens cross-covariance"
                        : "left-right lens cross-covariance") +
        " needs both lens covariances");
  }
  if (lens_cross_covariance.size() > 0 &&
      (lens_cross_covariance.rows() != left_num_params ||
       lens_cross_covariance.cols() != right_num_params)) {
    std::ostringstream message;
    message << "left-right lens cross-covariance is "
            << lens_cross_covariance.rows() << "x"
            << lens_cross_covariance.cols() << ", not " << left_num_params
            << "x" << right_num_params;
    return Status::Error(message.str());
  }
  if (extrinsics_lens_covariance.size() > 0 &&
      (extrinsics_lens_covariance.rows() != 6 ||
       extrinsics_lens_covariance.cols() !=
           left_num_params + right_num_params)) {
    std::ostringstream message;
    message << "cam1_from_cam0-lens cross-covariance is "
            << extrinsics_lens_covariance.rows() << "x"
            << extrinsics_lens_covariance.cols() << ", not 6x"
            << left_num_params + right_num_params;
    return Status::Error(message.str());
  }
  return CheckCovarianceMatrix(JointCovariance(),
                               "joint cam1_from_cam0 and lens covariance");
}

}  // namespace rcm
