// Keyword options -> the library's option structs. Names are the C++
// fields' (snake_case already); an unknown name is a TypeError, a value of
// the wrong type a TypeError, a value the struct's Check() refuses a
// ValueError, each one line.
#ifndef RCM_PYTHON_SRC_OPTIONS_H_
#define RCM_PYTHON_SRC_OPTIONS_H_

#include <pybind11/pybind11.h>

#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "errors.h"

namespace rcm {
enum class RobustLoss;
struct RefinementOptions;
struct StereoFrontEndOptions;
}  // namespace rcm

namespace rcm::python {

// One keyword: its name and how to store a Python value of it.
struct OptionField {
  std::string name;
  std::function<void(const pybind11::handle&)> set;
  std::function<pybind11::object()> get;
};

// Setters of the common kinds, naming the option in their errors.
// A bool (True/False only).
OptionField BoolOption(const std::string& name, bool* field);
// An int (not a bool, not a float).
OptionField IntOption(const std::string& name, int* field);
// A robust loss by its name: 'none', 'huber' or 'cauchy' (TypeError for
// another type, ValueError for another name).
OptionField LossOption(const std::string& name, RobustLoss* field);
// A real number (int or float; inf allowed where `allow_inf`).
OptionField DoubleOption(const std::string& name, double* field,
                         bool allow_inf = false);

// Applies `kwargs` to the fields; `function` names the caller in the
// unknown-keyword TypeError.
void ApplyOptions(const pybind11::dict& kwargs,
                  const std::vector<OptionField>& fields,
                  const std::string& function);
// The keywords of RefinementOptions, named as its fields (estimators.cc).
std::vector<OptionField> RefinementOptionFields(RefinementOptions* options);

// Applies keywords to `options`: `options=` (an rcm.RefinementOptions) as
// the base, then each RefinementOptions keyword (estimators.cc).
void ApplyRefinementOptions(const pybind11::dict& kwargs,
                            RefinementOptions* options,
                            const std::string& function);

// StereoFrontEndOptions from keywords, nested fields flattened with their
// prefix (frontend.cc); Check()ed.
std::vector<OptionField> FrontEndOptionFields(StereoFrontEndOptions* options);
StereoFrontEndOptions FrontEndOptionsFrom(const pybind11::dict& kwargs,
                                          const std::string& function);

// {name: current value} of the fields.
pybind11::dict OptionValues(const std::vector<OptionField>& fields);

// The keyword fields of one options struct.
template <typename Options>
using OptionFields = std::vector<OptionField> (*)(Options*);

// Applies `kwargs` to `options`: `options=` (an instance of the bound class
// `class_name`) as the base, then each field's keyword.
template <typename Options>
void ApplyOptionsWithBase(const pybind11::dict& kwargs, Options* options,
                          OptionFields<Options> fields,
                          const std::string& class_name,
                          const std::string& function) {
  pybind11::dict rest;
  for (const auto& [key, value] : kwargs) {
    if (pybind11::str(key).cast<std::string>() == "options") {
      if (!pybind11::isinstance<Options>(value)) {
        ThrowTypeError(function + "(): options must be an " + class_name);
      }
      *options = value.template cast<Options>();
    } else {
      rest[key] = value;
    }
  }
  ApplyOptions(rest, fields(options), function);
}

// rcm.NAME: the C++ options struct with its defaults; NAME(**keywords), one
// property per field (documented by `docs`), check() (the struct's Check(),
// ValueError), to_dict() (the keywords) and a repr.
template <typename Options>
void BindOptionsClass(
    pybind11::module_& module, const char* name, const char* doc,
    OptionFields<Options> fields,
    const std::vector<std::pair<const char*, const char*>>& docs) {
  namespace py = pybind11;
  const std::string class_name = name;
  py::class_<Options> cls(module, name, doc);
  cls.def(py::init([fields, class_name](const py::kwargs& kwargs) {
       Options options;
       ApplyOptions(kwargs, fields(&options), class_name);
       return options;
     }))
      .def(
          "check", [](const Options& o) { ThrowIfError(o.Check()); },
          "Raises ValueError with the library's message for a value the "
          "C++ Check() refuses.")
      .def(
          "to_dict", [fields](Options& o) { return OptionValues(fields(&o)); },
          "The fields as keywords.")
      .def("__repr__", [fields, class_name](Options& o) {
        return class_name + "(" +
               py::repr(OptionValues(fields(&o))).template cast<std::string>() +
               ")";
      });
  for (const auto& [field_name, field_doc] : docs) {
    const std::string field(field_name);
    cls.def_property(
        field_name,
        [fields, field](Options& o) -> py::object {
          for (const OptionField& f : fields(&o)) {
            if (f.name == field) return f.get();
          }
          return py::none();
        },
        [fields, field](Options& o, const py::object& value) {
          for (const OptionField& f : fields(&o)) {
            if (f.name == field) f.set(value);
          }
        },
        field_doc);
  }
}

}  // namespace rcm::python

#endif  // RCM_PYTHON_SRC_OPTIONS_H_
