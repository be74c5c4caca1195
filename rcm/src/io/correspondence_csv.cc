#include "rcm/io/correspondence_csv.h"

#include <glog/logging.h>

#include <array>
#include <charconv>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string_view>
#include <system_error>
#include <utility>

#include "rcm/io/atomic_file.h"
#include "rcm/util/message_text.h"

namespace rcm {
namespace {

constexpr std::string_view kUtf8Bom = "\xEF\xBB\xBF";

// The columns the reader knows, in the order FormatCorrespondenceCsv writes
// them.
enum Column : int { kFrame = 0, kXl, kYl, kXr, kYr, kTime, kNumColumns };
constexpr std::array<std::string_view, kNumColumns> kColumnNames = {
    "frame", "xl", "yl", "xr", "yr", "t"};
constexpr std::array<Column, 4> kRequiredColumns = {kXl, kYl, kXr, kYr};

std::string_view TrimBlanks(std::string_view text) {
  while (!text.empty() && (text.front() == ' ' || text.front() == '\t')) {
    text.remove_prefix(1);
  }
  while (!text.empty() && (text.back() == ' ' || text.back() == '\t')) {
    text.remove_suffix(1);
  }
  return text;
}

// Splits on ',' and trims blanks around every field.
void SplitFields(std::string_view line, std::vector<std::string_view>* fields) {
  fields->clear();
  while (true) {
    const size_t comma = line.find(',');
    fields->push_back(TrimBlanks(line.substr(0, comma)));
    if (comma == std::string_view::npos) return;
    line.remove_prefix(comma + 1);
  }
}

// Parses a whole field as a finite double. The error names the column.
Status ParseFiniteDouble(std::string_view field, Column column, double* value) {
  const std::string name(kColumnNames[column]);
  double parsed = 0.0;
  const auto [end, error] =
      std::from_chars(field.data(), field.data() + field.size(), parsed);
  if (error == std::errc::result_out_of_range &&
      end == field.data() + field.size()) {
    return Status::Error(name + ": " + QuoteForMessage(field) +
                         " is out of the range of a double");
  }
  if (error != std::errc() || end != field.data() + field.size() ||
      field.empty()) {
    return Status::Error(name + ": " + QuoteForMessage(field) +
                         " is not a number");
  }
  if (!std::isfinite(parsed)) {
    return Status::Error(name + ": " + EscapeForMessage(field) +
                         " is not finite");
  }
  *value = parsed;
  return Status::Ok();
}

Status ParseFrame(std::string_view field, int64_t* frame) {
  int64_t parsed = 0;
  const auto [end, error] =
      std::from_chars(field.data(), field.data() + field.size(), parsed);
  if (error != std::errc() || end != field.data() + field.size() ||
      field.empty() || parsed < 0) {
    return Status::Error("frame: " + QuoteForMessage(field) +
                         " is not a non-negative integer");
  }
  *frame = parsed;
  return Status::Ok();
}

Status ErrorAtLine(const std::string& source_name, int64_t line_number,
                   const std::string& what) {
  return Status::Error(source_name + ":" + std::to_string(line_number) + ": " +
                       what);
}

// Column index of every known column in the header, -1 when absent.
using ColumnIndices = std::array<int, kNumColumns>;

Status ParseHeader(const std::vector<std::string_view>& names,
                   ColumnIndices* indices) {
  indices->fill(-1);
  for (size_t i = 0; i < names.size(); ++i) {
    for (int column = 0; column < kNumColumns; ++column) {
      if (names[i] != kColumnNames[column]) continue;
      if ((*indices)[column] >= 0) {
        return Status::Error("column '" + std::string(kColumnNames[column]) +
                             "' appears twice");
      }
      (*indices)[column] = static_cast<int>(i);
    }
  }
  for (const Column column : kRequiredColumns) {
    if ((*indices)[column] < 0) {
      return Status::Error("header lacks column '" +
                           std::string(kColumnNames[column]) +
                           "' (expected frame,xl,yl,xr,yr with optional t)");
    }
  }
  return Status::Ok();
}

Status ParseRow(const std::vector<std::string_view>& fields,
                const ColumnIndices& indices,
                StereoCorrespondence* correspondence) {
  if (indices[kFrame] >= 0) {
    RCM_RETURN_IF_ERROR(
        ParseFrame(fields[indices[kFrame]], &correspondence->frame));
  }
  double* const targets[4] = {
      &correspondence->left_pixel.x(), &correspondence->left_pixel.y(),
      &correspondence->right_pixel.x(), &correspondence->right_pixel.y()};
  for (size_t i = 0; i < kRequiredColumns.size(); ++i) {
    const Column column = kRequiredColumns[i];
    RCM_RETURN_IF_ERROR(
        ParseFiniteDouble(fields[indices[column]], column, targets[i]));
  }
  if (indices[kTime] >= 0) {
    double timestamp = 0.0;
    RCM_RETURN_IF_ERROR(
        ParseFiniteDouble(fields[indices[kTime]], kTime, &timestamp));
    correspondence->timestamp = timestamp;
  }
  return Status::Ok();
}

void AppendDouble(double value, std::string* out) {
  CHECK(std::isfinite(value)) << "cannot write a non-finite value: " << value;
  // The shortest round-trip form of a double has at most 24 characters.
  char buffer[32];
  const auto [end, error] =
      std::to_chars(buffer, buffer + sizeof(buffer), value);
  CHECK(error == std::errc());
  out->append(buffer, end);
}

void AppendInt(int64_t value, std::string* out) {
  char buffer[24];
  const auto [end, error] =
      std::to_chars(buffer, buffer + sizeof(buffer), value);
  CHECK(error == std::errc());
  out->append(buffer, end);
}

}  // namespace

StatusOr<std::vector<StereoCorrespondence>> ParseCorrespondenceCsv(
    const std::string& text, const std::string& source_name) {
  std::string_view remaining(text);
  if (remaining.substr(0, kUtf8Bom.size()) == kUtf8Bom) {
    remaining.remove_prefix(kUtf8Bom.size());
  }

  std::vector<StereoCorrespondence> correspondences;
  std::vector<std::string_view> fields;
  ColumnIndices indices;
  bool have_header = false;
  size_t num_header_fields = 0;
  int64_t line_number = 0;
  while (!remaining.empty()) {
    const size_t newline = remaining.find('\n');
    std::string_view line = remaining.substr(0, newline);
    remaining.remove_prefix(newline == std::string_view::npos ? line.size()
                                                              : newline + 1);
    ++line_number;
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    const std::string_view content = TrimBlanks(line);
    if (content.empty() || content.front() == '#') continue;

    SplitFields(content, &fields);
    if (!have_header) {
      const Status status = ParseHeader(fields, &indices);
      if (!status.ok()) {
        return ErrorAtLine(source_name, line_number, status.message());
      }
      have_header = true;
      num_header_fields = fields.size();
      continue;
    }
    if (fields.size() != num_header_fields) {
      return ErrorAtLine(source_name, line_number,
                         "expected " + std::to_string(num_header_fields) +
                             " fields, got " + std::to_string(fields.size()));
    }
    StereoCorrespondence correspondence;
    const Status status = ParseRow(fields, indices, &correspondence);
    if (!status.ok()) {
      return ErrorAtLine(source_name, line_number, status.message());
    }
    if (!correspondences.empty() &&
        correspondence.frame < correspondences.back().frame) {
      return ErrorAtLine(source_name, line_number,
                         "frame " + std::to_string(correspondence.frame) +
                             " after frame " +
                             std::to_string(correspondences.back().frame) +
                             ": frames must not decrease");
    }
    correspondences.push_back(std::move(correspondence));
  }

  if (!have_header) return Status::Error(source_name + ": empty file");
  if (correspondences.empty()) {
    return Status::Error(source_name + ": no correspondences after the header");
  }
  return correspondences;
}

StatusOr<std::vector<StereoCorrespondence>> ReadCorrespondenceCsv(
    const std::string& path) {
  StatusOr<std::string> text = ReadFileToString(path);
  if (!text.ok()) return text.status();
  return ParseCorrespondenceCsv(*text, path);
}

std::string FormatCorrespondenceCsv(
    const std::vector<StereoCorrespondence>& correspondences) {
  const bool with_time =
      !correspondences.empty() && correspondences.front().timestamp.has_value();
  std::string out = with_time ? "frame,xl,yl,xr,yr,t\n" : "frame,xl,yl,xr,yr\n";
  int64_t previous_frame = 0;
  for (size_t i = 0; i < correspondences.size(); ++i) {
    const StereoCorrespondence& correspondence = correspondences[i];
    CHECK_EQ(correspondence.timestamp.has_value(), with_time)
        << "correspondence " << i
        << ": either all or none of the correspondences need a timestamp";
    CHECK_GE(correspondence.frame, previous_frame)
        << "correspondence " << i
        << ": frames must be non-negative and non-decreasing";
    previous_frame = correspondence.frame;
    AppendInt(correspondence.frame, &out);
    for (const double value :
         {correspondence.left_pixel.x(), correspondence.left_pixel.y(),
          correspondence.right_pixel.x(), correspondence.right_pixel.y()}) {
      out.push_back(',');
      AppendDouble(value, &out);
    }
    if (with_time) {
      out.push_back(',');
      AppendDouble(*correspondence.timestamp, &out);
    }
    out.push_back('\n');
  }
  return out;
}

Status WriteCorrespondenceCsv(
    const std::string& path,
    const std::vector<StereoCorrespondence>& correspondences) {
  return WriteFileAtomically(path, FormatCorrespondenceCsv(correspondences));
}

}  // namespace rcm
