#include "rcm/io/stereo_rig_file.h"

#include <filesystem>
#include <optional>
#include <utility>

#include "rcm/io/atomic_file.h"
#include "rcm/io/calibration_covariance_file.h"
#include "rcm/io/camchain.h"
#include "rcm/io/camera_file.h"
#include "rcm/io/camera_info.h"
#include "rcm/io/yaml_fields.h"

namespace rcm {
namespace {

// Reads a file and recognises its format.
struct RigFile {
  std::string text;
  CalibrationFileFormat format;
};
StatusOr<RigFile> ReadRigFile(const std::string& path) {
  StatusOr<std::string> text = ReadFileToString(path);
  if (!text.ok()) return text.status();
  const StatusOr<CalibrationFileFormat> format =
      DetectCalibrationFileFormat(path, *text);
  if (!format.ok()) return format.status();
  return RigFile{std::move(text).value(), *format};
}

// A camera's Camera::params() as a vector.
Eigen::VectorXd ParamsOf(const Camera& camera) {
  return Eigen::Map<const Eigen::VectorXd>(camera.params(),
                                           camera.num_params());
}

StatusOr<StereoRig> WithUncertainty(const StereoRig& rig,
                                    CalibrationUncertainty uncertainty,
                                    const std::string& source) {
  StatusOr<StereoRig> with =
      rig.WithCalibrationUncertainty(std::move(uncertainty));
  if (!with.ok()) return with.status().WithContext(source);
  return with;
}

StatusOr<StereoRig> ReadCamchainRig(const std::string& path,
                                    const std::string& text,
                                    const std::string& left,
                                    const std::string& right,
                                    const RigFileOptions& options) {
  const StatusOr<Camchain> camchain = ParseCamchain(text, path);
  if (!camchain.ok()) return camchain.status();
  if (camchain->cameras.size() == 1) {
    // A one-camera calibration (rcm calibrate --left alone).
    return Status::Error(path +
                         " has one camera (cam0); a stereo rig needs two: "
                         "calibrate the pair with --left and --right");
  }
  int indices[2];
  const std::string* names[2] = {&left, &right};
  for (int i = 0; i < 2; ++i) {
    const StatusOr<int> index = FindCamchainCamera(*camchain, *names[i]);
    if (!index.ok()) return index.status().WithContext(path);
    indices[i] = *index;
  }
  Camchain lenses = *camchain;
  if (options.domes_allowed) {
    for (CamchainCamera& camera : lenses.cameras) camera.dome.reset();
  }
  const StatusOr<StereoRig> rig =
      StereoRigFromCamchain(lenses, indices[0], indices[1]);
  if (!rig.ok()) return rig.status().WithContext(path);

  const std::string sidecar = CovarianceSidecarPath(path);
  std::error_code error;
  if (!std::filesystem::exists(sidecar, error)) {
    StatusOr<StereoRig> with = WithDefaultCalibrationUncertainty(*rig, options);
    if (!with.ok()) return with.status().WithContext(path);
    return with;
  }
  const StatusOr<CalibrationCovarianceFile> covariance =
      ReadCalibrationCovariance(sidecar);
  if (!covariance.ok()) return covariance.status();
  if (covariance->cameras.size() != camchain->cameras.size()) {
    return Status::Error(sidecar + ": has " +
                         std::to_string(covariance->cameras.size()) +
                         " cameras, " + path + " has " +
                         std::to_string(camchain->cameras.size()));
  }
  StatusOr<CalibrationUncertainty> uncertainty = PairCalibrationUncertainty(
      *covariance, indices[0], indices[1], sidecar, ParamsOf(rig->left()),
      ParamsOf(rig->right()), options.drift_prior, options.focal_drift);
  if (!uncertainty.ok()) return uncertainty.status();
  return WithUncertainty(*rig, std::move(uncertainty).value(), sidecar);
}

// True when `text` parses as YAML and holds a document.
bool IsYamlDocument(const std::string& path, const std::string& text) {
  const StatusOr<YAML::Node> root = YamlReader(path).Load(text);
  return root.ok() && !root->IsNull();
}

StatusOr<StereoRig> ReadCameraInfoPair(const std::string& left_path,
                                       const std::string& right_path) {
  const std::string paths[2] = {left_path, right_path};
  std::optional<CameraInfo> infos[2];
  for (int i = 0; i < 2; ++i) {
    const StatusOr<RigFile> file = ReadRigFile(paths[i]);
    if (!file.ok()) return file.status();
    // Empty text and YAML syntax errors detect as a camchain (so that a
    // lone file's problem is told by the camchain parser); in a pair the
    // camera_info parser tells it.
    if (file->format != CalibrationFileFormat::kCameraInfo &&
        IsYamlDocument(paths[i], file->text)) {
      return Status::Error(paths[i] +
                           ": is a Kalibr camchain, expected a ROS "
                           "camera_info (give a camchain alone, not in a "
                           "comma-separated pair)");
    }
    StatusOr<CameraInfo> info = ParseCameraInfo(file->text, paths[i]);
    if (!info.ok()) return info.status();
    infos[i] = std::move(info).value();
  }
  const StatusOr<StereoRig> rig = StereoRigFromCameraInfo(*infos[0], *infos[1]);
  if (!rig.ok()) {
    return rig.status().WithContext(left_path + "," + right_path);
  }
  return rig;
}

}  // namespace

StatusOr<StereoRig> WithDefaultCalibrationUncertainty(
    const StereoRig& rig, const RigFileOptions& options) {
  CalibrationUncertainty uncertainty =
      options.drift_prior
          ? CalibrationUncertainty::DriftPrior(options.drift_prior->first,
                                               options.drift_prior->second)
          : CalibrationUncertainty::DefaultDriftPrior();
  uncertainty.AddFocalDrift(
      options.focal_drift.value_or(
          1e-2 * CalibrationUncertainty::kDefaultFocalDriftPercent),
      ParamsOf(rig.left()), ParamsOf(rig.right()));
  return rig.WithCalibrationUncertainty(std::move(uncertainty));
}

StatusOr<StereoRig> ReadStereoRig(const std::string& spec,
                                  const std::string& left,
                                  const std::string& right,
                                  const RigFileOptions& options) {
  const size_t comma = spec.find(',');
  if (comma != std::string::npos) {
    const std::string left_path = spec.substr(0, comma);
    const std::string right_path = spec.substr(comma + 1);
    if (left_path.empty() || right_path.empty() ||
        right_path.find(',') != std::string::npos) {
      return Status::Error("'" + spec +
                           "': expected one camchain path or two camera_info "
                           "paths 'left.yaml,right.yaml'");
    }
    if (left != "cam0" || right != "cam1") {
      return Status::Error(
          "camera names ('" + left + "', '" + right +
          "') select cameras of a Kalibr camchain; with two ROS camera_info "
          "files '" +
          spec + "' the first is the left camera and the second the right");
    }
    const StatusOr<StereoRig> rig = ReadCameraInfoPair(left_path, right_path);
    if (!rig.ok()) return rig.status();
    StatusOr<StereoRig> with = WithDefaultCalibrationUncertainty(*rig, options);
    if (!with.ok()) return with.status().WithContext(spec);
    return with;
  }

  const StatusOr<RigFile> file = ReadRigFile(spec);
  if (!file.ok()) return file.status();
  if (file->format == CalibrationFileFormat::kCameraInfo) {
    return Status::Error(spec +
                         ": is a ROS camera_info, which describes one camera; "
                         "give the left and right files as "
                         "'left.yaml,right.yaml'");
  }
  return ReadCamchainRig(spec, file->text, left, right, options);
}

StatusOr<std::optional<std::array<DomePort, 2>>> ReadStereoRigDomes(
    const std::string& spec, const std::string& left,
    const std::string& right) {
  using Domes = std::optional<std::array<DomePort, 2>>;
  if (spec.find(',') != std::string::npos) return Domes();
  const StatusOr<RigFile> file = ReadRigFile(spec);
  if (!file.ok()) return file.status();
  if (file->format == CalibrationFileFormat::kCameraInfo) return Domes();
  const StatusOr<Camchain> camchain = ParseCamchain(file->text, spec);
  if (!camchain.ok()) return camchain.status();
  const std::string* names[2] = {&left, &right};
  std::optional<DomePort> domes[2];
  for (int i = 0; i < 2; ++i) {
    const StatusOr<int> index = FindCamchainCamera(*camchain, *names[i]);
    if (!index.ok()) return index.status().WithContext(spec);
    domes[i] = camchain->cameras[*index].dome;
  }
  if (!domes[0] && !domes[1]) return Domes();
  if (!domes[0] || !domes[1]) {
    const int with = domes[0] ? 0 : 1;
    return Status::Error(spec + ": " + *names[1 - with] +
                         " has no dome port block, " + *names[with] +
                         " has one: give both cameras one");
  }
  return Domes(std::array<DomePort, 2>{*domes[0], *domes[1]});
}

}  // namespace rcm
