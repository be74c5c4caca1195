#include "rcm/sim/tank_scene.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

namespace rcm::tank_scene_test {
namespace {

// Hits are computed in closed form from one division per axis: a few ulps
// of the 12 m tank's coordinates.
constexpr double kHitTolerance = 1e-12;
// A small textured tank, quick to build (~30 ms) yet with every texture
// feature.
TankSceneOptions SmallTank(uint64_t seed = 7) {
  TankSceneOptions options;
  options.length = 4.0;
  options.width = 3.0;
  options.depth = 1.5;
  options.seed = seed;
  return options;
}

TankScene FlatTank() {
  TankSceneOptions options;
  options.constant_albedo = 0.5;
  return TankScene::Create(options).value();
}

// Standard deviation of a sample.
double StdDev(const std::vector<double>& values) {
  double mean = 0.0;
  for (double v : values) mean += v / values.size();
  double variance = 0.0;
  for (double v : values) variance += (v - mean) * (v - mean) / values.size();
  return std::sqrt(variance);
}

TEST(TankScene, DefaultOptionsAreValid) {
  EXPECT_TRUE(TankSceneOptions().Check().ok());
  EXPECT_TRUE(SmallTank().Check().ok());
}

TEST(TankScene, CheckRejectsBadOptions) {
  const auto message = [](const TankSceneOptions& options) {
    return options.Check().message();
  };
  TankSceneOptions options;
  options.length = 1.0;
  EXPECT_NE(message(options).find("length"), std::string::npos);
  options = TankSceneOptions();
  options.width = NAN;
  EXPECT_NE(message(options).find("width"), std::string::npos);
  options = TankSceneOptions();
  options.depth = 0.5;
  EXPECT_NE(message(options).find("depth"), std::string::npos);
  options = TankSceneOptions();
  options.texel_size = 0.001;
  EXPECT_NE(message(options).find("texel_size"), std::string::npos);
  options = TankSceneOptions();
  options.constant_albedo = 1.5;
  EXPECT_NE(message(options).find("constant_albedo"), std::string::npos);
  EXPECT_FALSE(TankScene::Create(options).ok());
}

TEST(TankScene, RayFromCenterHitsFloor) {
  const TankScene scene = FlatTank();
  const std::optional<SurfaceHit> hit = scene.Intersect(
      Eigen::Vector3d(6.0, 4.0, 1.5), Eigen::Vector3d(0.0, 0.0, -1.0));
  ASSERT_TRUE(hit.has_value());
  EXPECT_EQ(hit->surface, TankSurface::kFloor);
  EXPECT_DOUBLE_EQ(hit->distance, 1.5);
  EXPECT_EQ(hit->point, Eigen::Vector3d(6.0, 4.0, 0.0));
  EXPECT_EQ(hit->normal, Eigen::Vector3d(0.0, 0.0, 1.0));
  EXPECT_EQ(hit->texture, Eigen::Vector2d(6.0, 4.0));
}

TEST(TankScene, RaysHitEachSurfaceWhereAnalysisSays) {
  // From o = (3, 2, 1) in the 12 x 8 x 3 tank, oblique rays towards each
  // face; the face is reached at t = (plane - o_k) / v_k.
  const TankScene scene = FlatTank();
  const double l = 12.0, w = 8.0;
  const Eigen::Vector3d o(3.0, 2.0, 1.0);
  struct Case {
    Eigen::Vector3d direction;
    TankSurface surface;
    Eigen::Vector3d normal;
    Eigen::Vector3d point;  // expected hit
    Eigen::Vector2d texture;
  };
  const auto on_ray = [&](const Eigen::Vector3d& v, int axis, double plane) {
    return Eigen::Vector3d(o + (plane - o[axis]) / v[axis] * v);
  };
  std::vector<Case> cases;
  {  // wall x = 0: u = y
    const Eigen::Vector3d v = Eigen::Vector3d(-1.0, 0.2, 0.1).normalized();
    const Eigen::Vector3d p = on_ray(v, 0, 0.0);
    cases.push_back({v, TankSurface::kWall, Eigen::Vector3d::UnitX(), p,
                     Eigen::Vector2d(p.y(), p.z())});
  }
  {  // wall y = width: u = width + x
    const Eigen::Vector3d v = Eigen::Vector3d(0.3, 1.0, 0.05).normalized();
    const Eigen::Vector3d p = on_ray(v, 1, w);
    cases.push_back({v, TankSurface::kWall, -Eigen::Vector3d::UnitY(), p,
                     Eigen::Vector2d(w + p.x(), p.z())});
  }
  {  // wall x = length: u = width + length + (width - y)
    const Eigen::Vector3d v = Eigen::Vector3d(1.0, 0.1, -0.05).normalized();
    const Eigen::Vector3d p = on_ray(v, 0, l);
    cases.push_back({v, TankSurface::kWall, -Eigen::Vector3d::UnitX(), p,
                     Eigen::Vector2d(w + l + (w - p.y()), p.z())});
  }
  {  // wall y = 0: u = 2 width + length + (length - x)
    const Eigen::Vector3d v = Eigen::Vector3d(0.4, -1.0, 0.2).normalized();
    const Eigen::Vector3d p = on_ray(v, 1, 0.0);
    cases.push_back({v, TankSurface::kWall, Eigen::Vector3d::UnitY(), p,
                     Eigen::Vector2d(2.0 * w + l + (l - p.x()), p.z())});
  }
  {  // surface z = depth
    const Eigen::Vector3d v = Eigen::Vector3d(0.3, 0.2, 1.0).normalized();
    const Eigen::Vector3d p = on_ray(v, 2, 3.0);
    cases.push_back({v, TankSurface::kSurface, -Eigen::Vector3d::UnitZ(), p,
                     Eigen::Vector2d(p.x(), p.y())});
  }
  {  // floor, oblique
    const Eigen::Vector3d v = Eigen::Vector3d(0.5, 0.5, -1.0).normalized();
    const Eigen::Vector3d p = on_ray(v, 2, 0.0);
    cases.push_back({v, TankSurface::kFloor, Eigen::Vector3d::UnitZ(), p,
                     Eigen::Vector2d(p.x(), p.y())});
  }
  for (const Case& c : cases) {
    SCOPED_TRACE(c.direction.transpose());
    const std::optional<SurfaceHit> hit = scene.Intersect(o, c.direction);
    ASSERT_TRUE(hit.has_value());
    EXPECT_EQ(hit->surface, c.surface);
    EXPECT_EQ(hit->normal, c.normal);
    EXPECT_LT((hit->point - c.point).norm(), kHitTolerance);
    EXPECT_NEAR(hit->distance, (c.point - o).norm(), kHitTolerance);
    EXPECT_LT((hit->texture - c.texture).norm(), kHitTolerance);
  }
}

TEST(TankScene, RandomRaysFromInsideEndOnTheBoundary) {
  const TankScene scene = FlatTank();
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::normal_distribution<double> gaussian;
  for (int i = 0; i < 2000; ++i) {
    // z, y, x, in statements of their own (argument order is unspecified).
    const double origin_z = 3.0 * unit(rng);
    const double origin_y = 8.0 * unit(rng);
    const Eigen::Vector3d origin(12.0 * unit(rng), origin_y, origin_z);
    const double direction_z = gaussian(rng);
    const double direction_y = gaussian(rng);
    const Eigen::Vector3d direction =
        Eigen::Vector3d(gaussian(rng), direction_y, direction_z).normalized();
    const std::optional<SurfaceHit> hit = scene.Intersect(origin, direction);
    ASSERT_TRUE(hit.has_value());
    EXPECT_TRUE(scene.Contains(hit->point));
    // On the face its normal names, facing the ray.
    int axis = 0;
    for (int k = 0; k < 3; ++k) {
      if (hit->normal[k] != 0.0) axis = k;
    }
    EXPECT_EQ(std::abs(hit->normal[axis]), 1.0);
    const double plane =
        hit->normal[axis] > 0.0 ? 0.0 : Eigen::Vector3d(12.0, 8.0, 3.0)[axis];
    EXPECT_EQ(hit->point[axis], plane);
    EXPECT_LT(hit->normal.dot(direction), 0.0);
    EXPECT_NEAR(hit->distance, (hit->point - origin).norm(), 1e-9);
    EXPECT_LT((origin + hit->distance * direction - hit->point).norm(), 1e-9);
  }
}

TEST(TankScene, WallCoordinateRunsContinuouslyAroundCorners) {
  // At each corner but the start (0, 0), the two walls meeting there give
  // the same u; the start is where u wraps around the perimeter.
  const TankScene scene = FlatTank();
  const Eigen::Vector3d center(6.0, 4.0, 1.0);
  const double eps = 1e-6;
  const double corners[3][2] = {{0.0, 8.0}, {12.0, 8.0}, {12.0, 0.0}};
  for (const auto& corner : corners) {
    for (double dx : {-eps, eps}) {
      for (double dy : {-eps, eps}) {
        const Eigen::Vector3d target(corner[0] + dx, corner[1] + dy, 1.0);
        if (!scene.Contains(target)) continue;
        const std::optional<SurfaceHit> hit =
            scene.Intersect(center, (target - center).normalized());
        ASSERT_TRUE(hit.has_value());
        const double expected =
            corner[0] == 0.0 ? 8.0 : (corner[1] == 8.0 ? 20.0 : 28.0);
        EXPECT_NEAR(hit->texture.x(), expected, 1e-5);
      }
    }
  }
}

TEST(TankScene, OriginOutsideOrBadDirectionMisses) {
  const TankScene scene = FlatTank();
  const Eigen::Vector3d down(0.0, 0.0, -1.0);
  EXPECT_FALSE(scene.Intersect(Eigen::Vector3d(-0.1, 4.0, 1.0), down));
  EXPECT_FALSE(scene.Intersect(Eigen::Vector3d(6.0, 4.0, 3.1), down));
  EXPECT_FALSE(
      scene.Intersect(Eigen::Vector3d(6.0, 4.0, 1.0), Eigen::Vector3d::Zero()));
  EXPECT_FALSE(scene.Intersect(Eigen::Vector3d(6.0, 4.0, 1.0),
                               Eigen::Vector3d(NAN, 0.0, -1.0)));
  // On the boundary counts as inside.
  EXPECT_TRUE(scene.Intersect(Eigen::Vector3d(0.0, 4.0, 1.0), down));
}

TEST(TankScene, ConstantAlbedoSceneIsFlat) {
  const TankScene scene = FlatTank();
  EXPECT_EQ(scene.NumTextureLevels(TankSurface::kFloor), 0);
  const SurfaceHit hit = *scene.Intersect(Eigen::Vector3d(6.0, 4.0, 1.0),
                                          Eigen::Vector3d(0.0, 0.6, 0.8));
  EXPECT_EQ(scene.Shade(hit, 0.0), 0.5f);
  EXPECT_EQ(scene.ShadeAnisotropic(hit, Eigen::Vector3d(0.0, 0.6, 0.8), 0.1),
            0.5f);
}

// Floor hits straight down from height 1 at random points.
std::vector<SurfaceHit> FloorHits(const TankScene& scene, int count,
                                  uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> x(0.0, scene.length());
  std::uniform_real_distribution<double> y(0.0, scene.width());
  std::vector<SurfaceHit> hits;
  for (int i = 0; i < count; ++i) {
    const double drawn_y = y(rng);  // before x, as above
    hits.push_back(*scene.Intersect(Eigen::Vector3d(x(rng), drawn_y, 1.0),
                                    Eigen::Vector3d(0.0, 0.0, -1.0)));
  }
  return hits;
}

TEST(TankScene, TexturesDependOnlyOnTheSeed) {
  const TankScene a = TankScene::Create(SmallTank(7)).value();
  const TankScene b = TankScene::Create(SmallTank(7)).value();
  const TankScene c = TankScene::Create(SmallTank(8)).value();
  EXPECT_EQ(a.TexelSize(TankSurface::kFloor), 0.004);
  EXPECT_EQ(a.TexelSize(TankSurface::kSurface), 0.008);
  EXPECT_EQ(a.NumTextureLevels(TankSurface::kWall), 8);
  int differing = 0;
  const std::vector<SurfaceHit> hits = FloorHits(a, 300, 1);
  for (const SurfaceHit& hit : hits) {
    EXPECT_EQ(a.Shade(hit, 0.0), b.Shade(hit, 0.0));
    differing += a.Shade(hit, 0.0) != c.Shade(hit, 0.0);
  }
  // Two independent textures agree at a point by chance only.
  EXPECT_GT(differing, 250);
}

TEST(TankScene, ShadeIsInUnitRangeAndBlursWithTheFootprint) {
  const TankScene scene = TankScene::Create(SmallTank()).value();
  std::vector<double> sharp, blurred, flat;
  for (const SurfaceHit& hit : FloorHits(scene, 500, 2)) {
    const float value = scene.Shade(hit, 0.0);
    EXPECT_GE(value, 0.0f);
    EXPECT_LE(value, 1.0f);
    sharp.push_back(value);
    blurred.push_back(scene.Shade(hit, 0.1));
    flat.push_back(scene.Shade(hit, 1.0));
  }
  // The texture has contrast at every scale (sharp > blurred) and each mip
  // level averages it down (blurred > flat).
  EXPECT_GT(StdDev(sharp), 0.08);
  EXPECT_GT(StdDev(sharp), 1.3 * StdDev(blurred));
  EXPECT_GT(StdDev(blurred), 1.3 * StdDev(flat));
}

TEST(TankScene, AnisotropicShadeHeadOnIsTheIsotropicOne) {
  const TankScene scene = TankScene::Create(SmallTank()).value();
  const Eigen::Vector3d down(0.0, 0.0, -1.0);
  for (const SurfaceHit& hit : FloorHits(scene, 50, 3)) {
    for (double footprint : {0.0, 0.003, 0.02, 0.3}) {
      EXPECT_EQ(scene.ShadeAnisotropic(hit, down, footprint),
                scene.Shade(hit, footprint));
    }
  }
  // Grazing: the footprint stretches along the ray, so the lookup blurs
  // more than head-on but stays in range.
  const Eigen::Vector3d grazing = Eigen::Vector3d(1.0, 0.0, -0.1).normalized();
  std::vector<double> head_on, oblique;
  for (const SurfaceHit& hit : FloorHits(scene, 300, 4)) {
    head_on.push_back(scene.ShadeAnisotropic(hit, down, 0.01));
    oblique.push_back(scene.ShadeAnisotropic(hit, grazing, 0.01));
    EXPECT_GE(oblique.back(), 0.0);
    EXPECT_LE(oblique.back(), 1.0);
  }
  EXPECT_LT(StdDev(oblique), StdDev(head_on));
}

}  // namespace
}  // namespace rcm::tank_scene_test
