#include "rcm/io/camera_info.h"

#include <yaml-cpp/yaml.h>

#include <array>
#include <charconv>
#include <cmath>
#include <exception>
#include <map>
#include <optional>
#include <system_error>
#include <vector>

#include "rcm/geometry/rigid3d.h"
#include "rcm/io/atomic_file.h"
#include "rcm/io/number_format.h"

namespace rcm {
namespace {

// The YAML reading helpers below follow those of camchain.cc, so that both
// rig formats word their errors the same way.

// A scalar as it appears in an error message: quoted, control characters
// escaped (so that the message stays on one line), long values shortened.
std::string Quote(const std::string& scalar) {
  constexpr size_t kMaxShown = 40;
  std::string shown;
  for (size_t i = 0; i < scalar.size() && i < kMaxShown; ++i) {
    const unsigned char c = static_cast<unsigned char>(scalar[i]);
    if (c < 0x20 || c == 0x7f) {
      static const char kHex[] = "0123456789abcdef";
      shown += "\\x";
      shown += kHex[c >> 4];
      shown += kHex[c & 0xf];
    } else {
      shown += static_cast<char>(c);
    }
  }
  if (scalar.size() > kMaxShown) shown += "...";
  return "'" + shown + "'";
}

std::string Describe(const YAML::Node& node) {
  switch (node.Type()) {
    case YAML::NodeType::Scalar:
      return Quote(node.Scalar());
    case YAML::NodeType::Sequence:
      return "a list";
    case YAML::NodeType::Map:
      return "a map";
    case YAML::NodeType::Null:
    case YAML::NodeType::Undefined:
      break;
  }
  return "nothing";
}

// YAML 1.1's spellings of infinity and NaN (which from_chars does not
// read).
bool IsYamlNonFinite(const std::string& text) {
  static const char* const kSpellings[] = {".nan",  ".NaN",  ".NAN",  ".inf",
                                           ".Inf",  ".INF",  "+.inf", "+.Inf",
                                           "+.INF", "-.inf", "-.Inf", "-.INF"};
  for (const char* spelling : kSpellings) {
    if (text == spelling) return true;
  }
  return false;
}

struct MapEntry {
  YAML::Node key;
  YAML::Node value;
};
using MapEntries = std::map<std::string, MapEntry>;

class FieldReader {
 public:
  explicit FieldReader(const std::string& source) : source_(source) {}

  Status Error(const YAML::Node& at, const std::string& field,
               const std::string& message) const {
    std::string text = source_;
    const YAML::Mark mark = at.Mark();
    if (!mark.is_null()) text += ":" + std::to_string(mark.line + 1);
    if (!field.empty()) text += ": " + field;
    return Status::Error(text + ": " + message);
  }
  Status MissingKey(const std::string& field, const std::string& key) const {
    return Status::Error(source_ + (field.empty() ? "" : ": " + field) +
                         ": missing key '" + key + "'");
  }

  StatusOr<MapEntries> Entries(const YAML::Node& map,
                               const std::string& field) const {
    MapEntries entries;
    for (auto it = map.begin(); it != map.end(); ++it) {
      if (!it->first.IsScalar()) continue;
      const std::string& key = it->first.Scalar();
      if (entries.count(key) > 0) {
        return Error(it->first, field, "duplicate key " + Quote(key));
      }
      entries.emplace(key, MapEntry{it->first, it->second});
    }
    return entries;
  }

  StatusOr<double> Number(const YAML::Node& node,
                          const std::string& field) const {
    if (!node.IsScalar()) {
      return Error(node, field, "expected a number, got " + Describe(node));
    }
    const std::string& text = node.Scalar();
    const size_t start = (text.size() > 1 && text[0] == '+') ? 1 : 0;
    double value = 0.0;
    const char* end = text.data() + text.size();
    const std::from_chars_result result =
        std::from_chars(text.data() + start, end, value);
    if (result.ec == std::errc::result_out_of_range) {
      return Error(node, field, Quote(text) + " is out of range");
    }
    if (IsYamlNonFinite(text)) {
      return Error(node, field, Quote(text) + " is not a finite number");
    }
    if (text.empty() || result.ec != std::errc() || result.ptr != end) {
      return Error(node, field, Quote(text) + " is not a number");
    }
    if (!std::isfinite(value)) {
      return Error(node, field, Quote(text) + " is not a finite number");
    }
    return value;
  }

  StatusOr<int> Integer(const YAML::Node& node,
                        const std::string& field) const {
    if (!node.IsScalar()) {
      return Error(node, field, "expected an integer, got " + Describe(node));
    }
    const std::string& text = node.Scalar();
    const size_t start = (text.size() > 1 && text[0] == '+') ? 1 : 0;
    int value = 0;
    const char* end = text.data() + text.size();
    const std::from_chars_result result =
        std::from_chars(text.data() + start, end, value);
    if (result.ec == std::errc::result_out_of_range) {
      return Error(node, field, Quote(text) + " is out of range");
    }
    if (text.empty() || result.ec != std::errc() || result.ptr != end) {
      return Error(node, field, Quote(text) + " is not an integer");
    }
    return value;
  }

  // A string; YAML's empty value (`key:`) reads as "".
  StatusOr<std::string> String(const YAML::Node& node,
                               const std::string& field) const {
    if (node.IsNull()) return std::string();
    if (!node.IsScalar()) {
      return Error(node, field, "expected a string, got " + Describe(node));
    }
    return node.Scalar();
  }

  // The row-major data of a {rows, cols, data} matrix. `cols` < 0 accepts
  // any number of columns (with rows = 1).
  StatusOr<std::vector<double>> Matrix(const YAML::Node& node,
                                       const std::string& field, int rows,
                                       int cols) const {
    if (!node.IsMap()) {
      return Error(
          node, field,
          "expected a map with rows, cols and data, got " + Describe(node));
    }
    const StatusOr<MapEntries> entries = Entries(node, field);
    if (!entries.ok()) return entries.status();
    const auto data_it = entries->find("data");
    if (data_it == entries->end()) return MissingKey(field, "data");
    const YAML::Node& data = data_it->second.value;
    const std::string data_field = field + ".data";
    if (!data.IsSequence()) {
      return Error(data, data_field,
                   "expected a list of numbers, got " + Describe(data));
    }
    const int size = static_cast<int>(data.size());
    if (cols >= 0 && size != rows * cols) {
      return Error(data, data_field,
                   "expected " + std::to_string(rows * cols) + " numbers (" +
                       std::to_string(rows) + "x" + std::to_string(cols) +
                       "), got " + std::to_string(size));
    }
    const std::pair<const char*, int> kShape[] = {
        {"rows", rows}, {"cols", cols >= 0 ? cols : size}};
    for (const auto& [name, expected] : kShape) {
      const auto it = entries->find(name);
      if (it == entries->end()) continue;
      const StatusOr<int> value = Integer(it->second.value, field + "." + name);
      if (!value.ok()) return value.status();
      if (*value != expected) {
        return Error(it->second.value, field + "." + name,
                     "expected " + std::to_string(expected) + ", got " +
                         std::to_string(*value));
      }
    }
    std::vector<double> values;
    for (const YAML::Node& element : data) {
      const StatusOr<double> value = Number(element, data_field);
      if (!value.ok()) return value.status();
      values.push_back(*value);
    }
    return values;
  }

 private:
  std::string source_;
};

const MapEntry* Find(const MapEntries& entries, const std::string& key) {
  const auto it = entries.find(key);
  return it == entries.end() ? nullptr : &it->second;
}

// The rcm lens model of a ROS distortion_model name.
std::optional<LensModelId> LensModelFromRosName(const std::string& name) {
  if (name == "plumb_bob" || name == "radtan") return LensModelId::kRadTan;
  if (name == "equidistant") return LensModelId::kEquidistant;
  if (name == "none" || name.empty()) return LensModelId::kPinhole;
  return std::nullopt;
}

// Checks the ROS distortion coefficients for `model` and returns rcm's.
StatusOr<std::vector<double>> DistortionFromRos(
    const FieldReader& reader, const YAML::Node& at, LensModelId model,
    const std::string& model_name, const std::vector<double>& ros) {
  const std::string field = "distortion_coefficients.data";
  const int size = static_cast<int>(ros.size());
  switch (model) {
    case LensModelId::kPinhole:
      for (double value : ros) {
        if (value != 0.0) {
          return reader.Error(at, field,
                              "distortion_model '" + model_name +
                                  "' takes no coefficients, got nonzero " +
                                  FormatDouble(value));
        }
      }
      return std::vector<double>();
    case LensModelId::kRadTan:
      if (size != 4 && size != 5) {
        return reader.Error(at, field,
                            "expected 4 or 5 numbers (k1, k2, p1, p2[, k3]) "
                            "for distortion_model '" +
                                model_name + "', got " + std::to_string(size));
      }
      if (size == 5 && ros[4] != 0.0) {
        return reader.Error(at, field,
                            "k3 = " + FormatDouble(ros[4]) +
                                " is not supported: rcm's radtan model has "
                                "k1, k2, p1, p2; recalibrate with k3 fixed "
                                "to 0");
      }
      return std::vector<double>(ros.begin(), ros.begin() + 4);
    case LensModelId::kEquidistant:
      if (size != 4) {
        return reader.Error(at, field,
                            "expected 4 numbers (k1, k2, k3, k4) for "
                            "distortion_model '" +
                                model_name + "', got " + std::to_string(size));
      }
      return ros;
  }
  return reader.Error(at, field, "unhandled lens model");
}

StatusOr<CameraInfo> ParseCameraInfoNode(const FieldReader& reader,
                                         const std::string& source_name,
                                         const YAML::Node& root) {
  if (root.IsNull()) return Status::Error(source_name + ": empty file");
  if (!root.IsMap()) {
    return reader.Error(root, "",
                        "top level is not a map (expected a ROS camera_info "
                        "with image_width, camera_matrix, ...), got " +
                            Describe(root));
  }
  const StatusOr<MapEntries> entries = reader.Entries(root, "");
  if (!entries.ok()) return entries.status();
  const MapEntry* width_entry = Find(*entries, "image_width");
  if (width_entry == nullptr) return reader.MissingKey("", "image_width");
  const StatusOr<int> width = reader.Integer(width_entry->value, "image_width");
  if (!width.ok()) return width.status();
  const MapEntry* height_entry = Find(*entries, "image_height");
  if (height_entry == nullptr) return reader.MissingKey("", "image_height");
  const StatusOr<int> height =
      reader.Integer(height_entry->value, "image_height");
  if (!height.ok()) return height.status();

  std::string camera_name;
  if (const MapEntry* entry = Find(*entries, "camera_name")) {
    const StatusOr<std::string> name =
        reader.String(entry->value, "camera_name");
    if (!name.ok()) return name.status();
    camera_name = *name;
  }

  const MapEntry* k_entry = Find(*entries, "camera_matrix");
  if (k_entry == nullptr) return reader.MissingKey("", "camera_matrix");
  const StatusOr<std::vector<double>> k =
      reader.Matrix(k_entry->value, "camera_matrix", 3, 3);
  if (!k.ok()) return k.status();
  const YAML::Node k_data = k_entry->value["data"];
  const std::string k_field = "camera_matrix.data";
  if ((*k)[1] != 0.0) {
    return reader.Error(k_data, k_field,
                        "nonzero skew K[0][1] = " + FormatDouble((*k)[1]) +
                            " is not supported");
  }
  for (int index : {3, 6, 7}) {
    if ((*k)[index] != 0.0) {
      return reader.Error(k_data, k_field,
                          "expected [fx, 0, cx, 0, fy, cy, 0, 0, 1], but K[" +
                              std::to_string(index / 3) + "][" +
                              std::to_string(index % 3) +
                              "] = " + FormatDouble((*k)[index]));
    }
  }
  if ((*k)[8] != 1.0) {
    return reader.Error(k_data, k_field,
                        "expected [fx, 0, cx, 0, fy, cy, 0, 0, 1], but K[2][2] "
                        "= " +
                            FormatDouble((*k)[8]));
  }

  std::string model_name = "plumb_bob";  // ROS's default when absent
  const MapEntry* model_entry = Find(*entries, "distortion_model");
  if (model_entry != nullptr) {
    const StatusOr<std::string> name =
        reader.String(model_entry->value, "distortion_model");
    if (!name.ok()) return name.status();
    model_name = *name;
  }
  const std::optional<LensModelId> model = LensModelFromRosName(model_name);
  if (!model.has_value()) {
    return reader.Error(model_entry->value, "distortion_model",
                        "unknown model " + Quote(model_name) +
                            " (supported: plumb_bob, radtan, equidistant, "
                            "none)");
  }
  std::vector<double> distortion;
  const MapEntry* d_entry = Find(*entries, "distortion_coefficients");
  if (d_entry == nullptr) {
    if (*model != LensModelId::kPinhole) {
      return reader.MissingKey("", "distortion_coefficients");
    }
  } else {
    const StatusOr<std::vector<double>> ros = reader.Matrix(
        d_entry->value, "distortion_coefficients", 1, /*cols=*/-1);
    if (!ros.ok()) return ros.status();
    const StatusOr<std::vector<double>> converted = DistortionFromRos(
        reader, d_entry->value["data"], *model, model_name, *ros);
    if (!converted.ok()) return converted.status();
    distortion = *converted;
  }

  // Camera::Create validates everything at once; build it in stages so that
  // its message can be attributed to the key it is about.
  const std::array<double, 4> intrinsics = {(*k)[0], (*k)[4], (*k)[2], (*k)[5]};
  StatusOr<Camera> camera = Camera::Create(LensModelId::kPinhole, *width,
                                           *height, {1.0, 1.0, 0.0, 0.0}, {});
  if (!camera.ok()) {
    const bool width_bad = *width <= 0;
    return reader.Error(width_bad ? width_entry->value : height_entry->value,
                        width_bad ? "image_width" : "image_height",
                        camera.status().message());
  }
  camera =
      Camera::Create(LensModelId::kPinhole, *width, *height, intrinsics, {});
  if (!camera.ok()) {
    return reader.Error(k_data, k_field, camera.status().message());
  }
  camera = Camera::Create(*model, *width, *height, intrinsics, distortion);
  if (!camera.ok()) {
    return reader.Error(d_entry != nullptr ? d_entry->value : root,
                        "distortion_coefficients", camera.status().message());
  }

  Eigen::Matrix3d rectification = Eigen::Matrix3d::Identity();
  if (const MapEntry* entry = Find(*entries, "rectification_matrix")) {
    const StatusOr<std::vector<double>> r =
        reader.Matrix(entry->value, "rectification_matrix", 3, 3);
    if (!r.ok()) return r.status();
    Eigen::Matrix4d homogeneous = Eigen::Matrix4d::Identity();
    for (int i = 0; i < 9; ++i) homogeneous(i / 3, i % 3) = (*r)[i];
    const StatusOr<Rigid3d> rotation = Rigid3d::FromMatrix(homogeneous);
    if (!rotation.ok()) {
      return reader.Error(entry->value["data"], "rectification_matrix.data",
                          rotation.status().message());
    }
    rectification = homogeneous.topLeftCorner<3, 3>();
  }

  Eigen::Matrix<double, 3, 4> projection = Eigen::Matrix<double, 3, 4>::Zero();
  for (int i = 0; i < 9; ++i) projection(i / 3, i % 3) = (*k)[i];
  if (const MapEntry* entry = Find(*entries, "projection_matrix")) {
    const StatusOr<std::vector<double>> p =
        reader.Matrix(entry->value, "projection_matrix", 3, 4);
    if (!p.ok()) return p.status();
    for (int i = 0; i < 12; ++i) projection(i / 4, i % 4) = (*p)[i];
  }

  return CameraInfo{camera_name, *camera, rectification, projection};
}

// Checks that a ROS projection matrix has the form
// [fx' 0 cx' Tx; 0 fy' cy' Ty; 0 0 1 0] with fx', fy' > 0.
Status CheckProjection(const std::string& which,
                       const Eigen::Matrix<double, 3, 4>& p) {
  const bool form_ok = p(0, 1) == 0.0 && p(1, 0) == 0.0 && p(2, 0) == 0.0 &&
                       p(2, 1) == 0.0 && p(2, 2) == 1.0 && p(2, 3) == 0.0 &&
                       p(0, 0) > 0.0 && p(1, 1) > 0.0;
  if (form_ok) return Status::Ok();
  std::string rows;
  for (int r = 0; r < 3; ++r) {
    rows += r == 0 ? "[" : "; ";
    for (int c = 0; c < 4; ++c) {
      rows += (c == 0 ? "" : " ") + FormatDouble(p(r, c));
    }
  }
  return Status::Error(which +
                       " projection_matrix: expected [fx' 0 cx' Tx; 0 fy' "
                       "cy' Ty; 0 0 1 0] with fx', fy' > 0, got " +
                       rows + "]");
}

}  // namespace

StatusOr<CameraInfo> ParseCameraInfo(const std::string& text,
                                     const std::string& source_name) {
  const FieldReader reader(source_name);
  try {
    YAML::Node root;
    try {
      root = YAML::Load(text);
    } catch (const YAML::ParserException& e) {
      std::string location = source_name;
      if (!e.mark.is_null()) location += ":" + std::to_string(e.mark.line + 1);
      return Status::Error(location + ": YAML syntax error: " + e.msg);
    }
    return ParseCameraInfoNode(reader, source_name, root);
  } catch (const std::exception& e) {
    // yaml-cpp reports misuse by exception; every access above is checked,
    // so this is a last line of defence that keeps the no-throw promise.
    return Status::Error(source_name +
                         ": cannot read the camera_info: " + e.what());
  }
}

StatusOr<CameraInfo> ReadCameraInfo(const std::string& path) {
  const StatusOr<std::string> text = ReadFileToString(path);
  if (!text.ok()) return text.status();
  return ParseCameraInfo(*text, path);
}

StatusOr<StereoRig> StereoRigFromCameraInfo(const CameraInfo& left,
                                            const CameraInfo& right) {
  RCM_RETURN_IF_ERROR(CheckProjection("left", left.projection));
  RCM_RETURN_IF_ERROR(CheckProjection("right", right.projection));
  if (left.projection(0, 3) != 0.0 || left.projection(1, 3) != 0.0) {
    return Status::Error(
        "left projection_matrix has a nonzero 4th column (Tx = " +
        FormatDouble(left.projection(0, 3)) +
        ", Ty = " + FormatDouble(left.projection(1, 3)) +
        "): it is the right camera of the pair; give the left camera first");
  }
  const Eigen::Vector3d translation_rectified(
      right.projection(0, 3) / right.projection(0, 0),
      right.projection(1, 3) / right.projection(1, 1), 0.0);
  Rigid3d right_from_left;
  right_from_left.rotation =
      right.rectification.transpose() * left.rectification;
  right_from_left.translation =
      right.rectification.transpose() * translation_rectified;
  return StereoRig::Create(left.camera, right.camera, right_from_left);
}

}  // namespace rcm
