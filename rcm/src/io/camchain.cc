#include "rcm/io/camchain.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <map>
#include <string_view>
#include <system_error>
#include <utility>

#include "rcm/io/atomic_file.h"
#include "rcm/io/yaml_fields.h"
#include "rcm/util/message_text.h"
#include "rcm/util/number_format.h"

namespace rcm {
namespace {

// ---------------------------------------------------------------------------
// Reading.

// A homogeneous 4x4 transform written as 4 rows of 4 numbers, validated by
// Rigid3d::FromMatrix.
StatusOr<Rigid3d> ReadTransform(const YamlReader& reader,
                                const YAML::Node& node,
                                const std::string& field) {
  const StatusOr<Eigen::Matrix4d> matrix = reader.Matrix<4, 4>(node, field);
  if (!matrix.ok()) return matrix.status();
  const StatusOr<Rigid3d> transform = Rigid3d::FromMatrix(*matrix);
  if (!transform.ok()) {
    return reader.Error(node, field, transform.status().message());
  }
  return *transform;
}

const YAML::Node* Find(const YamlEntries& entries, std::string_view key) {
  const YamlEntry* entry = FindYamlEntry(entries, key);
  return entry == nullptr ? nullptr : &entry->value;
}

// A number of a port block: `required` or left as it is when absent.
Status ReadPortNumber(const YamlReader& reader, const YamlEntries& entries,
                      const std::string& field, const char* key, bool required,
                      double* value) {
  const YAML::Node* item = Find(entries, key);
  if (item == nullptr) {
    return required ? reader.MissingKey(field, key) : Status::Ok();
  }
  const StatusOr<double> read = reader.Number(*item, field + "." + key);
  if (!read.ok()) return read.status();
  *value = *read;
  return Status::Ok();
}

// The keys a port block of `type` may have; the first unknown one is an
// error (a misspelt key would silently give a default).
Status CheckPortKeys(const YamlReader& reader, const YamlEntries& entries,
                     const std::string& field,
                     const std::vector<std::string_view>& keys,
                     const char* listing) {
  for (const auto& [key, entry] : entries) {
    if (std::find(keys.begin(), keys.end(), key) == keys.end()) {
      return reader.Error(entry.key, field + "." + key,
                          std::string("unknown key (") + listing + ")");
    }
  }
  return Status::Ok();
}

// The `port` block of type dome (dome_port_geometry.h): inner_radius and
// thickness (or outer_radius, or both when they agree) required,
// glass_index and decentering optional (1.49, the centred dome).
StatusOr<DomePort> ReadDomePort(const YamlReader& reader,
                                const YAML::Node& node,
                                const YamlEntries& entries,
                                const std::string& field) {
  RCM_RETURN_IF_ERROR(CheckPortKeys(
      reader, entries, field,
      {"type", "inner_radius", "outer_radius", "thickness", "glass_index",
       "decentering"},
      "a dome port has type, inner_radius, thickness or outer_radius, "
      "glass_index, decentering"));
  DomePort dome;
  RCM_RETURN_IF_ERROR(ReadPortNumber(reader, entries, field, "inner_radius",
                                     true, &dome.inner_radius));
  double thickness = -1.0;
  double outer_radius = -1.0;
  RCM_RETURN_IF_ERROR(
      ReadPortNumber(reader, entries, field, "thickness", false, &thickness));
  RCM_RETURN_IF_ERROR(ReadPortNumber(reader, entries, field, "outer_radius",
                                     false, &outer_radius));
  if (Find(entries, "outer_radius") != nullptr) {
    const StatusOr<double> from_radii =
        DomeThicknessFromRadii(dome.inner_radius, outer_radius, thickness);
    if (!from_radii.ok()) {
      return reader.Error(node, field, from_radii.status().message());
    }
    // Written with the thickness, the thickness keeps its bits.
    dome.thickness = thickness >= 0.0 ? thickness : *from_radii;
  } else if (Find(entries, "thickness") != nullptr) {
    dome.thickness = thickness;
  } else {
    return reader.MissingKey(field, "thickness");
  }
  RCM_RETURN_IF_ERROR(ReadPortNumber(reader, entries, field, "glass_index",
                                     false, &dome.glass_index));
  if (const YAML::Node* item = Find(entries, "decentering")) {
    const StatusOr<std::vector<double>> centre =
        reader.NumberList(*item, field + ".decentering", 3);
    if (!centre.ok()) return centre.status();
    dome.decentering =
        Eigen::Vector3d((*centre)[0], (*centre)[1], (*centre)[2]);
  }
  if (const Status status = dome.Check(); !status.ok()) {
    return reader.Error(node, field, status.message());
  }
  return dome;
}

// The `port` block of a camera (flat_port_geometry.h): air_gap and
// glass_thickness required, glass_index and normal optional; a normal
// that is not of unit length is normalized. An unknown key is an error here (a
// misspelt key of a port would silently give the thin port).
StatusOr<FlatPort> ReadFlatPort(const YamlReader& reader,
                                const YAML::Node& node,
                                const YamlEntries& entries_in,
                                const std::string& field) {
  const YamlEntries* entries = &entries_in;
  RCM_RETURN_IF_ERROR(CheckPortKeys(
      reader, *entries, field,
      {"type", "air_gap", "glass_thickness", "glass_index", "normal"},
      "a port has air_gap, glass_thickness, glass_index, normal; a dome "
      "has type: dome"));
  FlatPort port;
  const auto number = [&](const char* key, bool required,
                          double* value) -> Status {
    return ReadPortNumber(reader, *entries, field, key, required, value);
  };
  RCM_RETURN_IF_ERROR(number("air_gap", true, &port.air_gap));
  RCM_RETURN_IF_ERROR(number("glass_thickness", true, &port.glass_thickness));
  RCM_RETURN_IF_ERROR(number("glass_index", false, &port.glass_index));
  if (const YAML::Node* item = Find(*entries, "normal")) {
    const StatusOr<std::vector<double>> normal =
        reader.NumberList(*item, field + ".normal", 3);
    if (!normal.ok()) return normal.status();
    port.normal = Eigen::Vector3d((*normal)[0], (*normal)[1], (*normal)[2]);
  }
  if (const Status status = port.Check(); !status.ok()) {
    return reader.Error(node, field, status.message());
  }
  // A unit normal read back from a file rcm wrote stays bit-exact.
  if (std::abs(port.normal.norm() - 1.0) > 1e-12) port.normal.stableNormalize();
  return port;
}

// A camera's `port` block: a flat port (the default type) or a dome.
Status ReadPort(const YamlReader& reader, const YAML::Node& node,
                const std::string& field, CamchainCamera* camera) {
  if (!node.IsMap()) {
    return reader.Error(node, field,
                        "expected a map {air_gap, glass_thickness, "
                        "glass_index, normal} or a dome {type: dome, "
                        "inner_radius, thickness, glass_index, decentering}, "
                        "got " +
                            DescribeYamlNode(node));
  }
  const StatusOr<YamlEntries> entries = reader.Entries(node, field);
  if (!entries.ok()) return entries.status();
  std::string type = "flat";
  if (const YAML::Node* item = Find(*entries, "type")) {
    const StatusOr<std::string> read = reader.String(*item, field + ".type");
    if (!read.ok()) return read.status();
    type = *read;
  }
  if (type == "dome") {
    StatusOr<DomePort> dome = ReadDomePort(reader, node, *entries, field);
    if (!dome.ok()) return dome.status();
    camera->dome = *dome;
    return Status::Ok();
  }
  if (type != "flat") {
    return reader.Error(
        *Find(*entries, "type"), field + ".type",
        "unknown port type '" + type + "' (supported: flat, dome)");
  }
  StatusOr<FlatPort> port = ReadFlatPort(reader, node, *entries, field);
  if (!port.ok()) return port.status();
  camera->port = *port;
  return Status::Ok();
}

StatusOr<CamchainCamera> ParseCamera(const YamlReader& reader, int index,
                                     const YAML::Node& node) {
  const std::string name = "cam" + std::to_string(index);
  if (!node.IsMap()) {
    return reader.Error(
        node, name,
        "expected a map of camera parameters, got " + DescribeYamlNode(node));
  }
  const StatusOr<YamlEntries> entries = reader.Entries(node, name);
  if (!entries.ok()) return entries.status();
  const auto required =
      [&](const std::string& key) -> StatusOr<const YAML::Node*> {
    const YAML::Node* value = Find(*entries, key);
    if (value == nullptr) return reader.MissingKey(name, key);
    return value;
  };
  const auto field = [&](const std::string& key) { return name + "." + key; };

  const StatusOr<const YAML::Node*> camera_model_node =
      required("camera_model");
  if (!camera_model_node.ok()) return camera_model_node.status();
  const StatusOr<std::string> camera_model =
      reader.String(**camera_model_node, field("camera_model"));
  if (!camera_model.ok()) return camera_model.status();
  // Kalibr's camera models: "pinhole" with a distortion_model, or the
  // unified models "ds" and "eucm", whose two distortion parameters lead
  // the intrinsics and whose distortion_model is "none".
  std::optional<LensModelId> unified_model;
  if (*camera_model == "ds") unified_model = LensModelId::kDoubleSphere;
  if (*camera_model == "eucm") unified_model = LensModelId::kEucm;
  if (*camera_model != "pinhole" && !unified_model.has_value()) {
    return reader.Error(**camera_model_node, field("camera_model"),
                        "unknown model " + QuoteForMessage(*camera_model) +
                            " (supported: pinhole, ds, eucm)");
  }

  // The distortion model is read before its coefficients, whose number it
  // fixes.
  const StatusOr<const YAML::Node*> model_node = required("distortion_model");
  if (!model_node.ok()) return model_node.status();
  const StatusOr<std::string> model_name =
      reader.String(**model_node, field("distortion_model"));
  if (!model_name.ok()) return model_name.status();
  std::optional<LensModelId> model = LensModelFromName(*model_name);
  if (unified_model.has_value()) {
    if (*model_name != "none") {
      return reader.Error(**model_node, field("distortion_model"),
                          "camera_model '" + *camera_model +
                              "' takes distortion_model 'none', got " +
                              QuoteForMessage(*model_name));
    }
    model = unified_model;
  } else if (!model.has_value() || *model == LensModelId::kDoubleSphere ||
             *model == LensModelId::kEucm) {
    const std::string hint =
        model.has_value() ? "; '" + *model_name +
                                "' is a camera_model, with distortion_model "
                                "'none'"
                          : "";
    return reader.Error(**model_node, field("distortion_model"),
                        "unknown model " + QuoteForMessage(*model_name) +
                            " (supported: none, radtan, equidistant, "
                            "rational" +
                            hint + ")");
  }

  // The coefficients of a pinhole camera's distortion model; none for the
  // unified models (an empty list, as Kalibr writes, is accepted).
  std::vector<double> distortion;
  const int num_coeffs =
      unified_model.has_value() ? 0 : NumDistortionParams(*model);
  const YAML::Node* coeffs_node = Find(*entries, "distortion_coeffs");
  if (coeffs_node == nullptr) {
    if (num_coeffs > 0) {
      return reader.MissingKey(name, "distortion_coeffs");
    }
  } else {
    const StatusOr<std::vector<double>> coeffs =
        reader.NumberList(*coeffs_node, field("distortion_coeffs"));
    if (!coeffs.ok()) return coeffs.status();
    if (static_cast<int>(coeffs->size()) != num_coeffs) {
      return reader.Error(*coeffs_node, field("distortion_coeffs"),
                          "expected " + std::to_string(num_coeffs) +
                              " numbers for " +
                              (unified_model.has_value()
                                   ? "camera_model '" + *camera_model + "'"
                                   : "distortion_model '" + *model_name + "'") +
                              ", got " + std::to_string(coeffs->size()));
    }
    distortion = *coeffs;
  }

  // intrinsics: [fu, fv, pu, pv], or [xi, alpha, fu, fv, pu, pv] (ds) and
  // [alpha, beta, fu, fv, pu, pv] (eucm).
  const int num_unified = unified_model.has_value() ? 2 : 0;
  const StatusOr<const YAML::Node*> intrinsics_node = required("intrinsics");
  if (!intrinsics_node.ok()) return intrinsics_node.status();
  const StatusOr<std::vector<double>> read_intrinsics = reader.NumberList(
      **intrinsics_node, field("intrinsics"), 4 + num_unified);
  if (!read_intrinsics.ok()) return read_intrinsics.status();
  if (num_unified > 0) {
    distortion.assign(read_intrinsics->begin(),
                      read_intrinsics->begin() + num_unified);
  }
  const std::vector<double> intrinsics_values(
      read_intrinsics->begin() + num_unified, read_intrinsics->end());
  const std::vector<double>* intrinsics = &intrinsics_values;

  const StatusOr<const YAML::Node*> resolution_node = required("resolution");
  if (!resolution_node.ok()) return resolution_node.status();
  const StatusOr<std::vector<int>> resolution =
      reader.IntegerList(**resolution_node, field("resolution"), 2);
  if (!resolution.ok()) return resolution.status();

  // Each of Camera::Create's checks, attributed to the key it is about.
  const int width = (*resolution)[0];
  const int height = (*resolution)[1];
  const std::array<double, 4> fx_fy_cx_cy = {
      (*intrinsics)[0], (*intrinsics)[1], (*intrinsics)[2], (*intrinsics)[3]};
  if (const Status status = Camera::CheckImageSize(width, height);
      !status.ok()) {
    return reader.Error(**resolution_node, field("resolution"),
                        status.message());
  }
  if (const Status status = Camera::CheckIntrinsics(fx_fy_cx_cy);
      !status.ok()) {
    return reader.Error(**intrinsics_node, field("intrinsics"),
                        status.message());
  }
  if (const Status status = Camera::CheckDistortion(*model, distortion);
      !status.ok()) {
    if (num_unified > 0) {
      return reader.Error(**intrinsics_node, field("intrinsics"),
                          status.message());
    }
    return reader.Error(coeffs_node != nullptr ? *coeffs_node : node,
                        field("distortion_coeffs"), status.message());
  }
  // Cannot fail: Create runs exactly the three checks above.
  const Camera camera =
      Camera::Create(*model, width, height, fx_fy_cx_cy, distortion).value();

  CamchainCamera result{camera,       std::nullopt, std::nullopt,
                        std::nullopt, {},           ""};

  if (const YAML::Node* value = Find(*entries, "T_cam_imu")) {
    const StatusOr<Rigid3d> transform =
        ReadTransform(reader, *value, field("T_cam_imu"));
    if (!transform.ok()) return transform.status();
    result.cam_from_imu = *transform;
  }

  const YAML::Node* previous = Find(*entries, "T_cn_cnm1");
  if (index == 0 && previous != nullptr) {
    return reader.Error(*previous, field("T_cn_cnm1"),
                        "cam0 is the first camera and has no previous "
                        "camera; T_cn_cnm1 belongs on cam1 and later");
  }
  if (index > 0) {
    if (previous == nullptr) return reader.MissingKey(name, "T_cn_cnm1");
    const StatusOr<Rigid3d> transform =
        ReadTransform(reader, *previous, field("T_cn_cnm1"));
    if (!transform.ok()) return transform.status();
    result.cam_from_previous = *transform;
  }

  if (const YAML::Node* value = Find(*entries, "cam_overlaps")) {
    const StatusOr<std::vector<int>> overlaps =
        reader.IntegerList(*value, field("cam_overlaps"), -1);
    if (!overlaps.ok()) return overlaps.status();
    result.cam_overlaps = *overlaps;
  }
  if (const YAML::Node* value = Find(*entries, "rostopic")) {
    const StatusOr<std::string> rostopic =
        reader.String(*value, field("rostopic"));
    if (!rostopic.ok()) return rostopic.status();
    result.rostopic = *rostopic;
  }
  if (const YAML::Node* value = Find(*entries, "timeshift_cam_imu")) {
    const StatusOr<double> shift =
        reader.Number(*value, field("timeshift_cam_imu"));
    if (!shift.ok()) return shift.status();
    result.timeshift_cam_imu = *shift;
  }
  if (const YAML::Node* value = Find(*entries, "port")) {
    RCM_RETURN_IF_ERROR(ReadPort(reader, *value, field("port"), &result));
  }
  return result;
}

// The camera index of a top-level key "camN"; nullopt for any other key.
// A key of "cam" and digits that is not a canonical index ("cam01", an
// overflowing number) is an error rather than an ignored key, since it was
// clearly meant as a camera.
StatusOr<std::optional<int>> CameraIndex(const YamlReader& reader,
                                         const std::string& key,
                                         const YAML::Node& key_node) {
  const std::string_view digits =
      std::string_view(key).substr(std::min<size_t>(key.size(), 3));
  if (key.compare(0, 3, "cam") != 0 || digits.empty() ||
      !std::all_of(digits.begin(), digits.end(),
                   [](char c) { return c >= '0' && c <= '9'; })) {
    return std::optional<int>();
  }
  const std::optional<int> index = CamchainCameraIndex(key);
  if (!index.has_value()) {
    return reader.Error(key_node, "",
                        "malformed camera key " + QuoteForMessage(key) +
                            " (expected cam0, cam1, ...)");
  }
  return index;
}

StatusOr<Camchain> ParseCamchainNode(const YamlReader& reader,
                                     const YAML::Node& root) {
  const StatusOr<YamlEntries> entries =
      reader.RootEntries(root, "expected cam0, cam1, ...");
  if (!entries.ok()) return entries.status();

  std::map<int, std::pair<std::string, const YamlEntry*>> cameras;
  for (const auto& [key, entry] : *entries) {
    const StatusOr<std::optional<int>> index =
        CameraIndex(reader, key, entry.key);
    if (!index.ok()) return index.status();
    if (index->has_value()) cameras[**index] = {key, &entry};
  }
  if (cameras.count(0) == 0) {
    return reader.Error("", "no 'cam0' key: not a Kalibr camchain");
  }
  int expected = 0;
  for (const auto& [index, named_entry] : cameras) {
    if (index != expected) {
      return reader.Error(named_entry.second->key, "",
                          "cameras must be numbered cam0, cam1, ... without "
                          "gaps: found " +
                              named_entry.first + " but no cam" +
                              std::to_string(expected));
    }
    ++expected;
  }

  Camchain camchain;
  for (const auto& [index, named_entry] : cameras) {
    StatusOr<CamchainCamera> camera =
        ParseCamera(reader, index, named_entry.second->value);
    if (!camera.ok()) return camera.status();
    camchain.cameras.push_back(std::move(camera).value());
  }
  return camchain;
}

// ---------------------------------------------------------------------------
// Writing: a small emulation of PyYAML's emitter for the shapes a camchain
// has (block maps of scalars and flow lists, block lists of flow lists).

// PyYAML's defaults: wrap flow collections after column 80, indent by 2.
constexpr int kBestWidth = 80;

// A float as PyYAML's represent_float writes it.
std::string YamlFloat(double value) {
  if (std::isnan(value)) return ".nan";
  if (std::isinf(value)) return value > 0.0 ? ".inf" : "-.inf";
  std::string text = FormatDouble(value);
  const size_t e = text.find('e');
  if (e != std::string::npos && text.find('.') == std::string::npos) {
    text.insert(e, ".0");
  }
  return text;
}

// A string as PyYAML writes it: plain when that reads back as the same
// string, otherwise quoted. Plain style is used for the characters of ROS
// names (which is what rostopic holds) and never for a YAML keyword;
// anything else is single-quoted, or double-quoted with escapes when it
// holds control characters. (PyYAML allows plain style for a few more
// strings than this, and folds long quoted strings at spaces; neither
// happens for a ROS topic name.)
std::string YamlString(const std::string& text) {
  static const char* const kKeywords[] = {
      "yes",  "Yes",   "YES",   "no",    "No",   "NO", "true", "True",
      "TRUE", "false", "False", "FALSE", "on",   "On", "ON",   "off",
      "Off",  "OFF",   "null",  "Null",  "NULL", "~"};
  bool plain = !text.empty();
  if (plain) {
    const char first = text.front();
    plain = std::isalpha(static_cast<unsigned char>(first)) || first == '_' ||
            first == '/' || first == '~';
  }
  for (char c : text) {
    if (!plain) break;
    plain = std::isalnum(static_cast<unsigned char>(c)) || c == '_' ||
            c == '/' || c == '~' || c == '.' || c == '-';
  }
  for (const char* keyword : kKeywords) {
    if (text == keyword) plain = false;
  }
  if (plain) return text;

  const bool printable = std::all_of(text.begin(), text.end(), [](char c) {
    const unsigned char u = static_cast<unsigned char>(c);
    return u >= 0x20 && u != 0x7f;
  });
  if (printable) {
    std::string quoted = "'";
    for (char c : text) {
      quoted += c;
      if (c == '\'') quoted += '\'';
    }
    return quoted + "'";
  }
  std::string quoted = "\"";
  for (char c : text) {
    const unsigned char u = static_cast<unsigned char>(c);
    if (c == '"' || c == '\\') {
      quoted += '\\';
      quoted += c;
    } else if (u < 0x20 || u == 0x7f) {
      static const char kHex[] = "0123456789ABCDEF";
      quoted += "\\x";
      quoted += kHex[u >> 4];
      quoted += kHex[u & 0xf];
    } else {
      quoted += c;
    }
  }
  return quoted + "\"";
}

// Appends "[a, b, c]" at the end of `out` the way PyYAML writes a flow
// sequence: after each comma, when the line is already longer than
// kBestWidth, the next item goes on a new line indented by `indent`.
void AppendFlowList(const std::vector<std::string>& items, int indent,
                    std::string* out) {
  const auto column = [out]() {
    const size_t newline = out->rfind('\n');
    return static_cast<int>(
        newline == std::string::npos ? out->size() : out->size() - newline - 1);
  };
  const auto break_line = [&]() {
    *out += '\n';
    out->append(indent, ' ');
  };
  *out += '[';
  for (size_t i = 0; i < items.size(); ++i) {
    if (i > 0) *out += ',';
    if (column() > kBestWidth) {
      break_line();
    } else if (i > 0) {
      *out += ' ';
    }
    *out += items[i];
  }
  *out += ']';
}

std::vector<std::string> FloatItems(const std::vector<double>& values) {
  std::vector<std::string> items;
  for (double value : values) items.push_back(YamlFloat(value));
  return items;
}

// "  key: [a, b]\n" inside a camera map.
void AppendListField(const std::string& key,
                     const std::vector<std::string>& items, std::string* out) {
  *out += "  " + key + ": ";
  AppendFlowList(items, 4, out);
  *out += '\n';
}

void AppendTransformField(const std::string& key, const Rigid3d& transform,
                          std::string* out) {
  const Eigen::Matrix4d matrix = transform.ToMatrix();
  *out += "  " + key + ":\n";
  for (int row = 0; row < 4; ++row) {
    *out += "  - ";
    AppendFlowList(FloatItems({matrix(row, 0), matrix(row, 1), matrix(row, 2),
                               matrix(row, 3)}),
                   4, out);
    *out += '\n';
  }
}

void AppendCamera(const std::string& name, const CamchainCamera& entry,
                  std::string* out) {
  const Camera& camera = entry.camera;
  *out += name + ":\n";
  if (entry.cam_from_imu.has_value()) {
    AppendTransformField("T_cam_imu", *entry.cam_from_imu, out);
  }
  if (entry.cam_from_previous.has_value()) {
    AppendTransformField("T_cn_cnm1", *entry.cam_from_previous, out);
  }
  std::vector<std::string> overlaps;
  for (int index : entry.cam_overlaps)
    overlaps.push_back(std::to_string(index));
  AppendListField("cam_overlaps", overlaps, out);
  // ds and eucm as Kalibr writes them: the camera_model, no distortion
  // coefficients, the two model parameters before fu, fv, pu, pv. Every
  // other model is a pinhole camera_model with a distortion_model;
  // "rational" (OpenCV's 8 coefficients k1, k2, p1, p2, k3, k4, k5, k6) is
  // rcm's extension, Kalibr has no such model (docs/file_formats.md).
  const bool unified = camera.model() == LensModelId::kDoubleSphere ||
                       camera.model() == LensModelId::kEucm;
  std::vector<double> intrinsics = {camera.fx(), camera.fy(), camera.cx(),
                                    camera.cy()};
  if (unified) {
    const std::vector<double> distortion = camera.Distortion();
    intrinsics.insert(intrinsics.begin(), distortion.begin(), distortion.end());
    *out +=
        "  camera_model: " + std::string(LensModelName(camera.model())) + "\n";
    *out += "  distortion_coeffs: []\n";
    *out += "  distortion_model: none\n";
  } else {
    *out += "  camera_model: pinhole\n";
    AppendListField("distortion_coeffs", FloatItems(camera.Distortion()), out);
    *out +=
        "  distortion_model: " + std::string(LensModelName(camera.model())) +
        "\n";
  }
  AppendListField("intrinsics", FloatItems(intrinsics), out);
  AppendListField(
      "resolution",
      {std::to_string(camera.width()), std::to_string(camera.height())}, out);
  if (entry.dome.has_value()) {
    // Sorted keys; a map holding a list is written in block style.
    const DomePort& dome = *entry.dome;
    *out += "  port:\n";
    *out += "    decentering: ";
    AppendFlowList(FloatItems({dome.decentering.x(), dome.decentering.y(),
                               dome.decentering.z()}),
                   6, out);
    *out += '\n';
    *out += "    glass_index: " + YamlFloat(dome.glass_index) + "\n";
    *out += "    inner_radius: " + YamlFloat(dome.inner_radius) + "\n";
    *out += "    thickness: " + YamlFloat(dome.thickness) + "\n";
    *out += "    type: dome\n";
  } else if (entry.port.has_value()) {
    // Sorted keys; a map holding a list is written in block style.
    const FlatPort& port = *entry.port;
    *out += "  port:\n";
    *out += "    air_gap: " + YamlFloat(port.air_gap) + "\n";
    *out += "    glass_index: " + YamlFloat(port.glass_index) + "\n";
    *out += "    glass_thickness: " + YamlFloat(port.glass_thickness) + "\n";
    *out += "    normal: ";
    AppendFlowList(
        FloatItems({port.normal.x(), port.normal.y(), port.normal.z()}), 6,
        out);
    *out += '\n';
  }
  if (!entry.rostopic.empty()) {
    *out += "  rostopic: " + YamlString(entry.rostopic) + "\n";
  }
  if (entry.timeshift_cam_imu.has_value()) {
    *out +=
        "  timeshift_cam_imu: " + YamlFloat(*entry.timeshift_cam_imu) + "\n";
  }
}

}  // namespace

std::optional<int> CamchainCameraIndex(std::string_view name) {
  if (name.size() <= 3 || name.substr(0, 3) != "cam") return std::nullopt;
  const std::string_view digits = name.substr(3);
  if (digits.size() > 1 && digits[0] == '0') return std::nullopt;
  int index = 0;
  const std::from_chars_result result =
      std::from_chars(digits.data(), digits.data() + digits.size(), index);
  if (result.ec != std::errc() || result.ptr != digits.data() + digits.size() ||
      index < 0) {
    return std::nullopt;
  }
  return index;
}

StatusOr<int> FindCamchainCamera(const Camchain& camchain,
                                 std::string_view name) {
  const int num_cameras = static_cast<int>(camchain.cameras.size());
  const std::optional<int> index = CamchainCameraIndex(name);
  if (index.has_value() && *index < num_cameras) return *index;
  std::string known;
  for (int k = 0; k < num_cameras; ++k) {
    known += (k == 0 ? "cam" : ", cam") + std::to_string(k);
  }
  return Status::Error("unknown camera '" + std::string(name) +
                       "' (the camchain has " + known + ")");
}

StatusOr<Camchain> ParseCamchain(const std::string& text,
                                 const std::string& source_name) {
  const YamlReader reader(source_name);
  return reader.ReadDocument(text, "the camchain", [&](const YAML::Node& root) {
    return ParseCamchainNode(reader, root);
  });
}

StatusOr<Camchain> ReadCamchain(const std::string& path) {
  const StatusOr<std::string> text = ReadFileToString(path);
  if (!text.ok()) return text.status();
  return ParseCamchain(*text, path);
}

std::string FormatCamchain(const Camchain& camchain) {
  // Python sorts the keys as strings: cam0, cam1, cam10, cam11, cam2, ...
  std::vector<std::string> names;
  for (size_t i = 0; i < camchain.cameras.size(); ++i) {
    names.push_back("cam" + std::to_string(i));
  }
  std::vector<size_t> order(names.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(),
            [&](size_t a, size_t b) { return names[a] < names[b]; });
  std::string out;
  for (size_t i : order) AppendCamera(names[i], camchain.cameras[i], &out);
  return out;
}

Status WriteCamchain(const std::string& path, const Camchain& camchain) {
  if (camchain.cameras.empty()) {
    return Status::Error(path + ": cannot write a camchain without cameras");
  }
  if (camchain.cameras[0].cam_from_previous.has_value()) {
    return Status::Error(path +
                         ": cannot write: cam0 has a T_cn_cnm1 (cam0 is the "
                         "first camera and has no previous one)");
  }
  for (size_t i = 1; i < camchain.cameras.size(); ++i) {
    if (!camchain.cameras[i].cam_from_previous.has_value()) {
      return Status::Error(path + ": cannot write: cam" + std::to_string(i) +
                           " has no T_cn_cnm1");
    }
  }
  return WriteFileAtomically(path, FormatCamchain(camchain));
}

StatusOr<StereoRig> StereoRigFromCamchain(const Camchain& camchain,
                                          int left_index, int right_index) {
  const int num_cameras = static_cast<int>(camchain.cameras.size());
  for (int index : {left_index, right_index}) {
    if (index < 0 || index >= num_cameras) {
      return Status::Error(
          "camera index " + std::to_string(index) +
          " is out of range (the camchain has " +
          (num_cameras == 0 ? std::string("no cameras")
                            : "cam0..cam" + std::to_string(num_cameras - 1)) +
          ")");
    }
  }
  if (left_index == right_index) {
    return Status::Error("left and right are the same camera (cam" +
                         std::to_string(left_index) + ")");
  }
  for (int index : {left_index, right_index}) {
    if (camchain.cameras[index].dome.has_value()) {
      // The stereo tools model flat ports; a dome's rig is handled by the
      // dome tools (rcm calibrate --underwater --port dome, rcm
      // dome-check), which read the camchain's cameras themselves.
      return Status::Error(
          "cam" + std::to_string(index) +
          " looks through a dome port, which this stereo tool does not "
          "model (it handles flat ports); use the dome tools (rcm calibrate "
          "--underwater --port dome, rcm dome-check, rcm undistort "
          "--reference-depth)");
    }
  }
  // high_from_low = T(high) * ... * T(low + 1).
  const int low = std::min(left_index, right_index);
  const int high = std::max(left_index, right_index);
  Rigid3d high_from_low;
  for (int k = low + 1; k <= high; ++k) {
    const std::optional<Rigid3d>& cam_from_previous =
        camchain.cameras[k].cam_from_previous;
    if (!cam_from_previous.has_value()) {
      return Status::Error("cam" + std::to_string(k) + " has no T_cn_cnm1");
    }
    high_from_low =
        k == low + 1 ? *cam_from_previous : *cam_from_previous * high_from_low;
  }
  const Rigid3d right_from_left =
      right_index > left_index ? high_from_low : high_from_low.Inverse();
  const StatusOr<StereoRig> rig =
      StereoRig::Create(camchain.cameras[left_index].camera,
                        camchain.cameras[right_index].camera, right_from_left);
  if (!rig.ok()) {
    return rig.status().WithContext("cam" + std::to_string(right_index) +
                                    "_from_cam" + std::to_string(left_index));
  }
  const std::optional<FlatPort>& left_port = camchain.cameras[left_index].port;
  const std::optional<FlatPort>& right_port =
      camchain.cameras[right_index].port;
  if (left_port.has_value() || right_port.has_value()) {
    // A camera without a port block has the thin port.
    return rig->WithPorts(left_port.value_or(FlatPort()),
                          right_port.value_or(FlatPort()));
  }
  return rig;
}

Camchain CamchainFromStereoRig(const StereoRig& rig) {
  Camchain camchain;
  CamchainCamera left{rig.left(),   std::nullopt, std::nullopt,
                      std::nullopt, {1},          ""};
  CamchainCamera right{
      rig.right(), rig.right_from_left(), std::nullopt, std::nullopt, {0}, ""};
  if (rig.ports().has_value()) {
    left.port = rig.ports()->left;
    right.port = rig.ports()->right;
  }
  camchain.cameras = {left, right};
  return camchain;
}

Status CopyCamchainImuAndTopics(const Camchain& source, int left_index,
                                int right_index, Camchain* pair) {
  const int num_cameras = static_cast<int>(source.cameras.size());
  if (left_index < 0 || left_index >= num_cameras || right_index < 0 ||
      right_index >= num_cameras || left_index == right_index) {
    return Status::Error("cameras cam" + std::to_string(left_index) +
                         " and cam" + std::to_string(right_index) +
                         " are not two cameras of the camchain");
  }
  if (pair->cameras.size() != 2) {
    return Status::Error("the camchain to complete has " +
                         std::to_string(pair->cameras.size()) +
                         " cameras, expected 2");
  }
  const int indices[2] = {left_index, right_index};
  for (int k = 0; k < 2; ++k) {
    const CamchainCamera& from = source.cameras[indices[k]];
    CamchainCamera& to = pair->cameras[k];
    to.cam_from_imu = from.cam_from_imu;
    to.timeshift_cam_imu = from.timeshift_cam_imu;
    to.rostopic = from.rostopic;
  }
  return Status::Ok();
}

}  // namespace rcm
