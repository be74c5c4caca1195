// The water-side model: the conventional central camera (a lens model of
// lens_models.h: pinhole, radtan, equidistant, rational, ds or eucm; the
// ds and eucm coefficients kept in their ranges by bounds on the solve)
// that best reproduces a
// RefractiveCamera over its image. A VIO framework that loads only such
// models (OpenVINS, VINS-Fusion, ORB-SLAM3, ROVIO) can then use the raw
// underwater images directly, without remapping them (rcm export).
//
// Why a central model can: behind a thin port the refractive camera is
// central (every ray in the medium passes through the camera center,
// docs/design.md, "The refractive model"), so only its radial profile
// changes: the raw pixel at air angle theta_a sees the medium at
// theta_w = asin(sin(theta_a) / n) (Snell, paper eq. 1), and the fitted
// lens has to image theta_w at that pixel. Its polynomial follows the
// profile near the center and departs from it toward the corners, where
// theta_a reaches 80 degrees on the dataset's fisheye: the fit error is
// reported over the whole image and over an inset region.
//
// The fit. Pixels p_i on a grid over the raw image (every
// options.grid_step pixels, centered), their rays in the medium
// d_i = camera.BearingInWaterFromImage(p_i), and the parameters
// theta = [fx, fy, cx, cy, d...] of model M minimize, in pixels,
//
//   sum_i | pi_M(theta; d_i) - p_i |^2          (water_side_projection_error.h)
//
// over the samples at least options.fit_inset of the width (height) from
// the left and right (top and bottom) borders. Levenberg-Marquardt from
// K_n = (n fx, n fy, cx, cy) with zero distortion (the virtual pinhole,
// paper eq. 9; for the EUCM alpha = 0, beta = 1, its pinhole). Deterministic:
// there is no measurement noise, only model error, so no covariance is
// reported; the figures of merit are the fit errors. At n = 1 with M the
// camera's own lens model the fit returns the camera itself.
#ifndef RCM_ESTIMATION_WATER_SIDE_MODEL_FIT_H_
#define RCM_ESTIMATION_WATER_SIDE_MODEL_FIT_H_

#include <cstdint>

#include "rcm/camera/camera.h"
#include "rcm/camera/refractive_camera.h"
#include "rcm/estimation/image_error_field.h"
#include "rcm/estimation/pixel_error_stats.h"
#include "rcm/util/status.h"

namespace rcm {

struct WaterSideModelFitOptions {
  // Lens model of the fitted camera.
  LensModelId model = LensModelId::kEquidistant;
  // Spacing of the sample grid in pixels: 4 px gives 24300 samples on a
  // 720x540 image, enough that the fit does not depend on the grid (a
  // 2 px grid changes the RMS error by less than 1e-3 px). > 0.
  double grid_step = 4.0;
  // Fraction of the width and the height left out of the fit at each
  // side; 0 fits the whole image. 5 %: on the dataset's fisheye at
  // n = 1.333 an equidistant fit to the whole image is pulled by the
  // corners it cannot follow (RMS 0.109 px inside the 5 % inset, 0.179 px
  // over the image); fitted inside the inset it reaches 0.026 px there
  // (0.43 px over the image, 8.7 px at the extreme corners). In [0, 0.45].
  double fit_inset = 0.05;
  // Fraction at each side that the inset figures leave out: 5 % (the
  // corners are where a four-coefficient polynomial cannot follow
  // refraction). In [0, 0.45].
  double report_inset = 0.05;
  // Levenberg-Marquardt iterations. > 0.
  int max_iterations = 200;

  Status Check() const;
};

struct WaterSideModelFit {
  // The fitted camera: model options.model, the refractive camera's image
  // size.
  Camera camera;
  // Fit errors |pi_M(theta; d_i) - p_i| over every sample of the image,
  // and over the samples inside the options.report_inset region.
  PixelErrorStats full;
  PixelErrorStats inset;
  // The inset region [x0, y0, x1, y1] in pixels.
  Eigen::Vector4d inset_region = Eigen::Vector4d::Zero();
  // pi_M(theta; d_i) - p_i on the sample grid (for DrawImageErrorMap);
  // absent where the refractive camera cannot unproject the pixel.
  ImageErrorField errors;
  // Samples at which the fitted lens folds (LensInvertibleAt is false):
  // there the fitted model would send a ray to a wrong pixel. 0 for a
  // usable model.
  int64_t num_not_invertible = 0;
  int num_iterations = 0;
  bool converged = false;
};

// Errors: options.Check(); fewer samples in the fit region than twice the
// model's parameters; a fit that leaves the valid parameter space (e.g.
// non-positive focal length).
StatusOr<WaterSideModelFit> FitWaterSideModel(
    const RefractiveCamera& camera, const WaterSideModelFitOptions& options);

}  // namespace rcm

#endif  // RCM_ESTIMATION_WATER_SIDE_MODEL_FIT_H_
