#include "rcm/estimation/paper_online_estimator.h"

#include <cmath>
#include <limits>
#include <sstream>

#include "rcm/estimation/closed_form.h"

namespace rcm {

Status PaperOnlineEstimatorOptions::Check() const {
  if (!std::isfinite(eta) || eta < 0.0) {
    std::ostringstream message;
    message << "mask threshold eta = " << eta
            << " must be a finite number >= 0";
    return Status::Error(message.str());
  }
  return Status::Ok();
}

bool PassesObservabilityMask(const Eigen::Vector2d& left_normalized,
                             double eta) {
  return std::sqrt(std::abs(left_normalized.x())) *
             std::sqrt(std::abs(left_normalized.y())) >
         eta;
}

PaperOnlineEstimator::PaperOnlineEstimator(
    const StereoRig& rig, const PaperOnlineEstimatorOptions& options)
    : rig_(rig), options_(options) {
  const Status status = options.Check();
  CHECK(status.ok()) << status.message();
}

PaperOnlineEstimator::Contribution PaperOnlineEstimator::Add(
    const StereoCorrespondence& correspondence) {
  Contribution contribution;
  const std::optional<NormalizedCorrespondence> normalized =
      rig_.Normalize(correspondence);
  if (!normalized) {
    ++num_invalid_;
    return contribution;
  }
  if (!PassesObservabilityMask(normalized->left, options_.eta)) {
    contribution.outcome = Outcome::kMasked;
    ++num_masked_;
    return contribution;
  }
  const std::optional<double> n = ClosedFormN(*normalized);
  if (!n) {
    ++num_invalid_;
    return contribution;
  }
  contribution.outcome = Outcome::kUsed;
  contribution.n = *n;
  contribution.weight = normalized->left.norm();

  if (num_used_ == 0) shift_ = *n;
  const double w = contribution.weight;
  const double d = *n - shift_;
  sum_w_ += w;
  sum_w_d_ += w * d;
  sum_w2_ += w * w;
  sum_w2_d_ += w * w * d;
  sum_w2_d2_ += w * w * d * d;
  ++num_used_;
  return contribution;
}

std::optional<PaperOnlineEstimator::Estimate> PaperOnlineEstimator::Current()
    const {
  if (num_used_ == 0) return std::nullopt;
  Estimate estimate;
  estimate.used = num_used_;
  const double mean_d = sum_w_d_ / sum_w_;
  estimate.n = shift_ + mean_d;
  if (num_used_ < 2) {
    estimate.standard_error = std::numeric_limits<double>::quiet_NaN();
    return estimate;
  }
  // sum w^2 (d - mean_d)^2, expanded over the running sums.
  const double spread = std::max(
      0.0, sum_w2_d2_ - 2.0 * mean_d * sum_w2_d_ + mean_d * mean_d * sum_w2_);
  const double correction =
      static_cast<double>(num_used_) / static_cast<double>(num_used_ - 1);
  estimate.standard_error = std::sqrt(correction * spread) / sum_w_;
  return estimate;
}

void PaperOnlineEstimator::Reset() {
  shift_ = 0.0;
  sum_w_ = sum_w_d_ = sum_w2_ = sum_w2_d_ = sum_w2_d2_ = 0.0;
  num_used_ = num_masked_ = num_invalid_ = 0;
}

}  // namespace rcm
