#include "estimate_report.h"

#include <cmath>
#include <cstdio>
#include <sstream>

#include "rcm/plot/line_plot.h"
#include "rcm/util/number_format.h"

namespace rcm::cli {
namespace {

constexpr double kReportDegreesPerRadian = 180.0 / M_PI;

std::string FrameLabel(int64_t frame) {
  return "frame " + std::to_string(frame);
}

// A probability to two significant digits ("0.49", "3.4e-05").
std::string FormatProbability(double p) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.2g", p);
  return text;
}

}  // namespace

std::vector<std::string> EstimatorLines(const RefractiveIndexEstimate& e) {
  std::vector<std::string> lines;
  if (e.n_seed) {
    lines.push_back("  seeds      closed form " +
                    (e.n_closed_form ? FormatFixed(*e.n_closed_form, 4)
                                     : std::string("n/a")) +
                    ", scan " + FormatFixed(*e.n_seed, 4) + ", robust stage " +
                    FormatFixed(e.n_robust.value_or(NAN), 5));
  }
  if (e.bundle) {
    const BundleSummary& b = *e.bundle;
    lines.push_back("  bundle     " + std::to_string(b.frames_used) +
                    " keyframes, " + std::to_string(b.landmarks) +
                    " landmarks (" + std::to_string(b.tracks) +
                    " tracked over keyframes), " +
                    std::to_string(b.observations) + " observations");
    lines.push_back("  motion     " + b.motion);
  }
  if (e.air_gap) {
    const AirGapEstimate& gap = *e.air_gap;
    lines.push_back("  air gap    " + FormatFixed(1e3 * gap.left_air_gap, 2) +
                    " mm (left), " + FormatFixed(1e3 * gap.right_air_gap, 2) +
                    " mm (right) +- " + FormatFixed(1e3 * gap.sigma, 2) +
                    " mm, correlation with n " +
                    FormatFixed(gap.correlation_with_n, 2) +
                    (std::abs(gap.correlation_with_n) > 0.9
                         ? " (hardly separable from n: measure the gap instead)"
                         : ""));
  }
  if (e.rotation) {
    const RotationCorrection& rotation = *e.rotation;
    const Eigen::Vector3d degrees =
        rotation.angle_axis * kReportDegreesPerRadian;
    const Eigen::Vector3d sigma = rotation.sigma * kReportDegreesPerRadian;
    std::ostringstream line;
    line << "  rotation   cam1 "
         << (rotation.with_prior ? "self-calibrated: turned by ("
                                 : "corrected by (")
         << FormatFixed(degrees.x(), 4) << ", " << FormatFixed(degrees.y(), 4)
         << ", " << FormatFixed(degrees.z(), 4) << ") deg +- ("
         << FormatFixed(sigma.x(), 4) << ", " << FormatFixed(sigma.y(), 4)
         << ", " << FormatFixed(sigma.z(), 4)
         << (rotation.with_prior ? ") since the calibration" : ")")
         << "; correlation with n R = "
         << FormatFixed(rotation.multiple_correlation_with_n, 2);
    lines.push_back(line.str());
  }
  if (e.focal) {
    const FocalScaleCorrection& focal = *e.focal;
    lines.push_back("  lenses     focal lengths self-calibrated: cam0 " +
                    FormatFixed(1e2 * focal.scale[0], 3) + " +- " +
                    FormatFixed(1e2 * focal.sigma[0], 3) + " %, cam1 " +
                    FormatFixed(1e2 * focal.scale[1], 3) + " +- " +
                    FormatFixed(1e2 * focal.sigma[1], 3) +
                    " % since the calibration");
  }
  if (e.estimator == "online" && e.skipped_frames.value_or(0) > 0) {
    lines.push_back("  skipped    " + std::to_string(*e.skipped_frames) +
                    " frames without an own estimate (too few usable "
                    "matches or inliers)");
  }
  for (const MediumSwitch& s : e.switches) {
    lines.push_back("  switch     at " + FrameLabel(s.first_frame) +
                    " (confirmed at " + FrameLabel(s.detected_at_frame) +
                    "): n " + FormatFixed(s.n_before, 4) + " -> " +
                    FormatFixed(s.n_after, 4));
  }
  if (e.window) {
    lines.push_back("  window     " + FrameLabel(e.window->first_frame) +
                    " to " + FrameLabel(e.window->last_frame) + " (" +
                    std::to_string(e.window->frames) + " frames); " +
                    std::to_string(e.switches.size()) + " change" +
                    (e.switches.size() == 1 ? "" : "s") + " of medium");
  }
  if (e.masked) {
    lines.push_back("  used       " + std::to_string(e.inliers) + " (masked " +
                    std::to_string(*e.masked) + ", invalid " +
                    std::to_string(e.invalid) + ")");
  }
  return lines;
}

std::vector<std::string> UncertaintyLines(const RefractiveIndexEstimate& e) {
  std::vector<std::string> lines;
  if (e.estimator == "closed-form") {
    lines.push_back("  n          " + FormatFixed(e.n, 5) + " +- " +
                    FormatFixed(e.sigma_n, 5) + " (standard error)");
    return lines;
  }
  lines.push_back("  n          " + FormatFixed(e.n, 5) + " +- " +
                  FormatFixed(e.sigma_n, 5) + " (1 sigma: pixel noise " +
                  FormatFixed(e.sigma_n_noise, 5) + ", calibration " +
                  FormatFixed(e.sigma_n_calibration, 5) +
                  (e.sigma_n_systematic > 0.0
                       ? ", matches' systematic error " +
                             FormatFixed(e.sigma_n_systematic, 5)
                       : std::string()) +
                  "; Cramer-Rao bound " + FormatFixed(e.crlb, 5) +
                  " with the calibration exact)");
  lines.push_back("  pixel noise " + FormatFixed(e.sigma_px, 3) +
                  " px (estimated from the inliers)");
  if (e.calibration) {
    const CalibrationPropagation& p = *e.calibration;
    const Eigen::Vector3d tenth =
        0.1 * p.dn_drotation / kReportDegreesPerRadian;
    lines.push_back("  calibration " + p.source + "; n moves by (" +
                    FormatFixed(tenth.x(), 4) + ", " +
                    FormatFixed(tenth.y(), 4) + ", " +
                    FormatFixed(tenth.z(), 4) +
                    ") per 0.1 deg of cam1 rotation about x, y, z");
    if (p.mode == RotationMode::kHeld) {
      lines.push_back(
          "  rotation   held at the calibration's (its uncertainty is in "
          "sigma_n)");
    } else {
      lines.push_back(
          "  observability  from the data alone, n and cam1's rotation "
          "correlate with R = " +
          FormatFixed(p.rotation_multiple_correlation, 3) +
          " (a free rotation would multiply sigma_n by " +
          FormatFixed(p.rotation_sigma_inflation, 1) + ")");
    }
  }
  if (e.consistency) {
    const FrameConsistency& c = *e.consistency;
    const bool disagree = c.inflation > 1.0;
    lines.push_back("  frames     " + std::to_string(c.frames) +
                    (disagree ? " disagree beyond" : " agree within") +
                    " their sigmas: chi2 " + FormatFixed(c.chi_squared, 1) +
                    " for " + std::to_string(c.dof) + " dof (p " +
                    FormatProbability(c.p_value) + ")" +
                    (disagree
                         ? "; the pixel-noise share of sigma_n is inflated x" +
                               FormatFixed(c.inflation, 2)
                         : ""));
  }
  return lines;
}

cv::Mat PlotPerFrame(const RefractiveIndexEstimate& e) {
  std::vector<double> x, n, low, high;
  for (const FrameEstimateRow& row : e.per_frame) {
    if (!std::isfinite(row.n)) continue;
    x.push_back(static_cast<double>(row.frame));
    n.push_back(row.n);
    const double sigma = std::isfinite(row.sigma_n) ? row.sigma_n : 0.0;
    low.push_back(row.n - sigma);
    high.push_back(row.n + sigma);
  }
  LinePlot plot;
  plot.SetTitle("n = " + FormatFixed(e.n, 5) + " +- " +
                FormatFixed(e.sigma_n, 5) + " (" + e.estimator + ")");
  plot.SetXLabel("frame");
  plot.SetYLabel("refractive index n");
  // The bundle solves the dive once: its per-frame rows are each pair's
  // own epipolar estimate, with cam1 as the camchain has it.
  const std::string what = e.estimator == "refine"   ? "each frame alone"
                           : e.estimator == "window" ? "window estimate"
                           : e.estimator == "bundle"
                               ? "each pair alone, cam1 as calibrated"
                               : "estimate so far";
  if (!x.empty()) {
    plot.AddBand(x, low, high, what + ": 1 sigma", PaletteColor(7), 0.2);
    plot.AddLine(x, n, what, LineStyle{PaletteColor(7)});
    plot.AddMarkers(x, n, "",
                    MarkerStyle{PaletteColor(7), MarkerShape::kCircle, 3.0});
  }
  if (std::isfinite(e.n)) {
    plot.AddHorizontalLine(e.n, "final estimate",
                           LineStyle{PaletteColor(0), 2.0});
  }
  for (const FrameEstimateRow& row : e.per_frame) {
    if (row.medium_switch) {
      plot.AddVerticalMarker(static_cast<double>(row.frame) - 0.5, "switch",
                             LineStyle{PaletteColor(3), 1.5, 6.0, 4.0});
    }
  }
  return plot.Render(1000, 600);
}

cv::Mat PlotTrajectory(const RefractiveIndexEstimate& e) {
  std::vector<double> x, z;
  if (e.bundle) {
    for (const BundlePose& pose : e.bundle->trajectory) {
      x.push_back(pose.world_from_cam0.translation.x());
      z.push_back(pose.world_from_cam0.translation.z());
    }
  }
  LinePlot plot;
  std::string title =
      "n = " + FormatFixed(e.n, 5) + " +- " + FormatFixed(e.sigma_n, 5);
  if (e.rotation) {
    title += ", cam1 turned " +
             FormatFixed(e.rotation->angle_axis.norm() * 180.0 / M_PI, 3) +
             " deg";
  }
  plot.SetTitle(title);
  plot.SetXLabel("x (m, right of the first left camera)");
  plot.SetYLabel("z (m, ahead of the first left camera)");
  if (!x.empty()) {
    plot.AddLine(x, z, "left camera", LineStyle{PaletteColor(0), 2.0});
    // The first under the last, larger: a loop's both show.
    plot.AddMarkers({x.front()}, {z.front()}, "first keyframe",
                    MarkerStyle{PaletteColor(2), MarkerShape::kCircle, 10.0});
    plot.AddMarkers({x.back()}, {z.back()}, "last keyframe",
                    MarkerStyle{PaletteColor(3), MarkerShape::kCircle, 6.0});
  }
  return plot.Render(900, 800);
}

}  // namespace rcm::cli
