#include "camera_flag.h"

DEFINE_string(camera, "cam0",
              "the camera to read, in each file that is a camchain (a "
              "camera_info has one)");

namespace rcm::cli {

extern const char kCameraFlagSource[] = __FILE__;

}  // namespace rcm::cli
