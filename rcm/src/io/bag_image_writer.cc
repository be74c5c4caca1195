#include "rcm/io/bag_image_writer.h"

#include <fcntl.h>
#include <rosbag/bag.h>
#include <sensor_msgs/CompressedImage.h>
#include <sensor_msgs/Image.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <exception>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <utility>
#include <vector>

#include "rcm/io/number_format.h"
#include "rcm/util/message_text.h"

namespace rcm {
namespace {

// An exception's text fit for a one-line message (rosbag's may hold line
// breaks).
std::string OneLine(const std::exception& error) {
  std::string text = error.what();
  for (char& c : text) {
    if (c == '\n' || c == '\r' || c == '\t') c = ' ';
  }
  return text;
}

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
  ~Impl() { Discard(); }

  // Closes the bag, if open, and removes the temporary file, unless
  // Close() renamed it.
  void Discard() {
    if (bag != nullptr) {
      try {
        bag->close();
        bag.reset();
      } catch (...) {
        // rosbag::Bag's destructor would call close() again and throw out
        // of a destructor; leaking the Bag (and its file descriptor) on
        // this rare path (a full disk) is the lesser harm.
        static_cast<void>(bag.release());
      }
    }
    if (!renamed) std::remove(temporary.c_str());
  }

  // Whether a write may go ahead: an error once a write failed.
  Status CheckWritable() const {
    CHECK(!closed) << "BagImageWriter used after Close()";
    if (!failure.empty()) {
      return Status::Error(path + ": an earlier write failed (" + failure +
                           ")");
    }
    return Status::Ok();
  }

  // The checks every message passes before it is encoded: a writable bag,
  // a topic, a stamp ROS can hold, an image. Returns the stamp.
  StatusOr<ros::Time> CheckMessage(const std::string& topic, double stamp_s,
                                   const cv::Mat& image) const {
    RCM_RETURN_IF_ERROR(CheckWritable());
    if (topic.empty()) return Status::Error(path + ": an image needs a topic");
    const StatusOr<ros::Time> time = ToRosTime(stamp_s);
    if (!time.ok()) return time.status().WithContext(path + ": " + topic);
    if (image.empty()) {
      return Status::Error(path + ": " + topic +
                           ": cannot write an empty image");
    }
    return *time;
  }

  template <typename Message>
  Status Write(const std::string& topic, const ros::Time& time,
               const Message& message) {
    try {
      bag->write(topic, time, message);
    } catch (const std::exception& error) {
      failure = OneLine(error);
      return Status::Error(path + ": cannot write " + topic + ": " + failure);
    }
    return Status::Ok();
  }

  std::string path;
  std::string temporary;
  std::unique_ptr<rosbag::Bag> bag;
  // The first failed write's reason; empty while every write succeeded.
  std::string failure;
  bool closed = false;
  bool renamed = false;
};

BagImageWriter::BagImageWriter(std::unique_ptr<Impl> impl)
    : impl_(std::move(impl)) {}
BagImageWriter::BagImageWriter(BagImageWriter&& other) noexcept = default;
BagImageWriter& BagImageWriter::operator=(BagImageWriter&& other) noexcept =
    default;
BagImageWriter::~BagImageWriter() = default;

StatusOr<BagImageWriter> BagImageWriter::Create(const std::string& path) {
  struct stat info;
  if (stat(path.c_str(), &info) == 0 && S_ISDIR(info.st_mode)) {
    return Status::Error(path + ": cannot write: " + std::strerror(EISDIR));
  }
  auto impl = std::make_unique<Impl>();
  impl->path = path;
  impl->temporary =
      path + ".tmp." + std::to_string(static_cast<long>(getpid()));
  // rosbag's error for a file it cannot create has no reason; fopen's has.
  std::FILE* probe = std::fopen(impl->temporary.c_str(), "wb");
  if (probe == nullptr) {
    return Status::Error(path + ": cannot write: " + std::strerror(errno));
  }
  std::fclose(probe);
  auto bag = std::make_unique<rosbag::Bag>();
  try {
    bag->open(impl->temporary, rosbag::bagmode::Write);
  } catch (const std::exception& error) {
    std::remove(impl->temporary.c_str());
    return Status::Error(path + ": cannot write: " + OneLine(error));
  }
  impl->bag = std::move(bag);
  return BagImageWriter(std::move(impl));
}

Status BagImageWriter::WriteImage(const std::string& topic, double stamp_s,
                                  const cv::Mat& image,
                                  const std::string& encoding,
                                  const std::string& frame_id) {
  CHECK(impl_ != nullptr) << "BagImageWriter used after a move";
  const std::string& path = impl_->path;
  const StatusOr<ros::Time> time = impl_->CheckMessage(topic, stamp_s, image);
  RCM_RETURN_IF_ERROR(time.status());
  int type;
  if (encoding == "mono8") {
    type = CV_8UC1;
  } else if (encoding == "bgr8" || encoding == "rgb8") {
    type = CV_8UC3;
  } else {
    return Status::Error(path + ": " + topic + ": unknown encoding " +
                         QuoteForMessage(encoding) +
                         " (mono8, bgr8 or rgb8)");
  }
  if (image.type() != type) {
    return Status::Error(path + ": " + topic + ": encoding " + encoding +
                         " needs a " + cv::typeToString(type) +
                         " image, got " + cv::typeToString(image.type()));
  }
  sensor_msgs::Image message;
  message.header.stamp = *time;
  message.header.frame_id = frame_id;
  message.height = static_cast<uint32_t>(image.rows);
  message.width = static_cast<uint32_t>(image.cols);
  message.encoding = encoding;
  message.is_bigendian = 0;
  message.step = static_cast<uint32_t>(image.cols * image.channels());
  message.data.resize(static_cast<size_t>(message.step) * message.height);
  cv::Mat pixels(image.rows, image.cols, type, message.data.data(),
                 message.step);
  if (encoding == "rgb8") {
    cv::cvtColor(image, pixels, cv::COLOR_BGR2RGB);
  } else {
    image.copyTo(pixels);
  }
  CHECK(pixels.data == message.data.data()) << "the image was reallocated";
  return impl_->Write(topic, *time, message);
}

Status BagImageWriter::WriteCompressed(const std::string& topic,
                                       double stamp_s, const cv::Mat& image,
                                       const std::string& format,
                                       const std::string& frame_id) {
  CHECK(impl_ != nullptr) << "BagImageWriter used after a move";
  const std::string& path = impl_->path;
  const StatusOr<ros::Time> time = impl_->CheckMessage(topic, stamp_s, image);
  RCM_RETURN_IF_ERROR(time.status());
  std::string extension;
  std::vector<int> parameters;
  if (format == "png") {
    extension = ".png";
  } else if (format == "jpeg") {
    extension = ".jpg";
    parameters = {cv::IMWRITE_JPEG_QUALITY, 95};
  } else {
    return Status::Error(path + ": " + topic + ": unknown format " +
                         QuoteForMessage(format) + " (png or jpeg)");
  }
  if (image.type() != CV_8UC1 && image.type() != CV_8UC3) {
    return Status::Error(path + ": " + topic +
                         ": a compressed image must be CV_8UC1 or CV_8UC3, "
                         "got " +
                         cv::typeToString(image.type()));
  }
  const std::string encoding = image.channels() == 1 ? "mono8" : "bgr8";
  sensor_msgs::CompressedImage message;
  message.header.stamp = *time;
  message.header.frame_id = frame_id;
  message.format = encoding + "; " + format + " compressed " + encoding;
  try {
    if (!cv::imencode(extension, image, message.data, parameters)) {
      return Status::Error(path + ": " + topic + ": " + format +
                           " encoding failed");
    }
  } catch (const cv::Exception& error) {
    return Status::Error(path + ": " + topic + ": " + format +
                         " encoding failed: " + OneLine(error));
  }
  return impl_->Write(topic, *time, message);
}

Status BagImageWriter::Close() {
  CHECK(impl_ != nullptr) << "BagImageWriter used after a move";
  CHECK(!impl_->closed) << "BagImageWriter::Close() called twice";
  impl_->closed = true;
  const std::string& path = impl_->path;
  const std::string& temporary = impl_->temporary;
  if (!impl_->failure.empty()) {
    impl_->Discard();
    return Status::Error(path + ": not written: an earlier write failed (" +
                         impl_->failure + ")");
  }
  try {
    impl_->bag->close();
  } catch (const std::exception& error) {
    impl_->Discard();
    return Status::Error(path + ": write failed: " + OneLine(error));
  }
  impl_->bag.reset();
  // As in WriteFileAtomically: the data reach the disk before the rename
  // makes the bag visible.
  const int fd = open(temporary.c_str(), O_RDONLY);
  if (fd < 0 || fsync(fd) != 0) {
    const int sync_errno = errno;
    if (fd >= 0) ::close(fd);
    impl_->Discard();
    return Status::Error(path + ": write failed: " + std::strerror(sync_errno));
  }
  ::close(fd);
  if (std::rename(temporary.c_str(), path.c_str()) != 0) {
    const int rename_errno = errno;
    impl_->Discard();
    return Status::Error(path + ": cannot write: " +
                         std::strerror(rename_errno));
  }
  impl_->renamed = true;
  return Status::Ok();
}

}  // namespace rcm
