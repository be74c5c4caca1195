// The simulator: exact correspondences sampled from the model or from exact
// flat ports (rcm.sample_correspondences), noise and outliers, and whole
// synthetic sequences with images and ground truth (rcm.SequenceSimulator,
// rcm.simulate).
#include <pybind11/stl.h>

#include <cmath>
#include <memory>
#include <mutex>

#include "bindings.h"
#include "conversions.h"
#include "errors.h"
#include "options.h"
#include "rcm/sim/sequence_simulator.h"
#include "rcm/sim/stereo_sampler.h"

namespace rcm::python {
namespace {

uint64_t SeedFrom(const py::handle& value) {
  return SeedFromPython(value, "seed");
}

// A FlatPort argument (TypeError for anything else).
FlatPort PortFrom(const py::handle& value, const std::string& name) {
  if (!py::isinstance<FlatPort>(value)) {
    ThrowTypeError(name + " must be an rcm.FlatPort, got " +
                   py::str(py::type::of(value)).cast<std::string>());
  }
  return value.cast<FlatPort>();
}

Correspondences Sample(const py::object& rig_object, double n, double min_depth,
                       double max_depth, int num_frames, int per_frame,
                       double frame_rate, const py::object& seed,
                       const std::optional<bool>& exact_ports) {
  const StereoRig rig = RigFromPython(rig_object);
  StereoSamplerOptions options;
  options.n = n;
  options.min_depth = min_depth;
  options.max_depth = max_depth;
  options.num_frames = num_frames;
  options.per_frame = per_frame;
  options.frame_rate = frame_rate;
  options.seed = SeedFrom(seed);
  ThrowIfError(options.Check());
  const bool through_ports = exact_ports.value_or(rig.HasThickPort());
  StatusOr<std::vector<StereoCorrespondence>> matches =
      Status::Error("not run");
  {
    py::gil_scoped_release release;
    if (through_ports) {
      const StereoRig::Ports ports = rig.ports().value_or(StereoRig::Ports{});
      matches =
          SampleFlatPortCorrespondences(rig, ports.left, ports.right, options);
    } else {
      matches = SampleStereoCorrespondences(rig, options);
    }
  }
  return Correspondences{ValueOrThrow(std::move(matches))};
}

Correspondences WithNoise(const py::object& matches, double sigma_px,
                          const py::object& seed) {
  if (!std::isfinite(sigma_px) || sigma_px < 0.0) {
    ThrowValueError("sigma_px must be finite and >= 0");
  }
  Correspondences result{MatchesFromPython(matches, "matches", true)};
  AddPixelNoise(sigma_px, SeedFrom(seed), &result.matches);
  return result;
}

py::tuple WithOutliers(const StereoRig& rig, const py::object& matches,
                       double fraction, const py::object& seed) {
  if (!(fraction >= 0.0 && fraction <= 1.0)) {
    ThrowValueError("fraction must be in [0, 1]");
  }
  Correspondences result{MatchesFromPython(matches, "matches", true)};
  const std::vector<int64_t> replaced =
      AddOutliers(rig, fraction, SeedFrom(seed), &result.matches);
  py::array_t<int64_t> indices(
      std::vector<py::ssize_t>{static_cast<py::ssize_t>(replaced.size())});
  std::copy(replaced.begin(), replaced.end(), indices.mutable_data());
  return py::make_tuple(result, indices);
}

// SequenceOptions from keywords.
SequenceOptions SequenceOptionsFrom(const py::kwargs& kwargs) {
  SequenceOptions options;
  double n = 1.333;
  int frames = 20;
  std::optional<std::vector<MediaSegment>> media;
  Eigen::Vector3d drift_rotation = Eigen::Vector3d::Zero();
  Eigen::Vector3d drift_translation = Eigen::Vector3d::Zero();
  std::vector<OptionField> fields = {
      DoubleOption("n", &n),
      IntOption("frames", &frames),
      {"media",
       [&](const py::handle& value) {
         std::vector<MediaSegment> segments;
         for (const py::handle item : value) {
           const py::tuple pair = py::reinterpret_borrow<py::object>(item);
           if (pair.size() != 2) {
             ThrowValueError("media must be a list of (n, frames) pairs");
           }
           segments.push_back({FiniteDouble(pair[0], "media n"),
                               IntFromPython(pair[1], "media frames")});
         }
         media = segments;
       },
       [] { return py::object(py::none()); }},
      {"left_port",
       [&](const py::handle& value) {
         options.left_port = PortFrom(value, "left_port");
       },
       [&] { return py::cast(options.left_port); }},
      {"right_port",
       [&](const py::handle& value) {
         options.right_port = PortFrom(value, "right_port");
       },
       [&] { return py::cast(options.right_port); }},
      {"port",
       [&](const py::handle& value) {
         options.left_port = options.right_port = PortFrom(value, "port");
       },
       [&] { return py::cast(options.left_port); }},
      BoolOption("render_images", &options.render_images),
      IntOption("matches_per_frame", &options.matches_per_frame),
      DoubleOption("match_noise_px", &options.match_noise_px),
      DoubleOption("outlier_fraction", &options.outlier_fraction),
      DoubleOption("match_min_depth", &options.match_min_depth),
      DoubleOption("match_max_depth", &options.match_max_depth),
      {"cam1_drift_rotation",
       [&](const py::handle& value) {
         drift_rotation = Vector3FromPython(value, "cam1_drift_rotation");
       },
       [&] { return py::object(ToNumpy(drift_rotation)); }},
      {"cam1_drift_translation",
       [&](const py::handle& value) {
         drift_translation = Vector3FromPython(value, "cam1_drift_translation");
       },
       [&] { return py::object(ToNumpy(drift_translation)); }},
      IntOption("supersampling", &options.render.supersampling),
      DoubleOption("image_noise", &options.render.read_noise),
      DoubleOption("frame_rate", &options.trajectory.frame_rate),
      IntOption("num_threads", &options.render.num_threads),
      {"seed", [&](const py::handle& value) { options.seed = SeedFrom(value); },
       [&] { return py::object(py::int_(options.seed)); }},
  };
  ApplyOptions(kwargs, fields, "SequenceSimulator");
  options.media =
      media.value_or(std::vector<MediaSegment>{MediaSegment{n, frames}});
  options.cam1_drift.rotation = drift_rotation;
  options.cam1_drift.translation = drift_translation;
  ThrowIfError(options.Check());
  return options;
}

// Frame() is not thread-safe (the renderer caches rays) and runs without
// the GIL: `mutex` serializes calls from several Python threads.
struct Simulator {
  std::unique_ptr<SequenceSimulator> simulator;
  std::shared_ptr<std::mutex> mutex = std::make_shared<std::mutex>();
};

py::dict FrameDict(const SequenceFrame& frame) {
  py::dict d;
  d["index"] = frame.index;
  d["t"] = frame.t;
  d["n_true"] = frame.n;
  d["world_from_cam0"] = ToNumpy(frame.world_from_cam0.ToMatrix());
  d["left"] = frame.left.empty() ? py::object(py::none())
                                 : py::object(ImageToNumpy(frame.left));
  d["right"] = frame.right.empty() ? py::object(py::none())
                                   : py::object(ImageToNumpy(frame.right));
  d["matches"] = Correspondences{frame.matches};
  py::array_t<int64_t> outliers(std::vector<py::ssize_t>{
      static_cast<py::ssize_t>(frame.outlier_indices.size())});
  std::copy(frame.outlier_indices.begin(), frame.outlier_indices.end(),
            outliers.mutable_data());
  d["outlier_indices"] = outliers;
  return d;
}

py::dict FrameOf(Simulator& self, int index) {
  if (index < 0 || index >= self.simulator->num_frames()) {
    throw py::index_error("frame " + std::to_string(index) +
                          " out of range [0, " +
                          std::to_string(self.simulator->num_frames()) + ")");
  }
  StatusOr<SequenceFrame> frame = Status::Error("not rendered");
  {
    py::gil_scoped_release release;
    const std::lock_guard<std::mutex> lock(*self.mutex);
    frame = self.simulator->Frame(index);
  }
  return FrameDict(ValueOrThrow(std::move(frame)));
}

Simulator MakeSimulator(const py::object& rig_object,
                        const py::kwargs& kwargs) {
  const StereoRig rig = RigFromPython(rig_object);
  const SequenceOptions options = SequenceOptionsFrom(kwargs);
  StatusOr<std::unique_ptr<SequenceSimulator>> simulator =
      Status::Error("not built");
  {
    py::gil_scoped_release release;
    simulator = SequenceSimulator::Create(rig, options);
  }
  return Simulator{ValueOrThrow(std::move(simulator)),
                   std::make_shared<std::mutex>()};
}

constexpr const char* kSequenceOptionsDoc = R"doc(
Keyword options (SequenceOptions): n=1.333 and frames=20 (one medium), or
media=[(n, frames), ...] (e.g. air -> water: [(1.0, 5), (1.333, 10)]);
port / left_port / right_port (rcm.FlatPort; default thin); render_images=True;
matches_per_frame=0; match_noise_px=0.0 (Gaussian, pixels, all four
coordinates); outlier_fraction=0.0; match_min_depth, match_max_depth
(meters; both 0: matches on the scene's surfaces; otherwise points at
uniform depths, which needs render_images=False); cam1_drift_rotation
(angle-axis, radians, cam1 frame) and cam1_drift_translation (meters): how
cam1 moved since the air calibration; supersampling=2; image_noise=1.5
(read noise); frame_rate (Hz); num_threads=2; seed=1 (everything depends on
it only).
)doc";

}  // namespace

void BindSimulation(py::module_& module) {
  module.def("sample_correspondences", &Sample, py::arg("rig"), py::kw_only(),
             py::arg("n") = 1.333, py::arg("min_depth") = 0.6,
             py::arg("max_depth") = 6.0, py::arg("num_frames") = 1,
             py::arg("per_frame") = 100, py::arg("frame_rate") = 20.0,
             py::arg("seed") = 1, py::arg("exact_ports") = py::none(),
             R"doc(
Exact correspondences (C++ SampleStereoCorrespondences): a left pixel uniform
over the image, a depth Z uniform in [min_depth, max_depth] meters (left
camera frame), projected into both cameras; per_frame matches for each of
num_frames frames, timestamps frame / frame_rate seconds. exact_ports:
sample through the exact flat ports of the rig (SampleFlatPortCorrespondences,
physics sharing no code with the model); default: when the rig has a thick
port. Returns an rcm.Correspondences.
)doc");
  module.def("add_pixel_noise", &WithNoise, py::arg("matches"),
             py::arg("sigma_px"), py::kw_only(), py::arg("seed") = 1,
             "A copy of the matches with independent Gaussian noise of "
             "sigma_px pixels on all four coordinates (C++ AddPixelNoise).");
  module.def("add_outliers", &WithOutliers, py::arg("rig"), py::arg("matches"),
             py::arg("fraction"), py::kw_only(), py::arg("seed") = 1,
             "(copy, replaced indices): a random fraction of the matches made "
             "gross outliers, their right pixel uniform over the right image.");

  static const std::string simulator_doc = std::string(R"doc(
A synthetic underwater stereo sequence with ground truth (C++
SequenceSimulator): a robot moving through a textured tank, the rig behind
exact flat ports, per frame two rendered 8-bit images and exact
correspondences consistent with them.

SequenceSimulator(rig, **options), rig an rcm.StereoRig or a reference rig
name ('alphasense-rectified', 'alphasense-unrectified', 'narrow-field');
frame(i) -> dict(index, t (s), n_true,
world_from_cam0 (4x4), left, right (uint8 (H, W) arrays or None), matches
(rcm.Correspondences), outlier_indices); len() is the number of frames;
iterating renders every frame.
)doc") + kSequenceOptionsDoc;
  static const std::string simulate_doc =
      std::string(
          "Every frame of SequenceSimulator(rig, **options), as a "
          "list of dicts (see SequenceSimulator).\n") +
      kSequenceOptionsDoc;
  py::class_<Simulator>(module, "SequenceSimulator", simulator_doc.c_str())
      .def(py::init(&MakeSimulator), py::arg("rig"))
      .def("frame", &FrameOf, py::arg("index"),
           "Renders frame `index` in [0, len) and samples its matches: a dict "
           "(see the class). IndexError out of range. GIL released.")
      .def("__len__",
           [](const Simulator& s) { return s.simulator->num_frames(); })
      .def_property_readonly(
          "rig", [](const Simulator& s) { return s.simulator->rig(); },
          "The in-air calibration (what a user has).")
      .def_property_readonly(
          "true_rig",
          [](const Simulator& s) { return s.simulator->true_rig(); },
          "The rig as it is in the water (with the drift).")
      .def_property_readonly("n_of_frame", [](const Simulator& s) {
        return s.simulator->n_of_frame();
      });

  module.def(
      "simulate",
      [](const py::object& rig, const py::kwargs& kwargs) {
        Simulator simulator = MakeSimulator(rig, kwargs);
        py::list frames;
        for (int i = 0; i < simulator.simulator->num_frames(); ++i) {
          frames.append(FrameOf(simulator, i));
        }
        return frames;
      },
      py::arg("rig"), simulate_doc.c_str());
}

}  // namespace rcm::python
