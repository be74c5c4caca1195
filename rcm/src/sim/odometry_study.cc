#include "rcm/sim/odometry_study.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <utility>

#include "rcm/estimation/estimate_refractive_index.h"

namespace rcm {
namespace {

constexpr double kDegreesPerRadian = 180.0 / M_PI;

double SecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
      .count();
}

}  // namespace

Status OdometryStudyOptions::Check() const {
  RCM_RETURN_IF_ERROR(sequence.Check().WithContext("the dive"));
  RCM_RETURN_IF_ERROR(front_end.Check().WithContext("the front end"));
  RCM_RETURN_IF_ERROR(tracker.Check().WithContext("the tracker"));
  RCM_RETURN_IF_ERROR(bundle.Check().WithContext("the bundle"));
  if (sequence.media.size() != 1) {
    return Status::Error("an odometry study's dive is in one medium, not " +
                         std::to_string(sequence.media.size()));
  }
  if (sequence.media[0].frames < 3) {
    return Status::Error("an odometry study needs 3 pairs at least, not " +
                         std::to_string(sequence.media[0].frames));
  }
  if (num_threads < 1) {
    return Status::Error("odometry study threads = " +
                         std::to_string(num_threads) + " must be >= 1");
  }
  return Status::Ok();
}

const char* OdometryModelName(OdometryModel model) {
  switch (model) {
    case OdometryModel::kEstimated:
      return "n and turn estimated";
    case OdometryModel::kNAtTruth:
      return "n held at the truth";
    case OdometryModel::kWaterIgnored:
      return "n = 1 (water ignored)";
    case OdometryModel::kStaleRig:
      return "cam1 as calibrated in air";
  }
  return "?";
}

StatusOr<OdometryStudy> RunOdometryStudy(const StereoRig& calibration,
                                         const OdometryStudyOptions& options,
                                         const OdometryProgress& progress) {
  RCM_RETURN_IF_ERROR(options.Check());
  StatusOr<std::unique_ptr<SequenceSimulator>> simulator =
      SequenceSimulator::Create(calibration, options.sequence);
  if (!simulator.ok()) return simulator.status().WithContext("the dive");
  StatusOr<StereoDetector> detector = StereoDetector::Create(options.front_end);
  if (!detector.ok()) return detector.status();
  StatusOr<StereoFrontEnd> front_end =
      StereoFrontEnd::Create(calibration, options.front_end);
  if (!front_end.ok()) return front_end.status();
  StatusOr<StereoTracker> tracker =
      StereoTracker::Create(calibration, options.tracker);
  if (!tracker.ok()) return tracker.status();

  OdometryStudy study;
  study.true_n = options.sequence.media[0].n;
  const int pairs = (*simulator)->num_frames();
  std::vector<Rigid3d> truth;
  std::vector<StereoCorrespondence> all_matches;
  for (int i = 0; i < pairs; ++i) {
    const std::string where = "pair " + std::to_string(i);
    auto start = std::chrono::steady_clock::now();
    StatusOr<SequenceFrame> frame = (*simulator)->Frame(i);
    if (!frame.ok()) return frame.status().WithContext(where);
    study.render_seconds += SecondsSince(start);
    start = std::chrono::steady_clock::now();
    StatusOr<DetectedStereoPair> detected =
        detector->Detect(frame->left, frame->right, options.num_threads);
    if (!detected.ok()) return detected.status().WithContext(where);
    StatusOr<StereoMatches> matches = front_end->Match(*detected, i, frame->t);
    if (!matches.ok()) return matches.status().WithContext(where);
    StatusOr<int> added = tracker->AddKeyframe(*detected, *matches);
    if (!added.ok()) return added.status().WithContext(where);
    study.track_seconds += SecondsSince(start);
    all_matches.insert(all_matches.end(), matches->matches.begin(),
                       matches->matches.end());
    truth.push_back(frame->world_from_cam0);
    if (progress) progress(i + 1, pairs);
  }
  for (size_t f = 1; f < truth.size(); ++f) {
    const Rigid3d step = truth[f - 1].Inverse() * truth[f];
    study.path_length_m += step.translation.norm();
    study.max_step_m = std::max(study.max_step_m, step.translation.norm());
    study.max_turn_deg =
        std::max(study.max_turn_deg, step.RotationAngle() * kDegreesPerRadian);
  }
  const StereoTracks& tracks = tracker->tracks();
  study.keyframes = tracks.num_frames;
  study.landmarks = tracks.num_landmarks;
  study.mean_matches = static_cast<int>(all_matches.size() / pairs);
  {
    std::vector<std::vector<bool>> seen(tracks.num_landmarks);
    for (const StereoTrackObservation& o : tracks.observations) {
      std::vector<bool>& frames = seen[o.landmark];
      if (frames.empty()) frames.assign(tracks.num_frames, false);
      frames[o.frame] = true;
    }
    for (const std::vector<bool>& frames : seen) {
      int count = 0;
      for (bool b : frames) count += b ? 1 : 0;
      if (count >= 2) ++study.tracked;
    }
  }

  // The truth of cam1's turn: what the rig did since the calibration.
  const Eigen::Vector3d true_turn = options.sequence.cam1_drift.rotation;
  for (const OdometryModel model :
       {OdometryModel::kEstimated, OdometryModel::kNAtTruth,
        OdometryModel::kWaterIgnored, OdometryModel::kStaleRig}) {
    SequenceBundleOptions bundle = options.bundle;
    bundle.num_threads = options.num_threads;
    if (model == OdometryModel::kNAtTruth ||
        model == OdometryModel::kWaterIgnored) {
      bundle.refine_n = false;
      bundle.initial_n = model == OdometryModel::kNAtTruth ? study.true_n : 1.0;
    }
    if (model == OdometryModel::kStaleRig) {
      bundle.refine_rotation = false;
      bundle.epipolar_seed = false;  // its turn would be held
    }
    OdometryRow row;
    row.model = model;
    StatusOr<SequenceBundleAdjustment> adjustment =
        SequenceBundleAdjustment::Create(calibration, bundle);
    if (!adjustment.ok()) return adjustment.status();
    const auto start = std::chrono::steady_clock::now();
    StatusOr<SequenceBundleResult> result = adjustment->Solve(tracks);
    row.seconds = SecondsSince(start);
    if (!result.ok()) {
      row.status = result.status();
      study.rows.push_back(row);
      continue;
    }
    row.n = result->n;
    row.sigma_n = result->sigma_n;
    row.pixel_sigma = result->pixel_sigma;
    row.turn_error_deg =
        (result->state.cam1_rotation - true_turn).norm() * kDegreesPerRadian;
    std::vector<Rigid3d> estimated;
    for (int f = 0; f < tracks.num_frames; ++f) {
      estimated.push_back(result->WorldFromCam0(f));
    }
    StatusOr<TrajectoryError> error = CompareTrajectories(estimated, truth);
    if (!error.ok()) return error.status();
    row.error = *error;
    study.rows.push_back(row);
  }

  for (const bool free_turn : {false, true}) {
    EstimationOptions refine;
    refine.refinement.num_threads = options.num_threads;
    refine.refinement.refine_rotation = free_turn;
    const StatusOr<RefractiveIndexEstimate> epipolar =
        EstimateRefractiveIndex(calibration, SplitFrames(all_matches), refine);
    OdometryStudy::Epipolar& out =
        free_turn ? study.refine_free_turn : study.refine;
    if (epipolar.ok()) {
      out.n = epipolar->n;
      out.sigma_n = epipolar->sigma_n;
    } else {
      out.error = epipolar.status().message();
    }
  }
  return study;
}

}  // namespace rcm
