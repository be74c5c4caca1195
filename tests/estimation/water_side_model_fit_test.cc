#include "rcm/estimation/water_side_model_fit.h"

#include <ceres/ceres.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

#include "rcm/estimation/water_side_projection_error.h"
#include "support/reader_inputs.h"
#include "support/test_rigs.h"

// The fit has no measurement noise: its samples are exact rays of the
// refractive model, and what it leaves is model error (a polynomial lens
// cannot follow Snell's law into the corners). Its tests are therefore an
// exact case (n = 1, where the camera's own model is exact), the
// acceptance figures at n = 1.333, and the contract's edge cases; there is
// no noisy or Monte-Carlo case to run.

namespace rcm::water_side_model_fit_test {
namespace {

using ::testing::HasSubstr;

RefractiveCamera InWater(const Camera& camera, double n) {
  return RefractiveCamera::Create(camera, n).value();
}

// Parameters agree to 1e-9 relative (1e-9 absolute for the distortion
// coefficients, which are O(0.01-0.1)): the fit converges to the zero
// residual of the exact model, floored by the 1e-14 undistortion of the
// samples' rays.
void ExpectSameParameters(const Camera& fitted, const Camera& truth) {
  constexpr double kTolerance = 1e-9;
  ASSERT_EQ(fitted.model(), truth.model());
  for (int i = 0; i < truth.num_params(); ++i) {
    const double scale = std::max(1.0, std::abs(truth.params()[i]));
    EXPECT_NEAR(fitted.params()[i], truth.params()[i], kTolerance * scale)
        << "parameter " << i;
  }
}

TEST(WaterSideModelFit, ExactAtUnitIndexEquidistant) {
  const Camera camera = test::AlphasenseCam0();
  WaterSideModelFitOptions options;
  options.model = LensModelId::kEquidistant;
  const StatusOr<WaterSideModelFit> fit =
      FitWaterSideModel(InWater(camera, 1.0), options);
  ASSERT_TRUE(fit.ok()) << fit.status().message();
  ExpectSameParameters(fit->camera, camera);
  EXPECT_LT(fit->full.max_px, 1e-9);
  EXPECT_TRUE(fit->converged);
  EXPECT_EQ(fit->num_not_invertible, 0);
}

TEST(WaterSideModelFit, ExactAtUnitIndexRadtan) {
  const Camera camera = test::EurocRadtanCamera();
  WaterSideModelFitOptions options;
  options.model = LensModelId::kRadTan;
  options.fit_inset = 0.0;
  const StatusOr<WaterSideModelFit> fit =
      FitWaterSideModel(InWater(camera, 1.0), options);
  ASSERT_TRUE(fit.ok()) << fit.status().message();
  ExpectSameParameters(fit->camera, camera);
  EXPECT_LT(fit->full.max_px, 1e-9);
}

// The models of issue 21, each fitted to a camera of its own model at
// n = 1: the fit returns the camera (from the virtual pinhole start, with
// the ds and eucm coefficients kept in their ranges by the solve's
// bounds).
TEST(WaterSideModelFit, ExactAtUnitIndexNewModels) {
  for (const Camera& camera : {test::RationalCamera(),
                               test::DoubleSphereCamera(), test::EucmCamera()}) {
    WaterSideModelFitOptions options;
    options.model = camera.model();
    const StatusOr<WaterSideModelFit> fit =
        FitWaterSideModel(InWater(camera, 1.0), options);
    ASSERT_TRUE(fit.ok()) << fit.status().message();
    SCOPED_TRACE(LensModelName(camera.model()));
    ExpectSameParameters(fit->camera, camera);
    EXPECT_LT(fit->full.max_px, 1e-9);
    EXPECT_EQ(fit->num_not_invertible, 0);
  }
}

// Acceptance (issue 9): an exported equidistant model reproduces the
// refractive model of the dataset rig at n = 1.333 within 0.1 px RMS over
// the image inset by 5 % on each side. The whole-image figure is larger:
// four coefficients cannot follow the corners (80 degrees in air).
TEST(WaterSideModelFit, DatasetRigEquidistantWithinTenthPixelInset) {
  for (const Camera& camera : {test::AlphasenseCam0(), test::AlphasenseCam1()}) {
    const StatusOr<WaterSideModelFit> fit =
        FitWaterSideModel(InWater(camera, 1.333), WaterSideModelFitOptions());
    ASSERT_TRUE(fit.ok()) << fit.status().message();
    std::printf(
        "equidistant at n = 1.333: inset RMS %.4f px (max %.3f), whole image "
        "RMS %.4f px (max %.3f), %lld samples\n",
        fit->inset.rms_px, fit->inset.max_px, fit->full.rms_px,
        fit->full.max_px, static_cast<long long>(fit->full.num_samples));
    EXPECT_LT(fit->inset.rms_px, 0.1);
    EXPECT_GT(fit->full.rms_px, fit->inset.rms_px);
    EXPECT_GE(fit->full.max_px, fit->inset.max_px);
    EXPECT_EQ(fit->num_not_invertible, 0);
    EXPECT_TRUE(fit->converged);
    // The water-side focal is about n times the air focal: the virtual
    // pinhole K_n at the center (paper eq. 9).
    EXPECT_NEAR(fit->camera.fx() / camera.fx(), 1.333, 0.01);
    EXPECT_NEAR(fit->camera.cx(), camera.cx(), 0.01);
  }
}

TEST(WaterSideModelFit, FittingTheWholeImageTradesTheInsetForTheCorners) {
  const RefractiveCamera camera = InWater(test::AlphasenseCam0(), 1.333);
  WaterSideModelFitOptions whole;
  whole.fit_inset = 0.0;
  const StatusOr<WaterSideModelFit> fit_whole = FitWaterSideModel(camera, whole);
  const StatusOr<WaterSideModelFit> fit_inset =
      FitWaterSideModel(camera, WaterSideModelFitOptions());
  ASSERT_TRUE(fit_whole.ok() && fit_inset.ok());
  EXPECT_LT(fit_whole->full.rms_px, fit_inset->full.rms_px);
  EXPECT_GT(fit_whole->inset.rms_px, fit_inset->inset.rms_px);
}

TEST(WaterSideModelFit, RadtanFitsTheDatasetRigInWater) {
  WaterSideModelFitOptions options;
  options.model = LensModelId::kRadTan;
  const StatusOr<WaterSideModelFit> fit =
      FitWaterSideModel(InWater(test::AlphasenseCam0(), 1.333), options);
  ASSERT_TRUE(fit.ok()) << fit.status().message();
  EXPECT_EQ(fit->camera.model(), LensModelId::kRadTan);
  EXPECT_LT(fit->inset.rms_px, 0.1);
}

TEST(WaterSideModelFit, ErrorFieldMatchesTheStatistics) {
  const StatusOr<WaterSideModelFit> fit = FitWaterSideModel(
      InWater(test::AlphasenseCam0(), 1.333), WaterSideModelFitOptions());
  ASSERT_TRUE(fit.ok());
  ASSERT_TRUE(fit->errors.Check().ok());
  double sum_squares = 0.0;
  int64_t count = 0;
  for (const auto& error : fit->errors.errors) {
    if (!error.has_value()) continue;
    sum_squares += error->squaredNorm();
    ++count;
  }
  EXPECT_EQ(count, fit->full.num_samples);
  EXPECT_NEAR(std::sqrt(sum_squares / count), fit->full.rms_px, 1e-12);
}

TEST(WaterSideModelFit, RejectsInvalidOptions) {
  const RefractiveCamera camera = InWater(test::AlphasenseCam0(), 1.333);
  WaterSideModelFitOptions options;
  options.grid_step = 0.0;
  EXPECT_THAT(test::ErrorMessage(FitWaterSideModel(camera, options)),
              HasSubstr("grid_step"));
  options = WaterSideModelFitOptions();
  options.fit_inset = 0.5;
  EXPECT_THAT(test::ErrorMessage(FitWaterSideModel(camera, options)),
              HasSubstr("fit_inset"));
  options = WaterSideModelFitOptions();
  options.report_inset = std::nan("");
  EXPECT_THAT(test::ErrorMessage(FitWaterSideModel(camera, options)),
              HasSubstr("report_inset"));
  options = WaterSideModelFitOptions();
  options.max_iterations = 0;
  EXPECT_THAT(test::ErrorMessage(FitWaterSideModel(camera, options)),
              HasSubstr("max_iterations"));
}

TEST(WaterSideModelFit, RejectsTooFewSamples) {
  WaterSideModelFitOptions options;
  options.grid_step = 300.0;  // 3 x 2 samples for 8 parameters
  EXPECT_THAT(test::ErrorMessage(FitWaterSideModel(
                  InWater(test::AlphasenseCam0(), 1.333), options)),
              HasSubstr("fewer than twice the 8 parameters"));
}

// Autodiff Jacobian of the functor against central differences; the
// difference step 1e-6 relative leaves a truncation error ~1e-10 relative.
TEST(WaterSideProjectionError, JacobianMatchesCentralDifferences) {
  const Camera camera = test::AlphasenseCam0();
  const Eigen::Vector2d normalized(0.41, -0.27);
  const Eigen::Vector2d pixel(500.0, 180.0);
  std::unique_ptr<ceres::CostFunction> cost(
      WaterSideProjectionError<EquidistantLens>::Create(normalized, pixel));
  double params[8];
  for (int i = 0; i < 8; ++i) params[i] = camera.params()[i];
  const double* blocks[] = {params};
  double residual[2];
  double jacobian[16];
  double* jacobians[] = {jacobian};
  ASSERT_TRUE(cost->Evaluate(blocks, residual, jacobians));
  EXPECT_NEAR(residual[0], camera.ImageFromNormalized(normalized).x() - 500.0,
              1e-12);
  for (int j = 0; j < 8; ++j) {
    const double step = 1e-6 * std::max(1.0, std::abs(params[j]));
    double plus[8];
    double minus[8];
    std::copy(params, params + 8, plus);
    std::copy(params, params + 8, minus);
    plus[j] += step;
    minus[j] -= step;
    double r_plus[2];
    double r_minus[2];
    const double* plus_blocks[] = {plus};
    const double* minus_blocks[] = {minus};
    ASSERT_TRUE(cost->Evaluate(plus_blocks, r_plus, nullptr));
    ASSERT_TRUE(cost->Evaluate(minus_blocks, r_minus, nullptr));
    for (int k = 0; k < 2; ++k) {
      const double numeric = (r_plus[k] - r_minus[k]) / (2.0 * step);
      EXPECT_NEAR(jacobian[8 * k + j], numeric,
                  1e-6 * std::max(1.0, std::abs(numeric)))
          << "residual " << k << " parameter " << j;
    }
  }
}

}  // namespace
}  // namespace rcm::water_side_model_fit_test
