#include "rcm/sim/board_motion.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <iterator>
#include <optional>
#include <sstream>
#include <utility>

#include "rcm/sim/scene_intersection.h"
#include "rcm/util/splitmix64.h"

namespace rcm {
namespace {

constexpr double kDegree = M_PI / 180.0;
// The sinusoids' amplitudes (they sum to 1, so |w| <= 1).
constexpr std::array<double, 3> kAmplitudes = {0.5, 0.3, 0.2};
// The ratio of the largest vertical to horizontal offset (images are
// wider than tall).
constexpr double kVerticalOffsetRatio = 0.75;
// A board point is where the pixel's ray meets the board within this
// distance (the exact port and lens round trip to ~1e-11 m; an occluder
// is centimeters away).
constexpr double kVisibilityTolerance = 1e-6;  // meters
// Bisection steps for the largest visible excursion: 2^-10 of it.
constexpr int kExcursionBisections = 10;
// Below this, cam1's optical axis runs too close to parallel to cam0's
// image plane to cross a depth: the neutral point is on cam0's axis.
constexpr double kMinAxisZ = 0.1;

// Period range of each coordinate, seconds (see the header), in the order
// of BoardMotion's coordinates: distance, x, y, tilt x, tilt y, roll.
struct PeriodRange {
  double min;
  double max;
};
constexpr PeriodRange kPeriods[] = {{6.0, 14.0}, {4.0, 10.0}, {4.0, 10.0},
                                    {3.0, 8.0},  {3.0, 8.0},  {5.0, 12.0}};

// A uniform draw in [0, 1) from a counter: 53 bits of SplitMix64.
double UnitDraw(uint64_t seed, uint64_t counter) {
  return static_cast<double>(SplitMix64(seed + counter) >> 11) * 0x1.0p-53;
}

bool InRange(double value, double lo, double hi) {
  return std::isfinite(value) && value >= lo && value <= hi;
}

}  // namespace

Status BoardMotionOptions::Check() const {
  std::ostringstream message;
  if (!(min_distance > 0.0 && max_distance >= min_distance &&
        std::isfinite(max_distance))) {
    message << "board distance range [" << min_distance << ", " << max_distance
            << "] m must satisfy 0 < min <= max < inf";
  } else if (!InRange(max_tilt_deg, 0.0, 70.0)) {
    message << "board max_tilt_deg = " << max_tilt_deg << " is outside [0, 70]";
  } else if (!InRange(max_roll_deg, 0.0, 45.0)) {
    message << "board max_roll_deg = " << max_roll_deg << " is outside [0, 45]";
  } else if (!InRange(max_off_axis_deg, 0.0, 45.0)) {
    message << "board max_off_axis_deg = " << max_off_axis_deg
            << " is outside [0, 45]";
  } else {
    return Status::Ok();
  }
  return Status::Error(message.str());
}

double BoardMotion::Wave::operator()(double t) const {
  double w = 0.0;
  for (int k = 0; k < 3; ++k) {
    w += kAmplitudes[k] * std::sin(angular_rate[k] * t + phase[k]);
  }
  return w;
}

StatusOr<BoardMotion> BoardMotion::Create(const SceneBoard& board,
                                          const BoardMotionOptions& options,
                                          const Rigid3d& cam1_from_cam0) {
  RCM_RETURN_IF_ERROR(board.Check());
  RCM_RETURN_IF_ERROR(options.Check());
  BoardMotion motion(board, options);
  motion.cam1_center_ =
      -(cam1_from_cam0.rotation.transpose() * cam1_from_cam0.translation);
  motion.cam1_axis_ = cam1_from_cam0.rotation.row(2).transpose();
  static_assert(std::size(kPeriods) == kNumCoordinates);
  uint64_t counter = 0;
  for (int c = 0; c < kNumCoordinates; ++c) {
    const PeriodRange& periods = kPeriods[c];
    for (int k = 0; k < 3; ++k) {
      const double period_draw = UnitDraw(options.seed, counter++);
      const double phase_draw = UnitDraw(options.seed, counter++);
      const double period =
          periods.min + (periods.max - periods.min) * period_draw;
      motion.waves_[c].angular_rate[k] = 2.0 * M_PI / period;
      motion.waves_[c].phase[k] = 2.0 * M_PI * phase_draw;
    }
  }
  return motion;
}

Eigen::Vector3d BoardMotion::NeutralPoint(double depth) const {
  const Eigen::Vector3d on_cam0_axis(0.0, 0.0, depth);
  if (cam1_axis_.z() < kMinAxisZ) return on_cam0_axis;
  const Eigen::Vector3d on_cam1_axis =
      cam1_center_ + (depth - cam1_center_.z()) / cam1_axis_.z() * cam1_axis_;
  return 0.5 * (on_cam0_axis + on_cam1_axis);
}

Rigid3d BoardMotion::Cam0FromTarget(double t, double excursion) const {
  const BoardMotionOptions& o = options_;
  const double depth =
      0.5 * (o.min_distance + o.max_distance) +
      0.5 * (o.max_distance - o.min_distance) * waves_[kDistance](t);
  const double lateral = std::tan(o.max_off_axis_deg * kDegree);
  const Eigen::Vector3d center =
      NeutralPoint(depth) +
      excursion * depth *
          Eigen::Vector3d(lateral * waves_[kX](t),
                          kVerticalOffsetRatio * lateral * waves_[kY](t), 0.0);
  Eigen::Vector2d tilt(waves_[kTiltX](t), waves_[kTiltY](t));
  tilt *= excursion * o.max_tilt_deg * kDegree / std::max(1.0, tilt.norm());
  const double roll = excursion * o.max_roll_deg * kDegree * waves_[kRoll](t);
  Eigen::Matrix3d rotation =
      Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const double tilt_angle = tilt.norm();
  if (tilt_angle > 0.0) {
    rotation =
        Eigen::AngleAxisd(tilt_angle,
                          Eigen::Vector3d(tilt.x(), tilt.y(), 0.0) / tilt_angle)
            .toRotationMatrix() *
        rotation;
  }
  Rigid3d cam0_from_target;
  cam0_from_target.rotation = rotation;
  cam0_from_target.translation = center - rotation * board_.Center();
  return cam0_from_target;
}

bool BoardPointsVisible(const PlacedBoard& board,
                        const std::vector<Eigen::Vector3d>& points_in_target,
                        const TankScene& tank, const PortCamera& camera,
                        const Rigid3d& world_from_camera, double margin_px) {
  const Rigid3d camera_from_world = world_from_camera.Inverse();
  const Camera& lens = camera.camera();
  for (const Eigen::Vector3d& point_in_target : points_in_target) {
    const Eigen::Vector3d point_in_world =
        board.world_from_target() * point_in_target;
    const std::optional<Eigen::Vector2d> pixel =
        camera.ImageFromPoint(camera_from_world * point_in_world);
    if (!pixel || !(pixel->x() >= margin_px - 0.5 &&
                    pixel->x() <= lens.width() - 0.5 - margin_px &&
                    pixel->y() >= margin_px - 0.5 &&
                    pixel->y() <= lens.height() - 0.5 - margin_px)) {
      return false;
    }
    const std::optional<RayInMedium> ray = camera.RayFromImage(*pixel);
    if (!ray) return false;
    const std::optional<SceneHit> hit =
        IntersectScene(tank, &board, world_from_camera * ray->origin,
                       world_from_camera.rotation * ray->direction);
    if (!hit || !hit->on_board || !hit->board.printed_side ||
        (hit->board.point - point_in_world).norm() > kVisibilityTolerance) {
      return false;
    }
  }
  return true;
}

StatusOr<std::vector<BoardFrame>> PlanBoardFrames(
    const BoardMotion& motion, const StereoRig& rig, const FlatPort& left_port,
    const FlatPort& right_port, const std::vector<double>& n_of_frame,
    const std::vector<TimedPose>& poses, const TankScene& tank,
    const std::optional<DomePort>& left_dome,
    const std::optional<DomePort>& right_dome) {
  if (n_of_frame.size() != poses.size()) {
    return Status::Error("board frames: " + std::to_string(n_of_frame.size()) +
                         " media for " + std::to_string(poses.size()) +
                         " poses");
  }
  const SceneBoard& board = motion.board();
  const std::vector<Eigen::Vector3d> outline = board.PatternOutline();
  const std::vector<Eigen::Vector3d> corners = board.Corners();
  const Rigid3d cam0_from_cam1 = rig.right_from_left().Inverse();
  const int num_frames = static_cast<int>(poses.size());

  // The cameras behind their ports, once per medium (a sequence has few),
  // and which of them each frame uses.
  std::vector<double> media;
  std::vector<std::array<PortCamera, 2>> cameras;
  std::vector<int> medium_of_frame(num_frames);
  for (int f = 0; f < num_frames; ++f) {
    const double n = n_of_frame[f];
    const auto known = std::find(media.begin(), media.end(), n);
    medium_of_frame[f] = static_cast<int>(known - media.begin());
    if (known != media.end()) continue;
    StatusOr<PortCamera> left =
        PortCamera::Create(rig.left(), left_port, left_dome, n);
    if (!left.ok()) return left.status().WithContext("left port");
    StatusOr<PortCamera> right =
        PortCamera::Create(rig.right(), right_port, right_dome, n);
    if (!right.ok()) return right.status().WithContext("right port");
    media.push_back(n);
    cameras.push_back({std::move(left).value(), std::move(right).value()});
  }
  // Whether both cameras of frame f see `points` with the board at
  // excursion e.
  const auto visible = [&](int f, double e,
                           const std::vector<Eigen::Vector3d>& points) {
    const Rigid3d& world_from_cam0 = poses[f].world_from_cam0;
    const PlacedBoard placed(
        board, world_from_cam0 * motion.Cam0FromTarget(poses[f].t, e));
    const Rigid3d world_from_cam[2] = {world_from_cam0,
                                       world_from_cam0 * cam0_from_cam1};
    const std::array<PortCamera, 2>& camera = cameras[medium_of_frame[f]];
    std::array<bool, 2> seen;
    for (int c = 0; c < 2; ++c) {
      seen[c] = BoardPointsVisible(placed, points, tank, camera[c],
                                   world_from_cam[c], kBoardMarginPx);
    }
    return seen;
  };
  const auto both = [](const std::array<bool, 2>& seen) {
    return seen[0] && seen[1];
  };

  // The largest excursion per frame at which the whole pattern is seen.
  std::vector<double> excursion(num_frames, 0.0);
  for (int f = 0; f < num_frames; ++f) {
    if (both(visible(f, 1.0, outline))) {
      excursion[f] = 1.0;
      continue;
    }
    if (!both(visible(f, 0.0, outline))) continue;
    double lo = 0.0, hi = 1.0;
    for (int k = 0; k < kExcursionBisections; ++k) {
      const double mid = 0.5 * (lo + hi);
      (both(visible(f, mid, outline)) ? lo : hi) = mid;
    }
    excursion[f] = lo;
  }
  // Limited to kMaxExcursionStep per frame, from below.
  for (int f = 1; f < num_frames; ++f) {
    excursion[f] = std::min(excursion[f], excursion[f - 1] + kMaxExcursionStep);
  }
  for (int f = num_frames - 2; f >= 0; --f) {
    excursion[f] = std::min(excursion[f], excursion[f + 1] + kMaxExcursionStep);
  }

  std::vector<BoardFrame> frames(num_frames);
  for (int f = 0; f < num_frames; ++f) {
    BoardFrame& frame = frames[f];
    frame.excursion = excursion[f];
    frame.cam0_from_target = motion.Cam0FromTarget(poses[f].t, excursion[f]);
    frame.fully_visible = visible(f, excursion[f], corners);
  }
  return frames;
}

}  // namespace rcm
