#include "image_input_flags.h"

#include <cmath>

#include "rcm/io/stereo_image_folders.h"
#ifdef RCM_HAVE_ROSBAG
#include "rcm/rosbag/bag_stereo_source.h"
#endif

DEFINE_string(left, "", "folder of the left camera's images");
DEFINE_string(right, "", "folder of the right camera's images");
DEFINE_string(pairs, "",
              "instead of --left/--right: a text file with one pair per "
              "line, LEFT RIGHT [t], paths relative to the file");
DEFINE_string(bag, "", "ROS1 bag with the two image topics");
DEFINE_string(left_topic, "",
              "bag: topic of the left images (sensor_msgs/Image mono8, "
              "bgr8, rgb8, or sensor_msgs/CompressedImage); rcm calibrate: "
              "alone, without --right-topic, one camera");
DEFINE_string(right_topic, "", "bag: topic of the right images");
DEFINE_double(stamp_tolerance, 0.005,
              "bag: largest difference of header stamps, seconds, of a "
              "left and a right image that form a pair");
DEFINE_double(from, NAN,
              "use the pairs from this many seconds after the first one "
              "(needs timestamps: bag stamps, or file names that are "
              "stamps)");
DEFINE_double(to, NAN,
              "use the pairs up to this many seconds after the "
              "first one");
DEFINE_int32(stride, 1, "use every stride-th pair");

namespace rcm::cli {

extern const char kImageInputFlagsSource[] = __FILE__;

namespace {

FrameSelection SelectionFromFlags() {
  FrameSelection selection;
  if (!std::isnan(FLAGS_from)) selection.from_s = FLAGS_from;
  if (!std::isnan(FLAGS_to)) selection.to_s = FLAGS_to;
  selection.stride = FLAGS_stride;
  return selection;
}

}  // namespace

bool OneCameraImageInputGiven() {
  if (!FLAGS_bag.empty()) {
    return !FLAGS_left_topic.empty() && FLAGS_right_topic.empty();
  }
  return !FLAGS_left.empty() && FLAGS_right.empty() && FLAGS_pairs.empty();
}

bool ImageInputGiven() {
  return !FLAGS_left.empty() || !FLAGS_right.empty() || !FLAGS_pairs.empty() ||
         !FLAGS_bag.empty();
}

StatusOr<std::unique_ptr<StereoImageSource>> OpenImageInputFromFlags(
    bool allow_left_only) {
  const FrameSelection selection = SelectionFromFlags();
  RCM_RETURN_IF_ERROR(selection.Check().WithContext("--from/--to/--stride"));
  const bool folders =
      !FLAGS_left.empty() || !FLAGS_right.empty() || !FLAGS_pairs.empty();
  if (!FLAGS_bag.empty()) {
    if (folders) {
      return Status::Error(
          "give either --bag or image folders (--left/--right, --pairs), "
          "not both");
    }
    const bool left_only = allow_left_only && OneCameraImageInputGiven();
    if (FLAGS_left_topic.empty() && FLAGS_right_topic.empty()) {
      return Status::Error(allow_left_only
                               ? "--bag needs --left-topic (and "
                                 "--right-topic for a stereo pair)"
                               : "--bag needs --left-topic and --right-topic");
    }
    if (FLAGS_left_topic.empty()) {
      return Status::Error("--right-topic needs --left-topic");
    }
    if (FLAGS_right_topic.empty() && !left_only) {
      return Status::Error(
          "--bag needs --right-topic too: this command reads stereo pairs "
          "(only rcm calibrate takes one camera's --left-topic alone)");
    }
#ifdef RCM_HAVE_ROSBAG
    BagStereoOptions options;
    options.left_only = left_only;
    options.left_topic = FLAGS_left_topic;
    options.right_topic = FLAGS_right_topic;
    options.stamp_tolerance_s = FLAGS_stamp_tolerance;
    options.selection = selection;
    return OpenBagStereoSource(FLAGS_bag, options);
#else
    return Status::Error(
        "this rcm was built without ROS bag support (Debian's librosbag-dev "
        "was missing): run scripts/setup.sh and rebuild");
#endif
  }
  if (!folders) {
    return Status::Error(
        "no images: give --left DIR --right DIR, --pairs LIST or --bag");
  }
  if (!FLAGS_pairs.empty() && (!FLAGS_left.empty() || !FLAGS_right.empty())) {
    return Status::Error("give either --pairs or --left/--right, not both");
  }
  StereoFolderOptions options;
  options.left_only = allow_left_only && FLAGS_pairs.empty() &&
                      !FLAGS_left.empty() && FLAGS_right.empty();
  if (!options.left_only && FLAGS_pairs.empty() &&
      (FLAGS_left.empty() || FLAGS_right.empty())) {
    return Status::Error("--left and --right go together: give both folders");
  }
  options.left_dir = FLAGS_left;
  options.right_dir = FLAGS_right;
  options.pair_list = FLAGS_pairs;
  options.selection = selection;
  return OpenStereoImageFolders(options);
}

}  // namespace rcm::cli
