// Golden-section search for the minimum of a unimodal function on
// [low, high]: the bracket shrinks by 0.618 per evaluation until it is
// narrower than `tolerance`; returns its midpoint. Shared by the 1-D fits
// of n (robust_locus_fit.h, locus_cost_function.h).
#ifndef RCM_UTIL_GOLDEN_SECTION_H_
#define RCM_UTIL_GOLDEN_SECTION_H_

#include <cmath>

namespace rcm {

template <typename Cost>
double GoldenSectionMinimize(const Cost& cost, double low, double high,
                             double tolerance) {
  const double ratio = (std::sqrt(5.0) - 1.0) / 2.0;
  double a = high - ratio * (high - low);
  double b = low + ratio * (high - low);
  double cost_a = cost(a);
  double cost_b = cost(b);
  while (high - low > tolerance) {
    if (cost_a <= cost_b) {
      high = b;
      b = a;
      cost_b = cost_a;
      a = high - ratio * (high - low);
      cost_a = cost(a);
    } else {
      low = a;
      a = b;
      cost_a = cost_b;
      b = low + ratio * (high - low);
      cost_b = cost(b);
    }
  }
  return 0.5 * (low + high);
}

}  // namespace rcm

#endif  // RCM_UTIL_GOLDEN_SECTION_H_
