// The geometry of the flat port of an underwater housing: how far the
// glass sits in front of the camera center, how thick it is, its index
// and its normal. The paper's model (refractive_model.h) is the thin port:
// lens center on the glass, glass of negligible thickness, normal on the
// optical axis. Read from the `port` block of a camchain camera
// (camchain.h); used by the simulator's exact port (sim/flat_port.h) and
// by the thick-port camera model.
//
// Geometry in the camera frame (x right, y down, z forward), N the unit
// normal with N_z > 0, pointing out of the housing:
//   inner glass face   { p : N . p = air_gap }
//   outer glass face   { p : N . p = air_gap + glass_thickness }
//   medium             { p : N . p > air_gap + glass_thickness }
#ifndef RCM_CAMERA_FLAT_PORT_GEOMETRY_H_
#define RCM_CAMERA_FLAT_PORT_GEOMETRY_H_

#include <Eigen/Core>

#include "rcm/util/status.h"

namespace rcm {

// A flat port in front of one camera. The default is the thin port of the
// paper: no gap, no glass, normal on the optical axis.
struct FlatPort {
  // Largest accepted values: far beyond any housing, small enough that a
  // unit mix-up (millimetres for metres) is caught.
  static constexpr double kMaxAirGap = 0.5;          // meters
  static constexpr double kMaxGlassThickness = 0.1;  // meters
  static constexpr double kMaxTiltDegrees = 30.0;
  // Smallest nonzero air gap or glass thickness. Below it a layer is not a
  // housing but rounding: a ray through a gap of 1e-80 m leaves it at a
  // grazing angle the solvers cannot tell from a miss, so the port's round
  // trip fails (a fuzzing finding). Thinner layers must be given as 0.
  static constexpr double kMinLayerThickness = 1e-6;  // meters

  // d, meters, camera center to the glass: 0 or in [1e-6, 0.5].
  double air_gap = 0.0;
  // tg, meters: 0 or in [1e-6, 0.1].
  double glass_thickness = 0.0;
  double glass_index = 1.49;     // n_glass (acrylic; BK7 is 1.517), [1, 2]
  // Port normal in the camera frame; normalized by Check's caller. Must be
  // finite, nonzero and within 30 degrees of the optical axis.
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();

  // Errors name the offending field: "port air_gap = 8 m is outside
  // [0, 0.5]", "port air_gap = 1e-09 m is neither 0 nor at least 1e-06",
  // ...
  Status Check() const;
  // True for the paper's thin port (d = tg = 0, normal = +z exactly).
  bool IsThin() const;
  bool operator==(const FlatPort& other) const {
    return air_gap == other.air_gap &&
           glass_thickness == other.glass_thickness &&
           glass_index == other.glass_index && normal == other.normal;
  }
  bool operator!=(const FlatPort& other) const { return !(*this == other); }
};

// The normal of a port tilted by `tilt_radians` about the axis of angle
// `azimuth_radians` in the image plane (0 = about +x, i.e. pitch).
Eigen::Vector3d TiltedPortNormal(double tilt_radians, double azimuth_radians);

}  // namespace rcm

#endif  // RCM_CAMERA_FLAT_PORT_GEOMETRY_H_
