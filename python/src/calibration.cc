// Calibration (rcm::calib): targets, stereo and one-camera calibration in
// air and the underwater refinement, from images (NumPy arrays or files) or
// from corner observations; and the target renderer for synthetic views.
#include <pybind11/stl.h>

#include <cmath>
#include <sstream>

#include "bindings.h"
#include "conversions.h"
#include "errors.h"
#include "options.h"
#include "rcm/calib/calibration_target.h"
#include "rcm/calib/dome_calibration.h"
#include "rcm/calib/mono_calibration.h"
#include "rcm/calib/stereo_calibration.h"
#include "rcm/calib/target_detector.h"
#include "rcm/calib/target_image.h"
#include "rcm/calib/target_renderer.h"
#include "rcm/calib/underwater_calibration.h"
#include "rcm/camera/dome_port_geometry.h"
#include "rcm/io/image_file.h"

namespace rcm::python {
namespace {

using calib::CalibrationTarget;
using calib::ImageSize;
using calib::StereoView;
using calib::TargetObservation;

// One image of a list: a NumPy uint8 array (viewed, kept alive by `keep`)
// or a path (read as 8-bit gray by the library).
cv::Mat ImageOrFile(const py::handle& item, const std::string& name,
                    std::vector<py::object>* keep) {
  if (py::isinstance<py::array>(item)) {
    py::object holder;
    const cv::Mat image = ImageFromPython(item, name, &holder);
    keep->push_back(holder);
    return image;
  }
  const std::string path = PathFromPython(item);
  return ReadOrThrow(path, ReadImage(path, /*grayscale=*/true));
}

// Detects the target in every pair (GIL released), with the image sizes;
// `right` None: in the left images only (one camera).
struct Detections {
  std::vector<StereoView> views;
  ImageSize sizes[2];
};

Detections Detect(const CalibrationTarget& target, const py::sequence& left,
                  const py::object& right_images) {
  const int num_cameras = right_images.is_none() ? 1 : 2;
  const py::sequence right =
      num_cameras == 2 ? py::sequence(right_images) : left;
  if (py::len(left) != py::len(right)) {
    ThrowValueError("left_images and right_images differ in length (" +
                    std::to_string(py::len(left)) + " and " +
                    std::to_string(py::len(right)) + ")");
  }
  if (py::len(left) == 0) ThrowValueError("no images");
  std::vector<py::object> keep;
  std::vector<cv::Mat> images[2];
  Detections detections;
  for (size_t i = 0; i < py::len(left); ++i) {
    for (int side = 0; side < num_cameras; ++side) {
      const std::string name = std::string(side ? "right" : "left") +
                               "_images[" + std::to_string(i) + "]";
      const cv::Mat image = ImageOrFile((side ? right : left)[i], name, &keep);
      ImageSize& size = detections.sizes[side];
      if (i == 0) size = {image.cols, image.rows};
      if (image.cols != size.width || image.rows != size.height) {
        ThrowValueError(name + " is " + std::to_string(image.cols) + " x " +
                        std::to_string(image.rows) + ", the first image " +
                        std::to_string(size.width) + " x " +
                        std::to_string(size.height));
      }
      images[side].push_back(image);
    }
  }
  {
    py::gil_scoped_release release;
    for (size_t i = 0; i < images[0].size(); ++i) {
      StereoView view;
      if (num_cameras == 2) {
        view = calib::DetectTargetPair(images[0][i], images[1][i], target);
        view.right_name = "right " + std::to_string(i);
      } else {
        view.left = calib::DetectTarget(images[0][i], target);
        if (!view.left) view.note = "no target found";
      }
      view.left_name = "left " + std::to_string(i);
      detections.views.push_back(std::move(view));
    }
  }
  return detections;
}

// A corner list (ids (M,), pixels (M, 2)) or None.
std::optional<TargetObservation> ObservationFrom(const py::handle& item,
                                                 const std::string& name) {
  if (item.is_none()) return std::nullopt;
  const py::tuple pair = py::reinterpret_borrow<py::object>(item);
  if (pair.size() != 2) {
    ThrowValueError(name + " must be None or (point_ids, pixels)");
  }
  const py::array ids_array = py::array::ensure(pair[0]);
  if (!ids_array ||
      (ids_array.dtype().kind() != 'i' && ids_array.dtype().kind() != 'u')) {
    ThrowTypeError(name + " point ids must be integers");
  }
  const auto ids =
      py::array_t<int64_t, py::array::c_style | py::array::forcecast>::ensure(
          ids_array);
  const Rows pixels = RowsFromPython(pair[1], name + " pixels", 2, false, true);
  if (ids.ndim() != 1 || ids.shape(0) != pixels.rows) {
    ThrowValueError(name + ": one point id per pixel");
  }
  TargetObservation observation;
  observation.detector = "python";
  for (int64_t i = 0; i < pixels.rows; ++i) {
    observation.point_ids.push_back(static_cast<int>(ids.data()[i]));
    observation.pixels.emplace_back(pixels.data()[2 * i],
                                    pixels.data()[2 * i + 1]);
  }
  return observation;
}

// ObservationFrom, its point ids checked against the target's
// (`view_name` names the view in the message).
std::optional<TargetObservation> TargetObservationFrom(
    const py::handle& item, const std::string& name,
    const std::string& view_name, int num_points) {
  std::optional<TargetObservation> observation = ObservationFrom(item, name);
  if (!observation) return observation;
  for (const int id : observation->point_ids) {
    if (id < 0 || id >= num_points) {
      ThrowValueError(view_name + ": point id " + std::to_string(id) +
                      " outside [0, " + std::to_string(num_points) + ")");
    }
  }
  return observation;
}

// The views of corner observations: per view (left, right) of a pair, or
// (one camera) the left alone.
std::vector<StereoView> ViewsFromCorners(const CalibrationTarget& target,
                                         const py::sequence& views,
                                         bool one_camera = false) {
  const int num_points = calib::NumTargetPoints(target);
  std::vector<StereoView> result;
  for (size_t v = 0; v < py::len(views); ++v) {
    const std::string name = "views[" + std::to_string(v) + "]";
    StereoView view;
    view.left_name = "view " + std::to_string(v);
    if (one_camera) {
      view.left = TargetObservationFrom(views[v], name, name, num_points);
      result.push_back(std::move(view));
      continue;
    }
    const py::tuple pair = py::reinterpret_borrow<py::object>(views[v]);
    if (pair.size() != 2) {
      ThrowValueError(name + " must be (left corners, right corners)");
    }
    view.right_name = view.left_name;
    view.left = TargetObservationFrom(pair[0], name + "[0]", name, num_points);
    view.right = TargetObservationFrom(pair[1], name + "[1]", name, num_points);
    result.push_back(std::move(view));
  }
  if (result.empty()) ThrowValueError("no views");
  return result;
}

ImageSize SizeFrom(const std::pair<int, int>& size) {
  return {size.first, size.second};
}

// The keywords the air and the underwater calibration share: the board
// bundle adjustment's robust loss, outlier rounds, solver and threads.
template <typename Options>
std::vector<OptionField> BoardAdjustmentFields(Options* o) {
  return {
      DoubleOption("huber_px", &o->huber_px),
      DoubleOption("outlier_sigmas", &o->outlier_sigmas),
      DoubleOption("min_outlier_threshold_px", &o->min_outlier_threshold_px),
      IntOption("max_outlier_rounds", &o->max_outlier_rounds),
      IntOption("max_num_iterations", &o->max_num_iterations),
      BoolOption("use_single_camera_views", &o->use_single_camera_views),
      IntOption("min_corners_per_view", &o->min_corners_per_view),
      BoolOption("estimate_board_warp", &o->estimate_board_warp),
      IntOption("num_threads", &o->num_threads)};
}

calib::StereoCalibrationOptions StereoOptionsFrom(
    const std::string& model, const py::kwargs& kwargs,
    const std::string& function = "calibrate_stereo") {
  calib::StereoCalibrationOptions o;
  const std::optional<LensModelId> lens = LensModelFromName(model);
  if (!lens || *lens == LensModelId::kPinhole) {
    ThrowValueError(
        "model must be one of radtan, equidistant, rational, ds, eucm, got '" +
        model + "'");
  }
  o.model = *lens;
  std::vector<OptionField> fields = BoardAdjustmentFields(&o);
  fields.push_back(BoolOption("compute_covariance", &o.compute_covariance));
  ApplyOptions(kwargs, fields, function);
  ThrowIfError(o.Check());
  return o;
}

calib::UnderwaterCalibrationOptions UnderwaterOptionsFrom(
    const py::kwargs& kwargs) {
  calib::UnderwaterCalibrationOptions o;
  std::vector<OptionField> fields = BoardAdjustmentFields(&o);
  fields.push_back(DoubleOption("initial_n", &o.initial_n));
  fields.push_back(BoolOption("estimate_air_gap", &o.estimate_air_gap));
  fields.push_back(BoolOption("estimate_port_tilt", &o.estimate_port_tilt));
  fields.push_back(IntOption("folds", &o.folds));
  fields.push_back(
      BoolOption("fit_conventional_model", &o.fit_conventional_model));
  ApplyOptions(kwargs, fields, "calibrate_underwater");
  ThrowIfError(o.Check());
  return o;
}

// The result of a stereo calibration with its rig.
struct StereoCalibrationResult {
  calib::StereoCalibration calibration;
  StereoRig rig;
  std::vector<std::string> notes;
};

StereoCalibrationResult RunStereo(
    const CalibrationTarget& target, const std::vector<StereoView>& views,
    const ImageSize& cam0, const ImageSize& cam1,
    const calib::StereoCalibrationOptions& options) {
  StatusOr<calib::StereoCalibration> calibration = Status::Error("not run");
  {
    py::gil_scoped_release release;
    calibration = calib::CalibrateStereo(target, views, cam0, cam1, options);
  }
  calib::StereoCalibration result = ValueOrThrow(std::move(calibration));
  StereoRig rig = ValueOrThrow(StereoRig::Create(
      result.cam0.camera, result.cam1.camera, result.cam1_from_cam0));
  std::vector<std::string> notes;
  for (const StereoView& view : views) {
    if (!view.note.empty()) notes.push_back(view.left_name + ": " + view.note);
  }
  return {std::move(result), std::move(rig), std::move(notes)};
}

// The result of a one-camera calibration.
struct MonoCalibrationResult {
  calib::StereoCalibration calibration;
  std::vector<std::string> notes;
};

MonoCalibrationResult RunMono(const CalibrationTarget& target,
                              const std::vector<StereoView>& views,
                              const ImageSize& size,
                              const calib::StereoCalibrationOptions& options) {
  StatusOr<calib::StereoCalibration> calibration = Status::Error("not run");
  {
    py::gil_scoped_release release;
    calibration = calib::CalibrateMono(target, views, size, options);
  }
  MonoCalibrationResult result{ValueOrThrow(std::move(calibration)), {}};
  for (const StereoView& view : views) {
    if (!view.note.empty()) {
      result.notes.push_back(view.left_name + ": " + view.note);
    }
  }
  return result;
}

struct UnderwaterResult {
  calib::UnderwaterCalibration calibration;
  std::vector<std::string> notes;
};

UnderwaterResult RunUnderwater(
    const CalibrationTarget& target, const std::vector<StereoView>& views,
    const ImageSize& cam0, const ImageSize& cam1, const StereoRig& air_rig,
    const calib::UnderwaterCalibrationOptions& options) {
  StatusOr<calib::UnderwaterCalibration> calibration = Status::Error("not run");
  {
    py::gil_scoped_release release;
    calibration =
        calib::CalibrateUnderwater(target, views, cam0, cam1, air_rig, options);
  }
  UnderwaterResult result{ValueOrThrow(std::move(calibration)), {}};
  result.notes = result.calibration.notes;
  for (const StereoView& view : views) {
    if (!view.note.empty()) {
      result.notes.push_back(view.left_name + ": " + view.note);
    }
  }
  return result;
}

calib::DomeCalibrationOptions DomeOptionsFrom(const py::kwargs& kwargs,
                                              const std::string& function) {
  calib::DomeCalibrationOptions o;
  const std::vector<OptionField> fields = {
      BoolOption("estimate_n", &o.estimate_n),
      DoubleOption("n", &o.n),
      BoolOption("estimate_board_warp", &o.estimate_board_warp),
      DoubleOption("evidence_sigmas", &o.evidence_sigmas),
      BoolOption("weigh_views", &o.weigh_views),
      IntOption("folds", &o.folds),
      DoubleOption("huber_px", &o.huber_px),
      DoubleOption("outlier_sigmas", &o.outlier_sigmas),
      DoubleOption("min_outlier_threshold_px", &o.min_outlier_threshold_px),
      IntOption("max_outlier_rounds", &o.max_outlier_rounds),
      IntOption("max_num_iterations", &o.max_num_iterations),
      IntOption("min_corners_per_view", &o.min_corners_per_view),
      BoolOption("fit_conventional_model", &o.fit_conventional_model),
      IntOption("num_threads", &o.num_threads)};
  ApplyOptions(kwargs, fields, function);
  ThrowIfError(o.Check());
  return o;
}

// One object or a list of them (1 or 2) of the bound class T.
template <typename T>
std::vector<T> OneOrTwo(const py::handle& object, const std::string& name,
                        const std::string& type) {
  std::vector<T> items;
  if (py::isinstance<T>(object)) {
    items.push_back(object.cast<T>());
    return items;
  }
  if (!py::isinstance<py::sequence>(object) ||
      py::isinstance<py::str>(object)) {
    ThrowTypeError(name + " must be an rcm." + type + " or a list of 1 or 2");
  }
  for (const py::handle item : py::reinterpret_borrow<py::sequence>(object)) {
    if (!py::isinstance<T>(item)) {
      ThrowTypeError(name + " must hold rcm." + type + " objects");
    }
    items.push_back(item.cast<T>());
  }
  if (items.empty() || items.size() > 2) {
    ThrowValueError(name + " must hold 1 or 2 cameras' " + type + ", got " +
                    std::to_string(items.size()));
  }
  return items;
}

// The inputs of CalibrateDome from the Python arguments.
struct DomeInputs {
  std::vector<calib::DomeCameraInput> cameras;
  Rigid3d cam1_from_cam0;
};

DomeInputs DomeInputsFrom(const py::handle& lenses, const py::handle& domes,
                          const py::object& cam1_from_cam0) {
  const std::vector<Camera> cameras =
      OneOrTwo<Camera>(lenses, "cameras", "Camera");
  const std::vector<DomePort> ports =
      OneOrTwo<DomePort>(domes, "domes", "DomePort");
  if (cameras.size() != ports.size()) {
    ThrowValueError("cameras and domes differ in length (" +
                    std::to_string(cameras.size()) + " and " +
                    std::to_string(ports.size()) + ")");
  }
  DomeInputs inputs;
  for (size_t c = 0; c < cameras.size(); ++c) {
    inputs.cameras.push_back({cameras[c], ports[c]});
  }
  if (cameras.size() == 2) {
    if (cam1_from_cam0.is_none()) {
      ThrowValueError(
          "two cameras need cam1_from_cam0 (4x4, the air calibration's)");
    }
    inputs.cam1_from_cam0 = ValueOrThrow(Rigid3d::FromMatrix(
        Matrix4FromPython(cam1_from_cam0, "cam1_from_cam0")));
  } else if (!cam1_from_cam0.is_none()) {
    ThrowValueError("cam1_from_cam0 is for two cameras; one was given");
  }
  return inputs;
}

struct DomeResult {
  calib::DomeCalibration calibration;
  std::vector<std::string> notes;
};

DomeResult RunDome(const CalibrationTarget& target,
                   const std::vector<StereoView>& views,
                   const DomeInputs& inputs,
                   const calib::DomeCalibrationOptions& options) {
  StatusOr<calib::DomeCalibration> calibration = Status::Error("not run");
  {
    py::gil_scoped_release release;
    calibration = calib::CalibrateDome(views, inputs.cameras,
                                       inputs.cam1_from_cam0, target, options);
  }
  DomeResult result{ValueOrThrow(std::move(calibration)), {}};
  for (const StereoView& view : views) {
    if (!view.note.empty()) {
      result.notes.push_back(view.left_name + ": " + view.note);
    }
  }
  return result;
}

// Per camera 3-vectors as (K, 3).
DoubleArray PerCamera(const std::vector<Eigen::Vector3d>& vectors) {
  DoubleArray a = NewArray(static_cast<int64_t>(vectors.size()), 3);
  for (size_t c = 0; c < vectors.size(); ++c) {
    for (int k = 0; k < 3; ++k) a.mutable_data()[3 * c + k] = vectors[c][k];
  }
  return a;
}

DoubleArray Sigmas(const calib::CameraCalibration& c) {
  DoubleArray a(std::vector<py::ssize_t>{c.camera.num_params()});
  for (int i = 0; i < c.camera.num_params(); ++i)
    a.mutable_data()[i] = c.sigma[i];
  return a;
}

// The properties a stereo and a one-camera calibration result share (a
// Result has `calibration`, a calib::StereoCalibration, and `notes`): the
// residual statistics, the board's warp, the counts, the board poses
// (cam0_from_target: 4x4 or None per input view) and the notes.
template <typename Result>
void DefineBoardFitProperties(py::class_<Result>* result) {
  const auto number = [result](const char* name, auto member) {
    result->def_property_readonly(
        name, [member](const Result& r) { return r.calibration.*member; });
  };
  number("rms_px", &calib::StereoCalibration::rms_px);
  number("inlier_rms_px", &calib::StereoCalibration::inlier_rms_px);
  number("pixel_sigma", &calib::StereoCalibration::pixel_sigma);
  number("initial_rms_px", &calib::StereoCalibration::initial_rms_px);
  number("board_warp_estimated",
         &calib::StereoCalibration::board_warp_estimated);
  number("num_views_used", &calib::StereoCalibration::num_views_used);
  number("num_inliers", &calib::StereoCalibration::num_inliers);
  number("num_outliers", &calib::StereoCalibration::num_outliers);
  number("num_parameters", &calib::StereoCalibration::num_parameters);
  const auto matrix = [result](const char* name, auto member) {
    result->def_property_readonly(name, [member](const Result& r) {
      return ToNumpy(r.calibration.*member);
    });
  };
  matrix("board_warp", &calib::StereoCalibration::board_warp);
  matrix("board_warp_sigma", &calib::StereoCalibration::board_warp_sigma);
  matrix("board_warp_covariance",
         &calib::StereoCalibration::board_warp_covariance);
  result->def_property_readonly("cam0_from_target", [](const Result& r) {
    py::list poses;
    for (const std::optional<Rigid3d>& pose : r.calibration.cam0_from_target) {
      poses.append(pose ? py::object(ToNumpy(pose->ToMatrix()))
                        : py::object(py::none()));
    }
    return poses;
  });
  result->def_readonly("notes", &Result::notes);
}

constexpr const char* kStereoOptionsDoc = R"doc(
Keyword options (StereoCalibrationOptions): huber_px=1.0 (pixels),
outlier_sigmas=5.0, min_outlier_threshold_px=2.0, max_outlier_rounds=3,
max_num_iterations=200, use_single_camera_views=True,
min_corners_per_view=6, estimate_board_warp=True (the board's bow, two
parameters shared by all views, mrcal's calobject_warp), compute_covariance=True,
num_threads=2.
)doc";

constexpr const char* kUnderwaterOptionsDoc = R"doc(
Keyword options (UnderwaterCalibrationOptions): initial_n=1.34,
estimate_air_gap=False, estimate_port_tilt=False, huber_px=1.0,
outlier_sigmas=5.0, min_outlier_threshold_px=2.0, max_outlier_rounds=3,
max_num_iterations=200, use_single_camera_views=True,
min_corners_per_view=6, estimate_board_warp=True, folds=10 (leave-out
replicates; 0 or 1: none),
fit_conventional_model=True, num_threads=2.
)doc";

}  // namespace

void BindCalibration(py::module_& module) {
  py::class_<CalibrationTarget>(module, "CalibrationTarget", R"doc(
A planar calibration target (Kalibr's target YAML). Build one with
CalibrationTarget.checkerboard(cols, rows, square) (INNER corners, square
edge in meters), .aprilgrid(cols, rows, tag_size, tag_spacing) (tags, edge
in meters, gap as a fraction of the tag), .charuco(squares_x, squares_y,
square, marker, dictionary='DICT_6X6_250'), or read_calibration_target(path).
points: the (N, 3) target points in the target frame (z = 0), meters, in
point-id order.
)doc")
      .def_static(
          "checkerboard",
          [](int cols, int rows, double square) {
            return ValueOrThrow(
                calib::MakeCheckerboardTarget(cols, rows, square));
          },
          py::arg("cols"), py::arg("rows"), py::arg("square"))
      .def_static(
          "aprilgrid",
          [](int cols, int rows, double tag_size, double tag_spacing) {
            return ValueOrThrow(
                calib::MakeAprilGridTarget(cols, rows, tag_size, tag_spacing));
          },
          py::arg("cols"), py::arg("rows"), py::arg("tag_size"),
          py::arg("tag_spacing"))
      .def_static(
          "charuco",
          [](int squares_x, int squares_y, double square, double marker,
             const std::string& dictionary) {
            return ValueOrThrow(calib::MakeCharucoTarget(
                squares_x, squares_y, square, marker, dictionary));
          },
          py::arg("squares_x"), py::arg("squares_y"), py::arg("square"),
          py::arg("marker"), py::arg("dictionary") = "DICT_6X6_250")
      .def_property_readonly("points",
                             [](const CalibrationTarget& t) {
                               const std::vector<Eigen::Vector3d> points =
                                   calib::TargetPoints(t);
                               DoubleArray a = NewArray(points.size(), 3);
                               for (size_t i = 0; i < points.size(); ++i) {
                                 for (int k = 0; k < 3; ++k) {
                                   a.mutable_data()[3 * i + k] = points[i][k];
                                 }
                               }
                               return a;
                             })
      .def_readonly("cols", &CalibrationTarget::cols)
      .def_readonly("rows", &CalibrationTarget::rows)
      .def("__repr__", [](const CalibrationTarget& t) {
        return "CalibrationTarget(" + calib::DescribeTarget(t) + ")";
      });

  module.def(
      "read_calibration_target",
      [](const py::object& path) {
        const std::string file = PathFromPython(path);
        return ReadOrThrow(file, calib::ReadCalibrationTarget(file));
      },
      py::arg("path"), "Reads a Kalibr target YAML (OSError / ValueError).");

  module.def(
      "render_target",
      [](const Camera& camera, const CalibrationTarget& target,
         const py::object& cam_from_target, int supersampling,
         double blur_sigma_px, double noise_sigma, const py::object& seed,
         double pixels_per_metre) {
        const Rigid3d pose = ValueOrThrow(Rigid3d::FromMatrix(
            Matrix4FromPython(cam_from_target, "cam_from_target")));
        calib::TargetRenderOptions options;
        options.supersampling = supersampling;
        options.blur_sigma_px = blur_sigma_px;
        options.noise_sigma = noise_sigma;
        options.seed = SeedFromPython(seed, "seed");
        ThrowIfError(options.Check());
        // DrawTargetImage CHECKs the texture's size: refuse a density that
        // would exceed it (the board's extent plus its quiet zone).
        const std::vector<Eigen::Vector3d> points = calib::TargetPoints(target);
        Eigen::Vector2d low = points[0].head<2>();
        Eigen::Vector2d high = low;
        for (const Eigen::Vector3d& p : points) {
          low = low.cwiseMin(p.head<2>());
          high = high.cwiseMax(p.head<2>());
        }
        const Eigen::Vector2d extent = 2.0 * (high - low).cwiseMax(1e-3);
        if (!(pixels_per_metre > 0.0) || !std::isfinite(pixels_per_metre) ||
            extent.x() * extent.y() * pixels_per_metre * pixels_per_metre >
                1e8) {
          ThrowValueError(
              "pixels_per_metre must be > 0 and keep the texture "
              "below 1e8 pixels");
        }
        const calib::TargetRenderer renderer =
            ValueOrThrow(calib::TargetRenderer::Create(
                camera, calib::DrawTargetImage(target, pixels_per_metre)));
        cv::Mat image;
        {
          py::gil_scoped_release release;
          image = renderer.Render(pose, options);
        }
        return ImageToNumpy(image);
      },
      py::arg("camera"), py::arg("target"), py::arg("cam_from_target"),
      py::kw_only(), py::arg("supersampling") = 4,
      py::arg("blur_sigma_px") = 0.0, py::arg("noise_sigma") = 0.0,
      py::arg("seed") = 0, py::arg("pixels_per_metre") = 4000.0,
      R"doc(
A synthetic 8-bit image (uint8 (H, W)) of the target seen in air by an
rcm.Camera at cam_from_target (4x4, meters; target points map into the
camera frame). supersampling: sub-samples per pixel axis (1..16);
blur_sigma_px: Gaussian blur, pixels; noise_sigma: gray levels.
)doc");

  py::class_<StereoCalibrationResult> stereo_result(module,
                                                    "StereoCalibrationResult",
                                                    R"doc(
The result of calibrate_stereo: rig (rcm.StereoRig, cam1_from_cam0 in
meters), rms_px (over all corners of used views, as cv2.stereoCalibrate's),
inlier_rms_px, pixel_sigma (estimated corner noise, pixels), initial_rms_px
(OpenCV's initialization), baseline and baseline_sigma (meters), cam0_sigma
and cam1_sigma (standard deviations of [fx, fy, cx, cy, d...]),
extrinsics_covariance (6x6, [w; t] in rad and m), num_views_used,
num_stereo_views, num_inliers, num_outliers, num_parameters,
cam0_from_target (per input view: 4x4 or None), board_warp_estimated,
board_warp ([warp_x, warp_y], meters: the board's bow, zero when not
estimated; the bowl at the centre is their sum), board_warp_sigma (meters),
board_warp_covariance (2x2), notes (why views were dropped).
)doc");
  DefineBoardFitProperties(&stereo_result);
  stereo_result
      .def_property_readonly(
          "rig", [](const StereoCalibrationResult& r) { return r.rig; })
      .def_property_readonly("baseline",
                             [](const StereoCalibrationResult& r) {
                               return r.calibration.baseline;
                             })
      .def_property_readonly("baseline_sigma",
                             [](const StereoCalibrationResult& r) {
                               return r.calibration.baseline_sigma;
                             })
      .def_property_readonly("cam0_sigma",
                             [](const StereoCalibrationResult& r) {
                               return Sigmas(r.calibration.cam0);
                             })
      .def_property_readonly("cam1_sigma",
                             [](const StereoCalibrationResult& r) {
                               return Sigmas(r.calibration.cam1);
                             })
      .def_property_readonly(
          "extrinsics_covariance",
          [](const StereoCalibrationResult& r) {
            return ToNumpy(r.calibration.extrinsics_covariance);
          })
      .def_property_readonly("num_stereo_views",
                             [](const StereoCalibrationResult& r) {
                               return r.calibration.num_stereo_views;
                             })
      .def("__repr__", [](const StereoCalibrationResult& r) {
        return "StereoCalibrationResult(rms_px=" +
               std::to_string(r.calibration.rms_px) +
               ", views_used=" + std::to_string(r.calibration.num_views_used) +
               ", baseline=" + std::to_string(r.calibration.baseline) + " m)";
      });

  static const std::string stereo_doc = std::string(R"doc(
Air stereo calibration by bundle adjustment over views of a planar target
(C++ rcm::calib::CalibrateStereo).

calibrate_stereo(target, left_images, right_images, model='radtan', **options)
    images: equal-length lists of NumPy uint8 arrays (gray, BGR) or file
    paths; the target is detected in each pair (GIL released).
Returns a StereoCalibrationResult. ValueError with the library's message
when no view shows the target in both cameras, a camera has fewer than 3
usable views, and so on.
)doc") + kStereoOptionsDoc;
  module.def(
      "calibrate_stereo",
      [](const CalibrationTarget& target, const py::sequence& left_images,
         const py::sequence& right_images, const std::string& model,
         const py::kwargs& kwargs) {
        const calib::StereoCalibrationOptions options =
            StereoOptionsFrom(model, kwargs);
        const Detections detections = Detect(target, left_images, right_images);
        return RunStereo(target, detections.views, detections.sizes[0],
                         detections.sizes[1], options);
      },
      py::arg("target"), py::arg("left_images"), py::arg("right_images"),
      py::arg("model") = "radtan", stereo_doc.c_str());

  static const std::string stereo_corners_doc = std::string(R"doc(
calibrate_stereo from corner observations instead of images.

views: a list of (left, right) per view, each None or (point_ids (M,) ints,
pixels (M, 2) raw pixels), point ids indexing target.points; cam0_size,
cam1_size: (width, height) in pixels.
)doc") + kStereoOptionsDoc;
  module.def(
      "calibrate_stereo_from_corners",
      [](const CalibrationTarget& target, const py::sequence& views,
         const std::pair<int, int>& cam0_size,
         const std::pair<int, int>& cam1_size, const std::string& model,
         const py::kwargs& kwargs) {
        const calib::StereoCalibrationOptions options =
            StereoOptionsFrom(model, kwargs);
        return RunStereo(target, ViewsFromCorners(target, views),
                         SizeFrom(cam0_size), SizeFrom(cam1_size), options);
      },
      py::arg("target"), py::arg("views"), py::arg("cam0_size"),
      py::arg("cam1_size"), py::arg("model") = "radtan",
      stereo_corners_doc.c_str());

  py::class_<MonoCalibrationResult> mono_result(module, "MonoCalibrationResult",
                                                R"doc(
The result of calibrate_mono: camera (rcm.Camera, the calibrated lens),
sigma (standard deviations of [fx, fy, cx, cy, d...]: pixels for the
first four, the coefficients' own units after), covariance (their n x n
covariance, sigma^2 (J^T J)^-1 of the final least squares), rms_px (over
all corners of used views, as cv2.calibrateCamera's), inlier_rms_px,
pixel_sigma (estimated corner noise, pixels per axis), initial_rms_px
(OpenCV's initialization), num_views_used, num_inliers, num_outliers,
num_parameters, cam0_from_target (per input view: the camera from the
target, 4x4 in meters, or None), board_warp_estimated, board_warp
([warp_x, warp_y], meters), board_warp_sigma (meters),
board_warp_covariance (2x2, m^2), notes (why views were dropped).
)doc");
  DefineBoardFitProperties(&mono_result);
  mono_result
      .def_property_readonly("camera",
                             [](const MonoCalibrationResult& r) {
                               return r.calibration.cam0.camera;
                             })
      .def_property_readonly("sigma",
                             [](const MonoCalibrationResult& r) {
                               return Sigmas(r.calibration.cam0);
                             })
      .def_property_readonly(
          "covariance",
          [](const MonoCalibrationResult& r) {
            const int n = r.calibration.cam0.camera.num_params();
            return ToNumpy(
                r.calibration.cam0.covariance.topLeftCorner(n, n).eval());
          })
      .def("__repr__", [](const MonoCalibrationResult& r) {
        return "MonoCalibrationResult(rms_px=" +
               std::to_string(r.calibration.rms_px) +
               ", views_used=" + std::to_string(r.calibration.num_views_used) +
               ", fx=" + std::to_string(r.calibration.cam0.camera.fx()) +
               " px)";
      });

  static const std::string mono_doc = std::string(R"doc(
One camera's calibration in air by bundle adjustment over views of a
planar target (C++ rcm::calib::CalibrateMono; rcm calibrate --left alone):
the lens, every board pose and (by default) the board's bow, Huber solves
with outlier rounds, then plain least squares.

calibrate_mono(target, images, model='radtan', **options)
    images: a list of NumPy uint8 arrays (gray, BGR) or file paths, all of
    one size; the target is detected in each (GIL released).
Returns a MonoCalibrationResult. ValueError with the library's message
when fewer than 3 images show the target, and so on. With
estimate_board_warp=False and model='radtan' it is cv2.calibrateCamera's
model (k3 fixed to 0) on the same corners.
)doc") + kStereoOptionsDoc + "use_single_camera_views does not apply.";
  module.def(
      "calibrate_mono",
      [](const CalibrationTarget& target, const py::sequence& images,
         const std::string& model, const py::kwargs& kwargs) {
        const calib::StereoCalibrationOptions options =
            StereoOptionsFrom(model, kwargs, "calibrate_mono");
        const Detections detections = Detect(target, images, py::none());
        return RunMono(target, detections.views, detections.sizes[0], options);
      },
      py::arg("target"), py::arg("images"), py::arg("model") = "radtan",
      mono_doc.c_str());

  static const std::string mono_corners_doc = std::string(R"doc(
calibrate_mono from corner observations instead of images.

views: a list with, per view, None or (point_ids (M,) ints, pixels (M, 2)
raw pixels), point ids indexing target.points; image_size: (width, height)
in pixels.
)doc") + kStereoOptionsDoc;
  module.def(
      "calibrate_mono_from_corners",
      [](const CalibrationTarget& target, const py::sequence& views,
         const std::pair<int, int>& image_size, const std::string& model,
         const py::kwargs& kwargs) {
        const calib::StereoCalibrationOptions options =
            StereoOptionsFrom(model, kwargs, "calibrate_mono_from_corners");
        return RunMono(target,
                       ViewsFromCorners(target, views, /*one_camera=*/true),
                       SizeFrom(image_size), options);
      },
      py::arg("target"), py::arg("views"), py::arg("image_size"),
      py::arg("model") = "radtan", mono_corners_doc.c_str());

  py::class_<UnderwaterResult>(module, "UnderwaterCalibrationResult", R"doc(
The result of calibrate_underwater: n, sigma_n (from the covariance),
sigma_n_leave_out (or None), rig (the air lenses with the refined
cam1_from_cam0 and ports: what the other tools take), extrinsics_estimated,
extrinsic_change (dict: rotation_deg, angle_deg, translation_mm and their
sigmas), ports (two dicts: port, air_gap_estimated, air_gap_sigma (m),
tilt_estimated, tilt_deg), rms_px, inlier_rms_px, pixel_sigma,
initial_rms_px, num_views_used, num_stereo_views, num_inliers,
num_outliers, num_parameters, board_warp_estimated, board_warp and
board_warp_sigma (meters, as calibrate_stereo's), notes.
)doc")
      .def_property_readonly(
          "n", [](const UnderwaterResult& r) { return r.calibration.n; })
      .def_property_readonly(
          "sigma_n",
          [](const UnderwaterResult& r) { return r.calibration.sigma_n; })
      .def_property_readonly(
          "sigma_n_leave_out",
          [](const UnderwaterResult& r) -> py::object {
            if (!r.calibration.sigma_n_leave_out) return py::none();
            return py::float_(*r.calibration.sigma_n_leave_out);
          })
      .def_property_readonly(
          "rig", [](const UnderwaterResult& r) { return r.calibration.rig; })
      .def_property_readonly("extrinsics_estimated",
                             [](const UnderwaterResult& r) {
                               return r.calibration.extrinsics_estimated;
                             })
      .def_property_readonly("board_warp_estimated",
                             [](const UnderwaterResult& r) {
                               return r.calibration.board_warp_estimated;
                             })
      .def_property_readonly("board_warp",
                             [](const UnderwaterResult& r) {
                               return ToNumpy(r.calibration.board_warp);
                             })
      .def_property_readonly("board_warp_sigma",
                             [](const UnderwaterResult& r) {
                               return ToNumpy(r.calibration.board_warp_sigma);
                             })
      .def_property_readonly(
          "extrinsic_change",
          [](const UnderwaterResult& r) {
            const calib::ExtrinsicChange& c = r.calibration.extrinsic_change;
            py::dict d;
            d["rotation_deg"] = ToNumpy(c.rotation_deg);
            d["rotation_sigma_deg"] = ToNumpy(c.rotation_sigma_deg);
            d["angle_deg"] = c.angle_deg;
            d["angle_sigma_deg"] = c.angle_sigma_deg;
            d["translation_mm"] = ToNumpy(c.translation_mm);
            d["translation_sigma_mm"] = ToNumpy(c.translation_sigma_mm);
            return d;
          })
      .def_property_readonly(
          "ports",
          [](const UnderwaterResult& r) {
            py::list ports;
            for (const calib::PortEstimate& p : r.calibration.ports) {
              py::dict d;
              d["port"] = p.port;
              d["air_gap_estimated"] = p.air_gap_estimated;
              d["air_gap_sigma"] = p.air_gap_sigma;
              d["tilt_estimated"] = p.tilt_estimated;
              d["tilt_deg"] = p.tilt_deg;
              ports.append(d);
            }
            return ports;
          })
      .def_property_readonly(
          "rms_px",
          [](const UnderwaterResult& r) { return r.calibration.rms_px; })
      .def_property_readonly(
          "inlier_rms_px",
          [](const UnderwaterResult& r) { return r.calibration.inlier_rms_px; })
      .def_property_readonly(
          "pixel_sigma",
          [](const UnderwaterResult& r) { return r.calibration.pixel_sigma; })
      .def_property_readonly("initial_rms_px",
                             [](const UnderwaterResult& r) {
                               return r.calibration.initial_rms_px;
                             })
      .def_property_readonly("num_views_used",
                             [](const UnderwaterResult& r) {
                               return r.calibration.num_views_used;
                             })
      .def_property_readonly("num_stereo_views",
                             [](const UnderwaterResult& r) {
                               return r.calibration.num_stereo_views;
                             })
      .def_property_readonly(
          "num_inliers",
          [](const UnderwaterResult& r) { return r.calibration.num_inliers; })
      .def_property_readonly(
          "num_outliers",
          [](const UnderwaterResult& r) { return r.calibration.num_outliers; })
      .def_property_readonly("num_parameters",
                             [](const UnderwaterResult& r) {
                               return r.calibration.num_parameters;
                             })
      .def_readonly("notes", &UnderwaterResult::notes)
      .def("__repr__", [](const UnderwaterResult& r) {
        return "UnderwaterCalibrationResult(n=" +
               std::to_string(r.calibration.n) +
               ", sigma_n=" + std::to_string(r.calibration.sigma_n) +
               ", rms_px=" + std::to_string(r.calibration.rms_px) + ")";
      });

  static const std::string underwater_doc = std::string(R"doc(
The underwater target refinement (C++ rcm::calib::CalibrateUnderwater; rcm
calibrate --underwater): n, cam1_from_cam0 and the board poses (optionally
the air gaps and port tilts) from views of the target in water, with the
air rig's lenses held.

calibrate_underwater(target, left_images, right_images, air_rig, **options)
    images: lists of NumPy uint8 arrays or paths, each of its air camera's
    size. Returns an UnderwaterCalibrationResult.
)doc") + kUnderwaterOptionsDoc;
  module.def(
      "calibrate_underwater",
      [](const CalibrationTarget& target, const py::sequence& left_images,
         const py::sequence& right_images, const StereoRig& air_rig,
         const py::kwargs& kwargs) {
        const calib::UnderwaterCalibrationOptions options =
            UnderwaterOptionsFrom(kwargs);
        const Detections detections = Detect(target, left_images, right_images);
        return RunUnderwater(target, detections.views, detections.sizes[0],
                             detections.sizes[1], air_rig, options);
      },
      py::arg("target"), py::arg("left_images"), py::arg("right_images"),
      py::arg("air_rig"), underwater_doc.c_str());

  static const std::string underwater_corners_doc = std::string(R"doc(
calibrate_underwater from corner observations (views as in
calibrate_stereo_from_corners; the image sizes are the air rig's).
)doc") + kUnderwaterOptionsDoc;
  module.def(
      "calibrate_underwater_from_corners",
      [](const CalibrationTarget& target, const py::sequence& views,
         const StereoRig& air_rig, const py::kwargs& kwargs) {
        const calib::UnderwaterCalibrationOptions options =
            UnderwaterOptionsFrom(kwargs);
        return RunUnderwater(
            target, ViewsFromCorners(target, views),
            {air_rig.left().width(), air_rig.left().height()},
            {air_rig.right().width(), air_rig.right().height()}, air_rig,
            options);
      },
      py::arg("target"), py::arg("views"), py::arg("air_rig"),
      underwater_corners_doc.c_str());

  py::class_<DomeResult>(module, "DomeCalibrationResult", R"doc(
The result of calibrate_dome: per camera (K = 1 or 2) decentering (K, 3),
the dome's centre in the camera frame, meters; decentering_sigma (K, 3),
total (noise and the spread over candidate board models), meters;
decentering_sigma_model (K, 3), the spread alone; decentering_covariance
(K, 3, 3), m^2; n (estimated or held), sigma_n (total, 0 when held),
sigma_n_model, n_estimated, correlation_n_decentering (K, 3); rms_px (all
corners that project), inlier_rms_px, rms_px_per_camera (K,), pixel_sigma
(corner noise per axis), conventional_rms_px (a conventional lens fitted
freely to the same corners, no dome; None when not fitted or failed),
conventional (dict: ok, error, model, rms_px, inlier_rms_px, pixel_sigma,
num_parameters), candidates (list of dicts: name, board_warp,
decentering (K, 3), decentering_sigma (K, 3), n, sigma_n, rms_px,
pixel_sigma, evidence, plausible), chosen (index), rule (one line),
board_warp_estimated, board_warp and board_warp_sigma (meters),
cam0_from_target (per input view 4x4 meters or None), num_views_used,
num_inliers, num_outliers, num_parameters, num_outlier_views (dropped
whole), view_weights (V,) (per input view, its corners' weight relative to
the median view's; 0 when not used), notes.
)doc")
      .def_property_readonly("decentering",
                             [](const DomeResult& r) {
                               return PerCamera(r.calibration.decentering);
                             })
      .def_property_readonly(
          "decentering_sigma",
          [](const DomeResult& r) {
            return PerCamera(r.calibration.decentering_sigma);
          })
      .def_property_readonly(
          "decentering_sigma_model",
          [](const DomeResult& r) {
            return PerCamera(r.calibration.decentering_sigma_model);
          })
      .def_property_readonly(
          "decentering_covariance",
          [](const DomeResult& r) {
            const auto& covariances = r.calibration.decentering_covariance;
            DoubleArray a(std::vector<py::ssize_t>{
                static_cast<py::ssize_t>(covariances.size()), 3, 3});
            for (size_t c = 0; c < covariances.size(); ++c) {
              for (int i = 0; i < 3; ++i) {
                for (int j = 0; j < 3; ++j) {
                  a.mutable_data()[9 * c + 3 * i + j] = covariances[c](i, j);
                }
              }
            }
            return a;
          })
      .def_property_readonly(
          "correlation_n_decentering",
          [](const DomeResult& r) {
            return PerCamera(r.calibration.correlation_n_decentering);
          })
      .def_property_readonly(
          "n", [](const DomeResult& r) { return r.calibration.n; })
      .def_property_readonly(
          "sigma_n", [](const DomeResult& r) { return r.calibration.sigma_n; })
      .def_property_readonly(
          "sigma_n_model",
          [](const DomeResult& r) { return r.calibration.sigma_n_model; })
      .def_property_readonly(
          "n_estimated",
          [](const DomeResult& r) { return r.calibration.n_estimated; })
      .def_property_readonly(
          "rms_px", [](const DomeResult& r) { return r.calibration.rms_px; })
      .def_property_readonly(
          "inlier_rms_px",
          [](const DomeResult& r) { return r.calibration.inlier_rms_px; })
      .def_property_readonly(
          "rms_px_per_camera",
          [](const DomeResult& r) { return r.calibration.rms_px_per_camera; })
      .def_property_readonly(
          "pixel_sigma",
          [](const DomeResult& r) { return r.calibration.pixel_sigma; })
      .def_property_readonly("conventional_rms_px",
                             [](const DomeResult& r) -> py::object {
                               const calib::ConventionalFit& f =
                                   r.calibration.conventional;
                               if (!f.ok) return py::none();
                               return py::float_(f.rms_px);
                             })
      .def_property_readonly("conventional",
                             [](const DomeResult& r) {
                               const calib::ConventionalFit& f =
                                   r.calibration.conventional;
                               py::dict d;
                               d["ok"] = f.ok;
                               d["error"] = f.error;
                               d["model"] = std::string(LensModelName(f.model));
                               d["rms_px"] = f.rms_px;
                               d["inlier_rms_px"] = f.inlier_rms_px;
                               d["pixel_sigma"] = f.pixel_sigma;
                               d["num_parameters"] = f.num_parameters;
                               return d;
                             })
      .def_property_readonly(
          "candidates",
          [](const DomeResult& r) {
            py::list list;
            for (const calib::DomeCandidate& c : r.calibration.candidates) {
              py::dict d;
              d["name"] = c.name;
              d["board_warp"] = c.board_warp;
              d["decentering"] = PerCamera(c.decentering);
              d["decentering_sigma"] = PerCamera(c.decentering_sigma);
              d["n"] = c.n;
              d["sigma_n"] = c.sigma_n;
              d["rms_px"] = c.rms_px;
              d["pixel_sigma"] = c.pixel_sigma;
              d["evidence"] = c.evidence;
              d["plausible"] = c.plausible;
              list.append(d);
            }
            return list;
          })
      .def_property_readonly(
          "chosen", [](const DomeResult& r) { return r.calibration.chosen; })
      .def_property_readonly(
          "rule", [](const DomeResult& r) { return r.calibration.rule; })
      .def_property_readonly("board_warp_estimated",
                             [](const DomeResult& r) {
                               return r.calibration.board_warp_estimated;
                             })
      .def_property_readonly(
          "board_warp",
          [](const DomeResult& r) { return ToNumpy(r.calibration.board_warp); })
      .def_property_readonly("board_warp_sigma",
                             [](const DomeResult& r) {
                               return ToNumpy(r.calibration.board_warp_sigma);
                             })
      .def_property_readonly(
          "cam0_from_target",
          [](const DomeResult& r) {
            py::list poses;
            for (const auto& pose : r.calibration.cam0_from_target) {
              if (pose) {
                poses.append(ToNumpy(pose->ToMatrix()));
              } else {
                poses.append(py::none());
              }
            }
            return poses;
          })
      .def_property_readonly(
          "num_views_used",
          [](const DomeResult& r) { return r.calibration.num_views_used; })
      .def_property_readonly(
          "num_inliers",
          [](const DomeResult& r) { return r.calibration.num_inliers; })
      .def_property_readonly(
          "num_outliers",
          [](const DomeResult& r) { return r.calibration.num_outliers; })
      .def_property_readonly(
          "num_parameters",
          [](const DomeResult& r) { return r.calibration.num_parameters; })
      .def_property_readonly(
          "num_outlier_views",
          [](const DomeResult& r) { return r.calibration.num_outlier_views; })
      .def_property_readonly("view_weights",
                             [](const DomeResult& r) {
                               const std::vector<double>& w =
                                   r.calibration.view_weights;
                               return py::array_t<double>(w.size(), w.data());
                             })
      .def_readonly("notes", &DomeResult::notes)
      .def("__repr__", [](const DomeResult& r) {
        std::ostringstream text;
        text << "DomeCalibrationResult(decentering_mm=[";
        for (size_t c = 0; c < r.calibration.decentering.size(); ++c) {
          const Eigen::Vector3d mm = 1e3 * r.calibration.decentering[c];
          text << (c ? ", " : "") << "[" << mm.x() << ", " << mm.y() << ", "
               << mm.z() << "]";
        }
        text << "], n=" << r.calibration.n
             << ", rms_px=" << r.calibration.rms_px << ")";
        return text.str();
      });

  static const char* const kDomeOptionsDoc = R"doc(
Options (keywords, C++ rcm::calib::DomeCalibrationOptions): estimate_n
(False: n held), n (the medium's index, held or the start, default 1.333),
estimate_board_warp (True: the bowed board beside the flat one),
evidence_sigmas (3), weigh_views (True: each view weighed by its own
corner noise), folds (10: the leave-views-out groups of the sigma; 0:
the covariance alone), huber_px (1), outlier_sigmas (5),
min_outlier_threshold_px (2), max_outlier_rounds (3), max_num_iterations
(200), min_corners_per_view (6), fit_conventional_model (True),
num_threads (2).
)doc";
  static const std::string dome_doc = std::string(R"doc(
The underwater calibration through dome ports (C++
rcm::calib::CalibrateDome; rcm calibrate --underwater --port dome): each
dome's decentering (and n with estimate_n) from views of a planar target in
water, with the air lenses held.

calibrate_dome(target, images, cameras, domes, right_images=None,
               cam1_from_cam0=None, **options)
    images: a list of NumPy uint8 arrays or paths (the first camera's);
    right_images: the second camera's, for two cameras. cameras: an
    rcm.Camera (the air calibration) or a list of 1 or 2; domes: an
    rcm.DomePort or a list, one per camera (radii and glass; the
    decentering is the start); cam1_from_cam0: 4x4 (meters), the air
    calibration's extrinsics, for two cameras.
Returns a DomeCalibrationResult. ValueError with the library's message for
fewer than 3 usable views, a dome that fails its check, and so on.
)doc") + kDomeOptionsDoc;
  module.def(
      "calibrate_dome",
      [](const CalibrationTarget& target, const py::sequence& images,
         const py::object& cameras, const py::object& domes,
         const py::object& right_images, const py::object& cam1_from_cam0,
         const py::kwargs& kwargs) {
        const calib::DomeCalibrationOptions options =
            DomeOptionsFrom(kwargs, "calibrate_dome");
        const DomeInputs inputs =
            DomeInputsFrom(cameras, domes, cam1_from_cam0);
        if ((inputs.cameras.size() == 2) == right_images.is_none()) {
          ThrowValueError(
              "right_images go with two cameras, and only with two");
        }
        const Detections detections = Detect(target, images, right_images);
        return RunDome(target, detections.views, inputs, options);
      },
      py::arg("target"), py::arg("images"), py::arg("cameras"),
      py::arg("domes"), py::arg("right_images") = py::none(),
      py::arg("cam1_from_cam0") = py::none(), dome_doc.c_str());

  static const std::string dome_corners_doc = std::string(R"doc(
calibrate_dome from corner observations instead of images.

calibrate_dome_from_corners(target, views, cameras, domes,
                            cam1_from_cam0=None, **options)
    views: per view, for one camera None or (point_ids (M,) ints, pixels
    (M, 2) raw pixels); for two cameras (left corners, right corners), each
    None or such a pair. Point ids index target.points.
)doc") + kDomeOptionsDoc;
  module.def(
      "calibrate_dome_from_corners",
      [](const CalibrationTarget& target, const py::sequence& views,
         const py::object& cameras, const py::object& domes,
         const py::object& cam1_from_cam0, const py::kwargs& kwargs) {
        const calib::DomeCalibrationOptions options =
            DomeOptionsFrom(kwargs, "calibrate_dome_from_corners");
        const DomeInputs inputs =
            DomeInputsFrom(cameras, domes, cam1_from_cam0);
        return RunDome(
            target,
            ViewsFromCorners(target, views,
                             /*one_camera=*/inputs.cameras.size() == 1),
            inputs, options);
      },
      py::arg("target"), py::arg("views"), py::arg("cameras"), py::arg("domes"),
      py::arg("cam1_from_cam0") = py::none(), dome_corners_doc.c_str());
}

}  // namespace rcm::python
