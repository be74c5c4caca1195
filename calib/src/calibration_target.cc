#include "rcm/calib/calibration_target.h"

#include <glog/logging.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstdint>
#include <string>
#include <utility>

#include "rcm/io/atomic_file.h"
#include "rcm/io/yaml_fields.h"
#include "rcm/util/message_text.h"

namespace rcm::calib {
namespace {

constexpr char kSupportedTypes[] = "(supported: checkerboard, aprilgrid)";

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
    *value = parsed;
    return Status::Ok();
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
  return reader.Error(
      type->key, "",
      "unknown target_type " + QuoteForMessage(name) + " " + kSupportedTypes);
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
