// rcm.SequenceEstimator (C++ SequenceEstimator, rcm/live/sequence_estimator.h):
// the pair loop that `rcm estimate` on images, `rcm demo` and the live node
// run, for a notebook: raw stereo pairs in, each pair's matches and
// estimates out, and the final rcm.Estimate.
#include <pybind11/stl.h>

#include <cmath>
#include <memory>
#include <mutex>
#include <string>

#include "bindings.h"
#include "conversions.h"
#include "errors.h"
#include "options.h"
#include "rcm/estimation/estimate_json.h"
#include "rcm/estimation/refinement_options.h"
#include "rcm/live/sequence_estimator.h"

namespace rcm::python {
namespace {

// AddPair runs without the GIL: `mutex` serializes Python threads.
struct Sequence {
  std::unique_ptr<SequenceEstimator> engine;
  std::shared_ptr<std::mutex> mutex = std::make_shared<std::mutex>();
};

// One pair's result as the class rcm.SequencePair shows it.
struct PairResult {
  SequencePair pair;
};

// A field of the pair's own estimate or of the window's, None without one.
py::object OwnField(const SequencePair& p, double PooledLocusEstimate::*field) {
  return p.own.ok() ? py::object(py::float_((*p.own).*field)) : py::none();
}

py::object WindowField(const SequencePair& p,
                       double PooledLocusEstimate::*field) {
  return p.window.ok() ? py::object(py::float_((*p.window).*field))
                       : py::none();
}

py::dict PairDict(const SequencePair& p) {
  py::dict d;
  d["frame"] = p.frame;
  d["timestamp"] =
      p.timestamp ? py::object(py::float_(*p.timestamp)) : py::none();
  d["num_matches"] = p.matches.size();
  d["num_estimated"] = p.num_estimated;
  d["n"] = OwnField(p, &PooledLocusEstimate::n);
  d["sigma_n"] = OwnField(p, &PooledLocusEstimate::sigma_n);
  d["window_n"] = WindowField(p, &PooledLocusEstimate::n);
  d["window_sigma_n"] = WindowField(p, &PooledLocusEstimate::sigma_n);
  d["medium_switch"] = p.medium_switch.has_value();
  d["reacquired"] = p.reacquired;
  d["followed"] = p.followed;
  d["estimate_ms"] = p.estimate_ms;
  d["match_ms"] = p.timings.total_ms;
  return d;
}

Sequence MakeSequence(const py::object& rig_object,
                      const std::string& estimator, const py::object& front_end,
                      const py::object& refinement, int window_frames,
                      double change_threshold, int window_matches,
                      double follow_rotation_px, bool keep_frames) {
  const StereoRig rig = RigFromPython(rig_object);
  SequenceEstimatorOptions options;
  const std::optional<EstimatorKind> kind = EstimatorFromName(estimator);
  if (!kind) {
    ThrowValueError(
        "unknown estimator '" + estimator +
        "' (available: refine, online, window, closed-form, bundle)");
  }
  options.estimation.estimator = *kind;
  if (py::isinstance<StereoFrontEndOptions>(front_end)) {
    options.front_end = front_end.cast<StereoFrontEndOptions>();
    options.front_end.matching.num_threads = options.front_end.num_threads;
    ThrowIfError(options.front_end.Check());
  } else if (py::isinstance<py::dict>(front_end)) {
    options.front_end =
        FrontEndOptionsFrom(front_end.cast<py::dict>(), "SequenceEstimator");
  } else {
    ThrowTypeError(
        "front_end must be an rcm.FrontEndOptions or a dict of its keywords");
  }
  if (py::isinstance<RefinementOptions>(refinement)) {
    options.estimation.refinement = refinement.cast<RefinementOptions>();
  } else if (py::isinstance<py::dict>(refinement)) {
    ApplyRefinementOptions(refinement.cast<py::dict>(),
                           &options.estimation.refinement,
                           "SequenceEstimator's refinement");
  } else {
    ThrowTypeError(
        "refinement must be an rcm.RefinementOptions or a dict of its "
        "keywords");
  }
  SlidingWindowOptions& window = options.estimation.window;
  window.SetWindowFrames(window_frames);
  window.change_threshold = change_threshold;
  options.window_matches = window_matches;
  options.follow_rotation_px = follow_rotation_px;
  options.keep_frames = keep_frames;
  return Sequence{ValueOrThrow(SequenceEstimator::Create(rig, options))};
}

PairResult AddPair(Sequence& self, const py::object& left,
                   const py::object& right, int64_t frame,
                   std::optional<double> timestamp) {
  py::object keep_left;
  py::object keep_right;
  const cv::Mat left_image = ImageFromPython(left, "left", &keep_left);
  const cv::Mat right_image = ImageFromPython(right, "right", &keep_right);
  if (frame < 0) ThrowValueError("frame must be >= 0");
  if (timestamp && !std::isfinite(*timestamp)) {
    ThrowValueError("timestamp must be finite");
  }
  StatusOr<SequencePair> pair = Status::Error("not run");
  {
    py::gil_scoped_release release;
    const std::lock_guard<std::mutex> lock(*self.mutex);
    pair = self.engine->AddPair(left_image, right_image, frame, timestamp);
  }
  return PairResult{ValueOrThrow(std::move(pair))};
}

RefractiveIndexEstimate EstimateOf(Sequence& self) {
  StatusOr<RefractiveIndexEstimate> estimate = Status::Error("not run");
  {
    py::gil_scoped_release release;
    const std::lock_guard<std::mutex> lock(*self.mutex);
    estimate = self.engine->Estimate();
  }
  return ValueOrThrow(std::move(estimate));
}

}  // namespace

void BindSequence(py::module_& module) {
  py::class_<PairResult>(module, "SequencePair", R"doc(
What one pair gave in a rcm.SequenceEstimator (C++ SequencePair): frame,
timestamp (seconds or None); matches (rcm.Correspondences, raw pixels);
num_estimated (of them, the window's); n, sigma_n (the pair's own estimate,
None without one); window_n, window_sigma_n (the window's after it);
medium_switch (this pair confirmed a change of medium); reacquired (the
front end left the guide's band); followed (the front end now follows a new
rotation of cam1); estimate_ms, match_ms. to_dict() gives all but matches.
)doc")
      .def_property_readonly("frame",
                             [](const PairResult& r) { return r.pair.frame; })
      .def_property_readonly(
          "matches",
          [](const PairResult& r) { return Correspondences{r.pair.matches}; })
      .def_property_readonly("n",
                             [](const PairResult& r) {
                               return OwnField(r.pair, &PooledLocusEstimate::n);
                             })
      .def_property_readonly("sigma_n",
                             [](const PairResult& r) {
                               return OwnField(r.pair,
                                               &PooledLocusEstimate::sigma_n);
                             })
      .def_property_readonly("window_n",
                             [](const PairResult& r) {
                               return WindowField(r.pair,
                                                  &PooledLocusEstimate::n);
                             })
      .def_property_readonly("window_sigma_n",
                             [](const PairResult& r) {
                               return WindowField(
                                   r.pair, &PooledLocusEstimate::sigma_n);
                             })
      .def_property_readonly(
          "medium_switch",
          [](const PairResult& r) { return r.pair.medium_switch.has_value(); })
      .def_property_readonly(
          "followed", [](const PairResult& r) { return r.pair.followed; })
      .def("to_dict", [](const PairResult& r) { return PairDict(r.pair); })
      .def("__repr__", [](const PairResult& r) {
        return "SequencePair(" +
               py::repr(PairDict(r.pair)).cast<std::string>() + ")";
      });

  py::class_<Sequence>(module, "SequenceEstimator", R"doc(
The pair loop of rcm (C++ SequenceEstimator): what `rcm estimate` runs on
images and bags, `rcm demo` on its renders and the ROS node live, with one
policy. Per pair (add_pair): the front end matches it within the refractive
epipolar band of the last pair's own estimate (n +- max(6 sigma, 0.01)), or
of the prior search range without one; the sliding window takes its matches
(at most window_matches of them, spread over the image): the pair's own
estimate, the window's and a change of medium; when the window's
self-calibrated rotation of cam1 moves pixels at the focal length by more
than follow_rotation_px, the front end follows it. estimate() solves the
final estimate once (estimator: 'refine', 'online', 'window',
'closed-form' or 'bundle') over the pairs since the last change of medium
and returns an rcm.Estimate, the same as `rcm estimate --json`. 'bundle'
tracks every pair's features and solves rcm.SequenceBundleAdjustment over
them (Estimate.trajectory), or gives the refine estimate with the reason as
its first warning where motion does not help.

rig: rcm.StereoRig or a reference rig name. front_end: an
rcm.FrontEndOptions or a dict of its keywords; refinement: an rcm.RefinementOptions or a
dict of its keywords (systematic_px defaults to
rcm.FRONT_END_SYSTEMATIC_PX; an rcm.RefinementOptions replaces the defaults
whole); window_frames, change_threshold: the window's;
keep_frames=False keeps no matches (estimate() is then the window's).
)doc")
      .def(py::init(&MakeSequence), py::arg("rig"), py::kw_only(),
           py::arg("estimator") = "refine", py::arg("front_end") = py::dict(),
           py::arg("refinement") = py::dict(), py::arg("window_frames") = 20,
           py::arg("change_threshold") = 5.0, py::arg("window_matches") = 200,
           py::arg("follow_rotation_px") = 0.5, py::arg("keep_frames") = true)
      .def("add_pair", &AddPair, py::arg("left"), py::arg("right"),
           py::arg("frame"), py::arg("timestamp") = py::none(),
           "One raw stereo pair (uint8 images of the rig's size) -> "
           "rcm.SequencePair. The GIL is released while it runs.")
      .def("estimate", &EstimateOf,
           "The final rcm.Estimate (ValueError with the estimator's "
           "one-line message when there is none).")
      .def(
          "restart",
          [](Sequence& self) {
            const std::lock_guard<std::mutex> lock(*self.mutex);
            ThrowIfError(
                self.engine->Restart(self.engine->matching_rotation()));
          },
          "A new window, no guide, no kept frames (the front end keeps the "
          "rotation it follows).")
      .def_property_readonly(
          "matching_rotation",
          [](const Sequence& self) {
            return ToNumpy(Eigen::Vector3d(self.engine->matching_rotation()));
          },
          "The rotation of cam1 the front end matches with (angle-axis, "
          "radians).")
      .def_property_readonly(
          "num_frames",
          [](const Sequence& self) { return self.engine->frames().size(); })
      .def("__repr__", [](const Sequence& self) {
        return "SequenceEstimator(frames=" +
               std::to_string(self.engine->frames().size()) + ", estimator='" +
               std::string(
                   EstimatorName(self.engine->options().estimation.estimator)) +
               "')";
      });
}

}  // namespace rcm::python
