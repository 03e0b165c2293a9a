// Bands: one value per octave band (63 Hz .. 8 kHz), with arithmetic.
//
// The frequency-dependent quantity of dpc, as pbrt's SampledSpectrum is pbrt's: absorption
// coefficients, ray energies and energy-response bins are all Bands. The unit is whatever the
// holder says (energy fraction, intensity in 1/m^2 relative to source power, ...).
// Any thread; never allocates; no errors (arithmetic follows IEEE float).
// Source: octave-band centre frequencies of IEC 61260-1 / ISO 266 (nominal values).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>

namespace dpc {

/// Number of octave bands (63, 125, 250, 500, 1000, 2000, 4000, 8000 Hz).
inline constexpr int kNumBands = 8;

/// Nominal octave-band centre frequencies in Hz (ISO 266).
inline constexpr std::array<float, kNumBands> kBandCentreHz = {63.f,   125.f,  250.f,  500.f,
                                                               1000.f, 2000.f, 4000.f, 8000.f};

/// Exact base-2 centre frequency of band b in Hz: 1000 * 2^(b-4) (IEC 61260-1).
inline double bandCentreExactHz(int b) {
  return 1000.0 * std::exp2(double(b - 4));
}

/// Each octave band's share of a white spectrum's power from 0 Hz to Nyquist at sampleRate Hz:
/// its span between the band edges fc / sqrt 2 and fc sqrt 2 (exact centres), the 63 Hz band
/// from 0 Hz and the 8 kHz band to Nyquist, over Nyquist (the shares sum to 1). A band value
/// of an energy response is a spectral density, so sum_b E_b w_b is the broadband energy an IR
/// carrying the response has: the one definition of a response's broadband (dpc-analyze's CSV
/// column, a bake's parameter map). Requires sampleRate / 2 above 8 kHz's lower edge.
inline std::array<double, kNumBands> whiteSpectrumShares(double sampleRate) {
  const double nyquist = 0.5 * sampleRate;
  std::array<double, kNumBands> w{};
  double low = 0.0;
  for (int b = 0; b < kNumBands; ++b) {
    const double high =
        b + 1 < kNumBands ? std::min(nyquist, bandCentreExactHz(b) * std::sqrt(2.0)) : nyquist;
    w[size_t(b)] = std::max(0.0, high - low) / nyquist;
    low = std::max(low, high);
  }
  return w;
}

struct Bands {
  std::array<float, kNumBands> v{};

  constexpr Bands() = default;
  constexpr explicit Bands(float x) { v.fill(x); }

  constexpr float& operator[](int b) { return v[size_t(b)]; }
  constexpr float operator[](int b) const { return v[size_t(b)]; }

#define DPC_BANDS_OP(op)                                                    \
  constexpr Bands& operator op##=(const Bands& o) {                         \
    for (int b = 0; b < kNumBands; ++b) v[size_t(b)] op## = o.v[size_t(b)]; \
    return *this;                                                           \
  }                                                                         \
  constexpr Bands& operator op##=(float s) {                                \
    for (int b = 0; b < kNumBands; ++b) v[size_t(b)] op## = s;              \
    return *this;                                                           \
  }                                                                         \
  friend constexpr Bands operator op(Bands a, const Bands& o) {             \
    return a op## = o;                                                      \
  }                                                                         \
  friend constexpr Bands operator op(Bands a, float s) {                    \
    return a op## = s;                                                      \
  }
  DPC_BANDS_OP(+)
  DPC_BANDS_OP(-)
  DPC_BANDS_OP(*)
  DPC_BANDS_OP(/)
#undef DPC_BANDS_OP
  friend constexpr Bands operator*(float s, Bands a) {
    return a *= s;
  }

  constexpr bool operator==(const Bands&) const = default;

  float max() const {
    return *std::max_element(v.begin(), v.end());
  }
  float min() const {
    return *std::min_element(v.begin(), v.end());
  }
  float sum() const {
    float s = 0.f;
    for (float x : v) s += x;
    return s;
  }
  float average() const {
    return sum() / float(kNumBands);
  }
  bool hasNaN() const {
    return std::any_of(v.begin(), v.end(), [](float x) { return std::isnan(x); });
  }
  bool allFinite() const {
    return std::all_of(v.begin(), v.end(), [](float x) { return std::isfinite(x); });
  }
};

/// Element-wise exp (for air attenuation factors).
inline Bands exp(const Bands& a) {
  Bands r;
  for (int b = 0; b < kNumBands; ++b) r[b] = std::exp(a[b]);
  return r;
}

/// Element-wise minimum.
inline Bands min(const Bands& a, const Bands& b) {
  Bands r;
  for (int i = 0; i < kNumBands; ++i) r[i] = std::min(a[i], b[i]);
  return r;
}

/// Element-wise maximum.
inline Bands max(const Bands& a, const Bands& b) {
  Bands r;
  for (int i = 0; i < kNumBands; ++i) r[i] = std::max(a[i], b[i]);
  return r;
}

}  // namespace dpc
