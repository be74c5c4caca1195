#include "rcm/io/atomic_file.h"

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cstdio>
#include <filesystem>
#include <string>

namespace rcm::atomic_file_test {
namespace {

std::string TempPath(const std::string& name) {
  return ::testing::TempDir() + "/rcm_atomic_file_" + name;
}

TEST(AtomicFile, WritesAndReadsBack) {
  const std::string path = TempPath("round_trip.txt");
  ASSERT_TRUE(WriteFileAtomically(path, "line one\nline two\n").ok());
  const StatusOr<std::string> text = ReadFileToString(path);
  ASSERT_TRUE(text.ok()) << text.status().message();
  EXPECT_EQ(*text, "line one\nline two\n");
  std::remove(path.c_str());
}

TEST(AtomicFile, ReplacesExistingFile) {
  const std::string path = TempPath("replace.txt");
  ASSERT_TRUE(WriteFileAtomically(path, "old").ok());
  ASSERT_TRUE(WriteFileAtomically(path, "new").ok());
  EXPECT_EQ(ReadFileToString(path).value(), "new");
  std::remove(path.c_str());
}

TEST(AtomicFile, FailedWriteLeavesNothingBehind) {
  const std::string directory = TempPath("no_such_dir");
  const std::string path = directory + "/out.txt";
  const Status status = WriteFileAtomically(path, "data");
  ASSERT_FALSE(status.ok());
  EXPECT_EQ(status.message(),
            path + ": cannot write: No such file or directory");
  EXPECT_FALSE(std::filesystem::exists(directory));
}

TEST(AtomicFile, FailedRenameKeepsOldFile) {
  // Writing over a directory fails at the rename: the directory stays and
  // no temporary file is left next to it.
  const std::string directory = TempPath("is_a_directory");
  std::filesystem::create_directories(directory);
  ASSERT_FALSE(WriteFileAtomically(directory, "data").ok());
  EXPECT_TRUE(std::filesystem::is_directory(directory));
  for (const auto& entry :
       std::filesystem::directory_iterator(::testing::TempDir())) {
    EXPECT_EQ(entry.path().string().find("is_a_directory.tmp"),
              std::string::npos);
  }
  std::filesystem::remove_all(directory);
}

TEST(AtomicFile, ReadMissingFile) {
  const StatusOr<std::string> text = ReadFileToString(TempPath("missing"));
  ASSERT_FALSE(text.ok());
  EXPECT_EQ(text.status().message(),
            TempPath("missing") + ": cannot open: No such file or directory");
}

TEST(AtomicFile, ReadDirectory) {
  const StatusOr<std::string> text = ReadFileToString(::testing::TempDir());
  ASSERT_FALSE(text.ok());
  EXPECT_NE(text.status().message().find("is a directory"), std::string::npos);
}

}  // namespace
}  // namespace rcm::atomic_file_test
