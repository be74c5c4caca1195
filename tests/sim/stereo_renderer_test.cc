#include "rcm/sim/stereo_renderer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgproc.hpp>
#include <random>

#include "rcm/camera/flat_port_camera.h"
#include "rcm/sim/reference_rigs.h"
#include "rcm/sim/scene_board.h"
#include "rcm/sim/trajectory.h"
#include "sim/test_pool.h"

namespace rcm::stereo_renderer_test {
namespace {

// Rendered DN are rounded: within 0.5 of the exact value, plus float
// storage of the cached rays (1e-7 relative in distance, 1e-5 DN).
constexpr double kRoundingTolerance = 0.5 + 1e-3;

using test::Pool;
using test::RobotPose;

// A pool whose every surface is the same grey.
const TankScene& FlatPool() {
  static const TankScene* const scene = [] {
    TankSceneOptions options;
    options.constant_albedo = 0.6;
    return new TankScene(TankScene::Create(options).value());
  }();
  return *scene;
}

// Camera frame x right, y down, z forward; world z up.
Rigid3d LookingDown(const Eigen::Vector3d& position) {
  Rigid3d pose;
  pose.rotation.col(0) = Eigen::Vector3d(1.0, 0.0, 0.0);
  pose.rotation.col(1) = Eigen::Vector3d(0.0, -1.0, 0.0);
  pose.rotation.col(2) = Eigen::Vector3d(0.0, 0.0, -1.0);
  pose.translation = position;
  return pose;
}

RenderOptions Quick() {
  RenderOptions options;
  options.supersampling = 1;
  return options;
}

StereoRenderer MakeRenderer(
    const TankScene& scene, const RenderOptions& options,
    const StereoRig& rig = AlphasenseFrontRectifiedRig(),
    const FlatPort& port = FlatPort()) {
  return StereoRenderer::Create(rig, port, port, &scene, options).value();
}

int DifferingPixels(const cv::Mat& a, const cv::Mat& b) {
  return cv::countNonZero(a != b);
}

// Normalized cross-correlation of two equally sized float patches.
double Ncc(const cv::Mat& a, const cv::Mat& b) {
  cv::Scalar mean_a, std_a, mean_b, std_b;
  cv::meanStdDev(a, mean_a, std_a);
  cv::meanStdDev(b, mean_b, std_b);
  if (std_a[0] == 0.0 || std_b[0] == 0.0) return 0.0;
  const cv::Mat da = a - mean_a[0], db = b - mean_b[0];
  return da.dot(db) / (a.total() * std_a[0] * std_b[0]);
}

TEST(StereoRenderer, DefaultOptionsAreValid) {
  EXPECT_TRUE(RenderOptions().Check().ok());
}

TEST(StereoRenderer, CheckRejectsBadOptions) {
  const auto message = [](const RenderOptions& options) {
    return options.Check().message();
  };
  RenderOptions options;
  options.supersampling = 0;
  EXPECT_NE(message(options).find("supersampling"), std::string::npos);
  options = RenderOptions();
  options.water_attenuation = -0.1;
  EXPECT_NE(message(options).find("attenuation"), std::string::npos);
  options = RenderOptions();
  options.water_radiance = 1.5;
  EXPECT_NE(message(options).find("water_radiance"), std::string::npos);
  options = RenderOptions();
  options.light_intensity = NAN;
  EXPECT_NE(message(options).find("light_intensity"), std::string::npos);
  options = RenderOptions();
  options.exposure = 0.0;
  EXPECT_NE(message(options).find("exposure"), std::string::npos);
  options = RenderOptions();
  options.read_noise = -1.0;
  EXPECT_NE(message(options).find("read_noise"), std::string::npos);
  options = RenderOptions();
  options.full_well = 0.5;
  EXPECT_NE(message(options).find("full_well"), std::string::npos);
  options = RenderOptions();
  options.num_threads = 0;
  EXPECT_NE(message(options).find("num_threads"), std::string::npos);
  options = RenderOptions();
  options.max_cached_indices = 0;
  EXPECT_NE(message(options).find("max_cached_indices"), std::string::npos);
  EXPECT_FALSE(StereoRenderer::Create(AlphasenseFrontRectifiedRig(), FlatPort(),
                                      FlatPort(), &FlatPool(), options)
                   .ok());
}

TEST(StereoRenderer, CreateRejectsANullSceneAndBadPorts) {
  const StereoRig rig = AlphasenseFrontRectifiedRig();
  EXPECT_FALSE(StereoRenderer::Create(rig, FlatPort(), FlatPort(), nullptr,
                                      RenderOptions())
                   .ok());
  FlatPort bad;
  bad.air_gap = -1.0;
  const Status status =
      StereoRenderer::Create(rig, FlatPort(), bad, &FlatPool(), RenderOptions())
          .status();
  EXPECT_NE(status.message().find("right"), std::string::npos);
}

TEST(StereoRenderer, RenderFailsOutsideTheTankOrForABadIndex) {
  StereoRenderer renderer = MakeRenderer(FlatPool(), Quick());
  EXPECT_FALSE(renderer.Render(LookingDown({6.0, 4.0, 3.5}), 1.333, 0).ok());
  // cam1 is 0.11 m to the right (+x here) of cam0, beyond the wall x = 12.
  EXPECT_FALSE(renderer.Render(LookingDown({11.95, 4.0, 1.0}), 1.333, 0).ok());
  EXPECT_FALSE(renderer.Render(LookingDown({6.0, 4.0, 1.0}), 2.5, 0).ok());
  EXPECT_FALSE(renderer.Render(LookingDown({6.0, 4.0, 1.0}), 0.9, 0).ok());
  EXPECT_EQ(renderer.NumCachedIndices(), 0);
}

TEST(StereoRenderer, ImagesAreEightBitMonoAtCameraResolution) {
  StereoRenderer renderer = MakeRenderer(Pool(), Quick());
  const StereoImages images = renderer.Render(RobotPose(), 1.333, 0).value();
  for (const cv::Mat* image : {&images.left, &images.right}) {
    EXPECT_EQ(image->type(), CV_8UC1);
    EXPECT_EQ(image->cols, 720);
    EXPECT_EQ(image->rows, 540);
    // Textured, exposed: neither flat nor clipped.
    cv::Scalar mean, stddev;
    cv::meanStdDev(*image, mean, stddev);
    EXPECT_GT(mean[0], 50.0);
    EXPECT_LT(mean[0], 200.0);
    EXPECT_GT(stddev[0], 15.0);
  }
}

TEST(StereoRenderer, CachesOneRayTablePerIndex) {
  RenderOptions options = Quick();
  options.max_cached_indices = 2;
  StereoRenderer renderer = MakeRenderer(FlatPool(), options);
  EXPECT_TRUE(renderer.PrepareRays(1.0).ok());
  EXPECT_TRUE(renderer.PrepareRays(1.333).ok());
  EXPECT_TRUE(renderer.PrepareRays(1.0).ok());
  EXPECT_EQ(renderer.NumCachedIndices(), 2);
  EXPECT_TRUE(renderer.PrepareRays(1.34).ok());
  EXPECT_EQ(renderer.NumCachedIndices(), 2);
  EXPECT_FALSE(renderer.PrepareRays(2.5).ok());
}

TEST(StereoRenderer, SameInputsGiveTheSameBytes) {
  RenderOptions options = Quick();
  StereoRenderer renderer = MakeRenderer(Pool(), options);
  options.num_threads = 1;
  StereoRenderer single_thread = MakeRenderer(Pool(), options);
  const Rigid3d pose = RobotPose();
  const StereoImages a = renderer.Render(pose, 1.333, 5).value();
  const StereoImages b = renderer.Render(pose, 1.333, 5).value();
  const StereoImages c = single_thread.Render(pose, 1.333, 5).value();
  EXPECT_EQ(DifferingPixels(a.left, b.left), 0);
  EXPECT_EQ(DifferingPixels(a.right, b.right), 0);
  EXPECT_EQ(DifferingPixels(a.left, c.left), 0);
  EXPECT_EQ(DifferingPixels(a.right, c.right), 0);

  // Another frame or noise seed: new noise (sigma ~2 DN, so most pixels
  // change), the same scene.
  const int pixels = 720 * 540;
  const StereoImages next_frame = renderer.Render(pose, 1.333, 6).value();
  EXPECT_GT(DifferingPixels(a.left, next_frame.left), pixels / 2);
  EXPECT_LT(cv::norm(a.left, next_frame.left, cv::NORM_L1) / pixels, 4.0);
  options.seed = 2;
  StereoRenderer other_seed = MakeRenderer(Pool(), options);
  EXPECT_GT(
      DifferingPixels(a.left, other_seed.Render(pose, 1.333, 5).value().left),
      pixels / 2);
  // Another scene: other textures.
  TankSceneOptions scene_options;
  scene_options.seed = 99;
  const TankScene other_scene = TankScene::Create(scene_options).value();
  StereoRenderer other = MakeRenderer(other_scene, Quick());
  EXPECT_GT(
      cv::norm(a.left, other.Render(pose, 1.333, 5).value().left, cv::NORM_L1) /
          pixels,
      10.0);
}

// Expected DN of a pixel of the flat pool (see stereo_renderer.h): the
// radiance of the surface it sees, attenuated over the distance to it.
double ExpectedDn(const FlatPortCamera& camera, const Rigid3d& world_from_cam,
                  const Eigen::Vector2d& pixel, const RenderOptions& o,
                  double attenuation) {
  const RayInMedium ray = camera.RayFromImage(pixel).value();
  const Eigen::Vector3d direction = world_from_cam.rotation * ray.direction;
  const SurfaceHit hit =
      FlatPool().Intersect(world_from_cam * ray.origin, direction).value();
  constexpr double kAlbedo = 0.6;                  // FlatPool()
  double radiance = o.surface_radiance * kAlbedo;  // the emitting surface
  if (hit.surface != TankSurface::kSurface) {
    double irradiance = o.ambient * (0.7 + 0.3 * hit.normal.z());
    const Eigen::Vector3d light = world_from_cam * o.light_position_in_cam0;
    const Eigen::Vector3d to_point = hit.point - light;
    const double r = to_point.norm();
    const double cos_beam = world_from_cam.rotation.col(2).dot(to_point) / r;
    const double cos_incidence = -hit.normal.dot(to_point) / r;
    if (cos_beam > 0.0 && cos_incidence > 0.0) {
      irradiance += o.light_intensity *
                    std::pow(cos_beam, o.light_beam_exponent) * cos_incidence *
                    std::exp(-attenuation * r) / (r * r);
    }
    radiance = kAlbedo * irradiance;
  }
  const double transmittance = std::exp(-attenuation * hit.distance);
  return 255.0 * o.exposure *
         (radiance * transmittance + o.water_radiance * (1.0 - transmittance));
}

TEST(StereoRenderer, PixelsFollowTheAttenuationLaw) {
  RenderOptions options = Quick();
  options.read_noise = 0.0;
  options.full_well = 0.0;
  options.light_intensity = 0.0;
  options.water_attenuation = 0.2;
  options.water_radiance = 0.35;
  options.ambient = 0.8;
  const StereoRig rig = AlphasenseFrontRectifiedRig();
  const Rigid3d pose = RobotPose();
  // The image center sees the floor 4 m away, the top rows walls 7-12 m
  // away, the bottom rows the floor 1.5 m away: transmittances 0.1-0.75.
  const std::vector<Eigen::Vector2d> pixels = {
      {360, 271}, {360, 10}, {100, 40}, {700, 30}, {360, 530}, {20, 500}};
  for (double n : {1.0, 1.333}) {
    SCOPED_TRACE(n);
    StereoRenderer renderer = MakeRenderer(FlatPool(), options, rig);
    const StereoImages images = renderer.Render(pose, n, 0).value();
    const FlatPortCamera camera =
        FlatPortCamera::Create(rig.left(), FlatPort(), n).value();
    const double attenuation = n > 1.0 ? options.water_attenuation : 0.0;
    std::vector<double> expected;
    for (const Eigen::Vector2d& pixel : pixels) {
      expected.push_back(ExpectedDn(camera, pose, pixel, options, attenuation));
      EXPECT_NEAR(images.left.at<uint8_t>(pixel.y(), pixel.x()),
                  expected.back(), kRoundingTolerance)
          << pixel.transpose();
    }
    if (n > 1.0) {
      // Distance matters: the far wall fades towards the water's radiance.
      EXPECT_GT(*std::max_element(expected.begin(), expected.end()) -
                    *std::min_element(expected.begin(), expected.end()),
                20.0);
    }
  }
  // The vehicle's lamp adds its inverse-square, attenuated light.
  options.light_intensity = 1.5;
  StereoRenderer renderer = MakeRenderer(FlatPool(), options, rig);
  const StereoImages lit = renderer.Render(pose, 1.333, 0).value();
  const FlatPortCamera camera =
      FlatPortCamera::Create(rig.left(), FlatPort(), 1.333).value();
  for (const Eigen::Vector2d& pixel : pixels) {
    EXPECT_NEAR(lit.left.at<uint8_t>(pixel.y(), pixel.x()),
                ExpectedDn(camera, pose, pixel, options, 0.2),
                kRoundingTolerance)
        << pixel.transpose();
  }
}

TEST(StereoRenderer, WaterNarrowsTheFieldOfView) {
  // Looking down at the floor 1.5 m below: the water image's center is the
  // air image's magnified by about n (rays bend away from the axis at the
  // port, sin theta_air = n sin theta_water, so each pixel sees n times
  // less). Of a set of zooms, n fits best.
  RenderOptions options = Quick();
  options.read_noise = 0.0;
  options.full_well = 0.0;
  StereoRenderer renderer = MakeRenderer(Pool(), options);
  const Rigid3d pose = LookingDown({5.3, 3.7, 1.5});
  const cv::Mat air = renderer.Render(pose, 1.0, 0).value().left;
  const cv::Mat water = renderer.Render(pose, 1.333, 0).value().left;
  EXPECT_GT(cv::norm(air, water, cv::NORM_L1) / air.total(), 10.0);
  const Camera& camera = renderer.rig().left();
  const cv::Rect center(static_cast<int>(camera.cx()) - 50,
                        static_cast<int>(camera.cy()) - 50, 100, 100);
  cv::Mat water_center;
  water(center).convertTo(water_center, CV_32F);
  double best_zoom = 0.0, best_ncc = -1.0, unzoomed_ncc = 0.0;
  for (double zoom : {1.0, 1.1, 1.2, 1.333, 1.45, 1.6}) {
    // zoomed(p) = air(c + (p - c) / zoom)
    const cv::Mat map = (cv::Mat_<double>(2, 3) << 1.0 / zoom, 0.0,
                         camera.cx() * (1.0 - 1.0 / zoom), 0.0, 1.0 / zoom,
                         camera.cy() * (1.0 - 1.0 / zoom));
    cv::Mat zoomed;
    cv::warpAffine(air, zoomed, map, air.size(),
                   cv::INTER_LINEAR | cv::WARP_INVERSE_MAP);
    cv::Mat zoomed_center;
    zoomed(center).convertTo(zoomed_center, CV_32F);
    const double ncc = Ncc(water_center, zoomed_center);
    if (zoom == 1.0) unzoomed_ncc = ncc;
    if (ncc > best_ncc) {
      best_ncc = ncc;
      best_zoom = zoom;
    }
  }
  EXPECT_EQ(best_zoom, 1.333);
  EXPECT_GT(best_ncc, 0.8);
  EXPECT_LT(unzoomed_ncc, 0.5);
}

TEST(StereoRenderer, LeftAndRightPatchesAgreeThroughThePorts) {
  // The world point seen at a left pixel, projected through the right port
  // and lens, lands where the right image shows the same texture: 15 x 15
  // patches around the two pixels correlate. Unrectified rig, thick
  // ports, water, the default (supersampled, noisy) rendering.
  const StereoRig rig = AlphasenseFrontUnrectifiedRig();
  FlatPort port;
  port.air_gap = 0.01;
  port.glass_thickness = 0.008;
  port.normal = TiltedPortNormal(1.0 * M_PI / 180.0, 0.3);
  StereoRenderer renderer = MakeRenderer(Pool(), RenderOptions(), rig, port);
  const Rigid3d world_from_left = RobotPose();
  const Rigid3d right_from_world =
      (world_from_left * rig.right_from_left().Inverse()).Inverse();
  const double n = 1.333;
  const StereoImages images = renderer.Render(world_from_left, n, 3).value();
  const FlatPortCamera left =
      FlatPortCamera::Create(rig.left(), port, n).value();
  const FlatPortCamera right =
      FlatPortCamera::Create(rig.right(), port, n).value();

  constexpr int kHalf = 7;  // 15 x 15 patches
  std::mt19937_64 rng(11);
  std::uniform_int_distribution<int> u(kHalf, 719 - kHalf);
  std::uniform_int_distribution<int> v(kHalf, 539 - kHalf);
  int tested = 0, agreeing = 0;
  while (tested < 200) {
    // v before u, in a statement of its own (argument order is unspecified).
    const double drawn_v = v(rng);
    const Eigen::Vector2d left_pixel(u(rng), drawn_v);
    const RayInMedium ray = left.RayFromImage(left_pixel).value();
    const SurfaceHit hit =
        Pool()
            .Intersect(world_from_left * ray.origin,
                       world_from_left.rotation * ray.direction)
            .value();
    const std::optional<Eigen::Vector2d> right_pixel =
        right.ImageFromPoint(right_from_world * hit.point);
    if (!right_pixel || right_pixel->x() < kHalf + 1 ||
        right_pixel->y() < kHalf + 1 || right_pixel->x() > 718 - kHalf ||
        right_pixel->y() > 538 - kHalf) {
      continue;
    }
    ++tested;
    cv::Mat left_patch, right_patch;
    images
        .left(cv::Rect(left_pixel.x() - kHalf, left_pixel.y() - kHalf,
                       2 * kHalf + 1, 2 * kHalf + 1))
        .convertTo(left_patch, CV_32F);
    cv::getRectSubPix(images.right, cv::Size(2 * kHalf + 1, 2 * kHalf + 1),
                      cv::Point2f(right_pixel->x(), right_pixel->y()),
                      right_patch, CV_32F);
    agreeing += Ncc(left_patch, right_patch) > 0.8;
  }
  // 193 of 200 agree with the default seeds. Those that do not are
  // low-contrast patches (standard deviation 3-6 DN) of distant, hazy wall
  // where the ~2.3 DN sensor noise, independent in the two images, pulls
  // the correlation down; 170 leaves room for other textures.
  EXPECT_GE(agreeing, 170);
}

TEST(StereoRenderer, UntraceablePixelsAreBlack) {
  // f = 60 px: the corners (200 px off center) would see 3.3 rad off axis,
  // beyond what the equidistant lens can undistort (pi / 2).
  const Camera wide =
      Camera::Create(LensModelId::kEquidistant, 320, 240,
                     {60.0, 60.0, 159.5, 119.5}, {0.0, 0.0, 0.0, 0.0})
          .value();
  Rigid3d right_from_left;
  right_from_left.translation = Eigen::Vector3d(-0.11, 0.0, 0.0);
  const StereoRig rig = StereoRig::Create(wide, wide, right_from_left).value();
  StereoRenderer renderer = MakeRenderer(Pool(), RenderOptions(), rig);
  const StereoImages images = renderer.Render(RobotPose(), 1.333, 0).value();
  EXPECT_EQ(images.left.at<uint8_t>(0, 0), 0);
  EXPECT_EQ(images.right.at<uint8_t>(239, 319), 0);
  EXPECT_GT(images.left.at<uint8_t>(120, 160), 0);
  EXPECT_FALSE(wide.NormalizedFromImage(Eigen::Vector2d(0.0, 0.0)));
}

TEST(StereoRenderer, ABoardOnlyChangesThePixelsThatSeeIt) {
  // Out of sight (behind the rig) a board changes no byte: the images are
  // those of the renderer without one. In front, it covers a patch of
  // both images, and no pixel outside the patch its outline projects to.
  StereoRenderer renderer = MakeRenderer(Pool(), Quick());
  const Rigid3d pose = RobotPose();
  const StereoImages plain = renderer.Render(pose, 1.333, 2).value();
  const SceneBoard board;
  Rigid3d behind;
  behind.translation = Eigen::Vector3d(0.0, 0.0, -1.0);
  const PlacedBoard hidden(board, pose * behind);
  const StereoImages with_hidden =
      renderer.Render(pose, 1.333, 2, &hidden).value();
  EXPECT_EQ(DifferingPixels(plain.left, with_hidden.left), 0);
  EXPECT_EQ(DifferingPixels(plain.right, with_hidden.right), 0);

  Rigid3d ahead;
  ahead.translation = Eigen::Vector3d(0.0, 0.0, 1.0) - board.Center();
  const PlacedBoard shown(board, pose * ahead);
  const StereoImages with_board =
      renderer.Render(pose, 1.333, 2, &shown).value();
  const FlatPortCamera camera =
      FlatPortCamera::Create(renderer.rig().left(), FlatPort(), 1.333).value();
  // The printed area's projection, a convex quadrilateral up to the
  // lens's and port's slight bending, grown by 2 px.
  std::vector<cv::Point> outline;
  for (const Eigen::Vector3d& corner :
       {Eigen::Vector3d(board.MinX(), board.MinY(), 0.0),
        Eigen::Vector3d(board.MaxX(), board.MinY(), 0.0),
        Eigen::Vector3d(board.MaxX(), board.MaxY(), 0.0),
        Eigen::Vector3d(board.MinX(), board.MaxY(), 0.0)}) {
    const Eigen::Vector2d pixel = camera.ImageFromPoint(ahead * corner).value();
    outline.emplace_back(static_cast<int>(std::lround(pixel.x())),
                         static_cast<int>(std::lround(pixel.y())));
  }
  cv::Mat mask(plain.left.size(), CV_8UC1, cv::Scalar(0));
  cv::fillConvexPoly(mask, outline, cv::Scalar(255));
  cv::dilate(mask, mask, cv::Mat(), cv::Point(-1, -1), 2);
  const cv::Mat changed = plain.left != with_board.left;
  EXPECT_GT(cv::countNonZero(changed & mask), cv::countNonZero(mask) / 2);
  EXPECT_EQ(cv::countNonZero(changed & ~mask), 0);
  EXPECT_GT(DifferingPixels(plain.right, with_board.right), 10000);
}

}  // namespace
}  // namespace rcm::stereo_renderer_test
