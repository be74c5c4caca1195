#include "rcm/sim/stereo_renderer.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <utility>
#include <vector>

#include "rcm/sim/port_camera.h"
#include "rcm/sim/scene_intersection.h"
#include "rcm/util/parallel_for.h"
#include "rcm/util/splitmix64.h"

namespace rcm {
namespace {

constexpr int kMaxSupersampling = 8;
// Floats per cached sample: origin (3), direction (3), angular footprint.
constexpr int kFloatsPerSample = 7;
// Rows per thread below which ParallelFor stays on one thread.
constexpr int64_t kMinRowsPerThread = 8;

// A sample whose ray could be traced (a unit direction, not zero).
bool ValidSample(const float* sample) {
  return sample[3] * sample[3] + sample[4] * sample[4] + sample[5] * sample[5] >
         0.5f;
}

// The chord between two unit directions (the angle between them, to
// second order).
float Chord(const float* a, const float* b) {
  const float dx = a[3] - b[3], dy = a[4] - b[4], dz = a[5] - b[5];
  return std::sqrt(dx * dx + dy * dy + dz * dz);
}

// Fills `samples` with the rays of every sample of `camera` (see RayTable).
void TraceSamples(const PortCamera& camera, int supersampling, int num_threads,
                  std::vector<float>* samples) {
  const int s = supersampling;
  const int64_t columns = static_cast<int64_t>(camera.camera().width()) * s;
  const int64_t rows = static_cast<int64_t>(camera.camera().height()) * s;
  samples->assign(columns * rows * kFloatsPerSample, 0.0f);
  float* data = samples->data();
  ParallelFor(rows, num_threads, kMinRowsPerThread,
              [&](int64_t begin, int64_t end) {
                for (int64_t sy = begin; sy < end; ++sy) {
                  const double v = (sy + 0.5) / s - 0.5;
                  for (int64_t sx = 0; sx < columns; ++sx) {
                    const double u = (sx + 0.5) / s - 0.5;
                    const std::optional<RayInMedium> ray =
                        camera.RayFromImage(Eigen::Vector2d(u, v));
                    if (!ray) continue;
                    float* out = data + (sy * columns + sx) * kFloatsPerSample;
                    for (int k = 0; k < 3; ++k) {
                      out[k] = static_cast<float>(ray->origin[k]);
                      out[3 + k] = static_cast<float>(ray->direction[k]);
                    }
                  }
                }
              });
  // Angular footprint: the larger of the angles to the neighbouring samples
  // along x and y (one-sided at the borders and next to untraceable ones).
  const float fallback = static_cast<float>(
      1.0 / (s * std::max(camera.camera().fx(), camera.camera().fy())));
  ParallelFor(
      rows, num_threads, kMinRowsPerThread, [&](int64_t begin, int64_t end) {
        const auto at = [&](int64_t x, int64_t y) -> const float* {
          if (x < 0 || y < 0 || x >= columns || y >= rows) return nullptr;
          const float* sample = data + (y * columns + x) * kFloatsPerSample;
          return ValidSample(sample) ? sample : nullptr;
        };
        for (int64_t sy = begin; sy < end; ++sy) {
          for (int64_t sx = 0; sx < columns; ++sx) {
            float* sample = data + (sy * columns + sx) * kFloatsPerSample;
            if (!ValidSample(sample)) continue;
            float footprint = 0.0f;
            bool found = false;
            for (const auto& [dx, dy] :
                 {std::pair<int, int>{1, 0}, std::pair<int, int>{0, 1}}) {
              const float* next = at(sx + dx, sy + dy);
              if (next == nullptr) next = at(sx - dx, sy - dy);
              if (next == nullptr) continue;
              footprint = std::max(footprint, Chord(sample, next));
              found = true;
            }
            sample[6] = found ? footprint : fallback;
          }
        }
      });
}

}  // namespace

// The sample rays of one camera in one medium, in the camera frame: for
// sample (sx, sy) of the (width s) x (height s) grid, kFloatsPerSample
// floats at index sy * (width s) + sx. A sample that cannot be traced has
// a zero direction.
struct StereoRenderer::RayTable {
  int width = 0;  // pixels
  int height = 0;
  std::vector<float> samples;
};

Status RenderOptions::Check() const {
  std::ostringstream message;
  const auto nonnegative = [](double value) {
    return std::isfinite(value) && value >= 0.0;
  };
  if (supersampling < 1 || supersampling > kMaxSupersampling) {
    message << "supersampling = " << supersampling << " is outside [1, "
            << kMaxSupersampling << "]";
  } else if (!nonnegative(water_attenuation) || !nonnegative(air_attenuation)) {
    message << "attenuation coefficients (water " << water_attenuation
            << ", air " << air_attenuation << " per m) must be >= 0";
  } else if (!nonnegative(water_radiance) || water_radiance > 1.0) {
    message << "water_radiance = " << water_radiance << " is outside [0, 1]";
  } else if (!nonnegative(ambient) || !nonnegative(light_intensity) ||
             !nonnegative(light_beam_exponent) ||
             !nonnegative(surface_radiance)) {
    message << "ambient, light_intensity, light_beam_exponent and "
               "surface_radiance must be finite and >= 0";
  } else if (!light_position_in_cam0.allFinite()) {
    message << "light_position_in_cam0 must be finite";
  } else if (!(exposure > 0.0) || !std::isfinite(exposure)) {
    message << "exposure = " << exposure << " must be > 0";
  } else if (!nonnegative(read_noise)) {
    message << "read_noise = " << read_noise << " DN must be >= 0";
  } else if (!std::isfinite(full_well) ||
             !(full_well == 0.0 || full_well >= 1.0)) {
    message << "full_well = " << full_well
            << " electrons must be 0 (no shot noise) or >= 1";
  } else if (num_threads < 1) {
    message << "num_threads = " << num_threads << " must be >= 1";
  } else if (max_cached_indices < 1) {
    message << "max_cached_indices = " << max_cached_indices << " must be >= 1";
  } else {
    return Status::Ok();
  }
  return Status::Error(message.str());
}

StatusOr<StereoRenderer> StereoRenderer::Create(
    const StereoRig& rig, const FlatPort& left_port, const FlatPort& right_port,
    const TankScene* scene, const RenderOptions& options,
    const std::optional<DomePort>& left_dome,
    const std::optional<DomePort>& right_dome) {
  RCM_RETURN_IF_ERROR(options.Check());
  if (scene == nullptr) return Status::Error("the renderer needs a scene");
  RCM_RETURN_IF_ERROR(left_port.Check().WithContext("left"));
  RCM_RETURN_IF_ERROR(right_port.Check().WithContext("right"));
  if (left_dome) RCM_RETURN_IF_ERROR(left_dome->Check().WithContext("left"));
  if (right_dome) {
    RCM_RETURN_IF_ERROR(right_dome->Check().WithContext("right"));
  }
  return StereoRenderer(rig, left_port, right_port, scene, options, left_dome,
                        right_dome);
}

StatusOr<const StereoRenderer::CacheEntry*> StereoRenderer::Rays(double n) {
  for (const CacheEntry& entry : cache_) {
    if (entry.n == n) return &entry;
  }
  CacheEntry entry;
  entry.n = n;
  for (int c = 0; c < 2; ++c) {
    const Camera& camera = c == 0 ? rig_.left() : rig_.right();
    StatusOr<PortCamera> port_camera =
        PortCamera::Create(camera, ports_[c], domes_[c], n);
    if (!port_camera.ok()) return port_camera.status();
    auto table = std::make_shared<RayTable>();
    table->width = camera.width();
    table->height = camera.height();
    TraceSamples(port_camera.value(), options_.supersampling,
                 options_.num_threads, &table->samples);
    entry.tables[c] = std::move(table);
  }
  if (static_cast<int>(cache_.size()) >= options_.max_cached_indices) {
    cache_.erase(cache_.begin());
  }
  cache_.push_back(std::move(entry));
  return &cache_.back();
}

Status StereoRenderer::PrepareRays(double n) { return Rays(n).status(); }

StatusOr<StereoImages> StereoRenderer::Render(
    const Rigid3d& world_from_cam0, double n, int64_t frame_index,
    const PlacedBoard* board, const std::optional<Rigid3d>& right_from_left) {
  const Rigid3d world_from_cam[2] = {
      world_from_cam0,
      world_from_cam0 *
          right_from_left.value_or(rig_.right_from_left()).Inverse()};
  for (int c = 0; c < 2; ++c) {
    if (!scene_->Contains(world_from_cam[c].translation)) {
      const Eigen::Vector3d& p = world_from_cam[c].translation;
      std::ostringstream message;
      message << (c == 0 ? "left" : "right") << " camera at (" << p.x() << ", "
              << p.y() << ", " << p.z() << ") is outside the tank";
      return Status::Error(message.str());
    }
  }
  StatusOr<const CacheEntry*> rays = Rays(n);
  if (!rays.ok()) return rays.status();
  const CacheEntry& entry = *rays.value();

  const RenderOptions& o = options_;
  const double attenuation = n > 1.0 ? o.water_attenuation : o.air_attenuation;
  const Eigen::Vector3d light_position =
      world_from_cam0 * o.light_position_in_cam0;
  const Eigen::Vector3d light_axis = world_from_cam0.rotation.col(2);
  const bool light_on = o.light_intensity > 0.0;
  const int s = o.supersampling;
  const double dn_scale = 255.0 * o.exposure / (s * s);
  const double shot_scale = o.full_well > 0.0 ? 255.0 / o.full_well : 0.0;
  const double read_variance = o.read_noise * o.read_noise;
  const bool noisy = read_variance > 0.0 || shot_scale > 0.0;
  const uint64_t frame_key =
      SplitMix64(SplitMix64(o.seed) + static_cast<uint64_t>(frame_index));

  // cos^k of the angle off the light's axis; integer k by multiplication
  // (the default 2 would otherwise cost a pow per sample).
  const double beam_exponent = o.light_beam_exponent;
  const bool exponent_is_integer =
      beam_exponent <= 8.0 && std::floor(beam_exponent) == beam_exponent;
  const int integer_exponent =
      exponent_is_integer ? static_cast<int>(beam_exponent) : 0;
  const auto beam = [&](double cosine) {
    if (!exponent_is_integer) return std::pow(cosine, beam_exponent);
    double power = 1.0;
    for (int k = 0; k < integer_exponent; ++k) power *= cosine;
    return power;
  };
  // Irradiance of a reflecting surface at `point` of unit normal `normal`
  // (pointing back to the camera): daylight and the lamp (see the header).
  const auto irradiance_at = [&](const Eigen::Vector3d& point,
                                 const Eigen::Vector3d& normal) {
    double irradiance = o.ambient * (0.7 + 0.3 * normal.z());
    if (light_on) {
      const Eigen::Vector3d to_point = point - light_position;
      const double r2 = to_point.squaredNorm();
      const double r = std::sqrt(r2);
      const double cos_beam = light_axis.dot(to_point) / r;
      const double cos_incidence = -normal.dot(to_point) / r;
      if (cos_beam > 0.0 && cos_incidence > 0.0) {
        irradiance += o.light_intensity * beam(cos_beam) * cos_incidence *
                      std::exp(-attenuation * r) / r2;
      }
    }
    return irradiance;
  };
  // Radiance `emitted` at `distance` from the port, seen through the medium.
  const auto through_medium = [&](double emitted, double distance) {
    if (attenuation == 0.0) return emitted;
    const double transmittance = std::exp(-attenuation * distance);
    return emitted * transmittance + o.water_radiance * (1.0 - transmittance);
  };
  // Radiance reaching the port along a traced sample (see the header).
  const auto radiance = [&](const SceneHit& scene_hit,
                            const Eigen::Vector3d& direction,
                            double angular_footprint) {
    if (scene_hit.on_board) {
      const BoardHit& hit = scene_hit.board;
      const double albedo =
          board->board().Shade(hit, angular_footprint * hit.distance);
      return through_medium(albedo * irradiance_at(hit.point, hit.normal),
                            hit.distance);
    }
    const SurfaceHit& hit = scene_hit.tank;
    const double albedo = scene_->ShadeAnisotropic(
        hit, direction, angular_footprint * hit.distance);
    const double emitted = TankScene::IsEmissive(hit.surface)
                               ? o.surface_radiance * albedo
                               : albedo * irradiance_at(hit.point, hit.normal);
    return through_medium(emitted, hit.distance);
  };

  StereoImages images;
  cv::Mat* outputs[2] = {&images.left, &images.right};
  int heights[2];
  for (int c = 0; c < 2; ++c) {
    const RayTable& table = *entry.tables[c];
    outputs[c]->create(table.height, table.width, CV_8UC1);
    heights[c] = table.height;
  }
  ParallelFor(
      static_cast<int64_t>(heights[0]) + heights[1], o.num_threads,
      kMinRowsPerThread, [&](int64_t begin, int64_t end) {
        for (int64_t r = begin; r < end; ++r) {
          const int c = r < heights[0] ? 0 : 1;
          const int y = static_cast<int>(c == 0 ? r : r - heights[0]);
          const RayTable& table = *entry.tables[c];
          const Eigen::Matrix3d& rotation = world_from_cam[c].rotation;
          const Eigen::Vector3d& translation = world_from_cam[c].translation;
          const int64_t columns = static_cast<int64_t>(table.width) * s;
          const uint64_t camera_key = SplitMix64(frame_key + c);
          uint8_t* out = outputs[c]->ptr<uint8_t>(y);
          for (int x = 0; x < table.width; ++x) {
            double sum = 0.0;
            int traced = 0;
            for (int j = 0; j < s; ++j) {
              const float* sample =
                  table.samples.data() +
                  ((static_cast<int64_t>(y) * s + j) * columns +
                   static_cast<int64_t>(x) * s) *
                      kFloatsPerSample;
              for (int i = 0; i < s; ++i, sample += kFloatsPerSample) {
                if (!ValidSample(sample)) continue;
                const Eigen::Vector3d origin =
                    rotation *
                        Eigen::Vector3d(sample[0], sample[1], sample[2]) +
                    translation;
                const Eigen::Vector3d direction =
                    rotation * Eigen::Vector3d(sample[3], sample[4], sample[5]);
                const std::optional<SceneHit> hit =
                    IntersectScene(*scene_, board, origin, direction);
                if (!hit) continue;
                sum += radiance(*hit, direction, sample[6]);
                ++traced;
              }
            }
            if (traced == 0) {
              out[x] = 0;
              continue;
            }
            double dn = dn_scale * sum;
            if (noisy) {
              const uint64_t pixel = static_cast<uint64_t>(y) * table.width + x;
              const double variance =
                  read_variance + shot_scale * std::max(dn, 0.0);
              dn += std::sqrt(variance) *
                    GaussianFromHash(SplitMix64(camera_key + pixel));
            }
            out[x] = static_cast<uint8_t>(std::clamp(dn, 0.0, 255.0) + 0.5);
          }
        }
      });
  return images;
}

}  // namespace rcm
