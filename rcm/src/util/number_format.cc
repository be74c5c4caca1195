#include "rcm/util/number_format.h"

#include <glog/logging.h>

#include <charconv>
#include <cmath>
#include <cstdlib>
#include <sstream>
#include <string_view>
#include <system_error>

namespace rcm {

std::string FormatDouble(double value) {
  if (std::isnan(value)) return "nan";
  if (std::isinf(value)) return value > 0.0 ? "inf" : "-inf";

  // Shortest round-trip digits as "[-]d[.ddd]e(+|-)XX".
  char buffer[64];
  const std::to_chars_result result = std::to_chars(
      buffer, buffer + sizeof(buffer), value, std::chars_format::scientific);
  CHECK(result.ec == std::errc()) << "to_chars failed on " << value;
  const std::string_view text(buffer, result.ptr - buffer);

  const bool negative = text.front() == '-';
  const size_t e_position = text.find('e');
  CHECK_NE(e_position, std::string_view::npos) << text;
  const std::string_view mantissa =
      text.substr(negative ? 1 : 0, e_position - (negative ? 1 : 0));
  std::string digits;  // the significant digits without the point
  for (char c : mantissa) {
    if (c != '.') digits.push_back(c);
  }
  const int exponent =
      std::atoi(std::string(text.substr(e_position + 1)).c_str());
  const int num_digits = static_cast<int>(digits.size());

  std::string out = negative ? "-" : "";
  if (exponent >= -4 && exponent < 16) {
    if (exponent < 0) {
      out += "0.";
      out.append(-exponent - 1, '0');
      out += digits;
    } else if (num_digits <= exponent + 1) {
      out += digits;
      out.append(exponent + 1 - num_digits, '0');
      out += ".0";
    } else {
      out += digits.substr(0, exponent + 1);
      out += '.';
      out += digits.substr(exponent + 1);
    }
    return out;
  }
  out += digits.front();
  if (num_digits > 1) {
    out += '.';
    out += digits.substr(1);
  }
  out += exponent < 0 ? "e-" : "e+";
  const int magnitude = std::abs(exponent);
  if (magnitude < 10) out += '0';
  out += std::to_string(magnitude);
  return out;
}

std::string FormatFixed(double value, int digits) {
  if (!std::isfinite(value)) return "n/a";
  std::ostringstream out;
  out.setf(std::ios::fixed);
  out.precision(digits);
  out << value;
  return out.str();
}

}  // namespace rcm
