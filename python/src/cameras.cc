// rcm.Camera (the in-air lens), rcm.FlatPort and rcm.RigCamera (a lens
// behind its port, in water), rcm.DomePort and rcm.DomePortCamera (a lens
// behind a dome) with the error of ignoring a dome: vectorized pixel <->
// ray maps.
#include <pybind11/stl.h>

#include <cmath>
#include <limits>
#include <sstream>

#include "bindings.h"
#include "conversions.h"
#include "errors.h"
#include "rcm/camera/dome_port_camera.h"
#include "rcm/camera/flat_port_camera.h"
#include "rcm/camera/refractive_camera.h"
#include "rcm/estimation/dome_port_error.h"

namespace rcm::python {
namespace {

LensModelId LensModelOrThrow(const std::string& name) {
  const std::optional<LensModelId> model = LensModelFromName(name);
  if (!model) {
    ThrowValueError("unknown lens model '" + name +
                    "' (available: " + LensModelNameList() + ")");
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

// Applies `ray_of` (pixel -> optional RayInMedium) to every pixel row,
// without the GIL: (origins, directions), NaN rows where it fails.
template <typename RayOf>
py::tuple RaysFromPixels(const py::handle& pixels, const RayOf& ray_of) {
  const Rows rows = RowsFromPython(pixels, "pixels", 2, true, true, false);
  DoubleArray origins = NewArray(rows.rows, 3, rows.single);
  DoubleArray directions = NewArray(rows.rows, 3, rows.single);
  double* o = origins.mutable_data();
  double* d = directions.mutable_data();
  const double* p = rows.data();
  {
    py::gil_scoped_release release;
    for (int64_t i = 0; i < rows.rows; ++i) {
      const Eigen::Vector2d pixel(p[2 * i], p[2 * i + 1]);
      const std::optional<RayInMedium> ray =
          pixel.allFinite() ? ray_of(pixel) : std::nullopt;
      for (int k = 0; k < 3; ++k) {
        o[3 * i + k] = ray ? ray->origin[k] : kNaN;
        d[3 * i + k] = ray ? ray->direction[k] : kNaN;
      }
    }
  }
  return py::make_tuple(origins, directions);
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

std::string DomeRepr(const DomePort& dome) {
  std::ostringstream text;
  text.precision(10);
  text << "DomePort(inner_radius=" << dome.inner_radius
       << ", thickness=" << dome.thickness
       << ", glass_index=" << dome.glass_index << ", decentering=["
       << dome.decentering.x() << ", " << dome.decentering.y() << ", "
       << dome.decentering.z() << "])";
  return text.str();
}

// The dome of the keywords: the thickness given, or that of the two radii
// (both: they must agree), checked.
DomePort MakeDome(double inner_radius, const py::object& thickness,
                  const py::object& outer_radius, double glass_index,
                  const py::object& decentering) {
  DomePort dome;
  dome.inner_radius = inner_radius;
  dome.glass_index = glass_index;
  dome.decentering = Vector3FromPython(decentering, "decentering");
  if (thickness.is_none() && outer_radius.is_none()) {
    ThrowValueError("DomePort needs thickness or outer_radius (meters)");
  }
  if (outer_radius.is_none()) {
    dome.thickness = FiniteDouble(thickness, "thickness");
  } else {
    const double given =
        thickness.is_none() ? -1.0 : FiniteDouble(thickness, "thickness");
    const double from_radii = ValueOrThrow(DomeThicknessFromRadii(
        inner_radius, FiniteDouble(outer_radius, "outer_radius"), given));
    dome.thickness = thickness.is_none() ? from_radii : given;
  }
  ThrowIfError(dome.Check());
  return dome;
}

// Per-pixel errors of a dome (IgnoredDomeError, CentralDomeError), NaN
// rows where there is none.
template <typename Error>
DoubleArray DomeErrorRows(const py::handle& pixels, const Error& error) {
  return MapRows<2, 2>(pixels, "pixels", error);
}

// The result of evaluate_dome_port_error.
DoubleArray PerDepth(const DomePortError& e,
                     double (*value)(const DomePortErrorAtDepth&)) {
  DoubleArray a(
      std::vector<py::ssize_t>{static_cast<py::ssize_t>(e.depths.size())});
  for (size_t i = 0; i < e.depths.size(); ++i) {
    a.mutable_data()[i] = value(e.depths[i]);
  }
  return a;
}

py::object PerDepthCentral(const DomePortError& e,
                           double (*value)(const PixelErrorStats&)) {
  if (!e.central_max_px) return py::none();
  DoubleArray a(
      std::vector<py::ssize_t>{static_cast<py::ssize_t>(e.depths.size())});
  for (size_t i = 0; i < e.depths.size(); ++i) {
    a.mutable_data()[i] = value(*e.depths[i].central);
  }
  return a;
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
            if (c.port.IsThin()) {
              const RefractiveCamera camera =
                  ValueOrThrow(RefractiveCamera::Create(c.camera, n));
              return RaysFromPixels(
                  pixels,
                  [&](const Eigen::Vector2d& pixel)
                      -> std::optional<RayInMedium> {
                    const std::optional<Eigen::Vector3d> bearing =
                        camera.BearingInWaterFromImage(pixel);
                    if (!bearing) return std::nullopt;
                    return RayInMedium{Eigen::Vector3d::Zero(), *bearing};
                  });
            }
            const FlatPortCamera camera =
                ValueOrThrow(FlatPortCamera::Create(c.camera, c.port, n));
            return RaysFromPixels(pixels, [&](const Eigen::Vector2d& pixel) {
              return camera.RayFromImage(pixel);
            });
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

  py::class_<DomePort>(module, "DomePort", R"doc(
The dome port of an underwater housing: a spherical glass shell whose
centre sits at `decentering` from the camera's projection centre (camera
frame x right, y down, z forward; meters).

DomePort(inner_radius, thickness=None, outer_radius=None, glass_index=1.49,
         decentering=(0, 0, 0))

inner_radius: r1 in [1e-6, 1] m; thickness: 0 or in [1e-6, 0.1] m, or
outer_radius (r2 = r1 + thickness; both when they agree to 1 micrometre);
glass_index in [1, 2] (acrylic 1.49, borosilicate 1.47, BK7 1.517);
decentering: the dome's centre in the camera frame, (3,) meters, |C| below
r1 (a camera 7 mm behind the centre is (0, 0, 0.007)). A centred dome
(C = 0) does not refract. Raises ValueError with the library's message.
)doc")
      .def(py::init(&MakeDome), py::arg("inner_radius"),
           py::arg("thickness") = py::none(),
           py::arg("outer_radius") = py::none(), py::arg("glass_index") = 1.49,
           py::arg("decentering") = py::make_tuple(0.0, 0.0, 0.0))
      .def_readwrite("inner_radius", &DomePort::inner_radius,
                     "Inner radius r1, meters.")
      .def_readwrite("thickness", &DomePort::thickness,
                     "Glass thickness, meters.")
      .def_property_readonly("outer_radius", &DomePort::outer_radius,
                             "Outer radius r2 = r1 + thickness, meters.")
      .def_readwrite("glass_index", &DomePort::glass_index,
                     "Refractive index of the glass.")
      .def_property(
          "decentering",
          [](const DomePort& d) { return ToNumpy(d.decentering); },
          [](DomePort& d, const py::object& value) {
            d.decentering = Vector3FromPython(value, "decentering");
          },
          "The dome's centre in the camera frame, (3,) meters.")
      .def_property_readonly("is_centred", &DomePort::IsCentred,
                             "True when the decentering is exactly 0 (no "
                             "refraction).")
      .def(
          "check", [](const DomePort& d) { ThrowIfError(d.Check()); },
          "Raises ValueError with the library's message for a dome the C++ "
          "DomePort::Check refuses (after fields were set).")
      .def("__eq__",
           [](const DomePort& a, const DomePort& b) { return a == b; })
      .def("__repr__", &DomeRepr);

  py::class_<DomePortCamera>(module, "DomePortCamera", R"doc(
An in-air calibrated camera behind a dome port in a medium of index n: exact
ray tracing through both glass surfaces (C++ rcm::DomePortCamera). A
decentered dome is not a central camera: each pixel's ray starts on the
dome's outer surface. A centred dome is the air camera.

DomePortCamera(camera, dome, n)

camera: rcm.Camera (the air calibration); dome: rcm.DomePort; n: index of
the medium in [1, 2] (1.333 fresh water). ValueError with the library's
message for a dome that fails its check or n outside [1, 2].
)doc")
      .def(py::init([](const Camera& camera, const DomePort& dome, double n) {
             return ValueOrThrow(DomePortCamera::Create(camera, dome, n));
           }),
           py::arg("camera"), py::arg("dome"), py::arg("n"))
      .def_property_readonly("camera", &DomePortCamera::camera,
                             "The air calibration (rcm.Camera).")
      .def_property_readonly("dome", &DomePortCamera::dome,
                             "The dome (rcm.DomePort).")
      .def_property_readonly("n", &DomePortCamera::n,
                             "Refractive index of the medium.")
      .def(
          "ray_from_image",
          [](const DomePortCamera& c, const py::object& pixels) {
            return RaysFromPixels(pixels, [&](const Eigen::Vector2d& pixel) {
              return c.RayFromImage(pixel);
            });
          },
          py::arg("pixels"),
          R"doc(
Rays in the medium of raw pixels: pixels (N, 2) -> (origins (N, 3),
directions (N, 3)), camera frame, meters; each origin lies on the dome's
outer surface, directions are unit vectors. NaN rows where the lens cannot
undistort a pixel or its ray is totally reflected. A single pixel (2,)
gives arrays (3,).
)doc")
      .def(
          "image_from_point",
          [](const DomePortCamera& c, const py::object& points) {
            return MapRows<3, 2>(
                points, "points",
                [&](const Eigen::Vector3d& x) { return c.ImageFromPoint(x); });
          },
          py::arg("points"),
          R"doc(
Raw pixels (N, 2) of points in the medium (N, 3) (camera frame, meters,
beyond the dome). NaN where a point is not seen: inside the dome, behind
the camera, past total internal reflection, or where the lens cannot
represent its ray. A pixel may lie outside the image (Camera.in_image).
)doc")
      .def(
          "normalized_from_point",
          [](const DomePortCamera& c, const py::object& points) {
            return MapRows<3, 2>(points, "points",
                                 [&](const Eigen::Vector3d& x) {
                                   return c.NormalizedFromPoint(x);
                                 });
          },
          py::arg("points"),
          "Lens-undistorted normalized points (N, 2) in air whose rays "
          "reach the points (N, 3); NaN as image_from_point.")
      .def("__repr__", [](const DomePortCamera& c) {
        std::ostringstream n;
        n << c.n();
        return "DomePortCamera(" + CameraRepr(c.camera()) + ", " +
               DomeRepr(c.dome()) + ", n=" + n.str() + ")";
      });

  module.def(
      "ignored_dome_error",
      [](const DomePortCamera& c, const py::object& pixels, double depth) {
        return DomeErrorRows(pixels, [&](const Eigen::Vector2d& p) {
          return IgnoredDomeError(c, p, depth);
        });
      },
      py::arg("dome_camera"), py::arg("pixels"), py::arg("depth"),
      R"doc(
The pixel error of ignoring the dome (C++ rcm::IgnoredDomeError,
rcm/estimation/dome_port_error.h): for raw pixels (N, 2) of a
DomePortCamera, the point at depth `depth` (camera-frame z, meters) on each
pixel's ray through the dome, imaged by the air calibration alone, less
the pixel: (N, 2) pixels. NaN rows where a ray does not reach the depth.
Zero (to 1e-12 px) for a centred dome.
)doc");
  module.def(
      "central_dome_error",
      [](const DomePortCamera& c, const py::object& pixels, double depth,
         double reference_depth) {
        return DomeErrorRows(pixels, [&](const Eigen::Vector2d& p) {
          return CentralDomeError(c, p, depth, reference_depth);
        });
      },
      py::arg("dome_camera"), py::arg("pixels"), py::arg("depth"),
      py::arg("reference_depth"),
      R"doc(
The pixel error at depth `depth` (meters) of the best central camera for a
dome, the one exact at `reference_depth` (C++ rcm::CentralDomeError): the
dome's parallax, zero at the reference depth. pixels (N, 2) -> (N, 2), NaN
rows where there is none.
)doc");

  py::class_<DomePortError>(module, "DomePortError", R"doc(
The result of evaluate_dome_port_error (rcm dome-check): the pixel error of
ignoring a dome over the image, per depth.

depths (K,) meters, ascending; max_px_per_depth, rms_px_per_depth,
median_px_per_depth (K,) pixels; num_unusable (K,) grid pixels without an
error; central_max_px_per_depth, central_rms_px_per_depth (K,) or None (the
central camera exact at the reference depth); max_px, rms_px over every
depth; worst_index, worst_depth (meters); worst_field (rows, cols, 2)
pixels, NaN where none, at worst_field_pixels (rows, cols, 2);
reference_depth, reference_max_px, reference_rms_px (or None); central_max_px
(or None).
)doc")
      .def_property_readonly(
          "depths",
          [](const DomePortError& e) {
            return PerDepth(
                e, [](const DomePortErrorAtDepth& a) { return a.depth; });
          })
      .def_property_readonly("max_px_per_depth",
                             [](const DomePortError& e) {
                               return PerDepth(
                                   e, [](const DomePortErrorAtDepth& a) {
                                     return a.ignored.max_px;
                                   });
                             })
      .def_property_readonly("rms_px_per_depth",
                             [](const DomePortError& e) {
                               return PerDepth(
                                   e, [](const DomePortErrorAtDepth& a) {
                                     return a.ignored.rms_px;
                                   });
                             })
      .def_property_readonly("median_px_per_depth",
                             [](const DomePortError& e) {
                               return PerDepth(
                                   e, [](const DomePortErrorAtDepth& a) {
                                     return a.ignored.median_px;
                                   });
                             })
      .def_property_readonly("num_unusable",
                             [](const DomePortError& e) {
                               py::array_t<int64_t> a(std::vector<py::ssize_t>{
                                   static_cast<py::ssize_t>(e.depths.size())});
                               for (size_t i = 0; i < e.depths.size(); ++i) {
                                 a.mutable_data()[i] = e.depths[i].num_unusable;
                               }
                               return a;
                             })
      .def_property_readonly(
          "central_max_px_per_depth",
          [](const DomePortError& e) {
            return PerDepthCentral(
                e, [](const PixelErrorStats& s) { return s.max_px; });
          })
      .def_property_readonly(
          "central_rms_px_per_depth",
          [](const DomePortError& e) {
            return PerDepthCentral(
                e, [](const PixelErrorStats& s) { return s.rms_px; });
          })
      .def_readonly("max_px", &DomePortError::max_px)
      .def_readonly("rms_px", &DomePortError::rms_px)
      .def_readonly("worst_index", &DomePortError::worst_index)
      .def_property_readonly(
          "worst_depth",
          [](const DomePortError& e) { return e.depths[e.worst_index].depth; })
      .def_property_readonly(
          "worst_field",
          [](const DomePortError& e) {
            const ImageErrorField& f = e.worst_field;
            DoubleArray a(std::vector<py::ssize_t>{f.rows, f.cols, 2});
            for (size_t i = 0; i < f.errors.size(); ++i) {
              for (int k = 0; k < 2; ++k) {
                a.mutable_data()[2 * i + k] =
                    f.errors[i] ? (*f.errors[i])[k] : kNaN;
              }
            }
            return a;
          })
      .def_property_readonly(
          "worst_field_pixels",
          [](const DomePortError& e) {
            const ImageErrorField& f = e.worst_field;
            DoubleArray a(std::vector<py::ssize_t>{f.rows, f.cols, 2});
            for (int row = 0; row < f.rows; ++row) {
              for (int col = 0; col < f.cols; ++col) {
                const Eigen::Vector2d p = f.Pixel(col, row);
                a.mutable_data()[2 * (row * f.cols + col)] = p.x();
                a.mutable_data()[2 * (row * f.cols + col) + 1] = p.y();
              }
            }
            return a;
          })
      .def_property_readonly("reference_depth",
                             [](const DomePortError& e) -> py::object {
                               if (!e.at_reference) return py::none();
                               return py::float_(e.at_reference->depth);
                             })
      .def_property_readonly(
          "reference_max_px",
          [](const DomePortError& e) -> py::object {
            if (!e.at_reference) return py::none();
            return py::float_(e.at_reference->ignored.max_px);
          })
      .def_property_readonly(
          "reference_rms_px",
          [](const DomePortError& e) -> py::object {
            if (!e.at_reference) return py::none();
            return py::float_(e.at_reference->ignored.rms_px);
          })
      .def_property_readonly("central_max_px",
                             [](const DomePortError& e) -> py::object {
                               if (!e.central_max_px) return py::none();
                               return py::float_(*e.central_max_px);
                             })
      .def("__repr__", [](const DomePortError& e) {
        std::ostringstream text;
        text << "DomePortError(max_px=" << e.max_px << ", rms_px=" << e.rms_px
             << ", worst_depth=" << e.depths[e.worst_index].depth << ")";
        return text.str();
      });

  module.def(
      "evaluate_dome_port_error",
      [](const DomePortCamera& c, double min_depth, double max_depth,
         int num_depths, double grid_step, const py::object& reference_depth) {
        DomePortErrorOptions options;
        options.min_depth = min_depth;
        options.max_depth = max_depth;
        options.num_depths = num_depths;
        options.grid_step = grid_step;
        if (!reference_depth.is_none()) {
          options.reference_depth =
              FiniteDouble(reference_depth, "reference_depth");
        }
        StatusOr<DomePortError> error = Status::Error("not run");
        {
          py::gil_scoped_release release;
          error = EvaluateDomePortError(c, options);
        }
        return ValueOrThrow(std::move(error));
      },
      py::arg("dome_camera"), py::arg("min_depth") = 0.3,
      py::arg("max_depth") = 10.0, py::arg("num_depths") = 12,
      py::arg("grid_step") = 8.0, py::arg("reference_depth") = py::none(),
      R"doc(
Is the dome worth modelling? (C++ rcm::EvaluateDomePortError; rcm
dome-check.) The pixel error of ignoring the dome, i.e. of using the air
calibration under water, over a grid every grid_step pixels on the image at
num_depths depths spaced geometrically over [min_depth, max_depth]
(camera-frame z, meters, beyond the dome); with reference_depth (meters)
also the error there and that of the central camera exact there at every
depth. Returns a DomePortError. ValueError with the library's message for a
depth range that is empty, not beyond the dome, and so on.
)doc");
}

}  // namespace rcm::python
