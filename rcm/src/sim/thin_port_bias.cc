#include "rcm/sim/thin_port_bias.h"

#include <cmath>
#include <sstream>

#include "rcm/estimation/batch_refinement.h"
#include "rcm/sim/stereo_sampler.h"

namespace rcm {

Status ThinPortBiasOptions::Check() const {
  if (num_matches < 20) {
    std::ostringstream message;
    message << "num_matches = " << num_matches << " must be >= 20";
    return Status::Error(message.str());
  }
  StereoSamplerOptions sampler;
  sampler.n = n;
  sampler.min_depth = min_depth;
  sampler.max_depth = max_depth;
  return sampler.Check();
}

StatusOr<ThinPortBias> MeasureThinPortBias(const StereoRig& rig,
                                           const FlatPort& port,
                                           const ThinPortBiasOptions& options) {
  RCM_RETURN_IF_ERROR(options.Check());
  StereoSamplerOptions sampler;
  sampler.n = options.n;
  sampler.min_depth = options.min_depth;
  sampler.max_depth = options.max_depth;
  sampler.per_frame = options.num_matches;
  sampler.seed = options.seed;
  StatusOr<std::vector<StereoCorrespondence>> matches =
      SampleFlatPortCorrespondences(rig, port, port, sampler);
  if (!matches.ok()) return matches.status();
  // The thin-port estimate: the rig without any port blocks it was read
  // with.
  StatusOr<StereoRig> thin_rig =
      StereoRig::Create(rig.left(), rig.right(), rig.right_from_left());
  if (!thin_rig.ok()) return thin_rig.status();
  StatusOr<RefinementSummary> summary =
      RefineRefractiveIndex(*thin_rig, matches.value(), RefinementOptions());
  if (!summary.ok()) return summary.status();
  ThinPortBias bias;
  bias.n_thin = summary.value().n;
  bias.bias = bias.n_thin - options.n;
  bias.inliers = static_cast<int64_t>(summary.value().inliers.size());
  // sigma_px is sqrt(cost-based RSS / (N - 1)): the RMS misfit.
  bias.rms_residual = summary.value().sigma_px;
  // The rig told about its ports: RefineRefractiveIndex takes the
  // thick-port model (the thin model again for a thin port).
  StatusOr<StereoRig> with_ports = thin_rig->WithPorts(port, port);
  if (!with_ports.ok()) return with_ports.status();
  StatusOr<RefinementSummary> thick =
      RefineRefractiveIndex(*with_ports, matches.value(), RefinementOptions());
  if (!thick.ok()) return thick.status();
  bias.n_thick = thick->n;
  bias.thick_bias = bias.n_thick - options.n;
  return bias;
}

}  // namespace rcm
