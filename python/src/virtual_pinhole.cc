// rcm.virtual_pinhole_maps / rcm.VirtualPinholeRig: refraction- and
// lens-corrected (virtual pinhole) images, their cv2.remap maps and the
// corrected rig.
#include <pybind11/stl.h>

#include <cstring>
#include <limits>

#include "bindings.h"
#include "conversions.h"
#include "errors.h"
#include "rcm/io/camchain.h"
#include "rcm/io/corrected_rig_files.h"
#include "rcm/stereo/virtual_pinhole_rig.h"

namespace rcm::python {
namespace {

py::array_t<float> FloatMap(const cv::Mat& map) {
  CHECK(map.type() == CV_32FC1);
  py::array_t<float> array(std::vector<py::ssize_t>{map.rows, map.cols});
  for (int r = 0; r < map.rows; ++r) {
    std::memcpy(array.mutable_data() + static_cast<size_t>(r) * map.cols,
                map.ptr<float>(r), sizeof(float) * map.cols);
  }
  return array;
}

VirtualPinholeRig MakeRig(const py::object& rig_object, double n,
                          const std::string& fit,
                          const std::optional<std::pair<int, int>>& output_size,
                          const std::optional<double>& focal_px, bool rectify,
                          double reference_depth, int num_threads) {
  const StereoRig rig = RigFromPython(rig_object);
  VirtualPinholeRigOptions options;
  const std::optional<VirtualPinholeFit> parsed =
      VirtualPinholeFitFromName(fit);
  if (!parsed) {
    ThrowValueError("unknown fit '" + fit +
                    "' (available: virtual-pinhole, no-border, full)");
  }
  options.fit = *parsed;
  if (output_size) {
    options.output_size = cv::Size(output_size->first, output_size->second);
  }
  options.focal_px = focal_px;
  options.rectify = rectify;
  options.reference_depth = reference_depth;
  options.num_threads = num_threads;
  // The float maps are what Python uses; cv::remap reads them directly.
  options.fixed_point_maps = false;
  ThrowIfError(options.Check());
  StatusOr<VirtualPinholeRig> result = Status::Error("not built");
  {
    py::gil_scoped_release release;
    result = VirtualPinholeRig::Create(rig, n, options);
  }
  return ValueOrThrow(std::move(result));
}

template <typename Map>
DoubleArray MapPixels(const py::object& pixels, const Map& map) {
  const Rows rows = RowsFromPython(pixels, "pixels", 2, true, true, false);
  DoubleArray out = NewArray(rows.rows, 2, rows.single);
  for (int64_t i = 0; i < rows.rows; ++i) {
    const Eigen::Vector2d p(rows.data()[2 * i], rows.data()[2 * i + 1]);
    const std::optional<Eigen::Vector2d> q =
        p.allFinite() ? map(p) : std::nullopt;
    out.mutable_data()[2 * i] = q ? q->x() : kNaN;
    out.mutable_data()[2 * i + 1] = q ? q->y() : kNaN;
  }
  return out;
}

}  // namespace

void BindVirtualPinhole(py::module_& module) {
  py::class_<VirtualPinholeCamera>(module, "VirtualPinholeCamera", R"doc(
One corrected camera of a VirtualPinholeRig. map_x, map_y: float32 arrays of
the output size (h', w') holding the raw pixel behind every output pixel,
-1 where the camera does not see the ray: cv2.remap(raw, map_x, map_y,
cv2.INTER_LINEAR) gives the corrected image. pinhole: the corrected image's
camera (rcm.Camera, model 'none', K' and size). K: its 3x3 matrix.
)doc")
      .def_property_readonly(
          "map_x",
          [](const VirtualPinholeCamera& c) { return FloatMap(c.maps.map_x); })
      .def_property_readonly(
          "map_y",
          [](const VirtualPinholeCamera& c) { return FloatMap(c.maps.map_y); })
      .def_property_readonly(
          "maps",
          [](const VirtualPinholeCamera& c) {
            return py::make_tuple(FloatMap(c.maps.map_x),
                                  FloatMap(c.maps.map_y));
          },
          "(map_x, map_y).")
      .def_property_readonly(
          "pinhole", [](const VirtualPinholeCamera& c) { return c.pinhole; })
      .def_property_readonly(
          "K", [](const VirtualPinholeCamera& c) { return ToNumpy(c.view.k); })
      .def_property_readonly(
          "camera_from_view",
          [](const VirtualPinholeCamera& c) {
            return ToNumpy(c.view.camera_from_view);
          },
          "Rotation taking view (corrected) coordinates to camera coordinates.")
      .def_property_readonly("focal_scale", &VirtualPinholeCamera::FocalScale,
                             "fx' / (n fx).")
      .def_property_readonly("black_fraction",
                             &VirtualPinholeCamera::BlackFraction,
                             "Fraction of output pixels that see nothing.")
      .def_property_readonly(
          "num_invalid",
          [](const VirtualPinholeCamera& c) { return c.maps.num_invalid; })
      .def(
          "correct",
          [](const VirtualPinholeCamera& c, const py::object& image) {
            py::object keep;
            const cv::Mat raw = ImageFromPython(image, "image", &keep);
            if (raw.cols != c.maps.raw_size.width ||
                raw.rows != c.maps.raw_size.height) {
              ThrowValueError("image is " + std::to_string(raw.cols) + " x " +
                              std::to_string(raw.rows) + ", the camera's " +
                              std::to_string(c.maps.raw_size.width) + " x " +
                              std::to_string(c.maps.raw_size.height));
            }
            cv::Mat corrected;
            {
              py::gil_scoped_release release;
              corrected = c.Correct(raw);
            }
            return ImageToNumpy(corrected);
          },
          py::arg("image"),
          "The corrected image (uint8) of a raw uint8 image of the camera's "
          "size: bilinear, black where the maps are invalid.")
      .def(
          "corrected_from_raw",
          [](const VirtualPinholeCamera& c, const py::object& pixels) {
            return MapPixels(pixels, [&](const Eigen::Vector2d& p) {
              return c.CorrectedFromRaw(p);
            });
          },
          py::arg("pixels"),
          "Corrected pixels (N, 2) of raw pixels (exact, not through the "
          "maps); NaN where undefined.")
      .def(
          "raw_from_corrected",
          [](const VirtualPinholeCamera& c, const py::object& pixels) {
            return MapPixels(pixels, [&](const Eigen::Vector2d& p) {
              return c.RawFromCorrected(p);
            });
          },
          py::arg("pixels"),
          "Raw pixels (N, 2) of corrected pixels (exact); NaN where the "
          "camera does not see the ray.");

  py::class_<VirtualPinholeRig>(module, "VirtualPinholeRig", R"doc(
A rig in water of index n turned into two ideal pinhole cameras (C++
VirtualPinholeRig): .left, .right (VirtualPinholeCamera, with the remap maps
and the corrected camera), .corrected_rig (rcm.StereoRig of the two pinholes,
cam1_from_cam0 = right view from left view), .n, write(path) (the corrected
Kalibr camchain). Build it with rcm.virtual_pinhole_maps.
)doc")
      .def_property_readonly("left", &VirtualPinholeRig::left)
      .def_property_readonly("right", &VirtualPinholeRig::right)
      .def(
          "camera",
          [](const VirtualPinholeRig& r, int index) {
            if (index != 0 && index != 1)
              ThrowValueError("index must be 0 or 1");
            return index == 0 ? r.left() : r.right();
          },
          py::arg("index"), "The corrected camera 0 (left) or 1 (right).")
      .def_property_readonly("corrected_rig", &VirtualPinholeRig::corrected_rig)
      .def_property_readonly("n", &VirtualPinholeRig::n)
      .def_property_readonly("build_ms", &VirtualPinholeRig::build_ms)
      .def(
          "write",
          [](const VirtualPinholeRig& r, const py::object& path) {
            const Status status =
                WriteCamchain(PathFromPython(path), CorrectedCamchain(r));
            if (!status.ok()) ThrowWriteError(status.message());
          },
          py::arg("path"), "Writes the corrected rig's Kalibr camchain.");

  module.def("virtual_pinhole_maps", &MakeRig, py::arg("rig"), py::arg("n"),
             py::kw_only(), py::arg("fit") = "no-border",
             py::arg("output_size") = py::none(),
             py::arg("focal_px") = py::none(), py::arg("rectify") = false,
             py::arg("reference_depth") = 2.0, py::arg("num_threads") = 2,
             R"doc(
The virtual pinhole correction of a rig in water of index n (paper Sec.
III-B; C++ VirtualPinholeRig::Create), as an rcm.VirtualPinholeRig whose
left/right cameras hold float32 (map_x, map_y) for cv2.remap and the
corrected camera model.

fit: 'virtual-pinhole' (K' = K_n = diag(n fx, n fy, 1)), 'no-border' (the
widest view without black borders; the default, as in C++), 'full' (the
narrowest view holding the whole field of view). output_size: (width,
height) in pixels (default each camera's); focal_px: output fx' in pixels
(overrides the fit's scale); rectify: rotate both views to the ideal
rectified pair with one K'; reference_depth: meters, where a thick port's
corrected images are exact. The GIL is released while the maps are built.
)doc");
}

}  // namespace rcm::python
