// The --medium flag, shared by the subcommands that estimate n: rcm
// estimate (the estimate is checked against the medium, and with the
// refinement cam1's drift since the calibration is estimated assuming it)
// and rcm calibrate --underwater (checked against it).
#ifndef RCM_EXAMPLES_CLI_MEDIUM_FLAG_H_
#define RCM_EXAMPLES_CLI_MEDIUM_FLAG_H_

#include <gflags/gflags.h>

#include <nlohmann/json.hpp>
#include <optional>

#include "rcm/estimation/medium_prior.h"
#include "rcm/util/status.h"

DECLARE_string(medium);

namespace rcm::cli {

// __FILE__ of medium_flag.cc, for Subcommand::flag_sources.
extern const char kMediumFlagSource[];

// The parsed --medium (nullopt when not given), or "--medium: ..." .
StatusOr<std::optional<MediumPrior>> MediumFromFlag();

// The JSON's "medium": the medium and an estimate's check against it.
nlohmann::json MediumJson(const MediumPrior& medium, const MediumCheck& check);

}  // namespace rcm::cli

#endif  // RCM_EXAMPLES_CLI_MEDIUM_FLAG_H_
