#include "rcm/camera/camera.h"

#include <Eigen/LU>
#include <cmath>
#include <sstream>

namespace rcm {

std::string_view LensModelName(LensModelId model) {
  switch (model) {
    case LensModelId::kPinhole:
      return "none";
    case LensModelId::kRadTan:
      return "radtan";
    case LensModelId::kEquidistant:
      return "equidistant";
  }
  LOG(FATAL) << "unknown LensModelId " << static_cast<int>(model);
  return "";
}

std::optional<LensModelId> LensModelFromName(std::string_view name) {
  for (LensModelId id : {LensModelId::kPinhole, LensModelId::kRadTan,
                         LensModelId::kEquidistant}) {
    if (name == LensModelName(id)) return id;
  }
  return std::nullopt;
}

int NumDistortionParams(LensModelId model) {
  RCM_LENS_MODEL_SWITCH(model, return LensModel::kNumDistortionParams;)
  LOG(FATAL) << "unknown LensModelId " << static_cast<int>(model);
  return 0;
}

Status Camera::CheckImageSize(int width, int height) {
  if (width > 0 && height > 0) return Status::Ok();
  std::ostringstream message;
  message << "image size must be positive, got " << width << " x " << height;
  return Status::Error(message.str());
}

Status Camera::CheckIntrinsics(const std::array<double, 4>& intrinsics) {
  const char* kNames[4] = {"fx", "fy", "cx", "cy"};
  for (int i = 0; i < 4; ++i) {
    if (!std::isfinite(intrinsics[i])) {
      return Status::Error(std::string(kNames[i]) + " is not a finite number");
    }
  }
  for (int i = 0; i < 2; ++i) {
    if (!(intrinsics[i] > 0.0)) {
      std::ostringstream message;
      message << "focal length must be positive, got " << kNames[i] << " = "
              << intrinsics[i];
      return Status::Error(message.str());
    }
  }
  return Status::Ok();
}

Status Camera::CheckDistortion(LensModelId model,
                               const std::vector<double>& distortion) {
  const int expected = NumDistortionParams(model);
  if (static_cast<int>(distortion.size()) != expected) {
    std::ostringstream message;
    message << "distortion model '" << LensModelName(model) << "' takes "
            << expected << " coefficients, got " << distortion.size();
    return Status::Error(message.str());
  }
  for (size_t i = 0; i < distortion.size(); ++i) {
    if (!std::isfinite(distortion[i])) {
      std::ostringstream message;
      message << "distortion coefficient " << i << " is not a finite number";
      return Status::Error(message.str());
    }
  }
  return Status::Ok();
}

StatusOr<Camera> Camera::Create(LensModelId model, int width, int height,
                                const std::array<double, 4>& intrinsics,
                                const std::vector<double>& distortion) {
  RCM_RETURN_IF_ERROR(CheckImageSize(width, height));
  RCM_RETURN_IF_ERROR(CheckIntrinsics(intrinsics));
  RCM_RETURN_IF_ERROR(CheckDistortion(model, distortion));
  const int expected = NumDistortionParams(model);
  Camera camera;
  camera.model_ = model;
  camera.width_ = width;
  camera.height_ = height;
  for (int i = 0; i < 4; ++i) camera.params_[i] = intrinsics[i];
  for (int i = 0; i < expected; ++i) camera.params_[4 + i] = distortion[i];
  return camera;
}

std::vector<double> Camera::Distortion() const {
  return std::vector<double>(params_.begin() + 4,
                             params_.begin() + num_params());
}

Eigen::Vector2d Camera::ImageFromNormalized(
    const Eigen::Vector2d& normalized) const {
  Eigen::Vector2d pixel;
  ImageFromNormalized(normalized.data(), pixel.data());
  return pixel;
}

std::optional<Eigen::Vector2d> Camera::NormalizedFromImage(
    const Eigen::Vector2d& pixel) const {
  Eigen::Vector2d normalized;
  if (!NormalizedFromImage(pixel.data(), normalized.data())) {
    return std::nullopt;
  }
  return normalized;
}

Eigen::Matrix2d Camera::ImageFromNormalizedJacobian(
    const Eigen::Vector2d& normalized) const {
  double distorted[2];
  double jacobian[4] = {1.0, 0.0, 0.0, 1.0};
  RCM_LENS_MODEL_SWITCH(
      model_, LensModel::DistortWithJacobian(params_.data() + 4, normalized.x(),
                                             normalized.y(), &distorted[0],
                                             &distorted[1], jacobian);
      break;)
  Eigen::Matrix2d result;
  result << fx() * jacobian[0], fx() * jacobian[1], fy() * jacobian[2],
      fy() * jacobian[3];
  return result;
}

std::optional<Eigen::Vector2d> Camera::ProjectNormalized(
    const Eigen::Vector2d& normalized) const {
  if (!LensInvertibleAt(normalized)) return std::nullopt;
  const Eigen::Vector2d pixel = ImageFromNormalized(normalized);
  if (!pixel.allFinite()) return std::nullopt;
  return pixel;
}

bool Camera::LensInvertibleAt(const Eigen::Vector2d& normalized) const {
  return ImageFromNormalizedJacobian(normalized).determinant() > 0.0;
}

bool Camera::InImage(const Eigen::Vector2d& pixel) const {
  return pixel.x() >= -0.5 && pixel.x() <= width_ - 0.5 && pixel.y() >= -0.5 &&
         pixel.y() <= height_ - 0.5;
}

bool Camera::operator==(const Camera& other) const {
  return model_ == other.model_ && width_ == other.width_ &&
         height_ == other.height_ && params_ == other.params_;
}

}  // namespace rcm
