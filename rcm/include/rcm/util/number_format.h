// Number formatting shared by every file rcm writes.
//
// FormatDouble prints a double exactly as Python 3's repr(float) does, so
// that a camchain written by rcm is byte-identical to the one Kalibr
// (Python) would write for the same values, and so that every printed
// value reads back bit-exactly:
//
//   - the digits are the shortest ones that round-trip (std::to_chars);
//   - fixed notation when the decimal exponent of the leading digit is in
//     [-4, 16), with at least one digit after the point:
//     1.0, -0.0, 0.0001, 346.68681661781403, 9999999999999998.0;
//   - scientific notation otherwise, with a signed exponent of at least
//     two digits and no ".0" on a single-digit mantissa:
//     1e-05, 2.365797666527927e-05, 1e+16, 5e-324;
//   - nan, inf, -inf for the non-finite values (the sign of a NaN is
//     dropped, as in Python).
#ifndef RCM_UTIL_NUMBER_FORMAT_H_
#define RCM_UTIL_NUMBER_FORMAT_H_

#include <string>

namespace rcm {

std::string FormatDouble(double value);

// For people rather than files: `digits` decimals in fixed notation
// ("1.33498"), "n/a" when the value is not finite.
std::string FormatFixed(double value, int digits);

}  // namespace rcm

#endif  // RCM_UTIL_NUMBER_FORMAT_H_
