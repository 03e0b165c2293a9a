#include "engine/transmission.h"

#include <algorithm>

namespace dpc {

float transmissionProbability(const Bands& energy, const Bands& reflectance, const Bands& tau) {
  float through = 0.f, total = 0.f;
  for (int b = 0; b < kNumBands; ++b) {
    through += energy[b] * tau[b];
    total += energy[b] * (tau[b] + reflectance[b]);
  }
  if (!(through > 0.f)) return 0.f;
  if (!(total > through)) return 1.f;
  return std::max(kMinTransmissionProbability, through / total);
}

bool chooseTransmission(const Bands& reflectance, const Bands& tau, float u, Bands& energy) {
  const float p = transmissionProbability(energy, reflectance, tau);
  if (u < p) {
    energy *= tau * (1.f / p);
    return true;
  }
  energy *= reflectance * (1.f / (1.f - p));
  return false;
}

PathTransmission transmissionAlong(const Tracer& tracer, const Geometry& geometry,
                                   const glm::vec3& from, const glm::vec3& dir, float length,
                                   int maxCrossings) {
  PathTransmission out;
  float tnear = 0.f;
  SurfaceHit hit;
  while (tnear < length) {
    if (!tracer.intersect(TraceRay{from, dir, tnear, length}, hit)) break;
    if (!geometry.transmits(hit.triangle) || out.crossings >= maxCrossings) {
      out.capped = geometry.transmits(hit.triangle);
      out.blocked = true;
      out.tau = Bands(0.f);
      return out;
    }
    out.tau *= geometry.transmittance(hit.triangle);
    ++out.crossings;
    tnear = hit.t + surfaceOffset(from + dir * hit.t, hit.t);
  }
  return out;
}

}  // namespace dpc
