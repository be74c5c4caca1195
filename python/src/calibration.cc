#include "bindings.h"

namespace rcm::python {

void BindCalibration(pybind11::module_& /*module*/) {}

}  // namespace rcm::python
