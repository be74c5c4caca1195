// rcm.Estimate (C++ RefractiveIndexEstimate), the one estimate type, and
// rcm.estimate_refractive_index (C++ EstimateRefractiveIndex), the function
// `rcm estimate` runs on its matches. Estimate.to_dict() is the library's
// JSON (rcm/estimation/estimate_json.h) read by Python's json module: its
// keys, and the attributes of the same names, mean what `rcm estimate
// --json` prints under them.
#include <pybind11/stl.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <string>
#include <vector>

#include "bindings.h"
#include "conversions.h"
#include "errors.h"
#include "options.h"
#include "rcm/estimation/estimate_json.h"
#include "rcm/estimation/estimate_refractive_index.h"
#include "rcm/estimation/refractive_index_estimate.h"

namespace rcm::python {

namespace {

py::dict EstimateDict(const RefractiveIndexEstimate& estimate) {
  return py::module_::import("json")
      .attr("loads")(EstimateJson(estimate, -1))
      .cast<py::dict>();
}

// One key of the JSON, so that the attribute and the key are one value;
// None for a key the estimator leaves out.
py::object Key(const RefractiveIndexEstimate& estimate, const char* key) {
  const py::dict d = EstimateDict(estimate);
  return d.contains(key) ? py::object(d[key]) : py::none();
}

py::dict PerFrameArrays(const RefractiveIndexEstimate& estimate) {
  const py::ssize_t size = static_cast<py::ssize_t>(estimate.per_frame.size());
  py::array_t<int64_t> frame(size);
  py::array_t<double> t(size), n(size), sigma_n(size);
  py::array_t<bool> medium_switch(size);
  for (py::ssize_t i = 0; i < size; ++i) {
    const FrameEstimateRow& row = estimate.per_frame[i];
    frame.mutable_data()[i] = row.frame;
    t.mutable_data()[i] = row.timestamp.value_or(RefractiveIndexEstimate::kNaN);
    n.mutable_data()[i] = row.n;
    sigma_n.mutable_data()[i] = row.sigma_n;
    medium_switch.mutable_data()[i] = row.medium_switch;
  }
  py::dict d;
  d["frame"] = frame;
  d["t"] = t;
  d["n"] = n;
  d["sigma_n"] = sigma_n;
  d["switch"] = medium_switch;
  return d;
}

RefractiveIndexEstimate Estimate(const py::object& rig_object,
                                 const py::object& matches,
                                 const std::string& estimator,
                                 int window_frames, double change_threshold,
                                 double mask_eta, bool estimate_air_gap,
                                 bool per_frame_estimates,
                                 const py::kwargs& kwargs) {
  const StereoRig rig = RigFromPython(rig_object);
  EstimationOptions options;
  const std::optional<EstimatorKind> kind = EstimatorFromName(estimator);
  if (!kind) {
    ThrowValueError(
        "unknown estimator '" + estimator +
        "' (available: refine, online, window, closed-form, bundle)");
  }
  options.estimator = *kind;
  ApplyRefinementOptions(kwargs, &options.refinement,
                         "estimate_refractive_index");
  options.window.SetWindowFrames(window_frames);
  options.window.change_threshold = change_threshold;
  options.closed_form.eta = mask_eta;
  options.estimate_air_gap = estimate_air_gap;
  options.per_frame_estimates = per_frame_estimates;
  ThrowIfError(options.Check());
  std::vector<StereoCorrespondence> list =
      MatchesFromPython(matches, "matches");
  if (list.empty()) {
    ThrowValueError("matches is empty: at least one correspondence is needed");
  }
  // Frames in time order, the matches of a frame in input order (as
  // `rcm estimate --matches`).
  std::stable_sort(
      list.begin(), list.end(),
      [](const StereoCorrespondence& a, const StereoCorrespondence& b) {
        return a.frame < b.frame;
      });
  StatusOr<RefractiveIndexEstimate> estimate = Status::Error("not run");
  {
    py::gil_scoped_release release;
    estimate = EstimateRefractiveIndex(rig, SplitFrames(list), options);
  }
  return ValueOrThrow(std::move(estimate));
}

}  // namespace

void BindEstimate(py::module_& module) {
  using E = RefractiveIndexEstimate;
  py::class_<E>(module, "Estimate", R"doc(
An estimate of n as every estimator reports it (C++ RefractiveIndexEstimate):
the same fields, under the same names, as `rcm estimate --json` prints.

n; sigma_n (total standard deviation) and its parts sigma_n_noise (pixel
noise, inflated when the frames disagree), sigma_n_calibration (the
camchain's uncertainty carried into n) and sigma_n_systematic (the matches'
systematic field), NaN where an estimator has none; systematic_px (pixels,
the floor assumed); crlb (Cramer-Rao bound, the calibration exact);
sigma_px (pixels); n_closed_form; inliers, invalid, correspondences, frames.
Blocks as dicts (None when absent): calibration, systematic_field,
consistency, rotation (degrees), focal_scale (percent), air_gap (metres).
trajectory (bundle): (N, 8) array [t, tx, ty, tz, qx, qy, qz, qw].
warnings: one line each (a stale calibration, n and the rotation hardly
separable, ...). per_frame: dict of arrays frame, t, n, sigma_n, switch.
to_dict() gives the JSON object; to_json() its text.
)doc")
      .def_readonly("estimator", &E::estimator)
      .def_readonly("port", &E::port)
      .def_readonly("method", &E::method)
      .def_readonly("n", &E::n)
      .def_readonly("sigma_n", &E::sigma_n)
      .def_readonly("sigma_n_noise", &E::sigma_n_noise)
      .def_readonly("sigma_n_calibration", &E::sigma_n_calibration)
      .def_readonly("sigma_n_systematic", &E::sigma_n_systematic)
      .def_readonly("systematic_px", &E::systematic_px)
      .def_readonly("crlb", &E::crlb)
      .def_readonly("sigma_px", &E::sigma_px)
      .def_property_readonly("n_closed_form",
                             [](const E& e) { return Key(e, "n_closed_form"); })
      .def_readonly("inliers", &E::inliers)
      .def_readonly("invalid", &E::invalid)
      .def_readonly("correspondences", &E::correspondences)
      .def_readonly("frames", &E::frames)
      .def_property_readonly("calibration",
                             [](const E& e) { return Key(e, "calibration"); })
      .def_property_readonly(
          "systematic_field",
          [](const E& e) { return Key(e, "systematic_field"); })
      .def_property_readonly("consistency",
                             [](const E& e) { return Key(e, "consistency"); })
      .def_property_readonly("rotation",
                             [](const E& e) { return Key(e, "rotation"); })
      .def_property_readonly("focal_scale",
                             [](const E& e) { return Key(e, "focal_scale"); })
      .def_property_readonly("air_gap",
                             [](const E& e) { return Key(e, "air_gap"); })
      .def_property_readonly(
          "trajectory",
          [](const E& e) -> py::object {
            if (!e.bundle) return py::none();
            const std::vector<BundlePose>& poses = e.bundle->trajectory;
            DoubleArray array = NewArray(static_cast<int64_t>(poses.size()), 8);
            double* data = array.mutable_data();
            for (size_t f = 0; f < poses.size(); ++f) {
              data[8 * f] = poses[f].timestamp
                                ? *poses[f].timestamp
                                : static_cast<double>(poses[f].frame);
              TumRow(poses[f].world_from_cam0, data + 8 * f + 1);
            }
            return array;
          },
          "bundle: (N, 8) array [t, tx, ty, tz, qx, qy, qz, qw] per keyframe "
          "(trajectory.tum's rows: t the timestamp, or the frame without "
          "one); None for the other estimators.")
      .def_readonly("warnings", &E::warnings)
      .def_property_readonly("per_frame", &PerFrameArrays)
      .def("to_dict", &EstimateDict,
           "The estimate as `rcm estimate --json` prints it (a dict).")
      .def(
          "to_json",
          [](const E& e, int indent) { return EstimateJson(e, indent); },
          py::arg("indent") = 2, "The JSON text (indent < 0: one line).")
      .def("__repr__", [](const E& e) {
        return "Estimate(estimator='" + e.estimator +
               "', n=" + py::repr(py::float_(e.n)).cast<std::string>() +
               ", sigma_n=" +
               py::repr(py::float_(e.sigma_n)).cast<std::string>() +
               ", frames=" + std::to_string(e.frames) +
               ", warnings=" + std::to_string(e.warnings.size()) + ")";
      });

  module.def("estimate_refractive_index", &Estimate, py::arg("rig"),
             py::arg("matches"), py::kw_only(), py::arg("estimator") = "refine",
             py::arg("window_frames") = 20, py::arg("change_threshold") = 5.0,
             py::arg("mask_eta") = 0.3, py::arg("estimate_air_gap") = false,
             py::arg("per_frame_estimates") = false, R"doc(
n from the matches of a sequence of frames with one of the estimators, as
`rcm estimate --matches` runs it (C++ EstimateRefractiveIndex): the same
function, so the same options give the same n.

rig: rcm.StereoRig or a reference rig name; matches: rcm.Correspondences, a
dict of arrays xl, yl, xr, yr [, frame, t] or an (N, 4) / (N, 5) array of
raw pixels (frames are taken in time order, the matches of a frame in input
order). estimator: 'refine' (the estimator of record), 'online', 'window'
(window_frames, change_threshold: sigmas of the change test) or
'closed-form' (mask_eta: the observability mask). estimate_air_gap
(refine): the ports' air gaps free. per_frame_estimates (refine): each
frame's own estimate into Estimate.per_frame.
Further keywords: RefinementOptions (as refine_refractive_index: loss,
loss_scale_px, inlier_threshold_px, systematic_px, detect_systematic, ...).
Returns an rcm.Estimate. Raises ValueError with the library's one-line
message. The GIL is released while it runs.
)doc");
}

}  // namespace rcm::python
