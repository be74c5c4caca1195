// The scene and pose the simulator's tests render: the default textured
// pool and the first pose of the default trajectory.
#ifndef RCM_TESTS_SIM_TEST_POOL_H_
#define RCM_TESTS_SIM_TEST_POOL_H_

#include "rcm/geometry/rigid3d.h"
#include "rcm/sim/tank_scene.h"
#include "rcm/sim/trajectory.h"

namespace rcm::test {

// The default textured pool (12 x 8 x 3 m), built once (~0.3 s).
inline const TankScene& Pool() {
  static const TankScene* const scene =
      new TankScene(TankScene::Create(TankSceneOptions()).value());
  return *scene;
}

// The first pose of the default trajectory: 1.2 m up, 16 degrees down.
inline Rigid3d RobotPose() {
  return GenerateTrajectory(Pool(), TrajectoryOptions())
      .value()[0]
      .world_from_cam0;
}

}  // namespace rcm::test

#endif  // RCM_TESTS_SIM_TEST_POOL_H_
