#include "rcm/rosbag/bag_image_writer.h"

#include <rosbag/bag.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/CompressedImage.h>
#include <sensor_msgs/Image.h>

#include <cmath>
#include <exception>
#include <utility>

#include "rcm/util/number_format.h"
#include "ros_image_message.h"

namespace rcm {
namespace {

// `stamp_s` as a ROS time. rosbag refuses message times before
// ros::TIME_MIN (1 ns), and ros::Time holds 32-bit seconds.
StatusOr<ros::Time> ToRosTime(double stamp_s) {
  if (!std::isfinite(stamp_s) || stamp_s <= 0.0 || stamp_s >= 4294967295.0) {
    return Status::Error("stamp " + FormatDouble(stamp_s) +
                         " s: expected a time after 0 and before 2^32 s");
  }
  const ros::Time time(stamp_s);
  if (time < ros::TIME_MIN) {
    return Status::Error("stamp " + FormatDouble(stamp_s) +
                         " s: expected a time of at least 1 ns");
  }
  return time;
}

}  // namespace

struct BagImageWriter::Impl {
  // Whether a write may go ahead: an error once a write failed.
  Status CheckWritable() const {
    CHECK(!closed) << "BagImageWriter used after Close()";
    if (!failure.empty()) {
      return Status::Error(path() + ": an earlier write failed (" + failure +
                           ")");
    }
    return Status::Ok();
  }

  // The checks every message passes before it is built: a writable bag, a
  // topic, a stamp ROS can hold. `what` names the message ("an image").
  // Returns the stamp.
  StatusOr<ros::Time> CheckMessage(const std::string& topic, double stamp_s,
                                   const std::string& what) const {
    RCM_RETURN_IF_ERROR(CheckWritable());
    if (topic.empty()) {
      return Status::Error(path() + ": " + what + " needs a topic");
    }
    const StatusOr<ros::Time> time = ToRosTime(stamp_s);
    if (!time.ok()) return time.status().WithContext(path() + ": " + topic);
    return *time;
  }

  // CheckMessage's checks and an image to write.
  StatusOr<ros::Time> CheckImage(const std::string& topic, double stamp_s,
                                 const cv::Mat& image) const {
    const StatusOr<ros::Time> time = CheckMessage(topic, stamp_s, "an image");
    RCM_RETURN_IF_ERROR(time.status());
    if (image.empty()) {
      return Status::Error(path() + ": " + topic +
                           ": cannot write an empty image");
    }
    return time;
  }

  // Sets the header stamp and frame id of `message` and writes it.
  template <typename Message>
  Status Write(const std::string& topic, const ros::Time& time,
               const std::string& frame_id, Message* message) {
    message->header.stamp = time;
    message->header.frame_id = frame_id;
    try {
      output->bag().write(topic, time, *message);
    } catch (const std::exception& error) {
      failure = OneLine(error);
      return Status::Error(path() + ": cannot write " + topic + ": " + failure);
    }
    return Status::Ok();
  }

  const std::string& path() const { return output->path(); }

  std::unique_ptr<TemporaryBag> output;
  // The first failed write's reason; empty while every write succeeded.
  std::string failure;
  bool closed = false;
};

BagImageWriter::BagImageWriter(std::unique_ptr<Impl> impl)
    : impl_(std::move(impl)) {}
BagImageWriter::BagImageWriter(BagImageWriter&& other) noexcept = default;
BagImageWriter& BagImageWriter::operator=(BagImageWriter&& other) noexcept =
    default;
BagImageWriter::~BagImageWriter() = default;

StatusOr<BagImageWriter> BagImageWriter::Create(const std::string& path) {
  StatusOr<std::unique_ptr<TemporaryBag>> output = TemporaryBag::Create(path);
  if (!output.ok()) return output.status();
  auto impl = std::make_unique<Impl>();
  impl->output = std::move(output).value();
  return BagImageWriter(std::move(impl));
}

Status BagImageWriter::WriteImage(const std::string& topic, double stamp_s,
                                  const cv::Mat& image,
                                  const std::string& encoding,
                                  const std::string& frame_id) {
  CHECK(impl_ != nullptr) << "BagImageWriter used after a move";
  const StatusOr<ros::Time> time = impl_->CheckImage(topic, stamp_s, image);
  RCM_RETURN_IF_ERROR(time.status());
  sensor_msgs::Image message;
  RCM_RETURN_IF_ERROR(EncodeImage(image, encoding, &message)
                          .WithContext(impl_->path() + ": " + topic));
  return impl_->Write(topic, *time, frame_id, &message);
}

Status BagImageWriter::WriteCompressed(const std::string& topic, double stamp_s,
                                       const cv::Mat& image,
                                       const std::string& format,
                                       const std::string& frame_id) {
  CHECK(impl_ != nullptr) << "BagImageWriter used after a move";
  const StatusOr<ros::Time> time = impl_->CheckImage(topic, stamp_s, image);
  RCM_RETURN_IF_ERROR(time.status());
  sensor_msgs::CompressedImage message;
  RCM_RETURN_IF_ERROR(EncodeCompressedImage(image, format, &message)
                          .WithContext(impl_->path() + ": " + topic));
  return impl_->Write(topic, *time, frame_id, &message);
}

Status BagImageWriter::WriteCameraInfo(const std::string& topic, double stamp_s,
                                       const CameraInfo& info,
                                       const std::string& frame_id) {
  CHECK(impl_ != nullptr) << "BagImageWriter used after a move";
  const StatusOr<ros::Time> time =
      impl_->CheckMessage(topic, stamp_s, "a camera_info");
  RCM_RETURN_IF_ERROR(time.status());
  RCM_RETURN_IF_ERROR(CheckCameraInfoModel(info.camera)
                          .WithContext(impl_->path() + ": " + topic));
  sensor_msgs::CameraInfo message = CameraInfoMessage(info);
  return impl_->Write(topic, *time, frame_id, &message);
}

Status BagImageWriter::Close() {
  CHECK(impl_ != nullptr) << "BagImageWriter used after a move";
  CHECK(!impl_->closed) << "BagImageWriter::Close() called twice";
  impl_->closed = true;
  if (!impl_->failure.empty()) {
    const std::string path = impl_->path();
    impl_->output.reset();  // removes the temporary file
    return Status::Error(path + ": not written: an earlier write failed (" +
                         impl_->failure + ")");
  }
  return impl_->output->Commit();
}

}  // namespace rcm
