#include "rcm/camera/flat_port_geometry.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <sstream>

namespace rcm {

Status FlatPort::Check() const {
  constexpr double kMaxIndex = 2.0;
  std::ostringstream message;
  const double norm = normal.stableNorm();  // No underflow of tiny normals.
  if (!std::isfinite(air_gap) || air_gap < 0.0 || air_gap > kMaxAirGap) {
    message << "port air_gap = " << air_gap << " m is outside [0, "
            << kMaxAirGap << "]";
  } else if (air_gap > 0.0 && air_gap < kMinLayerThickness) {
    message << "port air_gap = " << air_gap << " m is neither 0 nor at least "
            << kMinLayerThickness;
  } else if (!std::isfinite(glass_thickness) || glass_thickness < 0.0 ||
             glass_thickness > kMaxGlassThickness) {
    message << "port glass_thickness = " << glass_thickness
            << " m is outside [0, " << kMaxGlassThickness << "]";
  } else if (glass_thickness > 0.0 && glass_thickness < kMinLayerThickness) {
    message << "port glass_thickness = " << glass_thickness
            << " m is neither 0 nor at least " << kMinLayerThickness;
  } else if (!std::isfinite(glass_index) || glass_index < 1.0 ||
             glass_index > kMaxIndex) {
    message << "port glass_index = " << glass_index << " is outside [1, "
            << kMaxIndex << "]";
  } else if (!normal.allFinite() || !(norm > 0.0)) {
    message << "port normal must be a finite nonzero vector";
  } else if (normal.z() / norm <
             std::cos(kMaxTiltDegrees * M_PI / 180.0)) {
    message << "port normal is tilted "
            << std::acos(std::clamp(normal.z() / norm, -1.0, 1.0)) * 180.0 /
                   M_PI
            << " degrees from the optical axis (at most " << kMaxTiltDegrees
            << ")";
  } else {
    return Status::Ok();
  }
  return Status::Error(message.str());
}

bool FlatPort::IsThin() const {
  return air_gap == 0.0 && glass_thickness == 0.0 && normal.x() == 0.0 &&
         normal.y() == 0.0 && normal.z() > 0.0;
}

Eigen::Vector3d TiltedPortNormal(double tilt_radians, double azimuth_radians) {
  // Rotate +z by tilt about the in-plane axis (cos az, sin az, 0).
  const Eigen::Vector3d axis(std::cos(azimuth_radians),
                             std::sin(azimuth_radians), 0.0);
  const Eigen::Vector3d z = Eigen::Vector3d::UnitZ();
  return std::cos(tilt_radians) * z +
         std::sin(tilt_radians) * axis.cross(z);
}

}  // namespace rcm
