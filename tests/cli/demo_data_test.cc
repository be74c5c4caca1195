// The bundled demo data are what the API example writes: regenerating them
// with the documented command reproduces the file byte for byte.
#include <gtest/gtest.h>

#include <string>

#include "cli/cli_runner.h"
#include "rcm/io/camchain.h"
#include "support/temp_file.h"

namespace rcm::demo_data_test {
namespace {

TEST(DemoData, RegeneratesByteForByte) {
  const std::string source = RCM_SOURCE_DIR;
  const std::string output = test::TempFilePath("demo_matches.csv");
  // The command documented in examples/data/README.md.
  const test::RunResult result = test::RunProgram(
      RCM_SYNTHETIC_MATCHES_BINARY,
      {"--calib", source + "/examples/data/alphasense_front_rectified.yaml",
       "--n", "1.333", "--frames", "10", "--per_frame", "200", "--noise", "0.1",
       "--seed", "1", "--output", output});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_EQ(test::ReadWholeFile(output),
            test::ReadWholeFile(source + "/examples/data/demo_matches.csv"));
}

TEST(DemoData, RigFileIsWhatKalibrWouldWrite) {
  // The bundled camchain reads back and formats to the same bytes.
  const std::string path = std::string(RCM_SOURCE_DIR) +
                           "/examples/data/alphasense_front_rectified.yaml";
  const StatusOr<Camchain> camchain = ReadCamchain(path);
  ASSERT_TRUE(camchain.ok()) << camchain.status().message();
  EXPECT_EQ(FormatCamchain(*camchain), test::ReadWholeFile(path));
}

}  // namespace
}  // namespace rcm::demo_data_test
