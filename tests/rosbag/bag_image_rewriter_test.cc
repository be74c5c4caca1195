#include "rcm/rosbag/bag_image_rewriter.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <ros/serialization.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/CompressedImage.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/Imu.h>
#include <std_msgs/String.h>
#include <yaml-cpp/yaml.h>

#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <set>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "rcm/rosbag/bag_image_writer.h"
#include "rcm/rosbag/bag_stereo_source.h"
#include "support/temp_file.h"
#include "support/test_rigs.h"

namespace rcm::bag_image_rewriter_test {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;
using ::testing::Not;
using ::testing::StartsWith;

constexpr char kCam0[] = "/cam0/image_raw";             // Image, mono8
constexpr char kCam1[] = "/cam1/image_raw/compressed";  // png, colour
constexpr char kCam0Info[] = "/cam0/camera_info";       // in the input
constexpr char kCam1Info[] = "/cam1/camera_info";       // not in the input
constexpr char kImu[] = "/imu";
constexpr char kStatus[] = "/status";  // latched std_msgs/String

constexpr int kFrames = 4;
constexpr int kImuMessages = 20;

// 64x48 noise of `type` from a fixed seed.
cv::Mat TestImage(int type, int seed, cv::Size size = cv::Size(64, 48)) {
  cv::Mat image(size, type);
  cv::RNG rng(static_cast<uint64_t>(seed));
  rng.fill(image, cv::RNG::UNIFORM, 0, 256);
  return image;
}

// Bag time of frame k, and its header stamp, 1 ms earlier (a camera
// driver stamps before the recorder receives): both must be kept.
ros::Time FrameTime(int k) { return ros::Time(1000.0 + 0.25 * k); }
ros::Time FrameStamp(int k) { return ros::Time(1000.0 + 0.25 * k - 0.001); }

// A recorder's connection header: `callerid` and `latching` besides the
// type fields rosbag needs.
template <typename Message>
boost::shared_ptr<ros::M_string> ConnectionHeader(const std::string& callerid,
                                                  bool latching) {
  auto header = boost::make_shared<ros::M_string>();
  (*header)["type"] = ros::message_traits::datatype<Message>();
  (*header)["md5sum"] = ros::message_traits::md5sum<Message>();
  (*header)["message_definition"] = ros::message_traits::definition<Message>();
  (*header)["callerid"] = callerid;
  (*header)["latching"] = latching ? "1" : "0";
  return header;
}

std_msgs::Header ImageHeader(int k, const std::string& frame_id) {
  std_msgs::Header header;
  header.seq = 100 + k;
  header.stamp = FrameStamp(k);
  header.frame_id = frame_id;
  return header;
}

cv::Mat Cam0Image(int k) { return TestImage(CV_8UC1, k); }
cv::Mat Cam1Image(int k) { return TestImage(CV_8UC3, 50 + k); }

sensor_msgs::Image MonoMessage(int k) {
  const cv::Mat image = Cam0Image(k);
  sensor_msgs::Image message;
  message.header = ImageHeader(k, "cam0");
  message.height = image.rows;
  message.width = image.cols;
  message.encoding = "mono8";
  message.step = image.cols;
  message.data.assign(image.data, image.data + image.total());
  return message;
}

sensor_msgs::CompressedImage PngMessage(int k) {
  sensor_msgs::CompressedImage message;
  message.header = ImageHeader(k, "cam1");
  message.format = "bgr8; png compressed bgr8";
  cv::imencode(".png", Cam1Image(k), message.data);
  return message;
}

// The camera_info a driver published with the raw images; width 1 marks
// it, so that none may survive the rewrite.
sensor_msgs::CameraInfo OldCameraInfo(int k) {
  sensor_msgs::CameraInfo message;
  message.header = ImageHeader(k, "cam0");
  message.width = 1;
  message.height = 1;
  message.distortion_model = "old";
  return message;
}

// The input of most tests: kFrames frames on kCam0 (mono8) and kCam1
// (png), the old camera_info of cam0, kImuMessages IMU messages at 20 Hz
// from a node, and one latched status message.
std::string WriteInputBag() {
  const std::string path = test::TempFilePath("in.bag");
  rosbag::Bag bag(path, rosbag::bagmode::Write);
  std_msgs::String status;
  status.data = "ready";
  bag.write(kStatus, ros::Time(999.5), status,
            ConnectionHeader<std_msgs::String>("/supervisor", true));
  const auto driver = ConnectionHeader<sensor_msgs::Image>("/driver", false);
  for (int j = 0; j < kImuMessages; ++j) {
    sensor_msgs::Imu imu;
    imu.header.seq = j;
    imu.header.stamp = ros::Time(999.9 + 0.05 * j);
    imu.linear_acceleration.z = 9.81 + 0.001 * j;
    bag.write(kImu, imu.header.stamp, imu,
              ConnectionHeader<sensor_msgs::Imu>("/imu_node", false));
  }
  for (int k = 0; k < kFrames; ++k) {
    bag.write(kCam0, FrameTime(k), MonoMessage(k), driver);
    bag.write(kCam1, FrameTime(k), PngMessage(k));
    bag.write(kCam0Info, FrameTime(k), OldCameraInfo(k));
  }
  bag.close();
  return path;
}

// A camera for the camera_info of the rewritten images.
CameraInfo OutputCameraInfo(const std::string& name) {
  CameraInfo info =
      CameraInfoFromCamera(name, Camera::Create(LensModelId::kPinhole, 64, 48,
                                                {50.0, 50.5, 31.5, 23.5}, {})
                                     .value());
  info.projection(0, 3) = -5.5;  // so that P differs from [K | 0]
  return info;
}

std::vector<BagImageRewriteTopic> Topics() {
  return {{kCam0, kCam0Info, OutputCameraInfo("cam0")},
          {kCam1, kCam1Info, OutputCameraInfo("cam1")}};
}

// Inverts every pixel.
StatusOr<cv::Mat> Invert(size_t /*topic_index*/, const cv::Mat& image) {
  cv::Mat inverted;
  cv::bitwise_not(image, inverted);
  return inverted;
}

cv::Mat Inverted(const cv::Mat& image) {
  cv::Mat inverted;
  cv::bitwise_not(image, inverted);
  return inverted;
}

// One message of a bag, as read back.
struct Recorded {
  std::string topic;
  ros::Time time;
  std::string datatype;
  std::string md5sum;
  ros::M_string connection_header;
  std::vector<uint8_t> bytes;  // serialized
  rosbag::MessageInstance instance;
};

// Every message of the bag `path` in bag order; `bag` stays open for
// the instances.
std::vector<Recorded> ReadMessages(rosbag::Bag& bag, const std::string& path) {
  bag.open(path, rosbag::bagmode::Read);
  std::vector<Recorded> messages;
  rosbag::View view(bag);
  for (const rosbag::MessageInstance& m : view) {
    std::vector<uint8_t> bytes(m.size());
    ros::serialization::OStream stream(bytes.data(), bytes.size());
    m.write(stream);
    messages.push_back({m.getTopic(), m.getTime(), m.getDataType(),
                        m.getMD5Sum(), *m.getConnectionHeader(), bytes, m});
  }
  return messages;
}

std::vector<Recorded> OnTopics(const std::vector<Recorded>& messages,
                               const std::set<std::string>& topics, bool keep) {
  std::vector<Recorded> selected;
  for (const Recorded& m : messages) {
    if ((topics.count(m.topic) > 0) == keep) selected.push_back(m);
  }
  return selected;
}

// Names of the files in the test's temporary directory that start with
// the file name of `path` (the output and its temporary files).
std::vector<std::string> FilesOf(const std::string& path) {
  const std::string prefix = std::filesystem::path(path).filename().string();
  std::vector<std::string> names;
  for (const auto& entry :
       std::filesystem::directory_iterator(::testing::TempDir())) {
    const std::string name = entry.path().filename().string();
    if (name.rfind(prefix, 0) == 0) names.push_back(name);
  }
  return names;
}

StatusOr<BagRewriteSummary> Rewrite(const std::string& input,
                                    const std::string& output) {
  return RewriteBagImages(input, output, Topics(), Invert);
}

class BagImageRewriter : public ::testing::Test {
 protected:
  void SetUp() override {
    input_ = WriteInputBag();
    output_ = test::TempFilePath("out.bag");
  }
  void TearDown() override {
    std::remove(input_.c_str());
    std::remove(output_.c_str());
  }

  std::string input_;
  std::string output_;
};

TEST_F(BagImageRewriter, CopiesOtherTopicsUnchanged) {
  const StatusOr<BagRewriteSummary> summary = Rewrite(input_, output_);
  ASSERT_TRUE(summary.ok()) << summary.status().message();
  rosbag::Bag in_bag;
  rosbag::Bag out_bag;
  const std::set<std::string> camera_topics = {kCam0, kCam1, kCam0Info,
                                               kCam1Info};
  const std::vector<Recorded> in =
      OnTopics(ReadMessages(in_bag, input_), camera_topics, false);
  const std::vector<Recorded> out =
      OnTopics(ReadMessages(out_bag, output_), camera_topics, false);
  ASSERT_EQ(in.size(), static_cast<size_t>(kImuMessages + 1));
  ASSERT_EQ(out.size(), in.size());
  for (size_t i = 0; i < in.size(); ++i) {
    EXPECT_EQ(out[i].topic, in[i].topic) << i;
    EXPECT_EQ(out[i].time, in[i].time) << i;
    EXPECT_EQ(out[i].datatype, in[i].datatype) << i;
    EXPECT_EQ(out[i].md5sum, in[i].md5sum) << i;
    EXPECT_EQ(out[i].bytes, in[i].bytes) << i;
    // Callerid and latching too.
    EXPECT_EQ(out[i].connection_header, in[i].connection_header) << i;
  }
  EXPECT_EQ(out[0].topic, kStatus);
  EXPECT_EQ(out[0].connection_header.at("latching"), "1");
  EXPECT_EQ(out[1].connection_header.at("callerid"), "/imu_node");
  EXPECT_EQ(summary->copied_messages, kImuMessages + 1);
}

TEST_F(BagImageRewriter, RewritesImagesKeepingHeadersTimesAndTypes) {
  const StatusOr<BagRewriteSummary> summary = Rewrite(input_, output_);
  ASSERT_TRUE(summary.ok()) << summary.status().message();
  EXPECT_EQ(summary->images, (std::vector<int64_t>{kFrames, kFrames}));
  rosbag::Bag in_bag;
  rosbag::Bag out_bag;
  const std::vector<Recorded> all_in = ReadMessages(in_bag, input_);
  const std::vector<Recorded> all_out = ReadMessages(out_bag, output_);

  const std::vector<Recorded> cam0_in = OnTopics(all_in, {kCam0}, true);
  const std::vector<Recorded> cam0 = OnTopics(all_out, {kCam0}, true);
  ASSERT_EQ(cam0.size(), static_cast<size_t>(kFrames));
  for (int k = 0; k < kFrames; ++k) {
    EXPECT_EQ(cam0[k].time, FrameTime(k));
    EXPECT_EQ(cam0[k].connection_header, cam0_in[k].connection_header);
    const auto image = cam0[k].instance.instantiate<sensor_msgs::Image>();
    ASSERT_NE(image, nullptr);
    EXPECT_EQ(image->header, ImageHeader(k, "cam0"));
    EXPECT_EQ(image->encoding, "mono8");
    EXPECT_EQ(image->width, 64u);
    EXPECT_EQ(image->height, 48u);
    EXPECT_EQ(image->step, 64u);
    const cv::Mat expected = Inverted(Cam0Image(k));
    EXPECT_EQ(
        image->data,
        std::vector<uint8_t>(expected.data, expected.data + expected.total()));
  }

  const std::vector<Recorded> cam1 = OnTopics(all_out, {kCam1}, true);
  ASSERT_EQ(cam1.size(), static_cast<size_t>(kFrames));
  for (int k = 0; k < kFrames; ++k) {
    EXPECT_EQ(cam1[k].time, FrameTime(k));
    const auto image =
        cam1[k].instance.instantiate<sensor_msgs::CompressedImage>();
    ASSERT_NE(image, nullptr);
    EXPECT_EQ(image->header, ImageHeader(k, "cam1"));
    EXPECT_EQ(image->format, "bgr8; png compressed bgr8");
    const cv::Mat decoded = cv::imdecode(image->data, cv::IMREAD_UNCHANGED);
    ASSERT_EQ(decoded.type(), CV_8UC3);
    EXPECT_EQ(cv::norm(decoded, Inverted(Cam1Image(k)), cv::NORM_INF), 0.0);
  }
}

TEST_F(BagImageRewriter, WritesCameraInfoWithEachImageAndDropsTheOldOnes) {
  const StatusOr<BagRewriteSummary> summary = Rewrite(input_, output_);
  ASSERT_TRUE(summary.ok()) << summary.status().message();
  EXPECT_EQ(summary->dropped_camera_infos, kFrames);
  rosbag::Bag out_bag;
  const std::vector<Recorded> all_out = ReadMessages(out_bag, output_);
  for (const auto& [info_topic, frame_id] :
       {std::pair{kCam0Info, "cam0"}, std::pair{kCam1Info, "cam1"}}) {
    const std::vector<Recorded> infos = OnTopics(all_out, {info_topic}, true);
    ASSERT_EQ(infos.size(), static_cast<size_t>(kFrames)) << info_topic;
    const CameraInfo expected = OutputCameraInfo(frame_id);
    for (int k = 0; k < kFrames; ++k) {
      EXPECT_EQ(infos[k].time, FrameTime(k));
      const auto info =
          infos[k].instance.instantiate<sensor_msgs::CameraInfo>();
      ASSERT_NE(info, nullptr);
      EXPECT_EQ(info->header, ImageHeader(k, frame_id));
      EXPECT_EQ(info->width, 64u);
      EXPECT_EQ(info->height, 48u);
      EXPECT_EQ(info->distortion_model, "plumb_bob");
      EXPECT_EQ(info->D, std::vector<double>(5, 0.0));
      EXPECT_THAT(info->K,
                  ElementsAre(50.0, 0.0, 31.5, 0.0, 50.5, 23.5, 0.0, 0.0, 1.0));
      EXPECT_THAT(info->R,
                  ElementsAre(1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0));
      EXPECT_THAT(info->P, ElementsAre(50.0, 0.0, 31.5, -5.5, 0.0, 50.5, 23.5,
                                       0.0, 0.0, 0.0, 1.0, 0.0));
    }
  }
}

TEST_F(BagImageRewriter, ReportsProgressPerInputMessage) {
  std::vector<int64_t> done;
  int64_t total = -1;
  const StatusOr<BagRewriteSummary> summary = RewriteBagImages(
      input_, output_, Topics(), Invert, [&](int64_t d, int64_t t) {
        done.push_back(d);
        total = t;
      });
  ASSERT_TRUE(summary.ok()) << summary.status().message();
  const int64_t messages = 1 + kImuMessages + 3 * kFrames;
  EXPECT_EQ(total, messages);
  ASSERT_EQ(done.size(), static_cast<size_t>(messages));
  for (int64_t i = 0; i < messages; ++i) EXPECT_EQ(done[i], i + 1);
}

TEST_F(BagImageRewriter, OutputReadsAsAStereoSource) {
  ASSERT_TRUE(Rewrite(input_, output_).ok());
  BagStereoOptions options;
  options.left_topic = kCam0;
  options.right_topic = kCam1;
  StatusOr<std::unique_ptr<StereoImageSource>> source =
      OpenBagStereoSource(output_, options);
  ASSERT_TRUE(source.ok()) << source.status().message();
  ASSERT_EQ((*source)->NumPairs(), static_cast<size_t>(kFrames));
  for (int k = 0; k < kFrames; ++k) {
    const StatusOr<StereoImagePair> pair = (*source)->ReadPair(k);
    ASSERT_TRUE(pair.ok()) << pair.status().message();
    EXPECT_EQ(*pair->timestamp, FrameStamp(k).toSec());
    EXPECT_EQ(cv::norm(pair->left, Inverted(Cam0Image(k)), cv::NORM_INF), 0.0);
    EXPECT_EQ(cv::norm(pair->right, Inverted(Cam1Image(k)), cv::NORM_INF), 0.0);
  }
}

TEST_F(BagImageRewriter, WithoutCameraInfoTopicWritesNoneAndKeepsTheOldOnes) {
  std::vector<BagImageRewriteTopic> topics = Topics();
  topics[0].camera_info_topic.clear();
  topics.pop_back();
  const StatusOr<BagRewriteSummary> summary =
      RewriteBagImages(input_, output_, topics, Invert);
  ASSERT_TRUE(summary.ok()) << summary.status().message();
  EXPECT_EQ(summary->dropped_camera_infos, 0);
  EXPECT_EQ(summary->copied_messages, 1 + kImuMessages + 2 * kFrames);
  rosbag::Bag out_bag;
  const std::vector<Recorded> infos =
      OnTopics(ReadMessages(out_bag, output_), {kCam0Info, kCam1Info}, true);
  ASSERT_EQ(infos.size(), static_cast<size_t>(kFrames));
  EXPECT_EQ(infos[0].instance.instantiate<sensor_msgs::CameraInfo>()->width,
            1u);
}

TEST_F(BagImageRewriter, ColourImageIsWrittenBgr8AndJpegStaysJpeg) {
  const std::string input = test::TempFilePath("formats.bag");
  const std::string& output = output_;
  const cv::Mat bgr = TestImage(CV_8UC3, 7);
  cv::Mat smooth = TestImage(CV_8UC1, 8);
  cv::GaussianBlur(smooth, smooth, cv::Size(9, 9), 3.0);
  {
    rosbag::Bag bag(input, rosbag::bagmode::Write);
    sensor_msgs::Image rgb;
    rgb.header = ImageHeader(0, "colour");
    rgb.width = bgr.cols;
    rgb.height = bgr.rows;
    rgb.encoding = "rgb8";
    rgb.step = bgr.cols * 3;
    cv::Mat rgb_pixels;
    cv::cvtColor(bgr, rgb_pixels, cv::COLOR_BGR2RGB);
    rgb.data.assign(rgb_pixels.data, rgb_pixels.data + 3 * bgr.total());
    bag.write("/colour", FrameTime(0), rgb);
    sensor_msgs::CompressedImage jpeg;
    jpeg.header = ImageHeader(0, "mono");
    jpeg.format = "jpeg";
    cv::imencode(".jpg", smooth, jpeg.data);
    bag.write("/mono/compressed", FrameTime(0), jpeg);
  }
  // The camera_info of the halved mono images.
  const CameraInfo half_size_info =
      CameraInfoFromCamera("m", Camera::Create(LensModelId::kPinhole, 32, 24,
                                               {25.0, 25.25, 15.5, 11.5}, {})
                                    .value());
  // Halves the mono image, keeps the colour one.
  const BagImageTransform transform =
      [](size_t index, const cv::Mat& image) -> StatusOr<cv::Mat> {
    if (index == 0) return image.clone();
    cv::Mat half;
    cv::resize(image, half, cv::Size(), 0.5, 0.5, cv::INTER_AREA);
    return half;
  };
  const StatusOr<BagRewriteSummary> summary = RewriteBagImages(
      input, output,
      {{"/colour", "", OutputCameraInfo("c")},
       {"/mono/compressed", "/mono/camera_info", half_size_info}},
      transform);
  ASSERT_TRUE(summary.ok()) << summary.status().message();

  rosbag::Bag bag;
  const std::vector<Recorded> out = ReadMessages(bag, output);
  const auto colour = OnTopics(out, {"/colour"}, true)
                          .at(0)
                          .instance.instantiate<sensor_msgs::Image>();
  ASSERT_NE(colour, nullptr);
  EXPECT_EQ(colour->encoding, "bgr8");
  EXPECT_EQ(colour->data,
            std::vector<uint8_t>(bgr.data, bgr.data + 3 * bgr.total()));
  const auto mono = OnTopics(out, {"/mono/compressed"}, true)
                        .at(0)
                        .instance.instantiate<sensor_msgs::CompressedImage>();
  ASSERT_NE(mono, nullptr);
  EXPECT_EQ(mono->header, ImageHeader(0, "mono"));
  EXPECT_EQ(mono->format, "mono8; jpeg compressed mono8");
  ASSERT_GE(mono->data.size(), 2u);
  EXPECT_EQ(mono->data[0], 0xff);
  EXPECT_EQ(mono->data[1], 0xd8);
  const cv::Mat decoded = cv::imdecode(mono->data, cv::IMREAD_UNCHANGED);
  ASSERT_EQ(decoded.type(), CV_8UC1);
  EXPECT_EQ(decoded.size(), cv::Size(32, 24));
  EXPECT_EQ(OnTopics(out, {"/mono/camera_info"}, true).size(), 1u);
  bag.close();
  std::remove(input.c_str());
}

// --- Errors
// ----------------------------------------------------------------------

TEST_F(BagImageRewriter, ImageOfAnotherSizeThanItsCameraInfoFails) {
  const BagImageTransform halve =
      [](size_t, const cv::Mat& image) -> StatusOr<cv::Mat> {
    cv::Mat half;
    cv::resize(image, half, cv::Size(), 0.5, 0.5, cv::INTER_AREA);
    return half;
  };
  const StatusOr<BagRewriteSummary> summary =
      RewriteBagImages(input_, output_, Topics(), halve);
  ASSERT_FALSE(summary.ok());
  EXPECT_NE(summary.status().message().find(
                "returned a 32x24 image, but its camera_info is for 64x48"),
            std::string::npos)
      << summary.status().message();
  EXPECT_TRUE(FilesOf(output_).empty());
}

TEST_F(BagImageRewriter, MissingInputFails) {
  const std::string missing = test::TempFilePath("missing.bag");
  const StatusOr<BagRewriteSummary> summary = Rewrite(missing, output_);
  ASSERT_FALSE(summary.ok());
  EXPECT_EQ(summary.status().message(),
            missing + ": cannot open: No such file or directory");
  EXPECT_TRUE(FilesOf(output_).empty());
}

TEST_F(BagImageRewriter, OutputEqualToInputFails) {
  const uintmax_t size = std::filesystem::file_size(input_);
  const std::filesystem::path input(input_);
  const std::string other_spelling =
      (input.parent_path() / "." / input.filename()).string();
  for (const std::string& output : {input_, other_spelling}) {
    const StatusOr<BagRewriteSummary> summary = Rewrite(input_, output);
    ASSERT_FALSE(summary.ok());
    EXPECT_EQ(summary.status().message(),
              output +
                  ": is the input bag; write the rewritten bag to another "
                  "file");
  }
  EXPECT_EQ(std::filesystem::file_size(input_), size);
}

TEST_F(BagImageRewriter, UnknownTopicListsTheImageTopics) {
  std::vector<BagImageRewriteTopic> topics = Topics();
  topics[1].image_topic = "/cam1/image_raw";
  const StatusOr<BagRewriteSummary> summary =
      RewriteBagImages(input_, output_, topics, Invert);
  ASSERT_FALSE(summary.ok());
  EXPECT_EQ(summary.status().message(),
            input_ +
                ": no topic /cam1/image_raw (image topics in the bag: "
                "/cam0/image_raw [sensor_msgs/Image], "
                "/cam1/image_raw/compressed [sensor_msgs/CompressedImage])");
  EXPECT_TRUE(FilesOf(output_).empty());
}

TEST_F(BagImageRewriter, TopicOfAnotherTypeFails) {
  std::vector<BagImageRewriteTopic> topics = Topics();
  topics[1].image_topic = kImu;
  StatusOr<BagRewriteSummary> summary =
      RewriteBagImages(input_, output_, topics, Invert);
  ASSERT_FALSE(summary.ok());
  EXPECT_EQ(summary.status().message(),
            input_ +
                ": topic /imu has type sensor_msgs/Imu, expected "
                "sensor_msgs/Image or sensor_msgs/CompressedImage");

  topics = Topics();
  topics[1].camera_info_topic = kStatus;
  summary = RewriteBagImages(input_, output_, topics, Invert);
  ASSERT_FALSE(summary.ok());
  EXPECT_EQ(summary.status().message(),
            input_ +
                ": camera_info topic /status has type std_msgs/String, "
                "expected sensor_msgs/CameraInfo");
  EXPECT_TRUE(FilesOf(output_).empty());
}

TEST_F(BagImageRewriter, RejectsBadTopicLists) {
  const auto error = [&](const std::vector<BagImageRewriteTopic>& topics) {
    const StatusOr<BagRewriteSummary> summary =
        RewriteBagImages(input_, output_, topics, Invert);
    return summary.ok() ? std::string() : summary.status().message();
  };
  EXPECT_EQ(error({}), input_ + ": no image topic to rewrite");
  std::vector<BagImageRewriteTopic> topics = Topics();
  topics[1].image_topic.clear();
  EXPECT_EQ(error(topics), input_ + ": an image topic to rewrite is empty");
  topics = Topics();
  topics[1].image_topic = kCam0;
  EXPECT_EQ(error(topics),
            input_ + ": image topic /cam0/image_raw is given twice");
  topics = Topics();
  topics[1].camera_info_topic = kCam0;
  EXPECT_EQ(error(topics), input_ +
                               ": camera_info topic /cam0/image_raw is also "
                               "an image topic to rewrite");
  topics = Topics();
  topics[1].camera_info_topic = kCam0Info;
  EXPECT_EQ(error(topics),
            input_ + ": camera_info topic /cam0/camera_info is given twice");
  EXPECT_TRUE(FilesOf(output_).empty());
}

TEST_F(BagImageRewriter, TransformErrorLeavesNoOutput) {
  // Fails on cam0's second frame, after images were written.
  int cam0_calls = 0;
  const BagImageTransform fail_second =
      [&cam0_calls](size_t index, const cv::Mat& image) -> StatusOr<cv::Mat> {
    if (index == 0 && ++cam0_calls == 2) return Status::Error("remap failed");
    return image.clone();
  };
  StatusOr<BagRewriteSummary> summary =
      RewriteBagImages(input_, output_, Topics(), fail_second);
  ASSERT_FALSE(summary.ok());
  EXPECT_EQ(summary.status().message(),
            input_ + ": /cam0/image_raw @ 1000.249000: remap failed");
  EXPECT_TRUE(FilesOf(output_).empty());

  // cam1's images pass: the cam0 image of the first frame fails.
  const BagImageTransform throws =
      [](size_t index, const cv::Mat& image) -> StatusOr<cv::Mat> {
    if (index == 0) throw std::runtime_error("out of\nmemory");
    return image.clone();
  };
  summary = RewriteBagImages(input_, output_, Topics(), throws);
  ASSERT_FALSE(summary.ok());
  EXPECT_EQ(summary.status().message(),
            input_ +
                ": /cam0/image_raw @ 999.999000: the transform threw: out of "
                "memory");
  EXPECT_TRUE(FilesOf(output_).empty());

  const BagImageTransform to_float =
      [](size_t index, const cv::Mat& image) -> StatusOr<cv::Mat> {
    if (index == 1) return image.clone();
    cv::Mat result;
    image.convertTo(result, CV_32F);
    return result;
  };
  summary = RewriteBagImages(input_, output_, Topics(), to_float);
  ASSERT_FALSE(summary.ok());
  EXPECT_EQ(summary.status().message(),
            input_ +
                ": /cam0/image_raw @ 999.999000: the transform returned a "
                "CV_32FC1 image, expected CV_8UC1 or CV_8UC3");
  EXPECT_TRUE(FilesOf(output_).empty());
}

TEST_F(BagImageRewriter, UnwritableOutputDirectoryFails) {
  const std::string output = test::TempFilePath("no_such_dir") + "/out.bag";
  const StatusOr<BagRewriteSummary> summary = Rewrite(input_, output);
  ASSERT_FALSE(summary.ok());
  EXPECT_EQ(summary.status().message(),
            output + ": cannot write: No such file or directory");

  const StatusOr<BagRewriteSummary> over_directory =
      Rewrite(input_, ::testing::TempDir());
  ASSERT_FALSE(over_directory.ok());
  EXPECT_EQ(over_directory.status().message(),
            ::testing::TempDir() + ": cannot write: Is a directory");
}

TEST_F(BagImageRewriter, TruncatedInputFailsAndLeavesNoOutput) {
  const uintmax_t size = std::filesystem::file_size(input_);
  const std::string cut = test::TempFilePath("cut.bag");
  for (const uintmax_t length : {size / 2, size - 1, uintmax_t{20}}) {
    std::filesystem::copy_file(
        input_, cut, std::filesystem::copy_options::overwrite_existing);
    std::filesystem::resize_file(cut, length);
    const StatusOr<BagRewriteSummary> summary = Rewrite(cut, output_);
    ASSERT_FALSE(summary.ok()) << length;
    EXPECT_THAT(summary.status().message(),
                StartsWith(cut + ": not a readable ROS1 bag ("));
    EXPECT_THAT(summary.status().message(), Not(HasSubstr("\n")));
    EXPECT_TRUE(FilesOf(output_).empty());
  }
  std::remove(cut.c_str());

  const std::string text = test::WriteTempFile("text.bag", "not a bag\n");
  const StatusOr<BagRewriteSummary> summary = Rewrite(text, output_);
  ASSERT_FALSE(summary.ok());
  EXPECT_THAT(summary.status().message(),
              StartsWith(text + ": not a readable ROS1 bag ("));
  std::remove(text.c_str());
}

TEST_F(BagImageRewriter, CorruptImageIsNamedByTopicAndStamp) {
  const std::string input = test::TempFilePath("corrupt.bag");
  {
    rosbag::Bag bag(input, rosbag::bagmode::Write);
    bag.write(kCam0, FrameTime(0), MonoMessage(0));
    sensor_msgs::CompressedImage corrupt = PngMessage(0);
    corrupt.data = {0x89, 'P', 'N', 'G', 0};
    bag.write(kCam1, FrameTime(0), corrupt);
  }
  const StatusOr<BagRewriteSummary> summary = Rewrite(input, output_);
  ASSERT_FALSE(summary.ok());
  EXPECT_EQ(summary.status().message(),
            input +
                ": /cam1/image_raw/compressed @ 999.999000: compressed image "
                "(format 'bgr8; png compressed bgr8', 5 bytes) is corrupt or "
                "not a format OpenCV decodes");
  EXPECT_TRUE(FilesOf(output_).empty());
  std::remove(input.c_str());
}

TEST_F(BagImageRewriter, CompressedFormatOtherThanPngOrJpegFails) {
  const std::string input = test::TempFilePath("bmp.bag");
  {
    rosbag::Bag bag(input, rosbag::bagmode::Write);
    bag.write(kCam0, FrameTime(0), MonoMessage(0));
    sensor_msgs::CompressedImage bmp = PngMessage(0);
    bmp.format = "bmp";
    cv::imencode(".bmp", Cam1Image(0), bmp.data);
    bag.write(kCam1, FrameTime(0), bmp);
  }
  const StatusOr<BagRewriteSummary> summary = Rewrite(input, output_);
  ASSERT_FALSE(summary.ok());
  EXPECT_EQ(summary.status().message(),
            input +
                ": /cam1/image_raw/compressed @ 999.999000: compressed image "
                "(format 'bmp') is neither png nor jpeg, the formats rcm "
                "rewrites");
  EXPECT_TRUE(FilesOf(output_).empty());
  std::remove(input.c_str());
}

// --- BagImageWriter::WriteCameraInfo
// ----------------------------------------------

// A rectified right camera: R a rotation, P with Tx.
CameraInfo RightCameraInfo(const Camera& camera) {
  CameraInfo info = CameraInfoFromCamera("right", camera);
  info.rectification << 0.9998, -0.0175, 0.0087, 0.0174, 0.9998, 0.0052,
      -0.0088, -0.0050, 0.9999;
  info.projection << 345.5, 0.0, 352.25, -38.005, 0.0, 345.5, 268.5, 0.25, 0.0,
      0.0, 1.0, 0.0;
  return info;
}

TEST(BagImageWriter, WritesCameraInfo) {
  const std::string path = test::TempFilePath("camera_info.bag");
  const std::vector<Camera> cameras = {
      test::EurocRadtanCamera(), test::AlphasenseCam1(), test::PinholeCamera()};
  StatusOr<BagImageWriter> writer = BagImageWriter::Create(path);
  ASSERT_TRUE(writer.ok()) << writer.status().message();
  for (size_t i = 0; i < cameras.size(); ++i) {
    ASSERT_TRUE(writer
                    ->WriteCameraInfo("/cam1/camera_info", 1000.5 + i,
                                      RightCameraInfo(cameras[i]), "cam1")
                    .ok());
  }
  ASSERT_TRUE(writer->Close().ok());

  rosbag::Bag bag(path);
  rosbag::View view(bag);
  ASSERT_EQ(view.size(), cameras.size());
  size_t i = 0;
  for (const rosbag::MessageInstance& m : view) {
    const Camera& camera = cameras[i];
    const CameraInfo info = RightCameraInfo(camera);
    EXPECT_EQ(m.getTopic(), "/cam1/camera_info");
    EXPECT_EQ(m.getTime(), ros::Time(1000.5 + i));
    const auto message = m.instantiate<sensor_msgs::CameraInfo>();
    ASSERT_NE(message, nullptr);
    EXPECT_EQ(message->header.seq, 0u);
    EXPECT_EQ(message->header.stamp, ros::Time(1000.5 + i));
    EXPECT_EQ(message->header.frame_id, "cam1");
    EXPECT_EQ(message->width, static_cast<uint32_t>(camera.width()));
    EXPECT_EQ(message->height, static_cast<uint32_t>(camera.height()));
    // distortion_model and D as the camera_info file has them.
    const YAML::Node file = YAML::Load(FormatCameraInfo(info));
    EXPECT_EQ(message->distortion_model,
              file["distortion_model"].as<std::string>());
    EXPECT_EQ(
        message->D,
        file["distortion_coefficients"]["data"].as<std::vector<double>>());
    EXPECT_THAT(message->K,
                ElementsAre(camera.fx(), 0.0, camera.cx(), 0.0, camera.fy(),
                            camera.cy(), 0.0, 0.0, 1.0));
    for (int j = 0; j < 9; ++j) {
      EXPECT_EQ(message->R[j], info.rectification(j / 3, j % 3)) << j;
    }
    for (int j = 0; j < 12; ++j) {
      EXPECT_EQ(message->P[j], info.projection(j / 4, j % 4)) << j;
    }
    EXPECT_EQ(message->binning_x, 0u);
    EXPECT_EQ(message->binning_y, 0u);
    EXPECT_EQ(message->roi, sensor_msgs::RegionOfInterest());
    ++i;
  }
  const std::vector<std::string> models = {"plumb_bob", "equidistant",
                                           "plumb_bob"};
  i = 0;
  for (const rosbag::MessageInstance& m : view) {
    EXPECT_EQ(m.instantiate<sensor_msgs::CameraInfo>()->distortion_model,
              models[i++]);
  }
  bag.close();
  std::remove(path.c_str());
}

TEST(BagImageWriter, CameraInfoNeedsATopicAndAStamp) {
  const std::string path = test::TempFilePath("bad_info.bag");
  StatusOr<BagImageWriter> writer = BagImageWriter::Create(path);
  ASSERT_TRUE(writer.ok()) << writer.status().message();
  const CameraInfo info = RightCameraInfo(test::PinholeCamera());
  EXPECT_EQ(writer->WriteCameraInfo("", 1000.0, info, "cam1").message(),
            path + ": a camera_info needs a topic");
  EXPECT_EQ(writer->WriteCameraInfo("/info", -1.0, info, "cam1").message(),
            path +
                ": /info: stamp -1.0 s: expected a time after 0 and before "
                "2^32 s");
  // Neither spoiled the bag.
  ASSERT_TRUE(writer->WriteCameraInfo("/info", 1000.0, info, "cam1").ok());
  ASSERT_TRUE(writer->Close().ok());
  std::remove(path.c_str());
}

}  // namespace
}  // namespace rcm::bag_image_rewriter_test
