// StereoRenderer: 8-bit monochrome stereo images of a TankScene as the
// dataset cameras would record them, through each camera's lens and exact
// flat port (rcm/camera/flat_port_camera.h) or, when one is given, dome
// port (rcm/camera/dome_port_camera.h), in air (n = 1, the tank drained)
// or in water (n > 1).
//
// Per pixel, s x s samples on a regular grid (pixel centers at integers,
// sample (i, j) of pixel (x, y) at (x + (i + 0.5) / s - 0.5, y + ...)) are
// traced: the sample's ray in the medium (PortCamera::RayFromImage, exact
// through either port: origin on the port's outer surface, direction;
// camera frame; cached per camera and n since it does not depend on the
// pose) is moved to the world and intersected with the scene
// (scene_intersection.h: the tank, and the calibration board when one is
// given, which occludes the tank where it is in front of it). A sample
// whose ray cannot be traced (outside the lens model) contributes 0; a
// pixel none of whose samples can be traced is black (0, no noise).
//
// Radiance of a hit at distance d from the port, medium attenuation c
// (water_attenuation when n > 1, air_attenuation when n = 1), T = exp(-c d):
//   floor, walls:  L0 = albedo (ambient (0.7 + 0.3 n_z)
//                         + light_intensity beam cos_i exp(-c r) / r^2)
//     n_z the normal's vertical component (daylight from above, and from
//     the bright floor, lights the floor fully and the walls at 70%), r the
//     distance from the vehicle
//     light, beam = cos^k of the angle off the light's axis (cam0's +z),
//     cos_i the cosine of incidence (0 when lit from behind);
//   surface:       L0 = surface_radiance texture (emitted daylight);
//   at the camera: L = L0 T + water_radiance (1 - T)
//   board:         L0 = albedo (ambient (0.7 + 0.3 n_z) + lamp), as a wall,
//                  with the normal of the side hit (the printed side's
//                  black 0.05, white 0.85 by default; the back white)
// (single-scattering veiling light of a homogeneous medium). Each sample's
// texture lookup is filtered over its footprint: the angle between
// neighbouring sample rays times d, elongated on oblique surfaces (see
// TankScene::ShadeAnisotropic); the board's checker pattern is box-filtered
// analytically over the same footprint's extent in board coordinates
// (SceneBoard::Shade), so that its corners are where the geometry puts
// them. The s x s box then averages the samples.
//
// Sensor: DN = 255 exposure mean(L) plus Gaussian noise of variance
//   read_noise^2 + DN 255 / full_well     (read noise and shot noise)
// rounded and clamped to [0, 255]. The noise of pixel p of camera c
// (0 left, 1 right) in frame f is a function of (seed, f, c, p) only
// (SplitMix64 counter hash, Box-Muller): the same inputs give the same
// bytes whatever the threading.
#ifndef RCM_SIM_STEREO_RENDERER_H_
#define RCM_SIM_STEREO_RENDERER_H_

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <memory>
#include <opencv2/core.hpp>
#include <optional>
#include <vector>

#include "rcm/camera/dome_port_geometry.h"
#include "rcm/camera/flat_port.h"
#include "rcm/geometry/rigid3d.h"
#include "rcm/sim/scene_board.h"
#include "rcm/sim/tank_scene.h"
#include "rcm/stereo/stereo_rig.h"
#include "rcm/util/status.h"

namespace rcm {

struct RenderOptions {
  int supersampling = 2;  // samples per pixel along each axis, in [1, 8]
  // Beam attenuation coefficients, 1/m, >= 0: of the water (n > 1; clear
  // pool water is 0.05-0.2) and of the air (n = 1).
  double water_attenuation = 0.12;
  double air_attenuation = 0.0;
  // Radiance of the water far away (its grey "colour", the veiling light),
  // in [0, 1].
  double water_radiance = 0.4;
  // Daylight irradiance on an upward-facing surface, >= 0.
  double ambient = 0.7;
  // The vehicle's lamp: intensity (radiance times m^2; 0 turns it off,
  // >= 0), position in the cam0 frame (meters; between the cameras, above
  // them), beam exponent k of cos^k off cam0's optical axis (>= 0).
  double light_intensity = 1.2;
  Eigen::Vector3d light_position_in_cam0 = Eigen::Vector3d(0.055, -0.08, 0.0);
  double light_beam_exponent = 2.0;
  // Scale of the surface's emitted radiance, >= 0.
  double surface_radiance = 1.0;
  // DN = 255 exposure radiance, > 0.
  double exposure = 1.2;
  // Sensor noise: read noise sigma in DN (>= 0) and the full well in
  // electrons at 255 DN (shot noise; 0 turns it off, else >= 1).
  double read_noise = 1.5;
  double full_well = 8000.0;
  uint64_t seed = 1;    // the noise depends on it, the frame and the pixel
  int num_threads = 2;  // >= 1
  // Ray tables kept, one per medium index (a sequence switching between
  // air and water needs 2), >= 1. Each holds 28 bytes per sample and
  // camera: 87 MB at 720x540 with supersampling 2.
  int max_cached_indices = 2;

  Status Check() const;
};

struct StereoImages {
  cv::Mat left;   // CV_8UC1, the left camera's resolution
  cv::Mat right;  // CV_8UC1, the right camera's resolution
};

class StereoRenderer {
 public:
  // Fails when the options or a port are invalid or the scene is null.
  // The scene must outlive the renderer. A camera with a dome looks
  // through it instead of its flat port.
  static StatusOr<StereoRenderer> Create(
      const StereoRig& rig, const FlatPort& left_port,
      const FlatPort& right_port, const TankScene* scene,
      const RenderOptions& options,
      const std::optional<DomePort>& left_dome = std::nullopt,
      const std::optional<DomePort>& right_dome = std::nullopt);

  const StereoRig& rig() const { return rig_; }
  const RenderOptions& options() const { return options_; }

  // Traces and caches the sample rays of both cameras for medium index n
  // (Render does it on first use of an n). Fails when n is not in [1, 2].
  Status PrepareRays(double n);
  // Number of medium indices whose rays are cached.
  int NumCachedIndices() const { return static_cast<int>(cache_.size()); }

  // The stereo pair seen with cam0 at `world_from_cam0` in a medium of
  // index n (1 = air); `frame_index` selects the noise. With a `board`
  // (may be null), the board is in the tank at its pose and occludes it.
  // `right_from_left`, when given, is cam1's view for this frame in place
  // of the rig's (cameras not triggered together: the right image exposed
  // where the rig had moved to, ExposureDelay::RightFromLeftOfFrame); the
  // lamp is where it was at the left exposure. Fails when n is not in
  // [1, 2] or a camera is outside the tank.
  StatusOr<StereoImages> Render(
      const Rigid3d& world_from_cam0, double n, int64_t frame_index,
      const PlacedBoard* board = nullptr,
      const std::optional<Rigid3d>& right_from_left = std::nullopt);

 private:
  struct RayTable;  // per camera and n, defined in the .cc
  struct CacheEntry {
    double n = 1.0;
    std::array<std::shared_ptr<const RayTable>, 2> tables;  // left, right
  };

  StereoRenderer(const StereoRig& rig, const FlatPort& left_port,
                 const FlatPort& right_port, const TankScene* scene,
                 const RenderOptions& options,
                 const std::optional<DomePort>& left_dome,
                 const std::optional<DomePort>& right_dome)
      : rig_(rig),
        ports_{left_port, right_port},
        domes_{left_dome, right_dome},
        scene_(scene),
        options_(options) {}

  // The cached entry of n, tracing it (and evicting the oldest) if needed.
  StatusOr<const CacheEntry*> Rays(double n);

  StereoRig rig_;
  std::array<FlatPort, 2> ports_;
  std::array<std::optional<DomePort>, 2> domes_;  // nullopt: the flat port
  const TankScene* scene_;
  RenderOptions options_;
  std::vector<CacheEntry> cache_;  // oldest first
};

}  // namespace rcm

#endif  // RCM_SIM_STEREO_RENDERER_H_
