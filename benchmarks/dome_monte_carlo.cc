// The Monte Carlo of the dome calibration on rendered dives (issue 33,
// docs/dome.md "How well the decentering is recovered"): for one camera and
// for a stereo pair behind decentered 4-inch acrylic domes, N independent
// dives, each with its own board poses and its own render noise, rendered
// (tests/calib/rendered_dome_dive.h: blur 0.5 px, 2 gray levels),
// detected by the library's detector and calibrated with the true air
// lenses and n held. Where the tests' Monte Carlo draws Gaussian corners,
// here the corners' errors are the renderer's and the detector's. Per
// component: the error's mean and RMS, the mean reported sigma, the
// normalized error z = error / sigma (mean, sd), the largest error; the
// share of dives within 0.2 mm on every component.
//
//   build/bin/dome_monte_carlo [--trials 50] [--threads 2] [--seed 1]
//                              [--views 14] [--folds 10]
//                              [--dive one|stereo|both] [--dump FILE.csv]
//                              [--unweighted] [--verbose]
//
// Prints a markdown table, with progress on stderr (--verbose: and each
// dive's errors and sigmas). Trials run in parallel
// (--threads), each on one thread. --dump writes each dive's errors and
// sigmas (reported, the covariance's, the leave-out's) as CSV, meters;
// --unweighted calibrates without weighing the views by their noise.
#include <Eigen/Core>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <mutex>
#include <string>
#include <vector>

#include "calib/rendered_dome_dive.h"
#include "rcm/camera/dome_port_geometry.h"
#include "rcm/sim/reference_rigs.h"
#include "rcm/util/number_format.h"
#include "rcm/util/parallel_for.h"

namespace {

constexpr double kMaxErrorM = 2e-4;  // the 0.2 mm

struct DiveConfig {
  std::string name;
  std::vector<Eigen::Vector3d> decentering;  // per camera, meters
};

// One dive's outcome; `error` and `sigma` per camera, meters.
struct Trial {
  std::string failure;  // empty when the calibration succeeded
  std::vector<Eigen::Vector3d> error;
  std::vector<Eigen::Vector3d> sigma;            // reported (noise and spread)
  std::vector<Eigen::Vector3d> sigma_noise;      // the chosen fit's covariance
  std::vector<Eigen::Vector3d> sigma_leave_out;  // the jackknife's
  int folds = 0;
  double rms_px = 0.0;
  int views_used = 0;
  int corners = 0;
  bool flat_plausible = false;  // the spread widened sigma
  Eigen::Vector2d board_warp = Eigen::Vector2d::Zero();  // meters
};

// The dome of test::AcrylicDome (43.55 mm inside, 3.75 mm of acrylic).
rcm::DomePort AcrylicDome(const Eigen::Vector3d& decentering) {
  return rcm::DomePort{0.04355, 0.00375, 1.495, decentering};
}

Trial RunTrial(const rcm::StereoRig& rig, const DiveConfig& config, int views,
               int folds, bool weigh_views, uint64_t seed) {
  std::vector<rcm::DomePort> domes;
  for (const Eigen::Vector3d& c : config.decentering) {
    domes.push_back(AcrylicDome(c));
  }
  rcm::calib::test::DomeDiveOptions options;
  options.num_poses = views;
  options.pose_seed = static_cast<unsigned>(seed);
  options.noise_seed = seed << 8;  // 2 views * cameras < 256 seeds each
  options.num_threads = 1;
  const rcm::calib::test::DomeDive dive =
      rcm::calib::test::RenderDomeDive(rig, domes, options);
  const rcm::StatusOr<rcm::calib::DomeCalibration> result =
      rcm::calib::test::CalibrateDomeDive(dive, rig, 1, folds, weigh_views);
  Trial trial;
  trial.corners = dive.corners;
  if (!result.ok()) {
    trial.failure = result.status().message();
    return trial;
  }
  for (size_t c = 0; c < domes.size(); ++c) {
    trial.error.push_back(result->decentering[c] - config.decentering[c]);
    trial.sigma.push_back(result->decentering_sigma[c]);
    trial.sigma_noise.push_back(
        result->decentering_covariance[c].diagonal().cwiseSqrt());
    trial.sigma_leave_out.push_back(result->decentering_sigma_leave_out[c]);
  }
  trial.folds = result->folds;
  trial.rms_px = result->rms_px;
  trial.views_used = result->num_views_used;
  trial.board_warp = result->board_warp;
  for (const rcm::calib::DomeCandidate& candidate : result->candidates) {
    trial.flat_plausible |= !candidate.board_warp && candidate.plausible;
  }
  return trial;
}

// Distinct board poses and noise per dive and per configuration.
uint64_t TrialSeed(uint64_t seed, size_t config, int64_t trial) {
  return (seed * 4 + config) * 100003 + trial;
}

// Mean and sample standard deviation (N - 1).
Eigen::Vector2d MeanSd(const std::vector<double>& x) {
  const Eigen::Map<const Eigen::VectorXd> v(x.data(), x.size());
  const double mean = v.mean();
  const double n = static_cast<double>(x.size());
  return {mean, std::sqrt((v.array() - mean).square().sum() / (n - 1.0))};
}

std::string Cell(double value, int digits) {
  return rcm::FormatFixed(value, digits);
}

std::string Millimetres(const Eigen::Vector3d& v) {
  return "(" + Cell(1e3 * v.x(), 3) + ", " + Cell(1e3 * v.y(), 3) + ", " +
         Cell(1e3 * v.z(), 3) + ")";
}

// --verbose: one line per dive on stderr.
void PrintTrial(const std::string& dive, int index, uint64_t seed,
                const Trial& t) {
  std::cerr << dive << " dive " << index << " (seed " << seed << "): ";
  if (!t.failure.empty()) {
    std::cerr << "failed: " << t.failure << "\n";
    return;
  }
  std::cerr << t.views_used << " views, " << t.corners << " corners, rms "
            << Cell(t.rms_px, 3) << " px, warp ("
            << Cell(1e3 * t.board_warp.x(), 3) << ", "
            << Cell(1e3 * t.board_warp.y(), 3) << ") mm"
            << (t.flat_plausible ? ", flat plausible" : "");
  for (size_t c = 0; c < t.error.size(); ++c) {
    std::cerr << "; cam" << c << " error " << Millimetres(t.error[c])
              << " mm, sigma " << Millimetres(t.sigma[c]) << " mm, noise "
              << Millimetres(t.sigma_noise[c]) << " mm";
  }
  std::cerr << "\n";
}

// The table's rows of one camera's component over the successful trials.
void PrintComponent(const std::string& dive, int camera, int axis,
                    const std::vector<Trial>& trials) {
  std::vector<double> errors, sigmas, z, z_noise;
  for (const Trial& t : trials) {
    if (!t.failure.empty()) continue;
    const double e = t.error[camera][axis];
    errors.push_back(1e3 * e);
    sigmas.push_back(1e3 * t.sigma[camera][axis]);
    z.push_back(e / t.sigma[camera][axis]);
    z_noise.push_back(e / t.sigma_noise[camera][axis]);
  }
  if (errors.size() < 2) return;
  const Eigen::Map<const Eigen::VectorXd> e(errors.data(), errors.size());
  const Eigen::Vector2d zm = MeanSd(z);
  std::cout << "| " << dive << " | cam" << camera << " | "
            << "xyz"[axis] << " | " << Cell(e.mean(), 3) << " | "
            << Cell(std::sqrt(e.squaredNorm() / e.size()), 3) << " | "
            << Cell(MeanSd(sigmas)[0], 3) << " | " << Cell(zm[0], 2) << " | "
            << Cell(zm[1], 2) << " | " << Cell(MeanSd(z_noise)[1], 2) << " | "
            << Cell(e.cwiseAbs().maxCoeff(), 3) << " |\n";
}

}  // namespace

int main(int argc, char** argv) {
  int trials = 50;
  int threads = 2;
  int views = 14;
  int folds = 10;
  bool weigh_views = true;
  uint64_t seed = 1;
  std::string dump;
  std::string which = "both";
  bool verbose = false;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    const bool has_value = i + 1 < argc;
    if (arg == "--trials" && has_value) {
      trials = std::atoi(argv[++i]);
    } else if (arg == "--threads" && has_value) {
      threads = std::atoi(argv[++i]);
    } else if (arg == "--views" && has_value) {
      views = std::atoi(argv[++i]);
    } else if (arg == "--folds" && has_value) {
      folds = std::atoi(argv[++i]);
    } else if (arg == "--dump" && has_value) {
      dump = argv[++i];
    } else if (arg == "--seed" && has_value) {
      seed = std::strtoull(argv[++i], nullptr, 10);
    } else if (arg == "--dive" && has_value) {
      which = argv[++i];
    } else if (arg == "--unweighted") {
      weigh_views = false;
    } else if (arg == "--verbose") {
      verbose = true;
    } else {
      std::cerr << "usage: dome_monte_carlo [--trials 50] [--threads 2] "
                   "[--seed 1] [--views 14] [--folds 10] "
                   "[--dive one|stereo|both] [--dump FILE.csv] [--unweighted] "
                   "[--verbose]\n";
      return arg == "--help" ? 0 : 2;
    }
  }
  if (trials < 2 || threads < 1 || views < 3 || folds < 0 ||
      seed >= (uint64_t{1} << 40) ||
      (which != "one" && which != "stereo" && which != "both")) {
    std::cerr << "dome_monte_carlo: --trials >= 2, --threads >= 1, "
                 "--views >= 3, --folds >= 0, --seed < 2^40, "
                 "--dive one|stereo|both\n";
    return 2;
  }
  const rcm::StereoRig rig = rcm::AlphasenseFrontUnrectifiedRig();
  const std::vector<DiveConfig> configs = {
      {"one", {Eigen::Vector3d(0.002, -0.001, 0.007)}},
      {"stereo",
       {Eigen::Vector3d(0.002, -0.001, 0.007),
        Eigen::Vector3d(-0.0015, 0.0025, 0.009)}}};
  std::cout << "| dive | camera | axis | mean error (mm) | RMS error (mm) | "
               "mean sigma (mm) | z mean | z sd | z sd (noise sigma) | "
               "max abs error (mm) |\n"
               "|---|---|---|---|---|---|---|---|---|---|\n";
  std::vector<std::string> summaries;
  std::ofstream csv;
  if (!dump.empty()) {
    csv.open(dump);
    if (!csv) {
      std::cerr << "dome_monte_carlo: cannot write " << dump << "\n";
      return 1;
    }
    csv << "dive,trial,camera,views_used,folds";
    for (const char* name : {"error", "sigma", "sigma_noise", "leave_out"}) {
      for (const char* axis : {"x", "y", "z"})
        csv << "," << name << "_" << axis;
    }
    csv << "\n";
    csv.precision(10);
  }
  for (size_t k = 0; k < configs.size(); ++k) {
    const DiveConfig& config = configs[k];
    if (which != "both" && which != config.name) continue;
    std::vector<Trial> results(trials);
    std::atomic<int> done{0};
    std::mutex progress;
    const auto start = std::chrono::steady_clock::now();
    rcm::ParallelForChunks(trials, threads, 1, [&](int64_t begin, int64_t end) {
      for (int64_t t = begin; t < end; ++t) {
        results[t] = RunTrial(rig, config, views, folds, weigh_views,
                              TrialSeed(seed, k, t));
        const std::lock_guard<std::mutex> lock(progress);
        std::cerr << "\rdome_monte_carlo: " << config.name << " dive " << ++done
                  << " of " << trials << std::flush;
      }
    });
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
            .count();
    std::cerr << "\n";
    for (int t = 0; verbose && t < trials; ++t) {
      PrintTrial(config.name, t, TrialSeed(seed, k, t), results[t]);
    }
    const int cameras = static_cast<int>(config.decentering.size());
    for (int t = 0; csv.is_open() && t < trials; ++t) {
      const Trial& r = results[t];
      for (int c = 0; r.failure.empty() && c < cameras; ++c) {
        csv << config.name << "," << t << "," << c << "," << r.views_used << ","
            << r.folds;
        for (const Eigen::Vector3d* v :
             {&r.error[c], &r.sigma[c], &r.sigma_noise[c],
              &r.sigma_leave_out[c]}) {
          for (int i = 0; i < 3; ++i) csv << "," << (*v)[i];
        }
        csv << "\n";
      }
    }
    for (int c = 0; c < cameras; ++c) {
      for (int axis = 0; axis < 3; ++axis) {
        PrintComponent(config.name, c, axis, results);
      }
    }
    int ok = 0, within = 0, flat_plausible = 0;
    double rms = 0.0, used = 0.0, corners = 0.0;
    for (const Trial& t : results) {
      corners += t.corners;
      if (!t.failure.empty()) {
        std::cerr << config.name << ": a dive failed: " << t.failure << "\n";
        continue;
      }
      ++ok;
      bool all_within = true;
      for (const Eigen::Vector3d& e : t.error) {
        all_within &= e.cwiseAbs().maxCoeff() <= kMaxErrorM;
      }
      within += all_within ? 1 : 0;
      flat_plausible += t.flat_plausible ? 1 : 0;
      rms += t.rms_px;
      used += t.views_used;
    }
    summaries.push_back(
        config.name + ": " + std::to_string(ok) + " of " +
        std::to_string(trials) + " dives calibrated, " +
        std::to_string(within) + " within 0.2 mm on every component; " +
        Cell(used / std::max(ok, 1), 1) + " of " + std::to_string(views) +
        " views used, " + Cell(corners / trials / cameras, 0) +
        " corners per camera, rms " + Cell(rms / std::max(ok, 1), 3) +
        " px; the flat board plausible in " + std::to_string(flat_plausible) +
        "; " + Cell(seconds, 0) + " s on " + std::to_string(threads) +
        " threads");
  }
  std::cout << "\n";
  for (const std::string& summary : summaries) std::cout << summary << "\n";
  return 0;
}
