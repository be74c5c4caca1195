// Helpers for the tests of the file readers: breaking one spot of a valid
// input, and the error message a reader returns for it.
#ifndef RCM_TESTS_SUPPORT_READER_INPUTS_H_
#define RCM_TESTS_SUPPORT_READER_INPUTS_H_

#include <gtest/gtest.h>

#include <string>

#include "rcm/util/status.h"

namespace rcm::test {

// `text` with its only occurrence of `from` replaced by `to`. Fails the
// test (and returns `text` unchanged) when `from` does not occur exactly
// once, so that an edit never lands somewhere unintended.
inline std::string ReplaceOnce(const std::string& text, const std::string& from,
                               const std::string& to) {
  const size_t position = text.find(from);
  if (position == std::string::npos ||
      text.find(from, position + 1) != std::string::npos) {
    ADD_FAILURE() << "'" << from << "' does not occur exactly once";
    return text;
  }
  std::string result = text;
  result.replace(position, from.size(), to);
  return result;
}

// The error message of `result`, or "" when it holds a value.
template <typename T>
std::string ErrorMessage(const StatusOr<T>& result) {
  return result.ok() ? std::string() : result.status().message();
}

}  // namespace rcm::test

#endif  // RCM_TESTS_SUPPORT_READER_INPUTS_H_
