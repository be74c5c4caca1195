// Fuzzes the calibration target reader (rcm/calib/calibration_target.h),
// Kalibr's target YAML, with arbitrary text.
//
// Properties: parsing never crashes or throws, whatever the bytes; a file
// either parses or yields one error line prefixed with its source name; a
// target that parses is one the rest of the calibration can use: its
// description, point count and corner positions (which CHECK the accepted
// ranges) succeed, the count matches the corners, every corner is finite
// and distinct corners are distinct points.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "fuzz_input.h"
#include "rcm/calib/calibration_target.h"

namespace {

constexpr char kSource[] = "fuzz_target.yaml";

using rcm::fuzz::FuzzCheck;

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  const rcm::StatusOr<rcm::calib::CalibrationTarget> target =
      rcm::calib::ParseCalibrationTarget(text, kSource);
  if (!target.ok()) {
    rcm::fuzz::CheckErrorMessage(target.status().message(), kSource);
    return 0;
  }
  FuzzCheck(!rcm::calib::DescribeTarget(*target).empty(), "no description");
  const std::vector<Eigen::Vector3d> points =
      rcm::calib::TargetPoints(*target);
  FuzzCheck(static_cast<int>(points.size()) ==
                rcm::calib::NumTargetPoints(*target),
            "point count differs from the corners");
  for (size_t i = 0; i < points.size(); ++i) {
    FuzzCheck(points[i].allFinite(), "a non-finite corner");
    if (i > 0) {
      FuzzCheck((points[i] - points[i - 1]).norm() > 0.0,
                "two consecutive corners coincide");
    }
  }
  return 0;
}
