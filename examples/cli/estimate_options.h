// rcm estimate's flags (estimate_options.cc) as the library's options:
// the estimator and its refinement, the front end, the rig file's drift
// prior and the medium.
#ifndef RCM_EXAMPLES_CLI_ESTIMATE_OPTIONS_H_
#define RCM_EXAMPLES_CLI_ESTIMATE_OPTIONS_H_

#include <gflags/gflags.h>

#include <optional>

#include "rcm/estimation/estimate_refractive_index.h"
#include "rcm/estimation/medium_prior.h"
#include "rcm/frontend/stereo_front_end.h"
#include "rcm/io/stereo_rig_file.h"
#include "rcm/util/status.h"

// The flags the run reads beyond the options.
DECLARE_string(matches);
DECLARE_string(features);
DECLARE_bool(clahe);
DECLARE_int32(picture_frame);
DECLARE_string(estimator);
DECLARE_string(per_frame);

namespace rcm::cli {

extern const char kEstimateFlagsSource[];

struct EstimateCliOptions {
  bool images = false;  // folders, a pair list or a bag; else --matches
  EstimationOptions estimation;
  std::optional<StereoFrontEndOptions> front_end;  // with images
  RigFileOptions rig;                              // --drift-prior
  std::optional<MediumPrior> medium;               // --medium
};

// Errors: a flag's value (one line naming the flag), the input given twice
// or not at all.
StatusOr<EstimateCliOptions> EstimateOptionsFromFlags();

}  // namespace rcm::cli

#endif  // RCM_EXAMPLES_CLI_ESTIMATE_OPTIONS_H_
