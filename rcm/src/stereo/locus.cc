#include "rcm/stereo/locus.h"

#include <cmath>
#include <limits>

#include "rcm/camera/refractive_model.h"

namespace rcm {

RectifiedLocus::RectifiedLocus(double n, double xl, double yl)
    : n2_(n * n), xl_(xl), yl_(yl) {}

double RectifiedLocus::S() const {
  return yl_ / FlatPortRefraction::RadialFactor(std::sqrt(n2_),
                                                xl_ * xl_ + yl_ * yl_);
}

double RectifiedLocus::Hyperbola(double xr, double yr) const {
  if (yl_ == 0.0) return std::numeric_limits<double>::infinity();
  const double s = S();
  return (n2_ - 1.0) * xr * xr + (n2_ - 1.0 - 1.0 / (s * s)) * yr * yr + n2_;
}

double RectifiedLocus::Residual(double xr, double yr) const {
  return yl_ * yl_ * (n2_ + (n2_ - 1.0) * xr * xr) -
         yr * yr * (n2_ + (n2_ - 1.0) * xl_ * xl_);
}

double RectifiedLocus::RightY(double xr) const {
  return yl_ * std::sqrt((n2_ + (n2_ - 1.0) * xr * xr) /
                         (n2_ + (n2_ - 1.0) * xl_ * xl_));
}

}  // namespace rcm
