// Fuzzes the residuals the estimators minimize, over arbitrary doubles: the
// thin-port Sampson coplanarity residual (sampson_coplanarity_error.h, the
// estimator of record) and the thick-port generalized epipolar residual
// (generalized_epipolar_error.h), on doubles and on ceres::Jet, with the
// correspondence preparation (prepared_correspondence.h) that feeds them.
//
// The rig (two lenses, a rotation, a translation, two ports), the
// correspondence, n, the rotation correction and the air-gap offset all
// come from the bytes. No input may crash or hit undefined behaviour.
// Property: on the residuals' domain (n in [1, 2], pixels in the images,
// a finite rotation correction), a residual that reports success is finite
// and so are its derivatives.
#include <ceres/jet.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include "fuzz_input.h"
#include "rcm/camera/camera.h"
#include "rcm/estimation/generalized_epipolar_error.h"
#include "rcm/estimation/prepared_correspondence.h"
#include "rcm/estimation/sampson_coplanarity_error.h"
#include "rcm/stereo/epipolar.h"
#include "rcm/stereo/stereo_rig.h"

namespace {

using rcm::fuzz::ConsumeDouble;
using rcm::fuzz::FuzzCheck;
using Jet = ceres::Jet<double, 4>;

std::optional<rcm::Camera> ConsumeCamera(FuzzedDataProvider& data) {
  const auto model = static_cast<rcm::LensModelId>(
      data.ConsumeIntegralInRange<int>(0, rcm::kNumLensModels - 1));
  const double f = ConsumeDouble(data, 100.0, 1500.0);
  std::vector<double> distortion(rcm::NumDistortionParams(model));
  for (double& coefficient : distortion) {
    coefficient = ConsumeDouble(data, -0.3, 0.3);
  }
  // The unified models over the range of real calibrations.
  if (model == rcm::LensModelId::kDoubleSphere) {
    distortion[1] = ConsumeDouble(data, 0.0, 0.7);  // alpha
  } else if (model == rcm::LensModelId::kEucm) {
    distortion[0] = ConsumeDouble(data, 0.0, 0.7);  // alpha
    distortion[1] = ConsumeDouble(data, 0.5, 2.0);  // beta
  }
  rcm::StatusOr<rcm::Camera> camera =
      rcm::Camera::Create(model, 720, 540,
                          {f, f, ConsumeDouble(data, 300.0, 420.0),
                           ConsumeDouble(data, 220.0, 320.0)},
                          distortion);
  if (!camera.ok()) return std::nullopt;
  return *camera;
}

rcm::FlatPort ConsumePort(FuzzedDataProvider& data) {
  rcm::FlatPort port;
  port.air_gap = ConsumeDouble(data, 0.0, 0.05);
  port.glass_thickness = ConsumeDouble(data, 0.0, 0.02);
  port.glass_index = ConsumeDouble(data, 1.0, 2.0);
  port.normal = Eigen::Vector3d(ConsumeDouble(data, -0.3, 0.3),
                                ConsumeDouble(data, -0.3, 0.3), 1.0);
  return port;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* bytes, size_t size) {
  FuzzedDataProvider data(bytes, size);
  const std::optional<rcm::Camera> left = ConsumeCamera(data);
  const std::optional<rcm::Camera> right = ConsumeCamera(data);
  const Eigen::Vector3d angle_axis(ConsumeDouble(data, -0.1, 0.1),
                                   ConsumeDouble(data, -0.1, 0.1),
                                   ConsumeDouble(data, -0.1, 0.1));
  rcm::Rigid3d right_from_left;
  right_from_left.translation = Eigen::Vector3d(
      ConsumeDouble(data, -0.3, 0.3), ConsumeDouble(data, -0.05, 0.05),
      ConsumeDouble(data, -0.05, 0.05));
  rcm::FlatPort left_port = ConsumePort(data);
  rcm::FlatPort right_port = ConsumePort(data);
  rcm::StereoCorrespondence match;
  match.left_pixel = Eigen::Vector2d(ConsumeDouble(data, -10.0, 730.0),
                                     ConsumeDouble(data, -10.0, 550.0));
  match.right_pixel = Eigen::Vector2d(ConsumeDouble(data, -10.0, 730.0),
                                      ConsumeDouble(data, -10.0, 550.0));
  const double n = ConsumeDouble(data, 0.9, 2.1);
  const double correction[3] = {ConsumeDouble(data, -0.01, 0.01),
                                ConsumeDouble(data, -0.01, 0.01),
                                ConsumeDouble(data, -0.01, 0.01)};
  const double gap_delta = ConsumeDouble(data, -0.01, 0.01);
  if (!left || !right || !angle_axis.allFinite()) return 0;
  const double angle = angle_axis.norm();
  if (angle > 0.0 && std::isfinite(angle)) {
    right_from_left.rotation =
        Eigen::AngleAxisd(angle, angle_axis / angle).toRotationMatrix();
  }
  rcm::StatusOr<rcm::StereoRig> rig =
      rcm::StereoRig::Create(*left, *right, right_from_left);
  if (!rig.ok()) return 0;
  const std::optional<rcm::PreparedCorrespondence> prepared =
      rcm::PrepareCorrespondence(*rig, match);
  if (!prepared) return 0;
  const bool in_domain =
      n >= 1.0 && n <= 2.0 && left->InImage(match.left_pixel) &&
      right->InImage(match.right_pixel) && rcm::fuzz::AllFinite(correction, 3);

  // Thin port, with and without the rotation correction.
  const Eigen::Matrix3d essential = rcm::EssentialMatrix(right_from_left);
  double residual = 0.0;
  if (rcm::SampsonCoplanarityResidual<double>(essential, *prepared, n, nullptr,
                                              &residual) &&
      in_domain) {
    FuzzCheck(std::isfinite(residual), "Sampson residual not finite");
  }
  const Jet jet_n(n, 0);
  const Jet jet_correction[3] = {Jet(correction[0], 1), Jet(correction[1], 2),
                                 Jet(correction[2], 3)};
  Jet jet_residual;
  if (rcm::SampsonCoplanarityResidual(essential, *prepared, jet_n,
                                      jet_correction, &jet_residual) &&
      in_domain) {
    FuzzCheck(std::isfinite(jet_residual.a) && jet_residual.v.allFinite(),
              "Sampson residual or its derivatives not finite");
  }

  // Thick port.
  if (!left_port.Check().ok() || !right_port.Check().ok()) return 0;
  left_port.normal.normalize();
  right_port.normal.normalize();
  const rcm::ThickPortStereo stereo{left_port, right_port, right_from_left};
  if (rcm::GeneralizedEpipolarResidual(stereo, *prepared, n, gap_delta,
                                       &residual) &&
      in_domain) {
    FuzzCheck(std::isfinite(residual), "generalized residual not finite");
  }
  if (rcm::GeneralizedEpipolarResidual(stereo, *prepared, jet_n,
                                       Jet(gap_delta, 1), &jet_residual) &&
      in_domain) {
    FuzzCheck(std::isfinite(jet_residual.a) && jet_residual.v.allFinite(),
              "generalized residual or its derivatives not finite");
  }
  return 0;
}
