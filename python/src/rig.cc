// rcm.StereoRig, rcm.read_stereo_rig, StereoRig.write and the reference
// rigs of the simulator.
#include <pybind11/stl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <sstream>

#include "bindings.h"
#include "conversions.h"
#include "errors.h"
#include "rcm/io/camchain.h"
#include "rcm/io/stereo_rig_file.h"
#include "rcm/sim/reference_rigs.h"
#include "rcm/stereo/stereo_rig.h"

namespace rcm::python {
namespace {

bool Readable(const std::string& path) {
  struct stat info {};
  return ::stat(path.c_str(), &info) == 0 && !S_ISDIR(info.st_mode) &&
         ::access(path.c_str(), R_OK) == 0;
}

StereoRig ReadRig(const py::object& path, const py::object& right_info,
                  const std::string& left_camera,
                  const std::string& right_camera,
                  const std::optional<std::pair<double, double>>& drift_prior,
                  const std::optional<double>& focal_drift) {
  std::vector<std::string> paths = {PathFromPython(path)};
  if (!right_info.is_none()) paths.push_back(PathFromPython(right_info));
  for (const std::string& file : paths) {
    if (file.find(',') != std::string::npos) {
      ThrowValueError("'" + file +
                      "': a path with a comma; give two camera_info files as "
                      "two arguments");
    }
  }
  RigFileOptions options;
  if (drift_prior) {
    const auto [rotation, translation] = *drift_prior;
    if (!std::isfinite(rotation) || !std::isfinite(translation) ||
        rotation < 0.0 || translation < 0.0) {
      ThrowValueError(
          "drift_prior must be (rotation sigma in radians, translation sigma "
          "in meters), both finite and >= 0");
    }
    options.drift_prior = drift_prior;
  }
  if (focal_drift) {
    if (!std::isfinite(*focal_drift) || *focal_drift < 0.0) {
      ThrowValueError("focal_drift must be a relative sigma, finite and >= 0");
    }
    options.focal_drift = focal_drift;
  }
  const std::string spec =
      paths.size() == 1 ? paths[0] : paths[0] + "," + paths[1];
  StatusOr<StereoRig> rig = Status::Error("not read");
  {
    py::gil_scoped_release release;
    rig = ReadStereoRig(spec, left_camera, right_camera, options);
  }
  if (!rig.ok()) {
    for (const std::string& file : paths) {
      if (!Readable(file)) ThrowReadError(file, rig.status().message());
    }
    ThrowValueError(rig.status().message());
  }
  return std::move(rig).value();
}

void WriteRig(const StereoRig& rig, const py::object& path) {
  const std::string file = PathFromPython(path);
  const Status status = WriteCamchain(file, CamchainFromStereoRig(rig));
  if (!status.ok()) ThrowWriteError(status.message());
}

RigCamera CameraOf(const StereoRig& rig, int index) {
  if (index != 0 && index != 1) {
    ThrowValueError(
        "camera index must be 0 (left, cam0) or 1 (right, cam1), got " +
        std::to_string(index));
  }
  const bool left = index == 0;
  RigCamera camera{left ? rig.left() : rig.right(), FlatPort()};
  if (rig.ports()) camera.port = left ? rig.ports()->left : rig.ports()->right;
  return camera;
}

py::object UncertaintyDict(const StereoRig& rig) {
  if (!rig.calibration_uncertainty()) return py::none();
  const CalibrationUncertainty& u = *rig.calibration_uncertainty();
  py::dict result;
  result["source"] = u.source;
  result["extrinsics_covariance"] = ToNumpy(u.extrinsics_covariance);
  result["left_lens_covariance"] = ToNumpy(u.left_lens_covariance);
  result["right_lens_covariance"] = ToNumpy(u.right_lens_covariance);
  result["extrinsics_lens_covariance"] = ToNumpy(u.extrinsics_lens_covariance);
  result["lens_cross_covariance"] = ToNumpy(u.lens_cross_covariance);
  result["port_covariance"] = ToNumpy(u.port_covariance);
  result["port_cross_covariance"] = ToNumpy(u.port_cross_covariance);
  return std::move(result);
}

std::string RigRepr(const StereoRig& rig) {
  std::ostringstream text;
  text.precision(6);
  text << "StereoRig(baseline=" << rig.Baseline() << " m, rotation="
       << rig.right_from_left().RotationAngle() * 180.0 / M_PI << " deg, "
       << (rig.HasThickPort() ? "thick" : "thin")
       << " port, left=" << LensModelName(rig.left().model()) << " "
       << rig.left().width() << "x" << rig.left().height()
       << ", right=" << LensModelName(rig.right().model()) << " "
       << rig.right().width() << "x" << rig.right().height() << ")";
  return text.str();
}

StereoRig ReferenceRig(const std::string& name) {
  if (name == "alphasense-rectified") return AlphasenseFrontRectifiedRig();
  if (name == "alphasense-unrectified") return AlphasenseFrontUnrectifiedRig();
  if (name == "narrow-field") return NarrowFieldRig();
  ThrowValueError("unknown reference rig '" + name +
                  "' (available: alphasense-rectified, alphasense-unrectified, "
                  "narrow-field; a rig file is read with rcm.read_stereo_rig)");
}

}  // namespace

StereoRig RigFromPython(const py::handle& object) {
  if (py::isinstance<py::str>(object)) {
    return ReferenceRig(object.cast<std::string>());
  }
  if (!py::isinstance<StereoRig>(object)) {
    ThrowTypeError(
        "rig must be an rcm.StereoRig or a reference rig name, got " +
        py::str(py::type::of(object)).cast<std::string>());
  }
  return object.cast<StereoRig>();
}

void BindRig(py::module_& module) {
  py::class_<StereoRig>(module, "StereoRig", R"doc(
The two in-air calibrated cameras of a stereo pair, the transform between
them, their flat ports and how well the calibration is known.

StereoRig(left, right, cam1_from_cam0)

left, right: rcm.Camera; cam1_from_cam0: 4x4 homogeneous transform [R t; 0 0
0 1] mapping points in the left camera (cam0) frame into the right camera
(cam1) frame, t in meters. The left camera is the reference frame. A rig
made in code has no calibration uncertainty (the estimators take it as
exact); one read from a file carries the default drift prior (0.1 degree,
0.1 mm per axis) or its covariance sidecar.
)doc")
      .def(py::init([](const Camera& left, const Camera& right,
                       const py::object& cam1_from_cam0) {
             const Rigid3d pose = ValueOrThrow(Rigid3d::FromMatrix(
                 Matrix4FromPython(cam1_from_cam0, "cam1_from_cam0")));
             return ValueOrThrow(StereoRig::Create(left, right, pose));
           }),
           py::arg("left"), py::arg("right"), py::arg("cam1_from_cam0"))
      .def("camera", &CameraOf, py::arg("index"),
           "The camera `index` (0: left/cam0, 1: right/cam1) behind its port, "
           "an rcm.RigCamera.")
      .def_property_readonly(
          "cam0", [](const StereoRig& r) { return CameraOf(r, 0); },
          "The left camera (rcm.RigCamera).")
      .def_property_readonly(
          "cam1", [](const StereoRig& r) { return CameraOf(r, 1); },
          "The right camera (rcm.RigCamera).")
      .def_property_readonly(
          "left", [](const StereoRig& r) { return CameraOf(r, 0); },
          "Same as cam0.")
      .def_property_readonly(
          "right", [](const StereoRig& r) { return CameraOf(r, 1); },
          "Same as cam1.")
      .def_property_readonly(
          "cam1_from_cam0",
          [](const StereoRig& r) {
            return ToNumpy(r.right_from_left().ToMatrix());
          },
          "4x4 transform mapping cam0 (left) points into cam1 (right); "
          "meters.")
      .def_property_readonly(
          "rotation",
          [](const StereoRig& r) {
            return ToNumpy(r.right_from_left().rotation);
          },
          "3x3 rotation of cam1_from_cam0.")
      .def_property_readonly(
          "translation",
          [](const StereoRig& r) {
            return ToNumpy(r.right_from_left().translation);
          },
          "Translation of cam1_from_cam0, meters (cam0's origin in cam1).")
      .def_property_readonly("baseline", &StereoRig::Baseline,
                             "|translation|, meters.")
      .def_property_readonly(
          "ports",
          [](const StereoRig& r) -> py::object {
            if (!r.ports()) return py::none();
            return py::make_tuple(r.ports()->left, r.ports()->right);
          },
          "(left FlatPort, right FlatPort) from the rig file's port blocks, "
          "or None (the paper's thin ports).")
      .def_property_readonly("has_thick_port", &StereoRig::HasThickPort,
                             "True when a port has an air gap, glass or a "
                             "tilted normal (the estimators then use the "
                             "thick-port model).")
      .def_property_readonly(
          "deviation_from_rectified",
          [](const StereoRig& r) {
            const StereoRig::RectificationDeviation d =
                r.DeviationFromRectified();
            return py::make_tuple(d.rotation, d.baseline_off_axis);
          },
          "(rotation angle, baseline angle off the x axis), radians: how far "
          "the rig is from the ideal rectified pair the closed form assumes.")
      .def_property_readonly("calibration_uncertainty", &UncertaintyDict,
                             "dict(source, extrinsics_covariance (6x6, [w; dt] "
                             "in rad and m), left_lens_covariance, "
                             "right_lens_covariance, "
                             "extrinsics_lens_covariance (6 x (p_l + p_r), "
                             "empty when uncorrelated), lens_cross_covariance "
                             "(p_l x p_r, of a joint calibration; empty when "
                             "uncorrelated), port_covariance (6 x 6, of [d, "
                             "a, b] of each port: air gap in m, tilt (N_x, "
                             "N_y) / N_z; empty when the ports are exact), "
                             "port_cross_covariance ((6 + lens rows) x 6, "
                             "of [w; dt; lenses] with them)) or None "
                             "(exact).")
      .def(
          "with_ports",
          [](const StereoRig& r, const FlatPort& left, const FlatPort& right) {
            return ValueOrThrow(r.WithPorts(left, right));
          },
          py::arg("left"), py::arg("right"),
          "A copy with these flat ports (rcm.FlatPort).")
      .def(
          "with_cam1_moved",
          [](const StereoRig& r, const py::object& rotation,
             const py::object& translation) {
            return ValueOrThrow(
                r.WithCam1Moved(Vector3FromPython(rotation, "rotation"),
                                Vector3FromPython(translation, "translation")));
          },
          py::arg("rotation"), py::arg("translation") = py::make_tuple(0, 0, 0),
          "A copy with cam1 turned about its own center by the angle-axis "
          "`rotation` (radians, cam1 frame), then the translation changed by "
          "`translation` (meters, cam1 frame).")
      .def(
          "without_calibration_uncertainty",
          [](const StereoRig& r) {
            return ValueOrThrow(r.WithCalibrationUncertainty(std::nullopt));
          },
          "A copy whose calibration the estimators take as exact.")
      .def(
          "with_drift_prior",
          [](const StereoRig& r, double rotation_sigma,
             double translation_sigma, double focal_sigma) {
            if (!(rotation_sigma >= 0.0) || !(translation_sigma >= 0.0) ||
                !(focal_sigma >= 0.0) || !std::isfinite(rotation_sigma) ||
                !std::isfinite(translation_sigma) ||
                !std::isfinite(focal_sigma)) {
              ThrowValueError("drift prior sigmas must be finite and >= 0");
            }
            RigFileOptions options;
            options.drift_prior = {rotation_sigma, translation_sigma};
            options.focal_drift = focal_sigma;
            return ValueOrThrow(WithDefaultCalibrationUncertainty(r, options));
          },
          py::arg("rotation_sigma"), py::arg("translation_sigma"),
          py::arg("focal_sigma") = 0.0,
          "A copy whose calibration uncertainty is only a drift prior: "
          "per-axis standard deviations of cam1's rotation and translation "
          "in radians and meters, and of each camera's focal lengths, "
          "relative (0.003 = 0.3 %; calibration_uncertainty.h).")
      .def("write", &WriteRig, py::arg("path"),
           "Writes the rig as a two-camera Kalibr camchain (cam0 left, cam1 "
           "right, T_cn_cnm1 = cam1_from_cam0, port blocks for the ports), "
           "atomically; it reads back bit-identical. OSError on failure.")
      .def("__repr__", &RigRepr);

  module.def("read_stereo_rig", &ReadRig, py::arg("path"),
             py::arg("right_info") = py::none(), py::kw_only(),
             py::arg("left_camera") = "cam0", py::arg("right_camera") = "cam1",
             py::arg("drift_prior") = py::none(),
             py::arg("focal_drift") = py::none(),
             R"doc(
Reads a stereo rig.

read_stereo_rig(camchain_path, left_camera='cam0', right_camera='cam1')
    a Kalibr camchain YAML (optionally with rcm's `port` blocks);
read_stereo_rig(left_info_path, right_info_path)
    the ROS camera_info files of the left and the right camera.

drift_prior: (rotation sigma in radians, translation sigma in meters)
replacing the default drift prior of the calibration uncertainty;
focal_drift: each camera's focal lengths' relative sigma (0.003 = 0.3 %),
replacing the focal drift prior (by default 0.3 % for an air calibration
or a rig without a covariance sidecar, 0 for an underwater one).
Raises FileNotFoundError/PermissionError (OSError) for a file that cannot be
read and ValueError for bad contents, with the library's one-line message.
)doc");
  module.def(
      "write_stereo_rig",
      [](const py::object& path, const StereoRig& rig) { WriteRig(rig, path); },
      py::arg("path"), py::arg("rig"), "Same as rig.write(path).");
  module.def("reference_rig", &ReferenceRig, py::arg("name"),
             R"doc(
A rig of the simulator's presets, made in code (no calibration uncertainty):
'alphasense-rectified' (the paper dataset's 720x540 equidistant pair on ideal
rectified extrinsics, baseline 0.11 m), 'alphasense-unrectified' (cam1 turned
0.5 degrees, baseline slightly off axis), 'narrow-field' (radtan, 2.5 degree
toe-in, baseline 0.065 m).
)doc");
}

}  // namespace rcm::python
