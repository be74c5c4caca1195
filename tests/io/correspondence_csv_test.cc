#include "rcm/io/correspondence_csv.h"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>

namespace rcm::correspondence_csv_test {
namespace {

uint64_t Bits(double value) {
  uint64_t bits;
  std::memcpy(&bits, &value, sizeof(bits));
  return bits;
}

bool PathExists(const std::string& path) {
  struct stat info;
  return stat(path.c_str(), &info) == 0;
}

std::string ErrorOf(const std::string& text) {
  const StatusOr<std::vector<StereoCorrespondence>> parsed =
      ParseCorrespondenceCsv(text, "m.csv");
  if (parsed.ok()) return "(parsed fine)";
  return parsed.status().message();
}

// Random correspondences with pixel-like values, values of every magnitude
// and a few awkward doubles; frames non-decreasing.
std::vector<StereoCorrespondence> RandomCorrespondences(bool with_time,
                                                        uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> pixel(-100.0, 1000.0);
  std::uniform_real_distribution<double> exponent(-300.0, 300.0);
  std::uniform_int_distribution<int> frame_step(0, 2);
  const double awkward[] = {-0.0,
                            0.1,
                            1.0 / 3.0,
                            std::numeric_limits<double>::denorm_min(),
                            std::numeric_limits<double>::min(),
                            std::numeric_limits<double>::max(),
                            -std::numeric_limits<double>::max(),
                            1690000000.0500001};
  std::vector<StereoCorrespondence> correspondences;
  int64_t frame = 0;
  for (int i = 0; i < 500; ++i) {
    StereoCorrespondence correspondence;
    frame += frame_step(rng);
    correspondence.frame = frame;
    double values[5];
    for (double& value : values) {
      switch (rng() % 3) {
        case 0:
          value = pixel(rng);
          break;
        case 1:
          value = (rng() % 2 == 0 ? 1.0 : -1.0) * pixel(rng) *
                  std::pow(10.0, exponent(rng));
          break;
        default:
          value = awkward[rng() % (sizeof(awkward) / sizeof(awkward[0]))];
      }
    }
    correspondence.left_pixel = {values[0], values[1]};
    correspondence.right_pixel = {values[2], values[3]};
    if (with_time) correspondence.timestamp = values[4];
    correspondences.push_back(correspondence);
  }
  return correspondences;
}

void ExpectBitIdentical(const std::vector<StereoCorrespondence>& expected,
                        const std::vector<StereoCorrespondence>& actual) {
  ASSERT_EQ(actual.size(), expected.size());
  for (size_t i = 0; i < expected.size(); ++i) {
    SCOPED_TRACE("row " + std::to_string(i));
    EXPECT_EQ(actual[i].frame, expected[i].frame);
    for (int k = 0; k < 2; ++k) {
      EXPECT_EQ(Bits(actual[i].left_pixel[k]), Bits(expected[i].left_pixel[k]));
      EXPECT_EQ(Bits(actual[i].right_pixel[k]),
                Bits(expected[i].right_pixel[k]));
    }
    ASSERT_EQ(actual[i].timestamp.has_value(),
              expected[i].timestamp.has_value());
    if (expected[i].timestamp.has_value()) {
      EXPECT_EQ(Bits(*actual[i].timestamp), Bits(*expected[i].timestamp));
    }
  }
}

TEST(CorrespondenceCsv, ParsesMinimalFile) {
  const auto parsed = ParseCorrespondenceCsv(
      "xl,yl,xr,yr\n1.5,2,3,4\n-5,6.25,7,8e2\n", "m.csv");
  ASSERT_TRUE(parsed.ok()) << parsed.status().message();
  ASSERT_EQ(parsed->size(), 2u);
  EXPECT_EQ((*parsed)[0].frame, 0);
  EXPECT_FALSE((*parsed)[0].timestamp.has_value());
  EXPECT_EQ((*parsed)[0].left_pixel, Eigen::Vector2d(1.5, 2.0));
  EXPECT_EQ((*parsed)[0].right_pixel, Eigen::Vector2d(3.0, 4.0));
  EXPECT_EQ((*parsed)[1].frame, 0);
  EXPECT_EQ((*parsed)[1].left_pixel, Eigen::Vector2d(-5.0, 6.25));
  EXPECT_EQ((*parsed)[1].right_pixel, Eigen::Vector2d(7.0, 800.0));
}

TEST(CorrespondenceCsv, ParsesLastLineWithoutNewline) {
  const auto parsed = ParseCorrespondenceCsv("xl,yl,xr,yr\n1,2,3,4", "m.csv");
  ASSERT_TRUE(parsed.ok()) << parsed.status().message();
  ASSERT_EQ(parsed->size(), 1u);
  EXPECT_EQ((*parsed)[0].right_pixel, Eigen::Vector2d(3.0, 4.0));
}

TEST(CorrespondenceCsv, ParsesFrameAndTime) {
  const auto parsed = ParseCorrespondenceCsv(
      "frame,xl,yl,xr,yr,t\n"
      "0,1,2,3,4,100.5\n"
      "0,5,6,7,8,100.5\n"
      "7,9,10,11,12,100.55\n",
      "m.csv");
  ASSERT_TRUE(parsed.ok()) << parsed.status().message();
  ASSERT_EQ(parsed->size(), 3u);
  EXPECT_EQ((*parsed)[0].frame, 0);
  EXPECT_EQ((*parsed)[1].frame, 0);
  EXPECT_EQ((*parsed)[2].frame, 7);
  ASSERT_TRUE((*parsed)[0].timestamp.has_value());
  EXPECT_EQ(*(*parsed)[0].timestamp, 100.5);
  ASSERT_TRUE((*parsed)[2].timestamp.has_value());
  EXPECT_EQ(*(*parsed)[2].timestamp, 100.55);
  EXPECT_EQ((*parsed)[2].left_pixel, Eigen::Vector2d(9.0, 10.0));
  EXPECT_EQ((*parsed)[2].right_pixel, Eigen::Vector2d(11.0, 12.0));
}

TEST(CorrespondenceCsv, ParsesColumnsInAnyOrder) {
  const auto parsed =
      ParseCorrespondenceCsv("yr,t,xr,frame,yl,xl\n4,9.5,3,2,2,1\n", "m.csv");
  ASSERT_TRUE(parsed.ok()) << parsed.status().message();
  ASSERT_EQ(parsed->size(), 1u);
  EXPECT_EQ((*parsed)[0].frame, 2);
  EXPECT_EQ(*(*parsed)[0].timestamp, 9.5);
  EXPECT_EQ((*parsed)[0].left_pixel, Eigen::Vector2d(1.0, 2.0));
  EXPECT_EQ((*parsed)[0].right_pixel, Eigen::Vector2d(3.0, 4.0));
}

TEST(CorrespondenceCsv, IgnoresUnknownColumn) {
  const auto parsed = ParseCorrespondenceCsv(
      "frame,xl,yl,score,xr,yr\n3,1,2,high,3,4\n", "m.csv");
  ASSERT_TRUE(parsed.ok()) << parsed.status().message();
  ASSERT_EQ(parsed->size(), 1u);
  EXPECT_EQ((*parsed)[0].frame, 3);
  EXPECT_EQ((*parsed)[0].left_pixel, Eigen::Vector2d(1.0, 2.0));
  EXPECT_EQ((*parsed)[0].right_pixel, Eigen::Vector2d(3.0, 4.0));
}

TEST(CorrespondenceCsv, ToleratesCrlfBomCommentsAndBlankLines) {
  const auto parsed = ParseCorrespondenceCsv(
      "\xEF\xBB\xBF# matches from sift\r\n"
      "\r\n"
      "frame,xl,yl,xr,yr\r\n"
      "  # a comment between rows\r\n"
      "0,1,2,3,4\r\n"
      "   \t\r\n"
      "1,5,6,7,8\r\n",
      "m.csv");
  ASSERT_TRUE(parsed.ok()) << parsed.status().message();
  ASSERT_EQ(parsed->size(), 2u);
  EXPECT_EQ((*parsed)[1].frame, 1);
  EXPECT_EQ((*parsed)[1].left_pixel, Eigen::Vector2d(5.0, 6.0));
  EXPECT_EQ((*parsed)[1].right_pixel, Eigen::Vector2d(7.0, 8.0));
}

TEST(CorrespondenceCsv, ToleratesSpacesAroundFields) {
  const auto parsed = ParseCorrespondenceCsv(
      " frame , xl,yl ,\txr, yr\n 2 , 1 ,2, 3\t, 4 \n", "m.csv");
  ASSERT_TRUE(parsed.ok()) << parsed.status().message();
  ASSERT_EQ(parsed->size(), 1u);
  EXPECT_EQ((*parsed)[0].frame, 2);
  EXPECT_EQ((*parsed)[0].left_pixel, Eigen::Vector2d(1.0, 2.0));
  EXPECT_EQ((*parsed)[0].right_pixel, Eigen::Vector2d(3.0, 4.0));
}

TEST(CorrespondenceCsv, FormatsWithoutTimeColumn) {
  StereoCorrespondence correspondence;
  correspondence.frame = 4;
  correspondence.left_pixel = {0.1, -2.0};
  correspondence.right_pixel = {1e-7, 1234.5};
  EXPECT_EQ(FormatCorrespondenceCsv({correspondence}),
            "frame,xl,yl,xr,yr\n4,0.1,-2,1e-07,1234.5\n");
}

TEST(CorrespondenceCsv, FormatsTimeColumnWhenEveryRowHasTime) {
  StereoCorrespondence correspondence;
  correspondence.frame = 1;
  correspondence.timestamp = 1690000000.05;
  correspondence.left_pixel = {1.0, 2.0};
  correspondence.right_pixel = {3.0, 4.0};
  EXPECT_EQ(FormatCorrespondenceCsv({correspondence, correspondence}),
            "frame,xl,yl,xr,yr,t\n"
            "1,1,2,3,4,1690000000.05\n"
            "1,1,2,3,4,1690000000.05\n");
}

TEST(CorrespondenceCsvDeathTest, FormatRejectsTimeOnSomeRowsOnly) {
  StereoCorrespondence with_time;
  with_time.timestamp = 1.0;
  const StereoCorrespondence without_time;
  EXPECT_DEATH(FormatCorrespondenceCsv({with_time, without_time}),
               "all or none of the correspondences need a timestamp");
}

TEST(CorrespondenceCsv, RoundTripIsBitIdenticalWithoutTime) {
  const std::vector<StereoCorrespondence> original =
      RandomCorrespondences(/*with_time=*/false, /*seed=*/20240611);
  const auto parsed =
      ParseCorrespondenceCsv(FormatCorrespondenceCsv(original), "m.csv");
  ASSERT_TRUE(parsed.ok()) << parsed.status().message();
  ExpectBitIdentical(original, *parsed);
}

TEST(CorrespondenceCsv, RoundTripIsBitIdenticalWithTime) {
  const std::vector<StereoCorrespondence> original =
      RandomCorrespondences(/*with_time=*/true, /*seed=*/77);
  const auto parsed =
      ParseCorrespondenceCsv(FormatCorrespondenceCsv(original), "m.csv");
  ASSERT_TRUE(parsed.ok()) << parsed.status().message();
  ExpectBitIdentical(original, *parsed);
}

TEST(CorrespondenceCsv, WritesAndReadsFile) {
  const std::string path =
      ::testing::TempDir() + "/correspondence_csv_test_matches.csv";
  const std::vector<StereoCorrespondence> original =
      RandomCorrespondences(/*with_time=*/true, /*seed=*/5);
  const Status written = WriteCorrespondenceCsv(path, original);
  ASSERT_TRUE(written.ok()) << written.message();
  const auto read = ReadCorrespondenceCsv(path);
  ASSERT_TRUE(read.ok()) << read.status().message();
  ExpectBitIdentical(original, *read);
  unlink(path.c_str());
}

TEST(CorrespondenceCsv, WriteIntoMissingDirectoryFailsAndCreatesNothing) {
  const std::string directory =
      ::testing::TempDir() + "/correspondence_csv_test_no_such_directory";
  const std::string path = directory + "/matches.csv";
  StereoCorrespondence correspondence;
  const Status written = WriteCorrespondenceCsv(path, {correspondence});
  ASSERT_FALSE(written.ok());
  EXPECT_EQ(written.message().rfind(path + ": ", 0), 0u) << written.message();
  EXPECT_FALSE(PathExists(directory));
  EXPECT_FALSE(PathExists(path));
}

TEST(CorrespondenceCsv, ReadMissingFileReportsPath) {
  const std::string path =
      ::testing::TempDir() + "/correspondence_csv_test_missing.csv";
  const auto read = ReadCorrespondenceCsv(path);
  ASSERT_FALSE(read.ok());
  EXPECT_EQ(read.status().message().rfind(path + ": cannot open: ", 0), 0u)
      << read.status().message();
}

TEST(CorrespondenceCsv, ReadDirectoryReportsDirectory) {
  const std::string path = ::testing::TempDir();
  const auto read = ReadCorrespondenceCsv(path);
  ASSERT_FALSE(read.ok());
  EXPECT_EQ(read.status().message().rfind(path + ": is a directory", 0), 0u)
      << read.status().message();
}

TEST(CorrespondenceCsv, ErrorHeaderLacksColumn) {
  EXPECT_EQ(ErrorOf("frame,xl,yl,xr\n0,1,2,3\n"),
            "m.csv:1: header lacks column 'yr' (expected frame,xl,yl,xr,yr "
            "with optional t)");
}

TEST(CorrespondenceCsv, ErrorHeaderMissingReportsFirstDataLine) {
  EXPECT_EQ(ErrorOf("# no header\n0,1,2,3,4\n"),
            "m.csv:2: header lacks column 'xl' (expected frame,xl,yl,xr,yr "
            "with optional t)");
}

TEST(CorrespondenceCsv, ErrorColumnAppearsTwice) {
  EXPECT_EQ(ErrorOf("xl,yl,xr,yr,xl\n1,2,3,4,5\n"),
            "m.csv:1: column 'xl' appears twice");
}

TEST(CorrespondenceCsv, ErrorWrongFieldCount) {
  EXPECT_EQ(ErrorOf("frame,xl,yl,xr,yr\n"
                    "0,1,2,3,4\n"
                    "0,1,2,3,4\n"
                    "0,1,2,3,4\n"
                    "\n"
                    "# comment\n"
                    "0,1,2,3\n"),
            "m.csv:7: expected 5 fields, got 4");
}

TEST(CorrespondenceCsv, ErrorTrailingCommaCountsAsField) {
  EXPECT_EQ(ErrorOf("xl,yl,xr,yr\n1,2,3,4,\n"),
            "m.csv:2: expected 4 fields, got 5");
}

TEST(CorrespondenceCsv, ErrorNotANumber) {
  EXPECT_EQ(ErrorOf("xl,yl,xr,yr\nabc,2,3,4\n"),
            "m.csv:2: xl: 'abc' is not a number");
}

TEST(CorrespondenceCsv, ErrorNumberWithTrailingCharacters) {
  EXPECT_EQ(ErrorOf("xl,yl,xr,yr\n1,2px,3,4\n"),
            "m.csv:2: yl: '2px' is not a number");
}

TEST(CorrespondenceCsv, ErrorEmptyField) {
  EXPECT_EQ(ErrorOf("xl,yl,xr,yr\n1,2, ,4\n"),
            "m.csv:2: xr: '' is not a number");
}

TEST(CorrespondenceCsv, ErrorLongFieldIsShortenedInMessage) {
  const std::string message =
      ErrorOf("xl,yl,xr,yr\n1,2,3," + std::string(100000, '7') + "x\n");
  EXPECT_EQ(message,
            "m.csv:2: yr: '" + std::string(40, '7') + "...' is not a number");
}

TEST(CorrespondenceCsv, ErrorNotFinite) {
  EXPECT_EQ(ErrorOf("frame,xl,yl,xr,yr\n"
                    "0,1,2,3,4\n"
                    "0,1,2,3,4\n"
                    "0,1,2,3,4\n"
                    "0,1,2,3,4\n"
                    "0,1,2,3,4\n"
                    "0,1,2,3,4\n"
                    "0,1,2,3,4\n"
                    "0,1,2,3,nan\n"),
            "m.csv:9: yr: nan is not finite");
}

TEST(CorrespondenceCsv, ErrorTimeNotFinite) {
  EXPECT_EQ(ErrorOf("xl,yl,xr,yr,t\n1,2,3,4,inf\n"),
            "m.csv:2: t: inf is not finite");
}

TEST(CorrespondenceCsv, ErrorNumberOutOfRange) {
  EXPECT_EQ(ErrorOf("xl,yl,xr,yr\n1e999,2,3,4\n"),
            "m.csv:2: xl: '1e999' is out of the range of a double");
}

TEST(CorrespondenceCsv, ErrorFrameNotInteger) {
  EXPECT_EQ(ErrorOf("frame,xl,yl,xr,yr\n0,1,2,3,4\n\n2.5,1,2,3,4\n"),
            "m.csv:4: frame: '2.5' is not a non-negative integer");
}

TEST(CorrespondenceCsv, ErrorFrameNegative) {
  EXPECT_EQ(ErrorOf("frame,xl,yl,xr,yr\n-1,1,2,3,4\n"),
            "m.csv:2: frame: '-1' is not a non-negative integer");
}

TEST(CorrespondenceCsv, ErrorFrameTooLarge) {
  EXPECT_EQ(ErrorOf("frame,xl,yl,xr,yr\n99999999999999999999,1,2,3,4\n"),
            "m.csv:2: frame: '99999999999999999999' is not a non-negative "
            "integer");
}

TEST(CorrespondenceCsv, ErrorFramesDecrease) {
  EXPECT_EQ(ErrorOf("frame,xl,yl,xr,yr\n"
                    "0,1,2,3,4\n"
                    "1,1,2,3,4\n"
                    "2,1,2,3,4\n"
                    "3,1,2,3,4\n"
                    "4,1,2,3,4\n"
                    "5,1,2,3,4\n"
                    "5,1,2,3,4\n"
                    "# late matches\n"
                    "5,1,2,3,4\n"
                    "\n"
                    "3,1,2,3,4\n"),
            "m.csv:12: frame 3 after frame 5: frames must not decrease");
}

TEST(CorrespondenceCsv, ErrorEmptyFile) {
  EXPECT_EQ(ErrorOf(""), "m.csv: empty file");
}

TEST(CorrespondenceCsv, ErrorOnlyCommentsAndBlankLinesIsEmpty) {
  EXPECT_EQ(ErrorOf("\xEF\xBB\xBF# nothing yet\r\n\r\n  \n"),
            "m.csv: empty file");
}

TEST(CorrespondenceCsv, ErrorNoCorrespondencesAfterHeader) {
  EXPECT_EQ(ErrorOf("frame,xl,yl,xr,yr\n# none\n\n"),
            "m.csv: no correspondences after the header");
}

TEST(CorrespondenceCsv, ErrorMessageHasNoControlCharacters) {
  EXPECT_EQ(ErrorOf("xl,yl,xr,yr\n1\r2,2,3,4\n"),
            "m.csv:2: xl: '1\\x0d2' is not a number");
}

}  // namespace
}  // namespace rcm::correspondence_csv_test
