#include "synthesis/dirac_sequence.h"

#include <algorithm>
#include <numbers>

#include "common/random.h"

namespace dpc {

std::vector<float> diracSequence(int sampleRate, size_t length, double roomVolume,
                                 double speedOfSound, double maxDensity, uint64_t seed) {
  std::vector<float> seq(length, 0.f);
  Rng rng(seed, 0x0d1acULL);
  const double c3 = speedOfSound * speedOfSound * speedOfSound;
  const double dt = 1.0 / sampleRate;
  // Thinning per sample: probability mu(t) dt of a pulse in [t, t + dt).
  for (size_t n = 0; n < length; ++n) {
    const double t = double(n) * dt;
    const double mu = std::max(
        kMinPulseDensity, std::min(4.0 * std::numbers::pi * c3 * t * t / roomVolume, maxDensity));
    if (double(rng.uniform()) < mu * dt) seq[n] = rng.uniform() < 0.5f ? -1.f : 1.f;
  }
  return seq;
}

}  // namespace dpc
