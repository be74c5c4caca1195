// The stereo rig of a command line: one argument that names either rig
// file format rcm reads.
//
//   rig.yaml                 a Kalibr camchain (camchain.h); `left` and
//                            `right` name two of its cameras ("cam0",
//                            "cam1", ...), cam0/cam1 by default;
//   left.yaml,right.yaml     the ROS camera_info files of the left and the
//                            right camera (camera_info.h), in that order;
//                            `left` and `right` must keep their defaults.
//
// The format of each file is recognised by its top-level keys: `cam0` for a
// camchain, `camera_matrix` for a camera_info. A path that contains a comma
// is always taken as a pair.
#ifndef RCM_IO_STEREO_RIG_FILE_H_
#define RCM_IO_STEREO_RIG_FILE_H_

#include <string>

#include "rcm/geometry/stereo_rig.h"
#include "rcm/util/status.h"

namespace rcm {

StatusOr<StereoRig> ReadStereoRig(const std::string& spec,
                                  const std::string& left = "cam0",
                                  const std::string& right = "cam1");

}  // namespace rcm

#endif  // RCM_IO_STEREO_RIG_FILE_H_
