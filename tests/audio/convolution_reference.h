// Test signals and the double-precision direct convolution that the convolver tests compare
// against (one definition for tests/audio/*convolver_test.cpp).
#pragma once

#include <algorithm>
#include <random>
#include <vector>

namespace dpc::test {

using Signal = std::vector<float>;

/// n samples uniform in [-1, 1).
inline Signal randomSignal(std::mt19937& rng, size_t n) {
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  Signal s(n);
  for (float& v : s) v = u(rng);
  return s;
}

/// y[t] = sum_{k in [begin, min(end, h.size()))} h[k] x[t - k], t < x.size(), in double
/// precision (the whole IR: begin = 0, end = h.size()).
inline std::vector<double> segmentConvolution(const Signal& x, const Signal& h, size_t begin,
                                              size_t end) {
  std::vector<double> y(x.size(), 0.0);
  end = std::min(end, h.size());
  for (size_t t = 0; t < x.size(); ++t) {
    double acc = 0.0;
    for (size_t k = begin; k < end && k <= t; ++k) acc += double(h[k]) * double(x[t - k]);
    y[t] = acc;
  }
  return y;
}

}  // namespace dpc::test
