#include "rcm/util/status.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace rcm::status_test {
namespace {

StatusOr<std::vector<int>> MakeVector(bool fail) {
  if (fail) return Status::Error("no vector");
  return std::vector<int>{1, 2, 3};
}

Status Chain(bool fail) {
  RCM_RETURN_IF_ERROR(fail ? Status::Error("inner") : Status::Ok());
  return Status::Error("reached the end");
}

TEST(Status, OkAndError) {
  EXPECT_TRUE(Status::Ok().ok());
  EXPECT_TRUE(Status().message().empty());
  const Status error = Status::Error("bad thing");
  EXPECT_FALSE(error.ok());
  EXPECT_EQ(error.message(), "bad thing");
  EXPECT_EQ(error.WithContext("file.yaml").message(), "file.yaml: bad thing");
  EXPECT_TRUE(Status::Ok().WithContext("file.yaml").ok());
}

TEST(Status, ReturnIfErrorPropagates) {
  EXPECT_EQ(Chain(true).message(), "inner");
  EXPECT_EQ(Chain(false).message(), "reached the end");
}

TEST(StatusOr, HoldsValueOrStatus) {
  const StatusOr<std::vector<int>> good = MakeVector(false);
  ASSERT_TRUE(good.ok());
  EXPECT_EQ(good->size(), 3u);
  EXPECT_TRUE(good.status().ok());
  const StatusOr<std::vector<int>> bad = MakeVector(true);
  EXPECT_FALSE(bad.ok());
  EXPECT_EQ(bad.status().message(), "no vector");
}

TEST(StatusOr, RangeForOverTemporaryValueIsSafe) {
  // value() on an rvalue returns by value, so the loop owns the vector.
  int sum = 0;
  for (int x : MakeVector(false).value()) sum += x;
  EXPECT_EQ(sum, 6);
}

TEST(StatusOrDeathTest, ValueOfErrorIsProgrammerError) {
  const StatusOr<int> bad = Status::Error("nothing here");
  EXPECT_DEATH((void)bad.value(), "nothing here");
}

TEST(StatusOrDeathTest, ConstructionFromOkStatusIsProgrammerError) {
  EXPECT_DEATH((void)StatusOr<int>(Status::Ok()), "OK status");
}

}  // namespace
}  // namespace rcm::status_test
