// Fuzzes the rig readers, Kalibr camchain and ROS camera_info YAML
// (rcm/io/camchain.h, rcm/io/camera_info.h), with arbitrary text.
//
// Properties: parsing never crashes or throws, whatever the bytes; a file
// either parses or yields one error line prefixed with its source name; a
// camchain or camera_info that parses is formatted to text that parses
// again and formats to the same text (what rcm writes, rcm reads back);
// the stereo rig of a parsed file, when it builds, has a finite baseline
// of at least StereoRig::kMinBaseline.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz_input.h"
#include "rcm/io/camchain.h"
#include "rcm/io/camera_info.h"

namespace {

constexpr char kSource[] = "fuzz.yaml";

void CheckRig(const rcm::StereoRig& rig) {
  const double baseline = rig.Baseline();
  rcm::fuzz::FuzzCheck(
      std::isfinite(baseline) && baseline >= rcm::StereoRig::kMinBaseline,
      "rig with a zero or non-finite baseline");
}

void FuzzCamchain(const std::string& text) {
  const rcm::StatusOr<rcm::Camchain> camchain =
      rcm::ParseCamchain(text, kSource);
  if (!camchain.ok()) {
    rcm::fuzz::CheckErrorMessage(camchain.status().message(), kSource);
    return;
  }
  const std::string formatted = rcm::FormatCamchain(*camchain);
  const rcm::StatusOr<rcm::Camchain> again =
      rcm::ParseCamchain(formatted, kSource);
  rcm::fuzz::FuzzCheck(again.ok(), "a formatted camchain does not parse");
  rcm::fuzz::FuzzCheck(rcm::FormatCamchain(*again) == formatted,
                       "a camchain does not read back as written");
  if (camchain->cameras.size() >= 2) {
    const rcm::StatusOr<rcm::StereoRig> rig =
        rcm::StereoRigFromCamchain(*camchain, 0, 1);
    if (rig.ok()) CheckRig(*rig);
  }
}

void FuzzCameraInfo(const std::string& text) {
  const rcm::StatusOr<rcm::CameraInfo> info =
      rcm::ParseCameraInfo(text, kSource);
  if (!info.ok()) {
    rcm::fuzz::CheckErrorMessage(info.status().message(), kSource);
    return;
  }
  const std::string formatted = rcm::FormatCameraInfo(*info);
  const rcm::StatusOr<rcm::CameraInfo> again =
      rcm::ParseCameraInfo(formatted, kSource);
  rcm::fuzz::FuzzCheck(again.ok(), "a formatted camera_info does not parse");
  rcm::fuzz::FuzzCheck(rcm::FormatCameraInfo(*again) == formatted,
                       "a camera_info does not read back as written");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  FuzzCamchain(text);
  FuzzCameraInfo(text);
  return 0;
}
