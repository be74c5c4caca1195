// Writes camera images into a ROS1 bag, as sensor_msgs/Image or
// sensor_msgs/CompressedImage messages that rosbag, rviz and Kalibr read:
// the output of tools that produce image sequences for ROS users, and the
// bags of the bag reader's tests (bag_stereo_source.h).
//
// Like WriteFileAtomically (atomic_file.h), the writer never leaves a
// partial bag under the final name: it writes to a temporary file next to
// it and renames that file in Close(). A writer destroyed without a
// successful Close() removes its temporary file.
//
// Part of rcm::rosbag, built only when ROS1 bag support is found
// (RCM_HAVE_ROSBAG); this header needs no ROS headers.
#ifndef RCM_ROSBAG_BAG_IMAGE_WRITER_H_
#define RCM_ROSBAG_BAG_IMAGE_WRITER_H_

#include <memory>
#include <opencv2/core.hpp>
#include <string>

#include "rcm/io/camera_info.h"
#include "rcm/util/status.h"

namespace rcm {

class BagImageWriter {
 public:
  // Starts the bag `path` (uncompressed), written to "PATH.tmp.PID" until
  // Close(). Errors: "PATH: cannot write: <reason>" (e.g. a missing or
  // read-only directory).
  static StatusOr<BagImageWriter> Create(const std::string& path);

  BagImageWriter(BagImageWriter&& other) noexcept;
  BagImageWriter& operator=(BagImageWriter&& other) noexcept;
  ~BagImageWriter();

  // Writes `image` as a sensor_msgs/Image on `topic`, with header.stamp
  // and the bag's message time both `stamp_s` (seconds since the epoch, as
  // ROS stamps count) and header.frame_id `frame_id`. `encoding`:
  // "mono8" for CV_8UC1; "bgr8" or "rgb8" for CV_8UC3, which holds BGR like
  // every cv::Mat in rcm ("rgb8" stores the channels swapped, as that
  // encoding requires). Rows are stored without padding (step = width *
  // channels). Errors: an empty topic, a stamp that is not positive or does
  // not fit a ROS time (< 2^32 s), an empty image, an image type the
  // encoding cannot hold, an unknown encoding, a failed write.
  Status WriteImage(const std::string& topic, double stamp_s,
                    const cv::Mat& image, const std::string& encoding,
                    const std::string& frame_id);

  // Writes `image` (CV_8UC1 or CV_8UC3 BGR) as a
  // sensor_msgs/CompressedImage, encoded in `format`: "png" (lossless) or
  // "jpeg" (quality 95). The message's format field follows
  // image_transport's convention, e.g. "bgr8; jpeg compressed bgr8".
  // Stamps, frame id and errors as WriteImage.
  Status WriteCompressed(const std::string& topic, double stamp_s,
                         const cv::Mat& image, const std::string& format,
                         const std::string& frame_id);

  // Writes `info` as a sensor_msgs/CameraInfo on `topic` (stamp and
  // frame_id as WriteImage): width, height, distortion_model and D as
  // FormatCameraInfo (camera_info.h) writes them, K, R, P row-major,
  // binning 0 and an empty ROI. Errors: as WriteImage's stamp and topic
  // errors, a failed write.
  Status WriteCameraInfo(const std::string& topic, double stamp_s,
                         const CameraInfo& info, const std::string& frame_id);

  // Finishes the bag (writes its index) and renames it to its path. Once
  // a write failed, Close() fails too and removes the temporary file, so a
  // bag under the final name is always complete. Call at most once; no
  // writes after it.
  Status Close();

 private:
  struct Impl;
  explicit BagImageWriter(std::unique_ptr<Impl> impl);

  std::unique_ptr<Impl> impl_;
};

}  // namespace rcm

#endif  // RCM_ROSBAG_BAG_IMAGE_WRITER_H_
