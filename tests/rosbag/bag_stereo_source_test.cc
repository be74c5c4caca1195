#include "rcm/rosbag/bag_stereo_source.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/CompressedImage.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/Imu.h>

#include <cstdio>
#include <filesystem>
#include <functional>
#include <memory>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "rcm/io/stereo_image_folders.h"
#include "rcm/rosbag/bag_image_writer.h"
#include "support/temp_file.h"

namespace rcm::bag_stereo_source_test {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;
using ::testing::Not;
using ::testing::StartsWith;

constexpr char kLeft[] = "/cam0/image_raw";
constexpr char kRight[] = "/cam1/image_raw";

// 64x48 noise of `type` from a fixed seed: each seed a different image.
cv::Mat TestImage(int type, int seed, cv::Size size = cv::Size(64, 48)) {
  cv::Mat image(size, type);
  cv::RNG rng(static_cast<uint64_t>(seed));
  rng.fill(image, cv::RNG::UNIFORM, 0, 256);
  return image;
}

// 1000 s, 1000.25 s, ...: stamps a double and a ros::Time hold exactly.
double Stamp(int k) { return 1000.0 + 0.25 * k; }

BagStereoOptions Options() {
  BagStereoOptions options;
  options.left_topic = kLeft;
  options.right_topic = kRight;
  return options;
}

// How the tests write images with BagImageWriter.
enum class Storage { kMono8, kBgr8, kRgb8, kPng, kJpeg };

// Writes `left` and `right` (one image per stamp) on kLeft and kRight.
void WriteStereoBag(const std::string& path, const std::vector<double>& stamps,
                    const std::vector<cv::Mat>& left,
                    const std::vector<cv::Mat>& right, Storage storage) {
  StatusOr<BagImageWriter> writer = BagImageWriter::Create(path);
  ASSERT_TRUE(writer.ok()) << writer.status().message();
  for (size_t k = 0; k < stamps.size(); ++k) {
    for (const auto& [topic, image] :
         {std::pair{kLeft, left[k]}, std::pair{kRight, right[k]}}) {
      Status status;
      switch (storage) {
        case Storage::kMono8:
          status = writer->WriteImage(topic, stamps[k], image, "mono8", "cam");
          break;
        case Storage::kBgr8:
          status = writer->WriteImage(topic, stamps[k], image, "bgr8", "cam");
          break;
        case Storage::kRgb8:
          status = writer->WriteImage(topic, stamps[k], image, "rgb8", "cam");
          break;
        case Storage::kPng:
          status =
              writer->WriteCompressed(topic, stamps[k], image, "png", "cam");
          break;
        case Storage::kJpeg:
          status =
              writer->WriteCompressed(topic, stamps[k], image, "jpeg", "cam");
          break;
      }
      ASSERT_TRUE(status.ok()) << status.message();
    }
  }
  const Status closed = writer->Close();
  ASSERT_TRUE(closed.ok()) << closed.message();
}

// Writes a bag with rosbag itself, for messages BagImageWriter does not
// produce.
void WriteRawBag(const std::string& path,
                 const std::function<void(rosbag::Bag&)>& fill) {
  rosbag::Bag bag;
  bag.open(path, rosbag::bagmode::Write);
  fill(bag);
  bag.close();
}

// A sensor_msgs/Image with the given layout; `data` as stored.
sensor_msgs::Image RawImage(double stamp, int width, int height,
                            const std::string& encoding, int step,
                            std::vector<uint8_t> data) {
  sensor_msgs::Image image;
  image.header.stamp = ros::Time(stamp);
  image.width = width;
  image.height = height;
  image.encoding = encoding;
  image.step = step;
  image.data = std::move(data);
  return image;
}

// The bytes of `image` as a sensor_msgs/Image stores them: rows of `step`
// bytes, the padding after each row 0xab.
std::vector<uint8_t> Bytes(const cv::Mat& image, int step) {
  const int row_bytes = image.cols * static_cast<int>(image.elemSize());
  std::vector<uint8_t> data(static_cast<size_t>(step) * image.rows, 0xab);
  for (int y = 0; y < image.rows; ++y) {
    std::copy(image.ptr<uint8_t>(y), image.ptr<uint8_t>(y) + row_bytes,
              data.begin() + static_cast<ptrdiff_t>(y) * step);
  }
  return data;
}

// `bgr` with its channels reordered by `order` (output channel c is input
// channel order[c]) and, when `alpha`, a fourth channel of noise: written
// by hand so the test does not share the code under test's cvtColor.
cv::Mat Reorder(const cv::Mat& bgr, const std::vector<int>& order, bool alpha) {
  cv::Mat out(bgr.size(), CV_8UC(alpha ? 4 : 3));
  cv::RNG rng(99);
  for (int y = 0; y < bgr.rows; ++y) {
    for (int x = 0; x < bgr.cols; ++x) {
      const cv::Vec3b& in = bgr.at<cv::Vec3b>(y, x);
      uint8_t* pixel = out.ptr<uint8_t>(y) + x * out.channels();
      for (int c = 0; c < 3; ++c) pixel[c] = in[order[c]];
      if (alpha) pixel[3] = static_cast<uint8_t>(rng.uniform(0, 256));
    }
  }
  return out;
}

StatusOr<std::unique_ptr<StereoImageSource>> Open(
    const std::string& path, const BagStereoOptions& options = Options()) {
  return OpenBagStereoSource(path, options);
}

// Every pair of `source`; a failed read fails the test.
std::vector<StereoImagePair> ReadAll(StereoImageSource& source) {
  std::vector<StereoImagePair> pairs;
  for (size_t i = 0; i < source.NumPairs(); ++i) {
    StatusOr<StereoImagePair> pair = source.ReadPair(i);
    EXPECT_TRUE(pair.ok()) << pair.status().message();
    if (pair.ok()) pairs.push_back(std::move(pair).value());
  }
  return pairs;
}

double MaxDifference(const cv::Mat& a, const cv::Mat& b) {
  if (a.size() != b.size() || a.type() != b.type()) return 1e9;
  return cv::norm(a, b, cv::NORM_INF);
}

// Writes 3 pairs in `storage` and checks they read back as written (within
// `max_difference`, 0 for lossless storage).
void ExpectRoundTrip(Storage storage, int type, double max_difference) {
  const std::string path = test::TempFilePath("stereo.bag");
  std::vector<double> stamps;
  std::vector<cv::Mat> left;
  std::vector<cv::Mat> right;
  for (int k = 0; k < 3; ++k) {
    stamps.push_back(Stamp(k));
    cv::Mat l = TestImage(type, 2 * k);
    cv::Mat r = TestImage(type, 2 * k + 1);
    if (storage == Storage::kJpeg) {
      // Noise is JPEG's worst case; smooth it as a camera image is.
      cv::GaussianBlur(l, l, cv::Size(9, 9), 3.0);
      cv::GaussianBlur(r, r, cv::Size(9, 9), 3.0);
    }
    left.push_back(l);
    right.push_back(r);
  }
  WriteStereoBag(path, stamps, left, right, storage);
  if (::testing::Test::HasFatalFailure()) return;

  StatusOr<std::unique_ptr<StereoImageSource>> source = Open(path);
  ASSERT_TRUE(source.ok()) << source.status().message();
  EXPECT_EQ((*source)->Describe(), "bag " + path + " (" + kLeft + ", " +
                                       kRight +
                                       "): 3 pairs, 0 unpaired messages");
  const std::vector<StereoImagePair> pairs = ReadAll(**source);
  ASSERT_EQ(pairs.size(), 3u);
  for (int k = 0; k < 3; ++k) {
    const StereoImagePair& pair = pairs[k];
    EXPECT_EQ(pair.frame, k);
    ASSERT_TRUE(pair.timestamp.has_value());
    EXPECT_EQ(*pair.timestamp, Stamp(k));
    const std::string stamp_text[] = {"1000.000000", "1000.250000",
                                      "1000.500000"};
    EXPECT_EQ(pair.left_name, std::string(kLeft) + " @ " + stamp_text[k]);
    EXPECT_EQ(pair.right_name, std::string(kRight) + " @ " + stamp_text[k]);
    EXPECT_EQ(pair.left.type(), type);
    EXPECT_EQ(pair.right.type(), type);
    EXPECT_LE(MaxDifference(pair.left, left[k]), max_difference) << k;
    EXPECT_LE(MaxDifference(pair.right, right[k]), max_difference) << k;
    if (max_difference > 0) {
      EXPECT_LT(cv::norm(pair.left, left[k], cv::NORM_L1) / left[k].total() /
                    left[k].channels(),
                2.5);
    }
  }
  std::remove(path.c_str());
}

TEST(BagStereoSource, RoundTripsMono8) {
  ExpectRoundTrip(Storage::kMono8, CV_8UC1, 0.0);
}

TEST(BagStereoSource, RoundTripsBgr8) {
  ExpectRoundTrip(Storage::kBgr8, CV_8UC3, 0.0);
}

TEST(BagStereoSource, RoundTripsRgb8) {
  ExpectRoundTrip(Storage::kRgb8, CV_8UC3, 0.0);
}

TEST(BagStereoSource, RoundTripsPngExactly) {
  ExpectRoundTrip(Storage::kPng, CV_8UC1, 0.0);
  ExpectRoundTrip(Storage::kPng, CV_8UC3, 0.0);
}

TEST(BagStereoSource, RoundTripsJpegClosely) {
  // Quality 95, with chroma subsampling for colour: a few levels on
  // average, more at the sharpest colour edges.
  ExpectRoundTrip(Storage::kJpeg, CV_8UC1, 24.0);
  ExpectRoundTrip(Storage::kJpeg, CV_8UC3, 24.0);
}

TEST(BagImageWriter, StoresRgb8InRgbOrder) {
  const std::string path = test::TempFilePath("rgb.bag");
  const cv::Mat bgr = TestImage(CV_8UC3, 5, cv::Size(7, 3));
  StatusOr<BagImageWriter> writer = BagImageWriter::Create(path);
  ASSERT_TRUE(writer.ok()) << writer.status().message();
  ASSERT_TRUE(writer->WriteImage(kLeft, Stamp(0), bgr, "rgb8", "cam0").ok());
  ASSERT_TRUE(writer->Close().ok());

  rosbag::Bag bag(path);
  rosbag::View view(bag);
  ASSERT_EQ(view.size(), 1u);
  const auto message = view.begin()->instantiate<sensor_msgs::Image>();
  ASSERT_NE(message, nullptr);
  EXPECT_EQ(message->encoding, "rgb8");
  EXPECT_EQ(message->header.frame_id, "cam0");
  EXPECT_EQ(message->header.stamp, ros::Time(Stamp(0)));
  EXPECT_EQ(view.begin()->getTime(), ros::Time(Stamp(0)));
  EXPECT_EQ(message->width, 7u);
  EXPECT_EQ(message->height, 3u);
  EXPECT_EQ(message->step, 21u);
  EXPECT_EQ(message->data, Bytes(Reorder(bgr, {2, 1, 0}, false), 21));
  bag.close();
  std::remove(path.c_str());
}

TEST(BagStereoSource, ConvertsRawColourEncodingsToBgrAndSkipsRowPadding) {
  const std::string path = test::TempFilePath("raw.bag");
  const cv::Mat bgr = TestImage(CV_8UC3, 1, cv::Size(10, 6));
  const cv::Mat mono = TestImage(CV_8UC1, 2, cv::Size(10, 6));
  struct Case {
    std::string encoding;
    cv::Mat stored;
    cv::Mat expected;
  };
  const std::vector<Case> cases = {
      {"rgb8", Reorder(bgr, {2, 1, 0}, false), bgr},
      {"bgra8", Reorder(bgr, {0, 1, 2}, true), bgr},
      {"rgba8", Reorder(bgr, {2, 1, 0}, true), bgr},
      {"8UC3", bgr, bgr},
      {"8UC1", mono, mono},
      {"mono8", mono, mono},
  };
  WriteRawBag(path, [&](rosbag::Bag& bag) {
    for (size_t k = 0; k < cases.size(); ++k) {
      const cv::Mat& stored = cases[k].stored;
      // Rows padded by 3 bytes.
      const int step = stored.cols * stored.channels() + 3;
      const sensor_msgs::Image image =
          RawImage(Stamp(k), stored.cols, stored.rows, cases[k].encoding, step,
                   Bytes(stored, step));
      bag.write(kLeft, image.header.stamp, image);
      bag.write(kRight, image.header.stamp, image);
    }
  });
  StatusOr<std::unique_ptr<StereoImageSource>> source = Open(path);
  ASSERT_TRUE(source.ok()) << source.status().message();
  const std::vector<StereoImagePair> pairs = ReadAll(**source);
  ASSERT_EQ(pairs.size(), cases.size());
  for (size_t k = 0; k < cases.size(); ++k) {
    EXPECT_EQ(MaxDifference(pairs[k].left, cases[k].expected), 0.0)
        << cases[k].encoding;
    EXPECT_EQ(MaxDifference(pairs[k].right, cases[k].expected), 0.0)
        << cases[k].encoding;
  }
  std::remove(path.c_str());
}

TEST(BagStereoSource, PairsByStampWithJitterAndCountsUnpairedMessages) {
  const std::string path = test::TempFilePath("jitter.bag");
  // Left at 1000 s + 0.25 k, k = 0..4. Right within 3 ms of it, but none
  // for k = 3, and an extra one at 1000.125 s, between two frames.
  const std::vector<double> right_stamps = {Stamp(0) + 0.003, Stamp(1) - 0.002,
                                            1000.125, Stamp(2) + 0.001,
                                            Stamp(4) - 0.003};
  const std::vector<int> right_frame = {0, 1, -1, 2, 4};
  StatusOr<BagImageWriter> writer = BagImageWriter::Create(path);
  ASSERT_TRUE(writer.ok()) << writer.status().message();
  for (int k = 0; k < 5; ++k) {
    ASSERT_TRUE(writer
                    ->WriteImage(kLeft, Stamp(k), TestImage(CV_8UC1, k),
                                 "mono8", "cam0")
                    .ok());
  }
  for (size_t i = 0; i < right_stamps.size(); ++i) {
    ASSERT_TRUE(writer
                    ->WriteImage(kRight, right_stamps[i],
                                 TestImage(CV_8UC1, 100 + right_frame[i]),
                                 "mono8", "cam1")
                    .ok());
  }
  ASSERT_TRUE(writer->Close().ok());

  StatusOr<std::unique_ptr<StereoImageSource>> source = Open(path);
  ASSERT_TRUE(source.ok()) << source.status().message();
  EXPECT_EQ((*source)->Describe(), "bag " + path + " (" + kLeft + ", " +
                                       kRight +
                                       "): 4 pairs, 2 unpaired messages");
  const std::vector<StereoImagePair> pairs = ReadAll(**source);
  ASSERT_EQ(pairs.size(), 4u);
  const std::vector<int> left_frames = {0, 1, 2, 4};
  for (size_t i = 0; i < pairs.size(); ++i) {
    const int k = left_frames[i];
    EXPECT_EQ(pairs[i].frame, static_cast<int64_t>(i));
    EXPECT_EQ(*pairs[i].timestamp, Stamp(k));
    EXPECT_EQ(MaxDifference(pairs[i].left, TestImage(CV_8UC1, k)), 0.0) << i;
    EXPECT_EQ(MaxDifference(pairs[i].right, TestImage(CV_8UC1, 100 + k)), 0.0)
        << i;
  }
  EXPECT_EQ(pairs[0].right_name, std::string(kRight) + " @ 1000.003000");
  EXPECT_EQ(pairs[1].right_name, std::string(kRight) + " @ 1000.248000");
  std::remove(path.c_str());
}

TEST(BagStereoSource, PairsEachMessageWithTheNearestOne) {
  const std::string path = test::TempFilePath("nearest.bag");
  // With a tolerance of 0.2 s the right message at 1000.2 s is within
  // reach of both left ones; it belongs to the nearer, 1000.25 s.
  WriteRawBag(path, [&](rosbag::Bag& bag) {
    const cv::Mat image = TestImage(CV_8UC1, 0, cv::Size(4, 2));
    for (const double stamp : {Stamp(0), Stamp(1)}) {
      const sensor_msgs::Image left =
          RawImage(stamp, 4, 2, "mono8", 4, Bytes(image, 4));
      bag.write(kLeft, left.header.stamp, left);
    }
    const sensor_msgs::Image right =
        RawImage(1000.2, 4, 2, "mono8", 4, Bytes(image, 4));
    bag.write(kRight, right.header.stamp, right);
  });
  BagStereoOptions options = Options();
  options.stamp_tolerance_s = 0.2;
  StatusOr<std::unique_ptr<StereoImageSource>> source = Open(path, options);
  ASSERT_TRUE(source.ok()) << source.status().message();
  ASSERT_EQ((*source)->NumPairs(), 1u);
  StatusOr<StereoImagePair> pair = (*source)->ReadPair(0);
  ASSERT_TRUE(pair.ok()) << pair.status().message();
  EXPECT_EQ(*pair->timestamp, Stamp(1));
  EXPECT_EQ((*source)->Describe(), "bag " + path + " (" + kLeft + ", " +
                                       kRight +
                                       "): 1 pair, 1 unpaired message");
  std::remove(path.c_str());
}

TEST(BagStereoSource, OrdersByHeaderStampNotRecordTime) {
  const std::string path = test::TempFilePath("order.bag");
  // Recorded in the order k = 2, 0, 1 (record times ascending), so only
  // the header stamps give the true order.
  WriteRawBag(path, [&](rosbag::Bag& bag) {
    int record = 0;
    for (const int k : {2, 0, 1}) {
      const cv::Mat image = TestImage(CV_8UC1, k, cv::Size(4, 2));
      const sensor_msgs::Image message =
          RawImage(Stamp(k), 4, 2, "mono8", 4, Bytes(image, 4));
      const ros::Time recorded(2000.0 + record++);
      bag.write(kLeft, recorded, message);
      bag.write(kRight, recorded, message);
    }
  });
  StatusOr<std::unique_ptr<StereoImageSource>> source = Open(path);
  ASSERT_TRUE(source.ok()) << source.status().message();
  const std::vector<StereoImagePair> pairs = ReadAll(**source);
  ASSERT_EQ(pairs.size(), 3u);
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(*pairs[k].timestamp, Stamp(k));
    EXPECT_EQ(
        MaxDifference(pairs[k].left, TestImage(CV_8UC1, k, cv::Size(4, 2))),
        0.0);
  }
  std::remove(path.c_str());
}

// Writes 10 mono8 pairs, 0.25 s apart, image k from seed k.
std::string WriteTenPairs() {
  const std::string path = test::TempFilePath("ten.bag");
  std::vector<double> stamps;
  std::vector<cv::Mat> images;
  for (int k = 0; k < 10; ++k) {
    stamps.push_back(Stamp(k));
    images.push_back(TestImage(CV_8UC1, k, cv::Size(8, 6)));
  }
  WriteStereoBag(path, stamps, images, images, Storage::kMono8);
  return path;
}

std::vector<int64_t> Frames(StereoImageSource& source) {
  std::vector<int64_t> frames;
  for (const StereoImagePair& pair : ReadAll(source)) {
    frames.push_back(pair.frame);
    EXPECT_EQ(MaxDifference(pair.left,
                            TestImage(CV_8UC1, static_cast<int>(pair.frame),
                                      cv::Size(8, 6))),
              0.0);
  }
  return frames;
}

TEST(BagStereoSource, StrideKeepsFrameNumbers) {
  const std::string path = WriteTenPairs();
  BagStereoOptions options = Options();
  options.selection.stride = 3;
  StatusOr<std::unique_ptr<StereoImageSource>> source = Open(path, options);
  ASSERT_TRUE(source.ok()) << source.status().message();
  EXPECT_EQ(Frames(**source), (std::vector<int64_t>{0, 3, 6, 9}));
  EXPECT_EQ((*source)->Describe(),
            "bag " + path + " (" + kLeft + ", " + kRight +
                "): 4 pairs (every 3rd of 10), 0 unpaired messages");
  std::remove(path.c_str());
}

TEST(BagStereoSource, TimeRangeCountsFromTheFirstPair) {
  const std::string path = WriteTenPairs();
  BagStereoOptions options = Options();
  options.selection.from_s = 0.5;
  options.selection.to_s = 1.5;
  StatusOr<std::unique_ptr<StereoImageSource>> source = Open(path, options);
  ASSERT_TRUE(source.ok()) << source.status().message();
  EXPECT_EQ(Frames(**source), (std::vector<int64_t>{2, 3, 4, 5, 6}));
  EXPECT_EQ((*source)->Describe(),
            "bag " + path + " (" + kLeft + ", " + kRight +
                "): 5 pairs (of 10, 0.500 s to 1.500 s), 0 unpaired "
                "messages");

  options.selection.stride = 2;
  options.selection.to_s.reset();
  source = Open(path, options);
  ASSERT_TRUE(source.ok()) << source.status().message();
  EXPECT_EQ(Frames(**source), (std::vector<int64_t>{2, 4, 6, 8}));
  EXPECT_EQ((*source)->Describe(),
            "bag " + path + " (" + kLeft + ", " + kRight +
                "): 4 pairs (every 2nd of 10, 0.500 s to the end), 0 "
                "unpaired messages");

  options.selection.from_s = 5.0;
  source = Open(path, options);
  ASSERT_FALSE(source.ok());
  EXPECT_EQ(source.status().message(),
            path +
                ": no stereo pair between 5.000 s and the end: the sequence "
                "lasts 2.250 s");
  std::remove(path.c_str());
}

BagStereoOptions LeftOnlyOptions() {
  BagStereoOptions options;
  options.left_topic = kLeft;
  options.left_only = true;
  return options;
}

// One camera's topic alone: every message of it a "pair" in stamp order
// (recorded out of order here), an empty right image and name, the
// other topics (a right camera with fewer messages, an IMU) ignored and
// nothing unpaired.
TEST(BagStereoSource, LeftOnlyGivesEveryMessageOfTheLeftTopic) {
  const std::string path = test::TempFilePath("left.bag");
  WriteRawBag(path, [&](rosbag::Bag& bag) {
    int record = 0;
    for (const int k : {1, 0, 2, 3}) {
      const cv::Mat image = TestImage(CV_8UC1, k, cv::Size(4, 2));
      const ros::Time recorded(2000.0 + record++);
      bag.write(kLeft, recorded,
                RawImage(Stamp(k), 4, 2, "mono8", 4, Bytes(image, 4)));
      if (k == 0) {
        bag.write(kRight, recorded,
                  RawImage(Stamp(k), 4, 2, "mono8", 4, Bytes(image, 4)));
      }
    }
    sensor_msgs::Imu imu;
    imu.header.stamp = ros::Time(Stamp(0));
    bag.write("/imu0", ros::Time(2000.0), imu);
  });
  StatusOr<std::unique_ptr<StereoImageSource>> source =
      Open(path, LeftOnlyOptions());
  ASSERT_TRUE(source.ok()) << source.status().message();
  EXPECT_EQ((*source)->Describe(),
            "bag " + path + " (" + kLeft + ", left camera only): 4 images");
  const std::vector<StereoImagePair> pairs = ReadAll(**source);
  ASSERT_EQ(pairs.size(), 4u);
  const std::string stamp_text[] = {"1000.000000", "1000.250000", "1000.500000",
                                    "1000.750000"};
  for (int k = 0; k < 4; ++k) {
    EXPECT_EQ(pairs[k].frame, k);
    ASSERT_TRUE(pairs[k].timestamp.has_value());
    EXPECT_EQ(*pairs[k].timestamp, Stamp(k));
    EXPECT_EQ(pairs[k].left_name, std::string(kLeft) + " @ " + stamp_text[k]);
    EXPECT_EQ(
        MaxDifference(pairs[k].left, TestImage(CV_8UC1, k, cv::Size(4, 2))),
        0.0);
    EXPECT_TRUE(pairs[k].right.empty());
    EXPECT_EQ(pairs[k].right_name, "");
  }

  // The same topic as the left of a pair still pairs (one right message).
  source = Open(path);
  ASSERT_TRUE(source.ok()) << source.status().message();
  EXPECT_EQ((*source)->NumPairs(), 1u);
  std::remove(path.c_str());
}

// A bag of one camera (no right topic at all), colour and compressed,
// with a stride and a time range as for pairs.
TEST(BagStereoSource, LeftOnlyReadsABagOfOneCameraWithASelection) {
  const std::string path = test::TempFilePath("one.bag");
  {
    StatusOr<BagImageWriter> writer = BagImageWriter::Create(path);
    ASSERT_TRUE(writer.ok()) << writer.status().message();
    for (int k = 0; k < 10; ++k) {
      ASSERT_TRUE(writer
                      ->WriteCompressed(kLeft, Stamp(k),
                                        TestImage(CV_8UC3, k, cv::Size(8, 6)),
                                        "png", "cam0")
                      .ok());
    }
    ASSERT_TRUE(writer->Close().ok());
  }
  BagStereoOptions options = LeftOnlyOptions();
  options.selection.from_s = 0.5;
  options.selection.stride = 3;
  StatusOr<std::unique_ptr<StereoImageSource>> source = Open(path, options);
  ASSERT_TRUE(source.ok()) << source.status().message();
  EXPECT_EQ((*source)->Describe(),
            "bag " + path + " (" + kLeft +
                ", left camera only): 3 images (every 3rd of 10, 0.500 s to "
                "the end)");
  const std::vector<StereoImagePair> pairs = ReadAll(**source);
  ASSERT_EQ(pairs.size(), 3u);
  for (size_t i = 0; i < pairs.size(); ++i) {
    const int k = 2 + 3 * static_cast<int>(i);
    EXPECT_EQ(pairs[i].frame, k);
    EXPECT_EQ(*pairs[i].timestamp, Stamp(k));
    EXPECT_EQ(
        MaxDifference(pairs[i].left, TestImage(CV_8UC3, k, cv::Size(8, 6))),
        0.0);
    EXPECT_TRUE(pairs[i].right.empty());
    EXPECT_EQ(pairs[i].right_name, "");
  }

  // Two topics on a bag of one camera: the missing right topic is named.
  options = Options();
  source = Open(path, options);
  ASSERT_FALSE(source.ok());
  EXPECT_THAT(source.status().message(),
              AllOf(StartsWith(path), HasSubstr(kRight)));
  // And one topic that is not there.
  options = LeftOnlyOptions();
  options.left_topic = kRight;
  source = Open(path, options);
  ASSERT_FALSE(source.ok());
  EXPECT_THAT(source.status().message(), HasSubstr(kRight));
  std::remove(path.c_str());
}

// The calibration input treats one camera's bag as one camera's folder:
// the two sources' pairs hold the same fields (the names aside).
TEST(BagStereoSource, LeftOnlyPairsAreTheFolderSourcesPairs) {
  const std::string path = test::TempFilePath("same.bag");
  const std::string folder = test::TempFilePath("cam0");
  std::filesystem::remove_all(folder);
  std::filesystem::create_directories(folder);
  {
    StatusOr<BagImageWriter> writer = BagImageWriter::Create(path);
    ASSERT_TRUE(writer.ok()) << writer.status().message();
    for (int k = 0; k < 3; ++k) {
      const cv::Mat image = TestImage(CV_8UC1, k, cv::Size(8, 6));
      ASSERT_TRUE(
          writer->WriteImage(kLeft, Stamp(k), image, "mono8", "cam0").ok());
      ASSERT_TRUE(cv::imwrite(
          folder + "/" + std::to_string(Stamp(k)).substr(0, 7) + ".png",
          image));
    }
    ASSERT_TRUE(writer->Close().ok());
  }
  StatusOr<std::unique_ptr<StereoImageSource>> bag =
      Open(path, LeftOnlyOptions());
  ASSERT_TRUE(bag.ok()) << bag.status().message();
  StereoFolderOptions folder_options;
  folder_options.left_dir = folder;
  folder_options.left_only = true;
  StatusOr<std::unique_ptr<StereoImageSource>> files =
      OpenStereoImageFolders(folder_options);
  ASSERT_TRUE(files.ok()) << files.status().message();
  const std::vector<StereoImagePair> from_bag = ReadAll(**bag);
  const std::vector<StereoImagePair> from_files = ReadAll(**files);
  ASSERT_EQ(from_bag.size(), 3u);
  ASSERT_EQ(from_files.size(), 3u);
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(from_bag[k].frame, from_files[k].frame);
    EXPECT_EQ(from_bag[k].timestamp, from_files[k].timestamp);
    EXPECT_EQ(MaxDifference(from_bag[k].left, from_files[k].left), 0.0);
    EXPECT_TRUE(from_files[k].right.empty());
    EXPECT_TRUE(from_bag[k].right.empty());
    EXPECT_EQ(from_bag[k].right_name, from_files[k].right_name);
  }
  std::filesystem::remove_all(folder);
  std::remove(path.c_str());
}

TEST(BagStereoSource, LeftOnlyOptionsCheck) {
  BagStereoOptions options = LeftOnlyOptions();
  EXPECT_TRUE(options.Check().ok());
  options.right_topic = kRight;
  EXPECT_EQ(options.Check().message(),
            "one camera's images are read from the left topic alone, got a "
            "right topic too (/cam1/image_raw)");
  options = LeftOnlyOptions();
  options.left_topic.clear();
  EXPECT_EQ(options.Check().message(),
            "one camera's images need its (left) image topic");
  options = LeftOnlyOptions();
  options.selection.stride = 0;
  EXPECT_EQ(options.Check().message(), "stride must be at least 1, got 0");
}

TEST(BagStereoSource, MissingTopicListsTheImageTopics) {
  const std::string path = test::TempFilePath("topics.bag");
  WriteRawBag(path, [&](rosbag::Bag& bag) {
    const cv::Mat image = TestImage(CV_8UC1, 0, cv::Size(4, 2));
    const sensor_msgs::Image raw =
        RawImage(Stamp(0), 4, 2, "mono8", 4, Bytes(image, 4));
    bag.write("/alphasense/cam0/image_raw", raw.header.stamp, raw);
    sensor_msgs::CompressedImage compressed;
    compressed.header.stamp = raw.header.stamp;
    compressed.format = "png";
    bag.write("/alphasense/cam1/image_raw/compressed", raw.header.stamp,
              compressed);
    sensor_msgs::Imu imu;
    imu.header.stamp = raw.header.stamp;
    bag.write("/imu", raw.header.stamp, imu);
  });
  StatusOr<std::unique_ptr<StereoImageSource>> source = Open(path);
  ASSERT_FALSE(source.ok());
  EXPECT_EQ(source.status().message(),
            path +
                ": no topic /cam0/image_raw (image topics in the bag: "
                "/alphasense/cam0/image_raw [sensor_msgs/Image], "
                "/alphasense/cam1/image_raw/compressed "
                "[sensor_msgs/CompressedImage])");

  // The right topic is checked too.
  BagStereoOptions options = Options();
  options.left_topic = "/alphasense/cam0/image_raw";
  options.right_topic = "/alphasense/cam1/image_raw";
  source = Open(path, options);
  ASSERT_FALSE(source.ok());
  EXPECT_THAT(source.status().message(),
              StartsWith(path + ": no topic /alphasense/cam1/image_raw ("));
  std::remove(path.c_str());
}

TEST(BagStereoSource, MissingTopicInBagWithoutImages) {
  const std::string path = test::TempFilePath("imu.bag");
  WriteRawBag(path, [&](rosbag::Bag& bag) {
    sensor_msgs::Imu imu;
    bag.write("/imu", ros::Time(Stamp(0)), imu);
  });
  StatusOr<std::unique_ptr<StereoImageSource>> source = Open(path);
  ASSERT_FALSE(source.ok());
  EXPECT_EQ(source.status().message(),
            path +
                ": no topic /cam0/image_raw (the bag has no image topics; its "
                "topics: /imu [sensor_msgs/Imu])");
  std::remove(path.c_str());
}

TEST(BagStereoSource, NonImageTopicNamesItsType) {
  const std::string path = test::TempFilePath("imu_topic.bag");
  WriteRawBag(path, [&](rosbag::Bag& bag) {
    sensor_msgs::Imu imu;
    bag.write(kLeft, ros::Time(Stamp(0)), imu);
    const cv::Mat image = TestImage(CV_8UC1, 0, cv::Size(4, 2));
    const sensor_msgs::Image raw =
        RawImage(Stamp(0), 4, 2, "mono8", 4, Bytes(image, 4));
    bag.write(kRight, raw.header.stamp, raw);
  });
  StatusOr<std::unique_ptr<StereoImageSource>> source = Open(path);
  ASSERT_FALSE(source.ok());
  EXPECT_EQ(source.status().message(),
            path +
                ": topic /cam0/image_raw has type sensor_msgs/Imu, expected "
                "sensor_msgs/Image or sensor_msgs/CompressedImage");
  std::remove(path.c_str());
}

TEST(BagStereoSource, NoPairWithinToleranceSaysWhatToRaise) {
  const std::string path = test::TempFilePath("apart.bag");
  std::vector<double> left_stamps;
  std::vector<double> right_stamps;
  std::vector<cv::Mat> images;
  for (int k = 0; k < 3; ++k) {
    left_stamps.push_back(1.0 + 0.125 * k);
    right_stamps.push_back(3.5 + 0.125 * k);
    images.push_back(TestImage(CV_8UC1, k, cv::Size(4, 2)));
  }
  StatusOr<BagImageWriter> writer = BagImageWriter::Create(path);
  ASSERT_TRUE(writer.ok()) << writer.status().message();
  for (int k = 0; k < 3; ++k) {
    ASSERT_TRUE(
        writer->WriteImage(kLeft, left_stamps[k], images[k], "mono8", "").ok());
  }
  for (int k = 0; k < 2; ++k) {
    ASSERT_TRUE(
        writer->WriteImage(kRight, right_stamps[k], images[k], "mono8", "")
            .ok());
  }
  ASSERT_TRUE(writer->Close().ok());
  StatusOr<std::unique_ptr<StereoImageSource>> source = Open(path);
  ASSERT_FALSE(source.ok());
  EXPECT_EQ(source.status().message(),
            path +
                ": no left/right messages within 0.005 s of each other (3 on "
                "/cam0/image_raw, 2 on /cam1/image_raw; first stamps "
                "1.000000 and 3.500000); raise --stamp-tolerance");
  std::remove(path.c_str());
}

TEST(BagStereoSource, TruncatedBagIsAnErrorNotACrash) {
  const std::string whole = test::TempFilePath("whole.bag");
  std::vector<double> stamps;
  std::vector<cv::Mat> images;
  for (int k = 0; k < 5; ++k) {
    stamps.push_back(Stamp(k));
    images.push_back(TestImage(CV_8UC1, k));
  }
  WriteStereoBag(whole, stamps, images, images, Storage::kMono8);
  const uintmax_t size = std::filesystem::file_size(whole);
  for (const uintmax_t length : {size / 2, size - 1, uintmax_t{20}}) {
    const std::string cut = test::TempFilePath("cut.bag");
    std::filesystem::copy_file(
        whole, cut, std::filesystem::copy_options::overwrite_existing);
    std::filesystem::resize_file(cut, length);
    StatusOr<std::unique_ptr<StereoImageSource>> source = Open(cut);
    ASSERT_FALSE(source.ok()) << length;
    EXPECT_THAT(source.status().message(),
                StartsWith(cut + ": not a readable ROS1 bag ("));
    EXPECT_THAT(source.status().message(), Not(HasSubstr("\n")));
    std::remove(cut.c_str());
  }
  std::remove(whole.c_str());
}

TEST(BagStereoSource, NotABagIsAnError) {
  const std::string text = test::WriteTempFile("text.bag", "not a bag\n");
  StatusOr<std::unique_ptr<StereoImageSource>> source = Open(text);
  ASSERT_FALSE(source.ok());
  EXPECT_THAT(source.status().message(),
              StartsWith(text + ": not a readable ROS1 bag ("));
  EXPECT_THAT(source.status().message(), Not(HasSubstr("\n")));

  const std::string empty = test::WriteTempFile("empty.bag", "");
  source = Open(empty);
  ASSERT_FALSE(source.ok());
  EXPECT_THAT(source.status().message(),
              StartsWith(empty + ": not a readable ROS1 bag ("));

  const std::string missing = test::TempFilePath("missing.bag");
  source = Open(missing);
  ASSERT_FALSE(source.ok());
  EXPECT_EQ(source.status().message(),
            missing + ": cannot open: No such file or directory");

  source = Open(::testing::TempDir());
  ASSERT_FALSE(source.ok());
  EXPECT_EQ(source.status().message(),
            ::testing::TempDir() + ": is a directory, expected a file");
  std::remove(text.c_str());
  std::remove(empty.c_str());
}

TEST(BagStereoSource, UnsupportedEncodingIsAnErrorNamingIt) {
  const std::string path = test::TempFilePath("mono16.bag");
  WriteRawBag(path, [&](rosbag::Bag& bag) {
    const sensor_msgs::Image left =
        RawImage(Stamp(0), 4, 2, "mono16", 8, std::vector<uint8_t>(16, 7));
    bag.write(kLeft, left.header.stamp, left);
    const sensor_msgs::Image right =
        RawImage(Stamp(0), 4, 2, "mono8", 4, std::vector<uint8_t>(8, 7));
    bag.write(kRight, right.header.stamp, right);
  });
  StatusOr<std::unique_ptr<StereoImageSource>> source = Open(path);
  ASSERT_TRUE(source.ok()) << source.status().message();
  const StatusOr<StereoImagePair> pair = (*source)->ReadPair(0);
  ASSERT_FALSE(pair.ok());
  EXPECT_EQ(pair.status().message(),
            path +
                ": /cam0/image_raw @ 1000.000000: unsupported encoding "
                "'mono16' (rcm reads mono8, 8UC1, bgr8, 8UC3, rgb8, bgra8 "
                "and rgba8)");
  std::remove(path.c_str());
}

TEST(BagStereoSource, MalformedRawImageIsAnError) {
  const std::string path = test::TempFilePath("short.bag");
  WriteRawBag(path, [&](rosbag::Bag& bag) {
    // step * height = 8 bytes, 6 stored; then a step below the width.
    const sensor_msgs::Image short_data =
        RawImage(Stamp(0), 4, 2, "mono8", 4, std::vector<uint8_t>(6, 7));
    const sensor_msgs::Image short_step =
        RawImage(Stamp(1), 4, 2, "bgr8", 4, std::vector<uint8_t>(8, 7));
    for (const sensor_msgs::Image& image : {short_data, short_step}) {
      bag.write(kLeft, image.header.stamp, image);
      bag.write(kRight, image.header.stamp, image);
    }
  });
  StatusOr<std::unique_ptr<StereoImageSource>> source = Open(path);
  ASSERT_TRUE(source.ok()) << source.status().message();
  StatusOr<StereoImagePair> pair = (*source)->ReadPair(0);
  ASSERT_FALSE(pair.ok());
  EXPECT_EQ(pair.status().message(),
            path +
                ": /cam0/image_raw @ 1000.000000: data holds 6 bytes, step * "
                "height needs 8");
  pair = (*source)->ReadPair(1);
  ASSERT_FALSE(pair.ok());
  EXPECT_EQ(pair.status().message(),
            path +
                ": /cam0/image_raw @ 1000.250000: step 4 is less than width "
                "* channels = 12");
  std::remove(path.c_str());
}

TEST(BagStereoSource, CorruptCompressedImageIsAnError) {
  const std::string path = test::TempFilePath("corrupt.bag");
  WriteRawBag(path, [&](rosbag::Bag& bag) {
    sensor_msgs::CompressedImage compressed;
    compressed.header.stamp = ros::Time(Stamp(0));
    compressed.format = "png";
    compressed.data = {0x89, 'P', 'N', 'G', 0};
    bag.write(kLeft, compressed.header.stamp, compressed);
    bag.write(kRight, compressed.header.stamp, compressed);
  });
  StatusOr<std::unique_ptr<StereoImageSource>> source = Open(path);
  ASSERT_TRUE(source.ok()) << source.status().message();
  const StatusOr<StereoImagePair> pair = (*source)->ReadPair(0);
  ASSERT_FALSE(pair.ok());
  EXPECT_EQ(pair.status().message(),
            path +
                ": /cam0/image_raw @ 1000.000000: compressed image (format "
                "'png', 5 bytes) is corrupt or not a format OpenCV decodes");
  std::remove(path.c_str());
}

TEST(BagStereoSource, SizeMismatchIsAnErrorOnReadPair) {
  const std::string path = test::TempFilePath("sizes.bag");
  StatusOr<BagImageWriter> writer = BagImageWriter::Create(path);
  ASSERT_TRUE(writer.ok()) << writer.status().message();
  ASSERT_TRUE(
      writer
          ->WriteImage(kLeft, Stamp(0), TestImage(CV_8UC1, 0), "mono8", "cam0")
          .ok());
  ASSERT_TRUE(writer
                  ->WriteCompressed(kRight, Stamp(0),
                                    TestImage(CV_8UC3, 1, cv::Size(32, 24)),
                                    "png", "cam1")
                  .ok());
  ASSERT_TRUE(writer->Close().ok());
  StatusOr<std::unique_ptr<StereoImageSource>> source = Open(path);
  ASSERT_TRUE(source.ok()) << source.status().message();
  const StatusOr<StereoImagePair> pair = (*source)->ReadPair(0);
  ASSERT_FALSE(pair.ok());
  EXPECT_EQ(pair.status().message(),
            path +
                ": frame 0: left image 64x48 (/cam0/image_raw @ 1000.000000) "
                "but right 32x24 (/cam1/image_raw @ 1000.000000)");
  std::remove(path.c_str());
}

TEST(BagStereoSource, OptionsCheck) {
  const std::string path = test::TempFilePath("never_opened.bag");
  BagStereoOptions options = Options();
  EXPECT_TRUE(options.Check().ok());
  options.right_topic.clear();
  EXPECT_EQ(options.Check().message(),
            "a bag needs a left and a right image topic");
  options.right_topic = kLeft;
  EXPECT_EQ(options.Check().message(),
            "left and right topic are both /cam0/image_raw");
  options = Options();
  options.stamp_tolerance_s = -0.001;
  EXPECT_EQ(options.Check().message(),
            "stamp tolerance must be a finite number of seconds >= 0, got "
            "-0.001");
  options = Options();
  options.selection.stride = 0;
  EXPECT_EQ(options.Check().message(), "stride must be at least 1, got 0");
  // Options are checked before the file is touched.
  const StatusOr<std::unique_ptr<StereoImageSource>> source =
      Open(path, options);
  ASSERT_FALSE(source.ok());
  EXPECT_EQ(source.status().message(), "stride must be at least 1, got 0");
}

TEST(BagImageWriter, LeavesNoFileUnlessClosed) {
  const std::string path = test::TempFilePath("unclosed.bag");
  const std::filesystem::path directory =
      std::filesystem::path(path).parent_path();
  const std::string prefix = std::filesystem::path(path).filename().string();
  {
    StatusOr<BagImageWriter> writer = BagImageWriter::Create(path);
    ASSERT_TRUE(writer.ok()) << writer.status().message();
    ASSERT_TRUE(writer
                    ->WriteImage(kLeft, Stamp(0), TestImage(CV_8UC1, 0),
                                 "mono8", "cam0")
                    .ok());
    EXPECT_FALSE(std::filesystem::exists(path));
  }
  EXPECT_FALSE(std::filesystem::exists(path));
  // Nor its temporary file.
  for (const auto& entry : std::filesystem::directory_iterator(directory)) {
    EXPECT_THAT(entry.path().filename().string(), Not(StartsWith(prefix)));
  }
}

TEST(BagImageWriter, RejectsBadInputAndKeepsWriting) {
  const std::string path = test::TempFilePath("bad_input.bag");
  StatusOr<BagImageWriter> writer = BagImageWriter::Create(path);
  ASSERT_TRUE(writer.ok()) << writer.status().message();
  const cv::Mat mono = TestImage(CV_8UC1, 0);
  EXPECT_EQ(writer->WriteImage(kLeft, Stamp(0), mono, "bgr8", "").message(),
            path +
                ": /cam0/image_raw: encoding bgr8 needs a CV_8UC3 image, got "
                "CV_8UC1");
  EXPECT_EQ(writer->WriteImage(kLeft, Stamp(0), mono, "mono16", "").message(),
            path +
                ": /cam0/image_raw: unknown encoding 'mono16' (mono8, bgr8 "
                "or rgb8)");
  EXPECT_EQ(writer->WriteImage(kLeft, 0.0, mono, "mono8", "").message(),
            path +
                ": /cam0/image_raw: stamp 0.0 s: expected a time after 0 and "
                "before 2^32 s");
  EXPECT_EQ(writer->WriteImage("", Stamp(0), mono, "mono8", "").message(),
            path + ": an image needs a topic");
  EXPECT_EQ(
      writer->WriteImage(kLeft, Stamp(0), cv::Mat(), "mono8", "").message(),
      path + ": /cam0/image_raw: cannot write an empty image");
  EXPECT_EQ(writer->WriteCompressed(kLeft, Stamp(0), mono, "bmp", "").message(),
            path + ": /cam0/image_raw: unknown format 'bmp' (png or jpeg)");
  EXPECT_EQ(
      writer
          ->WriteCompressed(kLeft, Stamp(0), cv::Mat(2, 2, CV_16UC1), "png", "")
          .message(),
      path +
          ": /cam0/image_raw: a compressed image must be CV_8UC1 or "
          "CV_8UC3, got CV_16UC1");
  // None of these spoiled the bag.
  ASSERT_TRUE(writer->WriteImage(kLeft, Stamp(0), mono, "mono8", "").ok());
  ASSERT_TRUE(writer->WriteImage(kRight, Stamp(0), mono, "mono8", "").ok());
  ASSERT_TRUE(writer->Close().ok());
  StatusOr<std::unique_ptr<StereoImageSource>> source = Open(path);
  ASSERT_TRUE(source.ok()) << source.status().message();
  EXPECT_EQ((*source)->NumPairs(), 1u);
  std::remove(path.c_str());
}

TEST(BagImageWriter, CreateInMissingDirectoryFails) {
  const std::string path = test::TempFilePath("no_such_dir") + "/out.bag";
  const StatusOr<BagImageWriter> writer = BagImageWriter::Create(path);
  ASSERT_FALSE(writer.ok());
  EXPECT_EQ(writer.status().message(),
            path + ": cannot write: No such file or directory");
}

}  // namespace
}  // namespace rcm::bag_stereo_source_test
