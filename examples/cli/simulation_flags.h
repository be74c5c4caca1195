// Flags that describe a simulated sequence, shared by rcm simulate and
// rcm demo, and the simulator options they make.
#ifndef RCM_EXAMPLES_CLI_SIMULATION_FLAGS_H_
#define RCM_EXAMPLES_CLI_SIMULATION_FLAGS_H_

#include <gflags/gflags.h>

#include <nlohmann/json.hpp>
#include <string>

#include "glass_index_flag.h"
#include "rcm/sim/sequence_simulator.h"
#include "rcm/stereo/stereo_rig.h"
#include "rcm/util/status.h"

DECLARE_string(media);
DECLARE_int32(frames);
DECLARE_double(frame_rate);
DECLARE_string(rig);
DECLARE_double(air_gap);
DECLARE_double(glass_thickness);
DECLARE_double(port_tilt);
DECLARE_double(image_noise);
DECLARE_int32(supersampling);
DECLARE_uint64(seed);
DECLARE_string(tank);
DECLARE_int32(loops);
DECLARE_string(extrinsic_drift);

namespace rcm::cli {

// __FILE__ of simulation_flags.cc, for Subcommand::flag_sources.
extern const char kSimulationFlagsSource[];

struct Simulation {
  StereoRig rig;
  std::string rig_name;  // "alphasense", "narrow", ..., or the --calib path
  SequenceOptions options;
};

// The rig (--rig, or the cameras `left` and `right` of the file `calib`
// when it is not empty) and the sequence options of the flags. Fails with
// one line on a bad value.
StatusOr<Simulation> SimulationFromFlags(const std::string& calib,
                                         const std::string& left = "cam0",
                                         const std::string& right = "cam1");

// --extrinsic-drift into options->cam1_drift (the rig of the images moved
// from the calibration). Errors (wrong flags): not 3 or 6 numbers, not
// finite, beyond ExtrinsicDrift::Check's limits.
Status ExtrinsicDriftFromFlag(SequenceOptions* options);
// --lens-change into options->lens_change; one line on a bad value.
Status LensChangeFromFlag(SequenceOptions* options);

// The flags' values, for the JSON a run writes next to its outputs.
nlohmann::json SimulationFlagsJson(const Simulation& simulation);

}  // namespace rcm::cli

#endif  // RCM_EXAMPLES_CLI_SIMULATION_FLAGS_H_
