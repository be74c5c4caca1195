#include "rcm/sim/media_schedule.h"

#include <cctype>
#include <cmath>
#include <cstdlib>
#include <optional>
#include <sstream>

#include "rcm/util/number_format.h"

namespace rcm {
namespace {

std::string_view Trim(std::string_view text) {
  while (!text.empty() && std::isspace(static_cast<unsigned char>(text[0]))) {
    text.remove_prefix(1);
  }
  while (!text.empty() &&
         std::isspace(static_cast<unsigned char>(text.back()))) {
    text.remove_suffix(1);
  }
  return text;
}

// A whole-string number; nullopt on trailing characters or none.
std::optional<double> ParseNumber(std::string_view text) {
  const std::string copy(text);
  char* end = nullptr;
  const double value = std::strtod(copy.c_str(), &end);
  if (copy.empty() || end != copy.c_str() + copy.size()) return std::nullopt;
  return value;
}

}  // namespace

StatusOr<MediaSchedule> MediaSchedule::Create(
    std::vector<MediaSegment> segments) {
  if (segments.empty()) return Status::Error("media schedule is empty");
  int64_t total = 0;
  for (const MediaSegment& segment : segments) {
    std::ostringstream message;
    if (!std::isfinite(segment.n) || segment.n < 1.0 || segment.n > 2.0) {
      message << "medium n = " << segment.n << " is outside [1, 2]";
      return Status::Error(message.str());
    }
    if (segment.frames < 1) {
      message << "a medium lasts " << segment.frames
              << " frames; it must last at least 1";
      return Status::Error(message.str());
    }
    total += segment.frames;
    if (total > kMaxFrames) {
      message << "media schedule has more than " << kMaxFrames << " frames";
      return Status::Error(message.str());
    }
  }
  return MediaSchedule(std::move(segments), static_cast<int>(total));
}

StatusOr<MediaSchedule> MediaSchedule::Parse(std::string_view text,
                                             double water_n) {
  std::vector<MediaSegment> segments;
  while (true) {
    const size_t comma = text.find(',');
    const std::string_view item = Trim(text.substr(0, comma));
    const size_t colon = item.find(':');
    if (colon == std::string_view::npos) {
      return Status::Error("media segment '" + std::string(item) +
                           "' is not MEDIUM:FRAMES (e.g. water:30)");
    }
    const std::string_view medium = Trim(item.substr(0, colon));
    const std::string_view frames = Trim(item.substr(colon + 1));
    MediaSegment segment;
    if (medium == "air") {
      segment.n = 1.0;
    } else if (medium == "water") {
      segment.n = water_n;
    } else if (const std::optional<double> n = ParseNumber(medium)) {
      segment.n = *n;
    } else {
      return Status::Error("media segment '" + std::string(item) +
                           "': medium is not air, water or a number");
    }
    const std::optional<double> count = ParseNumber(frames);
    if (!count || *count != std::floor(*count) || *count > kMaxFrames) {
      return Status::Error("media segment '" + std::string(item) +
                           "': frame count is not a whole number");
    }
    segment.frames = static_cast<int>(*count);
    segments.push_back(segment);
    if (comma == std::string_view::npos) break;
    text.remove_prefix(comma + 1);
  }
  return Create(std::move(segments));
}

StatusOr<MediaSchedule> MediaSchedule::Constant(double n, int frames) {
  return Create({MediaSegment{n, frames}});
}

std::vector<double> MediaSchedule::PerFrame() const {
  std::vector<double> n;
  n.reserve(num_frames_);
  for (const MediaSegment& segment : segments_) {
    n.insert(n.end(), segment.frames, segment.n);
  }
  return n;
}

std::vector<int> MediaSchedule::SwitchFrames() const {
  std::vector<int> switches;
  int frame = 0;
  for (size_t i = 0; i < segments_.size(); ++i) {
    if (i > 0 && segments_[i].n != segments_[i - 1].n) {
      switches.push_back(frame);
    }
    frame += segments_[i].frames;
  }
  return switches;
}

std::string MediaSchedule::ToString() const {
  std::string text;
  for (const MediaSegment& segment : segments_) {
    if (!text.empty()) text += ',';
    text += FormatDouble(segment.n) + ":" + std::to_string(segment.frames);
  }
  return text;
}

}  // namespace rcm
