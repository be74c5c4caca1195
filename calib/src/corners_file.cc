#include "rcm/calib/corners_file.h"

#include <charconv>
#include <cmath>
#include <string_view>
#include <unordered_set>
#include <utility>

#include "rcm/io/atomic_file.h"
#include "rcm/util/number_format.h"

namespace rcm::calib {
namespace {

constexpr char kLegend[] = "# filename x y level";
constexpr char kDetectorName[] = "corners-file";

bool IsBlank(char c) { return c == ' ' || c == '\t' || c == '\r'; }

std::vector<std::string_view> SplitFields(std::string_view line) {
  std::vector<std::string_view> fields;
  size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && IsBlank(line[i])) ++i;
    const size_t start = i;
    while (i < line.size() && !IsBlank(line[i])) ++i;
    if (i > start) fields.push_back(line.substr(start, i - start));
  }
  return fields;
}

// A finite number, the whole field.
std::optional<double> ParseNumber(std::string_view field) {
  double value = 0.0;
  const char* end = field.data() + field.size();
  const auto [ptr, ec] = std::from_chars(field.data(), end, value);
  if (ec != std::errc() || ptr != end || !std::isfinite(value)) {
    return std::nullopt;
  }
  return value;
}

Status ErrorAt(const std::string& source_name, int line,
               const std::string& what) {
  return Status::Error(source_name + ":" + std::to_string(line) + ": " + what);
}

std::string Quoted(std::string_view field) {
  constexpr size_t kMaxShown = 40;
  std::string shown(field.substr(0, kMaxShown));
  if (field.size() > kMaxShown) shown += "...";
  return "'" + shown + "'";
}

// One image's rows while they are read.
struct Block {
  std::string filename;
  int first_line = 0;
  int rows = 0;
  bool any_point = false;
  TargetObservation observation;
};

}  // namespace

StatusOr<std::string> FormatCornersFile(
    const std::vector<CornersFileImage>& images, int num_points) {
  if (num_points < 1) {
    return Status::Error("corners file: num_points must be positive, got " +
                         std::to_string(num_points));
  }
  std::string out = std::string(kLegend) + "\n";
  std::vector<const Eigen::Vector2d*> by_id(num_points);
  for (const CornersFileImage& image : images) {
    const std::string& name = image.filename;
    if (name.empty() || name[0] == '#' ||
        name.find_first_of(" \t\r\n") != std::string::npos) {
      return Status::Error("corners file: image name '" + name +
                           "' cannot be written (empty, starting with '#' or "
                           "with a blank)");
    }
    if (!image.observation || image.observation->size() == 0) {
      out += name + " - - -\n";
      continue;
    }
    const TargetObservation& observation = *image.observation;
    if (observation.point_ids.size() != observation.pixels.size()) {
      return Status::Error(
          "corners file: " + name + ": " +
          std::to_string(observation.point_ids.size()) + " point ids but " +
          std::to_string(observation.pixels.size()) + " pixels");
    }
    std::fill(by_id.begin(), by_id.end(), nullptr);
    for (int k = 0; k < observation.size(); ++k) {
      const int id = observation.point_ids[k];
      const Eigen::Vector2d& pixel = observation.pixels[k];
      if (id < 0 || id >= num_points) {
        return Status::Error("corners file: " + name + ": point id " +
                             std::to_string(id) + " is not in [0, " +
                             std::to_string(num_points) + ")");
      }
      if (by_id[id] != nullptr) {
        return Status::Error("corners file: " + name + ": point id " +
                             std::to_string(id) + " appears twice");
      }
      if (!pixel.allFinite()) {
        return Status::Error("corners file: " + name + ": point " +
                             std::to_string(id) + " is not finite");
      }
      by_id[id] = &pixel;
    }
    for (int id = 0; id < num_points; ++id) {
      out += name;
      if (by_id[id] == nullptr) {
        out += " - - -\n";
      } else {
        out += ' ';
        out += FormatDouble(by_id[id]->x());
        out += ' ';
        out += FormatDouble(by_id[id]->y());
        out += " 0\n";
      }
    }
  }
  return out;
}

Status WriteCornersFile(const std::string& path,
                        const std::vector<CornersFileImage>& images,
                        int num_points) {
  StatusOr<std::string> text = FormatCornersFile(images, num_points);
  if (!text.ok()) return Status::Error(path + ": " + text.status().message());
  return WriteFileAtomically(path, *text);
}

StatusOr<std::vector<CornersFileImage>> ParseCornersFile(
    const std::string& text, int num_points, const std::string& source_name) {
  if (num_points < 1) {
    return Status::Error(source_name + ": num_points must be positive, got " +
                         std::to_string(num_points));
  }
  std::vector<CornersFileImage> images;
  std::unordered_set<std::string> finished;
  std::optional<Block> block;

  // Closes the block of the current image: num_points rows, or one row of
  // "-" for an image without the target.
  const auto finish = [&]() -> Status {
    if (!block) return Status::Ok();
    const bool not_found_row = block->rows == 1 && !block->any_point;
    if (block->rows != num_points && !not_found_row) {
      return ErrorAt(source_name, block->first_line,
                     block->filename + " has " + std::to_string(block->rows) +
                         " rows, but the target has " +
                         std::to_string(num_points) +
                         " points: corners of another board (check "
                         "--cols/--rows or the target)");
    }
    CornersFileImage image;
    image.filename = block->filename;
    if (block->any_point) {
      block->observation.detector = kDetectorName;
      image.observation = std::move(block->observation);
    }
    finished.insert(block->filename);
    images.push_back(std::move(image));
    block.reset();
    return Status::Ok();
  };

  int line_number = 0;
  size_t position = 0;
  while (position < text.size()) {
    size_t end = text.find('\n', position);
    if (end == std::string::npos) end = text.size();
    const std::string_view line(text.data() + position, end - position);
    position = end + 1;
    ++line_number;
    const std::vector<std::string_view> fields = SplitFields(line);
    if (fields.empty() || fields[0][0] == '#') continue;
    if (fields.size() != 3 && fields.size() != 4) {
      return ErrorAt(source_name, line_number,
                     "a row is 'filename x y [level]', got " +
                         std::to_string(fields.size()) + " fields");
    }
    const std::string filename(fields[0]);
    if (!block || block->filename != filename) {
      RCM_RETURN_IF_ERROR(finish());
      if (finished.count(filename) != 0) {
        return ErrorAt(source_name, line_number,
                       filename +
                           " appears again after other images: an image's "
                           "rows must be consecutive");
      }
      block = Block{filename, line_number, 0, false, {}};
    }
    const int id = block->rows++;
    const bool missing = fields[1] == "-" || fields[2] == "-" ||
                         (fields.size() == 4 && fields[3] == "-");
    if (missing) continue;
    const std::optional<double> x = ParseNumber(fields[1]);
    const std::optional<double> y = ParseNumber(fields[2]);
    if (!x || !y) {
      return ErrorAt(source_name, line_number,
                     "x and y must be finite numbers or '-', got " +
                         Quoted(fields[1]) + " " + Quoted(fields[2]));
    }
    if (fields.size() == 4) {
      const std::optional<double> level = ParseNumber(fields[3]);
      if (!level) {
        return ErrorAt(
            source_name, line_number,
            "level must be a number or '-', got " + Quoted(fields[3]));
      }
      if (*level < 0.0) continue;  // mrcal: a negative level is not found
    }
    if (id >= num_points) continue;  // counted; finish() reports the size
    block->any_point = true;
    block->observation.point_ids.push_back(id);
    block->observation.pixels.emplace_back(*x, *y);
  }
  RCM_RETURN_IF_ERROR(finish());
  if (images.empty()) {
    return Status::Error(source_name + ": no corners (no data rows)");
  }
  return images;
}

StatusOr<std::vector<CornersFileImage>> ReadCornersFile(const std::string& path,
                                                        int num_points) {
  StatusOr<std::string> text = ReadFileToString(path);
  if (!text.ok()) return text.status();
  return ParseCornersFile(*text, num_points, path);
}

}  // namespace rcm::calib
