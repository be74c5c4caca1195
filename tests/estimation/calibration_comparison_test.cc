#include "rcm/estimation/calibration_comparison.h"

#include <ceres/ceres.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "rcm/camera/refractive_camera.h"
#include "rcm/estimation/image_sample_grid.h"
#include "rcm/estimation/refracted_projection_error.h"
#include "rcm/estimation/water_side_model_fit.h"
#include "support/reader_inputs.h"
#include "support/test_rigs.h"

namespace rcm::calibration_comparison_test {
namespace {

using ::testing::HasSubstr;

// `camera` with its principal point moved by `shift` pixels.
Camera Shifted(const Camera& camera, const Eigen::Vector2d& shift) {
  return Camera::Create(camera.model(), camera.width(), camera.height(),
                        {camera.fx(), camera.fy(), camera.cx() + shift.x(),
                         camera.cy() + shift.y()},
                        camera.Distortion())
      .value();
}

// Exact observations: pixels on a grid over the image of `camera` behind a
// flat port at index n, each with the ray in the medium it sees, plus
// Gaussian pixel noise of `sigma_px` per coordinate (seeded).
std::vector<PixelRay> Observations(const Camera& camera, double n,
                                   double step, double sigma_px = 0.0,
                                   uint32_t seed = 1) {
  const RefractiveCamera refractive = RefractiveCamera::Create(camera, n).value();
  std::mt19937 random(seed);
  std::normal_distribution<double> noise(0.0, sigma_px);
  std::vector<PixelRay> samples;
  for (const Eigen::Vector2d& pixel : test::ImageGrid(camera, step)) {
    const std::optional<Eigen::Vector3d> ray =
        refractive.BearingInWaterFromImage(pixel);
    if (!ray.has_value() || !((*ray)[2] > 0.0)) continue;
    Eigen::Vector2d observed = pixel;
    if (sigma_px > 0.0) {
      // y before x, in a statement of its own (argument order is
      // unspecified).
      const double noise_y = noise(random);
      observed += Eigen::Vector2d(noise(random), noise_y);
    }
    samples.push_back({observed, *ray});
  }
  return samples;
}

CalibrationComparisonOptions WithShift(bool estimate_shift) {
  CalibrationComparisonOptions options;
  options.estimate_principal_point_shift = estimate_shift;
  return options;
}

// Noise-free observations give n (and the shift) to 1e-9: the solver
// reaches the zero residual, floored by the 1e-14 undistortion of the
// rays and the conditioning of n (d pixel / d n ~ 100-1000 px).
constexpr double kExactTolerance = 1e-9;

TEST(CalibrationComparison, ExactRaysGiveTheIndex) {
  for (const Camera& camera :
       {test::AlphasenseCam0(), test::EurocRadtanCamera()}) {
    const StatusOr<IndexFromRays> fit = EstimateIndexFromRays(
        camera, Observations(camera, 1.3371, 20.0), WithShift(false));
    ASSERT_TRUE(fit.ok()) << fit.status().message();
    EXPECT_NEAR(fit->n, 1.3371, kExactTolerance);
    EXPECT_LT(fit->sigma_px, 1e-9);
    EXPECT_TRUE(fit->converged);
  }
}

TEST(CalibrationComparison, ExactRaysGiveTheIndexAndTheShift) {
  const Camera camera = test::AlphasenseCam1();
  const Eigen::Vector2d shift(1.5, -0.8);
  const StatusOr<IndexFromRays> fit = EstimateIndexFromRays(
      camera, Observations(Shifted(camera, shift), 1.345, 20.0),
      WithShift(true));
  ASSERT_TRUE(fit.ok()) << fit.status().message();
  EXPECT_NEAR(fit->n, 1.345, kExactTolerance);
  EXPECT_NEAR(fit->principal_point_shift.x(), shift.x(), kExactTolerance);
  EXPECT_NEAR(fit->principal_point_shift.y(), shift.y(), kExactTolerance);
}

// 0.3 px noise on 1900 samples: n within 4 of its own sigmas (a 6e-5
// two-sided chance for a Gaussian), the noise estimate within 5 % (2m - p
// ~ 3800 degrees of freedom: its relative sd is 1/sqrt(2 * 3800) = 1.1 %).
TEST(CalibrationComparison, NoisyRaysWithinTheirSigma) {
  constexpr double kSigmaPx = 0.3;
  const Camera camera = test::AlphasenseCam0();
  const std::vector<PixelRay> samples =
      Observations(camera, 1.333, 12.0, kSigmaPx, 7);
  const StatusOr<IndexFromRays> fit =
      EstimateIndexFromRays(camera, samples, WithShift(true));
  ASSERT_TRUE(fit.ok()) << fit.status().message();
  EXPECT_GT(samples.size(), 1500u);
  EXPECT_LT(std::abs(fit->n - 1.333), 4.0 * fit->sigma_n);
  EXPECT_LT(fit->sigma_n, 1e-4);
  EXPECT_NEAR(fit->sigma_px, kSigmaPx, 0.05 * kSigmaPx);
  for (int k = 0; k < 2; ++k) {
    EXPECT_LT(std::abs(fit->principal_point_shift[k]),
              4.0 * fit->sigma_principal_point_shift[k]);
  }
}

// The reported sigma is honest: over 80 seeds the z-scores (estimate -
// truth) / sigma have a standard deviation within [0.75, 1.25] (its
// sampling sd is 1/sqrt(2 * 80) = 0.08, so the band is 3 sd) and a mean
// within 0.35 (3 sd of a mean of 80 unit variables).
TEST(CalibrationComparison, MonteCarloSigmaIsHonest) {
  constexpr int kTrials = 80;
  constexpr double kSigmaPx = 0.5;
  const Camera camera = test::EurocRadtanCamera();
  std::vector<double> z_n;
  std::vector<double> z_sx;
  for (int trial = 0; trial < kTrials; ++trial) {
    const StatusOr<IndexFromRays> fit = EstimateIndexFromRays(
        camera, Observations(camera, 1.34, 40.0, kSigmaPx, 100 + trial),
        WithShift(true));
    ASSERT_TRUE(fit.ok()) << fit.status().message();
    z_n.push_back((fit->n - 1.34) / fit->sigma_n);
    z_sx.push_back(fit->principal_point_shift.x() /
                   fit->sigma_principal_point_shift.x());
  }
  for (const std::vector<double>* z : {&z_n, &z_sx}) {
    double mean = 0.0;
    for (const double v : *z) mean += v / kTrials;
    double variance = 0.0;
    for (const double v : *z) variance += (v - mean) * (v - mean) / (kTrials - 1);
    EXPECT_NEAR(std::sqrt(variance), 1.0, 0.25);
    EXPECT_LT(std::abs(mean), 0.35);
  }
}

// Acceptance (issue 9): compare recovers n within 2e-4 when the "water"
// calibration is the one rcm export fits to the air calibration.
TEST(CalibrationComparison, RecoversIndexFromAnExportedWaterCalibration) {
  for (const Camera& air : {test::AlphasenseCam0(), test::AlphasenseCam1()}) {
    for (const LensModelId model :
         {LensModelId::kEquidistant, LensModelId::kRadTan}) {
      WaterSideModelFitOptions export_options;
      export_options.model = model;
      const StatusOr<WaterSideModelFit> water = FitWaterSideModel(
          RefractiveCamera::Create(air, 1.333).value(), export_options);
      ASSERT_TRUE(water.ok()) << water.status().message();
      const StatusOr<CalibrationComparison> comparison =
          CompareCalibrations(air, water->camera, WithShift(true));
      ASSERT_TRUE(comparison.ok()) << comparison.status().message();
      std::printf(
          "%s water model: n = %.7f (off by %+.1e), shift (%+.4f, %+.4f) px, "
          "residual RMS %.4f px, max %.3f px\n",
          std::string(LensModelName(model)).c_str(), comparison->fit.n,
          comparison->fit.n - 1.333, comparison->fit.principal_point_shift.x(),
          comparison->fit.principal_point_shift.y(),
          comparison->residual_stats.rms_px, comparison->residual_stats.max_px);
      EXPECT_NEAR(comparison->fit.n, 1.333, 2e-4);
      EXPECT_LT(comparison->residual_stats.rms_px, 0.1);
      EXPECT_EQ(comparison->num_unusable, 0);
    }
  }
}

TEST(CalibrationComparison, ResidualFieldHoldsTheResiduals) {
  const Camera air = test::AlphasenseCam0();
  const StatusOr<WaterSideModelFit> water = FitWaterSideModel(
      RefractiveCamera::Create(air, 1.333).value(), WaterSideModelFitOptions());
  ASSERT_TRUE(water.ok());
  const StatusOr<CalibrationComparison> comparison =
      CompareCalibrations(air, water->camera, CalibrationComparisonOptions());
  ASSERT_TRUE(comparison.ok());
  ASSERT_TRUE(comparison->residual_field.Check().ok());
  int64_t present = 0;
  for (size_t i = 0; i < comparison->residual_field.errors.size(); ++i) {
    const auto& error = comparison->residual_field.errors[i];
    if (!error.has_value()) continue;
    ++present;
    const int col = static_cast<int>(i) % comparison->residual_field.cols;
    const int row = static_cast<int>(i) / comparison->residual_field.cols;
    EXPECT_TRUE(InRegion(comparison->residual_field.Pixel(col, row),
                                comparison->region));
  }
  EXPECT_EQ(present, comparison->residual_stats.num_samples);
}

TEST(CalibrationComparison, RejectsDifferentImageSizes) {
  EXPECT_THAT(test::ErrorMessage(CompareCalibrations(
                  test::AlphasenseCam0(), test::EurocRadtanCamera(),
                  CalibrationComparisonOptions())),
              HasSubstr("720 x 540 images and the underwater one for 752 x 480"));
}

TEST(CalibrationComparison, RejectsNonFiniteAndBehindTheCameraSamples) {
  const Camera camera = test::AlphasenseCam0();
  std::vector<PixelRay> samples = Observations(camera, 1.333, 40.0);
  samples[3].pixel.x() = std::nan("");
  EXPECT_THAT(test::ErrorMessage(EstimateIndexFromRays(
                  camera, samples, CalibrationComparisonOptions())),
              HasSubstr("sample 3"));
  samples = Observations(camera, 1.333, 40.0);
  samples[5].ray_in_water.z() = -1.0;
  EXPECT_THAT(test::ErrorMessage(EstimateIndexFromRays(
                  camera, samples, CalibrationComparisonOptions())),
              HasSubstr("sample 5"));
}

TEST(CalibrationComparison, RejectsTooFewSamples) {
  const Camera camera = test::AlphasenseCam0();
  std::vector<PixelRay> samples = Observations(camera, 1.333, 40.0);
  samples.resize(9);
  EXPECT_THAT(test::ErrorMessage(EstimateIndexFromRays(
                  camera, samples, CalibrationComparisonOptions())),
              HasSubstr("at least 10 needed"));
}

// Every sample at the principal point: refraction does not move the
// optical axis, so n is not observed.
TEST(CalibrationComparison, RejectsSamplesThatDoNotObserveTheIndex) {
  const Camera camera = test::AlphasenseCam0();
  const std::vector<PixelRay> samples(
      20, PixelRay{Eigen::Vector2d(camera.cx(), camera.cy()),
                   Eigen::Vector3d(0.0, 0.0, 1.0)});
  EXPECT_THAT(test::ErrorMessage(EstimateIndexFromRays(
                  camera, samples, CalibrationComparisonOptions())),
              HasSubstr("do not determine the refractive index"));
}

TEST(CalibrationComparison, RejectsInvalidOptions) {
  CalibrationComparisonOptions options;
  options.inset = -0.1;
  EXPECT_THAT(test::ErrorMessage(CompareCalibrations(
                  test::AlphasenseCam0(), test::AlphasenseCam0(), options)),
              HasSubstr("inset"));
  options = CalibrationComparisonOptions();
  options.grid_step = std::nan("");
  EXPECT_THAT(test::ErrorMessage(CompareCalibrations(
                  test::AlphasenseCam0(), test::AlphasenseCam0(), options)),
              HasSubstr("grid_step"));
}

// Autodiff Jacobian against central differences in n and the shift.
TEST(RefractedProjectionError, JacobianMatchesCentralDifferences) {
  const Camera camera = test::AlphasenseCam0();
  std::unique_ptr<ceres::CostFunction> cost(
      RefractedProjectionError<EquidistantLens>::Create(
          camera, Eigen::Vector3d(0.3, -0.2, 1.0), Eigen::Vector2d(470, 200)));
  double n = 1.333;
  double shift[2] = {0.4, -0.3};
  const double* blocks[] = {&n, shift};
  double residual[2];
  double jacobian_n[2];
  double jacobian_shift[4];
  double* jacobians[] = {jacobian_n, jacobian_shift};
  ASSERT_TRUE(cost->Evaluate(blocks, residual, jacobians));
  auto evaluate = [&](double n_value, double sx, double sy, double* r) {
    const double s[2] = {sx, sy};
    const double* b[] = {&n_value, s};
    ASSERT_TRUE(cost->Evaluate(b, r, nullptr));
  };
  constexpr double kStep = 1e-6;
  double plus[2];
  double minus[2];
  evaluate(n + kStep, shift[0], shift[1], plus);
  evaluate(n - kStep, shift[0], shift[1], minus);
  for (int k = 0; k < 2; ++k) {
    EXPECT_NEAR(jacobian_n[k], (plus[k] - minus[k]) / (2 * kStep), 1e-4);
  }
  evaluate(n, shift[0] + kStep, shift[1], plus);
  evaluate(n, shift[0] - kStep, shift[1], minus);
  EXPECT_NEAR(jacobian_shift[0], (plus[0] - minus[0]) / (2 * kStep), 1e-6);
  EXPECT_NEAR(jacobian_shift[2], (plus[1] - minus[1]) / (2 * kStep), 1e-6);
}

TEST(RefractedProjectionError, FalsePastTotalInternalReflection) {
  std::unique_ptr<ceres::CostFunction> cost(
      RefractedProjectionError<EquidistantLens>::Create(
          test::AlphasenseCam0(), Eigen::Vector3d(1.0, 0.0, 0.5),
          Eigen::Vector2d(700, 270)));
  double n = 1.333;  // critical angle 48.6 deg; the ray is 63 deg off axis
  double shift[2] = {0.0, 0.0};
  const double* blocks[] = {&n, shift};
  double residual[2];
  EXPECT_FALSE(cost->Evaluate(blocks, residual, nullptr));
}

}  // namespace
}  // namespace rcm::calibration_comparison_test
