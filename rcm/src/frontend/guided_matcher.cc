#include "rcm/frontend/guided_matcher.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/core/hal/hal.hpp>

#include "rcm/util/parallel_for.h"

namespace rcm {
namespace {

// The sorted index of the right keys.
struct RightIndex {
  std::vector<double> center;  // ascending
  std::vector<int> keypoint;   // right keypoint of each entry
  std::vector<LocusKey> key;   // its key (in this order: read in sequence)
  double max_half_width = 0.0;
};

RightIndex IndexRightKeys(const std::vector<LocusKey>& keys) {
  std::vector<int> order;
  order.reserve(keys.size());
  RightIndex index;
  for (size_t j = 0; j < keys.size(); ++j) {
    if (!keys[j].valid) continue;
    order.push_back(static_cast<int>(j));
    index.max_half_width =
        std::max(index.max_half_width,
                 0.5 * std::abs(keys[j].phi[1] - keys[j].phi[0]));
  }
  const auto center = [&](int j) {
    return 0.5 * (keys[j].phi[0] + keys[j].phi[1]);
  };
  std::sort(order.begin(), order.end(),
            [&](int a, int b) { return center(a) < center(b); });
  index.keypoint = order;
  index.center.reserve(order.size());
  index.key.reserve(order.size());
  for (int j : order) {
    index.center.push_back(center(j));
    index.key.push_back(keys[j]);
  }
  return index;
}

// Descriptor distance: bits for binary descriptors, L2 for float ones.
float Distance(const cv::Mat& a, int i, const cv::Mat& b, int j,
               int norm_type) {
  if (norm_type == cv::NORM_L2) {
    return std::sqrt(cv::hal::normL2Sqr_(a.ptr<float>(i), b.ptr<float>(j),
                                         a.cols));
  }
  return static_cast<float>(
      cv::hal::normHamming(a.ptr<uchar>(i), b.ptr<uchar>(j), a.cols));
}

// Per thread: the best forward match of each left keypoint of its range and
// the best left keypoint seen for each right one.
struct Partial {
  std::vector<float> best_left_distance;  // per right keypoint
  std::vector<int> best_left;
};

}  // namespace

Status GuidedMatchOptions::Check() const {
  if (!(ratio > 0.0 && ratio <= 1.0)) {
    return Status::Error("ratio test threshold must be in (0, 1], got " +
                         std::to_string(ratio));
  }
  if (max_hamming_distance < 0 || max_hamming_distance > 256) {
    return Status::Error("max Hamming distance must be in [0, 256], got " +
                         std::to_string(max_hamming_distance));
  }
  if (num_threads < 1) {
    return Status::Error("threads must be at least 1, got " +
                         std::to_string(num_threads));
  }
  return Status::Ok();
}

std::vector<KeypointMatch> MatchInLocusBand(
    const Features& left, const std::vector<LocusKey>& left_keys,
    const Features& right, const std::vector<LocusKey>& right_keys,
    const LocusBand& band, const GuidedMatchOptions& options) {
  CHECK(options.Check().ok()) << options.Check().message();
  CHECK_EQ(left.keypoints.size(), left_keys.size());
  CHECK_EQ(right.keypoints.size(), right_keys.size());
  CHECK_EQ(left.norm_type, right.norm_type);
  const int num_left = static_cast<int>(left.keypoints.size());
  const int num_right = static_cast<int>(right.keypoints.size());
  std::vector<KeypointMatch> forward(num_left, KeypointMatch{-1, -1, 0.0f});
  if (num_left == 0 || num_right == 0) return {};
  CHECK_EQ(left.descriptors.cols, right.descriptors.cols);

  const RightIndex index = IndexRightKeys(right_keys);
  const double tolerance = band.angle_tolerance();
  const bool binary = left.norm_type != cv::NORM_L2;
  const double ratio = options.ratio;
  const float max_distance =
      binary ? static_cast<float>(options.max_hamming_distance)
             : std::numeric_limits<float>::infinity();

  const int threads = std::max(1, options.num_threads);
  std::vector<Partial> partials(threads);
  // Chunks of left keypoints; each thread writes its own chunk of
  // `forward` and its own Partial.
  const int64_t chunk = (num_left + threads - 1) / threads;
  ParallelFor(threads, threads, 1, [&](int64_t first, int64_t last) {
    for (int64_t t = first; t < last; ++t) {
      Partial& partial = partials[t];
      partial.best_left_distance.assign(
          num_right, std::numeric_limits<float>::infinity());
      partial.best_left.assign(num_right, -1);
      const int begin = static_cast<int>(t * chunk);
      const int end = static_cast<int>(std::min<int64_t>(num_left,
                                                         (t + 1) * chunk));
      for (int i = begin; i < end; ++i) {
        const LocusKey& key = left_keys[i];
        if (!key.valid) continue;
        const double center = 0.5 * (key.phi[0] + key.phi[1]);
        const double reach = 0.5 * std::abs(key.phi[1] - key.phi[0]) +
                             index.max_half_width + tolerance;
        auto it = std::lower_bound(index.center.begin(), index.center.end(),
                                   center - reach);
        float d1 = std::numeric_limits<float>::infinity();
        float d2 = d1;
        int best = -1;
        for (; it != index.center.end() && *it <= center + reach; ++it) {
          const ptrdiff_t entry = it - index.center.begin();
          if (!band.Contains(key, index.key[entry])) continue;
          const int j = index.keypoint[entry];
          const float d = Distance(left.descriptors, i, right.descriptors, j,
                                   left.norm_type);
          if (d < d1) {
            d2 = d1;
            d1 = d;
            best = j;
          } else if (d < d2) {
            d2 = d;
          }
          if (d < partial.best_left_distance[j]) {
            partial.best_left_distance[j] = d;
            partial.best_left[j] = i;
          }
        }
        if (best < 0 || d1 > max_distance) continue;
        if (std::isfinite(d2) && !(d1 < ratio * d2)) continue;
        forward[i] = KeypointMatch{i, best, d1};
      }
    }
  });

  // The best left keypoint of each right one over all threads; ties go to
  // the lower left index, as a single thread would.
  std::vector<int> best_left(num_right, -1);
  if (options.cross_check) {
    std::vector<float> best_distance(num_right,
                                     std::numeric_limits<float>::infinity());
    for (const Partial& partial : partials) {
      for (int j = 0; j < num_right; ++j) {
        if (partial.best_left_distance[j] < best_distance[j]) {
          best_distance[j] = partial.best_left_distance[j];
          best_left[j] = partial.best_left[j];
        }
      }
    }
  }
  std::vector<KeypointMatch> matches;
  for (const KeypointMatch& match : forward) {
    if (match.left < 0) continue;
    if (options.cross_check && best_left[match.right] != match.left) continue;
    matches.push_back(match);
  }
  return matches;
}

}  // namespace rcm
