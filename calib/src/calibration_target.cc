#include "rcm/calib/calibration_target.h"

#include <glog/logging.h>
#include <yaml-cpp/yaml.h>

#include <charconv>
#include <cmath>
#include <cstdint>
#include <exception>
#include <optional>
#include <string_view>
#include <system_error>
#include <utility>

#include "rcm/io/atomic_file.h"

namespace rcm::calib {
namespace {

constexpr char kSupportedTypes[] = "supported: checkerboard, aprilgrid";
constexpr size_t kMaxEchoLength = 40;

// A YAML scalar as quoted in an error message: on one line, shortened.
std::string Echo(std::string_view text) {
  std::string echo;
  for (const char c : text.substr(0, kMaxEchoLength)) {
    const auto byte = static_cast<unsigned char>(c);
    echo.push_back(byte < 0x20 || byte == 0x7f ? '?' : c);
  }
  if (text.size() > kMaxEchoLength) echo += "...";
  return echo;
}

std::string Location(const std::string& source_name, const YAML::Mark& mark) {
  if (mark.is_null() || mark.line < 0) return source_name;
  return source_name + ":" + std::to_string(mark.line + 1);
}

const char* KindOfNode(const YAML::Node& node) {
  switch (node.Type()) {
    case YAML::NodeType::Sequence:
      return "a list";
    case YAML::NodeType::Map:
      return "a map";
    case YAML::NodeType::Null:
      return "nothing";
    default:
      return "a scalar";
  }
}

// A key of the root map with its value.
struct Entry {
  YAML::Node key;
  YAML::Node value;
};

// The first entry of `map` whose key is the scalar `key`.
std::optional<Entry> FindEntry(const YAML::Node& map, const char* key) {
  for (YAML::const_iterator it = map.begin(); it != map.end(); ++it) {
    if (it->first.IsScalar() && it->first.Scalar() == key) {
      return Entry{it->first, it->second};
    }
  }
  return std::nullopt;
}

// Reads the keys of one target type from the root map, with error messages
// naming the file, line and key.
class TargetKeys {
 public:
  // `required_keys` is the list quoted when a key is missing.
  TargetKeys(const YAML::Node& root, const std::string& source_name,
             std::string type_name, std::string required_keys)
      : root_(root),
        source_name_(source_name),
        type_name_(std::move(type_name)),
        required_keys_(std::move(required_keys)) {}

  // An integer in [min, kMaxTargetCount]; `unit` names what it counts.
  Status Count(const char* key, int min, const char* unit, int* value) const {
    const StatusOr<Entry> entry = Lookup(key);
    if (!entry.ok()) return entry.status();
    const YAML::Node& node = entry->key;
    const std::string& text = entry->value.Scalar();
    int64_t parsed = 0;
    const auto [end, error] =
        std::from_chars(text.data(), text.data() + text.size(), parsed);
    if (error != std::errc() || end != text.data() + text.size() ||
        text.empty()) {
      return ErrorAt(
          node, std::string(key) + ": '" + Echo(text) + "' is not an integer");
    }
    if (parsed < min || parsed > kMaxTargetCount) {
      return ErrorAt(node, std::string(key) + ": must be between " +
                               std::to_string(min) + " and " +
                               std::to_string(kMaxTargetCount) + " " + unit +
                               ", got " + Echo(text));
    }
    *value = static_cast<int>(parsed);
    return Status::Ok();
  }

  // A finite number > 0.
  Status PositiveLength(const char* key, double* value) const {
    const StatusOr<Entry> entry = Lookup(key);
    if (!entry.ok()) return entry.status();
    const YAML::Node& node = entry->key;
    const std::string& text = entry->value.Scalar();
    double parsed = 0.0;
    const auto [end, error] =
        std::from_chars(text.data(), text.data() + text.size(), parsed);
    if ((error != std::errc() && error != std::errc::result_out_of_range) ||
        end != text.data() + text.size() || text.empty()) {
      return ErrorAt(
          node, std::string(key) + ": '" + Echo(text) + "' is not a number");
    }
    if (error != std::errc() || !std::isfinite(parsed) || !(parsed > 0.0)) {
      return ErrorAt(node, std::string(key) +
                               ": must be positive and finite, got " +
                               Echo(text));
    }
    *value = parsed;
    return Status::Ok();
  }

 private:
  // The value of `key`, which must be a scalar. Errors point at the key's
  // line: yaml-cpp marks a missing value at the next token.
  StatusOr<Entry> Lookup(const char* key) const {
    const std::optional<Entry> entry = FindEntry(root_, key);
    if (!entry.has_value()) {
      return Status::Error(source_name_ + ": missing key '" + key + "' (" +
                           type_name_ + " needs " + required_keys_ + ")");
    }
    if (!entry->value.IsScalar()) {
      return ErrorAt(entry->key, std::string(key) +
                                     ": expected a number, got " +
                                     KindOfNode(entry->value));
    }
    return *entry;
  }

  Status ErrorAt(const YAML::Node& node, const std::string& what) const {
    return Status::Error(Location(source_name_, node.Mark()) + ": " + what);
  }

  const YAML::Node& root_;
  const std::string& source_name_;
  std::string type_name_;
  std::string required_keys_;
};

StatusOr<CalibrationTarget> ParseCheckerboard(const YAML::Node& root,
                                              const std::string& source_name) {
  const TargetKeys keys(
      root, source_name, "a checkerboard",
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

StatusOr<CalibrationTarget> ParseAprilGrid(const YAML::Node& root,
                                           const std::string& source_name) {
  const TargetKeys keys(root, source_name, "an aprilgrid",
                        "tagCols, tagRows, tagSize, tagSpacing");
  CalibrationTarget target;
  target.type = TargetType::kAprilGrid;
  RCM_RETURN_IF_ERROR(keys.Count("tagCols", 1, "tags", &target.cols));
  RCM_RETURN_IF_ERROR(keys.Count("tagRows", 1, "tags", &target.rows));
  RCM_RETURN_IF_ERROR(keys.PositiveLength("tagSize", &target.tag_size));
  RCM_RETURN_IF_ERROR(keys.PositiveLength("tagSpacing", &target.tag_spacing));
  return target;
}

StatusOr<CalibrationTarget> ParseRoot(const YAML::Node& root,
                                      const std::string& source_name) {
  if (root.IsNull()) {
    return Status::Error(source_name +
                         ": empty file (expected a Kalibr target YAML map)");
  }
  if (!root.IsMap()) {
    return Status::Error(Location(source_name, root.Mark()) +
                         ": expected a map of target settings, got " +
                         KindOfNode(root));
  }
  const std::optional<Entry> type = FindEntry(root, "target_type");
  if (!type.has_value()) {
    return Status::Error(source_name + ": missing key 'target_type' (" +
                         kSupportedTypes + ")");
  }
  const std::string where = Location(source_name, type->key.Mark());
  if (!type->value.IsScalar()) {
    return Status::Error(where + ": target_type: expected a name, got " +
                         KindOfNode(type->value) + " (" + kSupportedTypes +
                         ")");
  }
  const std::string& name = type->value.Scalar();
  if (name == "checkerboard") return ParseCheckerboard(root, source_name);
  if (name == "aprilgrid") return ParseAprilGrid(root, source_name);
  return Status::Error(where + ": unknown target_type '" + Echo(name) + "' (" +
                       kSupportedTypes + ")");
}

void CheckValid(const CalibrationTarget& target) {
  const int min_count = target.type == TargetType::kCheckerboard ? 2 : 1;
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
  } else {
    CHECK(positive(target.tag_size) && positive(target.tag_spacing))
        << "invalid aprilgrid tag size " << target.tag_size << " or spacing "
        << target.tag_spacing;
  }
}

}  // namespace

StatusOr<CalibrationTarget> ParseCalibrationTarget(
    const std::string& yaml_text, const std::string& source_name) {
  try {
    const YAML::Node root = YAML::Load(yaml_text);
    return ParseRoot(root, source_name);
  } catch (const YAML::ParserException& error) {
    return Status::Error(Location(source_name, error.mark) +
                         ": invalid YAML: " + Echo(error.msg));
  } catch (const YAML::Exception& error) {
    return Status::Error(Location(source_name, error.mark) +
                         ": cannot read YAML: " + Echo(error.msg));
  } catch (const std::exception& error) {
    return Status::Error(source_name +
                         ": cannot read YAML: " + Echo(error.what()));
  }
}

StatusOr<CalibrationTarget> ReadCalibrationTarget(const std::string& path) {
  StatusOr<std::string> text = ReadFileToString(path);
  if (!text.ok()) return text.status();
  return ParseCalibrationTarget(*text, path);
}

int NumTargetPoints(const CalibrationTarget& target) {
  CheckValid(target);
  const int corners_per_cell = target.type == TargetType::kAprilGrid ? 4 : 1;
  return corners_per_cell * target.cols * target.rows;
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
