#include "rcm/estimation/sampson_coplanarity_cost_function.h"

#include <ceres/jet.h>
#include <ceres/rotation.h>

#include <cmath>

namespace rcm {
namespace {

// M = R(delta) E and dM/d(delta_k) for one rotation, kept per thread: every
// residual of an evaluation has the same delta and E, so it is made once
// per evaluation and thread (the Jacobian of the rotation matrix from
// ceres::AngleAxisToRotationMatrix on Jet<double, 3>, which takes the same
// small-angle branch as the autodiff form's AngleAxisRotatePoint).
struct RotatedEssential {
  bool made = false;
  double delta[3] = {0.0, 0.0, 0.0};
  Eigen::Matrix3d essential;
  Eigen::Matrix3d m;
  Eigen::Matrix3d dm[3];
};

const RotatedEssential& RotatedEssentialOf(const Eigen::Matrix3d& essential,
                                           const double* delta) {
  thread_local RotatedEssential cached;
  if (cached.made && cached.delta[0] == delta[0] &&
      cached.delta[1] == delta[1] && cached.delta[2] == delta[2] &&
      cached.essential == essential) {
    return cached;
  }
  using Jet = ceres::Jet<double, 3>;
  const Jet angle_axis[3] = {Jet(delta[0], 0), Jet(delta[1], 1),
                             Jet(delta[2], 2)};
  Jet rotation[9];
  ceres::AngleAxisToRotationMatrix(
      angle_axis, ceres::ColumnMajorAdapter3x3(rotation));  // R(i, j) at 3j+i
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      Jet sum(0.0);
      for (int k = 0; k < 3; ++k) sum += rotation[3 * k + i] * essential(k, j);
      cached.m(i, j) = sum.a;
      for (int q = 0; q < 3; ++q) cached.dm[q](i, j) = sum.v[q];
    }
  }
  for (int q = 0; q < 3; ++q) cached.delta[q] = delta[q];
  cached.essential = essential;
  cached.made = true;
  return cached;
}

// (g_x, g_y) J for J = d(x, y)/d(u, v) row-major: the pixel gradient.
inline void Chain(double gx, double gy, const double* j, double* out) {
  out[0] = gx * j[0] + gy * j[2];
  out[1] = gx * j[1] + gy * j[3];
}

// The residual of `match` and its derivatives (each pointer may be null)
// for M = R(delta) E, with dm the derivatives of M in delta (null: no
// rotation block) and `focal` the focal scales (null: none).
bool EvaluateMatch(const Eigen::Matrix3d& m, const Eigen::Matrix3d* dm,
                   const PreparedCorrespondence& match, double n,
                   const double* focal, double* residual, double* jacobian_n,
                   double* jacobian_rotation, double* jacobian_focal) {
  double xl = match.left_normalized[0];
  double yl = match.left_normalized[1];
  double xr = match.right_normalized[0];
  double yr = match.right_normalized[1];
  double jl[4];
  double jr[4];
  for (int k = 0; k < 4; ++k) {
    jl[k] = match.left_normalized_from_pixel[k];
    jr[k] = match.right_normalized_from_pixel[k];
  }
  if (focal != nullptr) {
    xl += focal[0] * match.left_focal_direction[0];
    yl += focal[0] * match.left_focal_direction[1];
    xr += focal[1] * match.right_focal_direction[0];
    yr += focal[1] * match.right_focal_direction[1];
    for (int k = 0; k < 4; ++k) {
      jl[k] += focal[0] * match.left_normalized_from_pixel_focal[k];
      jr[k] += focal[1] * match.right_normalized_from_pixel_focal[k];
    }
  }
  const double excess = n * n - 1.0;
  const double rho_l = xl * xl + yl * yl;
  const double rho_r = xr * xr + yr * yr;
  const double ml = std::sqrt(n * n + excess * rho_l);
  const double mr = std::sqrt(n * n + excess * rho_r);
  const Eigen::Vector3d bl(xl, yl, ml);
  const Eigen::Vector3d br(xr, yr, mr);
  const Eigen::Vector3d a = m * bl;
  const Eigen::Vector3d c = m.transpose() * br;
  const double e = br.dot(a);
  const double sl = excess / ml;
  const double sr = excess / mr;
  const double gl[2] = {c[0] + c[2] * sl * xl, c[1] + c[2] * sl * yl};
  const double gr[2] = {a[0] + a[2] * sr * xr, a[1] + a[2] * sr * yr};
  double g[4];
  Chain(gl[0], gl[1], jl, g);
  Chain(gr[0], gr[1], jr, g + 2);
  const double g2 = g[0] * g[0] + g[1] * g[1] + g[2] * g[2] + g[3] * g[3];
  if (!(g2 > 0.0)) return false;
  const double norm = std::sqrt(g2);
  const double r = e / norm;
  *residual = r;

  // dr/dq from e' and G' (header).
  const auto derivative = [&](double de, const double* dg) {
    const double g_dg =
        g[0] * dg[0] + g[1] * dg[1] + g[2] * dg[2] + g[3] * dg[3];
    return (de - r * g_dg / norm) / norm;
  };
  // G' from a' and c' at fixed s and (x, y): the rotation's and n's share.
  const auto gradient_from = [&](const Eigen::Vector3d& da,
                                 const Eigen::Vector3d& dc, double dsl,
                                 double dsr, double* dg) {
    Chain(dc[0] + dc[2] * sl * xl + c[2] * dsl * xl,
          dc[1] + dc[2] * sl * yl + c[2] * dsl * yl, jl, dg);
    Chain(da[0] + da[2] * sr * xr + a[2] * dsr * xr,
          da[1] + da[2] * sr * yr + a[2] * dsr * yr, jr, dg + 2);
  };

  if (jacobian_n != nullptr) {
    const double dml = n * (1.0 + rho_l) / ml;
    const double dmr = n * (1.0 + rho_r) / mr;
    const double dsl = (2.0 * n - sl * dml) / ml;
    const double dsr = (2.0 * n - sr * dmr) / mr;
    const Eigen::Vector3d da = dml * m.col(2);
    const Eigen::Vector3d dc = dmr * m.row(2).transpose();
    double dg[4];
    gradient_from(da, dc, dsl, dsr, dg);
    *jacobian_n = derivative(dmr * a[2] + dml * c[2], dg);
  }
  if (dm != nullptr && jacobian_rotation != nullptr) {
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d da = dm[k] * bl;
      const Eigen::Vector3d dc = dm[k].transpose() * br;
      double dg[4];
      gradient_from(da, dc, 0.0, 0.0, dg);
      jacobian_rotation[k] = derivative(br.dot(da), dg);
    }
  }
  if (focal != nullptr && jacobian_focal != nullptr) {
    {  // e_l: the left camera's coordinates, m_l, s_l and J_l move.
      const double dxl = match.left_focal_direction[0];
      const double dyl = match.left_focal_direction[1];
      const double dml = excess * (xl * dxl + yl * dyl) / ml;
      const double dsl = -sl * dml / ml;
      const Eigen::Vector3d da = m * Eigen::Vector3d(dxl, dyl, dml);
      double dg[4];
      double extra[2];
      Chain(c[2] * (dsl * xl + sl * dxl), c[2] * (dsl * yl + sl * dyl), jl, dg);
      Chain(gl[0], gl[1], match.left_normalized_from_pixel_focal, extra);
      dg[0] += extra[0];
      dg[1] += extra[1];
      Chain(da[0] + da[2] * sr * xr, da[1] + da[2] * sr * yr, jr, dg + 2);
      jacobian_focal[0] = derivative(br.dot(da), dg);
    }
    {  // e_r: the right camera's.
      const double dxr = match.right_focal_direction[0];
      const double dyr = match.right_focal_direction[1];
      const double dmr = excess * (xr * dxr + yr * dyr) / mr;
      const double dsr = -sr * dmr / mr;
      const Eigen::Vector3d dbr(dxr, dyr, dmr);
      const Eigen::Vector3d dc = m.transpose() * dbr;
      double dg[4];
      double extra[2];
      Chain(dc[0] + dc[2] * sl * xl, dc[1] + dc[2] * sl * yl, jl, dg);
      Chain(a[2] * (dsr * xr + sr * dxr), a[2] * (dsr * yr + sr * dyr), jr,
            dg + 2);
      Chain(gr[0], gr[1], match.right_normalized_from_pixel_focal, extra);
      dg[2] += extra[0];
      dg[3] += extra[1];
      jacobian_focal[1] = derivative(dbr.dot(a), dg);
    }
  }
  return true;
}

}  // namespace

SampsonCoplanarityCostFunction::SampsonCoplanarityCostFunction(
    const Eigen::Matrix3d& essential,
    std::vector<PreparedCorrespondence> matches, SampsonParameters parameters,
    RobustLoss loss, double loss_scale_px)
    : essential_(essential),
      matches_(std::move(matches)),
      parameters_(parameters),
      loss_(loss),
      loss_scale_px_(loss_scale_px) {
  set_num_residuals(static_cast<int>(matches_.size()));
  mutable_parameter_block_sizes()->push_back(1);
  if (parameters != SampsonParameters::kIndex) {
    mutable_parameter_block_sizes()->push_back(3);
  }
  if (parameters == SampsonParameters::kIndexRotationFocal) {
    mutable_parameter_block_sizes()->push_back(2);
  }
}

bool SampsonCoplanarityCostFunction::Evaluate(double const* const* parameters,
                                              double* residuals,
                                              double** jacobians) const {
  const double n = parameters[0][0];
  const bool with_rotation = parameters_ != SampsonParameters::kIndex;
  const bool with_focal = parameters_ == SampsonParameters::kIndexRotationFocal;
  const RotatedEssential* rotated =
      with_rotation ? &RotatedEssentialOf(essential_, parameters[1]) : nullptr;
  const Eigen::Matrix3d& m = with_rotation ? rotated->m : essential_;
  const Eigen::Matrix3d* dm = with_rotation ? rotated->dm : nullptr;
  const double* focal = with_focal ? parameters[2] : nullptr;
  double* jacobian_n = jacobians != nullptr ? jacobians[0] : nullptr;
  double* jacobian_rotation =
      jacobians != nullptr && with_rotation ? jacobians[1] : nullptr;
  double* jacobian_focal =
      jacobians != nullptr && with_focal ? jacobians[2] : nullptr;
  for (size_t i = 0; i < matches_.size(); ++i) {
    double* row_rotation =
        jacobian_rotation != nullptr ? jacobian_rotation + 3 * i : nullptr;
    double* row_focal =
        jacobian_focal != nullptr ? jacobian_focal + 2 * i : nullptr;
    double* row_n = jacobian_n != nullptr ? jacobian_n + i : nullptr;
    if (!EvaluateMatch(m, dm, matches_[i], n, focal, residuals + i, row_n,
                       row_rotation, row_focal)) {
      return false;
    }
    if (loss_ == RobustLoss::kNone) continue;
    double root = 0.0;
    double slope = 0.0;
    RobustLossRoot(loss_, loss_scale_px_, residuals[i], &root, &slope);
    residuals[i] = root;
    if (row_n != nullptr) *row_n *= slope;
    if (row_rotation != nullptr) {
      for (int k = 0; k < 3; ++k) row_rotation[k] *= slope;
    }
    if (row_focal != nullptr) {
      for (int k = 0; k < 2; ++k) row_focal[k] *= slope;
    }
  }
  return true;
}

}  // namespace rcm
