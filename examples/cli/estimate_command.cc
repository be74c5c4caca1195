// rcm estimate: the refractive index n from stereo images or
// correspondences. The run: the flags' options (estimate_options.cc), the
// rig, the library's pair loop on images (sequence_estimator.h) or its
// estimators on matches (estimate_refractive_index.h), the medium, and the
// report (estimate_report.cc, the library's JSON).
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "air_gap_flag.h"
#include "command.h"
#include "estimate_options.h"
#include "estimate_report.h"
#include "image_input_flags.h"
#include "medium_flag.h"
#include "progress.h"
#include "rcm/estimation/estimate_json.h"
#include "rcm/estimation/estimate_refractive_index.h"
#include "rcm/estimation/match_refractive_index.h"
#include "rcm/estimation/medium_drift.h"
#include "rcm/estimation/prepared_correspondence.h"
#include "rcm/io/atomic_file.h"
#include "rcm/io/correspondence_csv.h"
#include "rcm/io/image_file.h"
#include "rcm/io/stereo_rig_file.h"
#include "rcm/live/sequence_estimator.h"
#include "rcm/stereo/epipolar.h"
#include "rcm/util/number_format.h"
#include "rcm/viz/match_index_image.h"
#include "rig_flags.h"

namespace rcm::cli {
namespace {

constexpr char kEstimateUsage[] =
    "rcm estimate: the refractive index n of the medium from the stereo\n"
    "images (folders or a ROS1 bag) or correspondences of a rig calibrated\n"
    "in air.\n\n"
    "usage: rcm estimate --calib RIG.yaml --left DIR --right DIR [--out DIR]\n"
    "       rcm estimate --calib RIG.yaml --bag BAG --left-topic T0 "
    "--right-topic T1\n"
    "       rcm estimate --calib RIG.yaml --matches MATCHES.csv\n"
    "   [--estimator refine|online|window|closed-form|bundle] [--window N]\n"
    "   [--from S --to S --stride K] [--features orb|sift|akaze] [--clahe]\n"
    "   [--per-frame OUT.csv] [--json]\n\n"
    "From images, each pair's keypoints are matched within the band of the\n"
    "refractive epipolar loci of the current n (the previous pair's own\n"
    "estimate; --search-range before there is one), refined to subpixel and\n"
    "fed to the estimator. Folders pair by file name (or sorted order, or a\n"
    "--pairs list); names that are stamps (ns or s) give the times that\n"
    "--from/--to count. Bags pair the two topics by header stamp.\n\n"
    "refine fits n to the distance of every match from its refractive "
    "epipolar\nlocus (Sampson distance, pixels) over all frames: a robust "
    "stage that finds n\namong outliers, then least squares on the inliers, "
    "whose covariance gives\nsigma_n. It works on any calibrated rig. "
    "closed-form is the paper's baseline;\nit assumes a rectified rig and is "
    "biased under pixel noise (docs/design.md Sec. 3).\nbundle (images only) "
    "tracks landmarks over the pairs and adjusts n, cam1's\nturn and the "
    "rig's poses together: motion separates n from the turn that\none pair "
    "cannot; --out adds trajectory.tum and trajectory.png.\n\n"
    "sigma_n counts the calibration's uncertainty (the camchain's covariance\n"
    "sidecar, or a drift prior of 0.1 deg, 0.1 mm per axis and 0.3 % in\n"
    "each camera's focal lengths: --drift-prior) and the matches'\n"
    "systematic error (--systematic-px) beside the pixel noise; cam1's\n"
    "rotation is self-calibrated with its prior. An n at the\n"
    "upper bound 2 is refused; a stale calibration is named (then\n"
    "rcm calibrate --underwater).\n\n"
    "Exit status: 0 on success, 1 when the input cannot give an estimate, "
    "2 on\nwrong flags.";

double Degrees(double radians) { return radians * 180.0 / M_PI; }

// The sequence engine's run over the images (rcm/live/sequence_estimator.h)
// and what the report shows of it.
struct ImageRun {
  std::string source;  // the source's Describe()
  SequenceRun run;
  int rematched = 0;  // passes after the first
  // The pair drawn in matches_by_n.png.
  cv::Mat picture_left;
  int64_t picture_frame = -1;
  std::vector<StereoCorrespondence> picture_matches;
};

// The paper's Fig. 6b: a pair's matches colored by their own n.
cv::Mat MatchesByIndexPicture(const StereoRig& rig, const ImageRun& run,
                              double n) {
  const Eigen::Matrix3d essential = EssentialMatrix(rig.right_from_left());
  std::vector<Eigen::Vector2d> pixels;
  std::vector<std::optional<double>> values;
  int with_value = 0;
  for (const StereoCorrespondence& match : run.picture_matches) {
    pixels.push_back(match.left_pixel);
    const std::optional<PreparedCorrespondence> prepared =
        PrepareCorrespondence(rig, match);
    values.push_back(prepared ? RefractiveIndexOfMatch(essential, *prepared)
                              : std::nullopt);
    with_value += values.back() ? 1 : 0;
  }
  MatchIndexImageOptions options;
  options.center = std::isfinite(n) ? n : 1.333;
  options.half_range = 0.05;
  options.title = "frame " + std::to_string(run.picture_frame) + ": " +
                  std::to_string(with_value) + " of " +
                  std::to_string(pixels.size()) +
                  " matches by their own n (rings: none in [1, 2])";
  return DrawMatchesByRefractiveIndex(run.picture_left, pixels, values,
                                      options);
}

int RunEstimate();

}  // namespace

extern const Subcommand kEstimateCommand = {
    "estimate",
    "refractive index n from stereo images or correspondences",
    kEstimateUsage,
    {__FILE__, kEstimateFlagsSource, kRigFlagsSource, kImageInputFlagsSource,
     kAirGapFlagSource, kMediumFlagSource},
    RunEstimate};

namespace {

int RunEstimate() {
  const Subcommand& command = kEstimateCommand;
  StatusOr<EstimateCliOptions> cli = EstimateOptionsFromFlags();
  if (!cli.ok()) {
    PrintError(command, cli.status().message());
    return kExitUsage;
  }
  const EstimationOptions& estimation = cli->estimation;
  const RefinementOptions& refinement = estimation.refinement;
  const bool images = cli->images;
  const bool refine = estimation.estimator == EstimatorKind::kRefine;
  const std::optional<MediumPrior>& medium = cli->medium;
  const StatusOr<StereoRig> rig = ReadStereoRig(FLAGS_calib, FLAGS_left_camera,
                                                FLAGS_right_camera, cli->rig);
  if (!rig.ok()) {
    PrintError(command, rig.status().message());
    return kExitFailure;
  }
  if (rig->HasThickPort() && !refine) {
    PrintError(command,
               FLAGS_calib +
                   " gives a thick port (an air gap or glass), which only "
                   "--estimator refine models; the " +
                   FLAGS_estimator +
                   " estimator assumes the paper's thin port");
    return kExitUsage;
  }
  // The output folder first: a run is not wasted on one that cannot be
  // written.
  if (!FLAGS_out.empty()) {
    std::error_code error;
    std::filesystem::create_directories(FLAGS_out, error);
    if (error || !std::filesystem::is_directory(FLAGS_out)) {
      PrintError(command, FLAGS_out + ": cannot create the output folder" +
                              (error ? " (" + error.message() + ")" : ""));
      return kExitFailure;
    }
  }

  std::vector<StereoCorrespondence> matches;
  std::vector<FrameMatches> frames;
  std::optional<ImageRun> run;
  if (images) {
    StatusOr<std::unique_ptr<StereoImageSource>> source =
        OpenImageInputFromFlags();
    if (!source.ok()) {
      PrintError(command, source.status().message());
      return kExitFailure;
    }
    // The pair loop of the library: guided matching, a turned cam1
    // followed, the pairs matched again when the self-calibrated rotation
    // moved beyond the band, and the final estimate solved once.
    SequenceEstimatorOptions sequence_options;
    sequence_options.front_end = *cli->front_end;
    sequence_options.estimation = estimation;
    sequence_options.estimation.per_frame_estimates = false;
    ImageRun image_run;
    image_run.source = (*source)->Describe();
    const size_t pairs = (*source)->NumPairs();
    const size_t picture_index = FLAGS_picture_frame >= 0
                                     ? std::numeric_limits<size_t>::max()
                                     : pairs / 2;
    std::unique_ptr<Progress> progress;
    int progress_pass = 0;
    StatusOr<SequenceRun> sequence = EstimateSequence(
        *rig, source->get(), sequence_options,
        [&](int pass, size_t done, size_t total, const StereoImagePair& images,
            const SequencePair& pair) {
          if (pass != progress_pass) {
            progress.reset();  // erases the last pass's line
            progress = std::make_unique<Progress>("rcm estimate: pair", total);
            progress_pass = pass;
          }
          if (done - 1 == picture_index ||
              images.frame == FLAGS_picture_frame) {
            image_run.picture_left = images.left;
            image_run.picture_frame = images.frame;
            image_run.picture_matches = pair.matches;
          }
          std::string status = std::to_string(pair.matches.size()) + " matches";
          if (pair.own.ok()) {
            status += ", n = " + FormatFixed(pair.own->n, 4) + " +- " +
                      FormatFixed(pair.own->sigma_n, 4);
          }
          progress->Update(done, status);
        });
    progress.reset();
    if (!sequence.ok()) {
      PrintError(command, sequence.status().message());
      return kExitFailure;
    }
    image_run.run = std::move(*sequence);
    image_run.rematched = image_run.run.passes - 1;
    frames = image_run.run.frames;
    for (const FrameMatches& frame : frames) {
      matches.insert(matches.end(), frame.matches.begin(), frame.matches.end());
    }
    run = std::move(image_run);
  } else {
    StatusOr<std::vector<StereoCorrespondence>> read =
        ReadCorrespondenceCsv(FLAGS_matches);
    if (!read.ok()) {
      PrintError(command, read.status().message());
      return kExitFailure;
    }
    matches = std::move(*read);
    // Frames in time order; matches of a frame stay in file order.
    std::stable_sort(
        matches.begin(), matches.end(),
        [](const StereoCorrespondence& a, const StereoCorrespondence& b) {
          return a.frame < b.frame;
        });
    frames = SplitFrames(matches);
  }

  std::unique_ptr<Progress> progress;
  if (!images && (estimation.per_frame_estimates || !refine)) {
    progress = std::make_unique<Progress>(
        refine ? "rcm estimate: per-frame estimates, frame"
               : "rcm estimate: frame",
        frames.size());
  }
  StatusOr<RefractiveIndexEstimate> report =
      images ? std::move(run->run.estimate)
             : EstimateRefractiveIndex(*rig, frames, estimation,
                                       [&](size_t done, size_t) {
                                         if (progress) progress->Update(done);
                                       });
  if (!report.ok()) {
    PrintError(command, report.status().message());
    return kExitFailure;
  }
  for (const std::string& warning : report->warnings) {
    PrintWarning(command, warning);
  }
  // The medium (--medium): the estimate against it, and with the
  // refinement of thin ports cam1's rotation assuming it.
  nlohmann::json medium_json = nullptr;
  std::vector<std::string> medium_lines;
  if (medium) {
    const MediumPrior& water = *medium;
    const MediumCheck check =
        CheckAgainstMedium(report->n, report->sigma_n, water);
    medium_json = MediumJson(water, check);
    medium_lines.push_back("  medium     " + water.Describe() + ": n is " +
                           FormatFixed(check.z, 1) + " sigma from it");
    if (check.contradicts) {
      PrintWarning(command,
                   check.message +
                       ": the camchain may no longer describe the rig (it "
                       "turned since the calibration?), or the water is "
                       "another");
    }
    if (refine && !rig->HasThickPort()) {
      const StatusOr<MediumDrift> drift =
          EstimateDriftAssumingMedium(*rig, matches, refinement, water);
      if (drift.ok()) {
        const Eigen::Vector3d degrees =
            drift->assuming_medium.rotation->angle_axis * 180.0 / M_PI;
        medium_json["assuming_medium"] = {
            {"n", drift->assuming_medium.n},
            {"sigma_n", drift->assuming_medium.sigma_n},
            {"rotation_deg", {degrees.x(), degrees.y(), degrees.z()}},
            {"turned_deg", drift->angle * 180.0 / M_PI},
            {"sigma_turned_deg", drift->sigma_angle * 180.0 / M_PI},
            {"turned", drift->turned}};
        medium_lines.push_back("             " + drift->message);
        if (drift->turned) {
          PrintWarning(command, "the calibration is stale: " + drift->message +
                                    "; calibrate in the water (rcm calibrate "
                                    "--underwater) or re-calibrate in air");
        }
      } else {
        medium_json["assuming_medium_error"] = drift.status().message();
        medium_lines.push_back("             " + drift.status().message());
      }
    }
  }

  const StereoRig::RectificationDeviation deviation =
      rig->DeviationFromRectified();
  // The estimate's own JSON (the library's, as Python's to_dict()), and
  // what this run adds: the medium, the rig and the input.
  nlohmann::json json = nlohmann::json::parse(EstimateJson(*report, -1));
  json["medium"] = medium_json;
  json["rig"] = {
      {"calib", FLAGS_calib},
      {"left", FLAGS_left_camera},
      {"right", FLAGS_right_camera},
      {"baseline_m", rig->Baseline()},
      {"rotation_deg", Degrees(deviation.rotation)},
      {"baseline_off_axis_deg", Degrees(deviation.baseline_off_axis)}};
  if (run) {
    const double pairs = std::max<double>(1.0, frames.size());
    json["images"] = {
        {"source", run->source},
        {"pairs", frames.size()},
        {"features", FLAGS_features},
        {"clahe", FLAGS_clahe},
        {"matches_per_pair", matches.size() / pairs},
        {"reacquired_pairs", run->run.reacquired},
        {"rematched", run->rematched},
        {"matching_rotation_deg",
         {run->run.matching_rotation.x() * 180.0 / M_PI,
          run->run.matching_rotation.y() * 180.0 / M_PI,
          run->run.matching_rotation.z() * 180.0 / M_PI}},
        {"pairs_per_second", frames.size() / std::max(run->run.seconds, 1e-9)},
        {"ms_per_pair",
         {{"decode", run->run.read_ms / pairs},
          {"preprocess", run->run.timings.preprocess_ms / pairs},
          {"detect", run->run.timings.detect_ms / pairs},
          {"match", run->run.timings.match_ms / pairs},
          {"refine", run->run.timings.refine_ms / pairs},
          {"own_estimate", run->run.estimate_ms / pairs}}}};
  } else {
    json["matches"] = FLAGS_matches;
  }

  // Files: each written whole or not at all (atomic), the summary last.
  std::vector<std::string> written;
  const auto write = [&](const std::string& path, const Status& status) {
    if (!status.ok()) {
      PrintError(command, status.message());
      return false;
    }
    written.push_back(path);
    return true;
  };
  if (!FLAGS_per_frame.empty() &&
      !write(
          FLAGS_per_frame,
          WriteFileAtomically(FLAGS_per_frame, EstimatePerFrameCsv(*report)))) {
    return kExitFailure;
  }
  if (!FLAGS_out.empty()) {
    const std::filesystem::path out(FLAGS_out);
    const std::string per_frame = (out / "per_frame.csv").string();
    const std::string plot = (out / "n_per_frame.png").string();
    if (!write(per_frame,
               WriteFileAtomically(per_frame, EstimatePerFrameCsv(*report))) ||
        !write(plot, WritePng(PlotPerFrame(*report), plot))) {
      return kExitFailure;
    }
    if (report->bundle) {
      const std::string trajectory = (out / "trajectory.tum").string();
      const std::string picture = (out / "trajectory.png").string();
      if (!write(trajectory, WriteFileAtomically(
                                 trajectory, EstimateTrajectoryTum(*report))) ||
          !write(picture, WritePng(PlotTrajectory(*report), picture))) {
        return kExitFailure;
      }
    }
    if (run) {
      const std::string csv = (out / "matches.csv").string();
      if (!write(csv, WriteCorrespondenceCsv(csv, matches))) {
        return kExitFailure;
      }
      if (!run->picture_left.empty()) {
        const std::string picture = (out / "matches_by_n.png").string();
        if (!write(picture,
                   WritePng(MatchesByIndexPicture(*rig, *run, report->n),
                            picture))) {
          return kExitFailure;
        }
      }
    }
    const std::string summary = (out / "estimate.json").string();
    if (!write(summary, WriteFileAtomically(summary, json.dump(2) + "\n"))) {
      return kExitFailure;
    }
  }
  if (FLAGS_json) {
    std::cout << json.dump(2) << std::endl;
    return kExitOk;
  }

  const double deviation_deg =
      Degrees(std::max(deviation.rotation, deviation.baseline_off_axis));
  std::ostringstream text;
  text << "rcm estimate: " << report->method << "\n"
       << "  rig        " << FLAGS_calib << " (" << FLAGS_left_camera
       << " left, " << FLAGS_right_camera << " right), baseline "
       << FormatFixed(rig->Baseline(), 4) << " m, "
       << FormatFixed(deviation_deg, 3) << " deg from rectified\n";
  if (run) {
    const double pairs = std::max<double>(1.0, frames.size());
    text << "  images     " << run->source << "\n"
         << "  front end  " << FLAGS_features << (FLAGS_clahe ? " + CLAHE" : "")
         << ": " << FormatFixed(matches.size() / pairs, 0)
         << " matches per pair, "
         << FormatFixed(frames.size() / std::max(run->run.seconds, 1e-9), 1)
         << " pairs/s (ms per pair: decode "
         << FormatFixed(run->run.read_ms / pairs, 1) << ", detect "
         << FormatFixed(run->run.timings.detect_ms / pairs, 1) << ", match "
         << FormatFixed(run->run.timings.match_ms / pairs, 1) << ", refine "
         << FormatFixed(run->run.timings.refine_ms / pairs, 1) << ", estimate "
         << FormatFixed(run->run.estimate_ms / pairs, 1) << ")\n";
    if (run->rematched > 0) {
      text << "  re-matched " << run->rematched
           << (run->rematched == 1 ? " time" : " times")
           << " with cam1 turned by "
           << FormatFixed(run->run.matching_rotation.norm() * 180.0 / M_PI, 3)
           << " deg (the self-calibrated rotation), so that the matching "
              "band follows the rig\n";
    }
    if (run->run.reacquired > 0) {
      text << "  re-acquired " << run->run.reacquired
           << " pairs whose matches left the band of the estimate (a change "
              "of medium?)\n";
    }
  } else {
    text << "  matches    " << FLAGS_matches << ": " << matches.size()
         << " correspondences in " << frames.size() << " frame"
         << (frames.size() == 1 ? "" : "s") << "\n";
  }
  if (estimation.estimator != EstimatorKind::kClosedForm) {
    text << "  inliers    " << report->inliers
         << (estimation.estimator == EstimatorKind::kWindow ? " in the window"
                                                            : "")
         << " (" << report->invalid << " could not be undistorted)\n";
  }
  for (const std::string& line : EstimatorLines(*report)) text << line << "\n";
  for (const std::string& line : UncertaintyLines(*report)) {
    text << line << "\n";
  }
  for (const std::string& line : medium_lines) text << line << "\n";
  if (!written.empty()) {
    text << "  wrote     ";
    for (const std::string& path : written) text << " " << path;
    text << "\n";
  }
  std::cout << text.str() << std::flush;
  return kExitOk;
}

}  // namespace
}  // namespace rcm::cli
