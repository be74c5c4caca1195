// Helpers for code templated on the scalar type (double or ceres::Jet).
#ifndef RCM_UTIL_SCALAR_H_
#define RCM_UTIL_SCALAR_H_

#include <ceres/jet.h>

namespace rcm {

// The value without derivative parts: x for a double, x.a for a Jet (nested
// Jets recurse). Used where an iteration must branch on a plain number.
inline double ScalarPart(double x) { return x; }
template <typename T, int N>
double ScalarPart(const ceres::Jet<T, N>& x) {
  return ScalarPart(x.a);
}

}  // namespace rcm

#endif  // RCM_UTIL_SCALAR_H_
