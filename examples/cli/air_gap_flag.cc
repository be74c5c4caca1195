#include "air_gap_flag.h"

DEFINE_bool(estimate_air_gap, false,
            "also estimate the ports' air gap with n (the thick-port "
            "model), from the camchain's port blocks or 0, reported with "
            "its sigma and its correlation with n; rcm estimate: one offset "
            "for both cameras (--estimator refine); rcm calibrate "
            "--underwater: each camera's gap");

namespace rcm::cli {

extern const char kAirGapFlagSource[] = __FILE__;

}  // namespace rcm::cli
