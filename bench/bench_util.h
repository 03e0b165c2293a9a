// Small statistics helpers shared by the dpc-bench subcommands.
#pragma once

#include <algorithm>
#include <cmath>
#include <vector>

namespace dpc::bench {

/// The p-quantile (0..1) of v by linear interpolation between order statistics; NaN if empty.
inline double percentile(std::vector<double> v, double p) {
  if (v.empty()) return NAN;
  std::sort(v.begin(), v.end());
  const double idx = p * double(v.size() - 1);
  const size_t lo = size_t(std::floor(idx)), hi = size_t(std::ceil(idx));
  return v[lo] + (v[hi] - v[lo]) * (idx - double(lo));
}

}  // namespace dpc::bench
