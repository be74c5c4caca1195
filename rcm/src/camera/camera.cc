#include "rcm/camera/camera.h"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

namespace rcm {

namespace {

// Camera::MaxInvertibleRadius of a lens.
double FirstFoldRadius(LensModelId model,
                       const std::vector<double>& distortion) {
  constexpr double kInfinity = std::numeric_limits<double>::infinity();
  switch (model) {
    case LensModelId::kPinhole:
      return kInfinity;
    case LensModelId::kRadTan: {
      // d/dr [r (1 + k1 s + k2 s^2)] = 1 + 3 k1 s + 5 k2 s^2 with s = r^2:
      // its smallest positive root in s, by the stable quadratic formula.
      const double a = 5.0 * distortion[1];
      const double b = 3.0 * distortion[0];
      double smallest = kInfinity;
      if (a == 0.0) {
        if (b < 0.0) smallest = -1.0 / b;
      } else {
        const double discriminant = b * b - 4.0 * a;
        if (discriminant >= 0.0) {
          const double q =
              -0.5 * (b + std::copysign(std::sqrt(discriminant), b));
          for (const double root : {q / a, q != 0.0 ? 1.0 / q : kInfinity}) {
            if (root > 0.0) smallest = std::min(smallest, root);
          }
        }
      }
      return std::sqrt(smallest);
    }
    case LensModelId::kEquidistant: {
      // Once per camera: a fine scan, in steps of pi/2048.
      constexpr int kFoldScanSteps = 1024;
      const double fold =
          EquidistantLens::FirstFoldAngle(distortion.data(), kFoldScanSteps);
      return fold < EquidistantLens::kHalfPi ? std::tan(fold) : kInfinity;
    }
    case LensModelId::kRational: {
      // Once per camera: a fine scan, in steps of pi/8192 in the angle off
      // axis (n / q is a ratio of cubics in r^2 and may turn more than
      // once).
      constexpr int kFoldScanSteps = 4096;
      return lens_internal::FirstRadiusWhereFalse(
          [&](double r) {
            return RationalLens::RadiallyIncreasing(distortion.data(), r);
          },
          kFoldScanSteps);
    }
    case LensModelId::kDoubleSphere: {
      constexpr int kFoldScanSteps = 1024;
      return lens_internal::FirstRadiusWhereFalse(
          [&](double r) {
            return DoubleSphereLens::RadiallyIncreasing(distortion.data(), r);
          },
          kFoldScanSteps);
    }
    case LensModelId::kEucm:
      return kInfinity;  // Never folds (lens_models.h).
  }
  return kInfinity;
}

}  // namespace

std::string_view LensModelName(LensModelId model) {
  switch (model) {
    case LensModelId::kPinhole:
      return "none";
    case LensModelId::kRadTan:
      return "radtan";
    case LensModelId::kEquidistant:
      return "equidistant";
    case LensModelId::kRational:
      return "rational";
    case LensModelId::kDoubleSphere:
      return "ds";
    case LensModelId::kEucm:
      return "eucm";
  }
  LOG(FATAL) << "unknown LensModelId " << static_cast<int>(model);
  return "";
}

const std::array<LensModelId, kNumLensModels>& AllLensModels() {
  static const std::array<LensModelId, kNumLensModels> kModels = {
      LensModelId::kPinhole,      LensModelId::kRadTan,
      LensModelId::kEquidistant,  LensModelId::kRational,
      LensModelId::kDoubleSphere, LensModelId::kEucm};
  return kModels;
}

std::string LensModelNameList() {
  std::string list;
  for (LensModelId id : AllLensModels()) {
    if (!list.empty()) list += ", ";
    list += LensModelName(id);
  }
  return list;
}

std::optional<LensModelId> LensModelFromName(std::string_view name) {
  for (LensModelId id : AllLensModels()) {
    if (name == LensModelName(id)) return id;
  }
  return std::nullopt;
}

std::vector<DistortionBound> DistortionBounds(LensModelId model) {
  constexpr double kInside = 1e-6;
  switch (model) {
    case LensModelId::kDoubleSphere:
      return {{0, -1.0 + kInside, 1.0, "xi"}, {1, 0.0, 1.0, "alpha"}};
    case LensModelId::kEucm:
      return {{0, 0.0, 1.0, "alpha"},
              {1, kInside, Camera::kMaxDistortionCoefficient, "beta"}};
    default:
      return {};
  }
}

int NumDistortionParams(LensModelId model) {
  RCM_LENS_MODEL_SWITCH(model, return LensModel::kNumDistortionParams;)
  LOG(FATAL) << "unknown LensModelId " << static_cast<int>(model);
  return 0;
}

Status Camera::CheckImageSize(int width, int height) {
  if (width > 0 && height > 0 && width <= kMaxImageSide &&
      height <= kMaxImageSide) {
    return Status::Ok();
  }
  std::ostringstream message;
  if (width > 0 && height > 0) {
    message << "image size " << width << " x " << height
            << " is beyond the largest accepted side of " << kMaxImageSide
            << " px";
  } else {
    message << "image size must be positive, got " << width << " x " << height;
  }
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
    if (intrinsics[i] < kMinFocalLength || intrinsics[i] > kMaxFocalLength) {
      std::ostringstream message;
      message << kNames[i] << " = " << intrinsics[i]
              << " is not a focal length in pixels (accepted: "
              << kMinFocalLength << " to " << kMaxFocalLength << ")";
      return Status::Error(message.str());
    }
  }
  for (int i = 2; i < 4; ++i) {
    if (std::abs(intrinsics[i]) > kMaxPrincipalPointOffset) {
      std::ostringstream message;
      message << kNames[i] << " = " << intrinsics[i]
              << " is not a principal point in pixels (accepted: within "
              << kMaxPrincipalPointOffset << " of 0)";
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
    if (std::abs(distortion[i]) > kMaxDistortionCoefficient) {
      std::ostringstream message;
      message << "distortion coefficient " << i << " = " << distortion[i]
              << " is beyond the accepted magnitude of "
              << kMaxDistortionCoefficient;
      return Status::Error(message.str());
    }
  }
  // The ranges of the unified models (lens_models.h says why).
  const auto outside = [&](const char* key, double value, const char* range) {
    std::ostringstream message;
    message << LensModelName(model) << " " << key << " = " << value
            << " is outside " << range;
    return Status::Error(message.str());
  };
  if (model == LensModelId::kDoubleSphere) {
    const double xi = distortion[0];
    const double alpha = distortion[1];
    if (!(xi > -1.0 && xi <= 1.0)) return outside("xi", xi, "(-1, 1]");
    if (!(alpha >= 0.0 && alpha <= 1.0)) {
      return outside("alpha", alpha, "[0, 1]");
    }
  }
  if (model == LensModelId::kEucm) {
    const double alpha = distortion[0];
    const double beta = distortion[1];
    if (!(alpha >= 0.0 && alpha <= 1.0)) {
      return outside("alpha", alpha, "[0, 1]");
    }
    if (!(beta > 0.0)) return outside("beta", beta, "(0, 1000]");
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
  camera.max_invertible_radius_ = FirstFoldRadius(model, distortion);
  return camera;
}

StatusOr<Camera> Camera::WithParams(const double* params) const {
  return Create(model_, width_, height_,
                {params[0], params[1], params[2], params[3]},
                std::vector<double>(params + 4, params + num_params()));
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
    const Eigen::Vector2d& normalized, Eigen::Vector2d* pixel) const {
  double distorted[2];
  double jacobian[4] = {1.0, 0.0, 0.0, 1.0};
  RCM_LENS_MODEL_SWITCH(
      model_, LensModel::DistortWithJacobian(params_.data() + 4, normalized.x(),
                                             normalized.y(), &distorted[0],
                                             &distorted[1], jacobian);
      break;)
  // As BaseLens::ImgFromCam.
  pixel->x() = params_[0] * distorted[0] + params_[2];
  pixel->y() = params_[1] * distorted[1] + params_[3];
  Eigen::Matrix2d result;
  result << fx() * jacobian[0], fx() * jacobian[1], fy() * jacobian[2],
      fy() * jacobian[3];
  return result;
}

Eigen::Matrix2d Camera::ImageFromNormalizedJacobian(
    const Eigen::Vector2d& normalized) const {
  Eigen::Vector2d pixel;  // not wanted; the lens computes it anyway
  return ImageFromNormalizedJacobian(normalized, &pixel);
}

std::optional<Eigen::Vector2d> Camera::ProjectNormalized(
    const Eigen::Vector2d& normalized) const {
  if (!LensInvertibleAt(normalized)) return std::nullopt;
  const Eigen::Vector2d pixel = ImageFromNormalized(normalized);
  if (!pixel.allFinite()) return std::nullopt;
  return pixel;
}

bool Camera::LensInvertibleAt(const Eigen::Vector2d& normalized) const {
  return normalized.norm() < max_invertible_radius_ &&
         ImageFromNormalizedJacobian(normalized).determinant() > 0.0;
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
