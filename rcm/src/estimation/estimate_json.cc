#include "rcm/estimation/estimate_json.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>
#include <sstream>

namespace rcm {
namespace {

constexpr double kJsonDegreesPerRadian = 180.0 / M_PI;

using Json = nlohmann::json;  // (file-local names: unity builds)

// NaN and infinities are null (JSON has no such numbers).
Json JsonNumberOf(double value) {
  return std::isfinite(value) ? Json(value) : Json();
}

Json JsonNumberOf(const std::optional<double>& value) {
  return value ? JsonNumberOf(*value) : Json();
}

Json JsonArrayOf(const Eigen::Vector3d& v, double scale = 1.0) {
  return Json::array({JsonNumberOf(scale * v.x()), JsonNumberOf(scale * v.y()),
                      JsonNumberOf(scale * v.z())});
}

Json JsonArrayOf(const Eigen::Vector2d& v, double scale = 1.0) {
  return Json::array(
      {JsonNumberOf(scale * v.x()), JsonNumberOf(scale * v.y())});
}

double SqrtOfVariance(double variance) {
  return std::sqrt(std::max(0.0, variance));
}

Json EstimateCalibrationJson(const RefractiveIndexEstimate& e) {
  if (!e.calibration || !e.rotation_prior_covariance) return nullptr;
  const CalibrationPropagation& p = *e.calibration;
  const Eigen::Matrix3d& c = *e.rotation_prior_covariance;
  const Json prior = JsonArrayOf(
      Eigen::Vector3d(SqrtOfVariance(c(0, 0)), SqrtOfVariance(c(1, 1)),
                      SqrtOfVariance(c(2, 2))),
      kJsonDegreesPerRadian);
  return {
      {"source", p.source},
      {"rotation", RotationModeName(p.mode)},
      {"prior_sigma_deg", prior},
      {"sensitivity_per_deg",
       JsonArrayOf(p.dn_drotation, 1.0 / kJsonDegreesPerRadian)},
      {"sensitivity_per_mm", JsonArrayOf(p.dn_dtranslation, 1e-3)},
      {"sigma_n_rotation", SqrtOfVariance(p.variance_rotation)},
      {"sigma_n_translation", SqrtOfVariance(p.variance_translation)},
      {"sigma_n_lenses", SqrtOfVariance(p.variance_lenses)},
      {"sigma_n_ports", SqrtOfVariance(p.variance_ports)},
      {"sigma_n_medium", SqrtOfVariance(p.variance_medium)},
      {"rotation_multiple_correlation",
       JsonNumberOf(p.rotation_multiple_correlation)},
      {"sigma_inflation_if_free", JsonNumberOf(p.rotation_sigma_inflation)}};
}

// The residuals' test for a systematic field (calibration_propagation.h);
// null when it did not run.
Json EstimateSystematicFieldJson(const RefractiveIndexEstimate& e) {
  if (!e.calibration || e.calibration->systematic_dof == 0) return nullptr;
  const CalibrationPropagation& p = *e.calibration;
  return {{"chi_squared", JsonNumberOf(p.systematic_chi_squared)},
          {"dof", p.systematic_dof},
          {"p_value", JsonNumberOf(p.systematic_p_value)},
          {"detected_px", JsonNumberOf(p.systematic_detected_px)}};
}

Json EstimateConsistencyJson(const std::optional<FrameConsistency>& c) {
  if (!c) return nullptr;
  return {{"frames", c->frames},
          {"chi_squared", JsonNumberOf(c->chi_squared)},
          {"dof", c->dof},
          {"p_value", JsonNumberOf(c->p_value)},
          {"inflation", JsonNumberOf(c->inflation)}};
}

}  // namespace

std::string EstimateJson(const RefractiveIndexEstimate& e, int indent) {
  Json json;
  json["estimator"] = e.estimator;
  json["port"] = e.port;
  json["method"] = e.method;
  json["n"] = JsonNumberOf(e.n);
  json["sigma_n"] = JsonNumberOf(e.sigma_n);
  json["sigma_n_noise"] = JsonNumberOf(e.sigma_n_noise);
  json["sigma_n_calibration"] = JsonNumberOf(e.sigma_n_calibration);
  json["sigma_n_systematic"] = JsonNumberOf(e.sigma_n_systematic);
  json["systematic_px"] = JsonNumberOf(e.systematic_px);
  json["systematic_field"] = EstimateSystematicFieldJson(e);
  json["calibration"] = EstimateCalibrationJson(e);
  json["consistency"] = EstimateConsistencyJson(e.consistency);
  json["n_closed_form"] = JsonNumberOf(e.n_closed_form);
  json["crlb"] = JsonNumberOf(e.crlb);
  json["sigma_px"] = JsonNumberOf(e.sigma_px);
  json["inliers"] = e.inliers;
  json["invalid"] = e.invalid;
  json["correspondences"] = e.correspondences;
  json["frames"] = e.frames;
  if (e.rotation) {
    const RotationCorrection& r = *e.rotation;
    json["rotation"] = {
        {"angle_axis_deg", JsonArrayOf(r.angle_axis, kJsonDegreesPerRadian)},
        {"sigma_deg", JsonArrayOf(r.sigma, kJsonDegreesPerRadian)},
        {"correlation_with_n", JsonArrayOf(r.correlation_with_n)},
        {"multiple_correlation_with_n",
         JsonNumberOf(r.multiple_correlation_with_n)},
        {"with_prior", r.with_prior}};
  }
  if (e.focal) {
    const FocalScaleCorrection& f = *e.focal;
    json["focal_scale"] = {
        {"percent", JsonArrayOf(f.scale, 1e2)},
        {"sigma_percent", JsonArrayOf(f.sigma, 1e2)},
        {"correlation_with_n", JsonArrayOf(f.correlation_with_n)}};
  }
  if (e.air_gap) {
    json["air_gap"] = {
        {"left_m", JsonNumberOf(e.air_gap->left_air_gap)},
        {"right_m", JsonNumberOf(e.air_gap->right_air_gap)},
        {"sigma_m", JsonNumberOf(e.air_gap->sigma)},
        {"correlation_with_n", JsonNumberOf(e.air_gap->correlation_with_n)}};
  }
  if (e.n_seed) json["n_seed"] = JsonNumberOf(e.n_seed);
  if (e.n_robust) json["n_robust"] = JsonNumberOf(e.n_robust);
  if (e.cost) json["cost"] = JsonNumberOf(e.cost);
  if (e.iterations) json["iterations"] = *e.iterations;
  if (e.skipped_frames) json["skipped_frames"] = *e.skipped_frames;
  if (e.dropped_frames) json["dropped_frames"] = *e.dropped_frames;
  if (e.window) {
    json["window"] = {{"frames", e.window->frames},
                      {"first_frame", e.window->first_frame},
                      {"last_frame", e.window->last_frame}};
  }
  if (e.estimator == "window") {
    Json switches = Json::array();
    for (const MediumSwitch& s : e.switches) {
      switches.push_back({{"frame", s.first_frame},
                          {"detected_at_frame", s.detected_at_frame},
                          {"n_before", JsonNumberOf(s.n_before)},
                          {"n_after", JsonNumberOf(s.n_after)}});
    }
    json["switches"] = switches;
  }
  if (e.bundle) {
    json["frames_used"] = e.bundle->frames_used;
    json["landmarks"] = e.bundle->landmarks;
    json["tracks"] = e.bundle->tracks;
    json["observations"] = e.bundle->observations;
    json["motion"] = e.bundle->motion;
  }
  if (e.masked) json["masked"] = *e.masked;
  if (e.mask_eta) json["mask_eta"] = JsonNumberOf(e.mask_eta);
  json["warnings"] = e.warnings;
  return json.dump(indent);
}

std::string EstimatePerFrameCsv(const RefractiveIndexEstimate& estimate) {
  std::ostringstream out;
  out.precision(17);
  out << "frame,t,n,sigma_n,switch\n";
  for (const FrameEstimateRow& row : estimate.per_frame) {
    out << row.frame << ",";
    if (row.timestamp) out << *row.timestamp;
    out << ",";
    if (std::isfinite(row.n)) out << row.n;
    out << ",";
    if (std::isfinite(row.sigma_n)) out << row.sigma_n;
    out << "," << (row.medium_switch ? 1 : 0) << "\n";
  }
  return out.str();
}

std::string EstimateTrajectoryTum(const RefractiveIndexEstimate& estimate) {
  std::ostringstream out;
  out.precision(17);
  out << "# timestamp tx ty tz qx qy qz qw (world_from_cam0: the left camera "
         "in the first keyframe's frame, metres; the frame index where the "
         "pairs have no time)\n";
  if (!estimate.bundle) return out.str();
  for (const BundlePose& pose : estimate.bundle->trajectory) {
    const Eigen::Quaterniond q(pose.world_from_cam0.rotation);
    // + 0.0: no "-0" for the first keyframe's inverted identity.
    const Eigen::Vector3d t =
        pose.world_from_cam0.translation + Eigen::Vector3d::Zero();
    if (pose.timestamp) {
      out << *pose.timestamp;
    } else {
      out << pose.frame;
    }
    out << " " << t.x() << " " << t.y() << " " << t.z() << " " << q.x() << " "
        << q.y() << " " << q.z() << " " << q.w() << "\n";
  }
  return out.str();
}

}  // namespace rcm
