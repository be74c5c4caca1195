#include "rcm/io/stereo_image_source.h"

#include <cmath>

#include "rcm/util/number_format.h"

namespace rcm {
namespace {

std::string Seconds(double seconds) { return FormatFixed(seconds, 3) + " s"; }

}  // namespace

Status FrameSelection::Check() const {
  if (stride < 1) {
    return Status::Error("stride must be at least 1, got " +
                         std::to_string(stride));
  }
  for (const auto& [name, value] :
       {std::pair{"from", from_s}, std::pair{"to", to_s}}) {
    if (value && (!std::isfinite(*value) || *value < 0.0)) {
      return Status::Error(std::string("time range: '") + name +
                           "' must be a finite number of seconds >= 0");
    }
  }
  if (from_s && to_s && *from_s > *to_s) {
    return Status::Error("time range: from " + Seconds(*from_s) +
                         " is after to " + Seconds(*to_s));
  }
  return Status::Ok();
}

StatusOr<std::vector<size_t>> SelectFrames(
    const std::vector<double>& timestamps, size_t num_pairs,
    const FrameSelection& selection) {
  if (const Status status = selection.Check(); !status.ok()) return status;
  CHECK(timestamps.empty() || timestamps.size() == num_pairs)
      << "one timestamp per pair, or none";
  if (num_pairs == 0) return Status::Error("no stereo pair");
  if (selection.HasTimeRange() && timestamps.empty()) {
    return Status::Error(
        "a time range needs timestamps, and these images carry none (use "
        "the stride, or name the files by their stamps)");
  }
  const double start = timestamps.empty() ? 0.0 : timestamps.front();
  std::vector<size_t> in_range;
  for (size_t i = 0; i < num_pairs; ++i) {
    if (!timestamps.empty()) {
      const double t = timestamps[i] - start;
      if (selection.from_s && t < *selection.from_s) continue;
      if (selection.to_s && t > *selection.to_s) continue;
    }
    in_range.push_back(i);
  }
  if (in_range.empty()) {
    return Status::Error(
        "no stereo pair between " + Seconds(selection.from_s.value_or(0.0)) +
        " and " +
        (selection.to_s ? Seconds(*selection.to_s) : std::string("the end")) +
        ": the sequence lasts " + Seconds(timestamps.back() - start));
  }
  std::vector<size_t> selected;
  for (size_t k = 0; k < in_range.size(); k += selection.stride) {
    selected.push_back(in_range[k]);
  }
  return selected;
}

}  // namespace rcm
