#include "rcm/estimation/prepared_correspondence.h"

#include <Eigen/LU>
#include <cmath>

namespace rcm {
namespace {

// The inverse of the lens Jacobian at `normalized`, row-major; false where
// the lens map folds or the result is not finite.
bool NormalizedFromPixelJacobian(const Camera& camera,
                                 const Eigen::Vector2d& normalized,
                                 double* jacobian) {
  const Eigen::Matrix2d forward =
      camera.ImageFromNormalizedJacobian(normalized);
  const double determinant = forward.determinant();
  if (!(determinant > 0.0) || !std::isfinite(determinant)) return false;
  const Eigen::Matrix2d inverse = forward.inverse();
  if (!inverse.allFinite()) return false;
  jacobian[0] = inverse(0, 0);
  jacobian[1] = inverse(0, 1);
  jacobian[2] = inverse(1, 0);
  jacobian[3] = inverse(1, 1);
  return true;
}

}  // namespace

std::optional<PreparedCorrespondence> PrepareCorrespondence(
    const StereoRig& rig, const StereoCorrespondence& correspondence) {
  const std::optional<NormalizedCorrespondence> normalized =
      rig.Normalize(correspondence);
  if (!normalized || !normalized->left.allFinite() ||
      !normalized->right.allFinite()) {
    return std::nullopt;
  }
  PreparedCorrespondence prepared;
  prepared.left_normalized[0] = normalized->left.x();
  prepared.left_normalized[1] = normalized->left.y();
  prepared.right_normalized[0] = normalized->right.x();
  prepared.right_normalized[1] = normalized->right.y();
  if (!NormalizedFromPixelJacobian(rig.left(), normalized->left,
                                   prepared.left_normalized_from_pixel) ||
      !NormalizedFromPixelJacobian(rig.right(), normalized->right,
                                   prepared.right_normalized_from_pixel)) {
    return std::nullopt;
  }
  // d(x, y)/de (the header).
  const auto focal_direction =
      [](const Camera& camera, const Eigen::Vector2d& pixel,
         const double* normalized_from_pixel, double* direction) {
        const double du = pixel.x() - camera.params()[2];
        const double dv = pixel.y() - camera.params()[3];
        direction[0] =
            -(normalized_from_pixel[0] * du + normalized_from_pixel[1] * dv);
        direction[1] =
            -(normalized_from_pixel[2] * du + normalized_from_pixel[3] * dv);
      };
  focal_direction(rig.left(), correspondence.left_pixel,
                  prepared.left_normalized_from_pixel,
                  prepared.left_focal_direction);
  focal_direction(rig.right(), correspondence.right_pixel,
                  prepared.right_normalized_from_pixel,
                  prepared.right_focal_direction);
  for (int k = 0; k < 4; ++k) {
    prepared.left_normalized_from_pixel_focal[k] =
        -prepared.left_normalized_from_pixel[k];
    prepared.right_normalized_from_pixel_focal[k] =
        -prepared.right_normalized_from_pixel[k];
  }
  return prepared;
}

bool PrepareFocalDerivatives(const StereoRig& rig,
                             const StereoCorrespondence& correspondence,
                             PreparedCorrespondence* prepared) {
  constexpr double kFocalStep = 1e-6;
  const StatusOr<StereoRig> plus = rig.WithFocalScaled(kFocalStep, kFocalStep);
  const StatusOr<StereoRig> minus =
      rig.WithFocalScaled(-kFocalStep, -kFocalStep);
  if (!plus.ok() || !minus.ok()) return false;
  const std::optional<PreparedCorrespondence> up =
      PrepareCorrespondence(*plus, correspondence);
  const std::optional<PreparedCorrespondence> down =
      PrepareCorrespondence(*minus, correspondence);
  if (!up || !down) return false;
  for (int k = 0; k < 4; ++k) {
    prepared->left_normalized_from_pixel_focal[k] =
        (up->left_normalized_from_pixel[k] -
         down->left_normalized_from_pixel[k]) /
        (2.0 * kFocalStep);
    prepared->right_normalized_from_pixel_focal[k] =
        (up->right_normalized_from_pixel[k] -
         down->right_normalized_from_pixel[k]) /
        (2.0 * kFocalStep);
  }
  return true;
}

PreparedCorrespondences PrepareCorrespondences(
    const StereoRig& rig,
    const std::vector<StereoCorrespondence>& correspondences) {
  PreparedCorrespondences result;
  result.prepared.reserve(correspondences.size());
  result.source_index.reserve(correspondences.size());
  for (size_t i = 0; i < correspondences.size(); ++i) {
    if (std::optional<PreparedCorrespondence> prepared =
            PrepareCorrespondence(rig, correspondences[i])) {
      result.prepared.push_back(*prepared);
      result.source_index.push_back(static_cast<int64_t>(i));
    }
  }
  return result;
}

}  // namespace rcm
