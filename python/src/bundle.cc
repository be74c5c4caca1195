// rcm.SequenceBundleAdjustment (C++ SequenceBundleAdjustment,
// rcm/estimation/sequence_bundle_adjustment.h): n, cam1's turn and the
// trajectory from landmarks tracked over keyframes; rcm.SequenceBundleOptions;
// rcm.compare_trajectories (rcm/geometry/trajectory_error.h).
#include <pybind11/stl.h>

#include <Eigen/Geometry>
#include <cmath>
#include <string>
#include <vector>

#include "bindings.h"
#include "conversions.h"
#include "errors.h"
#include "options.h"
#include "rcm/estimation/refinement_options.h"
#include "rcm/estimation/sequence_bundle_adjustment.h"
#include "rcm/geometry/trajectory_error.h"

namespace rcm::python {
namespace {

std::vector<OptionField> BundleOptionFields(SequenceBundleOptions* o) {
  const OptionField loss = LossOption("loss", &o->loss);
  return {
      DoubleOption("initial_n", &o->initial_n),
      BoolOption("epipolar_seed", &o->epipolar_seed),
      BoolOption("refine_n", &o->refine_n),
      BoolOption("refine_rotation", &o->refine_rotation),
      BoolOption("refine_translation_direction",
                 &o->refine_translation_direction),
      BoolOption("self_calibrate_focal", &o->self_calibrate_focal),
      DoubleOption("min_translation_fraction", &o->min_translation_fraction),
      DoubleOption("min_rotation_deg", &o->min_rotation_deg),
      DoubleOption("axial_cone_deg", &o->axial_cone_deg),
      DoubleOption("plane_thickness", &o->plane_thickness),
      DoubleOption("plane_distance_spread", &o->plane_distance_spread),
      BoolOption("allow_degenerate_motion", &o->allow_degenerate_motion),
      loss,
      DoubleOption("loss_scale_px", &o->loss_scale_px),
      DoubleOption("inlier_threshold_px", &o->inlier_threshold_px),
      DoubleOption("min_triangulation_angle_deg",
                   &o->min_triangulation_angle_deg),
      IntOption("min_shared_landmarks", &o->min_shared_landmarks),
      IntOption("min_landmark_keyframes", &o->min_landmark_keyframes),
      IntOption("max_iterations", &o->max_iterations),
      BoolOption("propagate_calibration", &o->propagate_calibration),
      DoubleOption("systematic_px", &o->systematic_px),
      DoubleOption("propagation_eigenvalue_floor",
                   &o->propagation_eigenvalue_floor),
      IntOption("num_threads", &o->num_threads)};
}

// The tracks of an (M, 5) array [frame, camera, landmark, u, v]: the first
// three whole numbers (>= 0; camera 0 or 1), the pixels raw (the lens's
// distorted pixels). num_frames / num_landmarks default to the largest
// index + 1.
StereoTracks TracksFromPython(const py::handle& object,
                              const std::optional<int>& num_frames,
                              const std::optional<int>& num_landmarks) {
  const Rows rows = RowsFromPython(object, "observations", 5,
                                   /*allow_single=*/false);
  StereoTracks tracks;
  int max_frame = -1;
  int max_landmark = -1;
  tracks.observations.reserve(rows.rows);
  for (int64_t i = 0; i < rows.rows; ++i) {
    const double* row = rows.data() + 5 * i;
    for (int k = 0; k < 3; ++k) {
      if (row[k] != std::floor(row[k]) || row[k] < 0.0 || row[k] > 2e9) {
        ThrowValueError("observations row " + std::to_string(i) +
                        ": frame, camera and landmark must be whole numbers "
                        ">= 0");
      }
    }
    StereoTrackObservation o;
    o.frame = static_cast<int>(row[0]);
    o.camera = static_cast<int>(row[1]);
    o.landmark = static_cast<int>(row[2]);
    o.pixel = Eigen::Vector2d(row[3], row[4]);
    max_frame = std::max(max_frame, o.frame);
    max_landmark = std::max(max_landmark, o.landmark);
    tracks.observations.push_back(o);
  }
  tracks.num_frames = num_frames.value_or(max_frame + 1);
  tracks.num_landmarks = num_landmarks.value_or(max_landmark + 1);
  ThrowIfError(tracks.Check().WithContext("observations"));
  return tracks;
}

// Poses as TUM rows [tx, ty, tz, qx, qy, qz, qw] (world_from_cam).
DoubleArray PosesToNumpy(const std::vector<Rigid3d>& poses) {
  DoubleArray array = NewArray(static_cast<int64_t>(poses.size()), 7);
  double* data = array.mutable_data();
  for (size_t f = 0; f < poses.size(); ++f) TumRow(poses[f], data + 7 * f);
  return array;
}

std::vector<Rigid3d> PosesFromPython(const py::handle& object,
                                     const std::string& name) {
  const Rows rows = RowsFromPython(object, name, 7, /*allow_single=*/false);
  std::vector<Rigid3d> poses;
  for (int64_t f = 0; f < rows.rows; ++f) {
    const double* row = rows.data() + 7 * f;
    const Eigen::Quaterniond q(row[6], row[3], row[4], row[5]);
    if (!(std::abs(q.norm() - 1.0) < 1e-6)) {
      ThrowValueError(name + " row " + std::to_string(f) +
                      ": the quaternion (qx, qy, qz, qw) must have norm 1");
    }
    poses.push_back(Rigid3d{q.normalized().toRotationMatrix(),
                            Eigen::Vector3d(row[0], row[1], row[2])});
  }
  return poses;
}

const char* MotionName(BundleMotion kind) {
  switch (kind) {
    case BundleMotion::kMoving:
      return "moving";
    case BundleMotion::kStatic:
      return "static";
    case BundleMotion::kAlongAxis:
      return "along_axis";
    case BundleMotion::kOnePlane:
      return "one_plane";
  }
  return "?";
}

}  // namespace

void BindBundle(py::module_& module) {
  BindOptionsClass<SequenceBundleOptions>(
      module, "SequenceBundleOptions",
      "The sequence bundle adjustment's options (C++ SequenceBundleOptions), "
      "with its defaults; any of them is also a keyword of "
      "rcm.SequenceBundleAdjustment.",
      &BundleOptionFields,
      {{"initial_n", "n to start from (and to hold with refine_n=False)"},
       {"epipolar_seed",
        "start from n and the turn of the keyframes' stereo pairs"},
       {"refine_n", "estimate n (False: held at initial_n, for odometry)"},
       {"refine_rotation", "estimate cam1's turn since the calibration"},
       {"refine_translation_direction",
        "estimate the direction of cam1's translation (its length is the "
        "scale)"},
       {"self_calibrate_focal",
        "estimate each lens's focal scale under the camchain's focal drift "
        "prior"},
       {"min_translation_fraction",
        "static below this fraction of the landmarks' distance"},
       {"min_rotation_deg", "a rig turning less is checked for degeneracy"},
       {"axial_cone_deg", "moving along the axis within this cone, degrees"},
       {"plane_thickness", "one plane below this thickness over its extent"},
       {"plane_distance_spread", "seen from one distance within this spread"},
       {"allow_degenerate_motion", "solve where motion does not help"},
       {"loss", "stage 1's robust loss: 'none', 'huber', 'cauchy'"},
       {"loss_scale_px", "its scale, pixels"},
       {"inlier_threshold_px", "stage 2's inliers, pixels"},
       {"min_triangulation_angle_deg", "parallax a landmark needs, degrees"},
       {"min_shared_landmarks", "landmarks a keyframe needs to be placed"},
       {"min_landmark_keyframes", "keyframes a landmark needs to be used"},
       {"max_iterations", "Ceres iterations per stage"},
       {"propagate_calibration",
        "carry the camchain's uncertainty into sigma_n"},
       {"systematic_px",
        "the tracks' systematic floor per field coefficient, pixels (0.03 "
        "for the front end's tracks)"},
       {"propagation_eigenvalue_floor",
        "calibration directions below this fraction are dropped"},
       {"num_threads", "threads of Ceres and of the covariance"}});

  py::class_<SequenceBundleResult>(module, "SequenceBundleResult", R"doc(
The sequence bundle adjustment's solution (C++ SequenceBundleResult).

n, sigma_n (total, 1 sigma) and its parts sigma_n_noise,
sigma_n_calibration and sigma_n_systematic (0 where n was held);
focal_scales (2,): each lens's focal lengths' relative change e_c (None
unless estimated under a focal drift prior) and focal_scale_covariance
(2, 2); cam1_rotation (3,): the turn since
the calibration (angle-axis, radians, cam1 frame); rotation_covariance
(3, 3), radians^2; correlation_n_rotation: what the data leave of n's
correlation with the turn (0: motion separates them); pixel_sigma (pixels);
trajectory (N, 7): per keyframe [tx, ty, tz, qx, qy, qz, qw], the left
camera in keyframe 0's frame (metres; TUM order); landmarks (L, 3), metres,
NaN for a landmark left out; motion: one line; motion_kind: 'moving',
'static', 'along_axis' or 'one_plane'.
)doc")
      .def_readonly("n", &SequenceBundleResult::n)
      .def_readonly("sigma_n", &SequenceBundleResult::sigma_n)
      .def_readonly("sigma_n_noise", &SequenceBundleResult::sigma_n_noise)
      .def_readonly("sigma_n_calibration",
                    &SequenceBundleResult::sigma_n_calibration)
      .def_readonly("sigma_n_systematic",
                    &SequenceBundleResult::sigma_n_systematic)
      .def_property_readonly("focal_scales",
                             [](const SequenceBundleResult& r) -> py::object {
                               if (!r.focal_scales_estimated) return py::none();
                               return ToNumpy(r.state.focal_scales);
                             })
      .def_property_readonly("focal_scale_covariance",
                             [](const SequenceBundleResult& r) -> py::object {
                               if (!r.focal_scales_estimated) return py::none();
                               return ToNumpy(r.focal_scale_covariance);
                             })
      .def_property_readonly("cam1_rotation",
                             [](const SequenceBundleResult& r) {
                               return ToNumpy(r.state.cam1_rotation);
                             })
      .def_property_readonly("cam1_direction",
                             [](const SequenceBundleResult& r) {
                               return ToNumpy(r.state.cam1_direction);
                             })
      .def_property_readonly("rotation_covariance",
                             [](const SequenceBundleResult& r) {
                               return ToNumpy(r.rotation_covariance);
                             })
      .def_readonly("correlation_n_rotation",
                    &SequenceBundleResult::correlation_n_rotation)
      .def_readonly("pixel_sigma", &SequenceBundleResult::pixel_sigma)
      .def_readonly("num_observations", &SequenceBundleResult::num_observations)
      .def_readonly("num_inliers", &SequenceBundleResult::num_inliers)
      .def_readonly("num_landmarks", &SequenceBundleResult::num_landmarks)
      .def_readonly("num_frames", &SequenceBundleResult::num_frames)
      .def_readonly("iterations", &SequenceBundleResult::iterations)
      .def_property_readonly("trajectory",
                             [](const SequenceBundleResult& r) {
                               std::vector<Rigid3d> poses;
                               for (int f = 0; f < r.num_frames; ++f) {
                                 poses.push_back(r.WorldFromCam0(f));
                               }
                               return PosesToNumpy(poses);
                             })
      .def_property_readonly(
          "landmarks",
          [](const SequenceBundleResult& r) {
            DoubleArray array =
                NewArray(static_cast<int64_t>(r.state.landmarks.size()), 3);
            double* data = array.mutable_data();
            for (size_t l = 0; l < r.state.landmarks.size(); ++l) {
              for (int k = 0; k < 3; ++k) {
                data[3 * l + k] = r.state.landmarks[l][k];
              }
            }
            return array;
          })
      .def_property_readonly(
          "motion",
          [](const SequenceBundleResult& r) { return r.motion.Describe(); })
      .def_property_readonly("motion_kind",
                             [](const SequenceBundleResult& r) {
                               return std::string(MotionName(r.motion.kind));
                             })
      .def("__repr__", [](const SequenceBundleResult& r) {
        return "SequenceBundleResult(n=" +
               py::repr(py::float_(r.n)).cast<std::string>() + ", sigma_n=" +
               py::repr(py::float_(r.sigma_n)).cast<std::string>() +
               ", frames=" + std::to_string(r.num_frames) +
               ", landmarks=" + std::to_string(r.num_landmarks) + ")";
      });

  py::class_<SequenceBundleAdjustment>(module, "SequenceBundleAdjustment",
                                       R"doc(
n, cam1's turn since the air calibration and the rig's trajectory from
landmarks tracked over keyframes, with no target (C++
SequenceBundleAdjustment; docs/bundle.md): the refractive reprojection
error of every observation, Ceres with a Schur solver, a Cauchy stage then
least squares on the inliers, sigma_n from the Schur complement and the
camchain's uncertainty. Refuses in one line (ValueError) a rig that does
not move, moves along its axis only, or sees one plane from one distance.

SequenceBundleAdjustment(rig, options=None, **keywords): rig an
rcm.StereoRig or a reference rig name; keywords those of
rcm.SequenceBundleOptions.
)doc")
      .def(py::init([](const py::object& rig_object, const py::kwargs& kwargs) {
             SequenceBundleOptions options;
             ApplyOptionsWithBase<SequenceBundleOptions>(
                 kwargs, &options, &BundleOptionFields,
                 "rcm.SequenceBundleOptions", "SequenceBundleAdjustment");
             return ValueOrThrow(SequenceBundleAdjustment::Create(
                 RigFromPython(rig_object), options));
           }),
           py::arg("rig"))
      .def(
          "solve",
          [](const SequenceBundleAdjustment& self,
             const py::object& observations, std::optional<int> num_frames,
             std::optional<int> num_landmarks) {
            const StereoTracks tracks =
                TracksFromPython(observations, num_frames, num_landmarks);
            StatusOr<SequenceBundleResult> result = Status::Error("not run");
            {
              py::gil_scoped_release release;
              result = self.Solve(tracks);
            }
            return ValueOrThrow(std::move(result));
          },
          py::arg("observations"), py::kw_only(),
          py::arg("num_frames") = py::none(),
          py::arg("num_landmarks") = py::none(),
          R"doc(
Solves from the tracks alone (the epipolar seed, triangulation, PnP).
observations: (M, 5) array [frame, camera, landmark, u, v], camera 0 (left)
or 1 (right), pixels raw; num_frames, num_landmarks default to the largest
index + 1. Returns an rcm.SequenceBundleResult; ValueError with the
library's one-line message. The GIL is released while it runs.
)doc")
      .def_property_readonly(
          "options",
          [](const SequenceBundleAdjustment& self) { return self.options(); })
      .def("__repr__", [](const SequenceBundleAdjustment& self) {
        return std::string("SequenceBundleAdjustment(refine_n=") +
               (self.options().refine_n ? "True" : "False") +
               ", refine_rotation=" +
               (self.options().refine_rotation ? "True" : "False") + ")";
      });

  module.def(
      "compare_trajectories",
      [](const py::object& estimated, const py::object& truth) {
        const TrajectoryError error = ValueOrThrow(
            CompareTrajectories(PosesFromPython(estimated, "estimated"),
                                PosesFromPython(truth, "truth")));
        py::dict d;
        d["frames"] = error.frames;
        d["ate_m"] = error.ate_m;
        d["end_drift_m"] = error.end_drift_m;
        d["path_length_m"] = error.path_length_m;
        d["true_end_distance_m"] = error.true_end_distance_m;
        d["max_rotation_error_deg"] = error.max_rotation_error_deg;
        return d;
      },
      py::arg("estimated"), py::arg("truth"), R"doc(
How far an estimated trajectory is from the truth (C++ CompareTrajectories):
both (N, 7) arrays [tx, ty, tz, qx, qy, qz, qw] of world_from_cam, each in
its own world frame. Returns a dict: ate_m (RMS position error after the
best rigid alignment, metres), end_drift_m (the last pose seen from the
first, against the truth's: a loop's closure gap), path_length_m,
true_end_distance_m, max_rotation_error_deg, frames.
)doc");
}

}  // namespace rcm::python
