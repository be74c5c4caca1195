#include "rcm/io/stereo_image_source.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

namespace rcm::stereo_image_source_test {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;

// 100 s, 100.25 s, ...: steps a double holds exactly, so that the
// inclusive bounds are tested without rounding.
std::vector<double> Stamps(size_t n) {
  std::vector<double> stamps;
  for (size_t i = 0; i < n; ++i) stamps.push_back(100.0 + 0.25 * i);
  return stamps;
}

FrameSelection Range(std::optional<double> from_s, std::optional<double> to_s,
                     int stride = 1) {
  FrameSelection selection;
  selection.from_s = from_s;
  selection.to_s = to_s;
  selection.stride = stride;
  return selection;
}

TEST(FrameSelection, CheckAcceptsDefaultsAndValidRanges) {
  EXPECT_TRUE(FrameSelection().Check().ok());
  EXPECT_FALSE(FrameSelection().HasTimeRange());
  EXPECT_TRUE(Range(0.0, 0.0).Check().ok());
  EXPECT_TRUE(Range(2.5, std::nullopt, 3).Check().ok());
  EXPECT_TRUE(Range(std::nullopt, 7.0).Check().ok());
  EXPECT_TRUE(Range(std::nullopt, 7.0).HasTimeRange());
}

TEST(FrameSelection, CheckRejectsStrideBelowOne) {
  for (const int stride : {0, -2}) {
    const Status status = Range(std::nullopt, std::nullopt, stride).Check();
    ASSERT_FALSE(status.ok());
    EXPECT_EQ(status.message(),
              "stride must be at least 1, got " + std::to_string(stride));
  }
}

TEST(FrameSelection, CheckRejectsNegativeAndNonFiniteTimes) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  for (const double bad : {-0.5, nan, inf, -inf}) {
    const Status from = Range(bad, std::nullopt).Check();
    ASSERT_FALSE(from.ok()) << bad;
    EXPECT_EQ(from.message(),
              "time range: 'from' must be a finite number of seconds >= 0");
    const Status to = Range(std::nullopt, bad).Check();
    ASSERT_FALSE(to.ok()) << bad;
    EXPECT_EQ(to.message(),
              "time range: 'to' must be a finite number of seconds >= 0");
  }
}

TEST(FrameSelection, CheckRejectsFromAfterTo) {
  const Status status = Range(20.0, 10.0).Check();
  ASSERT_FALSE(status.ok());
  EXPECT_EQ(status.message(), "time range: from 20.000 s is after to 10.000 s");
}

TEST(SelectFrames, KeepsEveryPairByDefault) {
  const StatusOr<std::vector<size_t>> all = SelectFrames({}, 4, {});
  ASSERT_TRUE(all.ok()) << all.status().message();
  EXPECT_THAT(*all, ElementsAre(0, 1, 2, 3));
  const StatusOr<std::vector<size_t>> stamped = SelectFrames(Stamps(3), 3, {});
  ASSERT_TRUE(stamped.ok());
  EXPECT_THAT(*stamped, ElementsAre(0, 1, 2));
}

TEST(SelectFrames, StrideStartsWithTheFirstPair) {
  const StatusOr<std::vector<size_t>> selected =
      SelectFrames({}, 10, Range(std::nullopt, std::nullopt, 3));
  ASSERT_TRUE(selected.ok()) << selected.status().message();
  EXPECT_THAT(*selected, ElementsAre(0, 3, 6, 9));
  // A stride longer than the sequence keeps the first pair.
  const StatusOr<std::vector<size_t>> first =
      SelectFrames({}, 3, Range(std::nullopt, std::nullopt, 5));
  ASSERT_TRUE(first.ok());
  EXPECT_THAT(*first, ElementsAre(0));
}

TEST(SelectFrames, BoundsAreInclusiveAndRelativeToTheFirstStamp) {
  // Stamps 100, 100.25, ..., 102.25: t = 0, 0.25, ..., 2.25.
  const StatusOr<std::vector<size_t>> selected =
      SelectFrames(Stamps(10), 10, Range(0.5, 1.0));
  ASSERT_TRUE(selected.ok()) << selected.status().message();
  EXPECT_THAT(*selected, ElementsAre(2, 3, 4));

  const StatusOr<std::vector<size_t>> from =
      SelectFrames(Stamps(10), 10, Range(1.75, std::nullopt));
  ASSERT_TRUE(from.ok());
  EXPECT_THAT(*from, ElementsAre(7, 8, 9));

  const StatusOr<std::vector<size_t>> to =
      SelectFrames(Stamps(10), 10, Range(std::nullopt, 0.25));
  ASSERT_TRUE(to.ok());
  EXPECT_THAT(*to, ElementsAre(0, 1));

  // One instant: the pair stamped exactly then.
  const StatusOr<std::vector<size_t>> instant =
      SelectFrames(Stamps(10), 10, Range(1.5, 1.5));
  ASSERT_TRUE(instant.ok());
  EXPECT_THAT(*instant, ElementsAre(6));
}

TEST(SelectFrames, StrideCountsWithinTheTimeRange) {
  const StatusOr<std::vector<size_t>> selected =
      SelectFrames(Stamps(20), 20, Range(0.75, 3.0, 4));
  ASSERT_TRUE(selected.ok()) << selected.status().message();
  // In range: 3..12; every 4th of those, starting with 3.
  EXPECT_THAT(*selected, ElementsAre(3, 7, 11));
}

TEST(SelectFrames, TimeRangeWithoutTimestampsFails) {
  const StatusOr<std::vector<size_t>> selected =
      SelectFrames({}, 10, Range(1.0, std::nullopt));
  ASSERT_FALSE(selected.ok());
  EXPECT_THAT(selected.status().message(),
              HasSubstr("a time range needs timestamps"));
}

TEST(SelectFrames, EmptySelectionNamesTheSequenceLength) {
  // t = 0 .. 2.25 s.
  const StatusOr<std::vector<size_t>> after =
      SelectFrames(Stamps(10), 10, Range(10.0, 20.0));
  ASSERT_FALSE(after.ok());
  EXPECT_EQ(after.status().message(),
            "no stereo pair between 10.000 s and 20.000 s: the sequence "
            "lasts 2.250 s");
  // Between two pairs.
  const StatusOr<std::vector<size_t>> between =
      SelectFrames(Stamps(10), 10, Range(0.3, 0.4));
  ASSERT_FALSE(between.ok());
  EXPECT_EQ(between.status().message(),
            "no stereo pair between 0.300 s and 0.400 s: the sequence lasts "
            "2.250 s");
  const StatusOr<std::vector<size_t>> open_end =
      SelectFrames(Stamps(10), 10, Range(3.0, std::nullopt));
  ASSERT_FALSE(open_end.ok());
  EXPECT_EQ(open_end.status().message(),
            "no stereo pair between 3.000 s and the end: the sequence lasts "
            "2.250 s");
}

TEST(SelectFrames, RejectsAnInvalidSelectionAndNoPairs) {
  const StatusOr<std::vector<size_t>> reversed =
      SelectFrames(Stamps(10), 10, Range(2.0, 1.0));
  ASSERT_FALSE(reversed.ok());
  EXPECT_EQ(reversed.status().message(),
            "time range: from 2.000 s is after to 1.000 s");
  const StatusOr<std::vector<size_t>> nan = SelectFrames(
      Stamps(10), 10, Range(std::numeric_limits<double>::quiet_NaN(), 1.0));
  ASSERT_FALSE(nan.ok());
  EXPECT_THAT(nan.status().message(), HasSubstr("'from' must be a finite"));
  const StatusOr<std::vector<size_t>> none = SelectFrames({}, 0, {});
  ASSERT_FALSE(none.ok());
  EXPECT_EQ(none.status().message(), "no stereo pair");
}

}  // namespace
}  // namespace rcm::stereo_image_source_test
