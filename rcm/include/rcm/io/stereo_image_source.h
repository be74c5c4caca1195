// A sequence of stereo image pairs, whatever stores them: two image
// folders (stereo_image_folders.h) or a ROS1 bag (bag_stereo_source.h).
// Sources pair the two cameras' images when they are opened, apply the
// time range and stride of a FrameSelection, and decode a pair only when
// it is read, so a long dive costs no memory up front.
#ifndef RCM_IO_STEREO_IMAGE_SOURCE_H_
#define RCM_IO_STEREO_IMAGE_SOURCE_H_

#include <cstdint>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "rcm/util/status.h"

namespace rcm {

// One stereo pair as stored: 8-bit images, 1 channel (mono8) or 3 (BGR).
struct StereoImagePair {
  // Index of the pair in the source before selection (the first pair of a
  // folder or bag is 0), so frames keep their numbers under a stride.
  int64_t frame = 0;
  // Seconds: the header stamp of the left image (bags), or the stamp a
  // file name carries (folders); absent when the source has none.
  std::optional<double> timestamp;
  cv::Mat left;
  cv::Mat right;
  // Where the images came from, for messages: file paths, or
  // "TOPIC @ STAMP" for bags.
  std::string left_name;
  std::string right_name;
};

// Which pairs of a source to use. Times are seconds after the first pair's
// timestamp (as rosbag's --start and Kalibr's --bag-from-to count them),
// so `from 10, to 20` is the eleventh to twentieth second of the dive.
struct FrameSelection {
  // First and last time kept (inclusive); unset = from the start / to the
  // end. Needs timestamps: a source without them refuses a time range.
  std::optional<double> from_s;
  std::optional<double> to_s;
  // Keep every stride-th pair of those in the time range, starting with
  // the first; >= 1.
  int stride = 1;

  // Errors: stride < 1, a non-finite or negative time, from_s > to_s.
  Status Check() const;
  bool HasTimeRange() const { return from_s.has_value() || to_s.has_value(); }
};

// The indices (into `timestamps`, sorted ascending) that `selection` keeps.
// `timestamps` are seconds, one per pair in time order, or empty when the
// source has none. Errors: selection.Check(), a time range without
// timestamps, and a selection that keeps no pair ("no stereo pair between
// 10 s and 20 s: the sequence lasts 8.4 s").
StatusOr<std::vector<size_t>> SelectFrames(const std::vector<double>& timestamps,
                                           size_t num_pairs,
                                           const FrameSelection& selection);

class StereoImageSource {
 public:
  virtual ~StereoImageSource() = default;

  // Pairs after selection.
  virtual size_t NumPairs() const = 0;
  // Decodes the i-th selected pair, 0 <= i < NumPairs(). Errors: an
  // unreadable or corrupt image, an unsupported encoding, the two images
  // of the pair differing in size. Not thread-safe: read from one thread.
  virtual StatusOr<StereoImagePair> ReadPair(size_t i) = 0;
  // One line for progress and reports, e.g. "folders left/ and right/:
  // 120 pairs (every 2nd of 240)".
  virtual std::string Describe() const = 0;
};

}  // namespace rcm

#endif  // RCM_IO_STEREO_IMAGE_SOURCE_H_
