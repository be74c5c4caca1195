#include "depth_range_flag.h"

DEFINE_string(depth_range, "",
              "MIN,MAX in meters: rcm simulate samples the matches at depths "
              "uniform in [MIN, MAX] on random left pixels' rays instead of "
              "on the tank's surfaces (needs --noimages); rcm dome-check "
              "evaluates depths across it (default there 0.3,10)");

namespace rcm::cli {

extern const char kDepthRangeFlagSource[] = __FILE__;

}  // namespace rcm::cli
