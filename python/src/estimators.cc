// The estimators of n: rcm.refine_refractive_index (batch, the estimator of
// record), rcm.closed_form_refractive_index (the paper's baseline),
// rcm.OnlineEstimator and rcm.SlidingWindowEstimator.
#include <pybind11/stl.h>

#include <cmath>
#include <iomanip>
#include <limits>
#include <memory>
#include <mutex>
#include <sstream>

#include "bindings.h"
#include "conversions.h"
#include "errors.h"
#include "options.h"
#include "rcm/estimation/batch_refinement.h"
#include "rcm/estimation/closed_form.h"
#include "rcm/estimation/medium_prior.h"
#include "rcm/estimation/online_estimator.h"
#include "rcm/estimation/paper_online_estimator.h"
#include "rcm/estimation/refinement_options.h"
#include "rcm/estimation/sliding_window_estimator.h"

namespace rcm::python {

// The keywords of RefinementOptions, named as its fields.
std::vector<OptionField> RefinementOptionFields(RefinementOptions* o) {
  const OptionField loss = LossOption("loss", &o->loss);
  // A prior on n: None, a medium ('fresh', 'sea', 'N:SIGMA'; medium_prior.h)
  // or a pair (n, sigma).
  OptionField n_prior{
      "n_prior",
      [o](const py::handle& value) {
        if (value.is_none()) {
          o->n_prior.reset();
        } else if (py::isinstance<py::str>(value)) {
          const MediumPrior medium =
              ValueOrThrow(ParseMediumPrior(value.cast<std::string>()));
          o->n_prior = IndexPrior{medium.n, medium.sigma};
        } else {
          py::sequence pair;
          if (!py::isinstance<py::sequence>(value) ||
              (pair = value.cast<py::sequence>()).size() != 2) {
            ThrowTypeError(
                "n_prior must be None, 'fresh', 'sea', 'N:SIGMA' or a pair "
                "(n, sigma)");
          }
          try {
            o->n_prior =
                IndexPrior{pair[0].cast<double>(), pair[1].cast<double>()};
          } catch (const py::cast_error&) {
            ThrowTypeError("n_prior's pair must be two numbers (n, sigma)");
          }
        }
      },
      [o]() -> py::object {
        if (!o->n_prior) return py::none();
        return py::make_tuple(o->n_prior->n, o->n_prior->sigma);
      }};
  // Where the normal equations are taken: None or cam1's rotation
  // correction (3 numbers, angle-axis radians).
  OptionField rows_at_rotation{
      "rows_at_rotation",
      [o](const py::handle& value) {
        if (value.is_none()) {
          o->rows_at_rotation.reset();
          return;
        }
        py::sequence vector;
        if (!py::isinstance<py::sequence>(value) ||
            py::isinstance<py::str>(value) ||
            (vector = value.cast<py::sequence>()).size() != 3) {
          ThrowTypeError(
              "rows_at_rotation must be None or 3 numbers (angle-axis, "
              "radians)");
        }
        try {
          o->rows_at_rotation = Eigen::Vector3d(vector[0].cast<double>(),
                                                vector[1].cast<double>(),
                                                vector[2].cast<double>());
        } catch (const py::cast_error&) {
          ThrowTypeError("rows_at_rotation must be 3 numbers (radians)");
        }
      },
      [o]() -> py::object {
        if (!o->rows_at_rotation) return py::none();
        const Eigen::Vector3d& w = *o->rows_at_rotation;
        return py::make_tuple(w.x(), w.y(), w.z());
      }};
  return {loss,
          n_prior,
          rows_at_rotation,
          DoubleOption("loss_scale_px", &o->loss_scale_px),
          DoubleOption("inlier_threshold_px", &o->inlier_threshold_px, true),
          IntOption("num_scan_points", &o->num_scan_points),
          IntOption("min_inliers", &o->min_inliers),
          DoubleOption("max_crlb_per_px", &o->max_crlb_per_px),
          BoolOption("refine_rotation", &o->refine_rotation),
          BoolOption("self_calibrate_rotation", &o->self_calibrate_rotation),
          BoolOption("self_calibrate_focal", &o->self_calibrate_focal),
          DoubleOption("systematic_px", &o->systematic_px),
          BoolOption("detect_systematic", &o->detect_systematic),
          IntOption("max_num_iterations", &o->max_num_iterations),
          IntOption("num_threads", &o->num_threads)};
}

void ApplyRefinementOptions(const py::dict& kwargs, RefinementOptions* options,
                            const std::string& function) {
  ApplyOptionsWithBase(kwargs, options, &RefinementOptionFields,
                       "rcm.RefinementOptions", function);
}

namespace {

RefinementOptions RefinementOptionsFrom(const py::dict& kwargs,
                                        const std::string& function) {
  RefinementOptions options;
  ApplyRefinementOptions(kwargs, &options, function);
  ThrowIfError(options.Check());
  return options;
}

py::object OptionalDouble(const std::optional<double>& value) {
  if (!value) return py::none();
  return py::float_(*value);
}

py::object ConsistencyDict(const std::optional<FrameConsistency>& c) {
  if (!c) return py::none();
  py::dict d;
  d["frames"] = c->frames;
  d["chi_squared"] = c->chi_squared;
  d["dof"] = c->dof;
  d["p_value"] = c->p_value;
  d["inflation"] = c->inflation;
  return std::move(d);
}

py::object CalibrationDict(const std::optional<CalibrationPropagation>& c) {
  if (!c) return py::none();
  py::dict d;
  d["rotation"] = RotationModeName(c->mode);  // as the JSON's key
  d["source"] = c->source;
  d["sigma_n"] = c->sigma_n;
  d["sigma_n_noise"] = c->sigma_n_noise;
  d["sigma_n_calibration"] = c->sigma_n_calibration;
  d["sigma_n_systematic"] = c->sigma_n_systematic;
  d["systematic_chi_squared"] = c->systematic_chi_squared;
  d["systematic_p_value"] = c->systematic_p_value;
  d["systematic_detected_px"] = c->systematic_detected_px;
  d["variance_rotation"] = c->variance_rotation;
  d["variance_translation"] = c->variance_translation;
  d["variance_lenses"] = c->variance_lenses;
  d["variance_ports"] = c->variance_ports;
  d["variance_medium"] = c->variance_medium;
  d["variance_systematic"] = c->variance_systematic;
  d["dn_drotation"] = ToNumpy(c->dn_drotation);
  d["dn_dtranslation"] = ToNumpy(c->dn_dtranslation);
  d["rotation_multiple_correlation"] = c->rotation_multiple_correlation;
  d["sigma_inflation_if_free"] = c->rotation_sigma_inflation;
  d["rotation_covariance"] = ToNumpy(c->rotation_covariance);
  d["rotation_correlation_with_n"] = ToNumpy(c->rotation_correlation_with_n);
  return std::move(d);
}

// FocalScaleCorrection as a dict (relative scales), or None.
py::object FocalDict(const std::optional<FocalScaleCorrection>& f) {
  if (!f) return py::none();
  py::dict d;
  d["scale"] = ToNumpy(Eigen::VectorXd(f->scale));
  d["sigma"] = ToNumpy(Eigen::VectorXd(f->sigma));
  d["correlation_with_n"] = ToNumpy(Eigen::VectorXd(f->correlation_with_n));
  return d;
}

py::object RotationDict(const std::optional<RotationCorrection>& r) {
  if (!r) return py::none();
  py::dict d;
  d["angle_axis"] = ToNumpy(r->angle_axis);
  d["sigma"] = ToNumpy(r->sigma);
  d["correlation_with_n"] = ToNumpy(r->correlation_with_n);
  d["multiple_correlation_with_n"] = r->multiple_correlation_with_n;
  d["with_prior"] = r->with_prior;
  d["cam1_from_cam0"] = ToNumpy(r->cam1_from_cam0.ToMatrix());
  return std::move(d);
}

std::string Fixed(double value, int digits) {
  std::ostringstream text;
  text << std::setprecision(digits) << std::fixed << value;
  return text.str();
}

std::string SummaryRepr(const RefinementSummary& s) {
  return "RefinementResult(n=" + Fixed(s.n, 9) +
         ", sigma_n=" + Fixed(s.sigma_n, 6) + " (noise " +
         Fixed(s.sigma_n_noise, 6) + ", calibration " +
         Fixed(s.sigma_n_calibration, 6) + "), crlb=" + Fixed(s.crlb, 6) +
         ", sigma_px=" + Fixed(s.sigma_px, 4) +
         ", inliers=" + std::to_string(s.inliers.size()) + "/" +
         std::to_string(s.num_correspondences) +
         ", iterations=" + std::to_string(s.num_iterations) + ")";
}

py::array_t<int64_t> IndexArray(const std::vector<int64_t>& indices) {
  py::array_t<int64_t> a(
      std::vector<py::ssize_t>{static_cast<py::ssize_t>(indices.size())});
  std::copy(indices.begin(), indices.end(), a.mutable_data());
  return a;
}

py::array_t<bool> MaskArray(const std::vector<int64_t>& indices, int64_t size) {
  py::array_t<bool> a(std::vector<py::ssize_t>{size});
  std::fill(a.mutable_data(), a.mutable_data() + size, false);
  for (const int64_t i : indices) {
    if (i >= 0 && i < size) a.mutable_data()[i] = true;
  }
  return a;
}

RefinementSummary Refine(const py::object& rig_object,
                         const py::object& matches, const py::kwargs& kwargs) {
  const StereoRig rig = RigFromPython(rig_object);
  const RefinementOptions options =
      RefinementOptionsFrom(kwargs, "refine_refractive_index");
  const Correspondences* held = py::isinstance<Correspondences>(matches)
                                    ? &matches.cast<const Correspondences&>()
                                    : nullptr;
  std::vector<StereoCorrespondence> converted;
  if (held == nullptr) converted = MatchesFromPython(matches, "matches");
  if (held != nullptr && held->matches.empty()) {
    ThrowValueError("matches is empty: at least one correspondence is needed");
  }
  const std::vector<StereoCorrespondence>& list =
      held != nullptr ? held->matches : converted;
  StatusOr<RefinementSummary> summary = Status::Error("not run");
  {
    py::gil_scoped_release release;
    summary = RefineRefractiveIndex(rig, list, options);
  }
  return ValueOrThrow(std::move(summary));
}

// Closed form: the paper's estimator (mask, eq. 14, radially weighted mean).
struct ClosedFormResult {
  double n = 0.0;
  double standard_error = 0.0;
  int64_t used = 0;
  int64_t masked = 0;
  int64_t invalid = 0;
};

// As rcm estimate: the estimators but the batch assume the paper's thin
// port, and a thick port (an air gap or glass) is refused, not estimated
// with the wrong model.
void RefuseThickPort(const StereoRig& rig, const std::string& what) {
  if (rig.HasThickPort()) {
    ThrowValueError(
        "the rig gives a thick port (an air gap or glass), which "
        "only refine_refractive_index models; " +
        what + " assumes the paper's thin port");
  }
}

ClosedFormResult ClosedForm(const py::object& rig_object,
                            const py::object& matches, double mask_eta) {
  const StereoRig rig = RigFromPython(rig_object);
  RefuseThickPort(rig, "the closed form");
  PaperOnlineEstimatorOptions options;
  options.eta = mask_eta;
  ThrowIfError(options.Check());
  const std::vector<StereoCorrespondence> list =
      MatchesFromPython(matches, "matches");
  ClosedFormResult result;
  std::optional<PaperOnlineEstimator::Estimate> estimate;
  PaperOnlineEstimator estimator(rig, options);
  {
    py::gil_scoped_release release;
    for (const StereoCorrespondence& match : list) estimator.Add(match);
    estimate = estimator.Current();
  }
  result.used = estimator.num_used();
  result.masked = estimator.num_masked();
  result.invalid = estimator.num_invalid();
  if (!estimate) {
    ThrowValueError(
        "no usable correspondence: " + std::to_string(result.masked) +
        " removed by the observability mask, " +
        std::to_string(result.invalid) +
        " invalid; matches near the image axes do not observe n "
        "(lower mask_eta to keep more)");
  }
  result.n = estimate->n;
  result.standard_error = estimate->standard_error;
  return result;
}

DoubleArray ClosedFormPerMatch(const py::object& rig_object,
                               const py::object& matches) {
  const StereoRig rig = RigFromPython(rig_object);
  RefuseThickPort(rig, "the closed form");
  const std::vector<StereoCorrespondence> list =
      MatchesFromPython(matches, "matches");
  DoubleArray n(
      std::vector<py::ssize_t>{static_cast<py::ssize_t>(list.size())});
  double* out = n.mutable_data();
  py::gil_scoped_release release;
  for (size_t i = 0; i < list.size(); ++i) {
    const std::optional<NormalizedCorrespondence> normalized =
        rig.Normalize(list[i]);
    const std::optional<double> value =
        normalized ? ClosedFormN(*normalized) : std::nullopt;
    out[i] = value.value_or(kNaN);
  }
  return n;
}

// The online and window estimators with the last update kept.
// The estimators run without the GIL, so two Python threads may call one
// object at once: `mutex` serializes them.
struct Online {
  OnlineRefractiveIndexEstimator estimator;
  std::optional<OnlineRefractiveIndexEstimator::FrameUpdate> last;
  std::shared_ptr<std::mutex> mutex = std::make_shared<std::mutex>();
};

struct Window {
  SlidingWindowRefractiveIndexEstimator estimator;
  std::optional<SlidingWindowRefractiveIndexEstimator::WindowUpdate> last;
  int64_t calls = 0;
  std::shared_ptr<std::mutex> mutex = std::make_shared<std::mutex>();
};

template <typename T>
py::object ValueOrNone(const StatusOr<T>& value) {
  if (!value.ok()) return py::none();
  return py::cast(value.value());
}

template <typename T>
py::object ErrorOrNone(const StatusOr<T>& value) {
  if (value.ok()) return py::none();
  return py::str(value.status().message());
}

// The fields every pooled estimate has.
template <typename Estimate, typename Class>
void BindPooledFields(Class& cls) {
  cls.def_readonly("n", &Estimate::n, "Refractive index.")
      .def_readonly("sigma_n", &Estimate::sigma_n,
                    "Total standard deviation of n (noise, calibration, "
                    "systematic).")
      .def_readonly("sigma_n_noise", &Estimate::sigma_n_noise)
      .def_readonly("sigma_n_calibration", &Estimate::sigma_n_calibration)
      .def_readonly("sigma_n_systematic", &Estimate::sigma_n_systematic)
      .def_readonly("crlb", &Estimate::crlb,
                    "Cramer-Rao bound of n alone, calibration known.")
      .def_readonly("sigma_px", &Estimate::sigma_px,
                    "Estimated pixel noise of the inliers, pixels.")
      .def_readonly("inliers", &Estimate::inliers, "Pooled inlier count.")
      .def_property_readonly(
          "consistency",
          [](const Estimate& e) { return ConsistencyDict(e.consistency); })
      .def_property_readonly(
          "calibration",
          [](const Estimate& e) { return CalibrationDict(e.calibration); })
      .def_property_readonly("rotation",
                             [](const Estimate& e) -> py::object {
                               if (!e.rotation) return py::none();
                               return ToNumpy(*e.rotation);
                             })
      .def_property_readonly(
          "focal_scale",
          [](const Estimate& e) -> py::object {
            if (!e.focal_scale) return py::none();
            return ToNumpy(*e.focal_scale);
          },
          "Self-calibrated focal scales (left, right), relative (focal "
          "lengths times 1 + e since the calibration), or None.");
}

const char* DecisionName(SlidingWindowRefractiveIndexEstimator::Decision d) {
  using Decision = SlidingWindowRefractiveIndexEstimator::Decision;
  switch (d) {
    case Decision::kSkipped:
      return "skipped";
    case Decision::kAccepted:
      return "accepted";
    case Decision::kPending:
      return "pending";
    case Decision::kSwitch:
      return "switch";
  }
  return "unknown";
}

}  // namespace

void BindEstimators(py::module_& module) {
  // rcm.RefinementOptions: the C++ struct with its defaults, one property
  // per field (the keywords' names), documented from refinement_options.h.
  const std::vector<std::pair<const char*, const char*>> field_docs = {
      {"loss",
       "Loss of the robust stage: 'cauchy' (default), 'huber', 'none'."},
      {"n_prior",
       "A prior on n (thin ports): None (default), 'fresh', 'sea', "
       "'N:SIGMA' or (n, sigma)."},
      {"loss_scale_px",
       "Scale of the robust loss, pixels of distance from the locus; > 0 "
       "(1.0)."},
      {"inlier_threshold_px",
       "Inliers of the final least squares lie within this many pixels of "
       "their locus; > 0, inf keeps all (2.0)."},
      {"num_scan_points",
       "Points of the scan of [1, 2] that seeds n; >= 3 (51)."},
      {"min_inliers", "Fewest inliers accepted; >= 2 (10)."},
      {"max_crlb_per_px",
       "Refuse data whose Cramer-Rao bound of n at 1 px exceeds this (0.1): "
       "data that cannot tell water from air."},
      {"refine_rotation",
       "Estimate a rotation of cam1 without a prior (False)."},
      {"self_calibrate_rotation",
       "Estimate cam1's rotation with n under the calibration's drift prior "
       "(True)."},
      {"self_calibrate_focal",
       "Estimate each camera's focal scale with n under the focal drift "
       "prior (True)."},
      {"systematic_px",
       "The matches' systematic error floor, pixels per coefficient of a "
       "smooth field, carried into sigma_n (0.0; the image front end's is "
       "rcm.FRONT_END_SYSTEMATIC_PX)."},
      {"detect_systematic",
       "Test the residuals for a smooth field and widen sigma_n by it "
       "(False; rcm estimate turns it on)."},
      {"rows_at_rotation",
       "Take the normal equations (and the uncertainty from them) at this "
       "rotation correction of cam1, 3 numbers, angle-axis radians, instead "
       "of the solution's, with the rotation self-calibrated: for pooling "
       "frames' rows at one point (None: at the solution)."},
      {"max_num_iterations", "Solver iterations per stage; >= 1 (100)."},
      {"num_threads", "Threads for the residuals; >= 1 (2)."}};
  BindOptionsClass<RefinementOptions>(module, "RefinementOptions", R"doc(
The estimators' options (C++ RefinementOptions, refinement_options.h), with
the C++ defaults: RefinementOptions(loss='huber', ...). Every estimator
takes one as options=..., or its fields as keywords; check() raises
ValueError with the library's message for a value Check() refuses;
to_dict() gives the keywords.
)doc",
                                      &RefinementOptionFields, field_docs);

  py::class_<RefinementSummary>(module, "RefinementResult", R"doc(
The result of refine_refractive_index (C++ RefinementSummary).

n; sigma_n (total standard deviation: sigma_n_noise, sigma_n_calibration and
sigma_n_systematic in quadrature); crlb (Cramer-Rao bound of n, a standard
deviation); sigma_px (estimated pixel noise of the inliers, pixels);
inliers (bool array, one per input match); inlier_indices (int64);
n_closed_form (None when undefined), n_seed, n_robust; robust_cost, cost
(Ceres' 1/2 sum of squares); num_correspondences, num_invalid (pixels that
could not be undistorted), num_iterations (solver iterations, both stages);
rotation, calibration, consistency (dicts or None); focal (dict of each
camera's focal scale since the calibration, relative: scale, sigma,
correlation_with_n, with a focal drift prior and self_calibrate_focal; or
None).
)doc")
      .def_readonly("n", &RefinementSummary::n)
      .def_readonly("sigma_n", &RefinementSummary::sigma_n)
      .def_readonly("sigma_n_noise", &RefinementSummary::sigma_n_noise)
      .def_readonly("sigma_n_calibration",
                    &RefinementSummary::sigma_n_calibration)
      .def_readonly("sigma_n_systematic",
                    &RefinementSummary::sigma_n_systematic)
      .def_readonly("crlb", &RefinementSummary::crlb)
      .def_readonly("sigma_px", &RefinementSummary::sigma_px)
      .def_property_readonly("n_closed_form",
                             [](const RefinementSummary& s) {
                               return OptionalDouble(s.n_closed_form);
                             })
      .def_readonly("n_seed", &RefinementSummary::n_seed)
      .def_readonly("n_robust", &RefinementSummary::n_robust)
      .def_readonly("robust_cost", &RefinementSummary::robust_cost)
      .def_readonly("cost", &RefinementSummary::cost)
      .def_property_readonly("inliers",
                             [](const RefinementSummary& s) {
                               return MaskArray(s.inliers,
                                                s.num_correspondences);
                             })
      .def_property_readonly(
          "inlier_indices",
          [](const RefinementSummary& s) { return IndexArray(s.inliers); })
      .def_property_readonly(
          "num_inliers",
          [](const RefinementSummary& s) { return s.inliers.size(); })
      .def_readonly("num_correspondences",
                    &RefinementSummary::num_correspondences)
      .def_readonly("num_invalid", &RefinementSummary::num_invalid)
      .def_readonly("num_iterations", &RefinementSummary::num_iterations)
      .def_property_readonly(
          "rotation",
          [](const RefinementSummary& s) { return RotationDict(s.rotation); })
      .def_property_readonly(
          "focal",
          [](const RefinementSummary& s) { return FocalDict(s.focal); })
      .def_property_readonly("calibration",
                             [](const RefinementSummary& s) {
                               return CalibrationDict(s.calibration);
                             })
      .def_property_readonly("consistency",
                             [](const RefinementSummary& s) {
                               return ConsistencyDict(s.consistency);
                             })
      .def(
          "to_dict",
          [](const py::object& self) {
            // Every attribute above, under its name.
            py::dict d;
            for (const char* name : {"n",
                                     "sigma_n",
                                     "sigma_n_noise",
                                     "sigma_n_calibration",
                                     "sigma_n_systematic",
                                     "crlb",
                                     "sigma_px",
                                     "n_closed_form",
                                     "n_seed",
                                     "n_robust",
                                     "robust_cost",
                                     "cost",
                                     "num_inliers",
                                     "num_correspondences",
                                     "num_invalid",
                                     "num_iterations",
                                     "inlier_indices",
                                     "rotation",
                                     "focal",
                                     "calibration",
                                     "consistency"}) {
              d[name] = self.attr(name);
            }
            return d;
          },
          "The attributes as a dict (the C++ struct's fields, radians; "
          "for the report's keys use rcm.estimate_refractive_index's "
          "rcm.Estimate).")
      .def("__repr__", &SummaryRepr);

  module.def("refine_refractive_index", &Refine, py::arg("rig"),
             py::arg("matches"), R"doc(
n by robust least squares on the refractive epipolar loci (the estimator of
record; C++ RefineRefractiveIndex), over all matches of all frames.

rig: rcm.StereoRig or a reference rig name (a rig with a thick port is
refined with the thick-port model); matches: rcm.Correspondences, a dict of arrays xl, yl, xr, yr
[, frame, t], an (N, 4) [xl, yl, xr, yr] or (N, 5) [frame, xl, yl, xr, yr]
array of raw pixels.

Keyword options (RefinementOptions, same names and defaults):
  loss='cauchy' ('none', 'huber', 'cauchy'), loss_scale_px=1.0 (pixels),
  inlier_threshold_px=2.0 (pixels, inf keeps all), num_scan_points=51,
  min_inliers=10, max_crlb_per_px=0.1, refine_rotation=False,
  self_calibrate_rotation=True, self_calibrate_focal=True,
  systematic_px=0.0 (pixels), detect_systematic=False,
  n_prior=None (a prior on n: 'fresh', 'sea', 'N:SIGMA' or (n, sigma); with
  refine_rotation=True it gives cam1's turn on a narrow rig),
  max_num_iterations=100, num_threads=2.
Returns an rcm.RefinementResult. Raises ValueError with the library's
one-line message (too few inliers, n unobservable, n pinned at 2, bad
options), TypeError for an unknown keyword. The GIL is released while it
runs.
)doc");

  module.def(
      "default_refinement_options",
      []() {
        RefinementOptions options;
        return OptionValues(RefinementOptionFields(&options));
      },
      "The keyword options of the estimators with their default values.");

  py::class_<ClosedFormResult>(module, "ClosedFormResult",
                               "The paper's closed form: n (radially weighted "
                               "mean of eq. 14 over the masked matches), "
                               "standard_error (NaN with one match), used, "
                               "masked, invalid (counts).")
      .def_readonly("n", &ClosedFormResult::n)
      .def_readonly("standard_error", &ClosedFormResult::standard_error)
      .def_readonly("used", &ClosedFormResult::used)
      .def_readonly("masked", &ClosedFormResult::masked)
      .def_readonly("invalid", &ClosedFormResult::invalid)
      .def("__repr__", [](const ClosedFormResult& r) {
        return "ClosedFormResult(n=" + Fixed(r.n, 9) +
               ", standard_error=" + Fixed(r.standard_error, 6) +
               ", used=" + std::to_string(r.used) +
               ", masked=" + std::to_string(r.masked) +
               ", invalid=" + std::to_string(r.invalid) + ")";
      });

  module.def("closed_form_refractive_index", &ClosedForm, py::arg("rig"),
             py::arg("matches"), py::kw_only(), py::arg("mask_eta") = 0.3,
             R"doc(
The paper's baseline (rcm estimate --estimator closed-form): per match eq. 14
for an ideal rectified pair, the observability mask sqrt|u| sqrt|v| > mask_eta
on the left normalized coordinates, and the radially weighted mean (eq. 17).
Exact on exact data of a rectified rig, biased on others, heavy-tailed with
noise: a seed, not the estimator of record. Thin ports only.
)doc");
  module.def(
      "water_refractive_index",
      [](double salinity, double temperature, double wavelength) {
        return ValueOrThrow(
            WaterRefractiveIndex(salinity, temperature, wavelength));
      },
      py::arg("salinity"), py::arg("temperature"), py::arg("wavelength"),
      "n of water relative to air (Quan and Fry 1995) from its salinity "
      "(g/kg, 0-35), temperature (degrees C, 0-30) and the light's "
      "wavelength (nm, 400-700); ValueError outside that range.");
  module.def(
      "medium_prior",
      [](const std::string& text) {
        const MediumPrior medium = ValueOrThrow(ParseMediumPrior(text));
        py::dict d;
        d["name"] = medium.name;
        d["n"] = medium.n;
        d["sigma"] = medium.sigma;
        d["range"] = py::make_tuple(medium.min_n, medium.max_n);
        d["description"] = medium.Describe();
        return d;
      },
      py::arg("text"),
      "The medium's prior on n ('fresh', 'sea' or 'N:SIGMA'; C++ "
      "ParseMediumPrior) as a dict: name, n, sigma, range (min, max), "
      "description. ValueError on anything else.");

  module.def("closed_form_n", &ClosedFormPerMatch, py::arg("rig"),
             py::arg("matches"),
             "n of eq. 14 for every match (float64 array, NaN where n^2 is not "
             "a positive finite number or a pixel cannot be undistorted); no "
             "mask.");

  py::class_<PooledLocusEstimate> frame_estimate(
      module, "FrameEstimate",
      "One frame's own estimate, what refine_refractive_index reports on that "
      "frame's matches alone: n, sigma_n (total), sigma_n_noise, "
      "sigma_n_calibration, sigma_n_systematic, crlb, sigma_px (pixels), "
      "inliers.");
  BindPooledFields<PooledLocusEstimate>(frame_estimate);
  frame_estimate.def("__repr__", [](const PooledLocusEstimate& e) {
    return "FrameEstimate(n=" + Fixed(e.n, 9) +
           ", sigma_n=" + Fixed(e.sigma_n, 6) +
           ", inliers=" + std::to_string(e.inliers) + ")";
  });

  using OnlineEstimate = OnlineRefractiveIndexEstimator::Estimate;
  py::class_<OnlineEstimate> online_estimate(
      module, "OnlineEstimate",
      "The online estimator's estimate of all frames so far (pooled): n, "
      "sigma_n (total), sigma_n_noise, sigma_n_calibration, "
      "sigma_n_systematic, crlb, sigma_px (pixels), inliers, correspondences, "
      "frames.");
  BindPooledFields<OnlineEstimate>(online_estimate);
  online_estimate
      .def_readonly("correspondences", &OnlineEstimate::correspondences)
      .def_readonly("frames", &OnlineEstimate::frames)
      .def("__repr__", [](const OnlineEstimate& e) {
        return "OnlineEstimate(n=" + Fixed(e.n, 9) +
               ", sigma_n=" + Fixed(e.sigma_n, 6) +
               ", frames=" + std::to_string(e.frames) +
               ", inliers=" + std::to_string(e.inliers) + ")";
      });

  using FrameUpdate = OnlineRefractiveIndexEstimator::FrameUpdate;
  py::class_<FrameUpdate>(module, "OnlineFrameUpdate",
                          "What one add_frame did: frame, correspondences, "
                          "usable, skipped, inliers (indices into the frame), "
                          "frame_estimate / cumulative (or None, with the "
                          "reason in *_error).")
      .def_readonly("frame", &FrameUpdate::frame)
      .def_readonly("correspondences", &FrameUpdate::correspondences)
      .def_readonly("usable", &FrameUpdate::usable)
      .def_readonly("skipped", &FrameUpdate::skipped)
      .def_property_readonly(
          "inliers", [](const FrameUpdate& u) { return IndexArray(u.inliers); })
      .def_property_readonly(
          "frame_estimate",
          [](const FrameUpdate& u) { return ValueOrNone(u.frame_estimate); })
      .def_property_readonly(
          "frame_estimate_error",
          [](const FrameUpdate& u) { return ErrorOrNone(u.frame_estimate); })
      .def_property_readonly(
          "cumulative",
          [](const FrameUpdate& u) { return ValueOrNone(u.cumulative); })
      .def_property_readonly("cumulative_error", [](const FrameUpdate& u) {
        return ErrorOrNone(u.cumulative);
      });

  py::class_<Online>(module, "OnlineEstimator", R"doc(
The estimator of record fed one frame at a time, in constant memory (C++
OnlineRefractiveIndexEstimator): n of all frames so far, agreeing with the
batch refinement on the same frames.

OnlineEstimator(rig, **options) takes the keyword options of
refine_refractive_index (refine_rotation is batch-only and refused).
add_frame(matches) adds one stereo pair's matches and returns the current
estimate (an OnlineEstimate), or None while there is none yet (the reason
is in last_update.cumulative_error); current() returns it or raises
ValueError with the reason. Thin ports only.
)doc")
      .def(py::init([](const py::object& rig_object, const py::kwargs& kwargs) {
             const StereoRig rig = RigFromPython(rig_object);
             RefuseThickPort(rig, "the online estimator");
             const RefinementOptions options =
                 RefinementOptionsFrom(kwargs, "OnlineEstimator");
             return Online{ValueOrThrow(OnlineRefractiveIndexEstimator::Create(
                               rig, options)),
                           std::nullopt, std::make_shared<std::mutex>()};
           }),
           py::arg("rig"))
      .def(
          "add_frame",
          [](Online& self, const py::object& matches) {
            const std::vector<StereoCorrespondence> list =
                MatchesFromPython(matches, "matches", /*allow_empty=*/true);
            {
              py::gil_scoped_release release;
              const std::lock_guard<std::mutex> lock(*self.mutex);
              self.last = self.estimator.AddFrame(list);
            }
            return ValueOrNone(self.last->cumulative);
          },
          py::arg("matches"),
          "Adds one stereo pair's matches (any form refine_refractive_index "
          "takes; an empty frame counts as skipped) and returns the "
          "cumulative OnlineEstimate, or None while there is none (the "
          "reason: last_update.cumulative_error). GIL released.")
      .def(
          "current",
          [](const Online& self) {
            return ValueOrThrow(self.estimator.Current());
          },
          "The cumulative OnlineEstimate; ValueError with the reason while "
          "there is none (too few inliers, n unobservable).")
      .def_property_readonly("last_update",
                             [](const Online& self) -> py::object {
                               if (!self.last) return py::none();
                               return py::cast(*self.last);
                             })
      .def_property_readonly(
          "num_frames",
          [](const Online& self) { return self.estimator.num_frames(); })
      .def_property_readonly("num_skipped_frames", [](const Online& self) {
        return self.estimator.num_skipped_frames();
      });

  using WindowEstimate = SlidingWindowRefractiveIndexEstimator::Estimate;
  py::class_<WindowEstimate> window_estimate(
      module, "WindowEstimate",
      "The sliding window's pooled estimate: the fields of OnlineEstimate "
      "but correspondences, plus frames (in the window), first_frame, "
      "last_frame.");
  BindPooledFields<WindowEstimate>(window_estimate);
  window_estimate.def_readonly("frames", &WindowEstimate::frames)
      .def_readonly("first_frame", &WindowEstimate::first_frame)
      .def_readonly("last_frame", &WindowEstimate::last_frame)
      .def("__repr__", [](const WindowEstimate& e) {
        return "WindowEstimate(n=" + Fixed(e.n, 9) +
               ", sigma_n=" + Fixed(e.sigma_n, 6) + ", frames " +
               std::to_string(e.first_frame) + "-" +
               std::to_string(e.last_frame) + ")";
      });

  py::class_<MediumSwitch>(module, "MediumSwitch",
                           "A declared change of medium: first_frame (the "
                           "first in the new medium), detected_at_frame, "
                           "n_before, n_after.")
      .def_readonly("first_frame", &MediumSwitch::first_frame)
      .def_readonly("detected_at_frame", &MediumSwitch::detected_at_frame)
      .def_readonly("n_before", &MediumSwitch::n_before)
      .def_readonly("n_after", &MediumSwitch::n_after)
      .def("__repr__", [](const MediumSwitch& s) {
        return "MediumSwitch(first_frame=" + std::to_string(s.first_frame) +
               ", detected_at_frame=" + std::to_string(s.detected_at_frame) +
               ", n_before=" + Fixed(s.n_before, 6) +
               ", n_after=" + Fixed(s.n_after, 6) + ")";
      });

  using WindowUpdate = SlidingWindowRefractiveIndexEstimator::WindowUpdate;
  py::class_<WindowUpdate>(module, "WindowUpdate",
                           "What one add_frame did: frame, correspondences, "
                           "usable, decision ('skipped', 'accepted', "
                           "'pending', 'switch'), frame_estimate, z, window "
                           "(or None, reason in *_error), medium_switch.")
      .def_readonly("frame", &WindowUpdate::frame)
      .def_readonly("correspondences", &WindowUpdate::correspondences)
      .def_readonly("usable", &WindowUpdate::usable)
      .def_property_readonly("decision",
                             [](const WindowUpdate& u) {
                               return std::string(DecisionName(u.decision));
                             })
      .def_property_readonly(
          "frame_estimate",
          [](const WindowUpdate& u) { return ValueOrNone(u.frame_estimate); })
      .def_property_readonly(
          "frame_estimate_error",
          [](const WindowUpdate& u) { return ErrorOrNone(u.frame_estimate); })
      .def_property_readonly(
          "z", [](const WindowUpdate& u) { return OptionalDouble(u.z); })
      .def_property_readonly(
          "window", [](const WindowUpdate& u) { return ValueOrNone(u.window); })
      .def_property_readonly(
          "window_error",
          [](const WindowUpdate& u) { return ErrorOrNone(u.window); })
      .def_property_readonly("medium_switch",
                             [](const WindowUpdate& u) -> py::object {
                               if (!u.medium_switch) return py::none();
                               return py::cast(*u.medium_switch);
                             });

  py::class_<Window>(module, "SlidingWindowEstimator", R"doc(
The sliding-window estimator (paper Sec. V-D; C++
SlidingWindowRefractiveIndexEstimator): n of the last window_frames frames,
with a test that declares a change of medium (z = |n_f - n_w| /
sqrt(sigma_f^2 + sigma_w^2) above change_threshold on confirm_frames
consecutive, mutually consistent frames), drops the window and restarts.

SlidingWindowEstimator(rig, window_frames=20, change_threshold=5.0,
confirm_frames=2, **options), options as refine_refractive_index's
(refine_rotation refused). add_frame(matches, frame=None) returns the window
estimate (WindowEstimate) or None; `frame` labels the frame in the reports
(default: the count of add_frame calls). switches: the MediumSwitch list.
Thin ports only.
)doc")
      .def(py::init([](const py::object& rig_object, int window_frames,
                       double change_threshold, int confirm_frames,
                       const py::kwargs& kwargs) {
             const StereoRig rig = RigFromPython(rig_object);
             RefuseThickPort(rig, "the sliding-window estimator");
             const RefinementOptions options =
                 RefinementOptionsFrom(kwargs, "SlidingWindowEstimator");
             SlidingWindowOptions window;
             window.window_frames = window_frames;
             window.change_threshold = change_threshold;
             window.confirm_frames = confirm_frames;
             ThrowIfError(window.Check());
             return Window{
                 ValueOrThrow(SlidingWindowRefractiveIndexEstimator::Create(
                     rig, options, window)),
                 std::nullopt, 0, std::make_shared<std::mutex>()};
           }),
           py::arg("rig"), py::arg("window_frames") = 20,
           py::arg("change_threshold") = 5.0, py::arg("confirm_frames") = 2)
      .def(
          "add_frame",
          [](Window& self, const py::object& matches,
             std::optional<int64_t> frame) {
            const std::vector<StereoCorrespondence> list =
                MatchesFromPython(matches, "matches", /*allow_empty=*/true);
            {
              py::gil_scoped_release release;
              const std::lock_guard<std::mutex> lock(*self.mutex);
              const int64_t label = frame.value_or(self.calls);
              ++self.calls;
              self.last = self.estimator.AddFrame(label, list);
            }
            return ValueOrNone(self.last->window);
          },
          py::arg("matches"), py::arg("frame") = py::none(),
          "Adds one stereo pair's matches and returns the window's "
          "WindowEstimate after it, or None (reason: "
          "last_update.window_error). `frame` labels the frame in the "
          "reports and switches (default: the count of add_frame calls). "
          "GIL released.")
      .def(
          "current",
          [](const Window& self) {
            return ValueOrThrow(self.estimator.Current());
          },
          "The window's WindowEstimate; ValueError with the reason while "
          "there is none.")
      .def_property_readonly("last_update",
                             [](const Window& self) -> py::object {
                               if (!self.last) return py::none();
                               return py::cast(*self.last);
                             })
      .def_property_readonly(
          "switches",
          [](const Window& self) { return self.estimator.switches(); })
      .def_property_readonly("num_dropped_frames",
                             [](const Window& self) {
                               return self.estimator.num_dropped_frames();
                             })
      .def_property_readonly("num_skipped_frames", [](const Window& self) {
        return self.estimator.num_skipped_frames();
      });
}

}  // namespace rcm::python
