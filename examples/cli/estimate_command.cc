// rcm estimate: the refractive index n from stereo correspondences.
#include <gflags/gflags.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "command.h"
#include "rcm/estimation/paper_online_estimator.h"
#include "rcm/io/atomic_file.h"
#include "rcm/io/correspondence_csv.h"
#include "rcm/io/stereo_rig_file.h"

DECLARE_bool(json);

DEFINE_string(calib, "",
              "the in-air calibration: a Kalibr camchain YAML, or two ROS "
              "camera_info YAML files as LEFT.yaml,RIGHT.yaml (required)");
DEFINE_string(matches, "",
              "correspondence CSV with header frame,xl,yl,xr,yr[,t] in raw "
              "pixels (required)");
DEFINE_string(estimator, "closed-form",
              "closed-form: the paper's estimator (eq. 14 per match, "
              "observability mask, radially weighted mean, Sec. III-E)");
DEFINE_string(left, "cam0", "camchain camera that is the left one");
DEFINE_string(right, "cam1", "camchain camera that is the right one");
DEFINE_double(mask_eta, 0.3,
              "observability mask: use a match when sqrt|u| sqrt|v| > eta, "
              "(u, v) its normalized left coordinates");
DEFINE_string(per_frame_csv, "",
              "also write the running estimate after each frame to this CSV "
              "(frame,t,used,n,standard_error)");

namespace rcm::cli {
namespace {

constexpr char kUsage[] =
    "rcm estimate: the refractive index n of the medium from stereo\n"
    "correspondences of a rig calibrated in air.\n\n"
    "usage: rcm estimate --calib RIG.yaml --matches MATCHES.csv "
    "[--estimator closed-form] [--json]\n\n"
    "The closed-form estimator is the paper's baseline; it assumes a "
    "rectified rig\nand is biased under pixel noise (DESIGN.md Sec. 2).";

// Above this deviation from a rectified pair the closed form is biased.
constexpr double kRectifiedToleranceDeg = 0.05;

double Degrees(double radians) { return radians * 180.0 / M_PI; }

std::string FormatFixed(double value, int digits) {
  if (!std::isfinite(value)) return "n/a";
  std::ostringstream out;
  out.setf(std::ios::fixed);
  out.precision(digits);
  out << value;
  return out.str();
}

// The q-quantile of sorted values (linear interpolation).
double Quantile(const std::vector<double>& sorted, double q) {
  const double position = q * (sorted.size() - 1);
  const size_t below = static_cast<size_t>(std::floor(position));
  const size_t above = std::min(below + 1, sorted.size() - 1);
  return sorted[below] + (position - below) * (sorted[above] - sorted[below]);
}

// The running estimate after one frame, for --per_frame_csv.
struct FrameRow {
  int64_t frame;
  std::optional<double> timestamp;
  int64_t used;
  double n;
  double standard_error;
};

std::string FormatFrameRows(const std::vector<FrameRow>& rows) {
  std::ostringstream out;
  out.precision(17);
  out << "frame,t,used,n,standard_error\n";
  for (const FrameRow& row : rows) {
    out << row.frame << ",";
    if (row.timestamp) out << *row.timestamp;
    out << "," << row.used << ",";
    if (std::isfinite(row.n)) out << row.n;
    out << ",";
    if (std::isfinite(row.standard_error)) out << row.standard_error;
    out << "\n";
  }
  return out.str();
}

int RunEstimate();

}  // namespace

extern const Subcommand kEstimateCommand = {
    "estimate", "refractive index n from stereo correspondences", kUsage,
    __FILE__, RunEstimate};

namespace {

int RunEstimate() {
  const Subcommand& command = kEstimateCommand;
  if (FLAGS_calib.empty()) {
    PrintError(command, "--calib is required (see rcm estimate --help)");
    return kExitUsage;
  }
  if (FLAGS_matches.empty()) {
    PrintError(command, "--matches is required (see rcm estimate --help)");
    return kExitUsage;
  }
  if (FLAGS_estimator != "closed-form") {
    PrintError(command, "unknown estimator '" + FLAGS_estimator +
                            "' (available: closed-form)");
    return kExitUsage;
  }
  PaperOnlineEstimatorOptions options;
  options.eta = FLAGS_mask_eta;
  if (const Status status = options.Check(); !status.ok()) {
    PrintError(command, "--mask_eta: " + status.message());
    return kExitUsage;
  }

  const StatusOr<StereoRig> rig =
      ReadStereoRig(FLAGS_calib, FLAGS_left, FLAGS_right);
  if (!rig.ok()) {
    PrintError(command, rig.status().message());
    return kExitFailure;
  }
  const StatusOr<std::vector<StereoCorrespondence>> matches =
      ReadCorrespondenceCsv(FLAGS_matches);
  if (!matches.ok()) {
    PrintError(command, matches.status().message());
    return kExitFailure;
  }

  const StereoRig::RectificationDeviation deviation =
      rig->DeviationFromRectified();
  const double deviation_deg =
      Degrees(std::max(deviation.rotation, deviation.baseline_off_axis));
  if (deviation_deg > kRectifiedToleranceDeg) {
    PrintWarning(command,
                 "the rig is " + FormatFixed(deviation_deg, 2) +
                     " deg from a rectified pair; the closed form assumes "
                     "one and is biased on this rig");
  }

  PaperOnlineEstimator estimator(*rig, options);
  std::vector<double> per_match;
  std::vector<FrameRow> frame_rows;
  per_match.reserve(matches->size());
  for (size_t i = 0; i < matches->size(); ++i) {
    const StereoCorrespondence& match = (*matches)[i];
    const PaperOnlineEstimator::Contribution contribution =
        estimator.Add(match);
    if (contribution.outcome == PaperOnlineEstimator::Outcome::kUsed) {
      per_match.push_back(contribution.n);
    }
    const bool frame_ends =
        i + 1 == matches->size() || (*matches)[i + 1].frame != match.frame;
    if (frame_ends) {
      const std::optional<PaperOnlineEstimator::Estimate> current =
          estimator.Current();
      frame_rows.push_back({match.frame, match.timestamp, estimator.num_used(),
                            current ? current->n : std::nan(""),
                            current ? current->standard_error : std::nan("")});
    }
  }

  const size_t num_frames = frame_rows.size();
  const std::optional<PaperOnlineEstimator::Estimate> estimate =
      estimator.Current();
  if (!estimate) {
    PrintError(
        command,
        "no usable correspondence: " + std::to_string(estimator.num_masked()) +
            " removed by the observability mask, " +
            std::to_string(estimator.num_invalid()) +
            " invalid; matches near the image axes do not observe n "
            "(lower --mask_eta to keep more)");
    return kExitFailure;
  }
  if (!FLAGS_per_frame_csv.empty()) {
    const Status written =
        WriteFileAtomically(FLAGS_per_frame_csv, FormatFrameRows(frame_rows));
    if (!written.ok()) {
      PrintError(command, written.message());
      return kExitFailure;
    }
  }

  std::sort(per_match.begin(), per_match.end());
  const double median = Quantile(per_match, 0.5);
  const double low = Quantile(per_match, 0.16);
  const double high = Quantile(per_match, 0.84);

  if (FLAGS_json) {
    nlohmann::json out;
    out["estimator"] = FLAGS_estimator;
    out["n"] = estimate->n;
    out["standard_error"] = estimate->standard_error;  // NaN -> null
    out["correspondences"] = matches->size();
    out["frames"] = num_frames;
    out["used"] = estimator.num_used();
    out["masked"] = estimator.num_masked();
    out["invalid"] = estimator.num_invalid();
    out["mask_eta"] = options.eta;
    out["per_match"] = {{"median", median}, {"p16", low}, {"p84", high}};
    out["rig"] = {
        {"calib", FLAGS_calib},
        {"left", FLAGS_left},
        {"right", FLAGS_right},
        {"baseline_m", rig->Baseline()},
        {"rotation_deg", Degrees(deviation.rotation)},
        {"baseline_off_axis_deg", Degrees(deviation.baseline_off_axis)}};
    out["matches"] = FLAGS_matches;
    std::cout << out.dump(2) << std::endl;
    return kExitOk;
  }

  std::cout << "rcm estimate: closed form (eq. 14), mask sqrt|u|sqrt|v| > "
            << options.eta << ", radially weighted mean (eq. 17)\n"
            << "  rig        " << FLAGS_calib << " (" << FLAGS_left << " left, "
            << FLAGS_right << " right), baseline "
            << FormatFixed(rig->Baseline(), 4) << " m, "
            << FormatFixed(deviation_deg, 3) << " deg from rectified\n"
            << "  matches    " << FLAGS_matches << ": " << matches->size()
            << " correspondences in " << num_frames << " frame"
            << (num_frames == 1 ? "" : "s") << "\n"
            << "  used       " << estimator.num_used() << " (masked "
            << estimator.num_masked() << ", invalid " << estimator.num_invalid()
            << ")\n"
            << "  n          " << FormatFixed(estimate->n, 5) << " +- "
            << FormatFixed(estimate->standard_error, 5) << " (standard error)\n"
            << "  per match  median " << FormatFixed(median, 5) << ", 16-84 % ["
            << FormatFixed(low, 5) << ", " << FormatFixed(high, 5) << "]"
            << std::endl;
  return kExitOk;
}

}  // namespace
}  // namespace rcm::cli
