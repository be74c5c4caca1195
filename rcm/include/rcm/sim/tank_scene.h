// TankScene: the simulator's world, a rectangular pool seen from inside.
//
// World frame: x along the tank's length, y across, z up. The tank is the
// box [0, length] x [0, width] x [0, depth]: the floor is z = 0, the four
// walls are x = 0, x = length, y = 0, y = width, and the water surface
// (the box's ceiling; in a drained tank, the ceiling of the hall) is
// z = depth.
//
// Ray casting from a point o inside the box along a unit direction v: for
// each axis k with v_k != 0 the ray leaves the slab [lo_k, hi_k] at
//   t_k = (hi_k - o_k) / v_k   (v_k > 0)   or   (lo_k - o_k) / v_k  (v_k < 0)
// and the first surface hit is the one of the smallest t_k (a convex box
// seen from inside: nothing occludes it).
//
// Texture coordinates, in meters, so that one texel has the same size
// everywhere:
//   floor, surface   (x, y)
//   walls            (u, z), u the arc length along the perimeter, counter-
//                    clockwise seen from above, starting at the corner
//                    (0, 0) along the wall x = 0:
//                      x = 0       u = y
//                      y = width   u = width + x
//                      x = length  u = width + length + (width - y)
//                      y = 0       u = 2 width + length + (length - x)
//                    Seen from inside, u increases to the right and z up
//                    (writing on the walls reads correctly).
//
// Textures are grey levels (the dataset cameras are monochrome), generated
// deterministically from the seed when the scene is built. The floor is a
// mosaic of 5 cm tiles laid in a random blend that drifts in patches,
// with dark lane lines, painted labels, rings, crosses and fiducial-like
// tags, sand drifts, algae stains, grime, a baked-in caustic network and
// debris (pebbles, leaves, shards, 5 mm to 12 cm). The walls are a lighter
// mosaic with a dark band below the waterline, lane targets on the end
// walls, depth markings, signs, algae streaks heavier towards the floor and
// biofouling spots. The surface seen from below is bright with a
// caustic-like network. Random content dominates the periodic tiling at
// every scale a feature detector looks at, so that stereo matching is
// unambiguous.
//
// Filtering: each texture is a mip pyramid (level l has texels 2^l times
// larger, each the box average of four texels of level l - 1). A lookup
// with a footprint f (meters covered by one sample) reads the two levels
// bracketing lambda = log2(f / texel) bilinearly and blends them
// (trilinear). The anisotropic lookup models the elliptical footprint of an
// oblique ray: minor axis f, major axis f / |cos theta| along the ray's
// projection onto the surface (theta the angle between ray and normal); it
// averages taps = round(1 / |cos theta|), clamped to [1,
// kMaxAnisotropicTaps], trilinear lookups spread evenly along the major
// axis, each at the level of max(f, major / taps).
#ifndef RCM_SIM_TANK_SCENE_H_
#define RCM_SIM_TANK_SCENE_H_

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include "rcm/util/status.h"

namespace rcm {

struct TankSceneOptions {
  double length = 12.0;  // meters, along world x, in [2, 100]
  double width = 8.0;    // meters, along world y, in [2, 100]
  double depth = 3.0;    // meters, floor to water surface, in [1, 20]
  // Texel size of the floor and wall textures, meters, in [0.002, 0.05].
  // The surface, always seen from afar, uses twice this. 4 mm is about the
  // footprint of a 720x540 dataset pixel on the floor 1.5 m away in water.
  double texel_size = 0.004;
  // Below 0: procedural textures (the default). In [0, 1]: every surface
  // is this flat grey level and no texture is generated (for tests of the
  // renderer's radiometry).
  double constant_albedo = -1.0;
  uint64_t seed = 1;  // the textures depend only on the seed and the sizes

  Status Check() const;
};

enum class TankSurface { kFloor, kWall, kSurface };

// A ray's first hit on the tank, in the world frame.
struct SurfaceHit {
  double distance = 0.0;  // meters along the ray from its origin, >= 0
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  // Unit normal pointing into the tank (towards the ray's origin).
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  TankSurface surface = TankSurface::kFloor;
  // Meters, see the file comment: (x, y) on the floor and the surface,
  // (u, z) on the walls.
  Eigen::Vector2d texture = Eigen::Vector2d::Zero();
};

class TankScene {
 public:
  // Most trilinear taps of an anisotropic lookup (ratio of the footprint's
  // axes beyond which the lookup blurs along the minor axis instead).
  static constexpr int kMaxAnisotropicTaps = 4;

  // Validates the options and generates the textures (about 0.3 s at the
  // default size on one core).
  static StatusOr<TankScene> Create(const TankSceneOptions& options);

  const TankSceneOptions& options() const { return options_; }
  double length() const { return options_.length; }
  double width() const { return options_.width; }
  double depth() const { return options_.depth; }

  // True when the point is inside the box, at least `margin` meters from
  // every face.
  bool Contains(const Eigen::Vector3d& point_in_world,
                double margin = 0.0) const;

  // The first surface hit by the ray from `origin_in_world` (inside the
  // box, up to 1e-9 m outside) along `unit_direction_in_world`; nullopt
  // when the origin is outside the box or the direction is not finite and
  // nonzero.
  std::optional<SurfaceHit> Intersect(
      const Eigen::Vector3d& origin_in_world,
      const Eigen::Vector3d& unit_direction_in_world) const;

  // The surfaces that emit light rather than reflect it: the water surface
  // (daylight from above).
  static bool IsEmissive(TankSurface surface) {
    return surface == TankSurface::kSurface;
  }

  // Grey level in [0, 1] at a hit: the albedo of the floor and the walls,
  // the relative radiance of the surface (IsEmissive). `footprint` is the
  // width in meters of the patch one sample stands for (isotropic
  // trilinear lookup); 0 reads the finest level.
  float Shade(const SurfaceHit& hit, double footprint) const;
  // The same with the anisotropic footprint of a ray along
  // `unit_direction_in_world` (see the file comment); `footprint` is the
  // width of the sample across the ray, distance times angular width.
  float ShadeAnisotropic(const SurfaceHit& hit,
                         const Eigen::Vector3d& unit_direction_in_world,
                         double footprint) const;

  // Texel size in meters of level 0 of a surface's texture, and the
  // texture's number of mip levels (0 with a constant albedo).
  double TexelSize(TankSurface surface) const;
  int NumTextureLevels(TankSurface surface) const;

 private:
  // One mip pyramid of 8-bit grey texels, row-major, level 0 first; texel
  // (i, j) of level l covers [i, i + 1) x [j, j + 1) times texel_size 2^l.
  struct MipLevel {
    int width = 0;
    int height = 0;
    float texels_per_meter = 0.0f;  // 1 / (texel_size 2^l)
    std::vector<uint8_t> texels;
  };
  struct MipTexture {
    double texel_size = 0.0;
    std::vector<MipLevel> levels;
  };

  explicit TankScene(const TankSceneOptions& options) : options_(options) {}
  const MipTexture& Texture(TankSurface surface) const {
    return textures_[static_cast<int>(surface)];
  }
  // The mip level of detail of a footprint width (meters): lambda =
  // log2(footprint / texel_size) clamped to [0, last level].
  static float LevelOfDetail(const MipTexture& texture, double footprint);
  // Trilinear lookup at texture coordinates (meters) and level of detail
  // lambda; in [0, 1].
  static float SampleTrilinear(const MipTexture& texture, float u, float v,
                               float lambda);

  TankSceneOptions options_;
  std::array<MipTexture, 3> textures_;  // indexed by TankSurface
};

}  // namespace rcm

#endif  // RCM_SIM_TANK_SCENE_H_
