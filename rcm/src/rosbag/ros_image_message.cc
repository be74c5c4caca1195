#include "ros_image_message.h"

#include <fcntl.h>
#include <rosbag/exceptions.h>
#include <rosbag/view.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <opencv2/imgproc.hpp>
#include <utility>
#include <vector>

#include "rcm/io/image_codec.h"
#include "rcm/util/message_text.h"
#include "rcm/util/number_format.h"

namespace rcm {
namespace {

// "/a [sensor_msgs/Image], /b [sensor_msgs/CompressedImage]" for the
// topics of `types` that `keep` accepts.
template <typename Keep>
std::string ListTopics(const BagTopicTypes& types, Keep keep) {
  std::string list;
  for (const auto& [topic, topic_types] : types) {
    for (const std::string& type : topic_types) {
      if (!keep(type)) continue;
      if (!list.empty()) list += ", ";
      list += topic + " [" + type + "]";
    }
  }
  return list;
}

}  // namespace

std::string OneLine(const std::exception& error) {
  std::string text = error.what();
  for (char& c : text) {
    if (c == '\n' || c == '\r' || c == '\t') c = ' ';
  }
  return text;
}

std::string StampedName(const std::string& topic, double stamp_s) {
  return topic + " @ " + FormatFixed(stamp_s, 6);
}

// ---------------------------------------------------------------------------
// Messages.

StatusOr<cv::Mat> DecodeImage(const sensor_msgs::Image& message) {
  const std::string& encoding = message.encoding;
  int channels;
  int conversion = -1;  // cv::COLOR_* to BGR, -1 for none
  if (encoding == "mono8" || encoding == "8UC1") {
    channels = 1;
  } else if (encoding == "bgr8" || encoding == "8UC3") {
    channels = 3;
  } else if (encoding == "rgb8") {
    channels = 3;
    conversion = cv::COLOR_RGB2BGR;
  } else if (encoding == "bgra8") {
    channels = 4;
    conversion = cv::COLOR_BGRA2BGR;
  } else if (encoding == "rgba8") {
    channels = 4;
    conversion = cv::COLOR_RGBA2BGR;
  } else {
    return Status::Error(
        "unsupported encoding " + QuoteForMessage(encoding) +
        " (rcm reads mono8, 8UC1, bgr8, 8UC3, rgb8, bgra8 and rgba8)");
  }
  if (message.width == 0 || message.height == 0) {
    return Status::Error("empty image (" + std::to_string(message.width) + "x" +
                         std::to_string(message.height) + ")");
  }
  // uint64_t: width * channels cannot overflow; OpenCV's sizes are int.
  const uint64_t row_bytes = uint64_t{message.width} * channels;
  if (message.width > (1u << 30) || message.height > (1u << 30)) {
    return Status::Error("image too large (" + std::to_string(message.width) +
                         "x" + std::to_string(message.height) + ")");
  }
  if (message.step < row_bytes) {
    return Status::Error(
        "step " + std::to_string(message.step) +
        " is less than width * channels = " + std::to_string(row_bytes));
  }
  const uint64_t needed = uint64_t{message.step} * message.height;
  if (message.data.size() < needed) {
    return Status::Error("data holds " + std::to_string(message.data.size()) +
                         " bytes, step * height needs " +
                         std::to_string(needed));
  }
  // A view of the message's bytes that respects the row padding (step).
  const cv::Mat pixels(static_cast<int>(message.height),
                       static_cast<int>(message.width), CV_8UC(channels),
                       const_cast<uint8_t*>(message.data.data()), message.step);
  cv::Mat image;
  if (conversion >= 0) {
    cv::cvtColor(pixels, image, conversion);
  } else {
    image = pixels.clone();
  }
  return image;
}

StatusOr<cv::Mat> DecodeCompressedImage(
    const sensor_msgs::CompressedImage& message) {
  const std::string format = QuoteForMessage(message.format);
  StatusOr<cv::Mat> decoded = DecodeImage(
      std::string_view(reinterpret_cast<const char*>(message.data.data()),
                       message.data.size()),
      ImageReadMode::kAsStored);
  if (!decoded.ok()) {
    return Status::Error("compressed image (format " + format + ", " +
                         std::to_string(message.data.size()) +
                         " bytes) is corrupt or not a format OpenCV decodes");
  }
  cv::Mat image = *std::move(decoded);
  if (image.depth() != CV_8U ||
      (image.channels() != 1 && image.channels() != 3 &&
       image.channels() != 4)) {
    return Status::Error("compressed image (format " + format + ") is " +
                         cv::typeToString(image.type()) +
                         ", rcm reads 8-bit images with 1, 3 or 4 channels");
  }
  if (image.channels() == 4) cv::cvtColor(image, image, cv::COLOR_BGRA2BGR);
  return image;
}

Status EncodeImage(const cv::Mat& image, const std::string& encoding,
                   sensor_msgs::Image* message) {
  int type;
  if (encoding == "mono8") {
    type = CV_8UC1;
  } else if (encoding == "bgr8" || encoding == "rgb8") {
    type = CV_8UC3;
  } else {
    return Status::Error("unknown encoding " + QuoteForMessage(encoding) +
                         " (mono8, bgr8 or rgb8)");
  }
  if (image.type() != type) {
    return Status::Error("encoding " + encoding + " needs a " +
                         cv::typeToString(type) + " image, got " +
                         cv::typeToString(image.type()));
  }
  message->height = static_cast<uint32_t>(image.rows);
  message->width = static_cast<uint32_t>(image.cols);
  message->encoding = encoding;
  message->is_bigendian = 0;
  message->step = static_cast<uint32_t>(image.cols * image.channels());
  message->data.resize(static_cast<size_t>(message->step) * message->height);
  cv::Mat pixels(image.rows, image.cols, type, message->data.data(),
                 message->step);
  if (encoding == "rgb8") {
    cv::cvtColor(image, pixels, cv::COLOR_BGR2RGB);
  } else {
    image.copyTo(pixels);
  }
  CHECK(pixels.data == message->data.data()) << "the image was reallocated";
  return Status::Ok();
}

Status EncodeCompressedImage(const cv::Mat& image, const std::string& format,
                             sensor_msgs::CompressedImage* message) {
  if (format != "png" && format != "jpeg") {
    return Status::Error("unknown format " + QuoteForMessage(format) +
                         " (png or jpeg)");
  }
  if (image.type() != CV_8UC1 && image.type() != CV_8UC3) {
    return Status::Error("a compressed image must be CV_8UC1 or CV_8UC3, got " +
                         cv::typeToString(image.type()));
  }
  const std::string encoding = image.channels() == 1 ? "mono8" : "bgr8";
  message->format = encoding + "; " + format + " compressed " + encoding;
  StatusOr<std::string> encoded =
      format == "png" ? EncodePng(image) : EncodeJpeg(image, /*quality=*/95);
  if (!encoded.ok()) {
    return Status::Error(format +
                         " encoding failed: " + encoded.status().message());
  }
  message->data.assign(encoded->begin(), encoded->end());
  return Status::Ok();
}

sensor_msgs::CameraInfo CameraInfoMessage(const CameraInfo& info) {
  const Camera& camera = info.camera;
  sensor_msgs::CameraInfo message;
  message.width = static_cast<uint32_t>(camera.width());
  message.height = static_cast<uint32_t>(camera.height());
  RosDistortion distortion = RosDistortionOf(camera);
  message.distortion_model = distortion.model;
  message.D = std::move(distortion.coefficients);
  message.K = {camera.fx(), 0.0, camera.cx(), 0.0, camera.fy(),
               camera.cy(), 0.0, 0.0,         1.0};
  for (int i = 0; i < 9; ++i) message.R[i] = info.rectification(i / 3, i % 3);
  for (int i = 0; i < 12; ++i) message.P[i] = info.projection(i / 4, i % 4);
  message.binning_x = 0;
  message.binning_y = 0;
  return message;
}

// ---------------------------------------------------------------------------
// Reading bags.

BagTopicTypes ReadTopicTypes(const rosbag::Bag& bag) {
  BagTopicTypes types;
  rosbag::View everything(bag);
  for (const rosbag::ConnectionInfo* connection : everything.getConnections()) {
    types[connection->topic].insert(connection->datatype);
  }
  return types;
}

bool IsImageType(const std::string& type) {
  return type == kImageType || type == kCompressedImageType;
}

Status CheckImageTopic(const std::string& path, const std::string& topic,
                       const BagTopicTypes& types) {
  const auto found = types.find(topic);
  if (found == types.end()) {
    const std::string images = ListTopics(types, IsImageType);
    if (!images.empty()) {
      return Status::Error(path + ": no topic " + topic +
                           " (image topics in the bag: " + images + ")");
    }
    const std::string all =
        ListTopics(types, [](const std::string&) { return true; });
    return Status::Error(path + ": no topic " + topic +
                         " (the bag has no image topics" +
                         (all.empty() ? std::string(" and no messages")
                                      : "; its topics: " + all) +
                         ")");
  }
  for (const std::string& type : found->second) {
    if (!IsImageType(type)) {
      return Status::Error(path + ": topic " + topic + " has type " + type +
                           ", expected " + kImageType + " or " +
                           kCompressedImageType);
    }
  }
  return Status::Ok();
}

Status CheckBagFileExists(const std::string& path) {
  struct stat info;
  if (stat(path.c_str(), &info) != 0) {
    return Status::Error(path + ": cannot open: " + std::strerror(errno));
  }
  if (S_ISDIR(info.st_mode)) {
    return Status::Error(path + ": is a directory, expected a file");
  }
  return Status::Ok();
}

Status UnreadableBagError(const std::string& path) {
  // rosbag reports a truncated or foreign file by throwing
  // rosbag::BagException and its subclasses, or whatever a corrupt chunk
  // makes its decompressors throw.
  try {
    throw;
  } catch (const rosbag::BagUnindexedException&) {
    return Status::Error(path +
                         ": not a readable ROS1 bag (unindexed, as a "
                         "recording that was cut off leaves it; `rosbag "
                         "reindex` repairs it)");
  } catch (const std::exception& error) {
    return Status::Error(path + ": not a readable ROS1 bag (" + OneLine(error) +
                         ")");
  } catch (...) {
    return Status::Error(path + ": not a readable ROS1 bag");
  }
}

// ---------------------------------------------------------------------------
// Writing bags.

TemporaryBag::TemporaryBag(std::string path, std::string temporary,
                           std::unique_ptr<rosbag::Bag> bag)
    : path_(std::move(path)),
      temporary_(std::move(temporary)),
      bag_(std::move(bag)) {}

TemporaryBag::~TemporaryBag() { Discard(); }

StatusOr<std::unique_ptr<TemporaryBag>> TemporaryBag::Create(
    const std::string& path) {
  struct stat info;
  if (stat(path.c_str(), &info) == 0 && S_ISDIR(info.st_mode)) {
    return Status::Error(path + ": cannot write: " + std::strerror(EISDIR));
  }
  const std::string temporary =
      path + ".tmp." + std::to_string(static_cast<long>(getpid()));
  // rosbag's error for a file it cannot create has no reason; fopen's has.
  std::FILE* probe = std::fopen(temporary.c_str(), "wb");
  if (probe == nullptr) {
    return Status::Error(path + ": cannot write: " + std::strerror(errno));
  }
  std::fclose(probe);
  auto bag = std::make_unique<rosbag::Bag>();
  try {
    bag->open(temporary, rosbag::bagmode::Write);
  } catch (const std::exception& error) {
    std::remove(temporary.c_str());
    return Status::Error(path + ": cannot write: " + OneLine(error));
  }
  return std::unique_ptr<TemporaryBag>(
      new TemporaryBag(path, temporary, std::move(bag)));
}

void TemporaryBag::Discard() {
  if (bag_ != nullptr) {
    try {
      bag_->close();
      bag_.reset();
    } catch (...) {
      // rosbag::Bag's destructor would call close() again and throw out
      // of a destructor; leaking the Bag (and its file descriptor) on this
      // rare path (a full disk) is the lesser harm.
      static_cast<void>(bag_.release());
    }
  }
  if (!renamed_) std::remove(temporary_.c_str());
}

Status TemporaryBag::Commit() {
  CHECK(bag_ != nullptr) << "TemporaryBag::Commit() called twice";
  try {
    bag_->close();
  } catch (const std::exception& error) {
    Discard();
    return Status::Error(path_ + ": write failed: " + OneLine(error));
  }
  bag_.reset();
  // As in WriteFileAtomically: the data reach the disk before the rename
  // makes the bag visible.
  const int fd = open(temporary_.c_str(), O_RDONLY);
  if (fd < 0 || fsync(fd) != 0) {
    const int sync_errno = errno;
    if (fd >= 0) ::close(fd);
    Discard();
    return Status::Error(path_ +
                         ": write failed: " + std::strerror(sync_errno));
  }
  ::close(fd);
  if (std::rename(temporary_.c_str(), path_.c_str()) != 0) {
    const int rename_errno = errno;
    Discard();
    return Status::Error(path_ +
                         ": cannot write: " + std::strerror(rename_errno));
  }
  renamed_ = true;
  return Status::Ok();
}

}  // namespace rcm
