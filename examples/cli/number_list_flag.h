// Flags whose value is a comma-separated list of numbers, e.g.
// --depth-range 0.6,6 or --extrinsic-drift 0.5,0,0.
#ifndef RCM_EXAMPLES_CLI_NUMBER_LIST_FLAG_H_
#define RCM_EXAMPLES_CLI_NUMBER_LIST_FLAG_H_

#include <string>
#include <vector>

#include "rcm/util/status.h"

namespace rcm::cli {

// The numbers of "A,B,...": each field a whole number as strtod reads it,
// finite. Errors (one line, quoting the field): an empty field, a field
// that is not a number or not finite.
StatusOr<std::vector<double>> ParseNumberList(const std::string& text);

}  // namespace rcm::cli

#endif  // RCM_EXAMPLES_CLI_NUMBER_LIST_FLAG_H_
