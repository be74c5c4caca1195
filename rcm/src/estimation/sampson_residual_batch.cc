#include "rcm/estimation/sampson_residual_batch.h"

namespace rcm {

SampsonResidualBatch::SampsonResidualBatch(
    const Eigen::Matrix3d& essential,
    const std::vector<PreparedCorrespondence>& matches) {
  const Eigen::Index count = static_cast<Eigen::Index>(matches.size());
  for (Eigen::ArrayXd* a :
       {&rl2_, &rr2_, &a0_, &a1_, &a2_, &a3_, &lu0_, &lu1_, &wul_, &lv0_, &lv1_,
        &wvl_, &ru0_, &ru1_, &wur_, &rv0_, &rv1_, &wvr_}) {
    a->resize(count);
  }
  const Eigen::Matrix3d& e = essential;
  // (a, b) . J[:, column]: a row vector on d(x, y)/du (column 0) or /dv (1).
  const auto along = [](int column, double a, double b, const double* j) {
    return a * j[column] + b * j[2 + column];
  };
  for (Eigen::Index i = 0; i < count; ++i) {
    const PreparedCorrespondence& match = matches[i];
    const double xl = match.left_normalized[0];
    const double yl = match.left_normalized[1];
    const double xr = match.right_normalized[0];
    const double yr = match.right_normalized[1];
    const double* jl = match.left_normalized_from_pixel;
    const double* jr = match.right_normalized_from_pixel;
    rl2_[i] = xl * xl + yl * yl;
    rr2_[i] = xr * xr + yr * yr;
    // E b_l = el + E(:, 2) m_l and E^T b_r = er + E(2, :) m_r.
    const double el0 = e(0, 0) * xl + e(0, 1) * yl;
    const double el1 = e(1, 0) * xl + e(1, 1) * yl;
    const double er0 = e(0, 0) * xr + e(1, 0) * yr;
    const double er1 = e(0, 1) * xr + e(1, 1) * yr;
    a0_[i] = xr * el0 + yr * el1;
    a1_[i] = e(0, 2) * xr + e(1, 2) * yr;
    a2_[i] = e(2, 0) * xl + e(2, 1) * yl;
    a3_[i] = e(2, 2);
    // The left pixel: (E^T b_r)_{0,1} . J_l[:, u] and (x_l, y_l) . J_l[:, u].
    lu0_[i] = along(0, er0, er1, jl);
    lu1_[i] = along(0, e(2, 0), e(2, 1), jl);
    wul_[i] = along(0, xl, yl, jl);
    lv0_[i] = along(1, er0, er1, jl);
    lv1_[i] = along(1, e(2, 0), e(2, 1), jl);
    wvl_[i] = along(1, xl, yl, jl);
    // The right pixel: (E b_l)_{0,1} . J_r[:, u] and (x_r, y_r) . J_r[:, u].
    ru0_[i] = along(0, el0, el1, jr);
    ru1_[i] = along(0, e(0, 2), e(1, 2), jr);
    wur_[i] = along(0, xr, yr, jr);
    rv0_[i] = along(1, el0, el1, jr);
    rv1_[i] = along(1, e(0, 2), e(1, 2), jr);
    wvr_[i] = along(1, xr, yr, jr);
  }
}

void SampsonResidualBatch::Evaluate(double n, Workspace* w,
                                    Eigen::ArrayXd* residual,
                                    Eigen::ArrayXd* derivative) const {
  const double n2 = n * n;
  const double excess = n2 - 1.0;
  // m, dm/dn, s = (n^2 - 1) / m and ds/dn of each camera (the header).
  // One division per camera: 1 / m.
  w->ml = (n2 + excess * rl2_).sqrt();
  w->mr = (n2 + excess * rr2_).sqrt();
  w->iml = w->ml.inverse();
  w->imr = w->mr.inverse();
  w->dml = n * (1.0 + rl2_) * w->iml;
  w->dmr = n * (1.0 + rr2_) * w->imr;
  w->sl = excess * w->iml;
  w->sr = excess * w->imr;
  w->dsl = (2.0 * n - w->sl * w->dml) * w->iml;
  w->dsr = (2.0 * n - w->sr * w->dmr) * w->imr;
  // de/dm of each camera, t = f s and dt/dn.
  w->fl = a1_ + a3_ * w->mr;
  w->fr = a2_ + a3_ * w->ml;
  w->tl = w->fl * w->sl;
  w->tr = w->fr * w->sr;
  w->dtl = a3_ * w->dmr * w->sl + w->fl * w->dsl;
  w->dtr = a3_ * w->dml * w->sr + w->fr * w->dsr;
  // de/dp for the four pixel coordinates, then |de/dp|^2 and
  // S = sum (de/dp_k) d(de/dp_k)/dn.
  w->gul = lu0_ + lu1_ * w->mr + w->tl * wul_;
  w->gvl = lv0_ + lv1_ * w->mr + w->tl * wvl_;
  w->gur = ru0_ + ru1_ * w->ml + w->tr * wur_;
  w->gvr = rv0_ + rv1_ * w->ml + w->tr * wvr_;
  w->g2 = w->gul.square() + w->gvl.square() + w->gur.square() +
          w->gvr.square();
  w->s = w->gul * (lu1_ * w->dmr + w->dtl * wul_) +
         w->gvl * (lv1_ * w->dmr + w->dtl * wvl_) +
         w->gur * (ru1_ * w->dml + w->dtr * wur_) +
         w->gvr * (rv1_ * w->dml + w->dtr * wvr_);
  // 1 / |de/dp| in g2; then r = e / |de/dp| and dr/dn.
  w->g2 = w->g2.rsqrt();
  *residual = (a0_ + a1_ * w->ml + w->fr * w->mr) * w->g2;
  *derivative =
      (w->fl * w->dml + w->fr * w->dmr - *residual * w->g2 * w->s) * w->g2;
}

}  // namespace rcm
