// A program outside the rcm tree that uses the installed library for two
// of the jobs rcm exists for: n from your own stereo matches, and the
// corrected camera models to hand to odometry.
//
//   consumer CAMCHAIN.yaml MATCHES.csv
//
// prints n +- sigma_n (17 significant digits, so that a test can compare
// it with `rcm estimate --json` on the same files) and the rectified
// pinhole camera of the corrected images at that n.
#include <cstdio>

#include "rcm/estimation/batch_refinement.h"
#include "rcm/io/correspondence_csv.h"
#include "rcm/io/stereo_rig_file.h"
#include "rcm/stereo/virtual_pinhole_rig.h"

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: consumer CAMCHAIN.yaml MATCHES.csv\n");
    return 2;
  }
  // The in-air calibration, with its covariance sidecar or the default
  // drift prior, and the matches (pixels of the raw images).
  const rcm::StatusOr<rcm::StereoRig> rig = rcm::ReadStereoRig(argv[1]);
  if (!rig.ok()) {
    std::fprintf(stderr, "consumer: %s\n", rig.status().message().c_str());
    return 1;
  }
  const auto matches = rcm::ReadCorrespondenceCsv(argv[2]);
  if (!matches.ok()) {
    std::fprintf(stderr, "consumer: %s\n", matches.status().message().c_str());
    return 1;
  }

  // n with the library's defaults (robust refinement, sigma_n counting the
  // pixel noise and the calibration).
  const auto summary =
      rcm::RefineRefractiveIndex(*rig, *matches, rcm::RefinementOptions());
  if (!summary.ok()) {
    std::fprintf(stderr, "consumer: %s\n", summary.status().message().c_str());
    return 1;
  }
  std::printf("n = %.17g\nsigma_n = %.17g\ninliers = %zu of %lld\n", summary->n,
              summary->sigma_n, summary->inliers.size(),
              static_cast<long long>(summary->num_correspondences));

  // The corrected pair at that n: rectified pinhole images whose model a
  // VIO takes as is.
  rcm::VirtualPinholeRigOptions corrected_options;
  corrected_options.rectify = true;
  const auto corrected =
      rcm::VirtualPinholeRig::Create(*rig, summary->n, corrected_options);
  if (!corrected.ok()) {
    std::fprintf(stderr, "consumer: %s\n",
                 corrected.status().message().c_str());
    return 1;
  }
  const rcm::Camera& left = corrected->left().pinhole;
  std::printf("corrected K = [%.6f %.6f %.6f %.6f] %dx%d\n", left.fx(),
              left.fy(), left.cx(), left.cy(), left.width(), left.height());
  return 0;
}
