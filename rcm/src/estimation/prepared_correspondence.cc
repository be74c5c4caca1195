#include "rcm/estimation/prepared_correspondence.h"

#include <Eigen/LU>
#include <cmath>

#include "rcm/util/parallel_for.h"

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

// The side's fields of `prepared` from its normalized point `point` (the
// pixel's under `camera`); false where the lens map folds there.
bool PrepareSideAt(const Camera& camera, const Eigen::Vector2d& pixel,
                   const Eigen::Vector2d& point, int side,
                   PreparedCorrespondence* prepared) {
  double* normalized =
      side == 0 ? prepared->left_normalized : prepared->right_normalized;
  double* normalized_from_pixel = side == 0
                                      ? prepared->left_normalized_from_pixel
                                      : prepared->right_normalized_from_pixel;
  double* focal_direction = side == 0 ? prepared->left_focal_direction
                                      : prepared->right_focal_direction;
  double* normalized_from_pixel_focal =
      side == 0 ? prepared->left_normalized_from_pixel_focal
                : prepared->right_normalized_from_pixel_focal;
  double jacobian[4];
  if (!NormalizedFromPixelJacobian(camera, point, jacobian)) return false;
  normalized[0] = point.x();
  normalized[1] = point.y();
  // d(x, y)/de (the header).
  const double du = pixel.x() - camera.params()[2];
  const double dv = pixel.y() - camera.params()[3];
  focal_direction[0] = -(jacobian[0] * du + jacobian[1] * dv);
  focal_direction[1] = -(jacobian[2] * du + jacobian[3] * dv);
  for (int k = 0; k < 4; ++k) {
    normalized_from_pixel[k] = jacobian[k];
    normalized_from_pixel_focal[k] = -jacobian[k];
  }
  return true;
}

}  // namespace

bool PrepareCorrespondenceSide(const Camera& camera,
                               const Eigen::Vector2d& pixel, int side,
                               PreparedCorrespondence* prepared) {
  Eigen::Vector2d point;
  if (!pixel.allFinite() ||
      !camera.NormalizedFromImage(pixel.data(), point.data()) ||
      !point.allFinite()) {
    return false;
  }
  return PrepareSideAt(camera, pixel, point, side, prepared);
}

bool PrepareCorrespondenceSideNear(const Camera& camera,
                                   const Eigen::Vector2d& pixel, int side,
                                   PreparedCorrespondence* prepared) {
  const double* start =
      side == 0 ? prepared->left_normalized : prepared->right_normalized;
  const Eigen::Vector2d near(start[0], start[1]);
  if (!pixel.allFinite() || !near.allFinite()) return false;
  // x_1 = x_0 + (d pixel / d x)^-1 (pixel - pixel(x_0)).
  // The pixel of x_0 and the Jacobian there from one lens evaluation.
  Eigen::Vector2d at_near;
  const Eigen::Matrix2d forward =
      camera.ImageFromNormalizedJacobian(near, &at_near);
  const double determinant = forward.determinant();
  if (!(determinant > 0.0) || !std::isfinite(determinant)) return false;
  const Eigen::Vector2d point = near + forward.inverse() * (pixel - at_near);
  if (!point.allFinite()) return false;
  return PrepareSideAt(camera, pixel, point, side, prepared);
}

std::optional<PreparedCorrespondence> PrepareCorrespondence(
    const StereoRig& rig, const StereoCorrespondence& correspondence) {
  PreparedCorrespondence prepared;
  if (!PrepareCorrespondenceSide(rig.left(), correspondence.left_pixel, 0,
                                 &prepared) ||
      !PrepareCorrespondenceSide(rig.right(), correspondence.right_pixel, 1,
                                 &prepared)) {
    return std::nullopt;
  }
  return prepared;
}

StatusOr<FocalStepRigs> FocalStepRigs::Of(const StereoRig& rig) {
  StatusOr<StereoRig> plus = rig.WithFocalScaled(kStep, kStep);
  if (!plus.ok()) return plus.status();
  StatusOr<StereoRig> minus = rig.WithFocalScaled(-kStep, -kStep);
  if (!minus.ok()) return minus.status();
  return FocalStepRigs{*std::move(plus), *std::move(minus)};
}

bool PrepareFocalDerivatives(const FocalStepRigs& rigs,
                             const StereoCorrespondence& correspondence,
                             PreparedCorrespondence* prepared) {
  const std::optional<PreparedCorrespondence> up =
      PrepareCorrespondence(rigs.plus, correspondence);
  const std::optional<PreparedCorrespondence> down =
      PrepareCorrespondence(rigs.minus, correspondence);
  if (!up || !down) return false;
  for (int k = 0; k < 4; ++k) {
    prepared->left_normalized_from_pixel_focal[k] =
        (up->left_normalized_from_pixel[k] -
         down->left_normalized_from_pixel[k]) /
        (2.0 * FocalStepRigs::kStep);
    prepared->right_normalized_from_pixel_focal[k] =
        (up->right_normalized_from_pixel[k] -
         down->right_normalized_from_pixel[k]) /
        (2.0 * FocalStepRigs::kStep);
  }
  return true;
}

bool PrepareFocalDerivatives(const StereoRig& rig,
                             const StereoCorrespondence& correspondence,
                             PreparedCorrespondence* prepared) {
  const StatusOr<FocalStepRigs> rigs = FocalStepRigs::Of(rig);
  return rigs.ok() && PrepareFocalDerivatives(*rigs, correspondence, prepared);
}

PreparedCorrespondences PrepareCorrespondences(
    const StereoRig& rig,
    const std::vector<StereoCorrespondence>& correspondences, int num_threads) {
  // Prepared in place on the threads, then the failures dropped in order.
  const int64_t count = static_cast<int64_t>(correspondences.size());
  PreparedCorrespondences result;
  result.prepared.resize(correspondences.size());
  std::vector<unsigned char> ok(correspondences.size(), 0);
  constexpr int64_t kMatchesPerChunk = 256;
  ParallelForChunks(
      count, count >= 2 * kMatchesPerChunk ? num_threads : 1, kMatchesPerChunk,
      [&](int64_t begin, int64_t end) {
        for (int64_t i = begin; i < end; ++i) {
          if (std::optional<PreparedCorrespondence> prepared =
                  PrepareCorrespondence(rig, correspondences[i])) {
            result.prepared[i] = *prepared;
            ok[i] = 1;
          }
        }
      });
  result.source_index.reserve(correspondences.size());
  for (int64_t i = 0; i < count; ++i) {
    if (!ok[i]) continue;
    result.prepared[result.source_index.size()] = result.prepared[i];
    result.source_index.push_back(i);
  }
  result.prepared.resize(result.source_index.size());
  return result;
}

}  // namespace rcm
