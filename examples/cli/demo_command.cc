// rcm demo: the main job on an embedded default. Simulates a short
// underwater sequence with the dataset rig, estimates n from the images,
// and writes a plot, a before/after image pair and a JSON summary.
#include <gflags/gflags.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "command.h"
#include "index_flag.h"
#include "rcm/camera/refractive_camera.h"
#include "rcm/camera/virtual_pinhole_remap.h"
#include "rcm/estimation/batch_refinement.h"
#include "rcm/estimation/estimate_json.h"
#include "rcm/estimation/prepared_correspondence.h"
#include "rcm/estimation/robust_locus_fit.h"
#include "rcm/frontend/stereo_front_end.h"
#include "rcm/io/atomic_file.h"
#include "rcm/io/image_file.h"
#include "rcm/io/stereo_rig_file.h"
#include "rcm/live/sequence_estimator.h"
#include "rcm/plot/line_plot.h"
#include "rcm/sim/sequence_simulator.h"
#include "rcm/stereo/epipolar.h"
#include "rcm/stereo/stereo_rectification.h"
#include "rcm/util/number_format.h"
#include "glass_index_flag.h"
#include "simulation_flags.h"

namespace rcm::cli {
namespace {

constexpr char kDefaultFolder[] = "rcm_demo";

constexpr char kDemoUsage[] =
    "rcm demo: the main job on built-in data, end to end.\n\n"
    "usage: rcm demo [--out DIR] [--frames 20] [--n 1.333] [--seed 1]\n\n"
    "Simulates a short sequence of the paper's dataset rig (Alphasense, "
    "720x540,\nequidistant lenses, calibrated in air) moving through a pool "
    "behind flat\nports, matches features in each stereo pair along the "
    "refractive epipolar\nloci (the front end of rcm estimate), estimates "
    "the\nrefractive index n of the water from the matches "
    "alone (per frame, over a\nsliding window, and over all frames), and "
    "writes into ./rcm_demo/ (or --out):\n"
    "  n_per_frame.png   n per frame with its 1-sigma band, against the "
    "truth\n"
    "  before.png        the first stereo pair as the cameras see it\n"
    "  after.png         the same pair corrected for refraction and lens "
    "at the\n"
    "                    estimated n and rectified (virtual pinholes K_n): "
    "matches\n"
    "                    share rows\n"
    "  summary.json      the numbers\n"
    "  per_frame.csv     frame,t,n_true,n_frame,sigma_frame,n_window,"
    "sigma_window,matches";

int RunDemo();

}  // namespace

extern const Subcommand kDemoCommand = {
    "demo",
    "simulate a dive, estimate n from the images, plot it (no input needed)",
    kDemoUsage,
    {__FILE__, kSimulationFlagsSource, kGlassIndexFlagSource, kIndexFlagSource},
    RunDemo};

namespace {

using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

struct FrameResult {
  int frame = 0;
  double t = 0.0;
  double n_true = NAN;
  int64_t matches = 0;
  double n_frame = NAN;
  double sigma_frame = NAN;
  double n_window = NAN;
  double sigma_window = NAN;
  bool medium_switch = false;   // this frame confirmed a switch
  int switch_first_frame = -1;  // the switch's first frame of the new medium
};

// Layout of a side-by-side picture: a title strip of kTitle pixels above
// the two images, kGap pixels between them.
constexpr int kTitle = 34;
constexpr int kGap = 8;

// The stereo pair side by side on a BGR canvas with a title strip.
cv::Mat SideBySide(const cv::Mat& left, const cv::Mat& right,
                   const std::string& title) {
  cv::Mat canvas(left.rows + kTitle, left.cols + kGap + right.cols, CV_8UC3,
                 cv::Scalar(255, 255, 255));
  cv::Mat left_bgr;
  cv::Mat right_bgr;
  cv::cvtColor(left, left_bgr, cv::COLOR_GRAY2BGR);
  cv::cvtColor(right, right_bgr, cv::COLOR_GRAY2BGR);
  left_bgr.copyTo(canvas(cv::Rect(0, kTitle, left.cols, left.rows)));
  right_bgr.copyTo(
      canvas(cv::Rect(left.cols + kGap, kTitle, right.cols, right.rows)));
  cv::putText(canvas, title, cv::Point(8, 24), cv::FONT_HERSHEY_SIMPLEX, 0.65,
              cv::Scalar(30, 30, 30), 1, cv::LINE_AA);
  return canvas;
}

// Draws each match as a colored dot in both halves and a horizontal line
// through its left point across both images: where the right dot sits on
// its line, the two pixels share a row.
void DrawMatchesOnRows(const std::vector<Eigen::Vector2d>& left_points,
                       const std::vector<Eigen::Vector2d>& right_points,
                       int right_offset, cv::Mat* canvas) {
  for (size_t i = 0; i < left_points.size(); ++i) {
    const cv::Scalar color = PaletteColor(static_cast<int>(i));
    const cv::Point2d l(left_points[i].x(), left_points[i].y() + kTitle);
    const cv::Point2d r(right_points[i].x() + right_offset,
                        right_points[i].y() + kTitle);
    cv::line(*canvas, cv::Point2d(0, l.y), cv::Point2d(canvas->cols - 1, l.y),
             color, 1, cv::LINE_AA);
    cv::circle(*canvas, l, 5, color, 2, cv::LINE_AA);
    cv::circle(*canvas, r, 5, color, 2, cv::LINE_AA);
  }
}

// Up to `count` inlier matches spread over the left image: the one
// nearest to each cell center of a coarse grid.
std::vector<StereoCorrespondence> SpreadMatches(
    const std::vector<StereoCorrespondence>& matches, const Camera& left,
    int count) {
  const int columns = static_cast<int>(std::ceil(std::sqrt(count * 1.5)));
  const int rows = std::max(1, count / columns);
  std::vector<StereoCorrespondence> chosen;
  for (int row = 0; row < rows; ++row) {
    for (int column = 0; column < columns; ++column) {
      const Eigen::Vector2d center((column + 0.5) * left.width() / columns,
                                   (row + 0.5) * left.height() / rows);
      const StereoCorrespondence* best = nullptr;
      double best_distance = 0.12 * left.width();
      for (const StereoCorrespondence& match : matches) {
        const double distance = (match.left_pixel - center).norm();
        if (distance < best_distance) {
          best_distance = distance;
          best = &match;
        }
      }
      if (best != nullptr) chosen.push_back(*best);
    }
  }
  return chosen;
}

double Median(std::vector<double> values) {
  if (values.empty()) return NAN;
  std::nth_element(values.begin(), values.begin() + values.size() / 2,
                   values.end());
  return values[values.size() / 2];
}

// Median |r| of the matches' distances from their loci at n (pixels).
double MedianLocusDistance(const StereoRig& rig,
                           const PreparedCorrespondences& prepared, double n) {
  std::vector<double> residuals = LocusResiduals(
      EssentialMatrix(rig.right_from_left()), prepared.prepared, n);
  residuals.erase(std::remove_if(residuals.begin(), residuals.end(),
                                 [](double r) { return !std::isfinite(r); }),
                  residuals.end());
  for (double& r : residuals) r = std::abs(r);
  return Median(std::move(residuals));
}

cv::Mat PlotNPerFrame(const std::vector<FrameResult>& frames, double n_final,
                      double sigma_final) {
  std::vector<double> x;
  std::vector<double> truth;
  std::vector<double> n_frame;
  std::vector<double> frame_low;
  std::vector<double> frame_high;
  std::vector<double> n_window;
  std::vector<double> window_low;
  std::vector<double> window_high;
  for (const FrameResult& f : frames) {
    x.push_back(f.frame);
    truth.push_back(f.n_true);
    n_frame.push_back(f.n_frame);
    frame_low.push_back(f.n_frame - f.sigma_frame);
    frame_high.push_back(f.n_frame + f.sigma_frame);
    n_window.push_back(f.n_window);
    window_low.push_back(f.n_window - f.sigma_window);
    window_high.push_back(f.n_window + f.sigma_window);
  }
  LinePlot plot;
  const bool switched =
      std::any_of(frames.begin(), frames.end(),
                  [](const FrameResult& f) { return f.medium_switch; });
  std::ostringstream title;
  title << (switched ? "n from the images since the last switch: "
                     : "n from the images: ")
        << FormatFixed(n_final, 4) << " +- " << FormatFixed(sigma_final, 4)
        << " (truth " << FormatFixed(frames.back().n_true, 3) << ")";
  plot.SetTitle(title.str());
  plot.SetXLabel("frame (20 Hz)");
  plot.SetYLabel("refractive index n");
  plot.AddBand(x, frame_low, frame_high, "frame: 1 sigma", PaletteColor(7),
               0.18);
  plot.AddBand(x, window_low, window_high, "window: 1 sigma", PaletteColor(0),
               0.25);
  plot.AddLine(x, truth, "truth",
               LineStyle{cv::Scalar(40, 40, 40), 2.0, 8.0, 6.0});
  plot.AddLine(x, n_window, "sliding window", LineStyle{PaletteColor(0)});
  plot.AddMarkers(x, n_frame, "each frame alone",
                  MarkerStyle{PaletteColor(7), MarkerShape::kCircle, 3.5});
  for (const FrameResult& f : frames) {
    if (f.medium_switch) {
      plot.AddVerticalMarker(f.switch_first_frame - 0.5, "switch",
                             LineStyle{PaletteColor(3), 1.5, 6.0, 4.0});
    }
  }
  return plot.Render(1000, 600);
}

// What the self-calibration found of cam1's rotation, against the
// simulated drift.
std::string DriftLine(const RefractiveIndexEstimate& estimate,
                      const ExtrinsicDrift& drift) {
  if (!estimate.rotation) return "";
  const Eigen::Vector3d found = estimate.rotation->angle_axis * 180.0 / M_PI;
  const Eigen::Vector3d truth = drift.rotation * 180.0 / M_PI;
  const auto text = [](const Eigen::Vector3d& v) {
    return "(" + FormatFixed(v.x(), 3) + ", " + FormatFixed(v.y(), 3) + ", " +
           FormatFixed(v.z(), 3) + ")";
  };
  return "  cam1 self-calibrated as turned by " + text(found) +
         " deg since the calibration (simulated: " + text(truth) + " deg)\n";
}

int RunDemo() {
  const Subcommand& command = kDemoCommand;
  const auto start = Clock::now();
  // The flags before the folder: a wrong flag leaves nothing behind.
  StatusOr<Simulation> simulation = SimulationFromFlags("");
  if (!simulation.ok()) {
    PrintError(command, simulation.status().message());
    return kExitFailure;
  }
  if (const Status drift = ExtrinsicDriftFromFlag(&simulation->options);
      !drift.ok()) {
    PrintError(command, drift.message());
    return kExitUsage;
  }
  if (const Status lens = LensChangeFromFlag(&simulation->options);
      !lens.ok()) {
    PrintError(command, lens.message());
    return kExitUsage;
  }
  const std::string folder = FLAGS_out.empty() ? kDefaultFolder : FLAGS_out;
  std::error_code error;
  std::filesystem::create_directories(folder, error);
  if (error) {
    PrintError(command,
               "cannot create folder " + folder + ": " + error.message());
    return kExitFailure;
  }
  // The estimates treat the built-in rig as a camchain without a covariance
  // sidecar (stereo_rig_file.h): with the default drift prior, which the
  // self-calibration of cam1's rotation uses; and the matches with the
  // front end's systematic error floor. So the demo's sigma is what
  // rcm estimate would report on these images.
  const StereoRig rig =
      WithDefaultCalibrationUncertainty(simulation->rig).value();
  RefinementOptions refinement;
  refinement.systematic_px = kFrontEndSystematicPx;
  StatusOr<std::unique_ptr<SequenceSimulator>> created =
      SequenceSimulator::Create(simulation->rig, simulation.value().options);
  if (!created.ok()) {
    PrintError(command, created.status().message());
    return kExitFailure;
  }
  SequenceSimulator& simulator = *created.value();
  const int num_frames = simulator.num_frames();
  std::cerr << "rcm demo: " << num_frames << " frames of the "
            << simulation.value().rig_name << " rig (" << rig.left().width()
            << "x" << rig.left().height() << ") in a pool, media "
            << simulator.media().ToString() << ", seed " << FLAGS_seed
            << std::endl;

  // The pair loop of the library (sequence_estimator.h), as `rcm estimate`
  // on images runs it: guided matching, cam1's turn followed, the window,
  // and the estimator of record over the frames of the current medium.
  SequenceEstimatorOptions sequence_options;
  sequence_options.estimation.refinement = refinement;
  StatusOr<std::unique_ptr<SequenceEstimator>> sequence =
      SequenceEstimator::Create(rig, sequence_options);
  CHECK(sequence.ok()) << sequence.status().message();
  std::vector<FrameResult> results;
  int first_frame_of_medium = 0;
  cv::Mat first_left;
  cv::Mat first_right;
  std::vector<StereoCorrespondence> first_matches;
  double render_seconds = 0.0;
  double match_seconds = 0.0;
  double estimate_seconds = 0.0;
  for (int i = 0; i < num_frames; ++i) {
    auto tick = Clock::now();
    StatusOr<SequenceFrame> frame = simulator.Frame(i);
    if (!frame.ok()) {
      PrintError(command, "frame " + std::to_string(i) + ": " +
                              frame.status().message());
      return kExitFailure;
    }
    render_seconds += SecondsSince(tick);
    tick = Clock::now();
    StatusOr<SequencePair> pair = (*sequence)->AddPair(
        frame.value().left, frame.value().right, i, frame.value().t);
    if (!pair.ok()) {
      PrintError(command,
                 "frame " + std::to_string(i) + ": " + pair.status().message());
      return kExitFailure;
    }
    estimate_seconds += pair->estimate_ms / 1000.0;
    match_seconds += SecondsSince(tick) - pair->estimate_ms / 1000.0;

    FrameResult result;
    result.frame = i;
    result.t = frame.value().t;
    result.n_true = frame.value().n;
    result.matches = static_cast<int64_t>(pair->matches.size());
    if (pair->own.ok()) {
      result.n_frame = pair->own->n;
      result.sigma_frame = pair->own->sigma_n;
    }
    if (pair->window.ok()) {
      result.n_window = pair->window->n;
      result.sigma_window = pair->window->sigma_n;
    }
    result.medium_switch = pair->medium_switch.has_value();
    if (result.medium_switch) {
      // The new medium began at the switch's first frame.
      result.switch_first_frame =
          static_cast<int>(pair->medium_switch->first_frame);
      first_frame_of_medium = result.switch_first_frame;
    }
    if (i == 0) {
      first_left = frame.value().left;
      first_right = frame.value().right;
      first_matches = pair->matches;
    }
    results.push_back(result);
    std::cerr << "rcm demo: [" << (i + 1) << "/" << num_frames << "] "
              << result.matches << " matches; frame n "
              << FormatFixed(result.n_frame, 4) << " +- "
              << FormatFixed(result.sigma_frame, 4) << ", window "
              << FormatFixed(result.n_window, 4) << " +- "
              << FormatFixed(result.sigma_window, 4)
              << (result.medium_switch ? "  (medium switch)" : "") << std::endl;
  }

  // The estimator of record over every frame of the current medium, solved
  // once by the sequence.
  auto tick = Clock::now();
  StatusOr<RefractiveIndexEstimate> summary = (*sequence)->Estimate();
  estimate_seconds += SecondsSince(tick);
  if (!summary.ok()) {
    PrintError(command, "no estimate from the matched features: " +
                            summary.status().message());
    return kExitFailure;
  }
  std::vector<StereoCorrespondence> since_switch;  // matches of this medium
  for (const FrameMatches& kept : (*sequence)->frames()) {
    if (kept.frame < first_frame_of_medium) continue;
    since_switch.insert(since_switch.end(), kept.matches.begin(),
                        kept.matches.end());
  }
  for (const std::string& warning : summary->warnings) {
    PrintWarning(command, warning);
  }
  const RefractiveIndexEstimate& estimate = summary.value();
  // The rig as the estimate found it: cam1 turned by the self-calibrated
  // rotation, for the corrected pictures.
  const StereoRig estimated_rig =
      estimate.rotation
          ? rig.WithCam1Moved(estimate.rotation->angle_axis).value()
          : rig;
  const double truth = results.back().n_true;
  const double error_n = estimate.n - truth;
  const PreparedCorrespondences prepared =
      PrepareCorrespondences(rig, since_switch);
  const double residual_air = MedianLocusDistance(rig, prepared, 1.0);
  const double residual_fit =
      MedianLocusDistance(estimated_rig, prepared, estimate.n);

  // Pictures: the plot and the first pair before and after correction.
  const std::string plot_path = folder + "/n_per_frame.png";
  const std::string before_path = folder + "/before.png";
  const std::string after_path = folder + "/after.png";
  const std::string json_path = folder + "/summary.json";
  const std::string csv_path = folder + "/per_frame.csv";
  // The corrected pair: both cameras' virtual pinholes at the estimate,
  // rotated to the rectified pair and given the left camera's K_n, so that
  // a scene point lands on the same row in both (stereo_rectification.h).
  const RefractiveCamera left_water =
      RefractiveCamera::Create(rig.left(), estimate.n).value();
  const RefractiveCamera right_water =
      RefractiveCamera::Create(rig.right(), estimate.n).value();
  // The lens corrected but the water ignored (n = 1), for comparison.
  const RefractiveCamera left_air =
      RefractiveCamera::Create(rig.left(), 1.0).value();
  const RefractiveCamera right_air =
      RefractiveCamera::Create(rig.right(), 1.0).value();
  const StereoRectification rectification = RectifyStereoRig(estimated_rig);
  VirtualPinholeView left_view = ChooseVirtualPinholeView(left_water).value();
  left_view.camera_from_view = rectification.left_camera_from_rect;
  VirtualPinholeView right_view = left_view;
  right_view.camera_from_view = rectification.right_camera_from_rect;
  StatusOr<RemapMaps> left_maps =
      BuildVirtualPinholeMaps(left_water, left_view);
  StatusOr<RemapMaps> right_maps =
      BuildVirtualPinholeMaps(right_water, right_view);
  if (!left_maps.ok() || !right_maps.ok()) {
    PrintError(command,
               "cannot build the correction maps: " +
                   (left_maps.ok() ? right_maps.status() : left_maps.status())
                       .message());
    return kExitFailure;
  }
  // Pixel of a raw pixel in a rectified view through `camera` (at n = 1:
  // the lens corrected, the water ignored).
  const auto rectified_pixel =
      [&](const RefractiveCamera& camera,
          const Eigen::Matrix3d& camera_from_view,
          const Eigen::Vector2d& raw) -> std::optional<Eigen::Vector2d> {
    const std::optional<Eigen::Vector3d> bearing =
        camera.BearingInWaterFromImage(raw);
    if (!bearing) return std::nullopt;
    const Eigen::Vector3d in_view = camera_from_view.transpose() * *bearing;
    if (!(in_view.z() > 0.0)) return std::nullopt;
    return (left_view.k * in_view).hnormalized();
  };
  // The first frame's inlier matches at the estimate (within 1 px of their
  // loci): how far apart their rows are, raw, with the lens corrected but
  // the water ignored, and with the refraction corrected.
  std::vector<StereoCorrespondence> inliers_first;
  {
    const PreparedCorrespondences prepared =
        PrepareCorrespondences(rig, first_matches);
    const std::vector<double> r =
        LocusResiduals(EssentialMatrix(estimated_rig.right_from_left()),
                       prepared.prepared, estimate.n);
    for (size_t k = 0; k < r.size(); ++k) {
      if (std::abs(r[k]) < 1.0) {
        inliers_first.push_back(first_matches[prepared.source_index[k]]);
      }
    }
  }
  std::vector<double> rows_raw;
  std::vector<double> rows_air;
  std::vector<double> rows_water;
  for (const StereoCorrespondence& match : inliers_first) {
    const auto air_l = rectified_pixel(
        left_air, rectification.left_camera_from_rect, match.left_pixel);
    const auto air_r = rectified_pixel(
        right_air, rectification.right_camera_from_rect, match.right_pixel);
    const auto water_l = rectified_pixel(
        left_water, rectification.left_camera_from_rect, match.left_pixel);
    const auto water_r = rectified_pixel(
        right_water, rectification.right_camera_from_rect, match.right_pixel);
    if (!air_l || !air_r || !water_l || !water_r) continue;
    rows_raw.push_back(std::abs(match.left_pixel.y() - match.right_pixel.y()));
    rows_air.push_back(std::abs(air_l->y() - air_r->y()));
    rows_water.push_back(std::abs(water_l->y() - water_r->y()));
  }
  const double row_gap_raw = Median(rows_raw);
  const double row_gap_air = Median(rows_air);
  const double row_gap_water = Median(rows_water);

  const std::vector<StereoCorrespondence> shown =
      SpreadMatches(inliers_first, rig.left(), 12);
  std::vector<Eigen::Vector2d> raw_left;
  std::vector<Eigen::Vector2d> raw_right;
  std::vector<Eigen::Vector2d> corrected_left;
  std::vector<Eigen::Vector2d> corrected_right;
  for (const StereoCorrespondence& match : shown) {
    const auto l = rectified_pixel(
        left_water, rectification.left_camera_from_rect, match.left_pixel);
    const auto r = rectified_pixel(
        right_water, rectification.right_camera_from_rect, match.right_pixel);
    if (!l || !r) continue;
    raw_left.push_back(match.left_pixel);
    raw_right.push_back(match.right_pixel);
    corrected_left.push_back(*l);
    corrected_right.push_back(*r);
  }
  cv::Mat before = SideBySide(
      first_left, first_right,
      "before: frame 0 as the cameras see it. Matches are " +
          FormatFixed(row_gap_raw, 1) + " px apart in rows (median)");
  DrawMatchesOnRows(raw_left, raw_right, first_left.cols + kGap, &before);
  cv::Mat after = SideBySide(
      RemapToVirtualPinhole(first_left, left_maps.value()),
      RemapToVirtualPinhole(first_right, right_maps.value()),
      "after: refraction corrected at n = " + FormatFixed(estimate.n, 4) +
          ", rectified: " + FormatFixed(row_gap_water, 2) + " px (" +
          FormatFixed(row_gap_air, 2) + " px if the water is ignored)");
  DrawMatchesOnRows(corrected_left, corrected_right, first_left.cols + kGap,
                    &after);

  nlohmann::json per_frame = nlohmann::json::array();
  std::string csv =
      "frame,t,n_true,n_frame,sigma_frame,n_window,sigma_window,matches\n";
  for (const FrameResult& f : results) {
    per_frame.push_back({{"frame", f.frame},
                         {"t", f.t},
                         {"n_true", f.n_true},
                         {"n_frame", JsonNumber(f.n_frame)},
                         {"sigma_frame", JsonNumber(f.sigma_frame)},
                         {"n_window", JsonNumber(f.n_window)},
                         {"sigma_window", JsonNumber(f.sigma_window)},
                         {"matches", f.matches},
                         {"switch", f.medium_switch}});
    csv += std::to_string(f.frame);
    for (const double value : {f.t, f.n_true, f.n_frame, f.sigma_frame,
                               f.n_window, f.sigma_window}) {
      csv += "," + (std::isfinite(value) ? FormatDouble(value) : "nan");
    }
    csv += "," + std::to_string(f.matches) + "\n";
  }
  const double seconds = SecondsSince(start);
  nlohmann::json report = {
      {"n", estimate.n},
      {"sigma_n", estimate.sigma_n},
      {"sigma_n_noise", estimate.sigma_n_noise},
      {"sigma_n_calibration", estimate.sigma_n_calibration},
      {"sigma_n_systematic", estimate.sigma_n_systematic},
      {"rotation_deg",
       estimate.rotation
           ? nlohmann::json{estimate.rotation->angle_axis.x() * 180.0 / M_PI,
                            estimate.rotation->angle_axis.y() * 180.0 / M_PI,
                            estimate.rotation->angle_axis.z() * 180.0 / M_PI}
           : nlohmann::json(nullptr)},
      {"crlb", estimate.crlb},
      {"sigma_px", estimate.sigma_px},
      {"n_true", truth},
      {"error", error_n},
      {"error_sigmas", error_n / estimate.sigma_n},
      {"frames", num_frames},
      {"frames_used", num_frames - first_frame_of_medium},
      {"matches", since_switch.size()},
      {"inliers", estimate.inliers},
      {"median_locus_distance_px",
       {{"assuming_air", JsonNumber(residual_air)},
        {"at_estimate", JsonNumber(residual_fit)}}},
      {"first_frame_row_gap_px",
       {{"raw", JsonNumber(row_gap_raw)},
        {"lens_corrected_water_ignored", JsonNumber(row_gap_air)},
        {"refraction_corrected", JsonNumber(row_gap_water)}}},
      {"per_frame", per_frame},
      // The estimate as `rcm estimate --json` prints it (the same keys).
      {"estimate", nlohmann::json::parse(EstimateJson(estimate, -1))},
      {"simulation", SimulationFlagsJson(simulation.value())},
      {"seconds",
       {{"total", seconds},
        {"render", render_seconds},
        {"match", match_seconds},
        {"estimate", estimate_seconds}}},
      {"files",
       {{"plot", plot_path},
        {"before", before_path},
        {"after", after_path},
        {"per_frame", csv_path}}}};

  for (const Status& written :
       {WritePng(PlotNPerFrame(results, estimate.n, estimate.sigma_n),
                 plot_path),
        WritePng(before, before_path), WritePng(after, after_path),
        WriteFileAtomically(csv_path, csv),
        WriteFileAtomically(json_path, report.dump(2) + "\n")}) {
    if (!written.ok()) {
      PrintError(command, written.message());
      return kExitFailure;
    }
  }

  if (FLAGS_json) {
    std::cout << report.dump() << std::endl;
    return kExitOk;
  }
  std::cout << "rcm demo: n = " << FormatFixed(estimate.n, 5) << " +- "
            << FormatFixed(estimate.sigma_n, 5) << " from " << estimate.inliers
            << " matched features in " << (num_frames - first_frame_of_medium)
            << (first_frame_of_medium > 0 ? " frames since the last switch"
                                          : " frames")
            << " (truth " << FormatFixed(truth, 5) << ", off by "
            << FormatFixed(std::abs(error_n / estimate.sigma_n), 1)
            << " sigma)\n"
            << "  sigma_n: pixel noise "
            << FormatFixed(estimate.sigma_n_noise, 5) << ", calibration "
            << FormatFixed(estimate.sigma_n_calibration, 5) << " ("
            << rig.calibration_uncertainty()->source
            << "), matches' systematic "
               "error "
            << FormatFixed(estimate.sigma_n_systematic, 5) << "\n"
            << DriftLine(estimate, simulation->options.cam1_drift)
            << "  matches lie " << FormatFixed(residual_air, 2)
            << " px from their epipolar curves if the water is ignored, "
            << FormatFixed(residual_fit, 2) << " px at the estimate (medians)\n"
            << "  corrected and rectified, a match's two pixels are "
            << FormatFixed(row_gap_water, 2) << " px apart in rows ("
            << FormatFixed(row_gap_air, 2) << " px with the lens corrected "
            << "but the water ignored, " << FormatFixed(row_gap_raw, 1)
            << " px raw)\n\n"
            << "  " << plot_path << "  n per frame against the truth\n"
            << "  " << before_path << "       the first stereo pair, raw\n"
            << "  " << after_path
            << "        the same pair, refraction corrected and rectified\n"
            << "  " << json_path << "     the numbers; per frame in "
            << csv_path << "\n"
            << "done in " << FormatFixed(seconds, 1) << " s (render "
            << FormatFixed(render_seconds, 1) << " s, matching "
            << FormatFixed(match_seconds, 1) << " s, estimation "
            << FormatFixed(estimate_seconds, 1) << " s)" << std::endl;
  return kExitOk;
}

}  // namespace
}  // namespace rcm::cli
