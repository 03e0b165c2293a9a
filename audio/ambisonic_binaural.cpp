#include "audio/ambisonic_binaural.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include "common/spherical_harmonics.h"

namespace dpc::audio {

AmbisonicBinauralDecoder::AmbisonicBinauralDecoder(int order, const Hrtf& hrtf)
    : order_(std::clamp(order, 1, kMaxAmbisonicOrder)) {
  const size_t nc = size_t(ambisonicChannels(order_)), taps = size_t(hrtf.filterLength());
  const int nz = order_ + 2, nphi = 2 * order_ + 4;
  std::vector<double> zs(static_cast<size_t>(nz)), ws(static_cast<size_t>(nz));
  for (int k = 0; k < nz; ++k) gaussLegendreNode(nz, k, zs[size_t(k)], ws[size_t(k)]);
  length_ = taps + size_t(hrtf.sampleRate() / 500);  // room for onset delays up to 2 ms
  filters_.assign(nc, {std::vector<float>(length_, 0.f), std::vector<float>(length_, 0.f)});
  std::vector<float> ear[2] = {std::vector<float>(taps), std::vector<float>(taps)};
  std::array<float, ambisonicChannels(kMaxAmbisonicOrder)> y{};
  for (size_t k = 0; k < zs.size(); ++k)
    for (int j = 0; j < nphi; ++j) {
      const double phi = 2.0 * std::numbers::pi * double(j) / double(nphi);
      const double s = std::sqrt(1.0 - zs[k] * zs[k]);
      const float u[3] = {float(s * std::cos(phi)), float(s * std::sin(phi)), float(zs[k])};
      float delay[2] = {0.f, 0.f};
      hrtf.hrir(u, ear[0].data(), ear[1].data(), &delay[0], &delay[1]);
      sphericalHarmonicsSn3d(order_, u, y);
      const double w = ws[k] * (2.0 * std::numbers::pi / double(nphi)) / (4.0 * std::numbers::pi);
      for (int n = 0; n <= order_; ++n)
        for (int c = n * n; c < (n + 1) * (n + 1); ++c)
          for (int e = 0; e < 2; ++e) {
            const float g = float(w * double(2 * n + 1) * y[size_t(c)]);
            const size_t d = std::min(size_t(std::max(0.f, std::round(delay[e]))), length_ - taps);
            float* f = filters_[size_t(c)][size_t(e)].data() + d;
            for (size_t t = 0; t < taps; ++t) f[t] += g * ear[e][t];
          }
    }
}

void AmbisonicBinauralDecoder::decode(const float* const* channels, size_t n, float* left,
                                      float* right) const {
  float* out[2] = {left, right};
  for (size_t c = 0; c < filters_.size(); ++c)
    for (int e = 0; e < 2; ++e) {
      const std::vector<float>& f = filters_[c][size_t(e)];
      for (size_t i = 0; i < n; ++i) {
        const float x = channels[c][i];
        if (x == 0.f) continue;
        const size_t m = std::min(f.size(), n - i);
        for (size_t t = 0; t < m; ++t) out[e][i + t] += x * f[t];
      }
    }
}

}  // namespace dpc::audio
