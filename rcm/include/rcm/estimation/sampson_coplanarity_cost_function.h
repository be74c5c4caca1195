// The Sampson coplanarity residual r(n, delta [, e_l, e_r]) of
// sampson_coplanarity_error.h (the estimator of record's residual, with
// cam1's rotation correction delta and optionally the focal scales) as a
// ceres::CostFunction with its Jacobian written out, for the batch
// refinement's solves: the same residual, and the derivatives that
// ceres::AutoDiffCostFunction<SampsonCoplanarityError, 1, 1, 3[, 2]> takes
// with Jet<double, 6>, to rounding (sampson_coplanarity_cost_function_test.cc
// compares the two). Autodiff carries six derivatives through every
// operation, two angle-axis rotations (with their sines and cosines)
// included, for each match; here the rotated essential matrix and its three
// derivatives are made once per rotation and thread, and each match costs
// two 3x3 products and its own terms.
//
// With M = R(delta) E, b_l = (x_l, y_l, m_l), b_r = (x_r, y_r, m_r),
// m = sqrt(n^2 + (n^2 - 1) rho^2), rho^2 = x^2 + y^2 (eq. 5), s = (n^2 - 1) /
// m:
//
//   a = M b_l,   c = M^T b_r,   e = b_r . a,
//   g_l = (c_0 + c_2 s_l x_l,  c_1 + c_2 s_l y_l)   (de/d(x_l, y_l)),
//   g_r = (a_0 + a_2 s_r x_r,  a_1 + a_2 s_r y_r)   (de/d(x_r, y_r)),
//   G = (g_l J_l, g_r J_r)    (de/dp; J = d(x, y)/d(u, v), 2x2 row-major),
//   r = e / |G|,
//
// and for any parameter q, with e' = de/dq and G' = dG/dq,
//
//   dr/dq = (e' - r (G . G') / |G|) / |G|.
//
// The parameters enter as follows (the focal scales e to first order, as
// in sampson_coplanarity_error.h: (x, y) = (x, y)_0 + e d, J = J_0 + e J_e):
//
//   n:        m' = n (1 + rho^2) / m,  s' = (2 n - s m') / m,
//             a' = m_l' M_{:,2},  c' = m_r' M_{2,:},  e' = m_r' a_2 + m_l' c_2;
//   delta_k:  M_k = dR/d(delta_k) E,  a' = M_k b_l,  c' = M_k^T b_r,
//             e' = b_r . a';
//   e_l:      (x_l, y_l)' = d_l,  m_l' = (n^2 - 1) (x_l, y_l) . d_l / m_l,
//             s_l' = -s_l m_l' / m_l,  a' = M b_l',  c' = 0,  e' = c . b_l',
//             and J_l' = J_le;
//   e_r:      the same with the cameras' roles exchanged (c' = M^T b_r',
//             a' = 0, e' = a . b_r', J_r' = J_re);
//
// g' follows by the product rule from a', c', s' and (x, y)'.
//
// One block may hold many matches (K residuals): Ceres' work per residual
// block (its scratch, the checks of every value, the Jacobian's copy, the
// loss) costs more than this residual itself, so the refinement gives it
// blocks of kSampsonBlockMatches. A robust loss then cannot be Ceres' (it
// applies to the whole block's squared norm): each residual is taken
// through the loss's square root instead (RobustLossRoot,
// refinement_options.h),
//
//   r~ = sign(r) sqrt(rho(r^2)),   dr~/dq = psi'(r) dr/dq,
//
// whose sum of squares is the robust cost Ceres would minimize, so the
// solution and the cost reported are the same; only the Gauss-Newton
// model of the steps toward it differs from Ceres' corrected one.
#ifndef RCM_ESTIMATION_SAMPSON_COPLANARITY_COST_FUNCTION_H_
#define RCM_ESTIMATION_SAMPSON_COPLANARITY_COST_FUNCTION_H_

#include <ceres/cost_function.h>

#include <Eigen/Core>
#include <utility>
#include <vector>

#include "rcm/estimation/prepared_correspondence.h"
#include "rcm/estimation/refinement_options.h"

namespace rcm {

// The matches per block of the batch refinement's problems: enough that
// Ceres' work per block is small beside the residuals' (~80 ns each), few
// enough that a frame's 200 matches still split between two threads.
constexpr int kSampsonBlockMatches = 64;

// The parameter blocks of the cost: n (1), then the rotation correction
// delta (angle-axis in cam1's frame, 3), then the focal scales (e_l, e_r)
// (2).
enum class SampsonParameters { kIndex, kIndexRotation, kIndexRotationFocal };

// One residual per match, in the order given, through `loss` with scale
// `loss_scale_px` (kNone: the residual itself). Evaluate returns false
// where a residual is undefined (|G| = 0), as the autodiff form does; a
// block held constant by the problem gets no Jacobian.
class SampsonCoplanarityCostFunction : public ceres::CostFunction {
 public:
  SampsonCoplanarityCostFunction(const Eigen::Matrix3d& essential,
                                 std::vector<PreparedCorrespondence> matches,
                                 SampsonParameters parameters,
                                 RobustLoss loss = RobustLoss::kNone,
                                 double loss_scale_px = 1.0);

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

  // One match, blocks n and delta [and the focal scales], no loss: the
  // form that ceres::AutoDiffCostFunction<SampsonCoplanarityError, 1, 1, 3
  // [, 2]> equals.
  static ceres::CostFunction* Create(const Eigen::Matrix3d& essential,
                                     const PreparedCorrespondence& match,
                                     bool with_focal) {
    return new SampsonCoplanarityCostFunction(
        essential, {match},
        with_focal ? SampsonParameters::kIndexRotationFocal
                   : SampsonParameters::kIndexRotation);
  }
  // A block of matches.
  static ceres::CostFunction* Create(
      const Eigen::Matrix3d& essential,
      std::vector<PreparedCorrespondence> matches, SampsonParameters parameters,
      RobustLoss loss, double loss_scale_px) {
    return new SampsonCoplanarityCostFunction(essential, std::move(matches),
                                              parameters, loss, loss_scale_px);
  }

 private:
  const Eigen::Matrix3d essential_;
  const std::vector<PreparedCorrespondence> matches_;
  const SampsonParameters parameters_;
  const RobustLoss loss_;
  const double loss_scale_px_;
};

}  // namespace rcm

#endif  // RCM_ESTIMATION_SAMPSON_COPLANARITY_COST_FUNCTION_H_
