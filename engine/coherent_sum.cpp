#include "engine/coherent_sum.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <glm/geometric.hpp>
#include <numbers>

#include "engine/barrier.h"

namespace dpc {

namespace {

using C = std::complex<double>;
constexpr double kPi = std::numbers::pi;

/// Per path and band, the pressure factors every path carries: the air's attenuation
/// sqrt(exp(-m l)) and the square root of the source's energy weight toward the path.
struct PathGains {
  std::vector<double> utd;   // times the UTD path's spreading
  std::vector<double> slit;  // for the slit path
  /// Per path, its UTD coefficient at band b's anchor frequencies (utdAnchors), and its end
  /// sums D^(e) there (engine/finite_edge.h; set where an end is finite).
  std::vector<std::array<C, kUtdAnchorsPerBand>> anchors;
  std::vector<std::array<std::array<C, kUtdAnchorsPerBand>, 2>> endAnchors;
};

/// Every path's UTD coefficient at band b's anchor frequencies, into gains.anchors.
void utdAnchors(int b, const std::vector<EdgePath>& paths, float speedOfSound,
                PathGains& gains) {
  gains.anchors.resize(paths.size());
  gains.endAnchors.resize(paths.size());
  for (int a = 0; a < kUtdAnchorsPerBand; ++a) {
    const double k = 2.0 * kPi * diffractionFrequencyHz(b, utdAnchorIndex(a)) / speedOfSound;
    for (size_t j = 0; j < paths.size(); ++j) {
      const EdgePath& q = paths[j];
      const double kl = k * q.distanceParameter;
      gains.anchors[j][size_t(a)] = utdScaled(q.terms, q.sums, q.prefactor, kl);
      if (!q.ends.finite()) continue;
      for (size_t e = 0; e < 2; ++e)
        gains.endAnchors[j][e][size_t(a)] =
            utdScaled(q.ends.terms[e], q.ends.sums[e], q.prefactor, kl);
    }
  }
}

/// Path j's UTD coefficient at band frequency i (wavenumber k), its edge's ends taken off
/// (engine/finite_edge.h withEnds), each sum interpolated from the anchors.
C pathUtd(const EdgePath& q, const PathGains& gains, size_t j, int i, double k) {
  const C d = interpolatedUtd(gains.anchors[j], i);
  if (!q.ends.finite()) return d;
  return withEnds(
      q.ends, endTails(q.ends, k), d,
      {interpolatedUtd(gains.endAnchors[j][0], i), interpolatedUtd(gains.endAnchors[j][1], i)});
}

/// Scratch of slitLoading: the coupled slits, the path each belongs to, their factors, and
/// per path its factor.
struct SlitLoading {
  std::vector<CoupledSlit> slits;
  std::vector<size_t> path;
  std::vector<C> factors, perPath;
};

/// Per path, the factor its slit's field takes from the slits' mutual loading at wavenumber k
/// (engine/slit.h, mutualLoading), into out.perPath: owner paths whose slit model holds (weight
/// s > 0) are coupled; 1 for the rest.
void slitLoading(const std::vector<EdgePath>& paths, const PathGains& gains, double k,
                 SlitLoading& out) {
  out.slits.clear();
  out.path.clear();
  out.perPath.assign(paths.size(), C(1.0, 0.0));
  for (size_t j = 0; j < paths.size(); ++j) {
    const EdgePath& q = paths[j];
    if (!(q.gapWidth > 0.f) || !q.slitOwner) continue;
    const double kt = k * q.slit.sinBeta, x = kt * q.slit.width;
    if (!(slitWeight(x, q.slitAspect) > 0.0)) continue;
    const glm::dvec3 along(q.edge->direction);
    out.slits.push_back({glm::dvec3(q.slitCentre), along,
                         glm::normalize(glm::cross(along, glm::dvec3(q.mouth))), x, kt,
                         gains.slit[j] * std::polar(1.0 / q.slit.r, -k * q.slit.r)});
    out.path.push_back(j);
  }
  if (out.slits.size() < 2) return;
  out.factors.resize(out.slits.size());
  mutualLoading(out.slits, out.factors);
  for (size_t i = 0; i < out.path.size(); ++i) out.perPath[out.path[i]] = out.factors[i];
}

/// The direct sound in the coherent sum: its amplitude (0 when not visible) and distance (m),
/// and the slit its line of sight passes through (null: none).
struct DirectPart {
  double amplitude;
  float distance;
  const EdgePath* slit;
};

/// |p|^2 of the direct sound plus every path, averaged over band b's frequencies. A path
/// through a gap adds its slit's field (engine/slit.h) with weight s = slitWeight(k_t w,
/// aspect) and its edge's UTD field with weight 1 - s; a direct sound whose line of sight
/// passes that slit keeps the weight 1 - s too (the slit's field carries the rest).
double bandMeanSquare(int b, const std::vector<EdgePath>& paths, const PathGains& gains,
                      const DirectPart& direct, float speedOfSound) {
  double acc = 0.0;
  SlitLoading loading;
  for (int i = 0; i < kDiffractionFrequenciesPerBand; ++i) {
    const double k = 2.0 * kPi * diffractionFrequencyHz(b, i) / speedOfSound;
    slitLoading(paths, gains, k, loading);
    double directAmplitude = direct.amplitude;
    if (const EdgePath* q = direct.slit)
      directAmplitude *= 1.0 - slitShare(*q, k);
    C p = directAmplitude * pathPhasor(k * double(direct.distance));
    C diffracted(0.0, 0.0);
    double scattered = 0.0;  // the slits' fields whose phase is not known, in energy
    for (size_t j = 0; j < paths.size(); ++j) {
      const EdgePath& q = paths[j];
      double amplitude = gains.utd[j];
      if (q.gapWidth > 0.f) {
        const double s = slitShare(q, k);
        if (s > 0.0 && q.slitOwner) {
          const C field = s * gains.slit[j] * loading.perPath[j] * slitPressure(q.slit, k);
          const double kj = k * double(q.phaseSpread), coherent = std::exp(-0.5 * kj * kj);
          p += coherent * field;
          scattered += (1.0 - coherent * coherent) * std::norm(field);
        }
        if (s >= 1.0) continue;
        amplitude *= 1.0 - s;
      }
      if (amplitude == 0.0) continue;  // no UTD field (a slit's path: its terms may be unset)
      const C d = pathUtd(q, gains, j, i, k);
      const C e = pathPhasor(k * q.length);  // e^{-jkl} = c - j s
      const double c = e.real(), sn = -e.imag();
      // amplitude * d * e^{-jkl}, written out (std::complex's operator* checks for NaN)
      diffracted += amplitude * C(d.real() * c + d.imag() * sn, d.imag() * c - d.real() * sn);
    }
    p += diffracted / std::sqrt(k);
    acc += std::norm(p) + scattered;
  }
  return acc / kDiffractionFrequenciesPerBand;
}

}  // namespace

const EdgePath* slitOnLineOfSight(const std::vector<EdgePath>& paths, const glm::vec3& source,
                                  const glm::vec3& L) {
  constexpr float kTolerance = 1e-4f;  // m, single-precision geometry
  constexpr float kWidthMargin = 1.05f;
  const glm::vec3 d = L - source;
  for (const EdgePath& p : paths) {
    if (!(p.gapWidth > 0.f) || !p.slitOwner) continue;
    const DiffractionEdge& e = *p.edge;
    const glm::vec3 normal = glm::cross(e.direction, p.mouth);  // the slit's plane
    const float den = glm::dot(d, normal);
    if (!(std::abs(den) > 1e-9f)) continue;
    const float t = glm::dot(e.a - source, normal) / den;
    if (!(t > 0.f && t < 1.f)) continue;
    const glm::vec3 v = source + t * d - e.a;
    const float across = glm::dot(v, p.mouth), along = glm::dot(v, e.direction);
    const float z0 = glm::dot(p.slitCentre - e.a, e.direction);  // the slit's own point
    // The probed width lies within 5 % of the gap's (engine/gap_probe.h): a line of sight
    // grazing the gap's far side still passes it.
    if (across >= -kTolerance && across <= kWidthMargin * p.gapWidth + kTolerance &&
        along >= z0 + float(p.slit.zFrom) - kTolerance &&
        along <= z0 + float(p.slit.zTo) + kTolerance)
      return &p;
  }
  return nullptr;
}

std::vector<Bands> leavingWeights(const std::vector<EdgePath>& paths, const Directivity& d,
                                  const glm::vec3& forward) {
  std::vector<Bands> w;
  if (d.omni()) return w;
  for (const EdgePath& p : paths) w.push_back(directivityWeight(d, glm::dot(forward, p.leaving)));
  return w;
}

double bandAmplitude(const EdgePath& p, int b, float speedOfSound) {
  if (p.share * p.spreading == 0.0) return 0.0;  // no UTD field: its terms may be unset
  const double k = 2.0 * kPi * diffractionFrequencyHz(b, 0) / double(speedOfSound);
  const double kl = k * p.distanceParameter;
  C d = utdScaled(p.terms, p.sums, p.prefactor, kl);
  if (p.ends.finite())  // the edge's ends (engine/finite_edge.h)
    d *= finiteEdgeFactor(p.ends, k, d,
                          {utdScaled(p.ends.terms[0], p.ends.sums[0], p.prefactor, kl),
                           utdScaled(p.ends.terms[1], p.ends.sums[1], p.prefactor, kl)});
  return p.share * p.spreading * std::abs(d) / std::sqrt(k);
}

Bands coherentIntensity(const std::vector<EdgePath>& paths, const DirectSound& direct,
                        const EdgePath* throughSlit, float speedOfSound, const Bands& airPerMetre,
                        const std::vector<Bands>& weights, int bands) {
  Bands intensity(0.f);
  PathGains gains{std::vector<double>(paths.size()), std::vector<double>(paths.size()), {}, {}};
  for (int b = 0; b < std::min(bands, kNumBands); ++b) {
    for (size_t j = 0; j < paths.size(); ++j) {
      const double w = weights.empty() ? 1.0 : std::sqrt(double(weights[j][b]));
      gains.utd[j] = paths[j].share * paths[j].spreading *
                     std::exp(-0.5 * double(airPerMetre[b]) * paths[j].length) *
                     grazingAmplitude(paths[j].grazeExcess, paths[j].grazeSpan,
                                      double(speedOfSound) / bandCentreExactHz(b));
      if (!weights.empty()) gains.utd[j] *= w;
      gains.slit[j] =
          w * std::exp(-0.5 * double(airPerMetre[b]) * (paths[j].slit.r + paths[j].slit.s));
    }
    const double directAmplitude =
        direct.visible ? std::sqrt(4.0 * kPi * double(direct.intensity[b])) : 0.0;
    utdAnchors(b, paths, speedOfSound, gains);
    const double meanSquare = bandMeanSquare(
        b, paths, gains, {directAmplitude, direct.distance, throughSlit}, speedOfSound);
    intensity[b] = float(meanSquare / (4.0 * kPi));
  }
  return intensity;
}

}  // namespace dpc
