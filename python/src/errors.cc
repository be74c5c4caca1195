#include "errors.h"

#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>

namespace rcm::python {
namespace {

[[noreturn]] void Raise(PyObject* type, const std::string& message) {
  PyErr_SetString(type, message.c_str());
  throw pybind11::error_already_set();
}

}  // namespace

void ThrowValueError(const std::string& message) {
  Raise(PyExc_ValueError, message);
}

void ThrowTypeError(const std::string& message) {
  Raise(PyExc_TypeError, message);
}

void ThrowIfError(const Status& status) {
  if (!status.ok()) ThrowValueError(status.message());
}

void ThrowReadError(const std::string& path, const std::string& message) {
  struct stat info {};
  if (::stat(path.c_str(), &info) != 0) {
    Raise(errno == ENOENT || errno == ENOTDIR ? PyExc_FileNotFoundError
                                              : PyExc_OSError,
          message);
  }
  if (S_ISDIR(info.st_mode)) Raise(PyExc_IsADirectoryError, message);
  if (::access(path.c_str(), R_OK) != 0) Raise(PyExc_PermissionError, message);
  Raise(PyExc_ValueError, message);
}

void ThrowWriteError(const std::string& message) {
  Raise(PyExc_OSError, message);
}

}  // namespace rcm::python
