// NonRigidLayer: matches that are not on the rigid scene. A matcher pairs
// what looks alike in the two images, and on a real dive not everything
// it pairs is a point fixed in the water that both cameras see through
// the rig's geometry. Seen on a real sea dive (a hand-held board at ~1 m,
// a snorkeler and the surface above): most matches off the board lay on
// the water surface's mirror image of the scene (total internal
// reflection off a wavy surface, which each camera sees at another point
// of the surface), on the swimmer's body moving on its own, and on
// particles. Epipolar geometry takes such a match as it takes a rigid one
// as long as it lies near its epipolar curve; the estimators then fit n
// and cam1's rotation to a scene that is not rigid.
//
// The model: a band of the image, the top `image_fraction` of the left
// image (where the surface's mirror is seen from below), whose matches'
// right pixels are moved vertically by an offset the layer keeps over the
// frames (the mirror's mean tilt between the cameras' views) plus a part
// drawn anew for each frame (the waves), the same for every match of the
// frame:
//
//   v_right += offset_px + offset_sd_px * g_f,   g_f ~ N(0, 1),
//
// g_f keyed by (seed, frame), so that the layer moves the right pixels of
// the same points however many frames are drawn. Rows below the band are
// the rigid scene, exactly as without the layer (unless a moved right
// pixel leaves the image: that point is drawn again, and the later draws
// of the sample with it).
//
// Measured in simulation (100 trials, the narrow rig at 0.9-1.1 m, cam1's
// rotation self-calibrated): 0.3 px +- 0.3 px on the top 30 % of the image
// moves n by 4.6 of its sigmas on average; the frames' consistency test
// does not see it, the offset being common to the frames.
#ifndef RCM_SIM_NON_RIGID_LAYER_H_
#define RCM_SIM_NON_RIGID_LAYER_H_

#include <Eigen/Core>
#include <cstdint>

#include "rcm/util/status.h"

namespace rcm {

struct NonRigidLayer {
  // Largest accepted offset, px: beyond it a matcher's epipolar band
  // rejects the matches and the layer is outliers, not a bias.
  static constexpr double kMaxOffsetPx = 10.0;

  // The top fraction of the left image whose matches are on the layer,
  // in [0, 1]. Default 0: every match is on the rigid scene.
  double image_fraction = 0.0;
  // The layer's vertical offset of the right pixel kept over the frames,
  // px, |offset_px| <= kMaxOffsetPx.
  double offset_px = 0.0;
  // Standard deviation of its per-frame part, px, in [0, kMaxOffsetPx].
  double offset_sd_px = 0.0;

  Status Check() const;
  // No effect: no band, or no offset.
  bool IsZero() const {
    return image_fraction == 0.0 || (offset_px == 0.0 && offset_sd_px == 0.0);
  }
  // Whether a left pixel of an image `height` pixels high is on the layer
  // (its row v, pixel centers at integers, above image_fraction * height
  // - 0.5).
  bool Covers(const Eigen::Vector2d& left_pixel, int height) const {
    return left_pixel.y() < image_fraction * height - 0.5;
  }
  // The vertical offset of frame `frame`'s right pixels on the layer, px
  // (0 when IsZero()). Depends only on (seed, frame).
  double OffsetOfFrame(uint64_t seed, int frame) const;
};

}  // namespace rcm

#endif  // RCM_SIM_NON_RIGID_LAYER_H_
