#include "rcm/calib/calibration_target.h"

#include <glog/logging.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstdint>
#include <iomanip>
#include <opencv2/aruco/dictionary.hpp>
#include <sstream>
#include <string>
#include <utility>

#include "rcm/io/atomic_file.h"
#include "rcm/io/yaml_fields.h"
#include "rcm/util/message_text.h"

namespace rcm::calib {
namespace {

constexpr char kSupportedTypes[] =
    "(supported: checkerboard, aprilgrid, charuco)";

struct NamedDictionary {
  const char* name;
  ArucoDictionaryInfo info;
};

// OpenCV's predefined dictionaries and their sizes (dictionary.hpp).
constexpr NamedDictionary kArucoDictionaries[] = {
    {"DICT_4X4_50", {cv::aruco::DICT_4X4_50, 50}},
    {"DICT_4X4_100", {cv::aruco::DICT_4X4_100, 100}},
    {"DICT_4X4_250", {cv::aruco::DICT_4X4_250, 250}},
    {"DICT_4X4_1000", {cv::aruco::DICT_4X4_1000, 1000}},
    {"DICT_5X5_50", {cv::aruco::DICT_5X5_50, 50}},
    {"DICT_5X5_100", {cv::aruco::DICT_5X5_100, 100}},
    {"DICT_5X5_250", {cv::aruco::DICT_5X5_250, 250}},
    {"DICT_5X5_1000", {cv::aruco::DICT_5X5_1000, 1000}},
    {"DICT_6X6_50", {cv::aruco::DICT_6X6_50, 50}},
    {"DICT_6X6_100", {cv::aruco::DICT_6X6_100, 100}},
    {"DICT_6X6_250", {cv::aruco::DICT_6X6_250, 250}},
    {"DICT_6X6_1000", {cv::aruco::DICT_6X6_1000, 1000}},
    {"DICT_7X7_50", {cv::aruco::DICT_7X7_50, 50}},
    {"DICT_7X7_100", {cv::aruco::DICT_7X7_100, 100}},
    {"DICT_7X7_250", {cv::aruco::DICT_7X7_250, 250}},
    {"DICT_7X7_1000", {cv::aruco::DICT_7X7_1000, 1000}},
    {"DICT_ARUCO_ORIGINAL", {cv::aruco::DICT_ARUCO_ORIGINAL, 1024}},
    {"DICT_APRILTAG_16h5", {cv::aruco::DICT_APRILTAG_16h5, 30}},
    {"DICT_APRILTAG_25h9", {cv::aruco::DICT_APRILTAG_25h9, 35}},
    {"DICT_APRILTAG_36h10", {cv::aruco::DICT_APRILTAG_36h10, 2320}},
    {"DICT_APRILTAG_36h11", {cv::aruco::DICT_APRILTAG_36h11, 587}},
};

// Why `dictionary` cannot serve a squares_x x squares_y charuco board, or
// "" when it can.
std::string CharucoDictionaryProblem(const std::string& dictionary,
                                     int squares_x, int squares_y) {
  const std::optional<ArucoDictionaryInfo> info =
      FindArucoDictionary(dictionary);
  if (!info) {
    return "unknown dictionary " + QuoteForMessage(dictionary) +
           " (OpenCV's predefined names, e.g. DICT_4X4_50, DICT_6X6_250, "
           "DICT_APRILTAG_36h11)";
  }
  const int needed = squares_x * squares_y / 2;
  if (info->num_markers < needed) {
    return "dictionary " + dictionary + " has " +
           std::to_string(info->num_markers) + " markers, a " +
           std::to_string(squares_x) + "x" + std::to_string(squares_y) +
           " board needs " + std::to_string(needed);
  }
  return "";
}

bool PositiveFinite(double value) {
  return std::isfinite(value) && value > 0.0;
}

// "must be between MIN and kMaxTargetCount UNIT, got VALUE", or "".
std::string CountProblem(int value, int min, const char* unit) {
  if (value >= min && value <= kMaxTargetCount) return "";
  return "must be between " + std::to_string(min) + " and " +
         std::to_string(kMaxTargetCount) + " " + unit + ", got " +
         std::to_string(value);
}

std::string LengthProblem(double value) {
  if (PositiveFinite(value)) return "";
  std::ostringstream text;
  text << "must be positive and finite, got " << value;
  return text.str();
}

// Millimetres with at most 3 decimals and no trailing zeros ("25", "2.5").
std::string Millimetres(double metres) {
  std::ostringstream text;
  text << std::fixed << std::setprecision(3) << metres * 1000.0;
  std::string value = text.str();
  value.erase(value.find_last_not_of('0') + 1);
  if (!value.empty() && value.back() == '.') value.pop_back();
  return value;
}

// Reads the keys of one target type from the entries of the root map, with
// error messages naming the file, line and key.
class TargetKeys {
 public:
  // `required_keys` is the list quoted when a key is missing.
  TargetKeys(const YamlReader& reader, const YamlEntries& entries,
             std::string type_name, std::string required_keys)
      : reader_(reader),
        entries_(entries),
        type_name_(std::move(type_name)),
        required_keys_(std::move(required_keys)) {}

  // An integer in [min, kMaxTargetCount]; `unit` names what it counts.
  Status Count(const char* key, int min, const char* unit, int* value) const {
    const StatusOr<const YamlEntry*> entry = Lookup(key);
    if (!entry.ok()) return entry.status();
    const std::string& text = (*entry)->value.Scalar();
    int64_t parsed = 0;
    if (ParseYamlInteger(text, &parsed) != NumberSyntax::kOk) {
      return reader_.Error((*entry)->key, key,
                           QuoteForMessage(text) + " is not an integer");
    }
    if (parsed < min || parsed > kMaxTargetCount) {
      return reader_.Error((*entry)->key, key,
                           "must be between " + std::to_string(min) + " and " +
                               std::to_string(kMaxTargetCount) + " " + unit +
                               ", got " + EscapeForMessage(text));
    }
    *value = static_cast<int>(parsed);
    return Status::Ok();
  }

  // A finite number > 0.
  Status PositiveLength(const char* key, double* value) const {
    const YamlEntry* ignored = nullptr;
    return PositiveLength(key, value, &ignored);
  }

  // The same, also returning the entry (for later errors about the value).
  Status PositiveLength(const char* key, double* value,
                        const YamlEntry** entry_out) const {
    const StatusOr<const YamlEntry*> entry = Lookup(key);
    if (!entry.ok()) return entry.status();
    const std::string& text = (*entry)->value.Scalar();
    double parsed = 0.0;
    const NumberSyntax syntax = ParseYamlDouble(text, &parsed);
    if (syntax == NumberSyntax::kMalformed) {
      return reader_.Error((*entry)->key, key,
                           QuoteForMessage(text) + " is not a number");
    }
    if (syntax != NumberSyntax::kOk || !(parsed > 0.0)) {
      return reader_.Error(
          (*entry)->key, key,
          "must be positive and finite, got " + EscapeForMessage(text));
    }
    // Found by fuzz_calibration_target: tagSpacing 2.2e57 put the corners
    // so far out that neighbours rounded to the same point.
    if (parsed < kMinTargetLength || parsed > kMaxTargetLength) {
      return reader_.Error((*entry)->key, key,
                           "must be between 1e-06 and 10, got " +
                               EscapeForMessage(text));
    }
    *value = parsed;
    *entry_out = *entry;
    return Status::Ok();
  }

  // "SOURCE:LINE: KEY: MESSAGE" at the line of `entry`.
  Status ErrorAt(const YamlEntry& entry, const char* key,
                 const std::string& message) const {
    return reader_.Error(entry.key, key, message);
  }

 private:
  // The entry of `key`, whose value must be a scalar. Errors point at the
  // key's line: yaml-cpp marks a missing value at the next token.
  StatusOr<const YamlEntry*> Lookup(const char* key) const {
    const YamlEntry* entry = FindYamlEntry(entries_, key);
    if (entry == nullptr) {
      return reader_.Error("", "missing key " + QuoteForMessage(key) + " (" +
                                   type_name_ + " needs " + required_keys_ +
                                   ")");
    }
    if (!entry->value.IsScalar()) {
      return reader_.Error(
          entry->key, key,
          "expected a number, got " + DescribeYamlNode(entry->value));
    }
    return entry;
  }

  const YamlReader& reader_;
  const YamlEntries& entries_;
  std::string type_name_;
  std::string required_keys_;
};

StatusOr<CalibrationTarget> ParseCheckerboard(const YamlReader& reader,
                                              const YamlEntries& entries) {
  const TargetKeys keys(
      reader, entries, "a checkerboard",
      "targetCols, targetRows, rowSpacingMeters, colSpacingMeters");
  CalibrationTarget target;
  target.type = TargetType::kCheckerboard;
  RCM_RETURN_IF_ERROR(
      keys.Count("targetCols", 2, "inner corners", &target.cols));
  RCM_RETURN_IF_ERROR(
      keys.Count("targetRows", 2, "inner corners", &target.rows));
  RCM_RETURN_IF_ERROR(
      keys.PositiveLength("rowSpacingMeters", &target.row_spacing));
  RCM_RETURN_IF_ERROR(
      keys.PositiveLength("colSpacingMeters", &target.col_spacing));
  return target;
}

StatusOr<CalibrationTarget> ParseAprilGrid(const YamlReader& reader,
                                           const YamlEntries& entries) {
  const TargetKeys keys(reader, entries, "an aprilgrid",
                        "tagCols, tagRows, tagSize, tagSpacing");
  CalibrationTarget target;
  target.type = TargetType::kAprilGrid;
  RCM_RETURN_IF_ERROR(keys.Count("tagCols", 1, "tags", &target.cols));
  RCM_RETURN_IF_ERROR(keys.Count("tagRows", 1, "tags", &target.rows));
  RCM_RETURN_IF_ERROR(keys.PositiveLength("tagSize", &target.tag_size));
  RCM_RETURN_IF_ERROR(keys.PositiveLength("tagSpacing", &target.tag_spacing));
  return target;
}

StatusOr<CalibrationTarget> ParseCharuco(const YamlReader& reader,
                                         const YamlEntries& entries) {
  const TargetKeys keys(reader, entries, "a charuco board",
                        "squaresX, squaresY, squareSize, markerSize");
  CalibrationTarget target;
  target.type = TargetType::kCharuco;
  RCM_RETURN_IF_ERROR(keys.Count("squaresX", 2, "squares", &target.cols));
  RCM_RETURN_IF_ERROR(keys.Count("squaresY", 2, "squares", &target.rows));
  RCM_RETURN_IF_ERROR(keys.PositiveLength("squareSize", &target.square_size));
  const YamlEntry* marker_entry = nullptr;
  RCM_RETURN_IF_ERROR(
      keys.PositiveLength("markerSize", &target.marker_size, &marker_entry));
  if (!(target.marker_size < target.square_size)) {
    return keys.ErrorAt(
        *marker_entry, "markerSize",
        "must be smaller than squareSize (" +
            EscapeForMessage(marker_entry->value.Scalar()) + " >= " +
            EscapeForMessage(
                FindYamlEntry(entries, "squareSize")->value.Scalar()) +
            ")");
  }
  target.dictionary = kDefaultCharucoDictionary;
  const YamlEntry* dictionary = FindYamlEntry(entries, "dictionary");
  if (dictionary != nullptr) {
    if (!dictionary->value.IsScalar()) {
      return reader.Error(
          dictionary->key, "dictionary",
          "expected a name, got " + DescribeYamlNode(dictionary->value));
    }
    target.dictionary = dictionary->value.Scalar();
  }
  const std::string problem =
      CharucoDictionaryProblem(target.dictionary, target.cols, target.rows);
  if (!problem.empty()) {
    if (dictionary != nullptr) {
      return reader.Error(dictionary->key, "dictionary", problem);
    }
    // The default dictionary is too small: the board size is at fault.
    return reader.Error(FindYamlEntry(entries, "squaresY")->key, "squaresY",
                        problem + " (default dictionary; name a larger one)");
  }
  return target;
}

StatusOr<CalibrationTarget> ParseRoot(const YamlReader& reader,
                                      const YAML::Node& root) {
  if (root.IsNull()) {
    return reader.Error("", "empty file (expected a Kalibr target YAML map)");
  }
  if (!root.IsMap()) {
    return reader.Error(
        root, "",
        "expected a map of target settings, got " + DescribeYamlNode(root));
  }
  const StatusOr<YamlEntries> entries = reader.Entries(root, "");
  if (!entries.ok()) return entries.status();
  const YamlEntry* type = FindYamlEntry(*entries, "target_type");
  if (type == nullptr) {
    return reader.Error(
        "", std::string("missing key 'target_type' ") + kSupportedTypes);
  }
  if (!type->value.IsScalar()) {
    return reader.Error(type->key, "target_type",
                        "expected a name, got " +
                            DescribeYamlNode(type->value) + " " +
                            kSupportedTypes);
  }
  const std::string& name = type->value.Scalar();
  if (name == "checkerboard") return ParseCheckerboard(reader, *entries);
  if (name == "aprilgrid") return ParseAprilGrid(reader, *entries);
  if (name == "charuco") return ParseCharuco(reader, *entries);
  return reader.Error(
      type->key, "",
      "unknown target_type " + QuoteForMessage(name) + " " + kSupportedTypes);
}

void CheckValid(const CalibrationTarget& target) {
  const int min_count = target.type == TargetType::kAprilGrid ? 1 : 2;
  CHECK(target.cols >= min_count && target.cols <= kMaxTargetCount &&
        target.rows >= min_count && target.rows <= kMaxTargetCount)
      << "invalid target size " << target.cols << " x " << target.rows;
  const auto positive = [](double value) {
    return std::isfinite(value) && value > 0.0;
  };
  if (target.type == TargetType::kCheckerboard) {
    CHECK(positive(target.row_spacing) && positive(target.col_spacing))
        << "invalid checkerboard spacing " << target.row_spacing << ", "
        << target.col_spacing;
  } else if (target.type == TargetType::kCharuco) {
    CHECK(positive(target.square_size) && positive(target.marker_size) &&
          target.marker_size < target.square_size)
        << "invalid charuco square size " << target.square_size
        << " or marker size " << target.marker_size;
    const std::string problem =
        CharucoDictionaryProblem(target.dictionary, target.cols, target.rows);
    CHECK(problem.empty()) << "invalid charuco target: " << problem;
  } else {
    CHECK(positive(target.tag_size) && positive(target.tag_spacing))
        << "invalid aprilgrid tag size " << target.tag_size << " or spacing "
        << target.tag_spacing;
  }
}

}  // namespace

StatusOr<CalibrationTarget> ParseCalibrationTarget(
    const std::string& yaml_text, const std::string& source_name) {
  const YamlReader reader(source_name, /*syntax_error=*/"invalid YAML");
  return reader.ReadDocument(yaml_text, "YAML", [&](const YAML::Node& root) {
    return ParseRoot(reader, root);
  });
}

StatusOr<CalibrationTarget> ReadCalibrationTarget(const std::string& path) {
  StatusOr<std::string> text = ReadFileToString(path);
  if (!text.ok()) return text.status();
  return ParseCalibrationTarget(*text, path);
}

StatusOr<CalibrationTarget> MakeCheckerboardTarget(int cols, int rows,
                                                   double square) {
  const auto error = [](const char* what, const std::string& problem) {
    return Status::Error(std::string("checkerboard: ") + what + " " + problem);
  };
  std::string problem;
  if (!(problem = CountProblem(cols, 2, "inner corners")).empty()) {
    return error("cols", problem);
  }
  if (!(problem = CountProblem(rows, 2, "inner corners")).empty()) {
    return error("rows", problem);
  }
  if (!(problem = LengthProblem(square)).empty()) {
    return error("square size", problem);
  }
  CalibrationTarget target;
  target.type = TargetType::kCheckerboard;
  target.cols = cols;
  target.rows = rows;
  target.row_spacing = square;
  target.col_spacing = square;
  return target;
}

StatusOr<CalibrationTarget> MakeAprilGridTarget(int cols, int rows,
                                                double tag_size,
                                                double tag_spacing) {
  const auto error = [](const char* what, const std::string& problem) {
    return Status::Error(std::string("aprilgrid: ") + what + " " + problem);
  };
  std::string problem;
  if (!(problem = CountProblem(cols, 1, "tags")).empty()) {
    return error("cols", problem);
  }
  if (!(problem = CountProblem(rows, 1, "tags")).empty()) {
    return error("rows", problem);
  }
  if (!(problem = LengthProblem(tag_size)).empty()) {
    return error("tag size", problem);
  }
  if (!(problem = LengthProblem(tag_spacing)).empty()) {
    return error("tag spacing", problem);
  }
  CalibrationTarget target;
  target.type = TargetType::kAprilGrid;
  target.cols = cols;
  target.rows = rows;
  target.tag_size = tag_size;
  target.tag_spacing = tag_spacing;
  return target;
}

StatusOr<CalibrationTarget> MakeCharucoTarget(int squares_x, int squares_y,
                                              double square, double marker,
                                              const std::string& dictionary) {
  const auto error = [](const char* what, const std::string& problem) {
    return Status::Error(std::string("charuco: ") + what + " " + problem);
  };
  std::string problem;
  if (!(problem = CountProblem(squares_x, 2, "squares")).empty()) {
    return error("squares x", problem);
  }
  if (!(problem = CountProblem(squares_y, 2, "squares")).empty()) {
    return error("squares y", problem);
  }
  if (!(problem = LengthProblem(square)).empty()) {
    return error("square size", problem);
  }
  if (!(problem = LengthProblem(marker)).empty()) {
    return error("marker size", problem);
  }
  if (!(marker < square)) {
    std::ostringstream text;
    text << "must be smaller than the square size (" << marker
         << " >= " << square << ")";
    return error("marker size", text.str());
  }
  if (!(problem = CharucoDictionaryProblem(dictionary, squares_x, squares_y))
           .empty()) {
    return Status::Error("charuco: " + problem);
  }
  CalibrationTarget target;
  target.type = TargetType::kCharuco;
  target.cols = squares_x;
  target.rows = squares_y;
  target.square_size = square;
  target.marker_size = marker;
  target.dictionary = dictionary;
  return target;
}

std::string DescribeTarget(const CalibrationTarget& target) {
  const std::string size =
      std::to_string(target.cols) + "x" + std::to_string(target.rows);
  switch (target.type) {
    case TargetType::kCheckerboard: {
      const std::string squares = target.col_spacing == target.row_spacing
                                      ? Millimetres(target.col_spacing)
                                      : Millimetres(target.col_spacing) +
                                            " x " +
                                            Millimetres(target.row_spacing);
      return "checkerboard " + size + " inner corners, " + squares +
             " mm squares";
    }
    case TargetType::kAprilGrid: {
      std::ostringstream spacing;
      spacing << target.tag_spacing;
      return "aprilgrid " + size + " tags, " + Millimetres(target.tag_size) +
             " mm tags, spacing " + spacing.str();
    }
    case TargetType::kCharuco:
      return "charuco " + size + " squares, " +
             Millimetres(target.square_size) + " mm squares, " +
             Millimetres(target.marker_size) + " mm markers, " +
             target.dictionary;
  }
  return "unknown target";
}

std::optional<ArucoDictionaryInfo> FindArucoDictionary(
    const std::string& name) {
  for (const NamedDictionary& dictionary : kArucoDictionaries) {
    if (name == dictionary.name) return dictionary.info;
  }
  return std::nullopt;
}

int NumCharucoMarkers(const CalibrationTarget& target) {
  CHECK(target.type == TargetType::kCharuco) << "not a charuco target";
  CheckValid(target);
  return target.cols * target.rows / 2;
}

int NumTargetPoints(const CalibrationTarget& target) {
  CheckValid(target);
  switch (target.type) {
    case TargetType::kCheckerboard:
      return target.cols * target.rows;
    case TargetType::kAprilGrid:
      return 4 * target.cols * target.rows;
    case TargetType::kCharuco:
      return (target.cols - 1) * (target.rows - 1);
  }
  return 0;
}

std::vector<Eigen::Vector3d> TargetPoints(const CalibrationTarget& target) {
  CheckValid(target);
  std::vector<Eigen::Vector3d> points;
  points.reserve(NumTargetPoints(target));
  if (target.type == TargetType::kCheckerboard) {
    for (int r = 0; r < target.rows; ++r) {
      for (int c = 0; c < target.cols; ++c) {
        points.emplace_back(c * target.col_spacing, r * target.row_spacing,
                            0.0);
      }
    }
    return points;
  }
  if (target.type == TargetType::kCharuco) {
    // CharucoBoard::create: chessboardCorners[r * (squaresX - 1) + c] =
    // ((c + 1) squareLength, (r + 1) squareLength, 0).
    for (int r = 1; r < target.rows; ++r) {
      for (int c = 1; c < target.cols; ++c) {
        points.emplace_back(c * target.square_size, r * target.square_size,
                            0.0);
      }
    }
    return points;
  }
  const double size = target.tag_size;
  const double pitch = size * (1.0 + target.tag_spacing);
  const double corner_offsets[4][2] = {
      {0.0, 0.0}, {size, 0.0}, {size, size}, {0.0, size}};
  for (int j = 0; j < target.rows; ++j) {
    for (int i = 0; i < target.cols; ++i) {
      for (const auto& offset : corner_offsets) {
        points.emplace_back(pitch * i + offset[0], pitch * j + offset[1], 0.0);
      }
    }
  }
  return points;
}

}  // namespace rcm::calib
