// The report of a stereo calibration (stereo_calibration.h): numbers per
// view and per camera, warnings in plain words, and the pictures a person
// looks at before trusting the result.
//
// Two projection uncertainties. The one reported as "projection
// uncertainty" is mrcal's mean-frames figure (projection_uncertainty.h):
// through every unknown, board poses included, at a stated distance
// (CalibrationReportOptions::uncertainty_distance_m, infinity by default),
// so that it compares with mrcal's. The other, "intrinsics-only", is below.
//
// Intrinsics-only projection uncertainty (what Kalibr-style uncertainty
// maps show). For a
// pixel u0 of a camera with parameters p = [fx, fy, cx, cy, d0..d3]
// (lens_models.h order, n = camera.num_params() of them) and their
// covariance C (n x n, CameraCalibration::covariance):
//
//   x0      = pi^-1(p, u0)                 the ray seen at u0, held fixed
//   J       = d pi(p, x0) / d p            2 x n, at the nominal p
//   Sigma_u = J C J^T                      2 x 2 [px^2]
//   sigma   = sqrt(lambda_max(Sigma_u))    [px]
//
// i.e. the standard deviation, along its worst direction, of where the
// calibrated camera would project that ray if the parameters were drawn
// from their error distribution. Only the intrinsics covariance enters (no
// board poses, no extrinsics); the largest eigenvalue, not the trace, is
// reported so that the value is the semi-major axis of the 1-sigma ellipse.
// For a pinhole with independent errors it is
//   sigma^2 = max(x0^2 s_fx^2 + s_cx^2, y0^2 s_fy^2 + s_cy^2).
//
// Image grids. A pixel (u, v), pixel centers at integers, lies in cell
//   col = floor((u + 0.5) / width * cols),  row = floor((v + 0.5) / height *
//   rows)
// of a cols x rows grid over [-0.5, width - 0.5] x [-0.5, height - 0.5];
// pixels outside that rectangle lie in no cell. The uncertainty statistics
// and map sample the image at the centers of a grid of cells of about
// kUncertaintySpacingPx pixels.
//
// Percentiles are linear interpolations between order statistics (numpy's
// default): the q-quantile of sorted x_0..x_{m-1} is at position q (m - 1).
#ifndef RCM_CALIB_CALIBRATION_REPORT_H_
#define RCM_CALIB_CALIBRATION_REPORT_H_

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "rcm/calib/stereo_calibration.h"
#include "rcm/calib/target_observation.h"
#include "rcm/camera/camera.h"
#include "rcm/util/status.h"

namespace rcm::calib {

// Spacing [px] of the samples of the projection uncertainty over an image.
inline constexpr double kUncertaintySpacingPx = 8.0;

// d pi(p, x) / d p at the normalized point x: row 0 is d u, row 1 d v,
// column k the k-th entry of camera.params(); columns from
// camera.num_params() on are zero. Exact (automatic differentiation).
Eigen::Matrix<double, 2, kMaxLensParams> PixelFromParamsJacobian(
    const Camera& camera, const Eigen::Vector2d& normalized);

// Sigma_u = J C J^T above; nullopt where `pixel` cannot be unprojected.
std::optional<Eigen::Matrix2d> ProjectionCovariance(
    const CameraCalibration& calibration, const Eigen::Vector2d& pixel);

// sigma above [px]: sqrt of the largest eigenvalue of Sigma_u (0 for a
// zero covariance; a slightly indefinite Sigma_u from round-off gives 0,
// not NaN). NaN where `pixel` cannot be unprojected.
double ProjectionUncertainty(const CameraCalibration& calibration,
                             const Eigen::Vector2d& pixel);

struct CalibrationReportOptions {
  // Grid over each image for the coverage (cells, see the file comment).
  int coverage_cols = 8;
  int coverage_rows = 6;
  // Fraction of grid cells holding an inlier corner below which we warn.
  double min_coverage = 0.5;
  // Fewer used views -> warning.
  int min_views = 10;
  // Fewer used views where both cameras saw the target -> warning.
  int min_stereo_views = 5;
  // 95th percentile of the intrinsics-only ProjectionUncertainty over the
  // image above this [px] -> warning.
  double max_uncertainty_px = 0.5;
  // Distance [m] of the mean-frames projection uncertainty (> 0;
  // kInfiniteDistance: at infinity).
  double uncertainty_distance_m = std::numeric_limits<double>::infinity();
  // A view whose RMS in a camera exceeds this times that camera's overall
  // RMS is flagged (and warned about).
  double max_view_rms_factor = 3.0;

  // Fails with one line on a grid without cells, a negative count, a
  // coverage outside [0, 1], or a non-positive / non-finite threshold.
  Status Check() const;
};

struct CalibrationReport {
  struct View {
    int view = 0;  // index into the input views
    std::string left_name;
    std::string right_name;
    // Per camera (0 = left, 1 = right): corners of the final solve
    // (inliers and outliers), of which outliers, and their RMS residual
    // sqrt(mean |e|^2) over all of them [px]; NaN when that camera has no
    // corners in the view.
    int corners[2] = {0, 0};
    int outliers[2] = {0, 0};
    double rms_px[2] = {0.0, 0.0};
    // The calibration has a board pose for the view.
    bool used = false;
    // rms_px of a camera above that camera's view_rms_limit_px.
    bool flagged = false;
  };
  struct CameraStats {
    // RMS residual over all corners of the camera, and over its inliers
    // [px] (NaN without corners).
    double rms_px = 0.0;
    double inlier_rms_px = 0.0;
    int corners = 0;  // inliers and outliers
    int outliers = 0;
    // Fraction of the coverage grid's cells with >= 1 inlier corner.
    double coverage = 0.0;
    // The intrinsics-only ProjectionUncertainty over a grid of pixels
    // covering the image [px] (NaN when no pixel of the grid can be
    // unprojected).
    double intrinsics_only_uncertainty_median_px = 0.0;
    double intrinsics_only_uncertainty_p95_px = 0.0;
    double intrinsics_only_uncertainty_max_px = 0.0;
    // MeanFramesProjectionUncertainty at options.uncertainty_distance_m
    // over the same grid [px] (NaN without the full covariance).
    double projection_uncertainty_median_px = 0.0;
    double projection_uncertainty_p95_px = 0.0;
    double projection_uncertainty_max_px = 0.0;
    // max_view_rms_factor * rms_px: views above it are flagged [px].
    double view_rms_limit_px = 0.0;
  };

  std::vector<View> views;  // one per input view
  // 1 for a one-camera calibration (StereoCalibration::num_cameras): then
  // cameras[1] is unset and each view's second entries are 0 corners and a
  // NaN RMS.
  int num_cameras = 2;
  CameraStats cameras[2];
  int num_views_used = 0;
  int num_stereo_views_used = 0;  // used, with corners in both cameras
  // One line each, plain words, e.g. "cam1: corners cover 38 % of the
  // image (8x6 grid); add views near the corners and edges".
  std::vector<std::string> warnings;
};

// The numbers and warnings of a calibration. `views` are the views the
// calibration was made from (calibration.cam0_from_target has one entry
// per view; CHECKed, as are corner view indices in range, positive image
// sizes and options.Check()). One camera: cam1_size is not used, and no
// warning counts stereo views. Deterministic; no I/O.
CalibrationReport SummarizeCalibration(
    const StereoCalibration& calibration, const std::vector<StereoView>& views,
    const ImageSize& cam0_size, const ImageSize& cam1_size,
    const CalibrationReportOptions& options = {});

// ---------------------------------------------------------------------------
// Pictures: 8-bit BGR, a title strip above the image-sized panel (the
// sensor, light background, 1 panel pixel = 1 image pixel; centered in a
// figure at least 660 px wide so that the text fits) and a legend strip
// below; drawn at 3x and averaged down like rcm::LinePlot, text and strokes
// scaled with the image (sqrt of its area over 1000 x 600, at least 1).
// Deterministic. CHECKed: camera 0 or 1, positive sizes and grid counts.

// Every corner of `camera` (0 or 1) as a dot at its measured pixel and its
// residual (projected - measured) as an arrow magnified arrow_scale times,
// outliers in red; the mean inlier residual of each cell of a
// `cols` x `rows` grid as a thick arrow at the cell's center (cells with
// >= 3 inliers), magnified more (a 1-2-5 scale >= arrow_scale at which the
// largest mean draws 40 % of a cell long) since averaging removes most of
// the noise: what remains is the model's systematic error. arrow_scale = 0
// picks a 1-2-5 scale at which the 95th percentile inlier residual draws as
// about 3 % of the image width. The legend states it: "arrows x<scale>: <len>
// px = <value> px".
cv::Mat DrawResidualField(const StereoCalibration& calibration, int camera,
                          const ImageSize& size, double arrow_scale = 0.0,
                          int cols = 8, int rows = 6);

// The cells of a `cols` x `rows` grid shaded by their count of inlier
// corners (count printed in the cell), the convex hull of each used view's
// corners in a palette colour (view index modulo 10) with its corners as
// dots, the target detections of views the calibration did not use as gray
// hulls, and the coverage fraction.
cv::Mat DrawCoverage(const StereoCalibration& calibration,
                     const std::vector<StereoView>& views, int camera,
                     const ImageSize& size, int cols = 8, int rows = 6);

// ProjectionUncertainty over calibration.camera's image as a heat map
// (viridis, sampled every kUncertaintySpacingPx and interpolated
// bilinearly; gray where a pixel cannot be unprojected), with iso-lines
// labelled at the colour bar's ticks. The colour scale is logarithmic (such
// maps span decades: the image center is known far better than the
// corners, where the lens model extrapolates) from `high` = max_px, or for
// max_px = 0 the 1-2-5 number at or above the largest value, down to the
// 1-2-5 number at or below the smallest positive value but at least
// high / 10^4; values outside take the end colours.
// `camera_name` (e.g. "cam0") starts the title.
cv::Mat DrawProjectionUncertainty(const CameraCalibration& calibration,
                                  double max_px = 0.0,
                                  const std::string& camera_name = "");

// The same map of MeanFramesProjectionUncertainty (projection_
// uncertainty.h) of `camera` (0 or 1) at `distance_m` (named in the title;
// gray everywhere without the full covariance).
cv::Mat DrawMeanFramesUncertainty(const StereoCalibration& calibration,
                                  int camera, double distance_m,
                                  double max_px = 0.0,
                                  const std::string& camera_name = "");

// "infinity" or "1.5 m".
std::string DistanceName(double distance_m);

// RMS residual of each view in both cameras against the view index
// (rcm::LinePlot, 1000 x 600): each camera's overall RMS and flag limit as
// horizontal lines, flagged views circled in red.
cv::Mat DrawPerViewRms(const CalibrationReport& report);

// Creates `directory` if needed and writes, each atomically:
//   residuals_cam0.png, residuals_cam1.png    DrawResidualField
//   coverage_cam0.png, coverage_cam1.png      DrawCoverage
//   projection_uncertainty_cam0.png, ..._cam1.png
//                                             DrawMeanFramesUncertainty at
//                                             uncertainty_distance_m (when
//                                             the full covariance is there)
//   intrinsics_only_uncertainty_cam0.png, ..._cam1.png
//                                             DrawProjectionUncertainty
//   per_view_rms.png                          DrawPerViewRms
//   (one camera: the cam0 files only; cam1_size is not used)
//   per_view.csv  view,left,right,corners0,corners1,outliers0,outliers1,
//                 rms0_px,rms1_px,used,flagged
//                 (one row per view; names quoted when they hold a comma or
//                 a quote; rms "nan" without corners; used, flagged 0 or 1)
// Fails with one line on invalid options, a directory that cannot be
// created, or a file that cannot be written (the first such file).
Status WriteCalibrationReport(const std::string& directory,
                              const CalibrationReport& report,
                              const StereoCalibration& calibration,
                              const std::vector<StereoView>& views,
                              const ImageSize& cam0_size,
                              const ImageSize& cam1_size,
                              const CalibrationReportOptions& options = {});

// The per_view.csv text of WriteCalibrationReport.
std::string FormatPerViewCsv(const CalibrationReport& report);

}  // namespace rcm::calib

#endif  // RCM_CALIB_CALIBRATION_REPORT_H_
