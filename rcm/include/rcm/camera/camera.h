// Camera: one calibrated in-air camera (lens model, intrinsics, image size),
// chosen at run time. Dispatches to the static models of lens_models.h.
#ifndef RCM_CAMERA_CAMERA_H_
#define RCM_CAMERA_CAMERA_H_

#include <glog/logging.h>

#include <Eigen/Core>
#include <array>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "rcm/camera/lens_models.h"
#include "rcm/util/status.h"

namespace rcm {

// The model names: Kalibr's distortion_model names "none", "radtan",
// "equidistant", Kalibr's camera_model names "ds" (double sphere) and
// "eucm", and "rational" (OpenCV's rational model, which Kalibr does not
// have; rcm's name, see docs/file_formats.md).
std::string_view LensModelName(LensModelId model);
std::optional<LensModelId> LensModelFromName(std::string_view name);
// Every model, in LensModelId order.
const std::array<LensModelId, kNumLensModels>& AllLensModels();
// "none, radtan, equidistant, rational, ds, eucm": for messages.
std::string LensModelNameList();
// Number of distortion coefficients of a model (0, 2, 4 or 8).
int NumDistortionParams(LensModelId model);

// Box bounds on a distortion coefficient (index into the distortion
// coefficients, params + 4) that a solver fitting the lens must keep: the
// ranges of Camera::CheckDistortion, closed 1e-6 inside their open ends
// (ds xi > -1, eucm beta > 0). Empty for the polynomial models.
struct DistortionBound {
  int index = 0;
  double lower = 0.0;
  double upper = 0.0;
  const char* name = "";  // "xi", "alpha", "beta": for messages
};
std::vector<DistortionBound> DistortionBounds(LensModelId model);

// Calls `body` with `LensModel` bound to the static model struct of `id`,
// e.g. RCM_LENS_MODEL_SWITCH(model_, return LensModel::kNumParams;)
#define RCM_LENS_MODEL_SWITCH(id, ...)          \
  switch (id) {                                 \
    case ::rcm::LensModelId::kPinhole: {        \
      using LensModel = ::rcm::PinholeLens;     \
      __VA_ARGS__                               \
    }                                           \
    case ::rcm::LensModelId::kRadTan: {         \
      using LensModel = ::rcm::RadTanLens;      \
      __VA_ARGS__                               \
    }                                           \
    case ::rcm::LensModelId::kEquidistant: {    \
      using LensModel = ::rcm::EquidistantLens; \
      __VA_ARGS__                               \
    }                                           \
    case ::rcm::LensModelId::kRational: {       \
      using LensModel = ::rcm::RationalLens;    \
      __VA_ARGS__                               \
    }                                           \
    case ::rcm::LensModelId::kDoubleSphere: {   \
      using LensModel = ::rcm::DoubleSphereLens; \
      __VA_ARGS__                               \
    }                                           \
    case ::rcm::LensModelId::kEucm: {           \
      using LensModel = ::rcm::EucmLens;        \
      __VA_ARGS__                               \
    }                                           \
  }

class Camera {
 public:
  // Validates and builds a camera. `intrinsics` = [fx, fy, cx, cy];
  // `distortion` has NumDistortionParams(model) entries. Create fails
  // exactly when one of the three checks below does, with its message.
  static StatusOr<Camera> Create(LensModelId model, int width, int height,
                                 const std::array<double, 4>& intrinsics,
                                 const std::vector<double>& distortion);

  // The checks of Create, one per input, so that a file reader can
  // attribute a problem to the key it came from.
  // The accepted ranges, far beyond any camera, so that a value off by a
  // unit (a focal length in metres) or corrupted is refused before it
  // overflows a computation or an image allocation: image sides up to
  // kMaxImageSide px, focal lengths in [kMinFocalLength, kMaxFocalLength]
  // px, the principal point within kMaxPrincipalPointOffset px of pixel
  // (0, 0), distortion coefficients of magnitude up to
  // kMaxDistortionCoefficient (real lenses stay below ~10; the lens models'
  // series near the axis assume far less than 1e16).
  static constexpr int kMaxImageSide = 20000;
  static constexpr double kMinFocalLength = 1.0;
  static constexpr double kMaxFocalLength = 1e6;
  static constexpr double kMaxPrincipalPointOffset = 1e6;
  static constexpr double kMaxDistortionCoefficient = 1e3;

  // Width and height in [1, kMaxImageSide].
  static Status CheckImageSize(int width, int height);
  // All four finite, focal lengths and principal point in the ranges above.
  static Status CheckIntrinsics(const std::array<double, 4>& intrinsics);
  // NumDistortionParams(model) coefficients, all finite and within the
  // magnitude above; for the double sphere xi in (-1, 1] and alpha in
  // [0, 1], for the EUCM alpha in [0, 1] and beta > 0 (lens_models.h says
  // why). The message names the coefficient ("ds xi = 1.5 ...").
  static Status CheckDistortion(LensModelId model,
                                const std::vector<double>& distortion);

  LensModelId model() const { return model_; }
  int width() const { return width_; }
  int height() const { return height_; }
  double fx() const { return params_[0]; }
  double fy() const { return params_[1]; }
  double cx() const { return params_[2]; }
  double cy() const { return params_[3]; }
  // [fx, fy, cx, cy, d...] as in lens_models.h; num_params() entries.
  const double* params() const { return params_.data(); }
  int num_params() const { return 4 + NumDistortionParams(model_); }
  std::vector<double> Distortion() const;
  // This camera (model, image size) with other parameters `params`
  // (num_params() entries, the order of params()), checked as Create.
  StatusOr<Camera> WithParams(const double* params) const;

  // Pixel of a normalized point (z = 1 plane, before distortion).
  template <typename T>
  void ImageFromNormalized(const T* normalized, T* pixel) const;
  Eigen::Vector2d ImageFromNormalized(const Eigen::Vector2d& normalized) const;
  // The same, guarded: nullopt where the lens is not invertible (a folded
  // branch, see LensInvertibleAt) or the pixel is not finite. What every
  // projection of a ray into the image should call.
  std::optional<Eigen::Vector2d> ProjectNormalized(
      const Eigen::Vector2d& normalized) const;

  // Normalized point of a pixel; false / nullopt when undistortion fails.
  template <typename T>
  bool NormalizedFromImage(const T* pixel, T* normalized) const;
  std::optional<Eigen::Vector2d> NormalizedFromImage(
      const Eigen::Vector2d& pixel) const;

  // d pixel / d normalized at a normalized point (row-major 2x2): the
  // analytic lens Jacobian scaled by the focal lengths.
  Eigen::Matrix2d ImageFromNormalizedJacobian(
      const Eigen::Vector2d& normalized) const;
  // Both at once from one evaluation of the lens: the Jacobian returned,
  // the pixel in `pixel`. The same numbers as the two calls (every lens
  // model's Distort is its DistortWithJacobian without the Jacobian).
  Eigen::Matrix2d ImageFromNormalizedJacobian(const Eigen::Vector2d& normalized,
                                              Eigen::Vector2d* pixel) const;

  // True where the point lies on the lens map's principal branch: inside
  // the radius where the radial polynomial first folds back
  // (MaxInvertibleRadius) and where the map is locally invertible (det of
  // its Jacobian > 0). Beyond the fold a point would project onto a wrong
  // pixel inside the image; projection refuses such points. (The
  // determinant alone is not enough: past a second turn of the polynomial,
  // where the radial scale and its derivative are both negative, it is
  // positive again; found by fuzz_camera_model.)
  bool LensInvertibleAt(const Eigen::Vector2d& normalized) const;

  // The normalized radius at which the radial distortion first stops
  // increasing (infinity when it never does: pinhole, EUCM, and most real
  // lenses within the field of view): radtan r (1 + k1 r^2 + k2 r^4),
  // equidistant theta_d(theta) with r = tan(theta) (theta < pi/2),
  // rational r n(r^2) / q(r^2) (or where q first reaches 0), double sphere
  // r / N(r) (or where N first reaches 0).
  double MaxInvertibleRadius() const { return max_invertible_radius_; }

  // True when the pixel lies on the sensor: [-0.5, width - 0.5] x
  // [-0.5, height - 0.5] with pixel centers at integers.
  bool InImage(const Eigen::Vector2d& pixel) const;

  bool operator==(const Camera& other) const;
  bool operator!=(const Camera& other) const { return !(*this == other); }

 private:
  Camera() = default;

  LensModelId model_ = LensModelId::kPinhole;
  int width_ = 0;
  int height_ = 0;
  std::array<double, kMaxLensParams> params_{};
  // Derived from params_ by Create.
  double max_invertible_radius_ = 0.0;
};

// ---------------------------------------------------------------------------
// Template implementations.

template <typename T>
void Camera::ImageFromNormalized(const T* normalized, T* pixel) const {
  T params[kMaxLensParams];
  for (int i = 0; i < kMaxLensParams; ++i) params[i] = T(params_[i]);
  RCM_LENS_MODEL_SWITCH(
      model_, LensModel::ImgFromCam(params, normalized[0], normalized[1],
                                    &pixel[0], &pixel[1]);
      return;)
}

template <typename T>
bool Camera::NormalizedFromImage(const T* pixel, T* normalized) const {
  T params[kMaxLensParams];
  for (int i = 0; i < kMaxLensParams; ++i) params[i] = T(params_[i]);
  RCM_LENS_MODEL_SWITCH(
      model_, return LensModel::CamFromImg(params, pixel[0], pixel[1],
                                           &normalized[0], &normalized[1]);)
  return false;
}

}  // namespace rcm

#endif  // RCM_CAMERA_CAMERA_H_
