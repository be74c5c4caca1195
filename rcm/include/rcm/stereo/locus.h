// Locus of a correspondence for the ideal rectified pair (paper Sec. III-C).
//
// Eq. 15: yl / m_l = yr / m_r = S (normalized coordinates, each camera's
// own focal). Eq. 16: the right match of (xl, yl) lies on the hyperbola
//
//   h(xr, yr) = (n^2 - 1) xr^2 + (n^2 - 1 - 1/S^2) yr^2 + n^2 = 0,
//
// the epipolar line yr = yl bent by refraction (n = 1 gives the line).
// Multiplying by yl^2 removes the pole at yl = 0:
//
//   yl^2 h = yl^2 (n^2 + (n^2 - 1) xr^2) - yr^2 (n^2 + (n^2 - 1) xl^2),
//
// so yr = yl sqrt((n^2 + (n^2 - 1) xr^2) / (n^2 + (n^2 - 1) xl^2)): one
// branch, through (xl, yl) itself (the match of a point at infinity).
#ifndef RCM_STEREO_LOCUS_H_
#define RCM_STEREO_LOCUS_H_

namespace rcm {

class RectifiedLocus {
 public:
  // The locus of the left point (xl, yl) for refractive index n.
  RectifiedLocus(double n, double xl, double yl);

  // S of eq. 15 (0 when yl = 0).
  double S() const;
  // h of eq. 16 (defined for yl != 0; infinite otherwise).
  double Hyperbola(double xr, double yr) const;
  // yl^2 h: the same locus without the pole at yl = 0.
  double Residual(double xr, double yr) const;
  // The yr on the locus at abscissa xr (same sign as yl).
  double RightY(double xr) const;

 private:
  double n2_;
  double xl_;
  double yl_;
};

}  // namespace rcm

#endif  // RCM_STEREO_LOCUS_H_
