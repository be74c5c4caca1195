// Files for the tests that read from and write to disk.
//
// Every path is in ::testing::TempDir() and its file name starts with the
// current test's suite and name ("Camchain.ReadRejectsMissingFile.x.yaml"),
// so that tests run in parallel by ctest, each in its own process, never
// share a file.
#ifndef RCM_TESTS_SUPPORT_TEMP_FILE_H_
#define RCM_TESTS_SUPPORT_TEMP_FILE_H_

#include <gtest/gtest.h>

#include <fstream>
#include <string>

namespace rcm::test {

// The path of the temporary file `name` of the current test; nothing is
// created. For files a test expects to be missing or has the code under
// test write.
inline std::string TempFilePath(const std::string& name) {
  std::string prefix = "test";
  if (const ::testing::TestInfo* info =
          ::testing::UnitTest::GetInstance()->current_test_info()) {
    prefix = std::string(info->test_suite_name()) + "." + info->name();
  }
  // Parameterized tests have '/' in their names.
  for (char& c : prefix) {
    if (c == '/') c = '_';
  }
  std::string directory = ::testing::TempDir();
  if (!directory.empty() && directory.back() != '/') directory += '/';
  return directory + prefix + "." + name;
}

// Writes `contents` to the temporary file `name` of the current test (see
// TempFilePath) and returns its path. A failure to write fails the test.
inline std::string WriteTempFile(const std::string& name,
                                 const std::string& contents) {
  const std::string path = TempFilePath(name);
  std::ofstream file(path, std::ios::binary | std::ios::trunc);
  file << contents;
  file.close();
  EXPECT_TRUE(file.good()) << "cannot write " << path;
  return path;
}

}  // namespace rcm::test

#endif  // RCM_TESTS_SUPPORT_TEMP_FILE_H_
