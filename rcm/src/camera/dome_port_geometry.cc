#include "rcm/camera/dome_port_geometry.h"

#include <cmath>
#include <sstream>

namespace rcm {

Status DomePort::Check() const {
  constexpr double kMaxIndex = 2.0;
  std::ostringstream message;
  if (!std::isfinite(inner_radius) || inner_radius < kMinLayer ||
      inner_radius > kMaxInnerRadius) {
    message << "dome inner_radius = " << inner_radius << " m is outside ["
            << kMinLayer << ", " << kMaxInnerRadius << "]";
    if (inner_radius > kMaxInnerRadius && inner_radius < 1e4) {
      message << " (millimetres given as metres?)";
    }
  } else if (!std::isfinite(thickness) || thickness < 0.0 ||
             thickness > kMaxThickness) {
    message << "dome thickness = " << thickness << " m is outside [0, "
            << kMaxThickness << "]";
  } else if (thickness > 0.0 && thickness < kMinLayer) {
    message << "dome thickness = " << thickness
            << " m is neither 0 nor at least " << kMinLayer;
  } else if (!std::isfinite(glass_index) || glass_index < 1.0 ||
             glass_index > kMaxIndex) {
    message << "dome glass_index = " << glass_index << " is outside [1, "
            << kMaxIndex << "]";
  } else if (!decentering.allFinite()) {
    message << "dome decentering must be finite";
  } else if (!(decentering.norm() <= inner_radius - kMinClearance)) {
    message << "dome decentering (" << decentering.x() << ", "
            << decentering.y() << ", " << decentering.z()
            << ") m puts the camera centre outside the inner sphere of "
               "radius "
            << inner_radius << " m (|C| = " << decentering.norm()
            << " m; at most r1 - " << kMinClearance << ")";
  } else {
    return Status::Ok();
  }
  return Status::Error(message.str());
}

StatusOr<double> DomeThicknessFromRadii(double inner_radius,
                                        double outer_radius, double thickness) {
  std::ostringstream message;
  if (!std::isfinite(inner_radius) || !std::isfinite(outer_radius) ||
      !(outer_radius > inner_radius)) {
    message << "dome outer radius " << outer_radius
            << " m is not beyond the inner radius " << inner_radius << " m";
    return Status::Error(message.str());
  }
  // To the nanometre: radii are known to micrometres at best, and the
  // difference of two decimal radii (0.0473 - 0.04355) carries rounding
  // (0.0037500000000000033) that a camchain would print.
  const double from_radii =
      std::round((outer_radius - inner_radius) * 1e9) / 1e9;
  // Radii and thickness written to 1 micrometre agree to that.
  constexpr double kAgreement = 1e-6;
  if (thickness >= 0.0 && std::abs(from_radii - thickness) > kAgreement) {
    message << "dome radii " << inner_radius << " m and " << outer_radius
            << " m give a thickness of " << from_radii << " m, not the "
            << thickness << " m given";
    return Status::Error(message.str());
  }
  return from_radii;
}

}  // namespace rcm
