#include "rcm/estimation/closed_form.h"

#include <cmath>

namespace rcm {

std::optional<double> ClosedFormN(const NormalizedCorrespondence& match) {
  const double n2 = ClosedFormNSquared(match.left.x(), match.left.y(),
                                       match.right.x(), match.right.y());
  if (!std::isfinite(n2) || !(n2 > 0.0)) return std::nullopt;
  return std::sqrt(n2);
}

}  // namespace rcm
