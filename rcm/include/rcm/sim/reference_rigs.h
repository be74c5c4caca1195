// Reference calibrations shipped with the library, for examples, demos,
// tests and benchmarks.
#ifndef RCM_SIM_REFERENCE_RIGS_H_
#define RCM_SIM_REFERENCE_RIGS_H_

#include <cmath>

#include "rcm/camera/camera.h"
#include "rcm/stereo/stereo_rig.h"

namespace rcm {

// The front stereo pair of the paper's dataset (Alphasense Core, 720x540,
// equidistant, calibrated in air with Kalibr; docs/design.md,
// "The reference rig"). Its image corners see rays 82.7 degrees off axis.
Camera AlphasenseFrontCam0();
Camera AlphasenseFrontCam1();

// EuRoC MAV cam0 (752x480, radtan): a strongly distorted radtan lens.
Camera EurocCam0();

// Those intrinsics on the ideal rectified extrinsics of the paper's
// derivation: right_from_left = (I, (-0.11 m, 0, 0)).
StereoRig AlphasenseFrontRectifiedRig();

// Those intrinsics on extrinsics as a real rig has them: cam1 rotated 0.5
// degrees about a skew axis and the baseline slightly off the x axis
// (0.11 m, 1.5 mm up, 2 mm back). Not rectified.
StereoRig AlphasenseFrontUnrectifiedRig();

// A narrow-field pair in a hand-built housing, like the rig of the sea
// dives whose extrinsics drifted (docs/design.md, "Rigs that drift"): two
// 640x480 pinhole cameras with mild radtan distortion (k1 ~ -0.12,
// k2 ~ 0.05, p ~ 1e-4) and slightly different intrinsics, f ~ 500 px (a
// field of view of about 67 by 52 degrees in air, 49 by 38 in water),
// 65 mm apart along x and toed in:
//
//   cam1_from_cam0 = (Ry(+2.5 deg), -Ry(+2.5 deg) (0.065, 0, 0)),
//
// i.e. cam1's center is at (0.065, 0, 0) in cam0 and its optical axis,
// in cam0, is Ry(2.5 deg)^T z = (-sin 2.5 deg, 0, cos 2.5 deg): the two
// axes meet b / tan(2.5 deg) = 1.49 m ahead of cam0, where a point on
// cam0's axis is imaged at cam1's principal point (in air and in water:
// the ray along the port normal is not bent).
Camera NarrowFieldCam0();
Camera NarrowFieldCam1();
StereoRig NarrowFieldRig();

// The toe-in of NarrowFieldRig, radians, and its baseline, meters.
inline constexpr double kNarrowFieldToeIn = 2.5 * M_PI / 180.0;
inline constexpr double kNarrowFieldBaseline = 0.065;

}  // namespace rcm

#endif  // RCM_SIM_REFERENCE_RIGS_H_
