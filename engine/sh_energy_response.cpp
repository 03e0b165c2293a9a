#include "engine/sh_energy_response.h"

#include <array>
#include <cmath>
#include <stdexcept>

#include "common/spherical_harmonics.h"

namespace dpc {

ShEnergyResponse::ShEnergyResponse(int order, double lengthSeconds, double binSeconds,
                                   ListenerFrame frame)
    : order_(order), binSeconds_(binSeconds), frame_(frame) {
  if (order < 0 || order > kMaxAmbisonicOrder || !(lengthSeconds > 0.0) || !(binSeconds > 0.0))
    throw std::invalid_argument("ShEnergyResponse: order 0..7, length and bin width > 0");
  channels_ = size_t(ambisonicChannels(order));
  invBin_ = 1.0 / binSeconds;
  bins_ = size_t(std::ceil(lengthSeconds / binSeconds - 1e-9));
  data_.assign(bins_ * channels_ * kNumBands, 0.f);
}

void addShEnergy(int order, const ListenerFrame& frame, const glm::vec3& worldDirection,
                 const Bands& intensity, float sign, float* out) {
  std::array<float, ambisonicChannels(kMaxAmbisonicOrder)> y{};
  const glm::vec3 d = frame.toListener(worldDirection);
  const float dir[3] = {d.x, d.y, d.z};
  if (order == 1)
    sphericalHarmonicsSn3dFirstOrder(dir, y);  // the bake's order, once per arrival
  else
    sphericalHarmonicsSn3d(order, dir, y);
  const int channels = ambisonicChannels(order);
  for (int n = 0; n < channels; ++n)
    for (int b = 0; b < kNumBands; ++b) out[n * kNumBands + b] += sign * y[size_t(n)] * intensity[b];
}

void ShEnergyResponse::add(double delaySeconds, const Bands& intensity,
                           const glm::vec3& worldDirection) {
  const double k = delaySeconds * invBin_;
  if (!(k >= 0.0) || k >= double(bins_)) return;
  addShEnergy(order_, frame_, worldDirection, intensity, 1.f,
              data_.data() + size_t(k) * channels_ * kNumBands);
}

void ShEnergyResponse::clear() { std::fill(data_.begin(), data_.end(), 0.f); }

}  // namespace dpc
