// Fuzzes the camera model entry points over arbitrary doubles: the lens
// models (rcm/camera/lens_models.h, through Camera), the thin-port
// refractive camera and its virtual pinhole (rcm/camera/refractive_camera.h,
// paper eqs. 5-9) and the thick-port camera (rcm/camera/flat_port_camera.h).
//
// Every entry point is called with whatever the bytes give, NaN and inf
// included: none may crash, hang or hit undefined behaviour, and the
// factories must reject what they cannot model. Properties checked on the
// results:
// - a pixel that unprojects reprojects onto itself (the lens equation is
//   solved, whatever branch the solver lands on);
// - every value a function returns (rather than nullopt/false) is finite,
//   and bearings are unit vectors;
// - for a lens of realistic coefficients (MildLens), a virtual pinhole
//   pixel that maps to a raw pixel in the image maps back onto itself.
//   With coefficients far beyond any calibration (p1 = p2 = -0.65, say)
//   the lens map is many-to-one inside the image, and the unprojection
//   may land on another preimage; it still reprojects (first property).
//   The virtual pixel must lie within ten image sizes of the image and
//   its ray within 85 degrees of the axis (NearTheImage): far beyond, its
//   bearing grazes 90 degrees and the back map cannot recover it.
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include "fuzz_input.h"
#include "rcm/camera/camera.h"
#include "rcm/camera/flat_port_camera.h"
#include "rcm/camera/refractive_camera.h"

namespace {

using rcm::fuzz::ConsumeDouble;
using rcm::fuzz::FuzzCheck;

// Reprojection of an unprojected pixel, in pixels: the undistortion
// converges to 1e-14 in normalized units (lens_models.h), 1e-9 px at a
// focal length of 1e5 px; the tolerance leaves room for the rounding of
// large coordinates.
bool Reprojects(const Eigen::Vector2d& pixel, const Eigen::Vector2d& back) {
  return (pixel - back).norm() <= 1e-6 * (1.0 + pixel.norm());
}

// Radial coefficients up to 0.3 and tangential ones up to 0.01 in
// magnitude: beyond every lens in the test data and Kalibr's examples. For
// the unified models, |xi| <= 0.5 and alpha <= 0.7 (ds), alpha <= 0.7 and
// beta in [0.5, 2] (eucm): the range of real calibrations (TUM-VI, basalt).
bool MildLens(const rcm::Camera& camera) {
  const std::vector<double> distortion = camera.Distortion();
  switch (camera.model()) {
    case rcm::LensModelId::kDoubleSphere:
      return std::abs(distortion[0]) <= 0.5 && distortion[1] <= 0.7;
    case rcm::LensModelId::kEucm:
      return distortion[0] <= 0.7 && distortion[1] >= 0.5 &&
             distortion[1] <= 2.0;
    default:
      break;
  }
  for (size_t i = 0; i < distortion.size(); ++i) {
    const bool tangential = (camera.model() == rcm::LensModelId::kRadTan ||
                             camera.model() == rcm::LensModelId::kRational) &&
                            (i == 2 || i == 3);
    if (std::abs(distortion[i]) > (tangential ? 0.01 : 0.3)) return false;
  }
  return true;
}

// Within ten image sizes of the image, and on a ray within 85 degrees of
// the axis (normalized radius up to tan 85 deg = 11.4, ten image sizes for
// a focal length of the image's size): any virtual pinhole image a remap
// of a real camera would ask for. Closer to 90 degrees the back map's unit
// bearing no longer determines the pixel to 1e-6 px (found by fuzzing: a
// virtual pixel at 6e135 px, whose raw pixel sees a ray in air 0.01
// degrees from grazing, mapped back to nothing; and a focal length of
// 5.4 px on a 3339 px high image, whose corner pixel, inside the image,
// lies 89.9 degrees off axis and came back 1.04e-6 px off).
bool NearTheImage(const rcm::Camera& camera, const Eigen::Vector2d& pixel) {
  constexpr double kMaxNormalizedRadius = 11.430052302761348;  // tan 85 deg
  const double x = (pixel.x() - camera.cx()) / camera.fx();
  const double y = (pixel.y() - camera.cy()) / camera.fy();
  return std::abs(pixel.x()) <= 10.0 * camera.width() &&
         std::abs(pixel.y()) <= 10.0 * camera.height() &&
         std::hypot(x, y) <= kMaxNormalizedRadius;
}

std::optional<rcm::Camera> ConsumeCamera(FuzzedDataProvider& data) {
  const auto model = static_cast<rcm::LensModelId>(
      data.ConsumeIntegralInRange<int>(0, rcm::kNumLensModels - 1));
  const int width = data.ConsumeIntegralInRange<int>(-1, 4000);
  const int height = data.ConsumeIntegralInRange<int>(-1, 4000);
  std::array<double, 4> intrinsics;
  intrinsics[0] = ConsumeDouble(data, -10.0, 5000.0);
  intrinsics[1] = ConsumeDouble(data, -10.0, 5000.0);
  intrinsics[2] = ConsumeDouble(data, -100.0, 4000.0);
  intrinsics[3] = ConsumeDouble(data, -100.0, 4000.0);
  std::vector<double> distortion(rcm::NumDistortionParams(model));
  for (double& coefficient : distortion) {
    coefficient = ConsumeDouble(data, -1.0, 1.0);
  }
  // The unified models' second coefficient over its range and beyond
  // (alpha of ds up to 1.1, beta of eucm up to 3), so that the range
  // checks and the whole range are both reached.
  if (model == rcm::LensModelId::kDoubleSphere) {
    distortion[1] = ConsumeDouble(data, -0.1, 1.1);
  } else if (model == rcm::LensModelId::kEucm) {
    distortion[0] = ConsumeDouble(data, -0.1, 1.1);
    distortion[1] = ConsumeDouble(data, -0.1, 3.0);
  }
  rcm::StatusOr<rcm::Camera> camera =
      rcm::Camera::Create(model, width, height, intrinsics, distortion);
  if (!camera.ok()) return std::nullopt;
  return *camera;
}

void FuzzLens(const rcm::Camera& camera, const Eigen::Vector2d& pixel,
              const Eigen::Vector2d& normalized) {
  if (const std::optional<Eigen::Vector2d> x =
          camera.NormalizedFromImage(pixel)) {
    FuzzCheck(x->allFinite(), "NormalizedFromImage returned a non-finite point");
    FuzzCheck(Reprojects(pixel, camera.ImageFromNormalized(*x)),
              "an unprojected pixel does not reproject onto itself");
    camera.ImageFromNormalizedJacobian(*x);
  }
  if (const std::optional<Eigen::Vector2d> projected =
          camera.ProjectNormalized(normalized)) {
    FuzzCheck(projected->allFinite(),
              "ProjectNormalized returned a non-finite pixel");
  }
  camera.LensInvertibleAt(normalized);
  camera.InImage(pixel);
}

void FuzzRefractive(const rcm::RefractiveCamera& camera,
                    const Eigen::Vector2d& pixel,
                    const Eigen::Vector3d& point) {
  if (const std::optional<Eigen::Vector3d> bearing =
          camera.BearingInWaterFromImage(pixel)) {
    FuzzCheck(bearing->allFinite() && std::abs(bearing->norm() - 1.0) < 1e-9,
              "a bearing that is not a finite unit vector");
  }
  if (const std::optional<Eigen::Vector2d> image =
          camera.ImageFromPointInWater(point)) {
    FuzzCheck(image->allFinite(), "ImageFromPointInWater: non-finite pixel");
  }
  if (const std::optional<Eigen::Vector2d> virtual_pixel =
          camera.VirtualPinholeFromImage(pixel)) {
    FuzzCheck(virtual_pixel->allFinite(),
              "VirtualPinholeFromImage: non-finite pixel");
  }
  // The remap direction: virtual pinhole pixel -> raw pixel -> back.
  if (const std::optional<Eigen::Vector2d> raw =
          camera.ImageFromVirtualPinhole(pixel)) {
    FuzzCheck(raw->allFinite(), "ImageFromVirtualPinhole: non-finite pixel");
    if (camera.camera().InImage(*raw) && MildLens(camera.camera()) &&
        NearTheImage(camera.camera(), pixel)) {
      const std::optional<Eigen::Vector2d> back =
          camera.VirtualPinholeFromImage(*raw);
      FuzzCheck(back.has_value() && Reprojects(pixel, *back),
                "a virtual pinhole pixel does not map back onto itself");
    }
  }
  FuzzCheck(camera.VirtualPinholeMatrix().allFinite(), "K_n not finite");
}

void FuzzThickPort(const rcm::FlatPortCamera& camera,
                   const Eigen::Vector2d& pixel, const Eigen::Vector3d& point) {
  if (const std::optional<rcm::RayInMedium> ray = camera.RayFromImage(pixel)) {
    FuzzCheck(ray->origin.allFinite() && ray->direction.allFinite(),
              "RayFromImage: non-finite ray");
  }
  if (const std::optional<Eigen::Vector2d> image =
          camera.ImageFromPoint(point)) {
    FuzzCheck(image->allFinite(), "ImageFromPoint: non-finite pixel");
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* bytes, size_t size) {
  FuzzedDataProvider data(bytes, size);
  const std::optional<rcm::Camera> camera = ConsumeCamera(data);
  const Eigen::Vector2d pixel(ConsumeDouble(data, -1000.0, 5000.0),
                              ConsumeDouble(data, -1000.0, 5000.0));
  const Eigen::Vector2d normalized(ConsumeDouble(data, -5.0, 5.0),
                                   ConsumeDouble(data, -5.0, 5.0));
  const Eigen::Vector3d point(ConsumeDouble(data, -10.0, 10.0),
                              ConsumeDouble(data, -10.0, 10.0),
                              ConsumeDouble(data, -1.0, 10.0));
  const double n = ConsumeDouble(data, 0.5, 2.5);
  rcm::FlatPort port;
  port.air_gap = ConsumeDouble(data, -0.01, 0.6);
  port.glass_thickness = ConsumeDouble(data, -0.01, 0.12);
  port.glass_index = ConsumeDouble(data, 0.5, 2.5);
  port.normal = Eigen::Vector3d(ConsumeDouble(data, -1.0, 1.0),
                                ConsumeDouble(data, -1.0, 1.0),
                                ConsumeDouble(data, -1.0, 1.0));
  const double reference_depth = ConsumeDouble(data, -1.0, 10.0);
  if (!camera) return 0;

  FuzzLens(*camera, pixel, normalized);
  if (rcm::StatusOr<rcm::RefractiveCamera> thin =
          rcm::RefractiveCamera::Create(*camera, n);
      thin.ok()) {
    FuzzRefractive(*thin, pixel, point);
  }
  if (rcm::StatusOr<rcm::RefractiveCamera> central =
          rcm::RefractiveCamera::CreateWithPort(*camera, n, port,
                                                reference_depth);
      central.ok()) {
    FuzzRefractive(*central, pixel, point);
  }
  if (rcm::StatusOr<rcm::FlatPortCamera> thick =
          rcm::FlatPortCamera::Create(*camera, port, n);
      thick.ok()) {
    FuzzThickPort(*thick, pixel, point);
  }
  return 0;
}
