#include "rcm/io/calibration_covariance_file.h"

#include <cmath>
#include <filesystem>
#include <sstream>
#include <utility>

#include "rcm/io/atomic_file.h"
#include "rcm/io/camchain.h"
#include "rcm/io/yaml_fields.h"
#include "rcm/util/number_format.h"

namespace rcm {
namespace {

constexpr double kDegree = M_PI / 180.0;

// A square matrix written as a list of rows of numbers, `size` of them
// (or any size for size < 0), checked by CheckCovarianceMatrix.
StatusOr<Eigen::MatrixXd> ReadCovariance(const YamlReader& reader,
                                         const YAML::Node& node,
                                         const std::string& field, int size) {
  if (!node.IsSequence() || node.size() == 0) {
    return reader.Error(node, field,
                        "expected a square matrix (a list of rows), got " +
                            DescribeYamlNode(node));
  }
  const int rows = static_cast<int>(node.size());
  if (size >= 0 && rows != size) {
    return reader.Error(node, field,
                        "expected " + std::to_string(size) + " rows, got " +
                            std::to_string(rows));
  }
  Eigen::MatrixXd matrix(rows, rows);
  for (int r = 0; r < rows; ++r) {
    const StatusOr<std::vector<double>> row = reader.NumberList(
        node[r], field + " row " + std::to_string(r + 1), rows);
    if (!row.ok()) return row.status();
    for (int c = 0; c < rows; ++c) matrix(r, c) = (*row)[c];
  }
  const Status valid = CheckCovarianceMatrix(matrix, "the matrix");
  if (!valid.ok()) {
    // "the matrix is not symmetric" -> "is not symmetric".
    return reader.Error(node, field, valid.message().substr(11));
  }
  return matrix;
}

// A 6-row matrix of any (equal) row length: a cross-covariance.
// A cross-covariance of `rows` rows (of `what`), or of any number of rows
// when `rows` is 0.
StatusOr<Eigen::MatrixXd> ReadCrossCovariance(const YamlReader& reader,
                                              const YAML::Node& node,
                                              const std::string& field,
                                              int rows = 6,
                                              const char* what = "[w; dt]") {
  if (!node.IsSequence() || node.size() == 0 ||
      (rows > 0 && static_cast<int>(node.size()) != rows)) {
    return reader.Error(
        node, field,
        "expected " +
            (rows > 0 ? std::to_string(rows) + " rows" : std::string("rows")) +
            " (of " + what + "), got " + DescribeYamlNode(node));
  }
  rows = static_cast<int>(node.size());
  Eigen::MatrixXd matrix;
  for (int r = 0; r < rows; ++r) {
    const std::string row_field = field + " row " + std::to_string(r + 1);
    const StatusOr<std::vector<double>> row =
        r == 0 ? reader.NumberList(node[r], row_field)
               : reader.NumberList(node[r], row_field,
                                   static_cast<int>(matrix.cols()));
    if (!row.ok()) return row.status();
    if (r == 0) {
      if (row->empty()) return reader.Error(node[r], row_field, "is empty");
      matrix.resize(rows, static_cast<Eigen::Index>(row->size()));
    }
    for (size_t c = 0; c < row->size(); ++c) matrix(r, c) = (*row)[c];
  }
  if (!matrix.allFinite()) return reader.Error(node, field, "is not finite");
  return matrix;
}

// The `ports` block of a file whose cameras are read: its matrices, checked
// with cam0's and cam1's blocks as one joint covariance.
Status ReadPorts(const YamlReader& reader, const YamlEntry& ports,
                 CalibrationCovarianceFile* file) {
  const StatusOr<YamlEntries> fields = reader.Entries(ports.value, "ports");
  if (!fields.ok()) return fields.status();
  const YAML::Node* cross_node = nullptr;
  for (const auto& [key, entry] : *fields) {
    const std::string field = "ports." + key;
    if (key == "covariance") {
      StatusOr<Eigen::MatrixXd> matrix = ReadCovariance(
          reader, entry.value, field, CalibrationUncertainty::kNumPortParams);
      if (!matrix.ok()) return matrix.status();
      file->port_covariance = std::move(matrix).value();
    } else if (key == "cross_covariance") {
      StatusOr<Eigen::MatrixXd> matrix =
          ReadCrossCovariance(reader, entry.value, field, 0,
                              "[w; dt] and the intrinsics, against q");
      if (!matrix.ok()) return matrix.status();
      file->port_cross_covariance = std::move(matrix).value();
      cross_node = &entry.value;
    } else {
      return reader.Error(entry.key, field,
                          "unknown key (expected covariance, "
                          "cross_covariance)");
    }
  }
  if (file->port_covariance.size() == 0) {
    return reader.Error(ports.key, "ports", "needs covariance");
  }
  if (file->cameras.size() < 2) {
    return reader.Error(ports.key, "ports", "needs cam0 and cam1");
  }
  CalibrationUncertainty joint;
  const CalibrationCovarianceFile::Camera& cam1 = file->cameras[1];
  joint.extrinsics_covariance = cam1.from_previous_covariance.value_or(
      Eigen::Matrix<double, 6, 6>::Zero());
  joint.left_lens_covariance = file->cameras[0].intrinsics_covariance;
  joint.right_lens_covariance = cam1.intrinsics_covariance;
  joint.extrinsics_lens_covariance = cam1.from_previous_intrinsics_covariance;
  joint.lens_cross_covariance = cam1.previous_intrinsics_covariance;
  joint.port_covariance = file->port_covariance;
  joint.port_cross_covariance = file->port_cross_covariance;
  const Status valid =
      joint.Check(static_cast<int>(joint.left_lens_covariance.rows()),
                  static_cast<int>(joint.right_lens_covariance.rows()));
  if (!valid.ok()) {
    return cross_node != nullptr
               ? reader.Error(*cross_node, "ports.cross_covariance",
                              valid.message())
               : reader.Error(ports.value, "ports", valid.message());
  }
  return Status::Ok();
}

StatusOr<CalibrationCovarianceFile> ReadDocument(const YamlReader& reader,
                                                 const YAML::Node& root) {
  const StatusOr<YamlEntries> entries =
      reader.RootEntries(root, "expected medium, drift_prior, cam0, ...");
  if (!entries.ok()) return entries.status();
  CalibrationCovarianceFile file;
  const YamlEntry* medium = FindYamlEntry(*entries, "medium");
  if (medium == nullptr) return reader.MissingKey("", "medium");
  const StatusOr<std::string> medium_name =
      reader.String(medium->value, "medium");
  if (!medium_name.ok()) return medium_name.status();
  if (*medium_name != "air" && *medium_name != "water") {
    return reader.Error(medium->value, "medium",
                        "expected air or water, got '" + *medium_name + "'");
  }
  file.medium = *medium_name;

  int num_cameras = 0;
  for (const auto& [key, entry] : *entries) {
    if (key == "medium" || key == "drift_prior" || key == "ports") continue;
    const std::optional<int> index = CamchainCameraIndex(key);
    if (!index) {
      return reader.Error(entry.key, key,
                          "unknown key (expected medium, drift_prior, cam0, "
                          "cam1, ..., ports)");
    }
    num_cameras = std::max(num_cameras, *index + 1);
  }
  // An older file without focal_percent: the default of its medium.
  file.drift_focal_sigma =
      file.medium == "air"
          ? 1e-2 * CalibrationUncertainty::kDefaultFocalDriftPercent
          : 0.0;
  if (const YamlEntry* drift = FindYamlEntry(*entries, "drift_prior")) {
    const StatusOr<YamlEntries> fields =
        reader.Entries(drift->value, "drift_prior");
    if (!fields.ok()) return fields.status();
    for (const auto& [key, entry] : *fields) {
      if (key != "rotation_deg" && key != "translation_mm" &&
          key != "focal_percent") {
        return reader.Error(entry.key, "drift_prior." + key,
                            "unknown key (expected rotation_deg, "
                            "translation_mm, focal_percent)");
      }
      const StatusOr<double> value =
          reader.Number(entry.value, "drift_prior." + key);
      if (!value.ok()) return value.status();
      if (*value < 0.0) {
        return reader.Error(entry.value, "drift_prior." + key, "must be >= 0");
      }
      if (key == "rotation_deg") {
        file.drift_rotation_sigma = *value * kDegree;
      } else if (key == "focal_percent") {
        file.drift_focal_sigma = 1e-2 * *value;
      } else {
        file.drift_translation_sigma = 1e-3 * *value;
      }
    }
  }
  file.cameras.resize(num_cameras);
  std::vector<YAML::Node> cross_nodes(num_cameras);
  std::vector<YAML::Node> lens_cross_nodes(num_cameras);
  for (int k = 0; k < num_cameras; ++k) {
    const std::string name = "cam" + std::to_string(k);
    const YamlEntry* camera = FindYamlEntry(*entries, name);
    if (camera == nullptr) {
      return reader.Error(name,
                          "missing (cameras must be cam0, cam1, ... "
                          "without gaps)");
    }
    const StatusOr<YamlEntries> fields = reader.Entries(camera->value, name);
    if (!fields.ok()) return fields.status();
    for (const auto& [key, entry] : *fields) {
      const std::string field = name + "." + key;
      if (key == "intrinsics_covariance") {
        StatusOr<Eigen::MatrixXd> matrix =
            ReadCovariance(reader, entry.value, field, -1);
        if (!matrix.ok()) return matrix.status();
        file.cameras[k].intrinsics_covariance = std::move(matrix).value();
      } else if (key == "T_cn_cnm1_covariance" && k > 0) {
        const StatusOr<Eigen::MatrixXd> matrix =
            ReadCovariance(reader, entry.value, field, 6);
        if (!matrix.ok()) return matrix.status();
        file.cameras[k].from_previous_covariance = *matrix;
      } else if (key == "T_cn_cnm1_intrinsics_covariance" && k > 0) {
        StatusOr<Eigen::MatrixXd> matrix =
            ReadCrossCovariance(reader, entry.value, field);
        if (!matrix.ok()) return matrix.status();
        file.cameras[k].from_previous_intrinsics_covariance =
            std::move(matrix).value();
        cross_nodes[k] = entry.value;
      } else if (key == "intrinsics_cross_covariance" && k > 0) {
        StatusOr<Eigen::MatrixXd> matrix = ReadCrossCovariance(
            reader, entry.value, field, 0, "cam(n-1)'s intrinsics");
        if (!matrix.ok()) return matrix.status();
        file.cameras[k].previous_intrinsics_covariance =
            std::move(matrix).value();
        lens_cross_nodes[k] = entry.value;
      } else {
        return reader.Error(entry.key, field,
                            k == 0 ? "unknown key (cam0 has "
                                     "intrinsics_covariance)"
                                   : "unknown key (expected "
                                     "intrinsics_covariance, "
                                     "T_cn_cnm1_covariance, "
                                     "T_cn_cnm1_intrinsics_covariance, "
                                     "intrinsics_cross_covariance)");
      }
    }
  }
  // The cross-covariances against the blocks they join.
  for (int k = 1; k < num_cameras; ++k) {
    const CalibrationCovarianceFile::Camera& camera = file.cameras[k];
    const bool extrinsics_cross =
        camera.from_previous_intrinsics_covariance.size() > 0;
    if (!extrinsics_cross &&
        camera.previous_intrinsics_covariance.size() == 0) {
      continue;
    }
    const std::string field =
        "cam" + std::to_string(k) +
        (extrinsics_cross ? ".T_cn_cnm1_intrinsics_covariance"
                          : ".intrinsics_cross_covariance");
    const YAML::Node& node =
        extrinsics_cross ? cross_nodes[k] : lens_cross_nodes[k];
    const Eigen::MatrixXd& previous = file.cameras[k - 1].intrinsics_covariance;
    if ((extrinsics_cross && !camera.from_previous_covariance) ||
        previous.size() == 0 || camera.intrinsics_covariance.size() == 0) {
      return reader.Error(node, field,
                          extrinsics_cross
                              ? "needs T_cn_cnm1_covariance and both cameras' "
                                "intrinsics_covariance"
                              : "needs both cameras' intrinsics_covariance");
    }
    CalibrationUncertainty joint;
    joint.extrinsics_covariance = camera.from_previous_covariance.value_or(
        Eigen::Matrix<double, 6, 6>::Zero());
    joint.left_lens_covariance = previous;
    joint.right_lens_covariance = camera.intrinsics_covariance;
    joint.extrinsics_lens_covariance =
        camera.from_previous_intrinsics_covariance;
    joint.lens_cross_covariance = camera.previous_intrinsics_covariance;
    const Status valid =
        joint.Check(static_cast<int>(previous.rows()),
                    static_cast<int>(camera.intrinsics_covariance.rows()));
    if (!valid.ok()) return reader.Error(node, field, valid.message());
  }
  if (const YamlEntry* ports = FindYamlEntry(*entries, "ports")) {
    RCM_RETURN_IF_ERROR(ReadPorts(reader, *ports, &file));
  }
  return file;
}

void AppendRows(const Eigen::MatrixXd& matrix, std::ostringstream* out) {
  for (int r = 0; r < matrix.rows(); ++r) {
    *out << "    - [";
    for (int c = 0; c < matrix.cols(); ++c) {
      *out << (c ? ", " : "") << FormatDouble(matrix(r, c));
    }
    *out << "]\n";
  }
}

// The rows of (M + M^T) / 2: a covariance computed as J C J^T is
// symmetric only to rounding, and the file should be exactly.
void AppendMatrix(const Eigen::MatrixXd& given, std::ostringstream* out) {
  AppendRows(0.5 * (given + given.transpose()), out);
}

}  // namespace

std::string CovarianceSidecarPath(const std::string& camchain_path) {
  const std::filesystem::path path(camchain_path);
  return (path.parent_path() / (path.stem().string() + "-covariance.yaml"))
      .string();
}

StatusOr<CalibrationCovarianceFile> ParseCalibrationCovariance(
    const std::string& text, const std::string& source_name) {
  const YamlReader reader(source_name);
  return reader.ReadDocument(
      text, "the calibration covariance",
      [&](const YAML::Node& root) { return ReadDocument(reader, root); });
}

StatusOr<CalibrationCovarianceFile> ReadCalibrationCovariance(
    const std::string& path) {
  const StatusOr<std::string> text = ReadFileToString(path);
  if (!text.ok()) return text.status();
  return ParseCalibrationCovariance(*text, path);
}

std::string FormatCalibrationCovariance(const CalibrationCovarianceFile& file) {
  std::ostringstream out;
  out << "# rcm: covariance of the calibration in the camchain next to this "
         "file\n"
      << "# intrinsics_covariance: of [fx, fy, cx, cy, d...]; "
         "T_cn_cnm1_covariance: of [w; dt],\n"
      << "# T_cn_cnm1 = (exp([w]x) R, exp([w]x) t + dt), w radians, dt "
         "meters, camn frame\n";
  bool cross = false;
  for (const CalibrationCovarianceFile::Camera& camera : file.cameras) {
    cross |= camera.from_previous_intrinsics_covariance.size() > 0;
  }
  bool lens_cross = false;
  for (const CalibrationCovarianceFile::Camera& camera : file.cameras) {
    lens_cross |= camera.previous_intrinsics_covariance.size() > 0;
  }
  if (cross) {
    out << "# T_cn_cnm1_intrinsics_covariance: of [w; dt] (rows) with the "
           "intrinsics of cam(n-1), then camn (columns)\n";
  }
  if (lens_cross) {
    out << "# intrinsics_cross_covariance: of the intrinsics of cam(n-1) "
           "(rows) with camn's (columns)\n";
  }
  if (file.port_covariance.size() > 0) {
    out << "# ports: of q = [d0, a0, b0, d1, a1, b1], air gap d (m) and tilt "
           "(a, b) = (N_x, N_y) / N_z\n# of cam0's and cam1's ports; "
           "cross_covariance: of [w; dt; cam0's intrinsics; cam1's] with q\n";
  }
  out << "medium: " << file.medium << "\n";
  out << "drift_prior:\n"
      << "  rotation_deg: " << FormatDouble(file.drift_rotation_sigma / kDegree)
      << "\n"
      << "  translation_mm: "
      << FormatDouble(1e3 * file.drift_translation_sigma) << "\n"
      << "  focal_percent: " << FormatDouble(1e2 * file.drift_focal_sigma)
      << "\n";
  for (size_t k = 0; k < file.cameras.size(); ++k) {
    const CalibrationCovarianceFile::Camera& camera = file.cameras[k];
    out << "cam" << k << ":";
    if (camera.intrinsics_covariance.size() == 0 &&
        !camera.from_previous_covariance) {
      out << " {}\n";
      continue;
    }
    out << "\n";
    if (camera.intrinsics_covariance.size() > 0) {
      out << "  intrinsics_covariance:\n";
      AppendMatrix(camera.intrinsics_covariance, &out);
    }
    if (camera.from_previous_covariance && k > 0) {
      out << "  T_cn_cnm1_covariance:\n";
      AppendMatrix(*camera.from_previous_covariance, &out);
    }
    if (camera.from_previous_intrinsics_covariance.size() > 0 && k > 0) {
      out << "  T_cn_cnm1_intrinsics_covariance:\n";
      AppendRows(camera.from_previous_intrinsics_covariance, &out);
    }
    if (camera.previous_intrinsics_covariance.size() > 0 && k > 0) {
      out << "  intrinsics_cross_covariance:\n";
      AppendRows(camera.previous_intrinsics_covariance, &out);
    }
  }
  if (file.port_covariance.size() > 0) {
    out << "ports:\n  covariance:\n";
    AppendMatrix(file.port_covariance, &out);
    if (file.port_cross_covariance.size() > 0) {
      out << "  cross_covariance:\n";
      AppendRows(file.port_cross_covariance, &out);
    }
  }
  return out.str();
}

Status WriteCalibrationCovariance(const std::string& path,
                                  const CalibrationCovarianceFile& file) {
  return WriteFileAtomically(path, FormatCalibrationCovariance(file));
}

StatusOr<CalibrationUncertainty> PairCalibrationUncertainty(
    const CalibrationCovarianceFile& file, int left_index, int right_index,
    const std::string& source, const Eigen::VectorXd& left_params,
    const Eigen::VectorXd& right_params,
    std::optional<std::pair<double, double>> drift_override,
    std::optional<double> focal_override) {
  const int num_cameras = static_cast<int>(file.cameras.size());
  for (const int index : {left_index, right_index}) {
    if (index < 0 || index >= num_cameras) {
      return Status::Error(source + ": has no cam" + std::to_string(index));
    }
  }
  CalibrationUncertainty uncertainty;
  uncertainty.left_lens_covariance =
      file.cameras[left_index].intrinsics_covariance;
  uncertainty.right_lens_covariance =
      file.cameras[right_index].intrinsics_covariance;
  if (right_index == left_index + 1 &&
      file.cameras[right_index].from_previous_covariance) {
    uncertainty.extrinsics_covariance =
        *file.cameras[right_index].from_previous_covariance;
    uncertainty.extrinsics_lens_covariance =
        file.cameras[right_index].from_previous_intrinsics_covariance;
  }
  if (right_index == left_index + 1) {
    uncertainty.lens_cross_covariance =
        file.cameras[right_index].previous_intrinsics_covariance;
  }
  if (left_index == 0 && right_index == 1) {
    uncertainty.port_covariance = file.port_covariance;
    uncertainty.port_cross_covariance = file.port_cross_covariance;
  }
  const auto [rotation, translation] =
      drift_override.value_or(std::pair<double, double>{
          file.drift_rotation_sigma, file.drift_translation_sigma});
  uncertainty.AddDrift(rotation, translation);
  uncertainty.source =
      source + " (" + file.medium + " calibration) + " +
      CalibrationUncertainty::DescribeDriftPrior(rotation, translation);
  const double focal = focal_override.value_or(file.drift_focal_sigma);
  if (focal > 0.0) {
    // The file's lens covariance and the camera must agree in size (the
    // rig's check tells it otherwise; the prior is added first).
    for (const auto& [index, params] :
         {std::pair<int, const Eigen::VectorXd*>{left_index, &left_params},
          {right_index, &right_params}}) {
      const Eigen::MatrixXd& lens = file.cameras[index].intrinsics_covariance;
      if (lens.size() > 0 && lens.rows() != params->size()) {
        return Status::Error(source + ": cam" + std::to_string(index) +
                             ": intrinsics_covariance has " +
                             std::to_string(lens.rows()) +
                             " rows, the camera has " +
                             std::to_string(params->size()) + " parameters");
      }
    }
    uncertainty.AddFocalDrift(focal, left_params, right_params);
  }
  return uncertainty;
}

}  // namespace rcm
