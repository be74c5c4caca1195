// Is a dome port worth modelling? The pixel error a user makes by ignoring
// a dome (rcm dome-check): for an in-air calibrated camera A behind a dome
// (dome_port_camera.h) in a medium of index n, how far from the true image
// of a point the camera's air model puts it, over the image and over a
// range of depths.
//
// "Ignoring the dome" is turning refraction off: using the air calibration
// A under water as it is. A centred dome does not refract (every ray meets
// the glass along its normal), so the air camera is what a user assumes who
// believes the dome centred, and the error below is zero for C = 0 exactly.
// A decentered dome bends every ray that is not along the line through the
// camera centre and the dome's centre; its error does not vanish at large
// depths: the dome is a weak lens (paraxially, an axial decentering c
// scales the image by about 1 + (n - 1) c / (n r1) for distant points, 4 %
// for c = 7 mm, r1 = 44 mm in water).
//
// The error. A pixel p of the grid over A's image sees, through the dome,
// the ray o(p) + s d(p) in the medium (DomePortCamera::RayFromImage). Its
// point at depth Z (camera frame z, meters) is
//
//   X(p, Z) = o + s d,   s = (Z - o_z) / d_z,
//
// which the real camera images at p exactly. The air model images X at
//
//   q(p, Z) = A(X_x / Z, X_y / Z)   (Camera::ProjectNormalized),
//
// and the error of ignoring the dome is e(p, Z) = q - p, pixels: the same
// as imaging a point through both models and subtracting, without solving
// the dome's forward projection (the grid is over the true image).
//
// The best central camera at a reference depth Zr (optional). A user who
// knows the dome is there, but wants a central camera (a conventional
// underwater calibration at one distance, a corrected pinhole image), gets
// at best the camera exact at one depth: the air-normalized point u sees
// the bearing of the point at depth Zr on its dome ray,
//
//   h(u) = (X_x(u, Zr) / Zr, X_y(u, Zr) / Zr),
//
// (an undistorted normalized point under water), and images X at the u'
// with h(u') = (X_x / Z, X_y / Z), found by Newton's method from
// u' = u(p) with h's Jacobian from ceres::Jet (2-3 steps: h is within a
// few percent of the identity). Its error e_c(p, Z) = A(u') - p is zero at
// Z = Zr and is the dome's non-central part: the parallax of the rays'
// offsets from the camera centre, roughly f |C_perp| |1/Z - 1/Zr|.
//
// Statistics: per depth, the max and RMS of |e| over the grid's pixels
// whose ray reaches the depth (d_z > 0) and whose image the air model can
// represent; pixels where either fails are counted, not averaged. Depths
// are spaced geometrically over [min, max] (the error is a function of
// 1/Z, which this spacing samples evenly in ratio).
#ifndef RCM_ESTIMATION_DOME_PORT_ERROR_H_
#define RCM_ESTIMATION_DOME_PORT_ERROR_H_

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <vector>

#include "rcm/camera/dome_port_camera.h"
#include "rcm/estimation/image_error_field.h"
#include "rcm/estimation/pixel_error_stats.h"
#include "rcm/util/status.h"

namespace rcm {

struct DomePortErrorOptions {
  // The largest depth, meters (RefractiveCamera::kMaxReferenceDepth).
  static constexpr double kMaxDepth = 1e4;
  static constexpr int kMaxNumDepths = 1000;
  // How far beyond the dome's outer surface every depth must lie, meters
  // (RefractiveCamera::kMinReferenceDepthBeyondGlass).
  static constexpr double kMinDepthBeyondDome = 1e-3;

  // The depth range [min_depth, max_depth], meters, 0 < min <= max <=
  // kMaxDepth; min_depth must lie beyond the dome (checked with the dome,
  // by EvaluateDomePortError).
  double min_depth = 0.3;
  double max_depth = 10.0;
  // Depths sampled, geometrically spaced, ends included: in [2,
  // kMaxNumDepths] (one depth when min_depth == max_depth).
  int num_depths = 12;
  // Spacing of the pixel grid over the image (CenteredSampleGrid), > 0.
  double grid_step = 8.0;
  // Zr of the header: also evaluate the error at this depth and the best
  // central camera's error at every depth. In (0, kMaxDepth], beyond the
  // dome.
  std::optional<double> reference_depth;

  Status Check() const;
};

struct DomePortErrorAtDepth {
  double depth = 0.0;
  // |e| of ignoring the dome over the grid.
  PixelErrorStats ignored;
  // |e_c| of the central camera exact at the reference depth; set with
  // DomePortErrorOptions::reference_depth.
  std::optional<PixelErrorStats> central;
  // Grid pixels without an error at this depth (see the header).
  int64_t num_unusable = 0;
};

struct DomePortError {
  // One per sampled depth, ascending.
  std::vector<DomePortErrorAtDepth> depths;
  // The index in `depths` of the largest ignored max error (the first of
  // equal ones).
  int worst_index = 0;
  // The largest ignored error over every depth and pixel, and the RMS
  // over all of them.
  double max_px = 0.0;
  double rms_px = 0.0;
  // e(p, Z) over the grid at the worst depth, for rcm/viz/image_error_map.h.
  ImageErrorField worst_field;
  // The errors at the reference depth (central there is zero); set with
  // DomePortErrorOptions::reference_depth.
  std::optional<DomePortErrorAtDepth> at_reference;
  // The largest central-camera error over every sampled depth; set with
  // the reference depth.
  std::optional<double> central_max_px;
};

// The depths sampled for `options` (valid): geometric from min to max.
std::vector<double> DomePortErrorDepths(const DomePortErrorOptions& options);

// The largest z any point of the dome's outer glass surface reaches,
// C_z + r2, meters. Every depth must exceed it by kMinDepthBeyondDome.
double DomeOuterSurfaceMaxDepth(const DomePort& dome);

// e(p, Z) of the header for one raw pixel; nullopt when the pixel's ray
// does not reach depth Z ahead of its origin or a model cannot image it.
std::optional<Eigen::Vector2d> IgnoredDomeError(const DomePortCamera& camera,
                                                const Eigen::Vector2d& pixel,
                                                double depth);

// e_c(p, Z) of the header for one raw pixel and reference depth Zr;
// nullopt as above or when Newton's method does not converge.
std::optional<Eigen::Vector2d> CentralDomeError(const DomePortCamera& camera,
                                                const Eigen::Vector2d& pixel,
                                                double depth,
                                                double reference_depth);

// The statistics of the header over a grid on the camera's image. Errors:
// options.Check(), a depth not beyond the dome ("depth 0.04 m is not
// beyond the dome: its outer surface reaches z = 0.0547 m"), no grid pixel
// with an error at some depth.
StatusOr<DomePortError> EvaluateDomePortError(
    const DomePortCamera& camera, const DomePortErrorOptions& options);

}  // namespace rcm

#endif  // RCM_ESTIMATION_DOME_PORT_ERROR_H_
