// Flags that name a stereo image sequence: two folders (or a list of
// pairs), or a ROS1 bag with two image topics; with a time range and a
// stride. Shared by the subcommands that read images (estimate; later
// calibrate and undistort).
#ifndef RCM_EXAMPLES_CLI_IMAGE_INPUT_FLAGS_H_
#define RCM_EXAMPLES_CLI_IMAGE_INPUT_FLAGS_H_

#include <gflags/gflags.h>

#include <memory>

#include "rcm/io/stereo_image_source.h"
#include "rcm/util/status.h"

DECLARE_string(left);
DECLARE_string(right);
DECLARE_string(pairs);
DECLARE_string(bag);
DECLARE_string(left_topic);
DECLARE_string(right_topic);
DECLARE_double(stamp_tolerance);
DECLARE_double(from);
DECLARE_double(to);
DECLARE_int32(stride);

namespace rcm::cli {

// __FILE__ of image_input_flags.cc, for Subcommand::flag_sources.
extern const char kImageInputFlagsSource[];

// True when any of --left, --right, --pairs, --bag is set.
bool ImageInputGiven();

// True when the flags name one camera's images: --left without --right
// and --pairs, or --bag with --left-topic and without --right-topic.
bool OneCameraImageInputGiven();

// Opens the sequence the flags name. Errors: no input or two kinds of
// input, a missing topic flag, a bag given to a build without bag
// support, and the sources' own errors (stereo_image_folders.h,
// bag_stereo_source.h).
// With `allow_left_only`, --left alone or --bag with --left-topic alone
// opens one camera's images (StereoFolderOptions::left_only,
// BagStereoOptions::left_only: empty right images); without it, those are
// errors.
StatusOr<std::unique_ptr<StereoImageSource>> OpenImageInputFromFlags(
    bool allow_left_only = false);

}  // namespace rcm::cli

#endif  // RCM_EXAMPLES_CLI_IMAGE_INPUT_FLAGS_H_
