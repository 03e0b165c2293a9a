#include "runtime/max_order_warning.h"

#include <cmath>
#include <cstdio>

namespace dpc {

std::string maxOrderWarning(int maxOrder, double share) {
  const std::string at = maxOrder > 0 ? "order " + std::to_string(maxOrder) : "their last order";
  char rest[224];
  std::snprintf(rest, sizeof rest,
                " still carried %.2g %% of the emitted energy (%.0f dB, largest band): the decay "
                "below that is lost (T30 and the late tail read short); raise max_order",
                100.0 * share, 10.0 * std::log10(share));
  return "propagation.max_order: rays ended at " + at + rest;
}

}  // namespace dpc
