// Rewrites the image topics of a ROS1 bag: every message of the input bag
// is copied to the output in bag order, unchanged, except the messages of
// the chosen image topics, whose images pass through a caller's transform
// (e.g. refraction correction, virtual_pinhole_remap.h), and the
// camera_info topics of those cameras, which are replaced by the
// camera_info of the transformed images. A VIO then reads the new bag
// exactly as it read the old one (IMU and every other topic untouched).
//
// For each rewritten image message the output holds, at the same bag time:
//   - the transformed image on the same topic, with the same message type
//     and header (seq, stamp, frame_id): a sensor_msgs/Image keeps its
//     encoding family (mono8 stays mono8; colour is written bgr8), a
//     sensor_msgs/CompressedImage keeps its format (png stays png, jpeg
//     stays jpeg, quality 95);
//   - when the topic has a camera_info_topic, a sensor_msgs/CameraInfo
//     with the same header and the given calibration. Messages the input
//     already has on that topic are dropped (they describe the raw images).
//
// Like BagImageWriter, the output is written to a temporary file next to
// it and renamed only when complete: on any failure no file is left under
// the output name.
//
// Part of rcm::rosbag, built only when ROS1 bag support is found
// (RCM_HAVE_ROSBAG); this header needs no ROS headers.
#ifndef RCM_ROSBAG_BAG_IMAGE_REWRITER_H_
#define RCM_ROSBAG_BAG_IMAGE_REWRITER_H_

#include <cstddef>
#include <cstdint>
#include <functional>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "rcm/io/camera_info.h"
#include "rcm/util/status.h"

namespace rcm {

struct BagImageRewriteTopic {
  // Input image topic (sensor_msgs/Image or sensor_msgs/CompressedImage).
  std::string image_topic;
  // Topic of the CameraInfo written with every image, e.g.
  // "/cam0/camera_info"; empty writes none.
  std::string camera_info_topic;
  // Calibration of the transformed images (camera_info.camera_name is
  // ignored; the message's header comes from the image).
  CameraInfo camera_info;
};

// The transform of one image: `topic_index` indexes the topics given to
// RewriteBagImages, `image` is the decoded input (CV_8UC1 or CV_8UC3 BGR).
// Returns the image to write (CV_8UC1 or CV_8UC3 BGR, any size), or an
// error that stops the rewrite.
using BagImageTransform =
    std::function<StatusOr<cv::Mat>(size_t topic_index, const cv::Mat& image)>;

// Progress: messages handled so far and messages in the input bag.
using BagRewriteProgress = std::function<void(int64_t done, int64_t total)>;

struct BagRewriteSummary {
  // Per topic (same order as the topics given): images rewritten.
  std::vector<int64_t> images;
  // Messages copied unchanged (every other topic).
  int64_t copied_messages = 0;
  // Input camera_info messages dropped because their topic is rewritten.
  int64_t dropped_camera_infos = 0;
};

// Errors, each one line naming the bag: a missing or unreadable input
// (not a bag, truncated, unindexed); an output path equal to the input; no
// topic, an empty or repeated topic; an image topic that the input does
// not have or whose type is not an image (the message lists the bag's
// image topics); a camera_info_topic that is an image topic or that the
// input has with a type other than sensor_msgs/CameraInfo; an image that
// does not decode (named by topic and stamp); the transform's error; an
// output that cannot be written. Empty `progress` reports nothing.
StatusOr<BagRewriteSummary> RewriteBagImages(
    const std::string& input_path, const std::string& output_path,
    const std::vector<BagImageRewriteTopic>& topics,
    const BagImageTransform& transform,
    const BagRewriteProgress& progress = {});

}  // namespace rcm

#endif  // RCM_ROSBAG_BAG_IMAGE_REWRITER_H_
