// Fuzzes the correspondence CSV reader (rcm/io/correspondence_csv.h) with
// arbitrary text.
//
// Properties: parsing never crashes, whatever the bytes; a file either
// parses or yields one error line prefixed with its source name; what
// parses has finite coordinates and timestamps, non-negative frames that
// do not decrease, and timestamps on all rows or none (the writer's
// preconditions), and reads back bit for bit from what the writer makes
// of it.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "fuzz_input.h"
#include "rcm/io/correspondence_csv.h"

namespace {

constexpr char kSource[] = "fuzz.csv";

using rcm::fuzz::FuzzCheck;

bool SameBits(double a, double b) {
  return std::memcmp(&a, &b, sizeof(a)) == 0;
}

bool Identical(const rcm::StereoCorrespondence& a,
               const rcm::StereoCorrespondence& b) {
  if (a.frame != b.frame) return false;
  if (a.timestamp.has_value() != b.timestamp.has_value()) return false;
  if (a.timestamp && !SameBits(*a.timestamp, *b.timestamp)) return false;
  for (int i = 0; i < 2; ++i) {
    if (!SameBits(a.left_pixel[i], b.left_pixel[i]) ||
        !SameBits(a.right_pixel[i], b.right_pixel[i])) {
      return false;
    }
  }
  return true;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  const rcm::StatusOr<std::vector<rcm::StereoCorrespondence>> parsed =
      rcm::ParseCorrespondenceCsv(text, kSource);
  if (!parsed.ok()) {
    rcm::fuzz::CheckErrorMessage(parsed.status().message(), kSource);
    return 0;
  }
  const std::vector<rcm::StereoCorrespondence>& rows = *parsed;
  FuzzCheck(!rows.empty(), "a file without correspondences parsed");
  int64_t previous_frame = 0;
  for (const rcm::StereoCorrespondence& row : rows) {
    FuzzCheck(row.frame >= previous_frame, "frames decrease");
    previous_frame = row.frame;
    FuzzCheck(row.left_pixel.allFinite() && row.right_pixel.allFinite(),
              "a non-finite coordinate parsed");
    FuzzCheck(row.timestamp.has_value() == rows[0].timestamp.has_value(),
              "timestamps on some rows only");
    FuzzCheck(!row.timestamp || std::isfinite(*row.timestamp),
              "a non-finite timestamp parsed");
  }
  const rcm::StatusOr<std::vector<rcm::StereoCorrespondence>> again =
      rcm::ParseCorrespondenceCsv(rcm::FormatCorrespondenceCsv(rows),
                                  kSource);
  FuzzCheck(again.ok() && again->size() == rows.size(),
            "a written file does not read back");
  for (size_t i = 0; i < rows.size(); ++i) {
    FuzzCheck(Identical(rows[i], (*again)[i]),
              "a written file reads back different values");
  }
  return 0;
}
