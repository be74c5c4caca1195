// MediaSchedule: which medium a simulated sequence is in at each frame,
// for sequences that go from air into water and back (paper Sec. V-D: the
// sliding window must detect each switch).
//
// Text form (the `--media` flag of rcm simulate and rcm demo): segments
// separated by commas, each `MEDIUM:FRAMES`, MEDIUM a refractive index in
// [1, 2] or a name: `air` (1.0) or `water` (the caller's water index),
// e.g. "water:30,air:30,water:30".
#ifndef RCM_SIM_MEDIA_SCHEDULE_H_
#define RCM_SIM_MEDIA_SCHEDULE_H_

#include <string>
#include <string_view>
#include <vector>

#include "rcm/util/status.h"

namespace rcm {

struct MediaSegment {
  double n = 1.333;  // refractive index in [1, 2]
  int frames = 1;    // >= 1
};

class MediaSchedule {
 public:
  // Fails on an empty list, a segment without ':' or with an index outside
  // [1, 2], a frame count < 1 or a total above kMaxFrames.
  static StatusOr<MediaSchedule> Create(std::vector<MediaSegment> segments);
  // Parses the text form; `water_n` is what `water` means.
  static StatusOr<MediaSchedule> Parse(std::string_view text, double water_n);
  // One medium for `frames` frames.
  static StatusOr<MediaSchedule> Constant(double n, int frames);

  // Upper bound on the frames of a simulated sequence (about 14 h at 20 Hz).
  static constexpr int kMaxFrames = 1000000;

  const std::vector<MediaSegment>& segments() const { return segments_; }
  int num_frames() const { return num_frames_; }
  // n of every frame, num_frames() entries.
  std::vector<double> PerFrame() const;
  // Frames where the medium differs from the previous frame's.
  std::vector<int> SwitchFrames() const;
  // Text form, with indices (not names), e.g. "1.333:30,1:30".
  std::string ToString() const;

 private:
  explicit MediaSchedule(std::vector<MediaSegment> segments, int num_frames)
      : segments_(std::move(segments)), num_frames_(num_frames) {}

  std::vector<MediaSegment> segments_;
  int num_frames_;
};

}  // namespace rcm

#endif  // RCM_SIM_MEDIA_SCHEDULE_H_
