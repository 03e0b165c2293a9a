#include "synthesis/pulse_energy.h"

#include <algorithm>

namespace dpc {

std::vector<double> pulseEnergyPerBin(const std::vector<float>& sequence, size_t length,
                                      size_t binSamples, const CentredTaps& h,
                                      const CentredTaps& g) {
  const size_t taps = std::min(h.taps.size(), g.taps.size());
  // running[i]: sum of h g over taps [0, i).
  std::vector<double> running(taps + 1, 0.0);
  for (size_t i = 0; i < taps; ++i)
    running[i + 1] = running[i] + double(h.taps[i]) * double(g.taps[i]);
  std::vector<double> out((length + binSamples - 1) / binSamples, 0.0);
  const long centre = long(h.centre);
  for (size_t p = 0; p < std::min(length, sequence.size()); ++p) {
    const double weight = double(sequence[p]) * double(sequence[p]);
    if (weight == 0.0) continue;
    // The pulse's taps cover samples [p - centre, p - centre + taps) within [0, length).
    const long first = std::max(0L, long(p) - centre);
    const long last = std::min(long(length), long(p) - centre + long(taps));
    for (long start = first; start < last;) {
      const size_t j = size_t(start) / binSamples;
      const long end = std::min(last, long((j + 1) * binSamples));
      const long i0 = start - long(p) + centre, i1 = end - long(p) + centre;
      out[j] += weight * (running[size_t(i1)] - running[size_t(i0)]);
      start = end;
    }
  }
  return out;
}

namespace {

/// The support of one filter (see commonSupport).
TapSupport supportOf(const std::vector<float>& h, double tail) {
  const size_t n = h.size();
  double total = 0.0;
  for (float x : h) total += double(x) * double(x);
  const double allowed = total * tail;
  // Walk inward from the outermost taps of each side while what is dropped stays within tail.
  TapSupport s{n / 2, n - n / 2};
  for (double cut = 0.0; s.before > 0; --s.before) {
    const double e = double(h[n - s.before]) * double(h[n - s.before]);
    if (cut + e > allowed) break;
    cut += e;
  }
  for (double cut = 0.0; s.after > 1; --s.after) {
    const double e = double(h[s.after - 1]) * double(h[s.after - 1]);
    if (cut + e > allowed) break;
    cut += e;
  }
  return s;
}

}  // namespace

TapSupport commonSupport(const std::vector<float>& h, const std::vector<float>& g, double tail) {
  const TapSupport a = supportOf(h, tail), b = supportOf(g, tail);
  return {std::max(a.before, b.before), std::max(a.after, b.after)};
}

CentredTaps centredTaps(const std::vector<float>& h, TapSupport support) {
  const size_t n = h.size();
  CentredTaps out;
  out.centre = support.before;
  out.taps.resize(support.before + support.after);
  for (size_t i = 0; i < out.taps.size(); ++i) out.taps[i] = h[(i + n - support.before) % n];
  return out;
}

}  // namespace dpc
