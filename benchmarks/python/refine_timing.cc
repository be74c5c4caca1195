// The C++ side of refine_benchmark.py: times rcm::RefineRefractiveIndex on
// a rig file and a correspondence file, the same call the Python package
// makes, and prints one JSON object.
//
//   rcm_refine_timing RIG.yaml MATCHES.csv [REPEATS]
//
// prints {"n": ..., "sigma_n": ..., "inliers": ..., "seconds": [...]}
// with n and sigma_n to 17 significant digits (exact doubles) and the wall
// time of each repeat (reading the files is not timed). Default options
// (RefinementOptions()), as rcm.refine_refractive_index without keywords.
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "rcm/estimation/batch_refinement.h"
#include "rcm/io/correspondence_csv.h"
#include "rcm/io/stereo_rig_file.h"

int main(int argc, char** argv) {
  if (argc < 3 || argc > 4) {
    std::fprintf(stderr, "usage: %s RIG.yaml MATCHES.csv [REPEATS]\n", argv[0]);
    return 2;
  }
  const int repeats = argc == 4 ? std::atoi(argv[3]) : 1;
  if (repeats < 1) {
    std::fprintf(stderr, "REPEATS must be >= 1\n");
    return 2;
  }
  const rcm::StatusOr<rcm::StereoRig> rig = rcm::ReadStereoRig(argv[1]);
  if (!rig.ok()) {
    std::fprintf(stderr, "%s\n", rig.status().message().c_str());
    return 1;
  }
  const rcm::StatusOr<std::vector<rcm::StereoCorrespondence>> matches =
      rcm::ReadCorrespondenceCsv(argv[2]);
  if (!matches.ok()) {
    std::fprintf(stderr, "%s\n", matches.status().message().c_str());
    return 1;
  }
  std::vector<double> seconds;
  rcm::StatusOr<rcm::RefinementSummary> summary = rcm::Status::Error("not run");
  for (int i = 0; i < repeats; ++i) {
    const auto start = std::chrono::steady_clock::now();
    summary =
        rcm::RefineRefractiveIndex(*rig, *matches, rcm::RefinementOptions());
    seconds.push_back(
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
            .count());
    if (!summary.ok()) {
      std::fprintf(stderr, "%s\n", summary.status().message().c_str());
      return 1;
    }
  }
  std::printf(
      "{\"n\": %.17g, \"sigma_n\": %.17g, \"inliers\": %zu, \"seconds\": [",
      summary->n, summary->sigma_n, summary->inliers.size());
  for (size_t i = 0; i < seconds.size(); ++i) {
    std::printf("%s%.6f", i ? ", " : "", seconds[i]);
  }
  std::printf("]}\n");
  return 0;
}
