// Values that probe a limit of scene/limits.h: each finite bound (accepted) and one step beyond
// it (refused). Shared by the tests that feed every entry point (scene file, C API, dpc-demo
// flags) each limit, so that a new table entry is probed everywhere without a new test.
#pragma once

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "scene/limits.h"

namespace dpc::test {

struct LimitProbe {
  double value;
  bool accepted;
  std::string what;  ///< "min", "max", "below min", "above max", for messages
};

/// The bounds and one step beyond each: 1 for integers, 1/1000 of the bound (at least 0.001)
/// for real numbers. An exclusive minimum is probed with the minimum itself (refused) and a
/// value just above it (accepted).
inline std::vector<LimitProbe> probesFor(const Limit& l) {
  const double scale = std::max(std::abs(l.min), std::isinf(l.max) ? 0.0 : std::abs(l.max));
  const double step = l.integer ? 1.0 : std::max(1e-3, 1e-3 * scale);
  std::vector<LimitProbe> probes;
  if (l.minExclusive) {
    const double above = std::isinf(l.max) ? 1e-3 : (l.max - l.min) * 1e-6;
    probes.push_back({l.min + above, true, "just above min"});
    probes.push_back({l.min, false, "min (exclusive)"});
  } else {
    probes.push_back({l.min, true, "min"});
    probes.push_back({l.min - step, false, "below min"});
  }
  if (!std::isinf(l.max)) {
    probes.push_back({l.max, true, "max"});
    probes.push_back({l.max + step, false, "above max"});
  }
  return probes;
}

}  // namespace dpc::test
