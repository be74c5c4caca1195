#include "support/test_rigs.h"

#include <Eigen/Geometry>
#include <cmath>

#include "rcm/camera/refractive_camera.h"
#include "rcm/sim/reference_rigs.h"
#include "rcm/sim/stereo_sampler.h"

namespace rcm::test {

Camera AlphasenseCam0() { return AlphasenseFrontCam0(); }

Camera AlphasenseCam1() { return AlphasenseFrontCam1(); }

Camera EurocRadtanCamera() { return EurocCam0(); }

StereoRig EurocRadtanTwinRig() {
  const Camera camera = EurocRadtanCamera();
  Rigid3d right_from_left;
  right_from_left.rotation =
      Eigen::AngleAxisd(0.5 * M_PI / 180.0,
                        Eigen::Vector3d(0.2, 1.0, 0.1).normalized())
          .toRotationMatrix();
  right_from_left.translation = Eigen::Vector3d(-0.11, 0.001, 0.002);
  return StereoRig::Create(camera, camera, right_from_left).value();
}

Camera PinholeCamera() {
  return Camera::Create(LensModelId::kPinhole, 640, 480,
                        {400.0, 400.0, 319.5, 239.5}, {})
      .value();
}

DomePort AcrylicDome(const Eigen::Vector3d& decentering) {
  DomePort dome;
  dome.inner_radius = 0.04355;
  dome.thickness = 0.00375;
  dome.glass_index = 1.495;
  dome.decentering = decentering;
  return dome;
}

Camera WideEquidistantCamera() {
  const std::vector<double> k = AlphasenseCam0().Distortion();
  const double theta = 89.5 * M_PI / 180.0;
  const double theta_d = EquidistantLens::DistortedAngle(k.data(), theta);
  const double corner_distance = std::hypot(512.0, 512.0);
  const double f = corner_distance / theta_d;
  return Camera::Create(LensModelId::kEquidistant, 1024, 1024,
                        {f, f, 511.5, 511.5}, k)
      .value();
}

Camera RationalCamera() {
  return Camera::Create(LensModelId::kRational, 752, 480,
                        {461.3, 460.8, 371.9, 243.6},
                        {0.5, 0.1, 9.0e-4, -6.0e-4, 0.001, 0.75, 0.2, 0.001})
      .value();
}

Camera DoubleSphereCamera() {
  return Camera::Create(LensModelId::kDoubleSphere, 640, 480,
                        {300.2, 299.7, 318.4, 241.9}, {-0.18, 0.59})
      .value();
}

Camera EucmCamera() {
  return Camera::Create(LensModelId::kEucm, 640, 480,
                        {320.4, 319.8, 321.1, 238.6}, {0.63, 1.04})
      .value();
}

std::vector<Camera> AllTestCameras() {
  return {PinholeCamera(),         EurocRadtanCamera(),
          AlphasenseCam0(),        AlphasenseCam1(),
          WideEquidistantCamera(), RationalCamera(),
          DoubleSphereCamera(),    EucmCamera()};
}

StereoRig IdealRig(const Camera& left, const Camera& right, double baseline) {
  Rigid3d right_from_left;
  right_from_left.translation = Eigen::Vector3d(-baseline, 0.0, 0.0);
  return StereoRig::Create(left, right, right_from_left).value();
}

StereoRig AlphasenseIdealRig() { return AlphasenseFrontRectifiedRig(); }

StereoRig AlphasenseRealisticRig() { return AlphasenseFrontUnrectifiedRig(); }

StereoRig NarrowRadtanRig() {
  const Camera left =
      Camera::Create(LensModelId::kRadTan, 640, 480,
                     {500.0, 500.0, 322.0, 238.0}, {-0.12, 0.05, 1e-4, -2e-4})
          .value();
  const Camera right =
      Camera::Create(LensModelId::kRadTan, 640, 480,
                     {503.0, 502.0, 317.0, 243.0}, {-0.11, 0.04, -1e-4, 1e-4})
          .value();
  const double toe_in = 2.5 * M_PI / 180.0;
  Rigid3d right_from_left;
  right_from_left.rotation =
      Eigen::AngleAxisd(toe_in, Eigen::Vector3d::UnitY()).toRotationMatrix();
  right_from_left.translation =
      -(right_from_left.rotation * Eigen::Vector3d(0.065, 0.0, 0.0));
  return StereoRig::Create(left, right, right_from_left).value();
}

std::vector<StereoCorrespondence> ExactMatches(const StereoRig& rig, double n,
                                               int count, uint64_t seed) {
  StereoSamplerOptions options;
  options.n = n;
  options.per_frame = count;
  options.seed = seed;
  return SampleStereoCorrespondences(rig, options).value();
}

std::vector<StereoCorrespondence> ExactSequence(const StereoRig& rig, double n,
                                                int frames, int per_frame,
                                                uint64_t seed) {
  StereoSamplerOptions options;
  options.n = n;
  options.num_frames = frames;
  options.per_frame = per_frame;
  options.seed = seed;
  return SampleStereoCorrespondences(rig, options).value();
}

std::vector<PreparedCorrespondence> NoisyPreparedMatches(const StereoRig& rig,
                                                         double n, int count,
                                                         double sigma_px,
                                                         uint64_t seed) {
  std::vector<StereoCorrespondence> data = ExactMatches(rig, n, count, seed);
  AddPixelNoise(sigma_px, seed + 100, &data);
  return PrepareCorrespondences(rig, data).prepared;
}

std::vector<StereoCorrespondence> ExactMatchesOnAxis(bool on_row, int count) {
  const StereoRig rig = test::AlphasenseIdealRig();
  const RefractiveCamera left =
      RefractiveCamera::Create(rig.left(), 1.333).value();
  const RefractiveCamera right =
      RefractiveCamera::Create(rig.right(), 1.333).value();
  std::vector<StereoCorrespondence> matches;
  for (int i = 0; i < count; ++i) {
    const double along = -1.0 + 2.0 * (i + 0.5) / count;  // normalized
    const Eigen::Vector2d normalized = on_row
                                           ? Eigen::Vector2d(along, 0.0)
                                           : Eigen::Vector2d(0.0, 0.6 * along);
    StereoCorrespondence match;
    match.left_pixel = rig.left().ImageFromNormalized(normalized);
    const Eigen::Vector3d bearing =
        left.BearingInWaterFromImage(match.left_pixel).value();
    const double depth = 0.6 + 5.4 * ((i * 7) % count) / count;
    const Eigen::Vector3d point = bearing * depth / bearing.z();
    const std::optional<Eigen::Vector2d> right_pixel =
        right.ImageFromPointInWater(rig.right_from_left().rotation * point +
                                    rig.right_from_left().translation);
    if (!right_pixel || !rig.right().InImage(*right_pixel)) continue;
    match.right_pixel = *right_pixel;
    matches.push_back(match);
  }
  return matches;
}

std::vector<Eigen::Vector2d> ImageGrid(const Camera& camera, double step) {
  std::vector<double> us, vs;
  for (double u = -0.5; u < camera.width() - 0.5; u += step) us.push_back(u);
  us.push_back(camera.width() - 0.5);
  for (double v = -0.5; v < camera.height() - 0.5; v += step) vs.push_back(v);
  vs.push_back(camera.height() - 0.5);
  std::vector<Eigen::Vector2d> grid;
  grid.reserve(us.size() * vs.size());
  for (double v : vs) {
    for (double u : us) grid.emplace_back(u, v);
  }
  return grid;
}

}  // namespace rcm::test
