#include "rcm/sim/scene_board.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <sstream>

namespace rcm {
namespace {

constexpr int kMinCorners = 2;
constexpr int kMaxCorners = 100;
constexpr double kMinSquare = 0.005;  // meters
constexpr double kMaxSquare = 0.5;
// Rays more grazing than this (|cos|) are filtered as if this grazing: the
// footprint is at most 64 times longer than wide (as on the tank's
// surfaces).
constexpr double kMinFootprintCosine = 1.0 / 64.0;

// The antiderivative of the square wave q (+1 on [0, square), -1 on
// [square, 2 square), period 2 square) with P(0) = 0: the triangle wave.
double TriangleWave(double u, double square) {
  const double period = 2.0 * square;
  const double r = u - period * std::floor(u / period);
  return r < square ? r : period - r;
}

// q(u), the square wave itself.
double SquareWave(double u, double square) {
  return static_cast<int64_t>(std::floor(u / square)) % 2 == 0 ? 1.0 : -1.0;
}

// The box means over [u - h, u + h] of the indicator of [lo, hi] and of q
// times it (see the header): {F[I], F[q I]}.
struct BoxMeans {
  double indicator = 0.0;
  double wave = 0.0;
};

BoxMeans AxisBoxMeans(double u, double h, double lo, double hi, double square) {
  BoxMeans means;
  if (!(h > 0.0)) {
    if (u >= lo && u < hi) {
      means.indicator = 1.0;
      means.wave = SquareWave(u, square);
    }
    return means;
  }
  const double a = std::max(u - h, lo);
  const double b = std::min(u + h, hi);
  if (b <= a) return means;
  const double scale = 0.5 / h;
  means.indicator = (b - a) * scale;
  means.wave = (TriangleWave(b, square) - TriangleWave(a, square)) * scale;
  return means;
}

}  // namespace

Status SceneBoard::Check() const {
  std::ostringstream message;
  if (cols < kMinCorners || cols > kMaxCorners || rows < kMinCorners ||
      rows > kMaxCorners) {
    message << "board of " << cols << " x " << rows
            << " inner corners: each count must be in [" << kMinCorners << ", "
            << kMaxCorners << "]";
  } else if (!(square >= kMinSquare && square <= kMaxSquare)) {
    message << "board square = " << square << " m is outside [" << kMinSquare
            << ", " << kMaxSquare << "]";
  } else if (!(black_albedo >= 0.0 && black_albedo < white_albedo &&
               white_albedo <= 1.0)) {
    message << "board albedos (black " << black_albedo << ", white "
            << white_albedo << ") must satisfy 0 <= black < white <= 1";
  } else if (!(std::abs(warp.x()) <= kMaxWarp &&
               std::abs(warp.y()) <= kMaxWarp)) {
    message << "board warp (" << warp.x() << ", " << warp.y()
            << ") m: each must be within " << kMaxWarp << " m";
  } else {
    return Status::Ok();
  }
  return Status::Error(message.str());
}

BoardWarpSurface SceneBoard::WarpSurface() const {
  BoardWarpSurface surface;
  surface.extent = Eigen::Vector2d((cols - 1) * square, (rows - 1) * square);
  surface.warp = warp;
  return surface;
}

double SceneBoard::Height(double x, double y) const {
  // A flat board's corners keep z = 0 bit for bit (not -0).
  return warp.isZero(0.0) ? 0.0 : WarpSurface().Height(x, y);
}

Eigen::Vector2d SceneBoard::Slope(double x, double y) const {
  return WarpSurface().Slope(x, y);
}

std::vector<Eigen::Vector3d> SceneBoard::Corners() const {
  std::vector<Eigen::Vector3d> corners;
  corners.reserve(static_cast<size_t>(cols) * rows);
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      corners.emplace_back(c * square, r * square,
                           Height(c * square, r * square));
    }
  }
  return corners;
}

std::vector<Eigen::Vector3d> SceneBoard::PatternOutline() const {
  // Lattice indices i in [-1, cols], j in [-1, rows]; the border walked
  // clockwise as seen from the printed side (x right, y down).
  std::vector<Eigen::Vector3d> outline;
  outline.reserve(2 * (cols + rows) + 4);
  const auto add = [&](int i, int j) {
    outline.emplace_back(i * square, j * square,
                         Height(i * square, j * square));
  };
  for (int i = -1; i < cols; ++i) add(i, -1);
  for (int j = -1; j < rows; ++j) add(cols, j);
  for (int i = cols; i > -1; --i) add(i, rows);
  for (int j = rows; j > -1; --j) add(-1, j);
  return outline;
}

Eigen::Vector3d SceneBoard::Center() const {
  return Eigen::Vector3d(0.5 * (cols - 1) * square, 0.5 * (rows - 1) * square,
                         0.0);
}

double SceneBoard::FilteredAlbedo(double x, double y, double hx,
                                  double hy) const {
  const BoxMeans along_x = AxisBoxMeans(x, hx, -square, cols * square, square);
  const BoxMeans along_y = AxisBoxMeans(y, hy, -square, rows * square, square);
  const double black = 0.5 * (along_x.indicator * along_y.indicator +
                              along_x.wave * along_y.wave);
  return black_albedo * black + white_albedo * (1.0 - black);
}

double SceneBoard::Shade(const BoardHit& hit, double footprint) const {
  if (!hit.printed_side) return white_albedo;
  const Eigen::Vector3d& v = hit.direction_in_target;
  const double cosine = std::max(std::abs(v.z()), kMinFootprintCosine);
  const double in_plane = v.x() * v.x() + v.y() * v.y();
  // u = (ux, uy): the ray's direction along the board (any unit vector
  // when it meets the board head on, and then along = across).
  const double ux2 = in_plane > 0.0 ? v.x() * v.x() / in_plane : 1.0;
  const double uy2 = in_plane > 0.0 ? v.y() * v.y() / in_plane : 0.0;
  const double across = footprint * footprint;
  const double along = across / (cosine * cosine);
  const double hx = 0.5 * std::sqrt(along * ux2 + across * uy2);
  const double hy = 0.5 * std::sqrt(along * uy2 + across * ux2);
  return FilteredAlbedo(hit.point_in_target.x(), hit.point_in_target.y(), hx,
                        hy);
}

std::optional<BoardHit> PlacedBoard::Intersect(
    const Eigen::Vector3d& origin_in_world,
    const Eigen::Vector3d& unit_direction_in_world) const {
  const Eigen::Vector3d o = target_from_world_ * origin_in_world;
  const Eigen::Vector3d v =
      target_from_world_.rotation * unit_direction_in_world;
  if (!(v.z() != 0.0)) return std::nullopt;  // parallel, or NaN
  double t = -o.z() / v.z();
  Eigen::Vector3d surface_normal = Eigen::Vector3d::UnitZ();  // target, +z
  if (!board_.warp.isZero(0.0)) {
    // Newton's method on f(t) (file comment), from the plane's hit.
    constexpr int kMaxIterations = 20;
    constexpr double kStepTolerance = 1e-12;  // meters
    bool settled = false;
    for (int k = 0; k < kMaxIterations && std::isfinite(t); ++k) {
      const double x = o.x() + t * v.x();
      const double y = o.y() + t * v.y();
      const double f = o.z() + t * v.z() - board_.Height(x, y);
      const double slope = v.z() - board_.Slope(x, y).dot(v.head<2>());
      if (!(slope != 0.0)) break;
      const double step = f / slope;
      t -= step;
      if (std::abs(step) < kStepTolerance) {
        settled = true;
        break;
      }
    }
    if (!settled) return std::nullopt;
    const Eigen::Vector2d gradient =
        board_.Slope(o.x() + t * v.x(), o.y() + t * v.y());
    surface_normal =
        Eigen::Vector3d(-gradient.x(), -gradient.y(), 1.0).normalized();
  }
  if (!(t > 0.0)) return std::nullopt;
  const double x = o.x() + t * v.x();
  const double y = o.y() + t * v.y();
  if (!board_.InPrintedArea(x, y)) return std::nullopt;
  BoardHit hit;
  hit.distance = t * unit_direction_in_world.norm();
  hit.point = origin_in_world + t * unit_direction_in_world;
  hit.printed_side = v.dot(surface_normal) > 0.0;
  hit.normal = world_from_target_.rotation * surface_normal *
               (hit.printed_side ? -1.0 : 1.0);
  hit.point_in_target = Eigen::Vector2d(x, y);
  hit.direction_in_target = v;
  return hit;
}

}  // namespace rcm
