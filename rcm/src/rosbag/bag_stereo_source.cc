#include "rcm/rosbag/bag_stereo_source.h"

#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/CompressedImage.h>
#include <sensor_msgs/Image.h>

#include <algorithm>
#include <cmath>
#include <exception>
#include <numeric>
#include <string_view>
#include <utility>
#include <vector>

#include "rcm/io/image_file.h"
#include "rcm/util/number_format.h"
#include "ros_image_message.h"

namespace rcm {
namespace {

// A stamp as messages and pair names show it: seconds, 6 decimals.
std::string FormatStamp(double stamp_s) { return FormatFixed(stamp_s, 6); }

std::string FormatSize(const cv::Mat& image) {
  return std::to_string(image.cols) + "x" + std::to_string(image.rows);
}

// "1 unpaired message", "2 unpaired messages".
std::string Count(size_t count, const std::string& noun) {
  return std::to_string(count) + " " + noun + (count == 1 ? "" : "s");
}

// "2nd", "11th", "23rd".
std::string Ordinal(int n) {
  const int tens = n % 100;
  const int units = n % 10;
  const char* suffix = "th";
  if (tens < 11 || tens > 13) {
    if (units == 1) suffix = "st";
    if (units == 2) suffix = "nd";
    if (units == 3) suffix = "rd";
  }
  return std::to_string(n) + suffix;
}

// The messages of one topic in the bag, with their header stamps.
struct TopicMessages {
  std::vector<rosbag::MessageInstance> messages;  // in the bag's order
  std::vector<double> stamps;                     // seconds, per message
};

// Reads the header stamp of `message`, an image of either type. Errors
// (no context): a message that does not deserialize as its type.
StatusOr<double> HeaderStamp(const rosbag::MessageInstance& message) {
  if (message.getDataType() == kImageType) {
    if (const auto image = message.instantiate<sensor_msgs::Image>()) {
      return image->header.stamp.toSec();
    }
  } else if (const auto image =
                 message.instantiate<sensor_msgs::CompressedImage>()) {
    return image->header.stamp.toSec();
  }
  return Status::Error("a " + message.getDataType() +
                       " message with a definition this build does not know "
                       "(md5sum " +
                       message.getMD5Sum() + ")");
}

// One left and one right message, by index into their TopicMessages;
// right kNoRight for one camera (BagStereoOptions::left_only).
struct Pair {
  size_t left;
  size_t right;
};
constexpr size_t kNoRight = static_cast<size_t>(-1);

// Pairs messages whose stamps differ by at most `tolerance`, each message
// at most once: walking both topics in stamp order, a left and a right
// message are paired when they are within the tolerance and neither the
// next right message is nearer to the left one nor the next left message
// nearer to the right one. Pairs come in stamp order.
std::vector<Pair> PairByStamp(const std::vector<double>& left,
                              const std::vector<size_t>& left_order,
                              const std::vector<double>& right,
                              const std::vector<size_t>& right_order,
                              double tolerance) {
  std::vector<Pair> pairs;
  size_t i = 0;
  size_t j = 0;
  while (i < left_order.size() && j < right_order.size()) {
    const double l = left[left_order[i]];
    const double r = right[right_order[j]];
    const double difference = l - r;
    if (difference > tolerance) {
      ++j;  // The right message is too early for any remaining left one.
    } else if (difference < -tolerance) {
      ++i;
    } else if (j + 1 < right_order.size() &&
               std::abs(l - right[right_order[j + 1]]) < std::abs(difference)) {
      ++j;
    } else if (i + 1 < left_order.size() &&
               std::abs(left[left_order[i + 1]] - r) < std::abs(difference)) {
      ++i;
    } else {
      pairs.push_back({left_order[i], right_order[j]});
      ++i;
      ++j;
    }
  }
  return pairs;
}

// Message indices of `topic` sorted by stamp (stable: equal stamps keep the
// bag's order).
std::vector<size_t> StampOrder(const TopicMessages& topic) {
  std::vector<size_t> order(topic.stamps.size());
  std::iota(order.begin(), order.end(), size_t{0});
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    return topic.stamps[a] < topic.stamps[b];
  });
  return order;
}

class BagStereoSource final : public StereoImageSource {
 public:
  BagStereoSource(std::string path, BagStereoOptions options,
                  std::unique_ptr<rosbag::Bag> bag, TopicMessages left,
                  TopicMessages right, std::vector<Pair> pairs,
                  std::vector<size_t> selected, size_t num_unpaired)
      : path_(std::move(path)),
        options_(std::move(options)),
        bag_(std::move(bag)),
        left_(std::move(left)),
        right_(std::move(right)),
        pairs_(std::move(pairs)),
        selected_(std::move(selected)),
        num_unpaired_(num_unpaired) {}

  size_t NumPairs() const override { return selected_.size(); }

  StatusOr<StereoImagePair> ReadPair(size_t i) override {
    CHECK_LT(i, selected_.size()) << "pair index out of range";
    const size_t frame = selected_[i];
    const Pair& pair = pairs_[frame];
    StereoImagePair result;
    result.frame = static_cast<int64_t>(frame);
    result.timestamp = left_.stamps[pair.left];
    result.left_name = Name(options_.left_topic, left_.stamps[pair.left]);
    if (pair.right == kNoRight) {
      // One camera only: the right image and name stay empty.
      StatusOr<cv::Mat> left =
          Decode(left_.messages[pair.left], result.left_name);
      if (!left.ok()) return left.status();
      result.left = std::move(left).value();
      return result;
    }
    result.right_name = Name(options_.right_topic, right_.stamps[pair.right]);
    StatusOr<cv::Mat> left =
        Decode(left_.messages[pair.left], result.left_name);
    if (!left.ok()) return left.status();
    StatusOr<cv::Mat> right =
        Decode(right_.messages[pair.right], result.right_name);
    if (!right.ok()) return right.status();
    result.left = std::move(left).value();
    result.right = std::move(right).value();
    if (result.left.size() != result.right.size()) {
      return Status::Error(
          path_ + ": frame " + std::to_string(frame) + ": left image " +
          FormatSize(result.left) + " (" + result.left_name + ") but right " +
          FormatSize(result.right) + " (" + result.right_name + ")");
    }
    return result;
  }

  std::string Describe() const override {
    if (options_.left_only) {
      // "bag dive.bag (/cam0/image_raw, left camera only): 8 images".
      return "bag " + path_ + " (" + options_.left_topic +
             ", left camera only): " + Count(selected_.size(), "image") +
             SelectionText();
    }
    return "bag " + path_ + " (" + options_.left_topic + ", " +
           options_.right_topic + "): " + Count(selected_.size(), "pair") +
           SelectionText() + ", " + Count(num_unpaired_, "unpaired message");
  }

 private:
  // " (every 2nd of 240, 10.000 s to the end)", or "" without a selection.
  std::string SelectionText() const {
    std::string text;
    const FrameSelection& selection = options_.selection;
    if (selection.stride > 1 || selection.HasTimeRange()) {
      text += " (";
      if (selection.stride > 1) {
        text += "every " + Ordinal(selection.stride) + " ";
      }
      text += "of " + std::to_string(pairs_.size());
      if (selection.HasTimeRange()) {
        text += ", " + FormatFixed(selection.from_s.value_or(0.0), 3) +
                " s to " +
                (selection.to_s ? FormatFixed(*selection.to_s, 3) + " s"
                                : std::string("the end"));
      }
      text += ")";
    }
    return text;
  }

  static std::string Name(const std::string& topic, double stamp_s) {
    return StampedName(topic, stamp_s);
  }

  // A cut or damaged PNG or JPEG is refused before it is decoded: libpng
  // and libjpeg would print their own warnings.
  static StatusOr<cv::Mat> DecodeCompressed(
      const sensor_msgs::CompressedImage& message) {
    RCM_RETURN_IF_ERROR(
        CheckImageFileStructure(
            std::string_view(reinterpret_cast<const char*>(message.data.data()),
                             message.data.size()))
            .WithContext("compressed image"));
    return DecodeCompressedImage(message);
  }

  StatusOr<cv::Mat> Decode(const rosbag::MessageInstance& message,
                           const std::string& name) const {
    // Opening read every message as its type; a null message here would
    // be a bag changed since.
    StatusOr<cv::Mat> image = Status::Error(
        "the message does not deserialize as " + message.getDataType());
    try {
      if (message.getDataType() == kImageType) {
        const auto decoded = message.instantiate<sensor_msgs::Image>();
        if (decoded != nullptr) image = DecodeImage(*decoded);
      } else {
        const auto decoded =
            message.instantiate<sensor_msgs::CompressedImage>();
        if (decoded != nullptr) image = DecodeCompressed(*decoded);
      }
    } catch (const std::exception& error) {
      return Status::Error(path_ + ": " + name + ": cannot read the message (" +
                           OneLine(error) + ")");
    }
    if (!image.ok()) return image.status().WithContext(path_ + ": " + name);
    return image;
  }

  std::string path_;
  BagStereoOptions options_;
  // Open for reading while the source lives: the message instances point
  // into it.
  std::unique_ptr<rosbag::Bag> bag_;
  TopicMessages left_;
  TopicMessages right_;
  std::vector<Pair> pairs_;       // all pairs, in stamp order
  std::vector<size_t> selected_;  // indices into pairs_
  size_t num_unpaired_;
};

}  // namespace

Status BagStereoOptions::Check() const {
  if (left_only) {
    if (left_topic.empty()) {
      return Status::Error("one camera's images need its (left) image topic");
    }
    if (!right_topic.empty()) {
      return Status::Error(
          "one camera's images are read from the left topic alone, got a "
          "right topic too (" +
          right_topic + ")");
    }
  } else if (left_topic.empty() || right_topic.empty()) {
    return Status::Error("a bag needs a left and a right image topic");
  } else if (left_topic == right_topic) {
    return Status::Error("left and right topic are both " + left_topic);
  }
  if (!std::isfinite(stamp_tolerance_s) || stamp_tolerance_s < 0.0) {
    return Status::Error(
        "stamp tolerance must be a finite number of seconds >= 0, got " +
        FormatDouble(stamp_tolerance_s));
  }
  return selection.Check();
}

StatusOr<std::unique_ptr<StereoImageSource>> OpenBagStereoSource(
    const std::string& path, const BagStereoOptions& options) {
  RCM_RETURN_IF_ERROR(options.Check());
  // rosbag's own errors for these name no reason.
  RCM_RETURN_IF_ERROR(CheckBagFileExists(path));

  auto bag = std::make_unique<rosbag::Bag>();
  TopicMessages left;
  TopicMessages right;
  try {
    bag->open(path, rosbag::bagmode::Read);
    const BagTopicTypes types = ReadTopicTypes(*bag);
    RCM_RETURN_IF_ERROR(CheckImageTopic(path, options.left_topic, types));
    std::vector<std::string> topics = {options.left_topic};
    if (!options.left_only) {
      RCM_RETURN_IF_ERROR(CheckImageTopic(path, options.right_topic, types));
      topics.push_back(options.right_topic);
    }

    rosbag::View view(*bag, rosbag::TopicQuery(topics));
    for (const rosbag::MessageInstance& message : view) {
      const StatusOr<double> stamp = HeaderStamp(message);
      if (!stamp.ok()) {
        return stamp.status().WithContext(path + ": " + message.getTopic());
      }
      TopicMessages& topic =
          message.getTopic() == options.left_topic ? left : right;
      topic.messages.push_back(message);
      topic.stamps.push_back(*stamp);
    }
  } catch (...) {
    return UnreadableBagError(path);
  }

  for (const auto& [topic, messages] :
       {std::pair{&options.left_topic, &left},
        std::pair{&options.right_topic, &right}}) {
    // (left_only: no right topic, no right messages.)
    if (messages->stamps.empty() && !topic->empty()) {
      return Status::Error(path + ": no messages on " + *topic);
    }
  }
  const std::vector<size_t> left_order = StampOrder(left);
  const std::vector<size_t> right_order = StampOrder(right);
  std::vector<Pair> pairs;
  if (options.left_only) {
    for (const size_t i : left_order) pairs.push_back({i, kNoRight});
  } else {
    pairs = PairByStamp(left.stamps, left_order, right.stamps, right_order,
                        options.stamp_tolerance_s);
  }
  if (pairs.empty()) {
    return Status::Error(
        path + ": no left/right messages within " +
        FormatDouble(options.stamp_tolerance_s) + " s of each other (" +
        std::to_string(left.stamps.size()) + " on " + options.left_topic +
        ", " + std::to_string(right.stamps.size()) + " on " +
        options.right_topic + "; first stamps " +
        FormatStamp(left.stamps[left_order.front()]) + " and " +
        FormatStamp(right.stamps[right_order.front()]) +
        "); raise --stamp-tolerance");
  }
  const size_t num_unpaired =
      options.left_only
          ? 0
          : left.stamps.size() + right.stamps.size() - 2 * pairs.size();

  std::vector<double> timestamps;
  timestamps.reserve(pairs.size());
  for (const Pair& pair : pairs) timestamps.push_back(left.stamps[pair.left]);
  StatusOr<std::vector<size_t>> selected =
      SelectFrames(timestamps, pairs.size(), options.selection);
  if (!selected.ok()) return selected.status().WithContext(path);

  return std::unique_ptr<StereoImageSource>(std::make_unique<BagStereoSource>(
      path, options, std::move(bag), std::move(left), std::move(right),
      std::move(pairs), std::move(selected).value(), num_unpaired));
}

}  // namespace rcm
