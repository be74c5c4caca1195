// The image front end: rcm.StereoFrontEnd and rcm.match_stereo, raw stereo
// pairs (NumPy uint8 images) to raw-pixel correspondences.
#include <pybind11/stl.h>

#include <memory>
#include <mutex>

#include "bindings.h"
#include "conversions.h"
#include "errors.h"
#include "options.h"
#include "rcm/frontend/stereo_front_end.h"

namespace rcm::python {

// The keywords of StereoFrontEndOptions, named after the C++ fields,
// nested structs flattened with their prefix (clahe_clip_limit =
// clahe.clip_limit).
std::vector<OptionField> FrontEndOptionFields(StereoFrontEndOptions* o) {
  return {
      {"features",
       [o](const py::handle& value) {
         const std::string name = py::str(value).cast<std::string>();
         const std::optional<FeatureType> type = FeatureTypeFromName(name);
         if (!py::isinstance<py::str>(value) || !type) {
           ThrowValueError("unknown features '" + name +
                           "' (available: orb, sift, akaze)");
         }
         o->features.type = *type;
       },
       [o] { return py::object(py::str(FeatureTypeName(o->features.type))); }},
      IntOption("max_features", &o->features.max_features),
      IntOption("fast_threshold", &o->features.fast_threshold),
      BoolOption("clahe", &o->clahe.enabled),
      DoubleOption("clahe_clip_limit", &o->clahe.clip_limit),
      IntOption("clahe_tiles", &o->clahe.tiles),
      DoubleOption("tolerance_px", &o->band.tolerance_px),
      DoubleOption("min_distance", &o->band.min_distance),
      DoubleOption("ratio", &o->matching.ratio),
      BoolOption("cross_check", &o->matching.cross_check),
      IntOption("max_hamming_distance", &o->matching.max_hamming_distance),
      BoolOption("subpixel", &o->subpixel.enabled),
      IntOption("subpixel_window", &o->subpixel.window),
      DoubleOption("subpixel_max_shift_px", &o->subpixel.max_shift_px),
      {"search_range",
       [o](const py::handle& value) {
         const std::vector<double> range =
             VectorFromPython(value, "search_range");
         if (range.size() != 2) {
           ThrowValueError("search_range must be (min, max)");
         }
         o->search_range = {range[0], range[1]};
       },
       [o] {
         return py::object(
             py::make_tuple(o->search_range.min, o->search_range.max));
       }},
      DoubleOption("reacquire_fraction", &o->reacquire_fraction),
      IntOption("max_refined_matches", &o->max_refined_matches),
      IntOption("num_threads", &o->num_threads),
  };
}

StereoFrontEndOptions FrontEndOptionsFrom(const py::dict& kwargs,
                                          const std::string& function) {
  StereoFrontEndOptions o;
  ApplyOptionsWithBase(kwargs, &o, FrontEndOptionFields, "rcm.FrontEndOptions",
                       function);
  o.matching.num_threads = o.num_threads;
  ThrowIfError(o.Check());
  return o;
}

namespace {

// Match runs without the GIL and keeps state between frames: `mutex`
// serializes calls from several Python threads.
struct FrontEnd {
  StereoFrontEnd front_end;
  std::shared_ptr<std::mutex> mutex = std::make_shared<std::mutex>();
};

StereoMatches Match(FrontEnd& self, const py::object& left,
                    const py::object& right, int64_t frame,
                    std::optional<double> timestamp,
                    const std::optional<std::pair<double, double>>& guide) {
  py::object keep_left;
  py::object keep_right;
  const cv::Mat left_image = ImageFromPython(left, "left", &keep_left);
  const cv::Mat right_image = ImageFromPython(right, "right", &keep_right);
  if (frame < 0) ThrowValueError("frame must be >= 0");
  if (timestamp && !std::isfinite(*timestamp)) {
    ThrowValueError("timestamp must be finite");
  }
  std::optional<RefractiveIndexInterval> interval;
  if (guide) {
    interval = RefractiveIndexInterval{guide->first, guide->second};
    ThrowIfError(interval->Check().WithContext("guide"));
  }
  StatusOr<StereoMatches> matches = Status::Error("not matched");
  {
    py::gil_scoped_release release;
    const std::lock_guard<std::mutex> lock(*self.mutex);
    matches = self.front_end.Match(left_image, right_image, frame, timestamp,
                                   interval);
  }
  return ValueOrThrow(std::move(matches));
}

FrontEnd MakeFrontEnd(const py::object& rig_object, const py::kwargs& kwargs) {
  const StereoRig rig = RigFromPython(rig_object);
  return FrontEnd{ValueOrThrow(StereoFrontEnd::Create(
      rig, FrontEndOptionsFrom(kwargs, "StereoFrontEnd")))};
}

constexpr const char* kOptionsDoc = R"doc(
Keyword options (StereoFrontEndOptions, nested fields flattened):
features='orb' ('orb', 'sift', 'akaze'), max_features=2000 (per image),
fast_threshold=20, clahe=False, clahe_clip_limit=2.0, clahe_tiles=8,
tolerance_px=2.0 (half width of the locus band, pixels), min_distance=0.2,
ratio=0.8 (Lowe's ratio), cross_check=True, max_hamming_distance=64,
subpixel=True, subpixel_window=11 (pixels), subpixel_max_shift_px=2.0,
search_range=(1.0, 1.6) (the n interval the band covers before anything is
known), reacquire_fraction=0.5, max_refined_matches=0 (0: all),
num_threads=2.
)doc";

}  // namespace

void BindFrontEnd(py::module_& module) {
  BindOptionsClass<StereoFrontEndOptions>(
      module, "FrontEndOptions",
      "The image front end's options (C++ StereoFrontEndOptions, "
      "stereo_front_end.h; nested fields flattened with their prefix), with "
      "the C++ defaults. rcm.StereoFrontEnd, rcm.match_stereo and "
      "rcm.SequenceEstimator take one as options=... (front_end=... for the "
      "sequence), or its fields as keywords.",
      &FrontEndOptionFields,
      {{"features",
        "Keypoints and descriptors: 'orb' (default), 'sift', 'akaze'."},
       {"max_features", "Keypoints per image (2000)."},
       {"fast_threshold", "ORB's FAST threshold (20)."},
       {"clahe", "Equalize contrast (CLAHE) before detection (False)."},
       {"clahe_clip_limit", "CLAHE's clip limit (2.0)."},
       {"clahe_tiles", "CLAHE's tiles per side (8)."},
       {"tolerance_px",
        "Half width of the refractive epipolar band, pixels (2.0)."},
       {"min_distance", "Nearest depth the band covers, metres (0.2)."},
       {"ratio",
        "Lowe's ratio among a keypoint's candidates in the band (0.8)."},
       {"cross_check", "Keep mutual best matches only (True)."},
       {"max_hamming_distance", "ORB: largest descriptor distance (64)."},
       {"subpixel", "Refine the right pixels to subpixel (True)."},
       {"subpixel_window", "Subpixel window, pixels (11)."},
       {"subpixel_max_shift_px", "Largest subpixel shift, pixels (2.0)."},
       {"search_range",
        "The n interval (min, max) the band covers before anything is known "
        "((1.0, 1.6))."},
       {"reacquire_fraction",
        "A guided pair keeping less than this fraction of the prior band's "
        "matches is matched again in it (0.5)."},
       {"max_refined_matches",
        "Descriptor matches refined to subpixel and returned at most, every "
        "k-th; 0 refines all (0)."},
       {"num_threads", "Threads (2)."}});
  // C++ kFrontEndSystematicPx: the systematic error floor of this front
  // end's matches (pixels), for refine_refractive_index(systematic_px=...)
  // on its matches, as `rcm estimate` does on images.
  module.attr("FRONT_END_SYSTEMATIC_PX") = kFrontEndSystematicPx;
  py::class_<StereoMatches>(module, "StereoMatches", R"doc(
The matches of one stereo pair: matches (rcm.Correspondences, raw pixels),
pixels ((N, 4) [xl, yl, xr, yr]), left_keypoints, right_keypoints,
descriptor_matches (after guided matching), band ((min, max) n interval the
matches were searched in), reacquired, timings_ms (dict per stage). The
library keeps no per-match score; every returned match passed the ratio
test, the cross check and the band verification.
)doc")
      .def_property_readonly(
          "matches",
          [](const StereoMatches& m) { return Correspondences{m.matches}; })
      .def_property_readonly("pixels",
                             [](const StereoMatches& m) {
                               const py::object matches =
                                   py::cast(Correspondences{m.matches});
                               return py::object(matches.attr("pixels"));
                             })
      .def("__len__", [](const StereoMatches& m) { return m.matches.size(); })
      .def_readonly("left_keypoints", &StereoMatches::left_keypoints)
      .def_readonly("right_keypoints", &StereoMatches::right_keypoints)
      .def_readonly("descriptor_matches", &StereoMatches::descriptor_matches)
      .def_property_readonly("band",
                             [](const StereoMatches& m) {
                               return py::make_tuple(m.band.min, m.band.max);
                             })
      .def_readonly("reacquired", &StereoMatches::reacquired)
      .def_property_readonly("timings_ms",
                             [](const StereoMatches& m) {
                               py::dict d;
                               d["preprocess"] = m.timings.preprocess_ms;
                               d["detect"] = m.timings.detect_ms;
                               d["match"] = m.timings.match_ms;
                               d["refine"] = m.timings.refine_ms;
                               d["total"] = m.timings.total_ms;
                               return d;
                             })
      .def("__repr__", [](const StereoMatches& m) {
        return "StereoMatches(" + std::to_string(m.matches.size()) +
               " matches, keypoints " + std::to_string(m.left_keypoints) + "/" +
               std::to_string(m.right_keypoints) + ")";
      });

  static const std::string front_end_doc = std::string(R"doc(
The per-pair stereo front end of a calibrated rig (C++ StereoFrontEnd):
preprocess, detect, match descriptors within the refractive epipolar band of
an n interval, refine the right pixels to subpixel, verify.

StereoFrontEnd(rig, **options); match(left, right, frame=0, timestamp=None,
guide=None) -> StereoMatches. Images: NumPy uint8 (H, W) gray, (H, W, 3) BGR
or (H, W, 4) BGRA of the rig's image size; any other dtype (float32, ...) is
a ValueError. guide: (min, max) interval of the current estimate of n (None:
the prior search_range). The GIL is released while it runs.
)doc") + kOptionsDoc;
  py::class_<FrontEnd>(module, "StereoFrontEnd", front_end_doc.c_str())
      .def(py::init(&MakeFrontEnd), py::arg("rig"))
      .def("match", &Match, py::arg("left"), py::arg("right"),
           py::arg("frame") = 0, py::arg("timestamp") = py::none(),
           py::arg("guide") = py::none(),
           "The matches of one stereo pair (StereoMatches), each with "
           "`frame` and `timestamp` (seconds). guide: (min, max) n interval "
           "of the current estimate, None for the prior search range.");

  static const std::string match_doc =
      std::string(
          "StereoFrontEnd(rig, **options).match(left, right): the "
          "matches of one stereo pair (StereoMatches).\n") +
      kOptionsDoc;
  module.def(
      "match_stereo",
      [](const py::object& rig_object, const py::object& left,
         const py::object& right, const py::kwargs& kwargs) {
        const StereoRig rig = RigFromPython(rig_object);
        FrontEnd front_end{ValueOrThrow(StereoFrontEnd::Create(
            rig, FrontEndOptionsFrom(kwargs, "match_stereo")))};
        return Match(front_end, left, right, 0, std::nullopt, std::nullopt);
      },
      py::arg("rig"), py::arg("left"), py::arg("right"), match_doc.c_str());
}

}  // namespace rcm::python
