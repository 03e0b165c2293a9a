// Butterworth low-pass and high-pass filters as cascaded biquads, and one first-order section
// for an odd order (bilinear transform, cutoff prewarped: the digital magnitude is the analog
// Butterworth one at the prewarped frequency, -3.01 dB at the cutoff). A low-pass and a
// high-pass of the same order and cutoff are power complementary: |H_lp|^2 + |H_hp|^2 = 1 at
// every frequency. Of odd order they are also in quadrature at every frequency, so their sum
// is an allpass (order 3: (s^2 - s + 1) / (s^2 + s + 1)): a signal in both bands keeps its
// level too. Causal and minimum phase: nothing filtered arrives before its input.
//
// Any thread; design() allocates the section list; run() never allocates; no errors (design
// requires 0 < cutoff < fs / 2 and an order >= 1, which callers check).
// Source: S. Butterworth, "On the theory of filter amplifiers" (1930); the bilinear transform
// with prewarping as in Oppenheim & Schafer, Discrete-Time Signal Processing, section 7.1.
#pragma once

#include <cmath>
#include <complex>
#include <numbers>
#include <span>
#include <vector>

#include "common/octave_filter.h"

namespace dpc {

class Butterworth {
 public:
  /// kAllPass: unit magnitude with the low-pass's poles, B(-s) / B(s): twice its phase.
  /// kSumAllPass (odd orders): the sum of the low-pass and the high-pass, which is the allpass
  /// of the complex pole pairs alone (order 3: (s^2 - s + 1) / (s^2 + s + 1)).
  enum class Kind { kLowPass, kHighPass, kAllPass, kSumAllPass };

  /// A `kind` filter of `order` at `cutoffHz`, sampling rate `fs` Hz.
  static Butterworth design(Kind kind, int order, double cutoffHz, double fs) {
    Butterworth f;
    const double pi = std::numbers::pi;
    const double k = std::tan(pi * cutoffHz / fs);  // prewarped, normalised to the cutoff
    for (int i = 0; i < order / 2; ++i) {
      // Analog pole pair of the normalised prototype: s = exp(j theta), theta in (pi/2, pi).
      const double theta = pi * double(2 * i + order + 1) / double(2 * order);
      const double a = -2.0 * std::cos(theta);  // s^2 + a s + 1
      const double norm = 1.0 + a * k + k * k;
      Biquad q{};
      q.a1 = 2.0 * (k * k - 1.0) / norm;
      q.a2 = (1.0 - a * k + k * k) / norm;
      if (kind == Kind::kLowPass) {
        q.b0 = k * k / norm;
        q.b1 = 2.0 * q.b0;
        q.b2 = q.b0;
      } else if (kind == Kind::kAllPass || kind == Kind::kSumAllPass) {  // denominator reversed
        q.b0 = q.a2;
        q.b1 = q.a1;
        q.b2 = 1.0;
      } else {
        q.b0 = 1.0 / norm;
        q.b1 = -2.0 * q.b0;
        q.b2 = q.b0;
      }
      f.sections_.push_back(q);
    }
    if (order % 2 && kind != Kind::kSumAllPass) f.sections_.push_back(firstOrder(kind, k));
    return f;
  }

  /// The real pole s = -1 of an odd order: 1 / (s + 1), s / (s + 1) or (1 - s) / (1 + s),
  /// bilinear at k.
  static Biquad firstOrder(Kind kind, double k) {
    Biquad q{};
    q.a1 = (k - 1.0) / (k + 1.0);
    if (kind == Kind::kAllPass) {
      q.b0 = q.a1;
      q.b1 = 1.0;
      return q;
    }
    q.b0 = kind == Kind::kLowPass ? k / (k + 1.0) : 1.0 / (k + 1.0);
    q.b1 = kind == Kind::kLowPass ? q.b0 : -q.b0;
    return q;
  }

  /// Filters x in place from zero state (transposed direct form II, double precision).
  void run(std::span<float> x) const {
    for (const Biquad& q : sections_) {
      double s1 = 0.0, s2 = 0.0;
      for (float& v : x) {
        const double in = v;
        const double y = q.b0 * in + s1;
        s1 = q.b1 * in - q.a1 * y + s2;
        s2 = q.b2 * in - q.a2 * y;
        if (std::abs(s1) < 1e-150) s1 = 0.0;  // no subnormal arithmetic while ringing out
        if (std::abs(s2) < 1e-150) s2 = 0.0;
        v = float(y);
      }
    }
  }

  /// |H(f)|^2 at `hz` for sampling rate fs, evaluated from the sections.
  double powerResponse(double hz, double fs) const {
    const std::complex<double> z = std::polar(1.0, 2.0 * std::numbers::pi * hz / fs);
    std::complex<double> h = 1.0;
    for (const Biquad& q : sections_)
      h *= (q.b0 + q.b1 / z + q.b2 / (z * z)) / (1.0 + q.a1 / z + q.a2 / (z * z));
    return std::norm(h);
  }

 private:
  std::vector<Biquad> sections_;
};

}  // namespace dpc
