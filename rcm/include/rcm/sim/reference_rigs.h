// Reference calibrations shipped with the library, for examples, demos,
// tests and benchmarks.
#ifndef RCM_SIM_REFERENCE_RIGS_H_
#define RCM_SIM_REFERENCE_RIGS_H_

#include "rcm/camera/camera.h"
#include "rcm/geometry/stereo_rig.h"

namespace rcm {

// The front stereo pair of the paper's dataset (Alphasense Core, 720x540,
// equidistant, calibrated in air with Kalibr; DESIGN.md Sec. 5). Its image
// corners see rays 82.7 degrees off axis.
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

}  // namespace rcm

#endif  // RCM_SIM_REFERENCE_RIGS_H_
