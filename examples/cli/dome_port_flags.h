// The dome-port flags, shared by the subcommands that take a dome
// (dome_port_geometry.h) on the command line for a camchain without a
// `port` block: rcm calibrate --underwater --port dome, rcm simulate
// --port dome, rcm dome-check, rcm undistort / export.
//
//   --port flat|dome            the housing's port (default flat: the
//                               camchain's port blocks, or thin ports)
//   --dome-inner-radius M       r1, meters
//   --dome-thickness M          tg, meters (or --dome-outer-radius M; both
//   --dome-outer-radius M       when they agree to 1 micrometre)
//   --glass-index N             the dome's glass (default 1.49, acrylic;
//                               glass_index_flag.h, also list
//                               kGlassIndexFlagSource)
//   --dome-decentering X,Y,Z    the dome's centre in the camera frame,
//                               meters (default 0,0,0: centred); the
//                               start of a calibration, the truth of a
//                               simulation, the value of a check
#ifndef RCM_EXAMPLES_CLI_DOME_PORT_FLAGS_H_
#define RCM_EXAMPLES_CLI_DOME_PORT_FLAGS_H_

#include <gflags/gflags.h>

#include <optional>
#include <string>
#include <vector>

#include "glass_index_flag.h"
#include "rcm/camera/dome_port_geometry.h"
#include "rcm/io/camchain.h"
#include "rcm/util/status.h"

DECLARE_string(port);
DECLARE_double(dome_inner_radius);
DECLARE_double(dome_thickness);
DECLARE_double(dome_outer_radius);
DECLARE_string(dome_decentering);

namespace rcm::cli {

// __FILE__ of dome_port_flags.cc, for Subcommand::flag_sources.
extern const char kDomePortFlagsSource[];

// The first of `names` (gflags names, e.g. "dome_thickness") given on the
// command line, as it is typed ("--dome-thickness"); empty when none.
std::string FirstGivenFlag(const std::vector<const char*>& names);

// True when --port dome was given.
bool DomePortRequested();

// The dome of the flags; nullopt without --port dome. Errors (one line):
// --port other than flat or dome, dome flags without --port dome, a
// missing inner radius or thickness, radii that contradict the thickness,
// a decentering that is not three numbers, a dome that fails
// DomePort::Check ("--port dome: dome decentering (0, 0, 0.05) m puts the
// camera centre outside the inner sphere ...").
StatusOr<std::optional<DomePort>> DomePortFromFlags();

// Each camera's dome: the flags' (when given, for every camera) or the
// camchain's port blocks of type dome. Errors: those of DomePortFromFlags,
// a camchain camera with a flat port block together with --port dome
// ("cam0 has a flat port block; --port dome describes a dome"), and no
// dome at all ("no dome: give --port dome --dome-inner-radius M
// --dome-thickness M, or a camchain with port blocks of type dome"), or
// only some cameras with one.
StatusOr<std::vector<DomePort>> DomesOfCameras(const Camchain& camchain,
                                               int num_cameras);

}  // namespace rcm::cli

#endif  // RCM_EXAMPLES_CLI_DOME_PORT_FLAGS_H_
