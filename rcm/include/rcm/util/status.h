// Status and StatusOr: how the library reports an expected failure (bad
// file, malformed value, degenerate geometry) together with one human
// readable line saying what went wrong. Programmer errors use CHECK instead.
//
// The interface follows absl::Status / absl::StatusOr closely enough that a
// later switch is mechanical; the project does not depend on Abseil for two
// small classes.
#ifndef RCM_UTIL_STATUS_H_
#define RCM_UTIL_STATUS_H_

#include <glog/logging.h>

#include <string>
#include <utility>
#include <variant>

namespace rcm {

class [[nodiscard]] Status {
 public:
  // An OK status.
  Status() = default;
  static Status Ok() { return Status(); }
  // A failure. The message is a single line without a trailing period, e.g.
  // "rig.yaml: cam1.intrinsics: expected 4 numbers, got 3".
  static Status Error(std::string message) {
    CHECK(!message.empty()) << "an error status needs a message";
    Status status;
    status.message_ = std::move(message);
    return status;
  }

  bool ok() const { return message_.empty(); }
  const std::string& message() const { return message_; }

  // Returns a copy whose message is "context: message" (no-op when OK).
  Status WithContext(const std::string& context) const {
    if (ok()) return *this;
    return Error(context + ": " + message_);
  }

 private:
  std::string message_;
};

template <typename T>
class [[nodiscard]] StatusOr {
 public:
  // NOLINTNEXTLINE(google-explicit-constructor): mirrors absl::StatusOr.
  StatusOr(T value) : data_(std::move(value)) {}
  // NOLINTNEXTLINE(google-explicit-constructor)
  StatusOr(Status status) : data_(std::move(status)) {
    CHECK(!std::get<Status>(data_).ok())
        << "StatusOr must not be constructed from an OK status";
  }

  bool ok() const { return std::holds_alternative<T>(data_); }
  Status status() const {
    return ok() ? Status::Ok() : std::get<Status>(data_);
  }

  const T& value() const& {
    CHECK(ok()) << "value() of a failed StatusOr: " << status().message();
    return std::get<T>(data_);
  }
  T& value() & {
    CHECK(ok()) << "value() of a failed StatusOr: " << status().message();
    return std::get<T>(data_);
  }
  // By value, not T&&: `for (x : Make().value())` must not dangle.
  T value() && {
    CHECK(ok()) << "value() of a failed StatusOr: " << status().message();
    return std::get<T>(std::move(data_));
  }
  const T& operator*() const& { return value(); }
  T& operator*() & { return value(); }
  const T* operator->() const { return &value(); }
  T* operator->() { return &value(); }

 private:
  std::variant<T, Status> data_;
};

}  // namespace rcm

// Returns from the enclosing function when `expr` (a Status) is an error.
#define RCM_RETURN_IF_ERROR(expr)              \
  do {                                         \
    ::rcm::Status rcm_status_ = (expr);        \
    if (!rcm_status_.ok()) return rcm_status_; \
  } while (false)

#endif  // RCM_UTIL_STATUS_H_
