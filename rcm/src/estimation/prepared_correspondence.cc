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
  return prepared;
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
