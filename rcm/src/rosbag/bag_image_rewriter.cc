#include "rcm/rosbag/bag_image_rewriter.h"

#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/CompressedImage.h>
#include <sensor_msgs/Image.h>

#include <algorithm>
#include <exception>
#include <filesystem>
#include <map>
#include <memory>
#include <set>
#include <string_view>
#include <system_error>
#include <utility>

#include "rcm/io/image_file.h"
#include "rcm/util/message_text.h"
#include "ros_image_message.h"

namespace rcm {
namespace {

// The checks of `topics` that need no bag: at least one, image topics
// given and distinct, camera_info topics distinct and not image topics.
Status CheckTopicNames(const std::string& input_path,
                       const std::vector<BagImageRewriteTopic>& topics) {
  if (topics.empty()) {
    return Status::Error(input_path + ": no image topic to rewrite");
  }
  std::set<std::string> image_topics;
  for (const BagImageRewriteTopic& topic : topics) {
    if (topic.image_topic.empty()) {
      return Status::Error(input_path + ": an image topic to rewrite is empty");
    }
    if (!image_topics.insert(topic.image_topic).second) {
      return Status::Error(input_path + ": image topic " + topic.image_topic +
                           " is given twice");
    }
  }
  std::set<std::string> camera_info_topics;
  for (const BagImageRewriteTopic& topic : topics) {
    const std::string& camera_info = topic.camera_info_topic;
    if (camera_info.empty()) continue;
    if (image_topics.count(camera_info) > 0) {
      return Status::Error(input_path + ": camera_info topic " + camera_info +
                           " is also an image topic to rewrite");
    }
    if (!camera_info_topics.insert(camera_info).second) {
      return Status::Error(input_path + ": camera_info topic " + camera_info +
                           " is given twice");
    }
  }
  return Status::Ok();
}

// Whether the two paths name one file: writing the output would then
// destroy the input while it is read.
bool SameFile(const std::string& a, const std::string& b) {
  std::error_code error;  // a missing file is not the same as any other
  return a == b || std::filesystem::equivalent(a, b, error);
}

// The checks of `topics` against the topics the input bag has.
Status CheckTopicsInBag(const std::string& path,
                        const std::vector<BagImageRewriteTopic>& topics,
                        const BagTopicTypes& types) {
  for (const BagImageRewriteTopic& topic : topics) {
    RCM_RETURN_IF_ERROR(CheckImageTopic(path, topic.image_topic, types));
    const auto found = types.find(topic.camera_info_topic);
    if (topic.camera_info_topic.empty() || found == types.end()) continue;
    for (const std::string& type : found->second) {
      if (type != kCameraInfoType) {
        return Status::Error(path + ": camera_info topic " +
                             topic.camera_info_topic + " has type " + type +
                             ", expected " + kCameraInfoType);
      }
    }
  }
  return Status::Ok();
}

// "png" or "jpeg", the format of a compressed image's data, told by its
// signature: the format field is free text (image_transport's
// "bgr8; jpeg compressed bgr8", or "jpeg", or empty in old bags).
StatusOr<std::string> CompressedFormat(
    const sensor_msgs::CompressedImage& message) {
  static constexpr uint8_t kPng[] = {0x89, 'P',  'N',  'G',
                                     '\r', '\n', 0x1a, '\n'};
  static constexpr uint8_t kJpeg[] = {0xff, 0xd8, 0xff};
  const std::vector<uint8_t>& data = message.data;
  const auto starts_with = [&data](const auto& signature) {
    return data.size() >= std::size(signature) &&
           std::equal(std::begin(signature), std::end(signature), data.begin());
  };
  if (starts_with(kPng)) return std::string("png");
  if (starts_with(kJpeg)) return std::string("jpeg");
  return Status::Error("compressed image (format " +
                       QuoteForMessage(message.format) +
                       ") is neither png nor jpeg, the formats rcm rewrites");
}

// The image of a message, in a format the rewrite can write back.
StatusOr<cv::Mat> Decode(const sensor_msgs::Image& message) {
  return DecodeImage(message);
}

StatusOr<cv::Mat> Decode(const sensor_msgs::CompressedImage& message) {
  // A cut or damaged PNG or JPEG is refused before it is decoded: libpng and
  // libjpeg would print their own warnings.
  RCM_RETURN_IF_ERROR(
      CheckImageFileStructure(
          std::string_view(reinterpret_cast<const char*>(message.data.data()),
                           message.data.size()))
          .WithContext("compressed image"));
  StatusOr<cv::Mat> image = DecodeCompressedImage(message);
  if (!image.ok()) return image;
  RCM_RETURN_IF_ERROR(CompressedFormat(message).status());
  return image;
}

// Replaces the pixels of `message`, keeping its header and kind: an Image
// is written mono8 or bgr8, a CompressedImage in the format it had.
Status Reencode(const cv::Mat& image, sensor_msgs::Image* message) {
  return EncodeImage(image, image.channels() == 1 ? "mono8" : "bgr8", message);
}

Status Reencode(const cv::Mat& image, sensor_msgs::CompressedImage* message) {
  const StatusOr<std::string> format = CompressedFormat(*message);
  RCM_RETURN_IF_ERROR(format.status());
  return EncodeCompressedImage(image, *format, message);
}

// Copies and rewrites the messages of the input bag, one at a time, into
// the output.
class BagRewriter {
 public:
  BagRewriter(const std::string& input_path,
              const std::vector<BagImageRewriteTopic>& topics,
              const BagImageTransform& transform, TemporaryBag* output)
      : input_path_(input_path),
        topics_(topics),
        transform_(transform),
        output_(*output) {
    summary_.images.assign(topics.size(), 0);
    for (size_t i = 0; i < topics.size(); ++i) {
      image_topics_[topics[i].image_topic] = i;
      if (!topics[i].camera_info_topic.empty()) {
        camera_info_topics_.insert(topics[i].camera_info_topic);
      }
    }
  }

  // Rewrites, drops or copies `message`. Throws what rosbag throws reading
  // the input; errors writing the output are returned.
  Status Handle(const rosbag::MessageInstance& message) {
    const std::string& topic = message.getTopic();
    const auto image = image_topics_.find(topic);
    if (image != image_topics_.end()) {
      if (message.getDataType() == kImageType) {
        return Rewrite<sensor_msgs::Image>(image->second, message);
      }
      return Rewrite<sensor_msgs::CompressedImage>(image->second, message);
    }
    if (camera_info_topics_.count(topic) > 0) {
      ++summary_.dropped_camera_infos;
      return Status::Ok();
    }
    // Reads the message's chunk here, so that a corrupt input throws as a
    // read error rather than inside Write.
    static_cast<void>(message.size());
    RCM_RETURN_IF_ERROR(Write(topic, message.getTime(), message,
                              message.getConnectionHeader()));
    ++summary_.copied_messages;
    return Status::Ok();
  }

  const BagRewriteSummary& summary() const { return summary_; }

 private:
  // Writes the transformed image of `instance` in place of it, with the
  // same header and connection, then its camera_info.
  template <typename Message>
  Status Rewrite(size_t index, const rosbag::MessageInstance& instance) {
    const BagImageRewriteTopic& topic = topics_[index];
    const boost::shared_ptr<Message> message = instance.instantiate<Message>();
    if (message == nullptr) {
      return Status::Error(input_path_ + ": " + topic.image_topic + ": a " +
                           instance.getDataType() +
                           " message with a definition this build does not "
                           "know (md5sum " +
                           instance.getMD5Sum() + ")");
    }
    const std::string context =
        input_path_ + ": " +
        StampedName(topic.image_topic, message->header.stamp.toSec());
    const StatusOr<cv::Mat> image = Decode(*message);
    if (!image.ok()) return image.status().WithContext(context);
    const StatusOr<cv::Mat> transformed = Transform(index, *image, context);
    RCM_RETURN_IF_ERROR(transformed.status());
    RCM_RETURN_IF_ERROR(
        Reencode(*transformed, message.get()).WithContext(context));
    RCM_RETURN_IF_ERROR(Write(topic.image_topic, instance.getTime(), *message,
                              instance.getConnectionHeader()));
    ++summary_.images[index];
    if (topic.camera_info_topic.empty()) return Status::Ok();
    sensor_msgs::CameraInfo camera_info = CameraInfoMessage(topic.camera_info);
    camera_info.header = message->header;
    return Write(topic.camera_info_topic, instance.getTime(), camera_info,
                 nullptr);
  }

  // The caller's transform of one image, checked to be one the rewrite can
  // write. `context` ("BAG: /topic @ stamp") prefixes its errors.
  StatusOr<cv::Mat> Transform(size_t index, const cv::Mat& image,
                              const std::string& context) const {
    StatusOr<cv::Mat> result = Status::Error("no result");
    try {
      result = transform_(index, image);
    } catch (const std::exception& error) {
      return Status::Error(context +
                           ": the transform threw: " + OneLine(error));
    }
    if (!result.ok()) return result.status().WithContext(context);
    if (result->empty() ||
        (result->type() != CV_8UC1 && result->type() != CV_8UC3)) {
      return Status::Error(
          context + ": the transform returned " +
          (result->empty()
               ? std::string("an empty image")
               : "a " + cv::typeToString(result->type()) + " image") +
          ", expected CV_8UC1 or CV_8UC3");
    }
    // The camera_info written with the image must describe it.
    const Camera& camera = topics_[index].camera_info.camera;
    if (!topics_[index].camera_info_topic.empty() &&
        (result->cols != camera.width() || result->rows != camera.height())) {
      return Status::Error(context + ": the transform returned a " +
                           std::to_string(result->cols) + "x" +
                           std::to_string(result->rows) +
                           " image, but its camera_info is for " +
                           std::to_string(camera.width()) + "x" +
                           std::to_string(camera.height()));
    }
    return result;
  }

  // Writes to the output; `connection_header` null makes rosbag write a
  // default one for the message's type.
  template <typename Message>
  Status Write(const std::string& topic, const ros::Time& time,
               const Message& message,
               const boost::shared_ptr<ros::M_string>& connection_header) {
    try {
      output_.bag().write(topic, time, message, connection_header);
    } catch (const std::exception& error) {
      return Status::Error(output_.path() + ": cannot write " + topic + ": " +
                           OneLine(error));
    }
    return Status::Ok();
  }

  const std::string& input_path_;
  const std::vector<BagImageRewriteTopic>& topics_;
  const BagImageTransform& transform_;
  TemporaryBag& output_;
  std::map<std::string, size_t> image_topics_;  // topic -> index in topics_
  std::set<std::string> camera_info_topics_;
  BagRewriteSummary summary_;
};

// Opens the input bag and checks the topics against it.
Status OpenInput(const std::string& path,
                 const std::vector<BagImageRewriteTopic>& topics,
                 rosbag::Bag* bag) {
  // rosbag's own errors for a missing file or a directory name no reason.
  RCM_RETURN_IF_ERROR(CheckBagFileExists(path));
  try {
    bag->open(path, rosbag::bagmode::Read);
    return CheckTopicsInBag(path, topics, ReadTopicTypes(*bag));
  } catch (...) {
    return UnreadableBagError(path);
  }
}

// Passes every message of `input`, in bag order, through `rewriter`.
Status RewriteMessages(const std::string& input_path, const rosbag::Bag& input,
                       const BagRewriteProgress& progress,
                       BagRewriter* rewriter) {
  try {
    rosbag::View view(input);
    const int64_t total = view.size();
    int64_t done = 0;
    for (const rosbag::MessageInstance& message : view) {
      RCM_RETURN_IF_ERROR(rewriter->Handle(message));
      if (progress) progress(++done, total);
    }
  } catch (...) {
    return UnreadableBagError(input_path);
  }
  return Status::Ok();
}

}  // namespace

StatusOr<BagRewriteSummary> RewriteBagImages(
    const std::string& input_path, const std::string& output_path,
    const std::vector<BagImageRewriteTopic>& topics,
    const BagImageTransform& transform, const BagRewriteProgress& progress) {
  RCM_RETURN_IF_ERROR(CheckTopicNames(input_path, topics));
  if (SameFile(input_path, output_path)) {
    return Status::Error(output_path +
                         ": is the input bag; write the rewritten bag to "
                         "another file");
  }
  rosbag::Bag input;
  RCM_RETURN_IF_ERROR(OpenInput(input_path, topics, &input));
  StatusOr<std::unique_ptr<TemporaryBag>> output =
      TemporaryBag::Create(output_path);
  if (!output.ok()) return output.status();
  // On an error below, the output's destructor removes its temporary file.
  BagRewriter rewriter(input_path, topics, transform, output->get());
  RCM_RETURN_IF_ERROR(RewriteMessages(input_path, input, progress, &rewriter));
  RCM_RETURN_IF_ERROR((*output)->Commit());
  return rewriter.summary();
}

}  // namespace rcm
