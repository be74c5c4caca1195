// OdometryStudy: the paper's Table I reproduced with ground truth. A
// rendered dive that returns to its start (trajectory.h's loops) is run
// through the front end and the tracker as `rcm estimate --estimator
// bundle` runs it, and the sequence bundle adjustment over its tracks is
// solved under four models of the water and the rig:
//
//   estimated    n and cam1's turn since the calibration estimated (the
//                bundle estimator)
//   n at truth   n held at the dive's true index, the turn estimated
//   n = 1        water ignored: n held at 1, the turn estimated
//   stale rig    n estimated, cam1 held as calibrated in air
//
// Each row scores its trajectory against the truth (trajectory_error.h:
// the ATE after a rigid alignment, the loop-closure gap). The epipolar
// refine estimate over the same pairs' matches is reported beside.
//
// The tracks link each keyframe to the one before only: nothing closes
// the loop, so the gap is the odometry's drift over the lap.
#ifndef RCM_SIM_ODOMETRY_STUDY_H_
#define RCM_SIM_ODOMETRY_STUDY_H_

#include <functional>
#include <string>
#include <vector>

#include "rcm/estimation/sequence_bundle_adjustment.h"
#include "rcm/frontend/stereo_front_end.h"
#include "rcm/frontend/stereo_tracker.h"
#include "rcm/geometry/trajectory_error.h"
#include "rcm/sim/sequence_simulator.h"
#include "rcm/stereo/stereo_rig.h"
#include "rcm/util/status.h"

namespace rcm {

struct OdometryStudyOptions {
  // The dive: one medium (its n is the truth), a loop (trajectory.loops),
  // the rig's drift and lens change since the calibration.
  SequenceOptions sequence;
  StereoFrontEndOptions front_end;
  StereoTrackerOptions tracker;
  // The bundle's options of the "estimated" row; the other rows change
  // refine_n, initial_n and refine_rotation only. By default the tracks'
  // systematic floor is the front end's (kFrontEndSystematicPx), as
  // `rcm estimate --estimator bundle` gives it.
  SequenceBundleOptions bundle = FrontEndBundleOptions();
  int num_threads = 2;  // detection, the bundle, the refine estimate

  // Errors: the parts' Check(); a dive of more than one medium.
  Status Check() const;

  static SequenceBundleOptions FrontEndBundleOptions() {
    SequenceBundleOptions options;
    options.systematic_px = kFrontEndSystematicPx;
    return options;
  }
};

enum class OdometryModel { kEstimated, kNAtTruth, kWaterIgnored, kStaleRig };

// "n and turn estimated", "n held at the truth", "n = 1 (water ignored)",
// "cam1 as calibrated in air".
const char* OdometryModelName(OdometryModel model);

struct OdometryRow {
  OdometryModel model = OdometryModel::kEstimated;
  // Ok, or the bundle's refusal (then nothing below is set).
  Status status;
  double n = 0.0;
  double sigma_n = 0.0;  // 0 where n is held
  // |w - w_true|, degrees: the turn the row ends with against the truth
  // (the stale rig's is the whole drift).
  double turn_error_deg = 0.0;
  double pixel_sigma = 0.0;
  TrajectoryError error;
  double seconds = 0.0;  // the bundle's wall clock
};

struct OdometryStudy {
  double true_n = 0.0;
  int keyframes = 0;
  int landmarks = 0;     // of the tracks
  int tracked = 0;       // landmarks seen in 2 keyframes or more
  int mean_matches = 0;  // stereo matches per pair
  // The true path's length, metres, and the largest step and turn between
  // consecutive pairs (metres, degrees): what the tracker must bridge.
  double path_length_m = 0.0;
  double max_step_m = 0.0;
  double max_turn_deg = 0.0;
  std::vector<OdometryRow> rows;  // in OdometryModel's order
  double render_seconds = 0.0;    // wall clock of the simulator
  double track_seconds = 0.0;     // of the front end and the tracker
  // The epipolar refine estimator over every pair's matches, with cam1 as
  // calibrated and with a free turn (refine_rotation); the error line
  // where it refused.
  struct Epipolar {
    double n = 0.0;
    double sigma_n = 0.0;
    std::string error;
  };
  Epipolar refine;
  Epipolar refine_free_turn;
};

// Called after each rendered and tracked pair: pairs done, pairs in all.
using OdometryProgress = std::function<void(int done, int total)>;

// Renders the dive, tracks it, and solves the four rows. Errors:
// options.Check(), the simulator's, the front end's or the tracker's (one
// line naming the pair). A bundle that refuses is a row's status, not an
// error.
StatusOr<OdometryStudy> RunOdometryStudy(const StereoRig& calibration,
                                         const OdometryStudyOptions& options,
                                         const OdometryProgress& progress = {});

}  // namespace rcm

#endif  // RCM_SIM_ODOMETRY_STUDY_H_
