#include "rcm/io/camera_info.h"

#include <glog/logging.h>
#include <yaml-cpp/yaml.h>

#include <array>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "rcm/geometry/rigid3d.h"
#include "rcm/io/atomic_file.h"
#include "rcm/io/yaml_fields.h"
#include "rcm/util/message_text.h"
#include "rcm/util/number_format.h"

namespace rcm {
namespace {

// A ROS matrix, {rows, cols, data} with the data in row-major order, and
// its data node (where errors about the values point).
struct RosMatrix {
  std::vector<double> data;
  YAML::Node data_node;
};

// Reads a `rows` x `cols` ROS matrix. `cols` < 0 accepts any number of
// columns (with rows = 1). The rows and cols keys may be left out.
StatusOr<RosMatrix> ReadRosMatrix(const YamlReader& reader,
                                  const YAML::Node& node,
                                  const std::string& field, int rows,
                                  int cols) {
  if (!node.IsMap()) {
    return reader.Error(node, field,
                        "expected a map with rows, cols and data, got " +
                            DescribeYamlNode(node));
  }
  const StatusOr<YamlEntries> entries = reader.Entries(node, field);
  if (!entries.ok()) return entries.status();
  const YamlEntry* data_entry = FindYamlEntry(*entries, "data");
  if (data_entry == nullptr) return reader.MissingKey(field, "data");
  const YAML::Node& data = data_entry->value;
  const std::string data_field = field + ".data";
  if (!data.IsSequence()) {
    return reader.Error(
        data, data_field,
        "expected a list of numbers, got " + DescribeYamlNode(data));
  }
  const int size = static_cast<int>(data.size());
  if (cols >= 0 && size != rows * cols) {
    return reader.Error(data, data_field,
                        "expected " + std::to_string(rows * cols) +
                            " numbers (" + std::to_string(rows) + "x" +
                            std::to_string(cols) + "), got " +
                            std::to_string(size));
  }
  const std::pair<const char*, int> kShape[] = {
      {"rows", rows}, {"cols", cols >= 0 ? cols : size}};
  for (const auto& [name, expected] : kShape) {
    const YamlEntry* entry = FindYamlEntry(*entries, name);
    if (entry == nullptr) continue;
    const std::string shape_field = field + "." + name;
    const StatusOr<int> value = reader.Integer(entry->value, shape_field);
    if (!value.ok()) return value.status();
    if (*value != expected) {
      return reader.Error(entry->value, shape_field,
                          "expected " + std::to_string(expected) + ", got " +
                              std::to_string(*value));
    }
  }
  StatusOr<std::vector<double>> values = reader.NumberList(data, data_field);
  if (!values.ok()) return values.status();
  return RosMatrix{std::move(values).value(), data};
}

// A string that may be left empty (`key:`), which reads as "".
StatusOr<std::string> OptionalString(const YamlReader& reader,
                                     const YAML::Node& node,
                                     const std::string& field) {
  if (node.IsNull()) return std::string();
  return reader.String(node, field);
}

// The rcm lens model of a ROS distortion_model name.
std::optional<LensModelId> LensModelFromRosName(const std::string& name) {
  if (name == "plumb_bob" || name == "radtan") return LensModelId::kRadTan;
  if (name == "equidistant") return LensModelId::kEquidistant;
  if (name == "rational_polynomial") return LensModelId::kRational;
  if (name == "none" || name.empty()) return LensModelId::kPinhole;
  return std::nullopt;
}

// Checks the ROS distortion coefficients for `model` and returns rcm's.
StatusOr<std::vector<double>> DistortionFromRos(
    const YamlReader& reader, const YAML::Node& at, LensModelId model,
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
    case LensModelId::kRational:
      // ROS's rational_polynomial, D = [k1, k2, p1, p2, k3, k4, k5, k6]:
      // OpenCV's order, which is rcm's.
      if (size != 8) {
        return reader.Error(at, field,
                            "expected 8 numbers (k1, k2, p1, p2, k3, k4, k5, "
                            "k6) for distortion_model '" +
                                model_name + "', got " + std::to_string(size));
      }
      return ros;
    case LensModelId::kDoubleSphere:
    case LensModelId::kEucm:
      break;  // No ROS name maps to them.
  }
  return reader.Error(at, field, "unhandled lens model");
}

StatusOr<CameraInfo> ParseCameraInfoNode(const YamlReader& reader,
                                         const YAML::Node& root) {
  const StatusOr<YamlEntries> entries = reader.RootEntries(
      root, "expected a ROS camera_info with image_width, camera_matrix, ...");
  if (!entries.ok()) return entries.status();
  const YamlEntry* width_entry = FindYamlEntry(*entries, "image_width");
  if (width_entry == nullptr) return reader.MissingKey("", "image_width");
  const StatusOr<int> width = reader.Integer(width_entry->value, "image_width");
  if (!width.ok()) return width.status();
  const YamlEntry* height_entry = FindYamlEntry(*entries, "image_height");
  if (height_entry == nullptr) return reader.MissingKey("", "image_height");
  const StatusOr<int> height =
      reader.Integer(height_entry->value, "image_height");
  if (!height.ok()) return height.status();

  std::string camera_name;
  if (const YamlEntry* entry = FindYamlEntry(*entries, "camera_name")) {
    const StatusOr<std::string> name =
        OptionalString(reader, entry->value, "camera_name");
    if (!name.ok()) return name.status();
    camera_name = *name;
  }

  const YamlEntry* k_entry = FindYamlEntry(*entries, "camera_matrix");
  if (k_entry == nullptr) return reader.MissingKey("", "camera_matrix");
  const StatusOr<RosMatrix> k_matrix =
      ReadRosMatrix(reader, k_entry->value, "camera_matrix", 3, 3);
  if (!k_matrix.ok()) return k_matrix.status();
  const std::vector<double>& k = k_matrix->data;
  const YAML::Node& k_data = k_matrix->data_node;
  const std::string k_field = "camera_matrix.data";
  if (k[1] != 0.0) {
    return reader.Error(
        k_data, k_field,
        "nonzero skew K[0][1] = " + FormatDouble(k[1]) + " is not supported");
  }
  for (int index : {3, 6, 7}) {
    if (k[index] != 0.0) {
      return reader.Error(k_data, k_field,
                          "expected [fx, 0, cx, 0, fy, cy, 0, 0, 1], but K[" +
                              std::to_string(index / 3) + "][" +
                              std::to_string(index % 3) +
                              "] = " + FormatDouble(k[index]));
    }
  }
  if (k[8] != 1.0) {
    return reader.Error(k_data, k_field,
                        "expected [fx, 0, cx, 0, fy, cy, 0, 0, 1], but K[2][2] "
                        "= " +
                            FormatDouble(k[8]));
  }

  std::string model_name = "plumb_bob";  // ROS's default when absent
  const YamlEntry* model_entry = FindYamlEntry(*entries, "distortion_model");
  if (model_entry != nullptr) {
    const StatusOr<std::string> name =
        OptionalString(reader, model_entry->value, "distortion_model");
    if (!name.ok()) return name.status();
    model_name = *name;
  }
  const std::optional<LensModelId> model = LensModelFromRosName(model_name);
  if (!model.has_value()) {
    return reader.Error(model_entry->value, "distortion_model",
                        "unknown model " + QuoteForMessage(model_name) +
                            " (supported: plumb_bob, radtan, equidistant, "
                            "rational_polynomial, none)");
  }
  std::vector<double> distortion;
  const YamlEntry* d_entry = FindYamlEntry(*entries, "distortion_coefficients");
  if (d_entry == nullptr) {
    if (*model != LensModelId::kPinhole) {
      return reader.MissingKey("", "distortion_coefficients");
    }
  } else {
    const StatusOr<RosMatrix> ros = ReadRosMatrix(
        reader, d_entry->value, "distortion_coefficients", 1, /*cols=*/-1);
    if (!ros.ok()) return ros.status();
    const StatusOr<std::vector<double>> converted = DistortionFromRos(
        reader, ros->data_node, *model, model_name, ros->data);
    if (!converted.ok()) return converted.status();
    distortion = *converted;
  }

  // Each of Camera::Create's checks, attributed to the key it is about.
  const std::array<double, 4> intrinsics = {k[0], k[4], k[2], k[5]};
  if (const Status status = Camera::CheckImageSize(*width, *height);
      !status.ok()) {
    const bool width_bad = *width <= 0;
    return reader.Error(width_bad ? width_entry->value : height_entry->value,
                        width_bad ? "image_width" : "image_height",
                        status.message());
  }
  if (const Status status = Camera::CheckIntrinsics(intrinsics); !status.ok()) {
    return reader.Error(k_data, k_field, status.message());
  }
  if (const Status status = Camera::CheckDistortion(*model, distortion);
      !status.ok()) {
    return reader.Error(d_entry != nullptr ? d_entry->value : root,
                        "distortion_coefficients", status.message());
  }
  // Cannot fail: Create runs exactly the three checks above.
  const Camera camera =
      Camera::Create(*model, *width, *height, intrinsics, distortion).value();

  Eigen::Matrix3d rectification = Eigen::Matrix3d::Identity();
  if (const YamlEntry* entry =
          FindYamlEntry(*entries, "rectification_matrix")) {
    const StatusOr<RosMatrix> r =
        ReadRosMatrix(reader, entry->value, "rectification_matrix", 3, 3);
    if (!r.ok()) return r.status();
    Eigen::Matrix4d homogeneous = Eigen::Matrix4d::Identity();
    for (int i = 0; i < 9; ++i) homogeneous(i / 3, i % 3) = r->data[i];
    const StatusOr<Rigid3d> rotation = Rigid3d::FromMatrix(homogeneous);
    if (!rotation.ok()) {
      return reader.Error(r->data_node, "rectification_matrix.data",
                          rotation.status().message());
    }
    rectification = homogeneous.topLeftCorner<3, 3>();
  }

  Eigen::Matrix<double, 3, 4> projection = Eigen::Matrix<double, 3, 4>::Zero();
  for (int i = 0; i < 9; ++i) projection(i / 3, i % 3) = k[i];
  if (const YamlEntry* entry = FindYamlEntry(*entries, "projection_matrix")) {
    const StatusOr<RosMatrix> p =
        ReadRosMatrix(reader, entry->value, "projection_matrix", 3, 4);
    if (!p.ok()) return p.status();
    for (int i = 0; i < 12; ++i) projection(i / 4, i % 4) = p->data[i];
  }

  return CameraInfo{camera_name, camera, rectification, projection};
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

// ---------------------------------------------------------------------------
// Writing: the layout of camera_calibration_parsers' writeCalibrationYml
// (yaml-cpp's emitter: block maps, each matrix's data a flow list).

// A string scalar as yaml-cpp's emitter writes it: plain when that reads
// back as the same string, quoted otherwise.
std::string YamlScalar(const std::string& text) {
  YAML::Emitter emitter;
  emitter << text;
  return emitter.c_str();
}

// "key:\n  rows: R\n  cols: C\n  data: [...]\n" for a row-major matrix.
std::string RosMatrixText(const std::string& key, int rows, int cols,
                          const double* row_major) {
  std::string text = key + ":\n  rows: " + std::to_string(rows) +
                     "\n  cols: " + std::to_string(cols) + "\n  data: [";
  for (int i = 0; i < rows * cols; ++i) {
    text += (i == 0 ? "" : ", ") + FormatDouble(row_major[i]);
  }
  return text + "]\n";
}

// K of `camera`, row-major.
std::array<double, 9> CameraMatrix(const Camera& camera) {
  return {camera.fx(), 0.0, camera.cx(), 0.0, camera.fy(),
          camera.cy(), 0.0, 0.0,         1.0};
}

}  // namespace

StatusOr<CameraInfo> ParseCameraInfo(const std::string& text,
                                     const std::string& source_name) {
  const YamlReader reader(source_name);
  return reader.ReadDocument(text, "the camera_info",
                             [&](const YAML::Node& root) {
                               return ParseCameraInfoNode(reader, root);
                             });
}

StatusOr<CameraInfo> ReadCameraInfo(const std::string& path) {
  const StatusOr<std::string> text = ReadFileToString(path);
  if (!text.ok()) return text.status();
  return ParseCameraInfo(*text, path);
}

CameraInfo CameraInfoFromCamera(const std::string& camera_name,
                                const Camera& camera) {
  Eigen::Matrix<double, 3, 4> projection = Eigen::Matrix<double, 3, 4>::Zero();
  const std::array<double, 9> k = CameraMatrix(camera);
  for (int i = 0; i < 9; ++i) projection(i / 3, i % 3) = k[i];
  return CameraInfo{camera_name, camera, Eigen::Matrix3d::Identity(),
                    projection};
}

Status CheckCameraInfoModel(const Camera& camera) {
  if (camera.model() == LensModelId::kDoubleSphere ||
      camera.model() == LensModelId::kEucm) {
    return Status::Error(
        "a camera_info cannot hold the lens model '" +
        std::string(LensModelName(camera.model())) +
        "' (ROS has plumb_bob, rational_polynomial, equidistant): write a "
        "Kalibr camchain instead");
  }
  return Status::Ok();
}

RosDistortion RosDistortionOf(const Camera& camera) {
  CHECK(CheckCameraInfoModel(camera).ok())
      << CheckCameraInfoModel(camera).message();
  switch (camera.model()) {
    case LensModelId::kRadTan: {
      // ROS's plumb_bob has a k3; rcm's radtan model holds it at 0.
      std::vector<double> coefficients = camera.Distortion();
      coefficients.push_back(0.0);
      return {"plumb_bob", coefficients};
    }
    case LensModelId::kEquidistant:
      return {"equidistant", camera.Distortion()};
    case LensModelId::kRational:
      return {"rational_polynomial", camera.Distortion()};
    case LensModelId::kDoubleSphere:
    case LensModelId::kEucm:
      break;  // Refused above.
    case LensModelId::kPinhole:
      // ROS tools treat plumb_bob with zero coefficients as undistorted;
      // some reject "none".
      return {"plumb_bob", std::vector<double>(5, 0.0)};
  }
  LOG(FATAL) << "unhandled lens model";
  return {};
}

std::string FormatCameraInfo(const CameraInfo& info) {
  const Camera& camera = info.camera;
  const RosDistortion distortion = RosDistortionOf(camera);
  const Eigen::Matrix<double, 3, 3, Eigen::RowMajor> r = info.rectification;
  const Eigen::Matrix<double, 3, 4, Eigen::RowMajor> p = info.projection;
  return "image_width: " + std::to_string(camera.width()) +
         "\nimage_height: " + std::to_string(camera.height()) +
         "\ncamera_name: " + YamlScalar(info.camera_name) + "\n" +
         RosMatrixText("camera_matrix", 3, 3, CameraMatrix(camera).data()) +
         "distortion_model: " + distortion.model + "\n" +
         RosMatrixText("distortion_coefficients", 1,
                       static_cast<int>(distortion.coefficients.size()),
                       distortion.coefficients.data()) +
         RosMatrixText("rectification_matrix", 3, 3, r.data()) +
         RosMatrixText("projection_matrix", 3, 4, p.data());
}

Status WriteCameraInfo(const std::string& path, const CameraInfo& info) {
  if (Status status = CheckCameraInfoModel(info.camera); !status.ok()) {
    return Status::Error(path + ": " + status.message());
  }
  return WriteFileAtomically(path, FormatCameraInfo(info));
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
