#include "rcm/sim/sequence_simulator.h"

#include <array>
#include <cmath>
#include <random>
#include <sstream>
#include <utility>

#include "rcm/sim/port_camera.h"
#include "rcm/sim/scene_intersection.h"
#include "rcm/sim/stereo_sampler.h"
#include "rcm/util/splitmix64.h"

namespace rcm {
namespace {

// A point is visible in the right image when the right camera's ray
// through its exact pixel hits the tank within this distance of it (the
// exact port and lens round trip to ~1e-11 m; an occluding surface is
// centimeters or more away).
constexpr double kVisibilityTolerance = 1e-6;  // meters
// Draws per requested match before a frame gives up (a frame that faces a
// wall close up may see little in both images).
constexpr int kDrawsPerMatch = 50;

// Independent seeds for each part from one user seed: SplitMix64 at the
// stream's position in the seed's sequence.
uint64_t DeriveSeed(uint64_t seed, uint64_t stream) {
  return SplitMix64(seed + 0x9E3779B97F4A7C15ull * stream);
}

enum SeedStream : uint64_t {
  kSceneSeed = 1,
  kTrajectorySeed = 2,
  kRenderSeed = 3,
  kMatchSeed = 4,
  kNoiseSeed = 5,
  kOutlierSeed = 6,
  kBoardSeed = 7,
  kExposureDelaySeed = 8,
};

}  // namespace

Status ExtrinsicDrift::Check() const {
  std::ostringstream message;
  if (!rotation.allFinite() || !translation.allFinite()) {
    message << "extrinsic drift is not finite";
  } else if (rotation.norm() > kMaxRotationDeg * M_PI / 180.0) {
    message << "extrinsic drift rotation of " << rotation.norm() * 180.0 / M_PI
            << " deg is above " << kMaxRotationDeg << " deg";
  } else if (translation.norm() > kMaxTranslation) {
    message << "extrinsic drift translation of " << translation.norm() * 1e3
            << " mm is above " << kMaxTranslation * 1e3 << " mm";
  } else {
    return Status::Ok();
  }
  return Status::Error(message.str());
}

Status LensChange::Check() const {
  for (int c = 0; c < 2; ++c) {
    if (!(std::abs(focal_scale[c]) <= kMaxRelative)) {
      std::ostringstream message;
      message << "lens change of camera " << c << ": a focal scale of "
              << focal_scale[c] << " is outside [-" << kMaxRelative << ", "
              << kMaxRelative << "]";
      return Status::Error(message.str());
    }
  }
  return Status::Ok();
}

StatusOr<StereoRig> LensChange::Apply(const StereoRig& rig) const {
  RCM_RETURN_IF_ERROR(Check());
  StatusOr<StereoRig> changed =
      rig.WithFocalScaled(focal_scale[0], focal_scale[1]);
  if (!changed.ok()) return changed.status().WithContext("lens change");
  // (The changed lenses are the truth: no calibration uncertainty.)
  return changed->WithCalibrationUncertainty(std::nullopt);
}

Status SequenceOptions::Check() const {
  RCM_RETURN_IF_ERROR(MediaSchedule::Create(media).status());
  RCM_RETURN_IF_ERROR(left_port.Check().WithContext("left port"));
  RCM_RETURN_IF_ERROR(right_port.Check().WithContext("right port"));
  if (left_dome) RCM_RETURN_IF_ERROR(left_dome->Check().WithContext("left"));
  if (right_dome) {
    RCM_RETURN_IF_ERROR(right_dome->Check().WithContext("right"));
  }
  RCM_RETURN_IF_ERROR(scene.Check());
  RCM_RETURN_IF_ERROR(render.Check());
  RCM_RETURN_IF_ERROR(cam1_drift.Check());
  RCM_RETURN_IF_ERROR(lens_change.Check());
  RCM_RETURN_IF_ERROR(exposure_delay.Check());
  if (board) {
    RCM_RETURN_IF_ERROR(board->Check());
    RCM_RETURN_IF_ERROR(board_motion.Check());
  }
  std::ostringstream message;
  if (matches_per_frame < 0) {
    message << "matches_per_frame = " << matches_per_frame << " must be >= 0";
  } else if (!std::isfinite(match_noise_px) || match_noise_px < 0.0) {
    message << "match noise = " << match_noise_px << " px must be >= 0";
  } else if (!(outlier_fraction >= 0.0 && outlier_fraction <= 1.0)) {
    message << "outlier fraction = " << outlier_fraction
            << " is outside [0, 1]";
  } else if (UsesDepthRange() &&
             !(match_min_depth > 0.0 && match_max_depth >= match_min_depth &&
               std::isfinite(match_max_depth))) {
    message << "match depth range [" << match_min_depth << ", "
            << match_max_depth << "] must satisfy 0 < min <= max < inf";
  } else if (UsesDepthRange() && render_images) {
    message << "matches over a depth range do not belong to the images; "
               "render no images with them";
  } else if (UsesDepthRange() && (left_dome || right_dome)) {
    message << "matches over a depth range are sampled through flat ports, "
               "not domes";
  } else {
    return Status::Ok();
  }
  return Status::Error(message.str());
}

StatusOr<std::unique_ptr<SequenceSimulator>> SequenceSimulator::Create(
    const StereoRig& rig, const SequenceOptions& options) {
  RCM_RETURN_IF_ERROR(options.Check());
  StereoRig true_rig = rig;
  if (!options.cam1_drift.IsZero()) {
    StatusOr<StereoRig> moved = rig.WithCam1Moved(
        options.cam1_drift.rotation, options.cam1_drift.translation);
    if (!moved.ok()) return moved.status().WithContext("extrinsic drift");
    true_rig = std::move(moved).value();
  }
  if (!options.lens_change.IsZero()) {
    StatusOr<StereoRig> changed = options.lens_change.Apply(true_rig);
    if (!changed.ok()) return changed.status();
    true_rig = std::move(changed).value();
  }
  std::unique_ptr<SequenceSimulator> simulator(new SequenceSimulator(
      rig, true_rig, options, MediaSchedule::Create(options.media).value()));
  simulator->n_of_frame_ = simulator->media_.PerFrame();

  TankSceneOptions scene_options = options.scene;
  scene_options.seed = DeriveSeed(options.seed, kSceneSeed);
  StatusOr<TankScene> scene = TankScene::Create(scene_options);
  if (!scene.ok()) return scene.status();
  simulator->scene_ = std::make_unique<TankScene>(std::move(scene).value());

  TrajectoryOptions trajectory = options.trajectory;
  trajectory.frames = simulator->num_frames();
  trajectory.seed = DeriveSeed(options.seed, kTrajectorySeed);
  StatusOr<std::vector<TimedPose>> poses =
      GenerateTrajectory(*simulator->scene_, trajectory);
  if (!poses.ok()) return poses.status();
  simulator->poses_ = std::move(poses).value();

  if (options.board) {
    BoardMotionOptions motion_options = options.board_motion;
    motion_options.seed = DeriveSeed(options.seed, kBoardSeed);
    StatusOr<BoardMotion> motion = BoardMotion::Create(
        *options.board, motion_options, true_rig.right_from_left());
    if (!motion.ok()) return motion.status();
    StatusOr<std::vector<BoardFrame>> frames = PlanBoardFrames(
        motion.value(), true_rig, options.left_port, options.right_port,
        simulator->n_of_frame_, simulator->poses_, *simulator->scene_,
        options.left_dome, options.right_dome);
    if (!frames.ok()) return frames.status();
    simulator->board_frames_ = std::move(frames).value();
  }

  if (options.render_images) {
    RenderOptions render = options.render;
    render.seed = DeriveSeed(options.seed, kRenderSeed);
    StatusOr<StereoRenderer> renderer = StereoRenderer::Create(
        true_rig, options.left_port, options.right_port,
        simulator->scene_.get(), render, options.left_dome, options.right_dome);
    if (!renderer.ok()) return renderer.status();
    simulator->renderer_ =
        std::make_unique<StereoRenderer>(std::move(renderer).value());
  }
  return simulator;
}

Rigid3d SequenceSimulator::RightFromLeftOfFrame(int index) const {
  return options_.exposure_delay.RightFromLeftOfFrame(
      true_rig_.right_from_left(),
      DeriveSeed(options_.seed, kExposureDelaySeed), index);
}

std::vector<StereoCorrespondence> SequenceSimulator::SampleMatches(
    int index, double n, const PlacedBoard* board) {
  // Ports and media passed SequenceOptions::Check in Create.
  const PortCamera left =
      PortCamera::Create(true_rig_.left(), options_.left_port,
                         options_.left_dome, n)
          .value();
  const PortCamera right =
      PortCamera::Create(true_rig_.right(), options_.right_port,
                         options_.right_dome, n)
          .value();
  const Rigid3d& world_from_left = poses_[index].world_from_cam0;
  // cam1 at the right exposure (exposure_delay.h).
  const Rigid3d world_from_right =
      world_from_left * RightFromLeftOfFrame(index).Inverse();
  const Rigid3d right_from_world = world_from_right.Inverse();
  const Camera& left_camera = true_rig_.left();
  const Camera& right_camera = true_rig_.right();

  std::mt19937_64 rng(DeriveSeed(DeriveSeed(options_.seed, kMatchSeed), index));
  std::uniform_real_distribution<double> u(-0.5, left_camera.width() - 0.5);
  std::uniform_real_distribution<double> v(-0.5, left_camera.height() - 0.5);

  std::vector<StereoCorrespondence> matches;
  matches.reserve(options_.matches_per_frame);
  const int64_t max_draws =
      static_cast<int64_t>(kDrawsPerMatch) * options_.matches_per_frame;
  for (int64_t draw = 0; draw < max_draws && static_cast<int>(matches.size()) <
                                                 options_.matches_per_frame;
       ++draw) {
    // v before u, in a statement of its own: arguments are evaluated in an
    // unspecified order (gcc right to left, clang left to right), and seeded
    // data must not depend on the compiler. gcc's order, as always.
    const double drawn_v = v(rng);
    const Eigen::Vector2d left_pixel(u(rng), drawn_v);
    const std::optional<RayInMedium> left_ray = left.RayFromImage(left_pixel);
    if (!left_ray) continue;
    const std::optional<SceneHit> hit =
        IntersectScene(*scene_, board, world_from_left * left_ray->origin,
                       world_from_left.rotation * left_ray->direction);
    if (!hit) continue;
    const std::optional<Eigen::Vector2d> right_pixel =
        right.ImageFromPoint(right_from_world * hit->point());
    if (!right_pixel || !right_camera.InImage(*right_pixel)) continue;
    const std::optional<RayInMedium> right_ray =
        right.RayFromImage(*right_pixel);
    if (!right_ray) continue;
    const std::optional<SceneHit> right_hit =
        IntersectScene(*scene_, board, world_from_right * right_ray->origin,
                       world_from_right.rotation * right_ray->direction);
    if (!right_hit ||
        (right_hit->point() - hit->point()).norm() > kVisibilityTolerance) {
      continue;
    }
    StereoCorrespondence match;
    match.frame = index;
    match.timestamp = poses_[index].t;
    match.left_pixel = left_pixel;
    match.right_pixel = *right_pixel;
    matches.push_back(match);
  }
  return matches;
}

StatusOr<SequenceFrame> SequenceSimulator::Frame(int index) {
  CHECK(index >= 0 && index < num_frames()) << index;
  SequenceFrame frame;
  frame.index = index;
  frame.t = poses_[index].t;
  frame.n = n_of_frame_[index];
  frame.world_from_cam0 = poses_[index].world_from_cam0;
  std::optional<PlacedBoard> board;
  if (options_.board) {
    const BoardFrame& board_frame = board_frames_[index];
    frame.cam0_from_target = board_frame.cam0_from_target;
    frame.board_fully_visible = board_frame.fully_visible;
    board.emplace(*options_.board,
                  frame.world_from_cam0 * board_frame.cam0_from_target);
  }
  const PlacedBoard* placed = board ? &*board : nullptr;
  if (renderer_ != nullptr) {
    StatusOr<StereoImages> images =
        renderer_->Render(frame.world_from_cam0, frame.n, index, placed,
                          RightFromLeftOfFrame(index));
    if (!images.ok()) return images.status();
    frame.left = images.value().left;
    frame.right = images.value().right;
  }
  if (options_.matches_per_frame > 0) {
    if (options_.UsesDepthRange()) {
      StereoSamplerOptions sampler;
      sampler.n = frame.n;
      sampler.min_depth = options_.match_min_depth;
      sampler.max_depth = options_.match_max_depth;
      sampler.per_frame = options_.matches_per_frame;
      sampler.seed = DeriveSeed(DeriveSeed(options_.seed, kMatchSeed), index);
      sampler.exposure_delay = options_.exposure_delay;
      StatusOr<std::vector<StereoCorrespondence>> sampled =
          SampleFlatPortCorrespondences(true_rig_, options_.left_port,
                                        options_.right_port, sampler);
      if (!sampled.ok()) return sampled.status();
      frame.matches = std::move(sampled).value();
      for (StereoCorrespondence& match : frame.matches) {
        match.frame = index;
        match.timestamp = frame.t;
      }
    } else {
      frame.matches = SampleMatches(index, frame.n, placed);
    }
    if (options_.match_noise_px > 0.0) {
      AddPixelNoise(options_.match_noise_px,
                    DeriveSeed(DeriveSeed(options_.seed, kNoiseSeed), index),
                    &frame.matches);
    }
    if (options_.outlier_fraction > 0.0) {
      frame.outlier_indices = AddOutliers(
          true_rig_, options_.outlier_fraction,
          DeriveSeed(DeriveSeed(options_.seed, kOutlierSeed), index),
          &frame.matches);
    }
  }
  return frame;
}

}  // namespace rcm
