#include "lens_model_flag.h"

#include <optional>

#include "rcm/camera/camera.h"

DEFINE_string(model, "",
              "lens model: radtan, equidistant, rational (OpenCV's 8 "
              "coefficients), ds (double sphere), eucm or none (default: "
              "radtan for calibrate, equidistant for export)");

namespace rcm::cli {

extern const char kLensModelFlagSource[] = __FILE__;

StatusOr<LensModelId> LensModelFromFlag(LensModelId default_model) {
  if (FLAGS_model.empty()) return default_model;
  const std::optional<LensModelId> model = LensModelFromName(FLAGS_model);
  if (!model.has_value()) {
    return Status::Error("unknown --model '" + FLAGS_model +
                         "' (available: " + LensModelNameList() + ")");
  }
  return *model;
}

}  // namespace rcm::cli
