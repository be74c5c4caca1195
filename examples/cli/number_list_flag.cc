#include "number_list_flag.h"

#include <cmath>
#include <cstdlib>

namespace rcm::cli {

StatusOr<std::vector<double>> ParseNumberList(const std::string& text) {
  std::vector<double> numbers;
  size_t begin = 0;
  while (true) {
    const size_t comma = text.find(',', begin);
    const std::string field = text.substr(
        begin, comma == std::string::npos ? std::string::npos : comma - begin);
    char* end = nullptr;
    const double value = std::strtod(field.c_str(), &end);
    if (field.empty() || *end != '\0' || !std::isfinite(value)) {
      return Status::Error("'" + field + "' is not a finite number");
    }
    numbers.push_back(value);
    if (comma == std::string::npos) return numbers;
    begin = comma + 1;
  }
}

}  // namespace rcm::cli
