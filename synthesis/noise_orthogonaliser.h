// Makes a synthesised noise add to the deterministic part of an IR in energy, band by band.
//
// An IR is the noise that carries the energy response's reverberant part plus a deterministic
// part (the direct sound, the exact early paths). Summed in pressure, their octave-band energy
// is E_fixed + E_noise + 2 X_b, where the cross term X_b = <H_b f, H_b n> (H_b the ISO 3382-1
// octave filter, common/octave_filter.h) is zero only in expectation: in one IR of a small room
// it held 10-25 % of the 250 Hz band's energy near the direct sound, and the levelling, which
// sees it through its own band views, cancelled it only in part. The energy response's paths add
// in energy, so one IR should read E_fixed + E_noise in every band.
//
// apply() removes the cross term at its source: with u_b = K_b f (K_b the zero-phase kernel of
// |H_b|^2, so that X_b = <n, u_b>), the noise loses its projection on the span of the u_b over
// its own support (n' = n - sum_b beta_b u_b, the Gram system G beta = <n, u> of the eight
// bands solved in double), after which X_b = 0 in every octave band. What is removed is at most
// eight degrees of freedom of the noise near the deterministic part; the window levelling that
// follows restores each window's energy.
//
// Construction: propagation thread; allocates. apply(): propagation thread; allocates FFTW
// buffers the first time a deterministic part spans a larger transform than before; no errors.
#pragma once

#include <array>
#include <cstddef>
#include <memory>
#include <vector>

#include "common/bands.h"
#include "common/octave_filter.h"

namespace dpc {

struct FftwRealTransforms;

class NoiseOrthogonaliser {
 public:
  /// IRs of `length` samples at sampleRate Hz; the octave bands firstBand..lastBand (0..7, the
  /// bands a caller levels) take part.
  NoiseOrthogonaliser(int sampleRate, size_t length, int firstBand, int lastBand);
  ~NoiseOrthogonaliser();
  NoiseOrthogonaliser(const NoiseOrthogonaliser&) = delete;
  NoiseOrthogonaliser& operator=(const NoiseOrthogonaliser&) = delete;

  /// noise[0..length) loses its projection on the octave-band images of fixed[0..length)
  /// (pressure, the same scale; fixed all zero: nothing changes). The fixed part's extent is
  /// where it exceeds kSignificant of its peak (its placed pulses ring on far below). Only
  /// samples where noise is non-zero change (its support: the cleared neighbourhoods of arrivals
  /// stay clear), and only within padSamples() of that extent.
  void apply(float* noise, const float* fixed);

  /// How far (samples) beyond the deterministic part the lowest band's power kernel reaches:
  /// where that band's filter has rung out to kRingOut of its impulse energy.
  size_t padSamples() const { return pad_; }

 private:
  struct Transform;  ///< an FFT size and each band's power response |H_b|^2 on its bins
  Transform& transformFor(size_t samples);
  /// u_[b][0..span) <- K_b fixed[from .. from + span), through `t`.
  void bandImages(Transform& t, const float* fixed, size_t from, size_t span);
  /// beta <- the projection coefficients of noise[from .. from + span) on the u_[b].
  std::array<double, kNumBands> coefficients(const float* noise, size_t span) const;

  int sampleRate_;
  size_t length_;
  int firstBand_, lastBand_;
  size_t pad_;
  std::array<OctaveBandPass, kNumBands> filters_;
  std::vector<std::unique_ptr<Transform>> transforms_;  ///< by size, ascending
  std::array<std::vector<double>, kNumBands> u_;
};

}  // namespace dpc
