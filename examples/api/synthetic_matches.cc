// API example: stereo correspondences of a rig in water, from the
// refractive camera model itself, written as a correspondence CSV.
//
// It shows the three calls most users of the library start with:
//   ReadStereoRig                 the in-air calibration (Kalibr camchain)
//   SampleStereoCorrespondences   points in the water seen by both cameras
//   WriteCorrespondenceCsv        the file `rcm estimate --matches` reads
//
// The demo data in examples/data were made with it (see the README there).
#include <gflags/gflags.h>
#include <glog/logging.h>

#include <iostream>

#include "rcm/io/correspondence_csv.h"
#include "rcm/io/stereo_rig_file.h"
#include "rcm/sim/stereo_sampler.h"

DEFINE_string(calib, "", "Kalibr camchain YAML of the rig (required)");
DEFINE_string(output, "", "correspondence CSV to write (required)");
DEFINE_double(n, 1.333, "refractive index of the water");
DEFINE_int32(frames, 10, "number of frames");
DEFINE_int32(per_frame, 200, "correspondences per frame");
DEFINE_double(noise, 0.0, "Gaussian pixel noise (standard deviation, px)");
DEFINE_double(min_depth, 0.6, "nearest scene depth (m)");
DEFINE_double(max_depth, 6.0, "farthest scene depth (m)");
DEFINE_uint64(seed, 1, "random seed; the output depends only on the flags");

int main(int argc, char** argv) {
  google::InitGoogleLogging(argv[0]);
  gflags::SetUsageMessage(
      "synthetic_matches --calib RIG.yaml --output MATCHES.csv [--n 1.333] "
      "[--noise 0.1]");
  gflags::ParseCommandLineFlags(&argc, &argv, true);
  if (FLAGS_calib.empty() || FLAGS_output.empty()) {
    std::cerr << "synthetic_matches: error: --calib and --output are required"
              << std::endl;
    return 2;
  }

  const rcm::StatusOr<rcm::StereoRig> rig = rcm::ReadStereoRig(FLAGS_calib);
  if (!rig.ok()) {
    std::cerr << "synthetic_matches: error: " << rig.status().message()
              << std::endl;
    return 1;
  }

  rcm::StereoSamplerOptions options;
  options.n = FLAGS_n;
  options.num_frames = FLAGS_frames;
  options.per_frame = FLAGS_per_frame;
  options.min_depth = FLAGS_min_depth;
  options.max_depth = FLAGS_max_depth;
  options.seed = FLAGS_seed;
  if (FLAGS_noise < 0.0) {
    std::cerr << "synthetic_matches: error: --noise must be >= 0" << std::endl;
    return 2;
  }
  rcm::StatusOr<std::vector<rcm::StereoCorrespondence>> matches =
      rcm::SampleStereoCorrespondences(*rig, options);
  if (!matches.ok()) {
    std::cerr << "synthetic_matches: error: " << matches.status().message()
              << std::endl;
    return 1;
  }
  if (FLAGS_noise > 0.0) {
    rcm::AddPixelNoise(FLAGS_noise, FLAGS_seed + 1, &*matches);
  }

  const rcm::Status written =
      rcm::WriteCorrespondenceCsv(FLAGS_output, *matches);
  if (!written.ok()) {
    std::cerr << "synthetic_matches: error: " << written.message() << std::endl;
    return 1;
  }
  std::cout << "wrote " << matches->size()
            << " correspondences of n = " << FLAGS_n << " to " << FLAGS_output
            << std::endl;
  return 0;
}
