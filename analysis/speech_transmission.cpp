#include "analysis/speech_transmission.h"

#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <numbers>

namespace dpc::audio {

double modulationTransfer(std::span<const double> energy, double binSeconds, double hz) {
  std::complex<double> sum = 0.0;
  double total = 0.0;
  const double w = 2.0 * std::numbers::pi * hz * binSeconds;
  for (size_t i = 0; i < energy.size(); ++i) {
    const double e = std::max(energy[i], 0.0);
    sum += e * std::polar(1.0, -w * (double(i) + 0.5));
    total += e;
  }
  if (!(total > 0.0)) return std::numeric_limits<double>::quiet_NaN();
  return std::abs(sum) / total;
}

namespace {

/// Transmission index of one modulation transfer: the clipped effective SNR mapped to 0..1.
double transmissionIndex(double m) {
  const double snr = m >= 1.0 ? 15.0 : 10.0 * std::log10(m / (1.0 - m));
  return (std::clamp(snr, -15.0, 15.0) + 15.0) / 30.0;
}

}  // namespace

double stiFromMti(const std::array<double, kStiBands>& mti) {
  double sti = 0.0;
  for (int k = 0; k < kStiBands; ++k) sti += kStiAlpha[size_t(k)] * mti[size_t(k)];
  for (int k = 0; k + 1 < kStiBands; ++k)
    sti -= kStiBeta[size_t(k)] * std::sqrt(mti[size_t(k)] * mti[size_t(k) + 1]);
  return sti;
}

double speechTransmissionIndex(const std::array<std::span<const double>, kStiBands>& bands,
                               double binSeconds) {
  std::array<double, kStiBands> mti{};
  for (int k = 0; k < kStiBands; ++k) {
    double sum = 0.0;
    for (const double hz : kStiModulationHz)
      sum += transmissionIndex(modulationTransfer(bands[size_t(k)], binSeconds, hz));
    mti[size_t(k)] = sum / kStiModulationFrequencies;
    if (std::isnan(mti[size_t(k)])) return std::numeric_limits<double>::quiet_NaN();
  }
  return stiFromMti(mti);
}

}  // namespace dpc::audio
