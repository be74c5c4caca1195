// Cameras and rigs shared by the tests: the paper's real calibration, a
// radtan camera, a pinhole, a fisheye reaching 89.5 degrees, stereo rigs
// built from them, and a dome port.
#ifndef RCM_TESTS_SUPPORT_TEST_RIGS_H_
#define RCM_TESTS_SUPPORT_TEST_RIGS_H_

#include <Eigen/Core>
#include <vector>

#include "rcm/camera/camera.h"
#include "rcm/camera/dome_port_geometry.h"
#include "rcm/estimation/prepared_correspondence.h"
#include "rcm/geometry/stereo_correspondence.h"
#include "rcm/stereo/stereo_rig.h"

namespace rcm::test {

// The paper's Alphasense front pair, 720x540, equidistant (docs/design.md,
// "The reference rig").
Camera AlphasenseCam0();
Camera AlphasenseCam1();
// EuRoC MAV cam0, 752x480, radtan.
Camera EurocRadtanCamera();
// 640x480, f = 400, no distortion.
Camera PinholeCamera();
// EurocRadtanCamera twice, cam1 turned by 0.5 degrees about
// (0.2, 1, 0.1) and 0.11 m to the right: a rig the calibrations solve.
StereoRig EurocRadtanTwinRig();
// 1024x1024 equidistant (Alphasense coefficients) whose image corners see
// rays 89.5 degrees off axis.
Camera WideEquidistantCamera();
// 752x480 rational (OpenCV's 8 coefficients, a moderately wide lens with
// tangential terms), f ~ 460 px.
Camera RationalCamera();
// 640x480 double sphere, f = 300 px, xi = -0.18, alpha = 0.59 (TUM-VI's
// fisheye coefficients as basalt calibrates them; the corners see ~75
// degrees off axis).
Camera DoubleSphereCamera();
// 640x480 EUCM, f = 320 px, alpha = 0.63, beta = 1.04 (TUM-VI-like).
Camera EucmCamera();
// Every camera above, for tests that sweep them.
std::vector<Camera> AllTestCameras();

// The dome of a deep-rated 4-inch housing (issue 33): acrylic (1.495),
// 43.55 mm inside, 3.75 mm thick (47.30 mm outside), its centre at
// `decentering` in the camera frame (meters).
DomePort AcrylicDome(const Eigen::Vector3d& decentering);

// The ideal rectified pair of the paper: right_from_left = (I, (-b, 0, 0)).
StereoRig IdealRig(const Camera& left, const Camera& right,
                   double baseline = 0.11);
// The Alphasense intrinsics on the ideal rectified extrinsics.
StereoRig AlphasenseIdealRig();
// The Alphasense intrinsics, 0.5 degrees of rotation about a skew axis and
// a baseline slightly off the x axis: a real, unrectified rig.
StereoRig AlphasenseRealisticRig();

// A hand-built narrow-field housing (the rig of the drifting-rig issue):
// two 640x480 radtan cameras, f ~ 500 px, 65 mm baseline, 2.5 degrees of
// toe-in (cam1 turned about y, the axes converging ~1.5 m ahead).
StereoRig NarrowRadtanRig();

// `count` exact correspondences of `rig` in a medium of index n, one frame,
// depths 0.6-6 m (rcm/sim/stereo_sampler.h).
std::vector<StereoCorrespondence> ExactMatches(const StereoRig& rig, double n,
                                               int count, uint64_t seed = 1);
// `frames` frames 0 .. frames-1 of `per_frame` exact correspondences each,
// the same way (a sequence for the multi-frame estimators).
std::vector<StereoCorrespondence> ExactSequence(const StereoRig& rig, double n,
                                                int frames, int per_frame,
                                                uint64_t seed);
// ExactMatches with Gaussian pixel noise of sigma_px (seed + 100), prepared
// for the estimators (prepared_correspondence.h; the unusable dropped).
std::vector<PreparedCorrespondence> NoisyPreparedMatches(const StereoRig& rig,
                                                         double n, int count,
                                                         double sigma_px,
                                                         uint64_t seed);

// `count` exact matches (n = 1.333, depths 0.6-6 m) of AlphasenseIdealRig()
// whose left pixels lie on one image axis: normalized y = 0 (`on_row`,
// where the loci do not depend on n) or x = 0 (where they barely do).
// Matches whose right pixel leaves the image are left out.
std::vector<StereoCorrespondence> ExactMatchesOnAxis(bool on_row, int count);

// Pixels on a grid covering the whole image with `step` spacing, plus the
// four borders (-0.5 and size - 0.5) and the exact corners.
std::vector<Eigen::Vector2d> ImageGrid(const Camera& camera, double step);

}  // namespace rcm::test

#endif  // RCM_TESTS_SUPPORT_TEST_RIGS_H_
