#include "rcm/io/stereo_image_folders.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <memory>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "rcm/io/image_file.h"
#include "support/temp_file.h"

namespace rcm::stereo_image_folders_test {
namespace {

namespace fs = std::filesystem;

using ::testing::HasSubstr;

// A folder of the current test's own, removed when the test ends.
class TempFolder {
 public:
  explicit TempFolder(const std::string& name = "data")
      : root_(test::TempFilePath(name)) {
    fs::remove_all(root_);
    fs::create_directories(root_);
  }
  ~TempFolder() {
    std::error_code ignored;
    fs::remove_all(root_, ignored);
  }
  TempFolder(const TempFolder&) = delete;
  TempFolder& operator=(const TempFolder&) = delete;

  // root/relative.
  std::string Path(const std::string& relative) const {
    return (fs::path(root_) / relative).string();
  }
  // Creates root/relative (and its parents); returns its path.
  std::string MakeDir(const std::string& relative) const {
    fs::create_directories(Path(relative));
    return Path(relative);
  }
  // Writes `image` as PNG, whatever the extension of `relative`.
  void WriteImage(const std::string& relative, const cv::Mat& image) const {
    fs::create_directories(fs::path(Path(relative)).parent_path());
    const Status status = WritePng(image, Path(relative));
    ASSERT_TRUE(status.ok()) << status.message();
  }
  void WriteText(const std::string& relative,
                 const std::string& contents) const {
    fs::create_directories(fs::path(Path(relative)).parent_path());
    std::ofstream file(Path(relative), std::ios::binary | std::ios::trunc);
    file << contents;
    file.close();
    ASSERT_TRUE(file.good()) << "cannot write " << Path(relative);
  }

 private:
  std::string root_;
};

// Random content, the same for the same seed.
cv::Mat RandomImage(int seed, int type, cv::Size size = cv::Size(32, 24)) {
  cv::Mat image(size, type);
  cv::RNG rng(seed);
  if (CV_MAT_DEPTH(type) == CV_16U) {
    rng.fill(image, cv::RNG::UNIFORM, 0, 65536);
  } else {
    rng.fill(image, cv::RNG::UNIFORM, 0, 256);
  }
  return image;
}

bool SameImage(const cv::Mat& a, const cv::Mat& b) {
  return a.type() == b.type() && a.size() == b.size() &&
         cv::norm(a, b, cv::NORM_INF) == 0.0;
}

StereoFolderOptions Folders(const TempFolder& folder,
                            const std::string& left = "left",
                            const std::string& right = "right") {
  StereoFolderOptions options;
  options.left_dir = folder.Path(left);
  options.right_dir = folder.Path(right);
  return options;
}

// Opens `options`, which must succeed.
std::unique_ptr<StereoImageSource> Open(const StereoFolderOptions& options) {
  StatusOr<std::unique_ptr<StereoImageSource>> source =
      OpenStereoImageFolders(options);
  EXPECT_TRUE(source.ok()) << source.status().message();
  if (!source.ok()) return nullptr;
  return std::move(source).value();
}

// The message of opening `options`, which must fail with one line.
std::string OpenError(const StereoFolderOptions& options) {
  const StatusOr<std::unique_ptr<StereoImageSource>> source =
      OpenStereoImageFolders(options);
  EXPECT_FALSE(source.ok());
  if (source.ok()) return "";
  EXPECT_EQ(source.status().message().find('\n'), std::string::npos)
      << source.status().message();
  return source.status().message();
}

// Reads every pair, which must succeed.
std::vector<StereoImagePair> ReadAll(StereoImageSource* source) {
  std::vector<StereoImagePair> pairs;
  for (size_t i = 0; i < source->NumPairs(); ++i) {
    StatusOr<StereoImagePair> pair = source->ReadPair(i);
    EXPECT_TRUE(pair.ok()) << pair.status().message();
    if (pair.ok()) pairs.push_back(std::move(pair).value());
  }
  return pairs;
}

std::vector<int64_t> Frames(const std::vector<StereoImagePair>& pairs) {
  std::vector<int64_t> frames;
  for (const StereoImagePair& pair : pairs) frames.push_back(pair.frame);
  return frames;
}

std::vector<std::string> LeftFileNames(
    const std::vector<StereoImagePair>& pairs) {
  std::vector<std::string> names;
  for (const StereoImagePair& pair : pairs) {
    names.push_back(fs::path(pair.left_name).filename().string());
  }
  return names;
}

// Writes the same names into left/ and right/, with different content.
void WritePairsByName(const TempFolder& folder,
                      const std::vector<std::string>& names, int type) {
  for (int i = 0; i < static_cast<int>(names.size()); ++i) {
    folder.WriteImage("left/" + names[i], RandomImage(2 * i, type));
    folder.WriteImage("right/" + names[i], RandomImage(2 * i + 1, type));
  }
}

TEST(StereoImageFolders, PairsByName) {
  const TempFolder folder;
  WritePairsByName(folder, {"000000.png", "000001.png", "000002.png"}, CV_8UC3);
  const std::unique_ptr<StereoImageSource> source = Open(Folders(folder));
  ASSERT_NE(source, nullptr);
  EXPECT_EQ(source->Describe(), "folders " + folder.Path("left") + " and " +
                                    folder.Path("right") +
                                    ": 3 pairs, paired by name");
  ASSERT_EQ(source->NumPairs(), 3u);
  for (int i = 0; i < 3; ++i) {
    const StatusOr<StereoImagePair> pair = source->ReadPair(i);
    ASSERT_TRUE(pair.ok()) << pair.status().message();
    const std::string name = "00000" + std::to_string(i) + ".png";
    EXPECT_EQ(pair->frame, static_cast<int64_t>(i));
    EXPECT_FALSE(pair->timestamp.has_value());
    EXPECT_EQ(pair->left_name, folder.Path("left/" + name));
    EXPECT_EQ(pair->right_name, folder.Path("right/" + name));
    EXPECT_TRUE(SameImage(pair->left, RandomImage(2 * i, CV_8UC3)));
    EXPECT_TRUE(SameImage(pair->right, RandomImage(2 * i + 1, CV_8UC3)));
  }
  // Reading again gives the same pair.
  const StatusOr<StereoImagePair> again = source->ReadPair(1);
  ASSERT_TRUE(again.ok());
  EXPECT_TRUE(SameImage(again->left, RandomImage(2, CV_8UC3)));
}

TEST(StereoImageFolders, ReadsGrayAndDropsAlpha) {
  const TempFolder folder;
  folder.WriteImage("left/0.png", RandomImage(1, CV_8UC1));
  folder.WriteImage("right/0.png", RandomImage(2, CV_8UC1));
  folder.WriteImage("left/1.png", RandomImage(3, CV_8UC4));
  folder.WriteImage("right/1.png", RandomImage(4, CV_8UC4));
  // A gray camera next to a color one.
  folder.WriteImage("left/2.png", RandomImage(5, CV_8UC1));
  folder.WriteImage("right/2.png", RandomImage(6, CV_8UC3));
  const std::unique_ptr<StereoImageSource> source = Open(Folders(folder));
  ASSERT_NE(source, nullptr);
  const std::vector<StereoImagePair> pairs = ReadAll(source.get());
  ASSERT_EQ(pairs.size(), 3u);

  EXPECT_TRUE(SameImage(pairs[0].left, RandomImage(1, CV_8UC1)));
  EXPECT_TRUE(SameImage(pairs[0].right, RandomImage(2, CV_8UC1)));

  cv::Mat bgr;
  cv::cvtColor(RandomImage(3, CV_8UC4), bgr, cv::COLOR_BGRA2BGR);
  EXPECT_TRUE(SameImage(pairs[1].left, bgr));
  cv::cvtColor(RandomImage(4, CV_8UC4), bgr, cv::COLOR_BGRA2BGR);
  EXPECT_TRUE(SameImage(pairs[1].right, bgr));

  cv::cvtColor(RandomImage(5, CV_8UC1), bgr, cv::COLOR_GRAY2BGR);
  EXPECT_TRUE(SameImage(pairs[2].left, bgr));
  EXPECT_TRUE(SameImage(pairs[2].right, RandomImage(6, CV_8UC3)));
}

TEST(StereoImageFolders, SortsNaturallyAndIgnoresOtherFiles) {
  const TempFolder folder;
  // Images under every extension (PNG content: OpenCV decodes by content).
  WritePairsByName(folder,
                   {"10.png", "2.png", "1.png", "007.png", "7.png", "img10.png",
                    "img9.png", "UPPER.PNG", "photo.JPEG", "a.jpg", "b.pgm",
                    "c.ppm", "d.bmp", "e.tif", "f.TIFF"},
                   CV_8UC1);
  for (const std::string side : {"left/", "right/"}) {
    folder.WriteText(side + "notes.txt", "not an image\n");
    folder.WriteText(side + "a.png.bak", "not an image\n");
    folder.WriteText(side + "png", "not an image\n");
    folder.WriteImage(side + ".hidden.png", RandomImage(9, CV_8UC1));
    folder.WriteImage(side + "sub/5.png", RandomImage(9, CV_8UC1));
    folder.MakeDir(side + "folder.png");
  }
  const std::unique_ptr<StereoImageSource> source = Open(Folders(folder));
  ASSERT_NE(source, nullptr);
  const std::vector<StereoImagePair> pairs = ReadAll(source.get());
  EXPECT_THAT(LeftFileNames(pairs),
              testing::ElementsAre("1.png", "2.png", "007.png", "7.png",
                                   "10.png", "UPPER.PNG", "a.jpg", "b.pgm",
                                   "c.ppm", "d.bmp", "e.tif", "f.TIFF",
                                   "img9.png", "img10.png", "photo.JPEG"));
  for (const StereoImagePair& pair : pairs) {
    EXPECT_EQ(fs::path(pair.left_name).filename(),
              fs::path(pair.right_name).filename());
  }
}

TEST(StereoImageFolders, PairsByOrderWhenNoNameIsShared) {
  const TempFolder folder;
  for (int i : {1, 2, 10}) {
    const std::string number = std::to_string(i);
    folder.WriteImage("cam0/cam0_" + number + ".png", RandomImage(i, CV_8UC1));
    folder.WriteImage("cam1/cam1_" + number + ".png",
                      RandomImage(100 + i, CV_8UC1));
  }
  const std::unique_ptr<StereoImageSource> source =
      Open(Folders(folder, "cam0", "cam1"));
  ASSERT_NE(source, nullptr);
  EXPECT_EQ(source->Describe(), "folders " + folder.Path("cam0") + " and " +
                                    folder.Path("cam1") +
                                    ": 3 pairs, paired by order");
  const std::vector<StereoImagePair> pairs = ReadAll(source.get());
  ASSERT_EQ(pairs.size(), 3u);
  EXPECT_EQ(pairs[2].left_name, folder.Path("cam0/cam0_10.png"));
  EXPECT_EQ(pairs[2].right_name, folder.Path("cam1/cam1_10.png"));
  EXPECT_TRUE(SameImage(pairs[1].left, RandomImage(2, CV_8UC1)));
  EXPECT_TRUE(SameImage(pairs[1].right, RandomImage(102, CV_8UC1)));
}

TEST(StereoImageFolders, RefusesDifferentCountsWithoutSharedNames) {
  const TempFolder folder;
  for (int i = 0; i < 3; ++i) {
    folder.WriteImage("cam0/l" + std::to_string(i) + ".png",
                      RandomImage(i, CV_8UC1));
  }
  folder.WriteImage("cam1/r0.png", RandomImage(5, CV_8UC1));
  folder.WriteImage("cam1/r1.png", RandomImage(6, CV_8UC1));
  const std::string left = folder.Path("cam0");
  const std::string right = folder.Path("cam1");
  EXPECT_EQ(OpenError(Folders(folder, "cam0", "cam1")),
            left + " has 3 images, " + right +
                " 2, and no name is in both, so the images can be paired "
                "neither by name nor by order: pair them with a list file");
}

TEST(StereoImageFolders, RefusesPartlyMatchingNames) {
  const TempFolder folder;
  for (int i = 0; i < 5; ++i) {
    folder.WriteImage("left/00000" + std::to_string(i) + ".png",
                      RandomImage(i, CV_8UC1));
  }
  for (int i : {0, 1, 3, 4, 7, 8}) {
    folder.WriteImage("right/00000" + std::to_string(i) + ".png",
                      RandomImage(i, CV_8UC1));
  }
  const std::string left = folder.Path("left");
  const std::string right = folder.Path("right");
  EXPECT_EQ(OpenError(Folders(folder)),
            left + " has 5 images, " + right + " 6; 000002.png has no " +
                "partner in " + right + "; 000007.png has no partner in " +
                left + " (nor have 1 more): pair the images with a list file");

  // One side only.
  fs::remove(folder.Path("right/000007.png"));
  fs::remove(folder.Path("right/000008.png"));
  EXPECT_EQ(OpenError(Folders(folder)),
            left + " has 5 images, " + right + " 4; 000002.png has no " +
                "partner in " + right + ": pair the images with a list file");
}

TEST(StereoImageFolders, RefusesMissingEmptyAndNonFolders) {
  const TempFolder folder;
  WritePairsByName(folder, {"0.png"}, CV_8UC1);
  const std::string missing = folder.Path("missing");
  EXPECT_EQ(OpenError(Folders(folder, "missing", "right")),
            missing + ": no such folder");
  EXPECT_EQ(OpenError(Folders(folder, "left", "missing")),
            missing + ": no such folder");

  const std::string file = folder.Path("left/0.png");
  StereoFolderOptions options = Folders(folder);
  options.right_dir = file;
  EXPECT_EQ(OpenError(options), file + ": not a folder");

  folder.WriteText("empty/readme.txt", "no images here\n");
  folder.WriteImage("empty/.hidden.png", RandomImage(1, CV_8UC1));
  folder.WriteImage("empty/sub/0.png", RandomImage(1, CV_8UC1));
  EXPECT_EQ(OpenError(Folders(folder, "empty", "right")),
            folder.Path("empty") +
                ": no images (looked for .png, .jpg, .jpeg, .pgm, .ppm, "
                ".bmp, .tif, .tiff)");

  options = Folders(folder, "left", "left");
  options.right_dir = folder.Path("left/.");
  EXPECT_EQ(OpenError(options), folder.Path("left") + " and " +
                                    folder.Path("left/.") +
                                    " are the same folder");
}

TEST(StereoImageFolders, CheckOptions) {
  StereoFolderOptions options;
  EXPECT_EQ(options.Check().message(),
            "no stereo images: give the left and right image folders, or a "
            "pair list");
  options.left_dir = "left";
  EXPECT_EQ(options.Check().message(), "no right image folder given");
  options.left_dir = "";
  options.right_dir = "right";
  EXPECT_EQ(options.Check().message(), "no left image folder given");
  options.left_dir = "left";
  EXPECT_TRUE(options.Check().ok());
  options.pair_list = "pairs.txt";
  EXPECT_EQ(options.Check().message(),
            "give either a pair list or the left and right image folders, "
            "not both");
  options.left_dir = "";
  options.right_dir = "";
  EXPECT_TRUE(options.Check().ok());
  options.selection.stride = 0;
  EXPECT_EQ(options.Check().message(), "stride must be at least 1, got 0");
  EXPECT_EQ(OpenError(options), "stride must be at least 1, got 0");
}

TEST(StereoImageFolders, NanosecondNamesGiveSeconds) {
  const TempFolder folder;
  const std::vector<std::string> names = {"1403636579763555584.png",
                                          "1403636579813555456.png",
                                          "1403636579863555584.png"};
  WritePairsByName(folder, names, CV_8UC1);
  const std::unique_ptr<StereoImageSource> source = Open(Folders(folder));
  ASSERT_NE(source, nullptr);
  const std::vector<StereoImagePair> pairs = ReadAll(source.get());
  ASSERT_EQ(pairs.size(), 3u);
  ASSERT_TRUE(pairs[0].timestamp.has_value());
  EXPECT_NEAR(*pairs[0].timestamp, 1403636579.763555584, 1e-6);
  EXPECT_NEAR(*pairs[1].timestamp, 1403636579.813555456, 1e-6);
  EXPECT_NEAR(*pairs[2].timestamp, 1403636579.863555584, 1e-6);

  // A time range counts from the first stamp and keeps frame numbers.
  StereoFolderOptions options = Folders(folder);
  options.selection.from_s = 0.04;
  options.selection.to_s = 0.2;
  const std::unique_ptr<StereoImageSource> range = Open(options);
  ASSERT_NE(range, nullptr);
  EXPECT_EQ(range->Describe(), "folders " + folder.Path("left") + " and " +
                                   folder.Path("right") +
                                   ": 2 pairs (t = 0.040 s to 0.200 s of 3), "
                                   "paired by name");
  const std::vector<StereoImagePair> selected = ReadAll(range.get());
  EXPECT_EQ(Frames(selected), (std::vector<int64_t>{1, 2}));
  EXPECT_EQ(LeftFileNames(selected),
            (std::vector<std::string>{names[1], names[2]}));
}

TEST(StereoImageFolders, DecimalSecondNamesSortByTime) {
  const TempFolder folder;
  // Natural order would put 10.5 before 10.25.
  WritePairsByName(folder, {"10.5.png", "9.75.png", "10.25.png", "10.125.png"},
                   CV_8UC1);
  const std::unique_ptr<StereoImageSource> source = Open(Folders(folder));
  ASSERT_NE(source, nullptr);
  const std::vector<StereoImagePair> pairs = ReadAll(source.get());
  EXPECT_EQ(LeftFileNames(pairs),
            (std::vector<std::string>{"9.75.png", "10.125.png", "10.25.png",
                                      "10.5.png"}));
  std::vector<double> stamps;
  for (const StereoImagePair& pair : pairs) stamps.push_back(*pair.timestamp);
  EXPECT_EQ(stamps, (std::vector<double>{9.75, 10.125, 10.25, 10.5}));
  EXPECT_EQ(Frames(pairs), (std::vector<int64_t>{0, 1, 2, 3}));
}

TEST(StereoImageFolders, FrameNumberNamesCarryNoStamps) {
  const TempFolder folder;
  // Short integers, up to 15 digits, are frame numbers.
  WritePairsByName(folder, {"000000.png", "000001.png", "140363657976355.png"},
                   CV_8UC1);
  const std::unique_ptr<StereoImageSource> source = Open(Folders(folder));
  ASSERT_NE(source, nullptr);
  for (const StereoImagePair& pair : ReadAll(source.get())) {
    EXPECT_FALSE(pair.timestamp.has_value()) << pair.left_name;
  }
  StereoFolderOptions options = Folders(folder);
  options.selection.to_s = 1.0;
  EXPECT_EQ(OpenError(options),
            "folders " + folder.Path("left") + " and " + folder.Path("right") +
                ": a time range needs timestamps, and these images carry "
                "none (use the stride, or name the files by their stamps)");
}

TEST(StereoImageFolders, RefusesNamesMixingStampsAndOthers) {
  const TempFolder folder;
  WritePairsByName(folder, {"1403636579763555584.png", "000001.png"}, CV_8UC1);
  EXPECT_EQ(OpenError(Folders(folder)),
            folder.Path("left") +
                ": 1403636579763555584.png carries a stamp in nanoseconds "
                "but 000001.png carries no stamp: name every image by its "
                "stamp (in one unit) or none");

  const TempFolder units("units");
  WritePairsByName(units, {"1403636579763555584.png", "1403636579.9.png"},
                   CV_8UC1);
  EXPECT_EQ(OpenError(Folders(units)),
            units.Path("left") +
                ": 1403636579.9.png carries a stamp in seconds but "
                "1403636579763555584.png carries a stamp in nanoseconds: "
                "name every image by its stamp (in one unit) or none");
}

TEST(StereoImageFolders, RefusesRepeatedStamps) {
  const TempFolder folder;
  WritePairsByName(folder, {"1.5.png", "1.50.png"}, CV_8UC1);
  EXPECT_EQ(OpenError(Folders(folder)),
            folder.Path("left") +
                ": 1.5.png and 1.50.png carry the same timestamp, 1.5 s: "
                "timestamps must increase from pair to pair");
  // In the right folder too, whose stamps pairing by order checks.
  const TempFolder by_order("by_order");
  for (const std::string name : {"1.0.png", "1.1.png", "1.2.png"}) {
    by_order.WriteImage("cam0/" + name, RandomImage(1, CV_8UC1));
  }
  for (const std::string name : {"1.01.png", "1.11.png", "1.110.png"}) {
    by_order.WriteImage("cam1/" + name, RandomImage(2, CV_8UC1));
  }
  EXPECT_EQ(OpenError(Folders(by_order, "cam0", "cam1")),
            by_order.Path("cam1") +
                ": 1.11.png and 1.110.png carry the same timestamp, 1.11 s: "
                "timestamps must increase from pair to pair");
}

TEST(StereoImageFolders, PairsStampedNamesByOrderWhenInStep) {
  const TempFolder folder;
  // Right stamps 1 ms after the left ones, 100 ms apart.
  for (int i = 0; i < 4; ++i) {
    const std::string tenths = std::to_string(i);
    folder.WriteImage("left/10." + tenths + "00.png", RandomImage(i, CV_8UC1));
    folder.WriteImage("right/10." + tenths + "01.png",
                      RandomImage(10 + i, CV_8UC1));
  }
  const std::unique_ptr<StereoImageSource> source = Open(Folders(folder));
  ASSERT_NE(source, nullptr);
  EXPECT_THAT(source->Describe(), HasSubstr("paired by order"));
  const std::vector<StereoImagePair> pairs = ReadAll(source.get());
  ASSERT_EQ(pairs.size(), 4u);
  EXPECT_EQ(pairs[3].right_name, folder.Path("right/10.301.png"));
  // The left image's stamp.
  EXPECT_EQ(*pairs[3].timestamp, 10.3);
}

TEST(StereoImageFolders, RefusesStampedNamesOutOfStep) {
  const TempFolder folder;
  // Right stamps 60 ms after the left ones, 100 ms apart: out of step.
  for (int i = 0; i < 4; ++i) {
    const std::string tenths = std::to_string(i);
    folder.WriteImage("left/10." + tenths + "00.png", RandomImage(i, CV_8UC1));
    folder.WriteImage("right/10." + tenths + "60.png",
                      RandomImage(10 + i, CV_8UC1));
  }
  EXPECT_EQ(OpenError(Folders(folder)),
            "pairing by order: " + folder.Path("left/10.000.png") + " and " +
                folder.Path("right/10.060.png") +
                " are 0.060 s apart, more than half the frame interval "
                "(0.050 s): the folders are out of step; pair the images "
                "with a list file");
}

TEST(StereoImageFolders, PairsFromListWithTimestampsAndRelativePaths) {
  const TempFolder folder;
  folder.WriteImage("left/a.png", RandomImage(1, CV_8UC3));
  folder.WriteImage("right/a.png", RandomImage(2, CV_8UC3));
  folder.WriteImage("cam/b.png", RandomImage(3, CV_8UC3));
  folder.WriteImage("other/b b.png", RandomImage(4, CV_8UC3));
  folder.WriteImage("abs/c0.png", RandomImage(5, CV_8UC3));
  folder.WriteImage("abs/c1.png", RandomImage(6, CV_8UC3));
  folder.WriteText("pairs.txt",
                   "# left right timestamp\n"
                   "\n"
                   "left/a.png   right/a.png\t100.5\n"
                   "  # a comma-separated line, a path with a blank\n"
                   "cam/b.png, other/b b.png, 100.75\r\n" +
                       folder.Path("abs/c0.png") + " " +
                       folder.Path("abs/c1.png") + " 101");
  StereoFolderOptions options;
  options.pair_list = folder.Path("pairs.txt");
  const std::unique_ptr<StereoImageSource> source = Open(options);
  ASSERT_NE(source, nullptr);
  EXPECT_EQ(source->Describe(), "3 pairs from list " + options.pair_list);
  const std::vector<StereoImagePair> pairs = ReadAll(source.get());
  ASSERT_EQ(pairs.size(), 3u);
  EXPECT_EQ(Frames(pairs), (std::vector<int64_t>{0, 1, 2}));
  EXPECT_EQ(pairs[0].left_name, folder.Path("left/a.png"));
  EXPECT_EQ(pairs[1].left_name, folder.Path("cam/b.png"));
  EXPECT_EQ(pairs[1].right_name, folder.Path("other/b b.png"));
  EXPECT_EQ(pairs[2].right_name, folder.Path("abs/c1.png"));
  EXPECT_EQ(*pairs[0].timestamp, 100.5);
  EXPECT_EQ(*pairs[1].timestamp, 100.75);
  EXPECT_EQ(*pairs[2].timestamp, 101.0);
  for (int i = 0; i < 3; ++i) {
    EXPECT_TRUE(SameImage(pairs[i].left, RandomImage(2 * i + 1, CV_8UC3)));
    EXPECT_TRUE(SameImage(pairs[i].right, RandomImage(2 * i + 2, CV_8UC3)));
  }

  options.selection.from_s = 0.25;
  options.selection.stride = 2;
  const std::unique_ptr<StereoImageSource> selected = Open(options);
  ASSERT_NE(selected, nullptr);
  EXPECT_EQ(selected->Describe(), "1 pair from list " + options.pair_list +
                                      " (every 2nd, t = 0.250 s to end, of "
                                      "3)");
  EXPECT_EQ(Frames(ReadAll(selected.get())), (std::vector<int64_t>{1}));
}

TEST(StereoImageFolders, PairsFromListWithoutTimestamps) {
  const TempFolder folder;
  WritePairsByName(folder, {"x.png", "y.png"}, CV_8UC1);
  // Both lines pair y with x: a list may pair any two files.
  folder.WriteText("pairs.csv",
                   "left/y.png,right/x.png\nleft/x.png,right/y.png\n");
  StereoFolderOptions options;
  options.pair_list = folder.Path("pairs.csv");
  const std::unique_ptr<StereoImageSource> source = Open(options);
  ASSERT_NE(source, nullptr);
  const std::vector<StereoImagePair> pairs = ReadAll(source.get());
  ASSERT_EQ(pairs.size(), 2u);
  EXPECT_FALSE(pairs[0].timestamp.has_value());
  EXPECT_EQ(pairs[0].left_name, folder.Path("left/y.png"));
  EXPECT_EQ(pairs[0].right_name, folder.Path("right/x.png"));
  EXPECT_TRUE(SameImage(pairs[0].left, RandomImage(2, CV_8UC1)));
  EXPECT_TRUE(SameImage(pairs[0].right, RandomImage(1, CV_8UC1)));

  options.selection.from_s = 1.0;
  EXPECT_EQ(OpenError(options),
            options.pair_list +
                ": a time range needs timestamps: give each pair's stamp in "
                "seconds as a third column");
}

TEST(StereoImageFolders, RefusesMalformedLists) {
  const TempFolder folder;
  WritePairsByName(folder, {"a.png"}, CV_8UC1);
  const std::string list = folder.Path("pairs.txt");
  const std::string left = folder.Path("left/a.png");
  struct Case {
    std::string contents;
    std::string message;
  };
  const std::vector<Case> cases = {
      {"left/a.png\n", ":1: expected LEFT RIGHT [TIMESTAMP], found 1 field"},
      {"# comment\nleft/a.png right/a.png 1 extra\n",
       ":2: expected LEFT RIGHT [TIMESTAMP], found 4 fields"},
      {"left/a.png, , 1\n", ":1: empty right path"},
      {"left/a.png right/a.png 1.5x\n",
       ":1: timestamp '1.5x' is not a number of seconds"},
      {"left/a.png right/a.png nan\n",
       ":1: timestamp 'nan' is not a number of seconds"},
      {"left/a.png right/a.png 1\nleft/a.png right/a.png\n",
       ":2: no timestamp, but line 1 has one: give a timestamp on every line "
       "or on none"},
      {"\nleft/a.png right/a.png\nleft/a.png right/a.png 2\n",
       ":3: a timestamp, but line 2 has none: give a timestamp on every line "
       "or on none"},
      {"left/a.png right/missing.png\n",
       ":1: " + folder.Path("right/missing.png") + ": no such file"},
      {"left right/a.png\n", ":1: " + folder.Path("left") + ": not a file"},
      {"left/a.png right/a.png 2\nleft/a.png right/a.png 1\n",
       ":2: " + left + " (t = 1.0 s) is not after " + left +
           " (t = 2.0 s): timestamps must increase from pair to pair"},
      {"# nothing\n\n", ": no pairs listed"},
      {"", ": no pairs listed"},
  };
  StereoFolderOptions options;
  options.pair_list = list;
  for (const Case& c : cases) {
    folder.WriteText("pairs.txt", c.contents);
    EXPECT_EQ(OpenError(options), list + c.message) << c.contents;
  }
  options.pair_list = folder.Path("missing.txt");
  EXPECT_EQ(OpenError(options),
            options.pair_list + ": cannot open: No such file or directory");
}

TEST(StereoImageFolders, RefusesSixteenBitImages) {
  const TempFolder folder;
  WritePairsByName(folder, {"0.png", "1.png"}, CV_8UC1);
  folder.WriteImage("right/1.png", RandomImage(1, CV_16UC1));
  const std::unique_ptr<StereoImageSource> source = Open(Folders(folder));
  ASSERT_NE(source, nullptr);
  EXPECT_TRUE(source->ReadPair(0).ok());
  const StatusOr<StereoImagePair> pair = source->ReadPair(1);
  ASSERT_FALSE(pair.ok());
  EXPECT_EQ(pair.status().message(),
            folder.Path("right/1.png") + ": 16-bit image, expected 8-bit");
}

TEST(StereoImageFolders, RefusesCorruptImages) {
  const TempFolder folder;
  WritePairsByName(folder, {"0.png", "1.png", "2.png"}, CV_8UC3);
  std::string noise(2000, '\0');
  cv::RNG rng(7);
  for (char& byte : noise) byte = static_cast<char>(rng.uniform(0, 256));
  folder.WriteText("left/1.png", noise);
  folder.WriteText("right/2.png", "");
  const std::unique_ptr<StereoImageSource> source = Open(Folders(folder));
  ASSERT_NE(source, nullptr);
  const std::string expected =
      ": not an image OpenCV can decode (corrupt or unsupported format)";
  const StatusOr<StereoImagePair> noisy = source->ReadPair(1);
  ASSERT_FALSE(noisy.ok());
  EXPECT_EQ(noisy.status().message(), folder.Path("left/1.png") + expected);
  const StatusOr<StereoImagePair> empty = source->ReadPair(2);
  ASSERT_FALSE(empty.ok());
  EXPECT_EQ(empty.status().message(), folder.Path("right/2.png") + expected);
  // The source still reads the good pair.
  const StatusOr<StereoImagePair> good = source->ReadPair(0);
  ASSERT_TRUE(good.ok()) << good.status().message();
  EXPECT_TRUE(SameImage(good->left, RandomImage(0, CV_8UC3)));
}

TEST(StereoImageFolders, RefusesPairsOfDifferentSizes) {
  const TempFolder folder;
  folder.WriteImage("left/0.png", RandomImage(1, CV_8UC1));
  folder.WriteImage("right/0.png", RandomImage(2, CV_8UC1, cv::Size(64, 48)));
  const std::unique_ptr<StereoImageSource> source = Open(Folders(folder));
  ASSERT_NE(source, nullptr);
  const StatusOr<StereoImagePair> pair = source->ReadPair(0);
  ASSERT_FALSE(pair.ok());
  EXPECT_EQ(pair.status().message(),
            folder.Path("left/0.png") + " is 32x24 but " +
                folder.Path("right/0.png") +
                " is 64x48: the two images of a pair must have the same size");
}

TEST(StereoImageFolders, StrideKeepsFrameNumbers) {
  const TempFolder folder;
  std::vector<std::string> names;
  for (int i = 0; i < 10; ++i) names.push_back(std::to_string(i) + ".png");
  WritePairsByName(folder, names, CV_8UC1);
  StereoFolderOptions options = Folders(folder);
  options.selection.stride = 3;
  const std::unique_ptr<StereoImageSource> source = Open(options);
  ASSERT_NE(source, nullptr);
  EXPECT_EQ(source->Describe(), "folders " + folder.Path("left") + " and " +
                                    folder.Path("right") +
                                    ": 4 pairs (every 3rd of 10), paired by "
                                    "name");
  const std::vector<StereoImagePair> pairs = ReadAll(source.get());
  EXPECT_EQ(Frames(pairs), (std::vector<int64_t>{0, 3, 6, 9}));
  ASSERT_EQ(pairs.size(), 4u);
  EXPECT_EQ(pairs[2].left_name, folder.Path("left/6.png"));
  EXPECT_TRUE(SameImage(pairs[2].left, RandomImage(12, CV_8UC1)));
  EXPECT_TRUE(SameImage(pairs[2].right, RandomImage(13, CV_8UC1)));
}

TEST(StereoImageFolders, RefusesATimeRangeOutsideTheSequence) {
  const TempFolder folder;
  WritePairsByName(folder, {"5.0.png", "5.1.png"}, CV_8UC1);
  StereoFolderOptions options = Folders(folder);
  options.selection.from_s = 10.0;
  EXPECT_EQ(OpenError(options),
            "folders " + folder.Path("left") + " and " + folder.Path("right") +
                ": no stereo pair between 10.000 s and the end: the sequence "
                "lasts 0.100 s");
}

}  // namespace
}  // namespace rcm::stereo_image_folders_test
