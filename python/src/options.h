// Keyword options -> the library's option structs. Names are the C++
// fields' (snake_case already); an unknown name is a TypeError, a value of
// the wrong type a TypeError, a value the struct's Check() refuses a
// ValueError, each one line.
#ifndef RCM_PYTHON_SRC_OPTIONS_H_
#define RCM_PYTHON_SRC_OPTIONS_H_

#include <pybind11/pybind11.h>

#include <functional>
#include <string>
#include <vector>

namespace rcm {
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

// StereoFrontEndOptions from keywords, nested fields flattened with their
// prefix (frontend.cc); Check()ed.
StereoFrontEndOptions FrontEndOptionsFrom(const pybind11::dict& kwargs,
                                          const std::string& function);

// {name: current value} of the fields.
pybind11::dict OptionValues(const std::vector<OptionField>& fields);

}  // namespace rcm::python

#endif  // RCM_PYTHON_SRC_OPTIONS_H_
