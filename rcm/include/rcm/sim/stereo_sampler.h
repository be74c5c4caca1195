// Correspondences sampled in two ways: from the refractive model itself
// (the model's own forward map, exact up to floating point, for tests of
// the estimators) and from the exact flat port of the simulator (physics
// that shares no code with the model: thick glass, air gaps, tilt), for
// tests of the model itself.
//
// Sampling: a left pixel uniform over the image, a depth Z (left camera
// frame) uniform in [min_depth, max_depth]; the scene point is the left
// pixel's ray in the medium at that depth, and both pixels are obtained by
// projecting it (RefractiveCamera::ImageFromPointInWater, or
// FlatPortCamera::ImageFromPoint). Points whose right pixel falls outside
// the right image are redrawn. With an exposure delay (exposure_delay.h),
// the right camera sees each frame's points moved by that frame's motion;
// with a non-rigid layer (non_rigid_layer.h), the right pixels of the
// matches in its band of the image are moved by its offset (before the
// right image's bounds are checked).
#ifndef RCM_SIM_STEREO_SAMPLER_H_
#define RCM_SIM_STEREO_SAMPLER_H_

#include <cstdint>
#include <vector>

#include "rcm/camera/flat_port.h"
#include "rcm/geometry/stereo_correspondence.h"
#include "rcm/sim/exposure_delay.h"
#include "rcm/sim/non_rigid_layer.h"
#include "rcm/stereo/stereo_rig.h"
#include "rcm/util/status.h"

namespace rcm {

struct StereoSamplerOptions {
  double n = 1.333;          // refractive index of the medium, in [1, 2]
  double min_depth = 0.6;    // meters, Z in the left camera frame, > 0
  double max_depth = 6.0;    // meters, >= min_depth
  int num_frames = 1;        // >= 1; frames are numbered 0, 1, ...
  int per_frame = 100;       // correspondences per frame, >= 1
  double frame_rate = 20.0;  // Hz; timestamps t = frame / frame_rate, > 0
  uint64_t seed = 1;         // the sample depends only on the seed
  // Default none: the cameras are triggered together. Its motions are
  // keyed by (seed, frame) apart from the points' draws, so that a delay
  // moves the right pixels of the same points.
  ExposureDelay exposure_delay;
  // Default none: every match is on the rigid scene. Its offsets are keyed
  // by (seed, frame) as the delay's are.
  NonRigidLayer non_rigid_layer;

  Status Check() const;
};

// Exact correspondences, per_frame for each frame, with timestamps. Fails
// when options are invalid or the rig's images barely overlap (fewer than
// one in 100 draws lands in both images).
StatusOr<std::vector<StereoCorrespondence>> SampleStereoCorrespondences(
    const StereoRig& rig, const StereoSamplerOptions& options);

// The same sampling through exact flat ports (rcm/camera/flat_port_camera.h):
// the left pixel's ray in the medium starts on the outer glass face and the
// point is where it reaches depth Z. The medium of frame f is
// n_of_frame[f] when given (num_frames entries, each in [1, 2]; media that
// switch between frames), options.n otherwise. Fails as the model sampler
// does, or when a port is invalid.
StatusOr<std::vector<StereoCorrespondence>> SampleFlatPortCorrespondences(
    const StereoRig& rig, const FlatPort& left_port, const FlatPort& right_port,
    const StereoSamplerOptions& options,
    const std::vector<double>& n_of_frame = {});

// Adds independent zero-mean Gaussian noise of standard deviation sigma_px
// to all four pixel coordinates.
void AddPixelNoise(double sigma_px, uint64_t seed,
                   std::vector<StereoCorrespondence>* correspondences);

// Makes a random `fraction` (in [0, 1]) of the correspondences gross
// outliers: their right pixel is replaced by one drawn uniformly over the
// right image. Returns the indices of the replaced ones, increasing.
std::vector<int64_t> AddOutliers(
    const StereoRig& rig, double fraction, uint64_t seed,
    std::vector<StereoCorrespondence>* correspondences);

}  // namespace rcm

#endif  // RCM_SIM_STEREO_SAMPLER_H_
