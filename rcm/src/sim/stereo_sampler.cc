#include "rcm/sim/stereo_sampler.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <numeric>
#include <random>
#include <sstream>
#include <utility>

#include "rcm/camera/flat_port_camera.h"
#include "rcm/camera/refractive_camera.h"

namespace rcm {

Status StereoSamplerOptions::Check() const {
  std::ostringstream message;
  if (!std::isfinite(n) || n < RefractiveCamera::kMinIndex ||
      n > RefractiveCamera::kMaxIndex) {
    message << "n = " << n << " is outside [" << RefractiveCamera::kMinIndex
            << ", " << RefractiveCamera::kMaxIndex << "]";
  } else if (!(min_depth > 0.0) || !std::isfinite(max_depth) ||
             !(max_depth >= min_depth)) {
    message << "depth range [" << min_depth << ", " << max_depth
            << "] must satisfy 0 < min_depth <= max_depth < inf";
  } else if (num_frames < 1 || per_frame < 1) {
    message << "num_frames = " << num_frames << " and per_frame = " << per_frame
            << " must be >= 1";
  } else if (!(frame_rate > 0.0) || !std::isfinite(frame_rate)) {
    message << "frame_rate = " << frame_rate << " must be > 0";
  } else if (const Status delay = exposure_delay.Check(); !delay.ok()) {
    return delay;
  } else {
    return non_rigid_layer.Check();
  }
  return Status::Error(message.str());
}

namespace {

// Traces one drawn sample of `frame`: the point at depth Z = `depth` (left
// camera frame) on the ray of left pixel `drawn`, imaged in both cameras.
// Returns false when the point is not visible in both.
using SampleTracer =
    std::function<bool(int frame, const Eigen::Vector2d& drawn, double depth,
                       Eigen::Vector2d* left, Eigen::Vector2d* right)>;

// The sampling loop shared by the model's and the flat port's sampler.
StatusOr<std::vector<StereoCorrespondence>> SampleWithTracer(
    const StereoRig& rig, const StereoSamplerOptions& options,
    const SampleTracer& trace) {
  std::mt19937_64 rng(options.seed);
  std::uniform_real_distribution<double> u_dist(-0.5, rig.left().width() - 0.5);
  std::uniform_real_distribution<double> v_dist(-0.5,
                                                rig.left().height() - 0.5);
  std::uniform_real_distribution<double> depth_dist(options.min_depth,
                                                    options.max_depth);

  const int64_t total =
      static_cast<int64_t>(options.num_frames) * options.per_frame;
  const int64_t max_draws = 100 * total;
  std::vector<StereoCorrespondence> correspondences;
  correspondences.reserve(total);
  int64_t draws = 0;
  std::vector<double> layer_offsets(options.num_frames);
  for (int frame = 0; frame < options.num_frames; ++frame) {
    layer_offsets[frame] =
        options.non_rigid_layer.OffsetOfFrame(options.seed, frame);
  }
  for (int frame = 0; frame < options.num_frames; ++frame) {
    for (int i = 0; i < options.per_frame;) {
      if (++draws > max_draws) {
        std::ostringstream message;
        message << "only " << correspondences.size() << " of " << total
                << " sampled points are visible in both images; do the "
                   "cameras overlap at depths ["
                << options.min_depth << ", " << options.max_depth << "] m?";
        return Status::Error(message.str());
      }
      // v before u, in statements of their own: arguments are evaluated in
      // an unspecified order (gcc right to left, clang left to right), and
      // seeded data must not depend on the compiler. This is the order gcc
      // has always drawn them in.
      const double drawn_v = v_dist(rng);
      const Eigen::Vector2d drawn(u_dist(rng), drawn_v);
      const double depth = depth_dist(rng);
      StereoCorrespondence correspondence;
      if (!trace(frame, drawn, depth, &correspondence.left_pixel,
                 &correspondence.right_pixel)) {
        continue;
      }
      if (options.non_rigid_layer.Covers(correspondence.left_pixel,
                                         rig.left().height())) {
        correspondence.right_pixel.y() += layer_offsets[frame];
      }
      if (!rig.left().InImage(correspondence.left_pixel) ||
          !rig.right().InImage(correspondence.right_pixel)) {
        continue;
      }
      correspondence.frame = frame;
      correspondence.timestamp = frame / options.frame_rate;
      correspondences.push_back(correspondence);
      ++i;
    }
  }
  return correspondences;
}

// cam1's view of each frame (ExposureDelay::RightFromLeftOfFrame).
std::vector<Rigid3d> RightFromLeftOfFrames(
    const StereoRig& rig, const StereoSamplerOptions& options) {
  std::vector<Rigid3d> right_from_left;
  right_from_left.reserve(options.num_frames);
  for (int frame = 0; frame < options.num_frames; ++frame) {
    right_from_left.push_back(options.exposure_delay.RightFromLeftOfFrame(
        rig.right_from_left(), options.seed, frame));
  }
  return right_from_left;
}

}  // namespace

StatusOr<std::vector<StereoCorrespondence>> SampleStereoCorrespondences(
    const StereoRig& rig, const StereoSamplerOptions& options) {
  RCM_RETURN_IF_ERROR(options.Check());
  const RefractiveCamera left =
      RefractiveCamera::Create(rig.left(), options.n).value();
  const RefractiveCamera right =
      RefractiveCamera::Create(rig.right(), options.n).value();
  const std::vector<Rigid3d> right_from_left =
      RightFromLeftOfFrames(rig, options);
  return SampleWithTracer(
      rig, options,
      [&](int frame, const Eigen::Vector2d& drawn, double depth,
          Eigen::Vector2d* left_pixel, Eigen::Vector2d* right_pixel) {
        const std::optional<Eigen::Vector3d> bearing =
            left.BearingInWaterFromImage(drawn);
        if (!bearing) return false;
        const Eigen::Vector3d point_in_left = *bearing * (depth / bearing->z());
        const std::optional<Eigen::Vector2d> l =
            left.ImageFromPointInWater(point_in_left);
        const std::optional<Eigen::Vector2d> r =
            right.ImageFromPointInWater(right_from_left[frame] * point_in_left);
        if (!l || !r) return false;
        *left_pixel = *l;
        *right_pixel = *r;
        return true;
      });
}

StatusOr<std::vector<StereoCorrespondence>> SampleFlatPortCorrespondences(
    const StereoRig& rig, const FlatPort& left_port, const FlatPort& right_port,
    const StereoSamplerOptions& options,
    const std::vector<double>& n_of_frame) {
  RCM_RETURN_IF_ERROR(options.Check());
  if (!n_of_frame.empty() &&
      n_of_frame.size() != static_cast<size_t>(options.num_frames)) {
    std::ostringstream message;
    message << "n_of_frame has " << n_of_frame.size() << " entries for "
            << options.num_frames << " frames";
    return Status::Error(message.str());
  }
  // One pair of port cameras per distinct medium, built once.
  std::vector<double> media = n_of_frame;
  if (media.empty()) media.assign(options.num_frames, options.n);
  std::vector<std::pair<FlatPortCamera, FlatPortCamera>> cameras;
  std::vector<size_t> camera_of_frame(media.size());
  std::vector<double> distinct;
  for (size_t f = 0; f < media.size(); ++f) {
    auto it = std::find(distinct.begin(), distinct.end(), media[f]);
    if (it == distinct.end()) {
      StatusOr<FlatPortCamera> left =
          FlatPortCamera::Create(rig.left(), left_port, media[f]);
      StatusOr<FlatPortCamera> right =
          FlatPortCamera::Create(rig.right(), right_port, media[f]);
      if (!left.ok()) return left.status().WithContext("left port");
      if (!right.ok()) return right.status().WithContext("right port");
      cameras.emplace_back(left.value(), right.value());
      distinct.push_back(media[f]);
      it = distinct.end() - 1;
    }
    camera_of_frame[f] = static_cast<size_t>(it - distinct.begin());
  }
  const std::vector<Rigid3d> right_from_left =
      RightFromLeftOfFrames(rig, options);
  return SampleWithTracer(
      rig, options,
      [&](int frame, const Eigen::Vector2d& drawn, double depth,
          Eigen::Vector2d* left_pixel, Eigen::Vector2d* right_pixel) {
        const auto& [left, right] = cameras[camera_of_frame[frame]];
        const std::optional<RayInMedium> ray = left.RayFromImage(drawn);
        if (!ray || !(ray->direction.z() > 0.0)) return false;
        const Eigen::Vector3d point_in_left =
            ray->origin +
            ray->direction * ((depth - ray->origin.z()) / ray->direction.z());
        const std::optional<Eigen::Vector2d> l =
            left.ImageFromPoint(point_in_left);
        const std::optional<Eigen::Vector2d> r =
            right.ImageFromPoint(right_from_left[frame] * point_in_left);
        if (!l || !r) return false;
        *left_pixel = *l;
        *right_pixel = *r;
        return true;
      });
}

void AddPixelNoise(double sigma_px, uint64_t seed,
                   std::vector<StereoCorrespondence>* correspondences) {
  CHECK(correspondences != nullptr);
  CHECK_GE(sigma_px, 0.0);
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, sigma_px);
  for (StereoCorrespondence& c : *correspondences) {
    c.left_pixel.x() += noise(rng);
    c.left_pixel.y() += noise(rng);
    c.right_pixel.x() += noise(rng);
    c.right_pixel.y() += noise(rng);
  }
}

std::vector<int64_t> AddOutliers(
    const StereoRig& rig, double fraction, uint64_t seed,
    std::vector<StereoCorrespondence>* correspondences) {
  CHECK(correspondences != nullptr);
  CHECK(fraction >= 0.0 && fraction <= 1.0) << fraction;
  std::mt19937_64 rng(seed);
  std::vector<int64_t> order(correspondences->size());
  std::iota(order.begin(), order.end(), int64_t{0});
  std::shuffle(order.begin(), order.end(), rng);
  order.resize(static_cast<size_t>(
      std::llround(fraction * static_cast<double>(order.size()))));
  std::sort(order.begin(), order.end());
  const Camera& right = rig.right();
  std::uniform_real_distribution<double> u(-0.5, right.width() - 0.5);
  std::uniform_real_distribution<double> v(-0.5, right.height() - 0.5);
  for (const int64_t i : order) {
    const double drawn_v = v(rng);  // before u, as above
    (*correspondences)[i].right_pixel = Eigen::Vector2d(u(rng), drawn_v);
  }
  return order;
}

}  // namespace rcm
