// rcm.Camera (the in-air lens), rcm.FlatPort and rcm.RigCamera (a lens
// behind its port, in water): vectorized pixel <-> ray maps.
#include <pybind11/stl.h>

#include <cmath>
#include <limits>
#include <sstream>

#include "bindings.h"
#include "conversions.h"
#include "errors.h"
#include "rcm/camera/flat_port_camera.h"
#include "rcm/camera/refractive_camera.h"

namespace rcm::python {
namespace {

LensModelId LensModelOrThrow(const std::string& name) {
  const std::optional<LensModelId> model = LensModelFromName(name);
  if (!model) {
    ThrowValueError("unknown lens model '" + name + "' (available: " +
                    LensModelNameList() + ")");
  }
  return *model;
}

std::string CameraRepr(const Camera& camera) {
  std::ostringstream text;
  text.precision(10);
  text << "Camera(model='" << LensModelName(camera.model())
       << "', width=" << camera.width() << ", height=" << camera.height()
       << ", intrinsics=[" << camera.fx() << ", " << camera.fy() << ", "
       << camera.cx() << ", " << camera.cy() << "], distortion=[";
  const std::vector<double> distortion = camera.Distortion();
  for (size_t i = 0; i < distortion.size(); ++i) {
    text << (i ? ", " : "") << distortion[i];
  }
  text << "])";
  return text.str();
}

std::string PortRepr(const FlatPort& port) {
  std::ostringstream text;
  text.precision(10);
  text << "FlatPort(air_gap=" << port.air_gap
       << ", glass_thickness=" << port.glass_thickness
       << ", glass_index=" << port.glass_index << ", normal=["
       << port.normal.x() << ", " << port.normal.y() << ", " << port.normal.z()
       << "])";
  return text.str();
}

DoubleArray IntrinsicsArray(const Camera& c) {
  DoubleArray a(std::vector<py::ssize_t>{4});
  for (int i = 0; i < 4; ++i) a.mutable_data()[i] = c.params()[i];
  return a;
}

DoubleArray DistortionArray(const Camera& c) {
  const std::vector<double> d = c.Distortion();
  DoubleArray a(std::vector<py::ssize_t>{static_cast<py::ssize_t>(d.size())});
  std::copy(d.begin(), d.end(), a.mutable_data());
  return a;
}

// Applies `map` (input row -> optional output) to every row, without the
// GIL; failed rows are NaN.
template <int kIn, int kOut, typename Map>
DoubleArray MapRows(const py::handle& input, const std::string& name,
                    const Map& map) {
  const Rows rows = RowsFromPython(input, name, kIn, true, true, false);
  DoubleArray output = NewArray(rows.rows, kOut, rows.single);
  double* out = output.mutable_data();
  const double* in = rows.data();
  {
    py::gil_scoped_release release;
    for (int64_t i = 0; i < rows.rows; ++i) {
      const Eigen::Map<const Eigen::Matrix<double, kIn, 1>> x(in + kIn * i);
      const std::optional<Eigen::Matrix<double, kOut, 1>> y =
          x.allFinite() ? map(Eigen::Matrix<double, kIn, 1>(x)) : std::nullopt;
      for (int k = 0; k < kOut; ++k) out[kOut * i + k] = y ? (*y)[k] : kNaN;
    }
  }
  return output;
}

FlatPort MakePort(double air_gap, double glass_thickness, double glass_index,
                  const py::object& normal) {
  FlatPort port;
  port.air_gap = air_gap;
  port.glass_thickness = glass_thickness;
  port.glass_index = glass_index;
  port.normal = Vector3FromPython(normal, "normal");
  ThrowIfError(port.Check());
  port.normal.normalize();
  return port;
}

}  // namespace

void BindCameras(py::module_& module) {
  py::class_<Camera>(module, "Camera", R"doc(
An in-air calibrated camera: lens model, intrinsics and image size.

Camera(model, width, height, intrinsics, distortion=())

model: 'none' (pinhole), 'radtan' (k1, k2, p1, p2, as OpenCV/Kalibr),
'equidistant' (Kannala-Brandt k1..k4, as OpenCV fisheye/Kalibr),
'rational' (OpenCV's k1, k2, p1, p2, k3, k4, k5, k6), 'ds' (double
sphere xi, alpha, as Kalibr/basalt) or 'eucm' (alpha, beta, as
Kalibr/basalt).
intrinsics: [fx, fy, cx, cy] in pixels; width, height in pixels. Pixel
centers are at integer coordinates. Raises ValueError with the library's
message on a value outside the accepted ranges.
)doc")
      .def(py::init([](const std::string& model, int width, int height,
                       const py::object& intrinsics,
                       const py::object& distortion) {
             const Rows k = RowsFromPython(intrinsics, "intrinsics", 4);
             if (!k.single) ThrowValueError("intrinsics must have shape (4,)");
             const std::vector<double> coefficients =
                 VectorFromPython(distortion, "distortion");
             return ValueOrThrow(Camera::Create(
                 LensModelOrThrow(model), width, height,
                 {k.data()[0], k.data()[1], k.data()[2], k.data()[3]},
                 coefficients));
           }),
           py::arg("model"), py::arg("width"), py::arg("height"),
           py::arg("intrinsics"), py::arg("distortion") = py::tuple())
      .def_property_readonly(
          "model",
          [](const Camera& c) { return std::string(LensModelName(c.model())); },
          "Lens model name: 'none', 'radtan', 'equidistant', 'rational', "
          "'ds' or 'eucm'.")
      .def_property_readonly("width", &Camera::width, "Image width, pixels.")
      .def_property_readonly("height", &Camera::height, "Image height, pixels.")
      .def_property_readonly(
          "image_size",
          [](const Camera& c) { return py::make_tuple(c.width(), c.height()); },
          "(width, height) in pixels.")
      .def_property_readonly("fx", &Camera::fx, "Focal length x, pixels.")
      .def_property_readonly("fy", &Camera::fy, "Focal length y, pixels.")
      .def_property_readonly("cx", &Camera::cx, "Principal point x, pixels.")
      .def_property_readonly("cy", &Camera::cy, "Principal point y, pixels.")
      .def_property_readonly("intrinsics", &IntrinsicsArray,
                             "[fx, fy, cx, cy] in pixels (float64 array).")
      .def_property_readonly("distortion", &DistortionArray,
                             "Distortion coefficients (0, 2, 4 or 8; float64 "
                             "array).")
      .def_property_readonly(
          "K",
          [](const Camera& c) {
            Eigen::Matrix3d k;
            k << c.fx(), 0.0, c.cx(), 0.0, c.fy(), c.cy(), 0.0, 0.0, 1.0;
            return ToNumpy(k);
          },
          "The 3x3 camera matrix [fx 0 cx; 0 fy cy; 0 0 1].")
      .def(
          "normalized_from_image",
          [](const Camera& c, const py::object& pixels) {
            return MapRows<2, 2>(pixels, "pixels",
                                 [&](const Eigen::Vector2d& p) {
                                   return c.NormalizedFromImage(p);
                                 });
          },
          py::arg("pixels"),
          "Lens-undistorted normalized coordinates (z = 1 plane) of raw "
          "pixels (N, 2) -> (N, 2); NaN where undistortion fails.")
      .def(
          "image_from_normalized",
          [](const Camera& c, const py::object& normalized) {
            return MapRows<2, 2>(normalized, "normalized",
                                 [&](const Eigen::Vector2d& x) {
                                   return c.ProjectNormalized(x);
                                 });
          },
          py::arg("normalized"),
          "Raw pixels (N, 2) of normalized points (N, 2) (z = 1 plane, before "
          "distortion); NaN where the lens is not invertible.")
      .def(
          "in_image",
          [](const Camera& c, const py::object& pixels) {
            const Rows rows =
                RowsFromPython(pixels, "pixels", 2, true, true, false);
            py::array_t<bool> out(std::vector<py::ssize_t>{rows.rows});
            for (int64_t i = 0; i < rows.rows; ++i) {
              out.mutable_data()[i] =
                  c.InImage({rows.data()[2 * i], rows.data()[2 * i + 1]});
            }
            return out;
          },
          py::arg("pixels"),
          "True where a pixel lies on the sensor [-0.5, w - 0.5] x "
          "[-0.5, h - 0.5] (bool array of N).")
      .def("__eq__", [](const Camera& a, const Camera& b) { return a == b; })
      .def("__repr__", &CameraRepr);

  py::class_<FlatPort>(module, "FlatPort", R"doc(
The flat port of an underwater housing, in the camera frame, meters.

FlatPort(air_gap=0.0, glass_thickness=0.0, glass_index=1.49,
         normal=(0, 0, 1))

air_gap: camera center to the glass, 0 or in [1e-6, 0.5] m;
glass_thickness: 0 or in [1e-6, 0.1] m; glass_index in [1, 2] (acrylic
1.49, BK7 1.517); normal: unit normal pointing out of the housing (it is
normalized), within 30 degrees of the optical axis. The default is the
paper's thin port. Raises ValueError with the library's message.
)doc")
      .def(py::init(&MakePort), py::arg("air_gap") = 0.0,
           py::arg("glass_thickness") = 0.0, py::arg("glass_index") = 1.49,
           py::arg("normal") = py::make_tuple(0.0, 0.0, 1.0))
      .def_readonly("air_gap", &FlatPort::air_gap, "Air gap, meters.")
      .def_readonly("glass_thickness", &FlatPort::glass_thickness,
                    "Glass thickness, meters.")
      .def_readonly("glass_index", &FlatPort::glass_index,
                    "Refractive index of the glass.")
      .def_property_readonly(
          "normal", [](const FlatPort& p) { return ToNumpy(p.normal); },
          "Unit port normal in the camera frame.")
      .def_property_readonly("is_thin", &FlatPort::IsThin,
                             "True for the paper's thin port (no gap, no "
                             "glass, normal +z).")
      .def("__eq__",
           [](const FlatPort& a, const FlatPort& b) { return a == b; })
      .def("__repr__", &PortRepr);

  py::class_<RigCamera>(module, "RigCamera", R"doc(
One camera of a StereoRig: its in-air lens (.lens, an rcm.Camera) behind its
flat port (.port; the paper's thin port when the rig file has none). The
lens's attributes (model, width, height, fx, ..., intrinsics, distortion)
are forwarded. With a thin port the camera is central (every water ray
starts at the camera center); with a thick port (air gap, glass, tilt) it is
not: a pixel's ray starts on the outer glass face.
)doc")
      .def_property_readonly("lens",
                             [](const RigCamera& c) { return c.camera; })
      .def_property_readonly("port", [](const RigCamera& c) { return c.port; })
      .def_property_readonly("is_thin_port",
                             [](const RigCamera& c) { return c.port.IsThin(); })
      .def_property_readonly(
          "model",
          [](const RigCamera& c) {
            return std::string(LensModelName(c.camera.model()));
          })
      .def_property_readonly(
          "width", [](const RigCamera& c) { return c.camera.width(); })
      .def_property_readonly(
          "height", [](const RigCamera& c) { return c.camera.height(); })
      .def_property_readonly("image_size",
                             [](const RigCamera& c) {
                               return py::make_tuple(c.camera.width(),
                                                     c.camera.height());
                             })
      .def_property_readonly("fx",
                             [](const RigCamera& c) { return c.camera.fx(); })
      .def_property_readonly("fy",
                             [](const RigCamera& c) { return c.camera.fy(); })
      .def_property_readonly("cx",
                             [](const RigCamera& c) { return c.camera.cx(); })
      .def_property_readonly("cy",
                             [](const RigCamera& c) { return c.camera.cy(); })
      .def_property_readonly(
          "intrinsics",
          [](const RigCamera& c) { return IntrinsicsArray(c.camera); },
          "[fx, fy, cx, cy] in pixels.")
      .def_property_readonly(
          "distortion",
          [](const RigCamera& c) { return DistortionArray(c.camera); },
          "Distortion coefficients (0 or 4).")
      .def(
          "pixel_to_ray",
          [](const RigCamera& c, const py::object& pixels, double n) {
            const Rows rows =
                RowsFromPython(pixels, "pixels", 2, true, true, false);
            DoubleArray origins = NewArray(rows.rows, 3, rows.single);
            DoubleArray directions = NewArray(rows.rows, 3, rows.single);
            double* o = origins.mutable_data();
            double* d = directions.mutable_data();
            const double* p = rows.data();
            if (c.port.IsThin()) {
              const RefractiveCamera camera =
                  ValueOrThrow(RefractiveCamera::Create(c.camera, n));
              py::gil_scoped_release release;
              for (int64_t i = 0; i < rows.rows; ++i) {
                const Eigen::Vector2d pixel(p[2 * i], p[2 * i + 1]);
                const std::optional<Eigen::Vector3d> bearing =
                    pixel.allFinite() ? camera.BearingInWaterFromImage(pixel)
                                      : std::nullopt;
                for (int k = 0; k < 3; ++k) {
                  o[3 * i + k] = bearing ? 0.0 : kNaN;
                  d[3 * i + k] = bearing ? (*bearing)[k] : kNaN;
                }
              }
            } else {
              const FlatPortCamera camera =
                  ValueOrThrow(FlatPortCamera::Create(c.camera, c.port, n));
              py::gil_scoped_release release;
              for (int64_t i = 0; i < rows.rows; ++i) {
                const Eigen::Vector2d pixel(p[2 * i], p[2 * i + 1]);
                const std::optional<RayInMedium> ray =
                    pixel.allFinite() ? camera.RayFromImage(pixel)
                                      : std::nullopt;
                for (int k = 0; k < 3; ++k) {
                  o[3 * i + k] = ray ? ray->origin[k] : kNaN;
                  d[3 * i + k] = ray ? ray->direction[k] : kNaN;
                }
              }
            }
            return py::make_tuple(origins, directions);
          },
          py::arg("pixels"), py::arg("n"),
          R"doc(
Rays in the water of raw pixels: pixels (N, 2) -> (origins (N, 3),
directions (N, 3)), in this camera's frame, meters; directions are unit
vectors. Thin port: every origin is the camera center (0, 0, 0). Thick
port: the origin is where the pixel's ray leaves the outer glass face.
Rows that cannot be unprojected (lens not invertible, ray misses the port)
are NaN. n: refractive index of the water, in [1, 2]. A single pixel (2,)
gives arrays (3,).
)doc")
      .def(
          "point_to_pixel",
          [](const RigCamera& c, const py::object& points, double n) {
            if (c.port.IsThin()) {
              const RefractiveCamera camera =
                  ValueOrThrow(RefractiveCamera::Create(c.camera, n));
              return MapRows<3, 2>(points, "points",
                                   [&](const Eigen::Vector3d& x) {
                                     return camera.ImageFromPointInWater(x);
                                   });
            }
            const FlatPortCamera camera =
                ValueOrThrow(FlatPortCamera::Create(c.camera, c.port, n));
            return MapRows<3, 2>(points, "points",
                                 [&](const Eigen::Vector3d& x) {
                                   return camera.ImageFromPoint(x);
                                 });
          },
          py::arg("points"), py::arg("n"),
          R"doc(
Raw pixels (N, 2) of points in the water (N, 3) (this camera's frame,
meters). NaN where a point does not project: behind the camera or the port,
past total internal reflection, or where the lens cannot represent its ray.
A pixel may lie outside the image (see Camera.in_image). n in [1, 2].
)doc")
      .def(
          "virtual_pinhole_matrix",
          [](const RigCamera& c, double n) {
            return ToNumpy(ValueOrThrow(RefractiveCamera::Create(c.camera, n))
                               .VirtualPinholeMatrix());
          },
          py::arg("n"),
          "K_n = [n fx, 0, cx; 0, n fy, cy; 0, 0, 1] (paper eq. 9), the "
          "virtual pinhole of the thin-port camera in water of index n.")
      .def("__repr__", [](const RigCamera& c) {
        return "RigCamera(" + CameraRepr(c.camera) + ", " + PortRepr(c.port) +
               ")";
      });
}

}  // namespace rcm::python
