// The odometry table of docs/bundle.md (issue 32, item 4; the paper's
// Table I with ground truth): a rendered dive of each rig once around a
// 5 m x 5 m pool, back where it began, cam1 turned 0.5 degrees since the
// calibration; the trajectory error of the bundle adjustment over its
// tracks with n estimated, held at the truth, held at 1, and with cam1 as
// calibrated in air (rcm/sim/odometry_study.h). The rigs carry a camchain
// file's default uncertainty: a drift prior of 0.1 deg and 0.1 mm, and a
// focal drift prior of 0.3 %.
//
//   build/bin/odometry_table [--frames 60] [--rig alphasense|narrow|both]
//
// Prints the markdown table docs/bundle.md holds, with progress on stderr.
#include <Eigen/Geometry>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <string>

#include "rcm/io/stereo_rig_file.h"
#include "rcm/sim/odometry_study.h"
#include "rcm/sim/reference_rigs.h"
#include "rcm/util/number_format.h"

namespace {

constexpr double kPi = 3.14159265358979323846;

rcm::OdometryStudyOptions DiveOptions(int frames) {
  rcm::OdometryStudyOptions options;
  options.sequence.media = {rcm::MediaSegment{1.333, frames}};
  options.sequence.scene.length = 5.0;
  options.sequence.scene.width = 5.0;
  options.sequence.trajectory.loops = 1;
  options.sequence.trajectory.frame_rate = 4.0;
  options.sequence.cam1_drift.rotation =
      0.5 * kPi / 180.0 * Eigen::Vector3d(0.3, 1.0, 0.2).normalized();
  options.sequence.seed = 11;
  return options;
}

std::string Cell(double value, int digits) {
  return rcm::FormatFixed(value, digits);
}

std::string Epipolar(const rcm::OdometryStudy::Epipolar& e) {
  return e.error.empty() ? Cell(e.n, 4) + " +- " + Cell(e.sigma_n, 4)
                         : "refused (" + e.error + ")";
}

}  // namespace

int main(int argc, char** argv) {
  int frames = 60;
  std::string which = "both";
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if ((arg == "--frames" || arg == "--rig") && i + 1 < argc) {
      (arg == "--frames" ? frames = std::atoi(argv[++i]) : 0);
      if (arg == "--rig") which = argv[++i];
    } else {
      std::cerr << "usage: odometry_table [--frames 60] "
                   "[--rig alphasense|narrow|both]\n";
      return arg == "--help" ? 0 : 2;
    }
  }
  std::cout << "| rig | model | n | sigma_n | turn error (deg) | ATE (mm) | "
               "ATE / path | loop gap (mm) |\n"
               "|---|---|---|---|---|---|---|---|\n";
  for (const std::string rig_name : {"alphasense", "narrow"}) {
    if (which != "both" && which != rig_name) continue;
    // As a camchain file gives it: the default drift prior (0.1 deg,
    // 0.1 mm) and focal drift prior (0.3 %).
    const rcm::StereoRig rig =
        rcm::WithDefaultCalibrationUncertainty(
            rig_name == "alphasense" ? rcm::AlphasenseFrontRectifiedRig()
                                     : rcm::NarrowFieldRig(),
            rcm::RigFileOptions())
            .value();
    const auto start = std::chrono::steady_clock::now();
    const rcm::StatusOr<rcm::OdometryStudy> study = rcm::RunOdometryStudy(
        rig, DiveOptions(frames), [&](int done, int total) {
          std::cerr << "\rodometry_table: " << rig_name << " pair " << done
                    << " of " << total << std::flush;
        });
    std::cerr << "\n";
    if (!study.ok()) {
      std::cerr << "odometry_table: " << rig_name << ": "
                << study.status().message() << "\n";
      return 1;
    }
    for (const rcm::OdometryRow& row : study->rows) {
      std::cout << "| " << rig_name << " | "
                << rcm::OdometryModelName(row.model) << " | ";
      if (!row.status.ok()) {
        std::cout << "refused: " << row.status.message() << " |||||\n";
        continue;
      }
      const double path = row.error.path_length_m;
      std::cout << Cell(row.n, 4) << " | "
                << (row.sigma_n > 0.0 ? Cell(row.sigma_n, 4) : "held") << " | "
                << Cell(row.turn_error_deg, 3) << " | "
                << Cell(1e3 * row.error.ate_m, 1) << " | "
                << Cell(100.0 * row.error.ate_m / path, 2) << " % | "
                << Cell(1e3 * row.error.end_drift_m, 1) << " |\n";
    }
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
            .count();
    std::cerr << rig_name << ": " << study->keyframes << " pairs, "
              << study->mean_matches << " matches per pair, "
              << study->landmarks << " landmarks (" << study->tracked
              << " tracked), path " << Cell(study->path_length_m, 2)
              << " m (steps up to " << Cell(100.0 * study->max_step_m, 1)
              << " cm and " << Cell(study->max_turn_deg, 1) << " deg); refine "
              << Epipolar(study->refine) << ", with a free turn "
              << Epipolar(study->refine_free_turn) << "; render "
              << Cell(study->render_seconds, 1) << " s, track "
              << Cell(study->track_seconds, 1) << " s, bundles";
    for (const rcm::OdometryRow& row : study->rows) {
      std::cerr << " " << Cell(row.seconds, 1);
    }
    std::cerr << "; " << Cell(seconds, 1) << " s\n";
  }
  return 0;
}
