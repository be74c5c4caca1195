#include "index_flag.h"

#include <cmath>
#include <sstream>

#include "rcm/camera/refractive_camera.h"

DEFINE_double(n, 1.333, "refractive index of the water, in [1, 2]");

namespace rcm::cli {

extern const char kIndexFlagSource[] = __FILE__;

StatusOr<double> RefractiveIndexFromFlag(bool required) {
  if (required && gflags::GetCommandLineFlagInfoOrDie("n").is_default) {
    return Status::Error(
        "--n is required: the refractive index of the water, e.g. --n 1.333 "
        "(rcm estimate measures it)");
  }
  if (!std::isfinite(FLAGS_n) || FLAGS_n < RefractiveCamera::kMinIndex ||
      FLAGS_n > RefractiveCamera::kMaxIndex) {
    std::ostringstream message;
    message << "--n " << FLAGS_n << " is outside ["
            << RefractiveCamera::kMinIndex << ", "
            << RefractiveCamera::kMaxIndex << "]";
    return Status::Error(message.str());
  }
  return FLAGS_n;
}

}  // namespace rcm::cli
