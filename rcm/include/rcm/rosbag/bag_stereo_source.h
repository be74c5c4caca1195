// Stereo pairs from a ROS1 bag (rosbag record of two camera topics), the
// way underwater rigs are usually logged. The bag is indexed when it is
// opened: every message of the two topics is read once for its header
// stamp, and left and right messages are paired by those stamps, since
// the two drivers publish independently and a bag may drop a message of
// either camera. Pixels are decoded only when a pair is read. One camera's
// topic alone (BagStereoOptions::left_only) gives each of its messages as
// a "pair" without a right image.
//
// Reads sensor_msgs/Image (encodings mono8, 8UC1, bgr8, 8UC3, rgb8, bgra8,
// rgba8; colour becomes BGR) and sensor_msgs/CompressedImage (any format
// OpenCV decodes that is 8-bit with 1, 3 or 4 channels, e.g. png, jpeg).
// Part of rcm::rosbag, built only when ROS1 bag support is found
// (RCM_HAVE_ROSBAG); this header needs no ROS headers.
#ifndef RCM_ROSBAG_BAG_STEREO_SOURCE_H_
#define RCM_ROSBAG_BAG_STEREO_SOURCE_H_

#include <memory>
#include <string>

#include "rcm/io/stereo_image_source.h"
#include "rcm/util/status.h"

namespace rcm {

struct BagStereoOptions {
  // The two image topics, e.g. "/cam0/image_raw" and "/cam1/image_raw".
  std::string left_topic;
  std::string right_topic;
  // One camera only (rcm calibrate --bag B --left-topic T alone): left_topic
  // alone, right_topic empty; each message of it a "pair" with an empty
  // right image and an empty right name, as StereoFolderOptions::left_only
  // gives a folder's images. stamp_tolerance_s is not used.
  bool left_only = false;
  // Largest difference of header stamps, in seconds, for a left and a
  // right message to form a pair. 5 ms: hardware-triggered cameras stamp
  // the two images of a pair within about 1 ms, and 5 ms is at most half
  // the frame period of cameras up to 100 Hz, so a message is not paired
  // with the neighbouring frame of the other camera. Free-running cameras
  // may need more. >= 0.
  double stamp_tolerance_s = 0.005;
  // Time range and stride, applied to the pairs (times count from the first
  // pair's left stamp).
  FrameSelection selection;

  // Errors: an empty or repeated topic, a right topic with left_only, a
  // negative or non-finite tolerance, selection.Check().
  Status Check() const;
};

// Opens the bag at `path` and pairs the messages of the two topics. Each
// left message is paired with the right message nearest in stamp, if
// within the tolerance, and each message is used at most once; the others
// are counted as unpaired (Describe() reports them). A pair's `frame` is
// its index among all pairs, its `timestamp` the left header stamp in
// seconds, its names "TOPIC @ STAMP" (stamp in seconds, 6 decimals).
// With options.left_only, every message of the left topic is a pair, in
// stamp order (equal stamps in the bag's order), and none is unpaired.
// Errors, each one line starting with `path`: options.Check(); a missing
// file; a file that is not a readable ROS1 bag (truncated, unindexed, not
// a bag); a topic that is not in the bag (the message lists the image
// topics the bag has) or whose type is not an image; no pair within the
// tolerance; a selection that keeps no pair.
StatusOr<std::unique_ptr<StereoImageSource>> OpenBagStereoSource(
    const std::string& path, const BagStereoOptions& options);

}  // namespace rcm

#endif  // RCM_ROSBAG_BAG_STEREO_SOURCE_H_
