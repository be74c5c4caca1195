// ExposureDelay: two cameras that are not triggered together. Boards that
// read two camera modules without a common trigger (the StereoPi's two
// Raspberry Pi cameras, two USB cameras) expose the right image some
// milliseconds after the left; when the scene moves relative to the rig
// in between (a hand-held rig, a board in a diver's hands, a swimming
// diver), the right camera sees every point where it is `delay` seconds
// later. Rolling shutters read both images row by row at the same rate,
// so a row sees the same delay; the delay is what the stereo pair feels.
//
// Per frame the scene's motion relative to the left camera is drawn at
// random (zero mean: a hand-held rig wanders, it does not drift): an
// angular velocity w (rad/s) and a velocity v (m/s), each component
// Gaussian with the stated standard deviation. A point X of the left
// camera's frame at the left exposure is, at the right exposure,
//
//   X' = exp([w delay]x) X + v delay,
//
// and the right pixel is cam1's image of right_from_left * X'. For one
// frame this is cam1 moved by a small rigid motion (WithCam1Moved's
// rotation w delay; a translation that is not quite its dt, since X' turns
// about the left camera), so a delay acts like an extrinsic drift that
// changes from frame to frame: frames then disagree beyond their pixel
// noise, and an estimator must count it (frame_consistency.h).
//
// Typical sizes: a delay of 5-20 ms, a hand-held rig turning at 5-20
// deg/s and moving at 0.05-0.3 m/s: 0.03-0.4 deg and 0.3-6 mm per frame,
// several times the drift prior of a calibration.
#ifndef RCM_SIM_EXPOSURE_DELAY_H_
#define RCM_SIM_EXPOSURE_DELAY_H_

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "rcm/geometry/rigid3d.h"
#include "rcm/util/status.h"

namespace rcm {

struct ExposureDelay {
  // Largest accepted sizes: beyond them the images are not one stereo pair.
  static constexpr double kMaxDelay = 0.1;         // seconds
  static constexpr double kMaxAngularSpeed = 3.0;  // rad/s (172 deg/s)
  static constexpr double kMaxSpeed = 3.0;         // m/s

  // The right camera's exposure after the left's, seconds, in
  // [-kMaxDelay, kMaxDelay] (negative: the right camera first). Default 0:
  // the cameras are triggered together.
  double delay = 0.0;
  // Standard deviation of each component of the scene's angular velocity
  // relative to the rig (left camera frame), rad/s, in
  // [0, kMaxAngularSpeed].
  double angular_speed_sd = 0.0;
  // Standard deviation of each component of its velocity, m/s, in
  // [0, kMaxSpeed].
  double speed_sd = 0.0;

  Status Check() const;
  // No effect: no delay, or a scene that does not move.
  bool IsZero() const {
    return delay == 0.0 || (angular_speed_sd == 0.0 && speed_sd == 0.0);
  }

  // The motion of frame `frame` during the delay, X -> X' above (identity
  // when IsZero()). Depends only on (seed, frame).
  Rigid3d MotionOfFrame(uint64_t seed, int frame) const;
  // cam1's view of frame `frame` at its exposure: right_from_left *
  // MotionOfFrame(seed, frame); `right_from_left` itself, bit for bit,
  // when IsZero().
  Rigid3d RightFromLeftOfFrame(const Rigid3d& right_from_left, uint64_t seed,
                               int frame) const {
    if (IsZero()) return right_from_left;
    return right_from_left * MotionOfFrame(seed, frame);
  }
};

}  // namespace rcm

#endif  // RCM_SIM_EXPOSURE_DELAY_H_
