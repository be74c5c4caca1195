// The geometry of the dome port of an underwater housing: a spherical
// glass shell of inner radius r1, thickness tg (outer radius
// r2 = r1 + tg) and index n_glass, whose centre C sits at the
// decentering vector from the camera's projection centre (camera frame,
// x right, y down, z forward, metres). Read from a camchain camera's
// `port` block of type dome (camchain.h); the model is in
// dome_port_refraction.h, the camera in dome_port_camera.h.
//
//   inner glass surface   { p : |p - C| = r1 }
//   outer glass surface   { p : |p - C| = r2 }
//   medium                { p : |p - C| > r2 }
//
// The camera centre must lie inside the inner sphere, |C| < r1. A dome
// whose centre is the projection centre (C = 0) does not refract: every
// ray meets both surfaces along their normals. A camera "7 mm behind the
// dome's centre" has C = (0, 0, +0.007).
#ifndef RCM_CAMERA_DOME_PORT_GEOMETRY_H_
#define RCM_CAMERA_DOME_PORT_GEOMETRY_H_

#include <Eigen/Core>

#include "rcm/util/status.h"

namespace rcm {

struct DomePort {
  // Largest accepted inner radius and thickness, meters: far beyond any
  // housing (deep-rated domes are 2-8 inches across), small enough that a
  // unit mix-up (millimetres given as metres) is caught.
  static constexpr double kMaxInnerRadius = 1.0;
  static constexpr double kMaxThickness = 0.1;
  // Smallest inner radius and nonzero thickness, meters: below them a
  // layer is rounding, not glass (as FlatPort::kMinLayerThickness).
  static constexpr double kMinLayer = 1e-6;
  // How far inside the inner sphere the camera centre must lie, meters:
  // nearer, rays leave the camera at grazing incidence on the glass.
  static constexpr double kMinClearance = 1e-4;

  // r1, meters, in [1e-6, 1].
  double inner_radius = 0.05;
  // tg, meters: 0 (a single water-air surface) or in [1e-6, 0.1].
  double thickness = 0.005;
  // n_glass, [1, 2] (acrylic 1.49; borosilicate 1.47; BK7 1.517).
  double glass_index = 1.49;
  // C, the dome's centre in the camera frame, meters; |C| at most
  // r1 - kMinClearance.
  Eigen::Vector3d decentering = Eigen::Vector3d::Zero();

  double outer_radius() const { return inner_radius + thickness; }
  // True when C = 0 exactly: the dome does not refract.
  bool IsCentred() const { return decentering.isZero(0.0); }

  // Errors name the field: "dome inner_radius = 43.55 m is outside
  // [1e-06, 1] (millimetres given as metres?)", "dome decentering (0, 0,
  // 0.05) m puts the camera centre outside the inner sphere of radius
  // 0.04355 m (|C| = 0.05)", ...
  Status Check() const;

  bool operator==(const DomePort& other) const {
    return inner_radius == other.inner_radius && thickness == other.thickness &&
           glass_index == other.glass_index && decentering == other.decentering;
  }
  bool operator!=(const DomePort& other) const { return !(*this == other); }
};

// The thickness of a dome given by its two radii (rounded to the
// nanometre), with the check that they agree with a thickness given too
// (`thickness` < 0: not given).
// Errors: "dome outer radius 0.0473 m is not beyond the inner radius
// 0.04355 m", "dome radii 0.04355 m and 0.0473 m give a thickness of
// 0.00375 m, not the 0.005 m given".
StatusOr<double> DomeThicknessFromRadii(double inner_radius,
                                        double outer_radius, double thickness);

}  // namespace rcm

#endif  // RCM_CAMERA_DOME_PORT_GEOMETRY_H_
