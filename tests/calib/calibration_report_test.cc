#include "rcm/calib/calibration_report.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "rcm/io/atomic_file.h"
#include "rcm/util/number_format.h"
#include "support/temp_file.h"
#include "support/test_rigs.h"

namespace rcm::calib::calibration_report_test {
namespace {

namespace fs = std::filesystem;

// Sums of a few squared residuals in another order than the code's: a few
// ulp of 1 px^2.
constexpr double kRmsTolerance = 1e-12;

Camera MakeCamera(LensModelId model, const std::array<double, 4>& intrinsics,
                  const std::vector<double>& distortion, int width = 640,
                  int height = 480) {
  return Camera::Create(model, width, height, intrinsics, distortion).value();
}

Camera WithParams(const Camera& camera, const double* params) {
  return MakeCamera(
      camera.model(), {params[0], params[1], params[2], params[3]},
      std::vector<double>(params + 4, params + camera.num_params()),
      camera.width(), camera.height());
}

// The covariance of the first 8 parameters (every model the tests
// calibrate has at most 8), zero beyond.
CameraCalibration Calibrated(const Camera& camera,
                             const Eigen::Matrix<double, 8, 8>& covariance) {
  CameraCalibration calibration(camera);
  calibration.covariance.setZero();
  calibration.covariance.topLeftCorner<8, 8>() = covariance;
  for (int k = 0; k < 8; ++k) {
    calibration.sigma[k] = std::sqrt(covariance(k, k));
  }
  return calibration;
}

Eigen::Matrix<double, 8, 8> DiagonalCovariance(
    const std::vector<double>& sigmas) {
  Eigen::Matrix<double, 8, 8> covariance = Eigen::Matrix<double, 8, 8>::Zero();
  for (size_t k = 0; k < sigmas.size(); ++k) {
    covariance(k, k) = sigmas[k] * sigmas[k];
  }
  return covariance;
}

// ---------------------------------------------------------------------------
// ProjectionUncertainty.

TEST(ProjectionUncertainty, JacobianMatchesCentralDifferences) {
  // Central differences with steps of 1e-6 relative: the projection is
  // linear in fx, fy, cx, cy and in every distortion coefficient of the
  // radtan and equidistant models, so the truncation error vanishes and
  // what is left is round-off, ~1e-16 * 1000 px / 1e-6 = 1e-7 px per unit
  // parameter; the rational, ds and eucm models are not linear in theirs,
  // but their truncation error, ~h^2 f'' ~ 1e-12 * 1000 px, is smaller.
  constexpr double kTolerance = 1e-6;
  for (const Camera& camera : rcm::test::AllTestCameras()) {
    for (const Eigen::Vector2d& normalized :
         {Eigen::Vector2d(0.0, 0.0), Eigen::Vector2d(0.3, -0.2),
          Eigen::Vector2d(-0.6, 0.45)}) {
      const Eigen::Matrix<double, 2, kMaxLensParams> jacobian =
          PixelFromParamsJacobian(camera, normalized);
      double params[kMaxLensParams];
      std::copy(camera.params(), camera.params() + kMaxLensParams, params);
      for (int k = 0; k < kMaxLensParams; ++k) {
        if (k >= camera.num_params()) {
          EXPECT_EQ(jacobian.col(k).norm(), 0.0);
          continue;
        }
        const double step = 1e-6 * std::max(1.0, std::abs(params[k]));
        double plus[kMaxLensParams], minus[kMaxLensParams];
        std::copy(params, params + kMaxLensParams, plus);
        std::copy(params, params + kMaxLensParams, minus);
        plus[k] += step;
        minus[k] -= step;
        const Eigen::Vector2d difference =
            (WithParams(camera, plus).ImageFromNormalized(normalized) -
             WithParams(camera, minus).ImageFromNormalized(normalized)) /
            (2.0 * step);
        EXPECT_NEAR((jacobian.col(k) - difference).norm(), 0.0, kTolerance)
            << LensModelName(camera.model()) << " param " << k << " at "
            << normalized.transpose();
      }
    }
  }
}

TEST(ProjectionUncertainty, PinholeMatchesHandComputation) {
  // J = [[x, 0, 1, 0], [0, y, 0, 1]]: Sigma_u is diagonal with
  // x^2 s_fx^2 + s_cx^2 and y^2 s_fy^2 + s_cy^2. A handful of flops.
  constexpr double kTolerance = 1e-12;
  const Camera camera =
      MakeCamera(LensModelId::kPinhole, {500.0, 480.0, 320.0, 240.0}, {});
  const CameraCalibration calibration =
      Calibrated(camera, DiagonalCovariance({2.0, 3.0, 1.0, 0.5}));
  // (420, 300): x = 100 / 500 = 0.2, y = 60 / 480 = 0.125.
  // u: 0.04 * 4 + 1 = 1.16; v: 0.015625 * 9 + 0.25 = 0.390625.
  EXPECT_NEAR(ProjectionUncertainty(calibration, {420.0, 300.0}),
              std::sqrt(1.16), kTolerance);
  const Eigen::Matrix2d covariance =
      ProjectionCovariance(calibration, {420.0, 300.0}).value();
  EXPECT_NEAR(covariance(0, 0), 1.16, kTolerance);
  EXPECT_NEAR(covariance(1, 1), 0.390625, kTolerance);
  EXPECT_NEAR(covariance(0, 1), 0.0, kTolerance);
  // At (320, 540): x = 0, y = 0.625; v wins: 0.390625 * 9 + 0.25.
  EXPECT_NEAR(ProjectionUncertainty(calibration, {320.0, 540.0}),
              std::sqrt(0.390625 * 9.0 + 0.25), kTolerance);
}

TEST(ProjectionUncertainty, RadTanK1MatchesHandComputation) {
  // Only k1 uncertain: J's k1 column is (fx x r^2, fy y r^2), so Sigma_u =
  // s^2 a a^T with the one nonzero eigenvalue s^2 |a|^2. Relative round-off
  // of the unprojection and a few products.
  constexpr double kRelativeTolerance = 1e-10;
  const Camera camera = rcm::test::EurocRadtanCamera();
  const double s_k1 = 0.003;
  const CameraCalibration calibration =
      Calibrated(camera, DiagonalCovariance({0, 0, 0, 0, s_k1}));
  for (const Eigen::Vector2d& pixel :
       {Eigen::Vector2d(100.0, 80.0), Eigen::Vector2d(600.0, 400.0),
        Eigen::Vector2d(376.0, 10.0)}) {
    const Eigen::Vector2d xy = camera.NormalizedFromImage(pixel).value();
    const double r2 = xy.squaredNorm();
    const double expected =
        s_k1 * r2 * std::hypot(camera.fx() * xy.x(), camera.fy() * xy.y());
    EXPECT_NEAR(ProjectionUncertainty(calibration, pixel), expected,
                kRelativeTolerance * expected)
        << pixel.transpose();
  }
}

TEST(ProjectionUncertainty, ZeroForZeroCovarianceAndLinearInSigma) {
  // sigma(k^2 C) = k sigma(C) up to the round-off of one sqrt.
  constexpr double kRelativeTolerance = 1e-12;
  const Camera camera = rcm::test::AlphasenseCam0();
  const CameraCalibration zero =
      Calibrated(camera, Eigen::Matrix<double, 8, 8>::Zero());
  Eigen::Matrix<double, 8, 8> a;
  std::mt19937 rng(5);
  std::normal_distribution<double> normal(0.0, 1e-2);
  for (int i = 0; i < 8; ++i) {
    for (int j = 0; j < 8; ++j) a(i, j) = normal(rng);
  }
  const Eigen::Matrix<double, 8, 8> base = a * a.transpose();
  for (const Eigen::Vector2d& pixel :
       {Eigen::Vector2d(360.0, 270.0), Eigen::Vector2d(10.0, 20.0),
        Eigen::Vector2d(700.0, 530.0)}) {
    EXPECT_EQ(ProjectionUncertainty(zero, pixel), 0.0);
    const double reference =
        ProjectionUncertainty(Calibrated(camera, base), pixel);
    ASSERT_GT(reference, 0.0);
    for (const double k : {0.1, 1.0, 3.0, 250.0}) {
      EXPECT_NEAR(
          ProjectionUncertainty(Calibrated(camera, k * k * base), pixel),
          k * reference, kRelativeTolerance * k * reference)
          << k;
    }
  }
}

TEST(ProjectionUncertainty, NaNWhereThePixelHasNoRay) {
  // The equidistant lens maps rays up to 90 degrees off axis into a disc;
  // a pixel far outside it has no ray.
  const CameraCalibration calibration =
      Calibrated(rcm::test::AlphasenseCam0(), DiagonalCovariance({1, 1, 1, 1}));
  EXPECT_TRUE(std::isnan(ProjectionUncertainty(calibration, {1e5, 1e5})));
  EXPECT_FALSE(ProjectionCovariance(calibration, {1e5, 1e5}).has_value());
  EXPECT_TRUE(std::isfinite(ProjectionUncertainty(calibration, {0.0, 0.0})));
}

// ---------------------------------------------------------------------------
// Hand-built calibrations.

void AddCorner(StereoCalibration* calibration, int view, int camera,
               const Eigen::Vector2d& pixel, const Eigen::Vector2d& residual,
               bool inlier = true) {
  CornerResidual corner;
  corner.view = view;
  corner.camera = camera;
  corner.point_id = static_cast<int>(calibration->corners.size());
  corner.pixel = pixel;
  corner.residual = residual;
  corner.inlier = inlier;
  calibration->corners.push_back(corner);
}

std::vector<StereoView> NamedViews(int count) {
  std::vector<StereoView> views(count);
  for (int v = 0; v < count; ++v) {
    views[v].left_name = "left_" + std::to_string(v) + ".png";
    views[v].right_name = "right_" + std::to_string(v) + ".png";
  }
  return views;
}

StereoCalibration EmptyCalibration(int num_views, const Camera& camera,
                                   double sigma_px) {
  StereoCalibration calibration(camera, camera);
  calibration.cam0 = Calibrated(
      camera, DiagonalCovariance({sigma_px, sigma_px, sigma_px, sigma_px}));
  calibration.cam1 = calibration.cam0;
  calibration.cam0_from_target.assign(num_views, Rigid3d());
  return calibration;
}

// `num_views` views in which both cameras see a corner at the center of
// every cell of the default 8x6 grid over 640x480, each with a residual of
// 0.2 px in a direction that turns from corner to corner: every view and
// camera has an RMS of exactly 0.2 px. The cameras' intrinsics are known
// to 0.1 px: the uncertainty stays below 0.13 px.
StereoCalibration GoodCalibration(int num_views = 10) {
  StereoCalibration calibration =
      EmptyCalibration(num_views, rcm::test::PinholeCamera(), 0.1);
  for (int v = 0; v < num_views; ++v) {
    for (int c = 0; c < 2; ++c) {
      for (int row = 0; row < 6; ++row) {
        for (int col = 0; col < 8; ++col) {
          const double angle = 0.7 * (row * 8 + col + v + c);
          AddCorner(&calibration, v, c,
                    {-0.5 + (col + 0.5) * 80.0, -0.5 + (row + 0.5) * 80.0},
                    0.2 * Eigen::Vector2d(std::cos(angle), std::sin(angle)));
        }
      }
    }
  }
  return calibration;
}

constexpr ImageSize kVga{640, 480};

TEST(CalibrationReport, StatisticsOfAHandBuiltCalibration) {
  // Three views over a 400x200 image and a 4x2 grid (cells of 100x100);
  // view 1 has no pose.
  StereoCalibration calibration =
      EmptyCalibration(3, rcm::test::PinholeCamera(), 0.1);
  calibration.cam0_from_target[1] = std::nullopt;
  // cam0, view 0: cells (0, 0) [twice, once on the image's corner] and
  // (3, 1) [on the far corner, clamped into the last cell].
  AddCorner(&calibration, 0, 0, {10.0, 10.0}, {0.3, 0.4});
  AddCorner(&calibration, 0, 0, {-0.5, -0.5}, {0.6, 0.8});
  AddCorner(&calibration, 0, 0, {399.5, 199.5}, {0.0, 1.0});
  // An outlier in cell (1, 0): counted in the RMS, not in the coverage.
  AddCorner(&calibration, 0, 0, {150.0, 50.0}, {3.0, 4.0}, false);
  // cam0, view 2: 99.49 still lies in column 0, 99.5 in column 1; a
  // corner outside the image lies in no cell.
  AddCorner(&calibration, 2, 0, {99.49, 120.0}, {1.0, 0.0});
  AddCorner(&calibration, 2, 0, {99.5, 120.0}, {0.0, 2.0});
  AddCorner(&calibration, 2, 0, {-3.0, 50.0}, {0.0, 0.0});
  // cam1 sees only view 2.
  AddCorner(&calibration, 2, 1, {200.0, 100.0}, {0.1, 0.0});
  AddCorner(&calibration, 2, 1, {250.0, 100.0}, {0.0, 0.3}, false);

  CalibrationReportOptions options;
  options.coverage_cols = 4;
  options.coverage_rows = 2;
  const ImageSize size{400, 200};
  const CalibrationReport report =
      SummarizeCalibration(calibration, NamedViews(3), size, size, options);

  ASSERT_EQ(report.views.size(), 3u);
  EXPECT_EQ(report.num_views_used, 2);
  EXPECT_EQ(report.num_stereo_views_used, 1);  // view 2
  const CalibrationReport::View& v0 = report.views[0];
  EXPECT_EQ(v0.view, 0);
  EXPECT_EQ(v0.left_name, "left_0.png");
  EXPECT_EQ(v0.right_name, "right_0.png");
  EXPECT_TRUE(v0.used);
  EXPECT_EQ(v0.corners[0], 4);
  EXPECT_EQ(v0.corners[1], 0);
  EXPECT_EQ(v0.outliers[0], 1);
  EXPECT_EQ(v0.outliers[1], 0);
  // |e|^2: 0.25, 1, 1, 25.
  EXPECT_NEAR(v0.rms_px[0], std::sqrt(27.25 / 4), kRmsTolerance);
  EXPECT_TRUE(std::isnan(v0.rms_px[1]));
  EXPECT_FALSE(report.views[1].used);
  EXPECT_EQ(report.views[1].corners[0], 0);
  EXPECT_TRUE(std::isnan(report.views[1].rms_px[0]));
  const CalibrationReport::View& v2 = report.views[2];
  EXPECT_EQ(v2.corners[0], 3);
  EXPECT_EQ(v2.corners[1], 2);
  EXPECT_EQ(v2.outliers[1], 1);
  // |e|^2: 1, 4, 0 and 0.01, 0.09.
  EXPECT_NEAR(v2.rms_px[0], std::sqrt(5.0 / 3), kRmsTolerance);
  EXPECT_NEAR(v2.rms_px[1], std::sqrt(0.1 / 2), kRmsTolerance);

  const CalibrationReport::CameraStats& cam0 = report.cameras[0];
  EXPECT_EQ(cam0.corners, 7);
  EXPECT_EQ(cam0.outliers, 1);
  EXPECT_NEAR(cam0.rms_px, std::sqrt(32.25 / 7), kRmsTolerance);
  EXPECT_NEAR(cam0.inlier_rms_px, std::sqrt(7.25 / 6), kRmsTolerance);
  // Cells (0, 0), (3, 1), (0, 1), (1, 1) of 8.
  EXPECT_EQ(cam0.coverage, 4.0 / 8.0);
  const CalibrationReport::CameraStats& cam1 = report.cameras[1];
  EXPECT_EQ(cam1.corners, 2);
  EXPECT_EQ(cam1.outliers, 1);
  EXPECT_NEAR(cam1.rms_px, std::sqrt(0.1 / 2), kRmsTolerance);
  EXPECT_NEAR(cam1.inlier_rms_px, 0.1, kRmsTolerance);
  EXPECT_EQ(cam1.coverage, 1.0 / 8.0);  // the outlier's cell does not count
  EXPECT_NEAR(cam0.view_rms_limit_px, 3.0 * cam0.rms_px, kRmsTolerance);
  // Uncertainty over the image: ordered, positive, finite.
  EXPECT_GT(cam0.intrinsics_only_uncertainty_median_px, 0.0);
  EXPECT_LE(cam0.intrinsics_only_uncertainty_median_px,
            cam0.intrinsics_only_uncertainty_p95_px);
  EXPECT_LE(cam0.intrinsics_only_uncertainty_p95_px,
            cam0.intrinsics_only_uncertainty_max_px);
  // No view reaches 3x its camera's RMS.
  for (const CalibrationReport::View& view : report.views) {
    EXPECT_FALSE(view.flagged) << view.view;
  }
}

TEST(CalibrationReport, UncertaintyStatisticsOfAPinhole) {
  // Independent 0.1 px errors of f and c: sigma^2 = 0.01 (1 + max(x^2,
  // y^2)); over 640x480 at f = 400 the largest |x| of a sample is just
  // below 0.8, so the max lies just below 0.1 sqrt(1.64).
  const StereoCalibration calibration = GoodCalibration();
  const CalibrationReport report =
      SummarizeCalibration(calibration, NamedViews(10), kVga, kVga);
  const double corner = 0.1 * std::sqrt(1.0 + 0.8 * 0.8);
  EXPECT_LT(report.cameras[0].intrinsics_only_uncertainty_max_px, corner);
  EXPECT_GT(report.cameras[0].intrinsics_only_uncertainty_max_px,
            0.99 * corner);
  EXPECT_GT(report.cameras[0].intrinsics_only_uncertainty_median_px, 0.1);
}

TEST(CalibrationReport, NoWarningsForAGoodCalibration) {
  const CalibrationReport report =
      SummarizeCalibration(GoodCalibration(), NamedViews(10), kVga, kVga);
  EXPECT_TRUE(report.warnings.empty()) << report.warnings.front();
  EXPECT_EQ(report.num_views_used, 10);
  EXPECT_EQ(report.num_stereo_views_used, 10);
  EXPECT_EQ(report.cameras[0].coverage, 1.0);
  EXPECT_NEAR(report.cameras[1].rms_px, 0.2, kRmsTolerance);
}

// The warnings containing `text`.
int CountWarnings(const CalibrationReport& report, const std::string& text) {
  int count = 0;
  for (const std::string& warning : report.warnings) {
    EXPECT_EQ(warning.find('\n'), std::string::npos) << warning;
    if (warning.find(text) != std::string::npos) ++count;
  }
  return count;
}

TEST(CalibrationReport, WarnsAboutFewViewsExactlyBelowTheMinimum) {
  const StereoCalibration calibration = GoodCalibration();
  CalibrationReportOptions options;
  options.min_views = 10;
  options.min_stereo_views = 10;
  EXPECT_TRUE(
      SummarizeCalibration(calibration, NamedViews(10), kVga, kVga, options)
          .warnings.empty());
  options.min_views = 11;
  CalibrationReport report =
      SummarizeCalibration(calibration, NamedViews(10), kVga, kVga, options);
  ASSERT_EQ(report.warnings.size(), 1u);
  EXPECT_EQ(CountWarnings(report, "only 10 views used (11 or more"), 1);
  options.min_views = 10;
  options.min_stereo_views = 11;
  report =
      SummarizeCalibration(calibration, NamedViews(10), kVga, kVga, options);
  ASSERT_EQ(report.warnings.size(), 1u);
  EXPECT_EQ(CountWarnings(report, "both cameras"), 1);
}

TEST(CalibrationReport, WarnsAboutCoverageExactlyBelowTheMinimum) {
  // cam1 keeps the corners of the first `cells` of the 48 cells (row-major).
  const auto with_cells = [](int cells) {
    StereoCalibration calibration = GoodCalibration();
    std::vector<CornerResidual> kept;
    for (const CornerResidual& corner : calibration.corners) {
      const int index = static_cast<int>(corner.pixel.y() / 80.0) * 8 +
                        static_cast<int>(corner.pixel.x() / 80.0);
      if (corner.camera == 0 || index < cells) kept.push_back(corner);
    }
    calibration.corners = kept;
    return SummarizeCalibration(calibration, NamedViews(10), kVga, kVga);
  };
  const CalibrationReport half = with_cells(24);  // 0.5: not below 0.5
  EXPECT_EQ(half.cameras[1].coverage, 0.5);
  EXPECT_TRUE(half.warnings.empty()) << half.warnings.front();
  const CalibrationReport below = with_cells(23);
  EXPECT_EQ(below.cameras[1].coverage, 23.0 / 48.0);
  ASSERT_EQ(below.warnings.size(), 1u);
  EXPECT_EQ(below.warnings[0],
            "cam1: corners cover 48 % of the image (8x6 grid); add views near "
            "the corners and edges");
}

TEST(CalibrationReport, WarnsAboutUncertaintyExactlyAboveTheMaximum) {
  // cam0 ten times less certain than cam1.
  StereoCalibration calibration = GoodCalibration();
  calibration.cam0.covariance *= 100.0;
  const CalibrationReport reference =
      SummarizeCalibration(calibration, NamedViews(10), kVga, kVga);
  const double p95 = reference.cameras[0].intrinsics_only_uncertainty_p95_px;
  ASSERT_GT(
      p95,
      10.0 * reference.cameras[1].intrinsics_only_uncertainty_p95_px * 0.999);
  CalibrationReportOptions options;
  options.max_uncertainty_px = p95 * (1.0 + 1e-9);
  EXPECT_TRUE(
      SummarizeCalibration(calibration, NamedViews(10), kVga, kVga, options)
          .warnings.empty());
  options.max_uncertainty_px = p95 * (1.0 - 1e-9);
  const CalibrationReport report =
      SummarizeCalibration(calibration, NamedViews(10), kVga, kVga, options);
  ASSERT_EQ(report.warnings.size(), 1u);
  EXPECT_EQ(report.warnings[0].rfind(
                "cam0: intrinsics-only projection uncertainty", 0),
            0u)
      << report.warnings[0];
}

TEST(CalibrationReport, FlagsAViewExactlyAboveTheFactor) {
  // View 3's cam1 residuals are 5 times the others'.
  StereoCalibration calibration = GoodCalibration();
  for (CornerResidual& corner : calibration.corners) {
    if (corner.view == 3 && corner.camera == 1) corner.residual *= 5.0;
  }
  const CalibrationReport reference =
      SummarizeCalibration(calibration, NamedViews(10), kVga, kVga);
  // Overall cam1 RMS: sqrt((9 * 0.04 + 25 * 0.04) / 10).
  const double overall = 0.2 * std::sqrt(34.0 / 10.0);
  EXPECT_NEAR(reference.cameras[1].rms_px, overall, kRmsTolerance);
  EXPECT_NEAR(reference.views[3].rms_px[1], 1.0, kRmsTolerance);
  const double ratio = 1.0 / overall;  // 2.71: not flagged at 3
  EXPECT_TRUE(reference.warnings.empty()) << reference.warnings.front();

  CalibrationReportOptions options;
  options.max_view_rms_factor = ratio * (1.0 + 1e-9);
  EXPECT_TRUE(
      SummarizeCalibration(calibration, NamedViews(10), kVga, kVga, options)
          .warnings.empty());
  options.max_view_rms_factor = ratio * (1.0 - 1e-9);
  const CalibrationReport report =
      SummarizeCalibration(calibration, NamedViews(10), kVga, kVga, options);
  for (const CalibrationReport::View& view : report.views) {
    EXPECT_EQ(view.flagged, view.view == 3) << view.view;
  }
  ASSERT_EQ(report.warnings.size(), 1u);
  EXPECT_EQ(report.warnings[0],
            "view 3 (left_3.png, right_3.png): RMS 1.00 px in cam1, 2.7 times "
            "the camera's 0.37 px; check its detection or drop the view");
}

TEST(CalibrationReport, OptionsCheck) {
  EXPECT_TRUE(CalibrationReportOptions().Check().ok());
  CalibrationReportOptions options;
  options.coverage_cols = 0;
  EXPECT_FALSE(options.Check().ok());
  options = CalibrationReportOptions();
  options.min_coverage = 1.5;
  EXPECT_FALSE(options.Check().ok());
  options = CalibrationReportOptions();
  options.max_uncertainty_px = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(options.Check().ok());
  options = CalibrationReportOptions();
  options.max_view_rms_factor = 0.0;
  EXPECT_FALSE(options.Check().ok());
}

// ---------------------------------------------------------------------------
// Pictures.

// Bounding box of the pixels where two images of equal size differ.
cv::Rect Difference(const cv::Mat& a, const cv::Mat& b) {
  cv::Mat diff;
  cv::absdiff(a, b, diff);
  cv::Mat gray;
  cv::cvtColor(diff, gray, cv::COLOR_BGR2GRAY);
  std::vector<cv::Point> points;
  cv::findNonZero(gray > 8, points);
  return points.empty() ? cv::Rect() : cv::boundingRect(points);
}

TEST(CalibrationReport, ResidualFieldDrawsArrowsWhereTheCornersAre) {
  // One corner with a 2 px residual drawn 10 times larger: to the right,
  // then to the left. Same numbers, so only the arrow moves.
  const auto draw = [](double direction) {
    StereoCalibration calibration = GoodCalibration(1);
    calibration.corners.clear();
    AddCorner(&calibration, 0, 1, {320.0, 240.0}, {2.0 * direction, 0.0});
    return DrawResidualField(calibration, 1, kVga, 10.0);
  };
  const cv::Mat right = draw(1.0);
  ASSERT_EQ(right.type(), CV_8UC3);
  EXPECT_GE(right.cols, kVga.width);
  EXPECT_GE(right.rows, kVga.height);
  const cv::Rect moved = Difference(right, draw(-1.0));
  // Two 20 px arrows from the same dot, opposite: about 40 px wide (less
  // where the shafts overlap the dot), a few px high (the heads).
  EXPECT_GT(moved.width, 30);
  EXPECT_LT(moved.width, 50);
  EXPECT_LT(moved.height, 16);
  EXPECT_GT(moved.y, 0.4 * right.rows);
  EXPECT_LT(moved.y, 0.6 * right.rows);
}

TEST(CalibrationReport, ResidualFieldAutoScale) {
  // Auto scale: the 95th percentile residual (0.2 px) is ~3 % of 640 px:
  // 19.2 px -> x96 -> the 1-2-5 number below, x50. Compared with the
  // explicit x50 picture it is identical.
  const StereoCalibration calibration = GoodCalibration(2);
  const cv::Mat automatic = DrawResidualField(calibration, 0, kVga);
  const cv::Mat fifty = DrawResidualField(calibration, 0, kVga, 50.0);
  EXPECT_EQ(cv::norm(automatic, fifty, cv::NORM_INF), 0.0);
  EXPECT_GT(cv::norm(automatic, DrawResidualField(calibration, 0, kVga, 20.0),
                     cv::NORM_INF),
            0.0);
}

TEST(CalibrationReport, CoverageAndUncertaintyPictures) {
  const StereoCalibration calibration = GoodCalibration(3);
  const cv::Mat coverage = DrawCoverage(calibration, NamedViews(3), 0, kVga);
  ASSERT_EQ(coverage.type(), CV_8UC3);
  EXPECT_GE(coverage.cols, kVga.width);
  EXPECT_GE(coverage.rows, kVga.height);
  StereoCalibration empty = calibration;
  empty.corners.clear();
  EXPECT_GT(
      Difference(coverage, DrawCoverage(empty, NamedViews(3), 0, kVga)).area(),
      kVga.width * kVga.height / 2);

  const cv::Mat uncertainty = DrawProjectionUncertainty(calibration.cam0);
  ASSERT_EQ(uncertainty.type(), CV_8UC3);
  EXPECT_GE(uncertainty.cols, kVga.width);
  EXPECT_GE(uncertainty.rows, kVga.height);
  // The heat map varies: many distinct colors.
  std::set<int> colors;
  for (int v = 0; v < uncertainty.rows; v += 3) {
    for (int u = 0; u < uncertainty.cols; u += 3) {
      const cv::Vec3b c = uncertainty.at<cv::Vec3b>(v, u);
      colors.insert(c[0] << 16 | c[1] << 8 | c[2]);
    }
  }
  EXPECT_GT(colors.size(), 100u);
  // A zero covariance still draws.
  StereoCalibration zero = calibration;
  zero.cam0.covariance.setZero();
  EXPECT_EQ(DrawProjectionUncertainty(zero.cam0).size(), uncertainty.size());
}

TEST(CalibrationReport, PerViewRmsPicture) {
  StereoCalibration calibration = GoodCalibration(4);
  calibration.cam0_from_target[2] = std::nullopt;
  const CalibrationReport report =
      SummarizeCalibration(calibration, NamedViews(4), kVga, kVga);
  const cv::Mat plot = DrawPerViewRms(report);
  ASSERT_EQ(plot.type(), CV_8UC3);
  EXPECT_EQ(plot.cols, 1000);
  EXPECT_EQ(plot.rows, 600);
  cv::Scalar mean, stddev;
  cv::meanStdDev(plot, mean, stddev);
  EXPECT_GT(stddev[0], 5.0);
  // An empty report draws too.
  EXPECT_EQ(DrawPerViewRms(CalibrationReport()).size(), plot.size());
}

// ---------------------------------------------------------------------------
// Files.

// A realistic synthetic calibration of the Alphasense pair: a 7x6 board
// seen from 18 poses, 0.12 px of noise, cam1 with a systematic radial
// residual (a lens model that does not quite fit), two outliers in view 5,
// view 11 12 times noisier in cam0 (flagged), view 16 not used, and covariances
// 0.12^2 (J^T J)^-1 over the inlier corners (intrinsics only).
struct Synthetic {
  Synthetic(const Camera& cam0, const Camera& cam1) : calibration(cam0, cam1) {}

  StereoCalibration calibration;
  std::vector<StereoView> views;
  ImageSize sizes[2];
};

Synthetic RealisticCalibration() {
  const Camera cameras[2] = {rcm::test::AlphasenseCam0(),
                             rcm::test::AlphasenseCam1()};
  Synthetic synthetic(cameras[0], cameras[1]);
  for (int c = 0; c < 2; ++c) {
    synthetic.sizes[c] = {cameras[c].width(), cameras[c].height()};
  }
  StereoCalibration& calibration = synthetic.calibration;
  calibration.cam1_from_cam0.translation = Eigen::Vector3d(-0.11, 0, 0);
  constexpr int kViews = 18;
  constexpr double kNoise = 0.12;
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  std::normal_distribution<double> noise(0.0, kNoise);
  synthetic.views = NamedViews(kViews);
  calibration.cam0_from_target.assign(kViews, std::nullopt);
  Eigen::Matrix<double, 8, 8> information[2] = {
      Eigen::Matrix<double, 8, 8>::Zero(), Eigen::Matrix<double, 8, 8>::Zero()};
  for (int v = 0; v < kViews; ++v) {
    const double depth = 0.45 + 0.35 * (0.5 + 0.5 * uniform(rng));
    // Draws in statements of their own, last coordinate first (gcc's
    // order): argument evaluation order is unspecified.
    const double center_y = 0.6 * depth * uniform(rng);
    const Eigen::Vector3d center(0.9 * depth * uniform(rng), center_y, depth);
    const double axis_z = 0.3 * uniform(rng);
    const double axis_y = uniform(rng);
    const Eigen::Vector3d axis =
        Eigen::Vector3d(uniform(rng), axis_y, axis_z).normalized();
    Rigid3d pose;
    pose.rotation = Eigen::AngleAxisd(0.6 * uniform(rng), axis).matrix();
    pose.translation =
        center - pose.rotation * Eigen::Vector3d(0.15, 0.125, 0.0);
    if (v != 16) calibration.cam0_from_target[v] = pose;
    for (int c = 0; c < 2; ++c) {
      TargetObservation observation;
      observation.detector = "synthetic";
      std::vector<CornerResidual> corners;
      for (int row = 0; row < 6; ++row) {
        for (int col = 0; col < 7; ++col) {
          Eigen::Vector3d point =
              pose * Eigen::Vector3d(0.05 * col, 0.05 * row, 0.0);
          if (c == 1) point = calibration.cam1_from_cam0 * point;
          if (point.z() <= 0.05) continue;
          const std::optional<Eigen::Vector2d> pixel =
              cameras[c].ProjectNormalized(point.hnormalized());
          if (!pixel || !cameras[c].InImage(*pixel)) continue;
          observation.point_ids.push_back(row * 7 + col);
          observation.pixels.push_back(*pixel);
          CornerResidual corner;
          corner.view = v;
          corner.camera = c;
          corner.point_id = row * 7 + col;
          corner.pixel = *pixel;
          const double scale = (v == 11 && c == 0) ? 12.0 : 1.0;
          const double noise_y = noise(rng);  // before x, as above
          corner.residual = scale * Eigen::Vector2d(noise(rng), noise_y);
          if (c == 1) {
            const Eigen::Vector2d offset =
                *pixel - Eigen::Vector2d(cameras[c].cx(), cameras[c].cy());
            corner.residual +=
                0.6 * std::pow(offset.norm() / 450.0, 3) * offset.normalized();
          }
          if (v == 5 && (row * 7 + col) % 17 == 3) {
            corner.residual = Eigen::Vector2d(2.5, -3.0);
            corner.inlier = false;
          }
          if (corner.inlier) {
            const Eigen::Matrix<double, 2, 8> j =
                PixelFromParamsJacobian(cameras[c], point.hnormalized())
                    .leftCols<8>();
            information[c] += j.transpose() * j;
          }
          corners.push_back(corner);
        }
      }
      if (observation.size() < 6) continue;
      (c == 0 ? synthetic.views[v].left : synthetic.views[v].right) =
          observation;
      if (v != 16) {
        calibration.corners.insert(calibration.corners.end(), corners.begin(),
                                   corners.end());
      }
    }
  }
  CameraCalibration* results[2] = {&calibration.cam0, &calibration.cam1};
  for (int c = 0; c < 2; ++c) {
    *results[c] =
        Calibrated(cameras[c], kNoise * kNoise * information[c].inverse());
  }
  return synthetic;
}

TEST(CalibrationReport, WritesEveryFile) {
  const Synthetic synthetic = RealisticCalibration();
  const CalibrationReport report =
      SummarizeCalibration(synthetic.calibration, synthetic.views,
                           synthetic.sizes[0], synthetic.sizes[1]);
  EXPECT_TRUE(report.views[11].flagged);
  EXPECT_EQ(report.cameras[0].outliers + report.cameras[1].outliers,
            static_cast<int>(std::count_if(
                synthetic.calibration.corners.begin(),
                synthetic.calibration.corners.end(),
                [](const CornerResidual& corner) { return !corner.inlier; })));
  // RCM_CALIB_REPORT_DIR keeps the pictures for a person to look at.
  const char* keep = std::getenv("RCM_CALIB_REPORT_DIR");
  const std::string directory = keep != nullptr
                                    ? std::string(keep)
                                    : rcm::test::TempFilePath("report/sub");
  const Status status = WriteCalibrationReport(
      directory, report, synthetic.calibration, synthetic.views,
      synthetic.sizes[0], synthetic.sizes[1]);
  ASSERT_TRUE(status.ok()) << status.message();
  for (const std::string name :
       {"residuals_cam0.png", "residuals_cam1.png", "coverage_cam0.png",
        "coverage_cam1.png", "intrinsics_only_uncertainty_cam0.png",
        "intrinsics_only_uncertainty_cam1.png", "per_view_rms.png",
        "per_view.csv"}) {
    const fs::path path = fs::path(directory) / name;
    ASSERT_TRUE(fs::is_regular_file(path)) << path;
    EXPECT_GT(fs::file_size(path), 100u) << path;
  }
  // This calibration is made by hand, without the covariance of every
  // unknown: no mean-frames map (CalibrateCli.FoldersToCamchainAndReport
  // sees it written).
  EXPECT_FALSE(
      fs::exists(fs::path(directory) / "projection_uncertainty_cam0.png"));
  const std::string csv = ReadFileToString(directory + "/per_view.csv").value();
  std::istringstream lines(csv);
  std::string line;
  std::getline(lines, line);
  EXPECT_EQ(line,
            "view,left,right,corners0,corners1,outliers0,outliers1,rms0_px,"
            "rms1_px,used,flagged");
  int rows = 0;
  while (std::getline(lines, line)) ++rows;
  EXPECT_EQ(rows, 18);
  if (keep == nullptr) fs::remove_all(rcm::test::TempFilePath("report"));
}

TEST(CalibrationReport, PerViewCsvRows) {
  StereoCalibration calibration = GoodCalibration(2);
  calibration.cam0_from_target[1] = std::nullopt;
  calibration.corners.erase(
      std::remove_if(calibration.corners.begin(), calibration.corners.end(),
                     [](const CornerResidual& c) { return c.view == 1; }),
      calibration.corners.end());
  std::vector<StereoView> views = NamedViews(2);
  views[1].left_name = "a,b \"c\".png";
  const CalibrationReport report =
      SummarizeCalibration(calibration, views, kVga, kVga);
  EXPECT_EQ(FormatPerViewCsv(report),
            "view,left,right,corners0,corners1,outliers0,outliers1,rms0_px,"
            "rms1_px,used,flagged\n"
            "0,left_0.png,right_0.png,48,48,0,0," +
                FormatDouble(report.views[0].rms_px[0]) + "," +
                FormatDouble(report.views[0].rms_px[1]) +
                ",1,0\n"
                "1,\"a,b \"\"c\"\".png\",right_1.png,0,0,0,0,nan,nan,0,0\n");
}

TEST(CalibrationReport, WriteFailsWithOneLineForAnUnwritableFolder) {
  const StereoCalibration calibration = GoodCalibration(1);
  const CalibrationReport report =
      SummarizeCalibration(calibration, NamedViews(1), kVga, kVga);
  const std::string file =
      rcm::test::WriteTempFile("plain.txt", "not a folder");
  const Status status = WriteCalibrationReport(
      file + "/report", report, calibration, NamedViews(1), kVga, kVga);
  ASSERT_FALSE(status.ok());
  EXPECT_EQ(status.message().find('\n'), std::string::npos);
  EXPECT_NE(status.message().find(file + "/report"), std::string::npos)
      << status.message();
  fs::remove(file);
}

}  // namespace
}  // namespace rcm::calib::calibration_report_test
