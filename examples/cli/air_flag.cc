#include "air_flag.h"

DEFINE_string(air, "",
              "the in-air calibration: a Kalibr camchain (rcm calibrate "
              "--underwater: with port blocks when the housing has an air "
              "gap or glass), or for rcm compare a ROS camera_info too");

namespace rcm::cli {

extern const char kAirFlagSource[] = __FILE__;

}  // namespace rcm::cli
