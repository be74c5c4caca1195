// How wrong the paper's thin-port model is for a real housing: the bias of
// the thin-port estimate of n (batch_refinement.h, default options) on
// exact, noise-free correspondences traced through a thick flat port
// (flat_port.h), next to the estimate that is given the port (the
// thick-port model). Noise-free, so the number is the model error alone; it is
// what the approximation table of docs/thin_port_bias.md reports, and what a
// user can compute for their own rig and housing.
#ifndef RCM_SIM_THIN_PORT_BIAS_H_
#define RCM_SIM_THIN_PORT_BIAS_H_

#include <cstdint>

#include "rcm/camera/flat_port.h"
#include "rcm/stereo/stereo_rig.h"
#include "rcm/util/status.h"

namespace rcm {

struct ThinPortBiasOptions {
  double n = 1.333;        // true refractive index of the medium, [1, 2]
  double min_depth = 0.6;  // meters, Z of the scene points in the left
  double max_depth = 6.0;  // camera frame (uniform), as in docs/design.md,
                           // "The estimator of record"
  int num_matches = 2000;  // exact correspondences, >= 20
  uint64_t seed = 1;       // the sample depends only on the seed

  Status Check() const;
};

struct ThinPortBias {
  double n_thin = 0.0;  // the thin-port estimate
  double bias = 0.0;    // n_thin - n
  // The same data estimated with the true port given (the thick-port
  // model, thick_port_refinement.h): n_thick - n, which is 0 to the
  // solver's tolerance.
  double n_thick = 0.0;
  double thick_bias = 0.0;
  int64_t inliers = 0;      // matches the robust stage kept (of num_matches)
  double rms_residual = 0;  // pixels: how visibly the thin model misfits
};

// Both cameras behind the same `port`. Fails on invalid options or port, or
// when the refinement fails (e.g. a port so thick that nothing fits).
StatusOr<ThinPortBias> MeasureThinPortBias(const StereoRig& rig,
                                           const FlatPort& port,
                                           const ThinPortBiasOptions& options);

}  // namespace rcm

#endif  // RCM_SIM_THIN_PORT_BIAS_H_
