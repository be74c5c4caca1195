#include "rcm/sim/trajectory.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <random>
#include <sstream>

namespace rcm {
namespace {

constexpr double kDegrees = M_PI / 180.0;
// Samples of the ellipse's arc-length table: the inverse is linear between
// them, accurate to ~1e-7 of the perimeter for any tank.
constexpr int kArcTableSize = 4096;
// The camera keeps this far from the floor and the surface, meters.
constexpr double kVerticalClearance = 0.3;
constexpr double kMinSemiAxis = 0.25;  // meters

// Arc length along the ellipse (a cos phi, b sin phi) at phi_k = 2 pi k / N.
std::vector<double> ArcLengthTable(double a, double b) {
  std::vector<double> table(kArcTableSize + 1, 0.0);
  const double step = 2.0 * M_PI / kArcTableSize;
  const auto speed = [&](double phi) {
    return std::hypot(a * std::sin(phi), b * std::cos(phi));
  };
  for (int k = 0; k < kArcTableSize; ++k) {
    const double phi = k * step;
    // Simpson's rule on each interval.
    table[k + 1] = table[k] + step / 6.0 *
                                  (speed(phi) + 4.0 * speed(phi + 0.5 * step) +
                                   speed(phi + step));
  }
  return table;
}

// The angle phi at arc length s (any real; wraps around the perimeter).
double AngleAtArcLength(const std::vector<double>& table, double s) {
  const double perimeter = table.back();
  const double turns = std::floor(s / perimeter);
  const double within = s - turns * perimeter;
  const auto it = std::upper_bound(table.begin(), table.end(), within);
  const int k = std::clamp(static_cast<int>(it - table.begin()) - 1, 0,
                           kArcTableSize - 1);
  const double fraction =
      (within - table[k]) / std::max(table[k + 1] - table[k], 1e-300);
  return 2.0 * M_PI * (turns + (k + fraction) / kArcTableSize);
}

}  // namespace

Status TrajectoryOptions::Check() const {
  std::ostringstream message;
  const auto finite_nonnegative = [](double value) {
    return std::isfinite(value) && value >= 0.0;
  };
  if (frames < 1) {
    message << "trajectory frames = " << frames << " must be >= 1";
  } else if (!(frame_rate > 0.0) || !std::isfinite(frame_rate)) {
    message << "trajectory frame_rate = " << frame_rate << " must be > 0";
  } else if (!(height > 0.0) || !std::isfinite(height)) {
    message << "trajectory height = " << height << " m must be > 0";
  } else if (!finite_nonnegative(speed) || speed > 5.0) {
    message << "trajectory speed = " << speed << " m/s is outside [0, 5]";
  } else if (loops < 0 || loops > 100 || (loops > 0 && frames < 2)) {
    message << "trajectory loops = " << loops << " with frames = " << frames
            << ": loops must be in [0, 100], and a loop needs 2 frames";
  } else if (!std::isfinite(pitch_deg) || pitch_deg < -60.0 ||
             pitch_deg > 80.0) {
    message << "trajectory pitch_deg = " << pitch_deg
            << " is outside [-60, 80]";
  } else if (!finite_nonnegative(sway_amplitude) ||
             !finite_nonnegative(heave_amplitude)) {
    message << "trajectory sway_amplitude = " << sway_amplitude
            << " m and heave_amplitude = " << heave_amplitude
            << " m must be >= 0";
  } else if (!std::isfinite(wall_margin) ||
             !(wall_margin - sway_amplitude > 1.0)) {
    message << "trajectory wall_margin - sway_amplitude = "
            << wall_margin - sway_amplitude
            << " m must exceed 1 (cameras well away from the walls)";
  } else if (!finite_nonnegative(yaw_amplitude_deg) ||
             yaw_amplitude_deg > 45.0 ||
             !finite_nonnegative(rock_amplitude_deg) ||
             rock_amplitude_deg > 20.0) {
    message << "trajectory yaw_amplitude_deg = " << yaw_amplitude_deg
            << " (at most 45) and rock_amplitude_deg = " << rock_amplitude_deg
            << " (at most 20) must be >= 0";
  } else {
    return Status::Ok();
  }
  return Status::Error(message.str());
}

StatusOr<std::vector<TimedPose>> GenerateTrajectory(
    const TankScene& scene, const TrajectoryOptions& options) {
  RCM_RETURN_IF_ERROR(options.Check());
  const double a = 0.5 * scene.length() - options.wall_margin;
  const double b = 0.5 * scene.width() - options.wall_margin;
  if (a < kMinSemiAxis || b < kMinSemiAxis) {
    std::ostringstream message;
    message << "a " << scene.length() << " m x " << scene.width()
            << " m tank leaves no room for a path " << options.wall_margin
            << " m from the walls";
    return Status::Error(message.str());
  }
  if (options.height - options.heave_amplitude < kVerticalClearance ||
      options.height + options.heave_amplitude >
          scene.depth() - kVerticalClearance) {
    std::ostringstream message;
    message << "trajectory height " << options.height << " +- "
            << options.heave_amplitude << " m does not stay "
            << kVerticalClearance << " m from the floor and the surface of a "
            << scene.depth() << " m deep tank";
    return Status::Error(message.str());
  }

  std::mt19937_64 rng(options.seed);
  std::uniform_real_distribution<double> phase(0.0, 2.0 * M_PI);
  const auto period = [&rng](double lo, double hi) {
    return std::uniform_real_distribution<double>(lo, hi)(rng);
  };
  const double start_angle = phase(rng);
  const double direction = std::bernoulli_distribution(0.5)(rng) ? 1.0 : -1.0;
  double sway_period = period(6.0, 10.0), sway_phase = phase(rng);
  double heave_period = period(4.0, 7.0), heave_phase = phase(rng);
  double yaw_period = period(7.0, 12.0), yaw_phase = phase(rng);
  double pitch_period = period(3.0, 5.0), pitch_phase = phase(rng);
  double roll_period = period(3.5, 6.0), roll_phase = phase(rng);
  const auto wave = [](double amplitude, double period, double phase,
                       double t) {
    return amplitude * std::sin(2.0 * M_PI * t / period + phase);
  };

  const std::vector<double> table = ArcLengthTable(a, b);
  const double perimeter = table.back();
  const double start_s = start_angle / (2.0 * M_PI) * perimeter;
  double speed = options.speed;
  if (options.loops > 0) {
    // K laps in the dive's duration, and whole cycles of every wobble.
    const double duration = (options.frames - 1) / options.frame_rate;
    speed = options.loops * perimeter / duration;
    if (speed > 5.0) {
      std::ostringstream message;
      message << options.loops << " laps of " << perimeter << " m in "
              << duration << " s fly at " << speed
              << " m/s, beyond 5: more frames, or a smaller tank";
      return Status::Error(message.str());
    }
    for (double* period : {&sway_period, &heave_period, &yaw_period,
                           &pitch_period, &roll_period}) {
      *period = duration / std::max(1.0, std::round(duration / *period));
    }
  }
  const Eigen::Vector2d center(0.5 * scene.length(), 0.5 * scene.width());

  std::vector<TimedPose> poses;
  poses.reserve(options.frames);
  for (int i = 0; i < options.frames; ++i) {
    const double t = i / options.frame_rate;
    const double phi = direction * AngleAtArcLength(table, start_s + speed * t);
    const Eigen::Vector2d on_path =
        center + Eigen::Vector2d(a * std::cos(phi), b * std::sin(phi));
    const Eigen::Vector2d tangent =
        direction *
        Eigen::Vector2d(-a * std::sin(phi), b * std::cos(phi)).normalized();
    const Eigen::Vector2d left(-tangent.y(), tangent.x());
    const Eigen::Vector2d position =
        on_path +
        wave(options.sway_amplitude, sway_period, sway_phase, t) * left;
    const double z = options.height + wave(options.heave_amplitude,
                                           heave_period, heave_phase, t);
    const double heading =
        std::atan2(tangent.y(), tangent.x()) +
        wave(options.yaw_amplitude_deg * kDegrees, yaw_period, yaw_phase, t);
    const double pitch = options.pitch_deg * kDegrees +
                         wave(options.rock_amplitude_deg * kDegrees,
                              pitch_period, pitch_phase, t);
    const double roll =
        wave(options.rock_amplitude_deg * kDegrees, roll_period, roll_phase, t);

    const Eigen::Vector3d forward(std::cos(pitch) * std::cos(heading),
                                  std::cos(pitch) * std::sin(heading),
                                  -std::sin(pitch));
    const Eigen::Vector3d right0(std::sin(heading), -std::cos(heading), 0.0);
    const Eigen::Vector3d down0 = forward.cross(right0);
    const Eigen::Vector3d right =
        std::cos(roll) * right0 + std::sin(roll) * down0;
    const Eigen::Vector3d down =
        -std::sin(roll) * right0 + std::cos(roll) * down0;

    TimedPose pose;
    pose.t = t;
    pose.world_from_cam0.rotation.col(0) = right;
    pose.world_from_cam0.rotation.col(1) = down;
    pose.world_from_cam0.rotation.col(2) = forward;
    pose.world_from_cam0.translation =
        Eigen::Vector3d(position.x(), position.y(), z);
    poses.push_back(pose);
  }
  return poses;
}

}  // namespace rcm
