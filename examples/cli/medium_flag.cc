#include "medium_flag.h"

DEFINE_string(medium, "",
              "fresh, sea or N:SIGMA: the water the rig dived in, from its "
              "physics (Quan and Fry 1995: fresh 1.3302-1.3404, sea "
              "1.3356-1.3474 over 0-30 C and 450-650 nm; N:SIGMA when the "
              "temperature and salinity are measured). An n that "
              "contradicts it (beyond 3 sigma) is flagged in one line; rcm "
              "estimate --estimator refine also estimates cam1's rotation "
              "since the calibration assuming it, which a narrow field at one "
              "depth cannot separate from n alone. n itself stays the data's");

namespace rcm::cli {

extern const char kMediumFlagSource[] = __FILE__;

StatusOr<std::optional<MediumPrior>> MediumFromFlag() {
  if (FLAGS_medium.empty()) return std::optional<MediumPrior>();
  StatusOr<MediumPrior> medium = ParseMediumPrior(FLAGS_medium);
  if (!medium.ok()) return medium.status().WithContext("--medium");
  return std::optional<MediumPrior>(*medium);
}

nlohmann::json MediumJson(const MediumPrior& medium, const MediumCheck& check) {
  return {{"name", medium.name},
          {"n", medium.n},
          {"sigma", medium.sigma},
          {"range", {medium.min_n, medium.max_n}},
          {"z", check.z},
          {"contradicts", check.contradicts}};
}

}  // namespace rcm::cli
