// SequenceSimulator: a synthetic underwater stereo sequence with ground
// truth. A robot moves through a textured tank (tank_scene.h, trajectory.h)
// with the stereo rig behind exact flat ports (flat_port.h) or domes
// (dome_port_geometry.h; SequenceOptions::left_dome, right_dome, traced
// exactly by port_camera.h); each frame is
// in the medium the schedule gives (media_schedule.h, e.g. air -> water ->
// air). Per frame it renders both 8-bit images (stereo_renderer.h) and
// samples exact correspondences that are consistent with the images: a
// left pixel's ray is cast into the scene (scene_intersection.h: the tank
// and the board), the surface point it hits is projected exactly into the
// right camera, and it is kept when the right camera's ray through that
// pixel hits the same point (visible, in both images). Or, for studies
// over a controlled depth range, points at sampled depths (no images
// then). Noise and outliers are then added as configured.
//
// Things a real dive has that an in-air calibration does not know:
// - extrinsic drift: the rig that renders the images and samples the
//   matches is rig.WithCam1Moved(drift) (stereo_rig.h), while rig() stays
//   the in-air calibration a user would have (and a writer's camchain);
// - cameras not triggered together (ExposureDelay): the right camera's
//   image and matches see the scene moved by the frame's motion during the
//   delay (RightFromLeftOfFrame);
// - lenses that changed (LensChange): each camera's focal lengths scaled
//   by 1 + s_c in that rig (a focus ring or a lens that shifted in its
//   mount, temperature), the calibration's unchanged;
// - a calibration board held by a diver (scene_board.h, board_motion.h):
//   a chessboard in front of the rig, moving smoothly, kept in view of
//   both cameras whenever possible, rendered into the images through the
//   exact ports; it occludes the tank, and the matches may land on it.
//   Each frame records its truth pose cam0_from_target, in rcm::calib's
//   target frame.
//
// Everything depends only on the options and the seed: the same options
// give the same images and matches, bit for bit, however many threads.
#ifndef RCM_SIM_SEQUENCE_SIMULATOR_H_
#define RCM_SIM_SEQUENCE_SIMULATOR_H_

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <memory>
#include <opencv2/core.hpp>
#include <optional>
#include <vector>

#include "rcm/camera/dome_port_geometry.h"
#include "rcm/camera/flat_port.h"
#include "rcm/geometry/rigid3d.h"
#include "rcm/geometry/stereo_correspondence.h"
#include "rcm/sim/board_motion.h"
#include "rcm/sim/exposure_delay.h"
#include "rcm/sim/media_schedule.h"
#include "rcm/sim/scene_board.h"
#include "rcm/sim/stereo_renderer.h"
#include "rcm/sim/tank_scene.h"
#include "rcm/sim/trajectory.h"
#include "rcm/stereo/stereo_rig.h"
#include "rcm/util/status.h"

namespace rcm {

// How cam1 has moved relative to cam0 since the in-air calibration (a
// housing whose cameras shifted), in StereoRig::WithCam1Moved's
// convention: cam1_from_cam0 = (R, t) becomes (exp([w]x) R,
// exp([w]x) t + dt).
struct ExtrinsicDrift {
  // Largest accepted drift: beyond it the rig is another rig.
  static constexpr double kMaxRotationDeg = 10.0;
  static constexpr double kMaxTranslation = 0.05;  // meters

  // w: angle-axis, radians, in cam1's frame; |w| <= kMaxRotationDeg.
  Eigen::Vector3d rotation = Eigen::Vector3d::Zero();
  // dt: meters, cam1 frame; |dt| <= kMaxTranslation.
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();

  Status Check() const;
  bool IsZero() const {
    return rotation.isZero(0.0) && translation.isZero(0.0);
  }
};

// How each camera's focal lengths have changed since the in-air
// calibration: fx and fy of camera c (0 left, 1 right) become (1 + s_c) fx,
// (1 + s_c) fy; the principal point and distortion stay.
struct LensChange {
  // Largest accepted change: beyond it the lens is another lens.
  static constexpr double kMaxRelative = 0.05;

  std::array<double, 2> focal_scale = {0.0, 0.0};  // s_c, |s_c| <= 0.05

  Status Check() const;
  bool IsZero() const { return focal_scale[0] == 0.0 && focal_scale[1] == 0.0; }
  // `rig` with the change applied (ports kept; no calibration uncertainty).
  StatusOr<StereoRig> Apply(const StereoRig& rig) const;
};

struct SequenceOptions {
  // The medium of each frame; its length is the sequence's. Default: 20
  // frames of water.
  std::vector<MediaSegment> media =
      std::vector<MediaSegment>(1, MediaSegment{1.333, 20});
  FlatPort left_port;   // default: the paper's thin port
  FlatPort right_port;  // default: the paper's thin port
  // A camera with a dome (default none) looks through it instead of its
  // flat port: images, board and matches. The decentering is the truth;
  // the rig (and a writer's camchain) knows nothing of it.
  std::optional<DomePort> left_dome;
  std::optional<DomePort> right_dome;
  TankSceneOptions scene;
  // Its frames is replaced by the media schedule's frame count.
  TrajectoryOptions trajectory;
  RenderOptions render;
  bool render_images = true;      // false: poses and matches only (fast)
  int matches_per_frame = 0;      // exact scene correspondences per frame, >= 0
  double match_noise_px = 0.0;    // Gaussian noise on all four coordinates
  double outlier_fraction = 0.0;  // of each frame's matches, in [0, 1]
  // Both zero (the default): matches are points of the tank's surfaces.
  // Otherwise 0 < min <= max: matches are points at depths Z uniform in
  // [min, max] (left camera frame) on the rays of uniform left pixels
  // (SampleFlatPortCorrespondences), for studies over a controlled depth
  // range; they do not belong to the images, so render_images must be
  // false, and need flat ports (no dome).
  double match_min_depth = 0.0;  // meters
  double match_max_depth = 0.0;  // meters
  // Default none: the rig is as calibrated.
  ExtrinsicDrift cam1_drift;
  LensChange lens_change;
  // Default none: the cameras are triggered together. With a delay the
  // right camera sees each frame's scene moved by that frame's motion
  // (exposure_delay.h), in its image and in the matches (the lamp where it
  // was at the left exposure).
  ExposureDelay exposure_delay;
  // A chessboard held in front of the rig (default none), and how it
  // moves; the motion's seed is replaced by one derived from `seed`.
  std::optional<SceneBoard> board;
  BoardMotionOptions board_motion;
  // Seeds everything (scene, trajectory, sensor noise, matches); the seeds
  // in `scene`, `trajectory` and `render` are replaced by ones derived
  // from it.
  uint64_t seed = 1;

  Status Check() const;
  bool UsesDepthRange() const {
    return match_min_depth != 0.0 || match_max_depth != 0.0;
  }
};

struct SequenceFrame {
  int index = 0;
  double t = 0.0;  // seconds
  double n = 1.0;  // the medium of this frame
  Rigid3d world_from_cam0;
  cv::Mat left;   // CV_8UC1; empty when images are not rendered
  cv::Mat right;  // CV_8UC1; empty when images are not rendered
  // Raw pixels, frame = index, timestamp = t. Exact unless noise or
  // outliers were asked for; outlier_indices lists the replaced ones.
  std::vector<StereoCorrespondence> matches;
  std::vector<int64_t> outlier_indices;
  // With a board: its truth pose (rcm::calib's target frame), and per
  // camera (left, right) whether every inner corner is visible
  // (BoardFrame::fully_visible).
  std::optional<Rigid3d> cam0_from_target;
  std::array<bool, 2> board_fully_visible = {false, false};
};

class SequenceSimulator {
 public:
  // Builds the tank textures, the trajectory and the board's motion. Fails
  // on invalid options, a trajectory that does not fit in the tank, or
  // ports/media the exact port refuses.
  static StatusOr<std::unique_ptr<SequenceSimulator>> Create(
      const StereoRig& rig, const SequenceOptions& options);

  // The in-air calibration (what a user has, and what a writer writes).
  const StereoRig& rig() const { return rig_; }
  // The rig as it is in the water: rig() with options().cam1_drift and
  // options().lens_change.
  const StereoRig& true_rig() const { return true_rig_; }
  const SequenceOptions& options() const { return options_; }
  const MediaSchedule& media() const { return media_; }
  int num_frames() const { return media_.num_frames(); }
  const std::vector<TimedPose>& poses() const { return poses_; }
  const TankScene& scene() const { return *scene_; }
  // n of every frame.
  const std::vector<double>& n_of_frame() const { return n_of_frame_; }
  // With a board: its pose and visibility in every frame; empty without.
  const std::vector<BoardFrame>& board_frames() const { return board_frames_; }
  // cam1's view of frame `index` at its exposure: true_rig()'s
  // right_from_left, moved by the frame's exposure delay motion when there
  // is one (ExposureDelay::RightFromLeftOfFrame).
  Rigid3d RightFromLeftOfFrame(int index) const;

  // Renders frame `index` (in [0, num_frames())) and samples up to
  // matches_per_frame matches (fewer only when the two cameras barely
  // overlap, e.g. facing a wall close up).
  // Not thread-safe (the renderer caches rays per medium).
  StatusOr<SequenceFrame> Frame(int index);

 private:
  SequenceSimulator(const StereoRig& rig, const StereoRig& true_rig,
                    const SequenceOptions& options, MediaSchedule media)
      : rig_(rig),
        true_rig_(true_rig),
        options_(options),
        media_(std::move(media)) {}

  // Matches of frame `index` on the scene's surfaces (the tank's, and the
  // board's when given), in a medium of index n.
  std::vector<StereoCorrespondence> SampleMatches(int index, double n,
                                                  const PlacedBoard* board);

  StereoRig rig_;
  StereoRig true_rig_;
  SequenceOptions options_;
  MediaSchedule media_;
  std::vector<double> n_of_frame_;
  std::unique_ptr<TankScene> scene_;
  std::vector<TimedPose> poses_;
  std::vector<BoardFrame> board_frames_;
  std::unique_ptr<StereoRenderer> renderer_;
};

}  // namespace rcm

#endif  // RCM_SIM_SEQUENCE_SIMULATOR_H_
