#include "rig_flags.h"

DEFINE_string(calib, "",
              "the in-air calibration: a Kalibr camchain YAML, or two ROS "
              "camera_info YAML files as LEFT.yaml,RIGHT.yaml");
DEFINE_string(left_camera, "cam0", "camchain camera that is the left one");
DEFINE_string(right_camera, "cam1", "camchain camera that is the right one");

namespace rcm::cli {

extern const char kRigFlagsSource[] = __FILE__;

}  // namespace rcm::cli
