// Fuzzes the closed form of the paper (eq. 14, rcm/estimation/closed_form.h)
// and the steps that feed it: a rig's normalization of a correspondence
// (rcm/stereo/stereo_rig.h), the paper's observability mask
// (paper_online_estimator.h) and the first-order sigma of n
// (rcm/stereo/observability.h), over arbitrary doubles.
//
// Properties: no crash or undefined behaviour for any input; ClosedFormN
// returns a finite positive n or nothing, and its square is eq. 14's n^2;
// eq. 14 evaluated on ceres::Jet has the value of the double evaluation
// (to rounding);
// a sigma, when returned, is finite and positive.
#include <ceres/jet.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <optional>

#include "fuzz_input.h"
#include "rcm/estimation/closed_form.h"
#include "rcm/estimation/paper_online_estimator.h"
#include "rcm/stereo/observability.h"
#include "rcm/stereo/stereo_rig.h"

namespace {

using rcm::fuzz::ConsumeDouble;
using rcm::fuzz::FuzzCheck;

void FuzzClosedForm(const rcm::NormalizedCorrespondence& match) {
  const double n_squared = rcm::ClosedFormNSquared(
      match.left.x(), match.left.y(), match.right.x(), match.right.y());
  using Jet = ceres::Jet<double, 4>;
  const Jet jet_n_squared =
      rcm::ClosedFormNSquared(Jet(match.left.x(), 0), Jet(match.left.y(), 1),
                              Jet(match.right.x(), 2), Jet(match.right.y(), 3));
  // Jet division multiplies by the inverse: a rounding or two apart, and
  // subnormals lose their relative precision (hence the absolute term).
  if (std::isfinite(n_squared) && std::isfinite(jet_n_squared.a)) {
    FuzzCheck(std::abs(jet_n_squared.a - n_squared) <=
                  1e-12 * std::abs(n_squared) + 1e-300,
              "eq. 14 on Jets differs from eq. 14 on doubles");
  }
  if (const std::optional<double> n = rcm::ClosedFormN(match)) {
    FuzzCheck(std::isfinite(*n) && *n > 0.0, "ClosedFormN: not a positive n");
    FuzzCheck(std::abs(*n * *n - n_squared) <= 1e-12 * n_squared + 1e-300,
              "ClosedFormN squared is not eq. 14's n^2");
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* bytes, size_t size) {
  FuzzedDataProvider data(bytes, size);
  rcm::NormalizedCorrespondence normalized;
  normalized.left = Eigen::Vector2d(ConsumeDouble(data, -3.0, 3.0),
                                    ConsumeDouble(data, -3.0, 3.0));
  normalized.right = Eigen::Vector2d(ConsumeDouble(data, -3.0, 3.0),
                                     ConsumeDouble(data, -3.0, 3.0));
  FuzzClosedForm(normalized);
  rcm::PassesObservabilityMask(normalized.left, ConsumeDouble(data, 0.0, 1.0));

  // The same through a rig: raw pixels of two pinhole cameras.
  const double f = ConsumeDouble(data, 1.0, 2000.0);
  const rcm::StatusOr<rcm::Camera> camera = rcm::Camera::Create(
      rcm::LensModelId::kPinhole, 640, 480, {f, f, 320.0, 240.0}, {});
  rcm::Rigid3d right_from_left;
  right_from_left.translation = Eigen::Vector3d(ConsumeDouble(data, -1.0, 1.0),
                                                ConsumeDouble(data, -0.1, 0.1),
                                                ConsumeDouble(data, -0.1, 0.1));
  rcm::StereoCorrespondence match;
  match.left_pixel = Eigen::Vector2d(ConsumeDouble(data, -100.0, 700.0),
                                     ConsumeDouble(data, -100.0, 600.0));
  match.right_pixel = Eigen::Vector2d(ConsumeDouble(data, -100.0, 700.0),
                                      ConsumeDouble(data, -100.0, 600.0));
  const double n = ConsumeDouble(data, 0.5, 2.5);
  const double sigma_px = ConsumeDouble(data, 0.0, 2.0);
  if (!camera.ok()) return 0;
  const rcm::StatusOr<rcm::StereoRig> rig =
      rcm::StereoRig::Create(*camera, *camera, right_from_left);
  if (!rig.ok()) return 0;
  if (const std::optional<rcm::NormalizedCorrespondence> from_rig =
          rig->Normalize(match)) {
    FuzzCheck(from_rig->left.allFinite() && from_rig->right.allFinite(),
              "Normalize returned a non-finite point");
    FuzzClosedForm(*from_rig);
  }
  if (const std::optional<double> sigma =
          rcm::FirstOrderSigmaN(*rig, match, n, sigma_px)) {
    FuzzCheck(std::isfinite(*sigma) && *sigma >= 0.0,
              "FirstOrderSigmaN: not a finite non-negative sigma");
  }
  return 0;
}
