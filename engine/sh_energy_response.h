// ShEnergyResponse: an energy response with its direction as real spherical-harmonic energy
// per time bin and octave band.
//
// coefficient[k][n][b] = sum over the arrivals in bin k (delay in [k T, (k + 1) T)) of
// I_b Y_n(d), with I_b the arrival's intensity in band b (1/m^2 relative to the source power,
// EnergyResponse's scale), d its direction (unit vector from the listener toward where it comes
// from) in `frame`'s listener coordinates (x forward, y left, z up), and Y_n the real spherical
// harmonics of common/spherical_harmonics.h: ACN channel n, SN3D normalisation, up to `order`.
// So coefficient 0 (Y_0 = 1) is the bin's energy, and at order 1 channels 1, 2, 3 (y, z, x) are
// the energy-weighted sums of the direction's components (the intensity vector's, in energy):
// a plane wave from d gives I_b (1, d_y, d_z, d_x), an isotropic field 0 in every channel above
// 0. The directional density the coefficients describe, band-limited to `order`, is
// f(u) = 1/(4 pi) sum_n (2 n + 1) sum_m c_nm Y_nm(u) (SN3D: the integral of Y_nm^2 over the
// sphere is 4 pi / (2 n + 1); F. Zotter, M. Frank, "Ambisonics", Springer 2019, ch. 4), whose
// integral over the sphere is c_0.
// Propagation thread (or a bake's). Construction allocates; add and clear do not. Arrivals at
// or beyond the length are dropped (as EnergyResponse drops them).
#pragma once

#include <cstddef>
#include <span>
#include <vector>

#include "common/bands.h"
#include "engine/energy_response.h"

namespace dpc {

class ShEnergyResponse final : public ArrivalSink {
 public:
  ShEnergyResponse() = default;
  /// order 0 .. kMaxAmbisonicOrder; lengthSeconds > 0, binSeconds > 0 (std::invalid_argument
  /// otherwise). `frame`: the listener coordinates of the directions (default: a listener at
  /// yaw 0, pitch 0).
  ShEnergyResponse(int order, double lengthSeconds, double binSeconds, ListenerFrame frame = {});

  void add(double delaySeconds, const Bands& intensity, const glm::vec3& worldDirection) override;
  void clear();

  int order() const { return order_; }
  /// (order + 1)^2 coefficients per bin and band.
  size_t channels() const { return channels_; }
  size_t binCount() const { return bins_; }
  double binSeconds() const { return binSeconds_; }
  const ListenerFrame& frame() const { return frame_; }
  /// All coefficients, [bin][channel][band], row-major.
  std::span<const float> data() const { return data_; }
  /// Bin k's coefficients, [channel][band].
  const float* bin(size_t k) const { return data_.data() + k * channels_ * kNumBands; }

 private:
  int order_ = 1;
  size_t channels_ = 4, bins_ = 0;
  double binSeconds_ = 0.01, invBin_ = 100.0;
  ListenerFrame frame_;
  std::vector<float> data_;
};

/// Adds sign x intensity x the order-`order` coefficients of a world direction, turned into
/// `frame`'s coordinates, into out[channel * kNumBands + band] (sign -1 takes an arrival out
/// again). Any thread; no allocation.
void addShEnergy(int order, const ListenerFrame& frame, const glm::vec3& worldDirection,
                 const Bands& intensity, float sign, float* out);

}  // namespace dpc
