// What the physics of the medium says of n, before any image: the index of
// water from its salinity, temperature and the light's wavelength, as a
// prior on n (rcm estimate / rcm calibrate --medium).
//
// Quan and Fry, "Empirical equation for the index of refraction of
// seawater", Applied Optics 34(18), 1995, eq. 2: n relative to air, the
// ratio that Snell's law at an air-backed port needs,
//
//   n(S, T, l) = n0 + (n1 + n2 T + n3 T^2) S + n4 T^2
//              + (n5 + n6 S + n7 T) / l + n8 / l^2 + n9 / l^3
//
// S salinity (g/kg, 0-35), T temperature (deg C, 0-30), l wavelength (nm,
// 400-700), the equation's range of validity; n is increasing in S and
// decreasing in T and l over it, so the extremes of a box of conditions
// are at its corners.
//
// The named media are boxes of conditions a dive does not usually measure:
//
//   fresh: S 0-1 g/kg, T 0-30 C, l 450-650 nm -> n 1.3302-1.3404
//   sea:   S 30-35 g/kg, T 0-30 C, l 450-650 nm -> n 1.3356-1.3474
//
// (450-650 nm: where a colour or monochrome camera's sensitivity lies
// under water). As a prior, a box is n ~ N(mid, (max - min)^2 / 12), the
// mean and variance of a uniform n over its range; "N:SIGMA" is n ~ N(N,
// SIGMA^2) directly (a measured temperature and salinity narrow it).
#ifndef RCM_ESTIMATION_MEDIUM_PRIOR_H_
#define RCM_ESTIMATION_MEDIUM_PRIOR_H_

#include <string>

#include "rcm/util/status.h"

namespace rcm {

// n of water relative to air (header); fails outside the equation's range.
StatusOr<double> WaterRefractiveIndex(double salinity_g_per_kg,
                                      double temperature_c,
                                      double wavelength_nm);

struct MediumPrior {
  std::string name;   // "sea water", "fresh water", "n 1.3400 +- 0.0020"
  double n = 0.0;     // mean
  double sigma = 0.0;  // standard deviation, > 0
  double min_n = 0.0;  // the range it stands for (n -+ 3 sigma for N:SIGMA)
  double max_n = 0.0;

  // One line: "sea water (n 1.3356-1.3474: 30-35 g/kg, 0-30 C, 450-650 nm)".
  std::string Describe() const;
};

MediumPrior FreshWater();
MediumPrior SeaWater();

// "fresh", "sea", or "N:SIGMA" (1 <= N < 2, SIGMA > 0); one line otherwise.
StatusOr<MediumPrior> ParseMediumPrior(const std::string& text);

// An estimate against the medium: z = |n - medium.n| / sqrt(sigma_n^2 +
// medium.sigma^2); it contradicts the medium beyond kMediumContradictionZ
// (3: a 0.3 % tail were both Gaussian and right).
inline constexpr double kMediumContradictionZ = 3.0;
struct MediumCheck {
  double z = 0.0;
  bool contradicts = false;
  // When it contradicts: "n 1.2496 +- 0.0118 contradicts sea water (...):
  // 7.4 sigma".
  std::string message;
};
MediumCheck CheckAgainstMedium(double n, double sigma_n,
                               const MediumPrior& medium);

}  // namespace rcm

#endif  // RCM_ESTIMATION_MEDIUM_PRIOR_H_
