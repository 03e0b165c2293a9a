// The ISO 3382-1 analysis octave filter: IEC 61260-1 octave band-pass, a 6th-order
// Butterworth (3rd-order low-pass prototype) realised as three biquads from the bilinear
// transform with both band edges prewarped, so the digital response is exactly the analog
// Butterworth one at prewarped frequencies: -3.01 dB at the edges fc * 2^(+-1/2), about
// -19.6 dB one octave away, unity gain at the centre fc.
//
// One definition shared by the band analysis (analysis/room_parameters.h), its expected reading
// of an energy response (analysis/expected_band_analysis.h) and the IR synthesis's window
// levelling (synthesis/window_leveller.h, which lays its windows so that the analysis's 80 ms
// split, delayed by these filters, falls on a window boundary).
// Any thread; design() allocates a few complex numbers; filtering never allocates; no errors
// (requires fc * sqrt(2) < fs / 2, which callers check).
#pragma once

#include <array>
#include <cmath>
#include <complex>
#include <numbers>
#include <vector>

namespace dpc {

/// One second-order section, transposed direct form II, double precision:
/// y = b0 x + s1; s1' = b1 x - a1 y + s2; s2' = b2 x - a2 y.
struct Biquad {
  double b0, b1, b2, a1, a2;
};

/// Three cascaded sections and their states (s1, s2 per section).
struct OctaveBandPass {
  std::array<Biquad, 3> sections{};
  using State = std::array<double, 6>;

  /// The IEC 61260-1 octave band around the exact centre fc (Hz) at sampling rate fs (Hz).
  static OctaveBandPass design(double fc, double fs) {
    using C = std::complex<double>;
    const double pi = std::numbers::pi;
    const double k = 2.0 * fs;
    const double f1 = fc / std::numbers::sqrt2, f2 = fc * std::numbers::sqrt2;
    const double w1 = k * std::tan(pi * f1 / fs), w2 = k * std::tan(pi * f2 / fs);
    const double w0 = std::sqrt(w1 * w2), bw = w2 - w1;
    constexpr int kOrder = 3;
    std::vector<C> upper;  // digital poles in the upper half plane
    for (int i = 1; i <= kOrder; ++i) {
      const C p = std::polar(1.0, pi * double(2 * i + kOrder - 1) / double(2 * kOrder));
      const C root = std::sqrt(p * p * bw * bw - 4.0 * w0 * w0);
      for (C s : {(p * bw + root) / 2.0, (p * bw - root) / 2.0}) {
        const C z = (k + s) / (k - s);
        if (z.imag() > 0) upper.push_back(z);
      }
    }
    OctaveBandPass out;
    const double omega0 = 2.0 * std::atan(w0 / k);
    const C zc = std::polar(1.0, omega0);
    for (size_t i = 0; i < out.sections.size() && i < upper.size(); ++i) {
      Biquad q{1.0, 0.0, -1.0, -2.0 * upper[i].real(), std::norm(upper[i])};
      const C h = (1.0 - 1.0 / (zc * zc)) / (1.0 + q.a1 / zc + q.a2 / (zc * zc));
      const double g = 1.0 / std::abs(h);
      q.b0 *= g;
      q.b2 *= g;
      out.sections[i] = q;
    }
    return out;
  }

  /// One sample through the cascade, updating `state`.
  double step(double x, State& state) const {
    for (size_t i = 0; i < 3; ++i) {
      const Biquad& q = sections[i];
      double& s1 = state[2 * i];
      double& s2 = state[2 * i + 1];
      const double y = q.b0 * x + s1;
      s1 = q.b1 * x - q.a1 * y + s2;
      s2 = q.b2 * x - q.a2 * y;
      x = y;
    }
    return x;
  }

  /// Energy of the unit impulse response, rung out over `samples` samples (a second's worth
  /// leaves the 63 Hz band's remainder far below 1e-12): the free-field reference of a band
  /// reading, about the band's share of a white spectrum. No allocation.
  double impulseEnergy(size_t samples) const { return impulseMoments(samples).energy; }

  /// The energy centroid of the unit impulse response rung out over `samples` samples, in
  /// samples: how late the filter delivers a band's energy (about one period of fc). No
  /// allocation.
  double energyCentroid(size_t samples) const {
    const Moments m = impulseMoments(samples);
    return m.energy > 0.0 ? m.moment / m.energy : 0.0;
  }

  /// The unit impulse response's energy sum_n h[n]^2 and first moment sum_n n h[n]^2 over
  /// `samples` samples. No allocation.
  struct Moments {
    double energy = 0.0, moment = 0.0;
  };
  Moments impulseMoments(size_t samples) const {
    State state{};
    Moments m;
    for (size_t n = 0; n < samples; ++n) {
      const double y = step(n == 0 ? 1.0 : 0.0, state);
      m.energy += y * y;
      m.moment += double(n) * y * y;
      if (n % 64 == 63) flushTiny(state);
    }
    return m;
  }

  /// Sets state values below 1e-150 to zero: a state ringing out with zero input would
  /// otherwise reach subnormal numbers, whose arithmetic is about 100 times slower.
  static void flushTiny(State& state) {
    for (double& v : state)
      if (std::abs(v) < 1e-150) v = 0.0;
  }

  /// Filters x[0..n) into y[0..n) (y may alias x) starting from `state`, which is updated.
  template <typename In, typename Out>
  void run(const In* x, Out* y, size_t n, State& state) const {
    constexpr size_t kChunk = 64;
    for (size_t i = 0; i < n; ++i) {
      y[i] = Out(step(double(x[i]), state));
      if (i % kChunk == kChunk - 1) flushTiny(state);
    }
  }
};

}  // namespace dpc
