// What the ROS1 bag code of rcm::rosbag shares (bag_stereo_source.cc,
// bag_image_writer.cc, bag_image_rewriter.cc), so that each is written
// once: image and camera_info messages to and from cv::Mat and CameraInfo,
// the checks and error texts of reading a bag, and the temporary file an
// output bag is written to. Private to rcm::rosbag: it needs ROS headers.
#ifndef RCM_SRC_ROSBAG_ROS_IMAGE_MESSAGE_H_
#define RCM_SRC_ROSBAG_ROS_IMAGE_MESSAGE_H_

#include <rosbag/bag.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/CompressedImage.h>
#include <sensor_msgs/Image.h>

#include <exception>
#include <map>
#include <memory>
#include <opencv2/core.hpp>
#include <set>
#include <string>

#include "rcm/io/camera_info.h"
#include "rcm/util/status.h"

namespace rcm {

inline constexpr char kImageType[] = "sensor_msgs/Image";
inline constexpr char kCompressedImageType[] = "sensor_msgs/CompressedImage";
inline constexpr char kCameraInfoType[] = "sensor_msgs/CameraInfo";

// An exception's text fit for a one-line message (rosbag's may hold line
// breaks).
std::string OneLine(const std::exception& error);

// How messages name an image message: "/cam0/image_raw @ 1000.250000"
// (header stamp in seconds, 6 decimals).
std::string StampedName(const std::string& topic, double stamp_s);

// ---------------------------------------------------------------------------
// Messages. Errors carry no context; callers prefix the bag and message.

// The 8-bit, 1- or 3-channel (BGR) image of a sensor_msgs/Image: mono8,
// 8UC1, bgr8, 8UC3, rgb8, bgra8 or rgba8, rows possibly padded (step).
StatusOr<cv::Mat> DecodeImage(const sensor_msgs::Image& message);

// The 8-bit, 1- or 3-channel (BGR) image of a sensor_msgs/CompressedImage
// (what rcm::DecodeImage reads, image_codec.h; an alpha channel is dropped).
StatusOr<cv::Mat> DecodeCompressedImage(
    const sensor_msgs::CompressedImage& message);

// Sets the pixel fields of `message` (all but the header) to `image`:
// "mono8" for CV_8UC1; "bgr8" or "rgb8" for CV_8UC3 holding BGR ("rgb8"
// stores the channels swapped). Rows without padding.
Status EncodeImage(const cv::Mat& image, const std::string& encoding,
                   sensor_msgs::Image* message);

// Sets the format and data of `message` (not the header) to `image`
// (CV_8UC1 or CV_8UC3 BGR) encoded in `format`: "png" or "jpeg" (quality
// 95). The format field follows image_transport, e.g. "bgr8; jpeg
// compressed bgr8".
Status EncodeCompressedImage(const cv::Mat& image, const std::string& format,
                             sensor_msgs::CompressedImage* message);

// The sensor_msgs/CameraInfo of `info`, header left empty: size,
// distortion_model and D as FormatCameraInfo writes them, K, R, P
// row-major, binning 0, an empty ROI.
sensor_msgs::CameraInfo CameraInfoMessage(const CameraInfo& info);

// ---------------------------------------------------------------------------
// Reading bags.

// Topic -> the data types of its connections.
using BagTopicTypes = std::map<std::string, std::set<std::string>>;

// The topics of an open bag. Throws what rosbag throws.
BagTopicTypes ReadTopicTypes(const rosbag::Bag& bag);

bool IsImageType(const std::string& type);

// Errors for a topic that `types` lacks, "PATH: no topic /x (image topics
// in the bag: /a [sensor_msgs/Image], ...)", or that is not an image topic.
Status CheckImageTopic(const std::string& path, const std::string& topic,
                       const BagTopicTypes& types);

// What rosbag cannot say clearly before opening `path`: "PATH: cannot
// open: <reason>", "PATH: is a directory, expected a file".
Status CheckBagFileExists(const std::string& path);

// Call only inside a catch block: the one-line error for the exception
// being handled, which rosbag threw reading `path`: "PATH: not a readable
// ROS1 bag (<reason>)".
Status UnreadableBagError(const std::string& path);

// ---------------------------------------------------------------------------
// Writing bags.

// A bag written to "PATH.tmp.PID" and renamed to PATH by Commit(), so that
// no partial bag is ever seen under PATH (as WriteFileAtomically does for
// other files). Destroyed without a successful Commit(), it removes its
// temporary file.
class TemporaryBag {
 public:
  // Starts an uncompressed bag. Errors: "PATH: cannot write: <reason>"
  // (e.g. a missing directory, PATH a directory).
  static StatusOr<std::unique_ptr<TemporaryBag>> Create(
      const std::string& path);

  TemporaryBag(const TemporaryBag&) = delete;
  TemporaryBag& operator=(const TemporaryBag&) = delete;
  ~TemporaryBag();

  const std::string& path() const { return path_; }
  // For writing only (rosbag throws on a failed write).
  rosbag::Bag& bag() { return *bag_; }

  // Finishes the bag (writes its index), syncs it to disk and renames it
  // to path(). Errors: "PATH: write failed: <reason>", "PATH: cannot write:
  // <reason>"; the temporary file is then removed. Call at most once.
  Status Commit();

 private:
  TemporaryBag(std::string path, std::string temporary,
               std::unique_ptr<rosbag::Bag> bag);

  // Closes the bag, if open, and removes the temporary file unless it was
  // renamed.
  void Discard();

  std::string path_;
  std::string temporary_;
  std::unique_ptr<rosbag::Bag> bag_;
  bool renamed_ = false;
};

}  // namespace rcm

#endif  // RCM_SRC_ROSBAG_ROS_IMAGE_MESSAGE_H_
