#include "rcm/sim/media_schedule.h"

#include <gtest/gtest.h>

namespace rcm::media_schedule_test {
namespace {

TEST(MediaSchedule, ParsesNamesAndIndices) {
  const MediaSchedule schedule =
      MediaSchedule::Parse("water:3, air:2,1.345:1", 1.333).value();
  EXPECT_EQ(schedule.num_frames(), 6);
  EXPECT_EQ(schedule.PerFrame(),
            (std::vector<double>{1.333, 1.333, 1.333, 1.0, 1.0, 1.345}));
  EXPECT_EQ(schedule.SwitchFrames(), (std::vector<int>{3, 5}));
  EXPECT_EQ(schedule.ToString(), "1.333:3,1.0:2,1.345:1");
}

TEST(MediaSchedule, RepeatedMediumIsNotASwitch) {
  const MediaSchedule schedule =
      MediaSchedule::Parse("water:2,water:2", 1.34).value();
  EXPECT_TRUE(schedule.SwitchFrames().empty());
  EXPECT_EQ(MediaSchedule::Constant(1.2, 5).value().num_frames(), 5);
}

TEST(MediaSchedule, RejectsMalformedText) {
  for (const char* bad :
       {"", "water", "water:", "water:0", "water:-1", "water:2.5", "oil:3",
        "2.5:3", "0.9:3", "nan:3", "water:3,", ",water:3", "water:3x",
        "water:99999999999"}) {
    const StatusOr<MediaSchedule> schedule = MediaSchedule::Parse(bad, 1.333);
    EXPECT_FALSE(schedule.ok()) << bad;
    if (!schedule.ok()) {
      EXPECT_EQ(schedule.status().message().find('\n'), std::string::npos);
    }
  }
}

TEST(MediaSchedule, RejectsWaterIndexOutsideRange) {
  EXPECT_FALSE(MediaSchedule::Parse("water:3", 2.5).ok());
  EXPECT_FALSE(MediaSchedule::Create({}).ok());
}

}  // namespace
}  // namespace rcm::media_schedule_test
