#include "options.h"

#include <cmath>

#include "errors.h"
#include "rcm/estimation/refinement_options.h"

namespace rcm::python {

namespace py = pybind11;

namespace {

std::string TypeName(const py::handle& value) {
  return py::str(py::type::of(value).attr("__name__")).cast<std::string>();
}

}  // namespace

OptionField BoolOption(const std::string& name, bool* field) {
  return {name,
          [name, field](const py::handle& value) {
            // NumPy bools are accepted; ints are not (a typo-prone 0/1).
            if (!PyBool_Check(value.ptr()) && TypeName(value) != "bool_") {
              ThrowTypeError(name + " must be True or False, got " +
                             TypeName(value));
            }
            *field = value.cast<bool>();
          },
          [field]() { return py::object(py::bool_(*field)); }};
}

OptionField IntOption(const std::string& name, int* field) {
  return {name,
          [name, field](const py::handle& value) {
            if (PyBool_Check(value.ptr()) || !PyIndex_Check(value.ptr())) {
              ThrowTypeError(name + " must be an int, got " + TypeName(value));
            }
            const long long number = PyLong_AsLongLong(value.ptr());
            if (PyErr_Occurred() || number < -2147483647LL ||
                number > 2147483647LL) {
              PyErr_Clear();
              ThrowValueError(name + " is out of range");
            }
            *field = static_cast<int>(number);
          },
          [field]() { return py::object(py::int_(*field)); }};
}

OptionField LossOption(const std::string& name, RobustLoss* field) {
  return {
      name,
      [name, field](const py::handle& value) {
        if (!py::isinstance<py::str>(value)) {
          ThrowTypeError(name + " must be a str ('none', 'huber', 'cauchy')");
        }
        const std::string text = value.cast<std::string>();
        const std::optional<RobustLoss> loss = RobustLossFromName(text);
        if (!loss) {
          ThrowValueError("unknown " + name + " '" + text +
                          "' (available: none, huber, cauchy)");
        }
        *field = *loss;
      },
      [field]() {
        return py::object(py::str(std::string(RobustLossName(*field))));
      }};
}

OptionField DoubleOption(const std::string& name, double* field,
                         bool allow_inf) {
  return {
      name,
      [name, field, allow_inf](const py::handle& value) {
        const bool numeric = PyFloat_Check(value.ptr()) ||
                             PyLong_Check(value.ptr()) ||
                             py::hasattr(value, "__float__");
        if (PyBool_Check(value.ptr()) || PyComplex_Check(value.ptr()) ||
            !numeric || TypeName(value) == "bool_") {
          ThrowTypeError(name + " must be a number, got " + TypeName(value));
        }
        const double number = PyFloat_AsDouble(value.ptr());
        if (PyErr_Occurred()) throw py::error_already_set();
        if (std::isnan(number) || (!allow_inf && std::isinf(number))) {
          ThrowValueError(name + " must be finite, got " +
                          py::str(value).cast<std::string>());
        }
        *field = number;
      },
      [field]() { return py::object(py::float_(*field)); }};
}

void ApplyOptions(const py::dict& kwargs,
                  const std::vector<OptionField>& fields,
                  const std::string& function) {
  for (const auto& [key, value] : kwargs) {
    const std::string name = py::str(key).cast<std::string>();
    const OptionField* field = nullptr;
    for (const OptionField& candidate : fields) {
      if (candidate.name == name) field = &candidate;
    }
    if (field == nullptr) {
      std::string names;
      for (const OptionField& candidate : fields) {
        names += (names.empty() ? "" : ", ") + candidate.name;
      }
      ThrowTypeError(function + "() got an unexpected keyword argument '" +
                     name + "' (options: " + names + ")");
    }
    field->set(value);
  }
}

py::dict OptionValues(const std::vector<OptionField>& fields) {
  py::dict values;
  for (const OptionField& field : fields)
    values[py::str(field.name)] = field.get();
  return values;
}

}  // namespace rcm::python
