// How the bindings turn the library's Status errors into Python exceptions.
//
// Every failure carries the library's one-line message unchanged:
//   ValueError  bad values (the default);
//   OSError     a file that cannot be read or written: FileNotFoundError
//               when it does not exist, PermissionError when it is not
//               readable, OSError otherwise (see ThrowFileError).
#ifndef RCM_PYTHON_SRC_ERRORS_H_
#define RCM_PYTHON_SRC_ERRORS_H_

#include <pybind11/pybind11.h>

#include <string>
#include <utility>

#include "rcm/util/status.h"

namespace rcm::python {

// Raises ValueError with `message` (one line).
[[noreturn]] void ThrowValueError(const std::string& message);
// Raises TypeError with `message` (one line).
[[noreturn]] void ThrowTypeError(const std::string& message);

// Raises ValueError with the status's message when it is an error.
void ThrowIfError(const Status& status);

// The value, or ValueError with the message.
template <typename T>
T ValueOrThrow(StatusOr<T> status_or) {
  if (!status_or.ok()) ThrowValueError(status_or.status().message());
  return std::move(status_or).value();
}

// A reader's failure on `path`: FileNotFoundError when the file does not
// exist, PermissionError when it cannot be opened for reading, OSError when
// it is not a regular file; otherwise (the file is there and readable, its
// contents are wrong) ValueError. The message is the library's.
[[noreturn]] void ThrowReadError(const std::string& path,
                                 const std::string& message);
// A writer's failure: always OSError (the library's writers fail only on
// the file system), with the library's message.
[[noreturn]] void ThrowWriteError(const std::string& message);

template <typename T>
T ReadOrThrow(const std::string& path, StatusOr<T> status_or) {
  if (!status_or.ok()) ThrowReadError(path, status_or.status().message());
  return std::move(status_or).value();
}

}  // namespace rcm::python

#endif  // RCM_PYTHON_SRC_ERRORS_H_
