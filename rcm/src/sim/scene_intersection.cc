#include "rcm/sim/scene_intersection.h"

namespace rcm {

std::optional<SceneHit> IntersectScene(
    const TankScene& tank, const PlacedBoard* board,
    const Eigen::Vector3d& origin_in_world,
    const Eigen::Vector3d& unit_direction_in_world) {
  const std::optional<SurfaceHit> tank_hit =
      tank.Intersect(origin_in_world, unit_direction_in_world);
  if (!tank_hit) return std::nullopt;
  SceneHit hit;
  if (board != nullptr) {
    const std::optional<BoardHit> board_hit =
        board->Intersect(origin_in_world, unit_direction_in_world);
    if (board_hit && board_hit->distance < tank_hit->distance) {
      hit.on_board = true;
      hit.board = *board_hit;
      return hit;
    }
  }
  hit.tank = *tank_hit;
  return hit;
}

}  // namespace rcm
