#include "rcm/estimation/medium_prior.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>

#include "rcm/util/number_format.h"

namespace rcm {
namespace {

// Quan and Fry (1995), eq. 2.
constexpr double kN0 = 1.31405;
constexpr double kN1 = 1.779e-4;
constexpr double kN2 = -1.05e-6;
constexpr double kN3 = 1.6e-8;
constexpr double kN4 = -2.02e-6;
constexpr double kN5 = 15.868;
constexpr double kN6 = 0.01155;
constexpr double kN7 = -0.00423;
constexpr double kN8 = -4382.0;
constexpr double kN9 = 1.1455e6;

// A box of conditions (header): its range of n at the corners.
struct Conditions {
  double min_salinity, max_salinity;
  double min_temperature, max_temperature;
  double min_wavelength, max_wavelength;
};

MediumPrior PriorOfBox(const std::string& name, const Conditions& box) {
  double low = std::numeric_limits<double>::infinity();
  double high = -low;
  for (const double s : {box.min_salinity, box.max_salinity}) {
    for (const double t : {box.min_temperature, box.max_temperature}) {
      for (const double l : {box.min_wavelength, box.max_wavelength}) {
        const double n = WaterRefractiveIndex(s, t, l).value();
        low = std::min(low, n);
        high = std::max(high, n);
      }
    }
  }
  MediumPrior prior;
  prior.name = name;
  prior.min_n = low;
  prior.max_n = high;
  prior.n = 0.5 * (low + high);
  prior.sigma = (high - low) / std::sqrt(12.0);
  return prior;
}

constexpr Conditions kFresh{0.0, 1.0, 0.0, 30.0, 450.0, 650.0};
constexpr Conditions kSea{30.0, 35.0, 0.0, 30.0, 450.0, 650.0};

std::string ConditionsText(const Conditions& box) {
  return FormatFixed(box.min_salinity, 0) + "-" +
         FormatFixed(box.max_salinity, 0) + " g/kg, " +
         FormatFixed(box.min_temperature, 0) + "-" +
         FormatFixed(box.max_temperature, 0) + " C, " +
         FormatFixed(box.min_wavelength, 0) + "-" +
         FormatFixed(box.max_wavelength, 0) + " nm";
}

}  // namespace

StatusOr<double> WaterRefractiveIndex(double salinity_g_per_kg,
                                      double temperature_c,
                                      double wavelength_nm) {
  const double s = salinity_g_per_kg;
  const double t = temperature_c;
  const double l = wavelength_nm;
  if (!(s >= 0.0 && s <= 35.0) || !(t >= 0.0 && t <= 30.0) ||
      !(l >= 400.0 && l <= 700.0)) {
    return Status::Error(
        "the index of water is known for salinity 0-35 g/kg, temperature "
        "0-30 C and wavelength 400-700 nm (Quan and Fry 1995), got " +
        FormatFixed(s, 3) + " g/kg, " + FormatFixed(t, 3) + " C, " +
        FormatFixed(l, 3) + " nm");
  }
  return kN0 + (kN1 + kN2 * t + kN3 * t * t) * s + kN4 * t * t +
         (kN5 + kN6 * s + kN7 * t) / l + kN8 / (l * l) + kN9 / (l * l * l);
}

std::string MediumPrior::Describe() const {
  std::string text =
      name + " (n " + FormatFixed(min_n, 4) + "-" + FormatFixed(max_n, 4);
  if (name == "fresh water") return text + ": " + ConditionsText(kFresh) + ")";
  if (name == "sea water") return text + ": " + ConditionsText(kSea) + ")";
  return text + ")";
}

MediumPrior FreshWater() { return PriorOfBox("fresh water", kFresh); }
MediumPrior SeaWater() { return PriorOfBox("sea water", kSea); }

StatusOr<MediumPrior> ParseMediumPrior(const std::string& text) {
  if (text == "fresh") return FreshWater();
  if (text == "sea") return SeaWater();
  const std::string usage =
      "expected fresh, sea or N:SIGMA (e.g. 1.340:0.002), got '" + text + "'";
  const size_t colon = text.find(':');
  if (colon == std::string::npos || colon == 0 || colon + 1 == text.size()) {
    return Status::Error(usage);
  }
  const std::string n_text = text.substr(0, colon);
  const std::string sigma_text = text.substr(colon + 1);
  char* end = nullptr;
  const double n = std::strtod(n_text.c_str(), &end);
  if (end != n_text.c_str() + n_text.size()) return Status::Error(usage);
  const double sigma = std::strtod(sigma_text.c_str(), &end);
  if (end != sigma_text.c_str() + sigma_text.size()) {
    return Status::Error(usage);
  }
  if (!(n >= 1.0 && n < 2.0)) {
    return Status::Error("the medium's n must lie in [1, 2), got " + n_text);
  }
  if (!(sigma > 0.0 && sigma < 1.0)) {
    return Status::Error("the medium's SIGMA must lie in (0, 1), got " +
                         sigma_text);
  }
  MediumPrior prior;
  prior.name = "n " + FormatFixed(n, 4) + " +- " + FormatFixed(sigma, 4);
  prior.n = n;
  prior.sigma = sigma;
  prior.min_n = n - 3.0 * sigma;
  prior.max_n = n + 3.0 * sigma;
  return prior;
}

MediumCheck CheckAgainstMedium(double n, double sigma_n,
                               const MediumPrior& medium) {
  MediumCheck check;
  const double sigma = std::hypot(sigma_n, medium.sigma);
  check.z = std::abs(n - medium.n) / sigma;
  check.contradicts = check.z > kMediumContradictionZ;
  if (check.contradicts) {
    check.message = "n " + FormatFixed(n, 4) + " +- " +
                    FormatFixed(sigma_n, 4) + " contradicts " +
                    medium.Describe() + " by " + FormatFixed(check.z, 1) +
                    " sigma";
  }
  return check;
}

}  // namespace rcm
