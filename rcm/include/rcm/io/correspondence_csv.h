// Reading and writing stereo correspondence files (docs/design.md,
// "Conventions").
//
// Format: comma-separated text with a REQUIRED header row naming the
// columns, e.g.
//
//   frame,xl,yl,xr,yr,t
//   0,361.25,270.5,302.75,271.0,1690000000.05
//   0,120.0,88.5,61.25,90.0,1690000000.05
//   1,...
//
//   xl,yl  raw (lens-distorted) pixel coordinates in the left image
//   xr,yr  the same scene point in the right image
//   frame  optional; a non-negative integer. Without the column every row
//          belongs to frame 0. Frames must not decrease down the file,
//          because online estimation consumes them in order.
//   t      optional; timestamp in seconds (finite).
//
// Columns may appear in any order; unknown columns (e.g. a matcher's
// `score`) are ignored but still count when checking the number of fields
// of a row; a known column named twice is an error. Column names are case
// sensitive. Fields carry no quoting (a field cannot contain a comma).
// Tolerated: spaces or tabs around fields and names, CRLF line endings, a
// UTF-8 byte order mark, blank lines, and lines whose first non-blank
// character is '#' (comments, also before the header). Numbers are decimal
// as std::from_chars reads them ("1.5", "-2", "3e2"; no leading '+'); the
// whole field must be a number.
//
// Errors are one line, "SOURCE:LINE: what" with 1-based physical line
// numbers (or "SOURCE: what" when no line applies), e.g.
//   m.csv:1: header lacks column 'yr' (expected frame,xl,yl,xr,yr with
//   optional t)
//   m.csv:7: expected 5 fields, got 4
//   m.csv:12: frame 3 after frame 5: frames must not decrease
#ifndef RCM_IO_CORRESPONDENCE_CSV_H_
#define RCM_IO_CORRESPONDENCE_CSV_H_

#include <string>
#include <vector>

#include "rcm/geometry/stereo_correspondence.h"
#include "rcm/util/status.h"

namespace rcm {

// Parses the text of a correspondence file. `source_name` (usually the
// path) prefixes every error message. A file needs a header and at least
// one correspondence.
StatusOr<std::vector<StereoCorrespondence>> ParseCorrespondenceCsv(
    const std::string& text, const std::string& source_name);

// Reads and parses the file at `path`; errors are prefixed with `path`.
StatusOr<std::vector<StereoCorrespondence>> ReadCorrespondenceCsv(
    const std::string& path);

// Formats correspondences with the header `frame,xl,yl,xr,yr`, plus `,t`
// when every correspondence has a timestamp, one row per correspondence and
// "\n" line endings. Numbers are written as the shortest decimal that reads
// back to the same double, so ParseCorrespondenceCsv(Format(x)) reproduces
// `x` bit for bit (for a non-empty `x`).
//
// Preconditions (CHECKed, as output that cannot be read back is a bug of
// the caller): either all or none of the correspondences have a timestamp;
// all coordinates and timestamps are finite; frames are non-negative and
// non-decreasing.
std::string FormatCorrespondenceCsv(
    const std::vector<StereoCorrespondence>& correspondences);

// Writes FormatCorrespondenceCsv(correspondences) to `path` atomically: on
// failure an existing file at `path` is left untouched. Same preconditions.
Status WriteCorrespondenceCsv(
    const std::string& path,
    const std::vector<StereoCorrespondence>& correspondences);

}  // namespace rcm

#endif  // RCM_IO_CORRESPONDENCE_CSV_H_
