// The Sampson coplanarity residual of many matches at one n, with its
// derivative in n: SampsonCoplanarityResidual<ceres::Jet<double, 1>>
// (sampson_coplanarity_error.h, no rotation correction) regrouped so that
// what does not depend on n is computed once per match, and what does is
// evaluated for all matches at once in Eigen's vectorized arrays. It is
// what LocusCostFunction::AddMatches evaluates kNumNodes = 577 times per
// match; the results agree with the Jet form to rounding
// (sampson_residual_batch_test.cc).
//
// With b_l = (x_l, y_l, m_l), b_r = (x_r, y_r, m_r), m = sqrt(n^2 + (n^2 - 1)
// r^2) (eq. 5), the coplanarity e = b_r^T E b_l is bilinear in (m_l, m_r):
//
//   e = a0 + a1 m_l + a2 m_r + a3 m_l m_r,
//   a0 = sum_{i,j<2} x_r,i E_ij x_l,j,  a1 = x_r E_02 + y_r E_12,
//   a2 = E_20 x_l + E_21 y_l,           a3 = E_22,
//
// so de/dm_l = f_l = a1 + a3 m_r and de/dm_r = f_r = a2 + a3 m_l. With
// dm/d(x, y) = s (x, y), s = (n^2 - 1) / m, each of the four pixel
// derivatives of e is affine in the other camera's m plus t = f s times a
// per-match weight:
//
//   de/du_l = L0 + L1 m_r + t_l W_l,   t_l = f_l s_l,
//   L0 = (E^T (x_r, y_r, 0))_{0,1} . J_l[:, u],  L1 = E_{2,0:1} . J_l[:, u],
//   W_l = (x_l, y_l) . J_l[:, u]          (likewise v_l, and u_r, v_r with
//                                          E b_l's terms and J_r),
//
// J the inverse lens Jacobian d(x, y)/d(u, v). Then
//
//   r = e / |de/dp|,   dr/dn = (de/dn - r S / |de/dp|) / |de/dp|,
//   S = sum_k (de/dp_k) d(de/dp_k)/dn,
//   dm/dn = n (1 + r^2) / m,   ds/dn = (2 n - s dm/dn) / m.
//
// Per match and n: 3 square roots and 3 divisions against the Jet form's 3
// and 6, and no 3x3 products; SSE2 does two matches per instruction.
// Where the residual is undefined (|de/dp| = 0, at an epipole) r or dr/dn
// is not finite, as the Jet form's failure.
#ifndef RCM_ESTIMATION_SAMPSON_RESIDUAL_BATCH_H_
#define RCM_ESTIMATION_SAMPSON_RESIDUAL_BATCH_H_

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "rcm/estimation/prepared_correspondence.h"

namespace rcm {

class SampsonResidualBatch {
 public:
  // The n-free terms of every match (header), for essential E.
  SampsonResidualBatch(const Eigen::Matrix3d& essential,
                       const std::vector<PreparedCorrespondence>& matches);

  int64_t size() const { return static_cast<int64_t>(a0_.size()); }

  // Scratch arrays of Evaluate, one per thread; sized at first use, reused
  // without allocation after.
  struct Workspace {
    Eigen::ArrayXd ml, mr, iml, imr, dml, dmr, sl, sr, dsl, dsr, fl, fr, tl, tr,
        dtl, dtr, gul, gvl, gur, gvr, g2, s;
  };

  // r_i(n) and dr_i/dn at n in [1, 2] for every match i into `residual`
  // and `derivative` (resized to size()); not finite where undefined.
  void Evaluate(double n, Workspace* workspace, Eigen::ArrayXd* residual,
                Eigen::ArrayXd* derivative) const;

 private:
  // Per match: r^2 of each camera, e's coefficients, and for the four
  // pixel derivatives (u_l, v_l, u_r, v_r) their constant, their factor of
  // the other camera's m, and the weight of t.
  Eigen::ArrayXd rl2_, rr2_, a0_, a1_, a2_, a3_;
  Eigen::ArrayXd lu0_, lu1_, wul_, lv0_, lv1_, wvl_;
  Eigen::ArrayXd ru0_, ru1_, wur_, rv0_, rv1_, wvr_;
};

}  // namespace rcm

#endif  // RCM_ESTIMATION_SAMPSON_RESIDUAL_BATCH_H_
