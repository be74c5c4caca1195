#include "rcm/estimation/image_error_field.h"

#include <cmath>
#include <string>

#include "rcm/util/number_format.h"

namespace rcm {

Status ImageErrorField::Check() const {
  const auto error = [](const std::string& what) {
    return Status::Error("image error field: " + what);
  };
  if (image_width <= 0 || image_height <= 0) {
    return error("image size " + std::to_string(image_width) + " x " +
                 std::to_string(image_height) + " is not positive");
  }
  if (cols < 1 || rows < 1) {
    return error("sample grid " + std::to_string(cols) + " x " +
                 std::to_string(rows) + " is empty");
  }
  if (!(std::isfinite(step) && step > 0.0)) {
    return error("step " + FormatDouble(step) + " is not positive and finite");
  }
  if (!origin.allFinite()) {
    return error("origin (" + FormatDouble(origin.x()) + ", " +
                 FormatDouble(origin.y()) + ") is not finite");
  }
  const unsigned long long expected = static_cast<unsigned long long>(cols) *
                                      static_cast<unsigned long long>(rows);
  if (errors.size() != expected) {
    return error(std::to_string(errors.size()) + " errors for a " +
                 std::to_string(cols) + " x " + std::to_string(rows) +
                 " grid, expected " + std::to_string(expected));
  }
  for (size_t i = 0; i < errors.size(); ++i) {
    if (errors[i] && !errors[i]->allFinite()) {
      const size_t c = static_cast<size_t>(cols);
      return error("error (" + FormatDouble(errors[i]->x()) + ", " +
                   FormatDouble(errors[i]->y()) + ") at column " +
                   std::to_string(i % c) + ", row " + std::to_string(i / c) +
                   " is not finite");
    }
  }
  return Status::Ok();
}

}  // namespace rcm
