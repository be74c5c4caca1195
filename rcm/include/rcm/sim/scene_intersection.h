// What a ray of the simulator meets first: the tank (tank_scene.h) or a
// board held in it (scene_board.h). The one ray cast that the renderer,
// the match sampler and the board's visibility test share, so that the
// images, the matches and the truth agree on what occludes what.
//
// From an origin inside the tank, the tank is always hit (a box seen from
// inside); the board, when given, occludes it where the ray crosses the
// board's printed area closer than the tank's surface:
//   hit = board  if d_board < d_tank,  tank otherwise.
// Without a board the result is the tank's hit, bit for bit.
#ifndef RCM_SIM_SCENE_INTERSECTION_H_
#define RCM_SIM_SCENE_INTERSECTION_H_

#include <Eigen/Core>
#include <optional>

#include "rcm/sim/scene_board.h"
#include "rcm/sim/tank_scene.h"

namespace rcm {

struct SceneHit {
  bool on_board = false;
  SurfaceHit tank;  // the hit when !on_board
  BoardHit board;   // the hit when on_board

  double distance() const { return on_board ? board.distance : tank.distance; }
  const Eigen::Vector3d& point() const {
    return on_board ? board.point : tank.point;
  }
};

// The first surface along the ray; nullopt when the tank's Intersect
// refuses the ray (origin outside the tank, direction not finite or zero).
// `board` may be null (no board in the scene).
std::optional<SceneHit> IntersectScene(
    const TankScene& tank, const PlacedBoard* board,
    const Eigen::Vector3d& origin_in_world,
    const Eigen::Vector3d& unit_direction_in_world);

}  // namespace rcm

#endif  // RCM_SIM_SCENE_INTERSECTION_H_
