#include "rcm/sim/exposure_delay.h"

#include <Eigen/Geometry>
#include <cmath>
#include <sstream>

#include "rcm/util/splitmix64.h"

namespace rcm {

Status ExposureDelay::Check() const {
  std::ostringstream message;
  if (!(std::abs(delay) <= kMaxDelay)) {
    message << "exposure delay of " << delay << " s is outside [-" << kMaxDelay
            << ", " << kMaxDelay << "] s";
  } else if (!(angular_speed_sd >= 0.0 &&
               angular_speed_sd <= kMaxAngularSpeed)) {
    message << "angular speed sd of " << angular_speed_sd
            << " rad/s is outside [0, " << kMaxAngularSpeed << "] rad/s";
  } else if (!(speed_sd >= 0.0 && speed_sd <= kMaxSpeed)) {
    message << "speed sd of " << speed_sd << " m/s is outside [0, " << kMaxSpeed
            << "] m/s";
  } else {
    return Status::Ok();
  }
  return Status::Error(message.str());
}

Rigid3d ExposureDelay::MotionOfFrame(uint64_t seed, int frame) const {
  if (IsZero()) return Rigid3d();
  // Six draws keyed by (seed, frame, component): a frame's motion does not
  // depend on how many frames were drawn before it.
  const uint64_t key =
      IndexKey(seed, 0x5DE1A7E5C0FFEE11ull, static_cast<uint64_t>(frame));
  Eigen::Matrix<double, 6, 1> draw;
  for (int k = 0; k < 6; ++k) {
    draw[k] = GaussianFromHash(SplitMix64(key + static_cast<uint64_t>(k)));
  }
  const Eigen::Vector3d rotation = draw.head<3>() * angular_speed_sd * delay;
  Rigid3d motion;
  if (rotation.norm() > 0.0) {
    motion.rotation =
        Eigen::AngleAxisd(rotation.norm(), rotation.normalized()).matrix();
  }
  motion.translation = draw.tail<3>() * speed_sd * delay;
  return motion;
}

}  // namespace rcm
