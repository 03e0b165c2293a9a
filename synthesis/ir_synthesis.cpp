#include "synthesis/ir_synthesis.h"

#include <fftw3.h>

#include <algorithm>
#include <cmath>
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <unordered_map>

#include "synthesis/band_leveller.h"
#include "common/fftw_util.h"
#include "common/random.h"
#include "common/wide_vectors.h"

namespace dpc {

double powerAbove(double f, double edge) {
  constexpr double halfWidth = 1.0 / 6.0;  // octaves either side of the edge
  const double x = f > 0.0 ? std::log2(f / edge) : -1e9;
  if (x >= halfWidth) return 1.0;
  if (x <= -halfWidth) return 0.0;
  const double s = std::sin(0.25 * std::numbers::pi * (1.0 + x / halfWidth));
  return s * s;
}

OctaveBandMasks::OctaveBandMasks(int sampleRate, size_t fftSize) {
  const size_t bins = fftSize / 2 + 1;
  for (auto& g : gains_) g.assign(bins, 0.f);
  for (size_t k = 0; k < bins; ++k) {
    const double f = double(k) * sampleRate / double(fftSize);
    // Power fraction passed above each edge e_b (between band b and b+1): powerAbove.
    double prevUpper = 1.0;  // fraction of power above the edge below band 0 (there is none)
    for (int b = 0; b < kNumBands; ++b) {
      const double upper =
          b < kNumBands - 1 ? powerAbove(f, bandCentreExactHz(b) * std::numbers::sqrt2) : 0.0;
      const double power = prevUpper - upper;  // in band b: above edge b-1, below edge b
      gains_[size_t(b)][k] = float(std::sqrt(std::max(0.0, power)));
      prevUpper = upper;
    }
  }
}

BandFilterData BandFilterData::compute(const OctaveBandMasks& masks, size_t fftSize) {
  BandFilterData d;
  const size_t nbins = masks.binCount();
  for (int b = 0; b < kNumBands; ++b) {
    double norm = 0.0, share = 0.0;
    for (size_t k = 0; k < nbins; ++k) {
      const double m2 = double(masks.gain(b, k)) * masks.gain(b, k);
      norm += m2;
      share += ((k == 0 || k == nbins - 1) ? 1.0 : 2.0) * m2 / double(fftSize);
    }
    d.share[size_t(b)] = share;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        const int bi = b + i - 1, bj = b + j - 1;
        if (bi < 0 || bj < 0 || bi >= kNumBands || bj >= kNumBands) continue;
        double c = 0.0;
        for (size_t k = 0; k < nbins; ++k) {
          const double m2 = double(masks.gain(b, k)) * masks.gain(b, k);
          c += m2 * double(masks.gain(bi, k)) * masks.gain(bi, k) * double(masks.gain(bj, k)) *
               masks.gain(bj, k);
        }
        d.coupling[size_t(b)][size_t(i)][size_t(j)] = c / norm;
      }
  }
  return d;
}

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

BandEnvelope::BandEnvelope(int sampleRate, const std::vector<float>& sequence, size_t length,
                           const BandFilterData& filters,
                           const std::array<std::vector<float>, kRealisedBands>& measured)
    : sampleRate_(sampleRate), length_(length), filters_(&filters) {
  for (int b = 0; b < kNumBands; ++b) {
    const size_t bi = size_t(b);
    binSamples_[bi] = binSamplesFor(sampleRate, b);
    const size_t nb = (length_ + binSamples_[bi] - 1) / binSamples_[bi];
    // Expected measured energy of s_b per bin: the pulses' energy in the bin times beta_b
    // (cross terms between pulses have random signs and vanish on average). Using the pulse
    // energy rather than the realised filtered energy keeps the gains of all bands moving
    // together from bin to bin, so neighbouring bands stay coherent in their crossovers.
    sequenceEnergy_[bi].assign(nb, 0.0);
    if (b < kRealisedBands) {
      const std::vector<float>& m = measured[bi];
      for (size_t n = 0; n < length_ && n < m.size(); ++n)
        sequenceEnergy_[bi][n / binSamples_[bi]] += double(m[n]) * m[n];
    } else {
      for (size_t n = 0; n < length_ && n < sequence.size(); ++n)
        sequenceEnergy_[bi][n / binSamples_[bi]] +=
            double(sequence[n]) * sequence[n] * filters.share[bi];
    }
    target_[bi].assign(nb, 0.0);
    gain_[bi].assign(nb, 0.f);
    wanted_[bi].assign(nb, 0.f);
  }
}

BandEnvelope::BandEnvelope(int sampleRate, const std::vector<float>& sequence, size_t length,
                           const BandFilterData& filters, Realised realised)
    : BandEnvelope(sampleRate, sequence, length, filters,
                   std::array<std::vector<float>, kRealisedBands>{}) {
  // The expectation form's e_b[j] (pulses' energy x beta_b) stays: it tells which bins hold a
  // pulse and gives the first guess of the gains.
  // The delegated constructor had no measured signals for the lowest bands: fill them in.
  for (int b = 0; b < kRealisedBands; ++b)
    for (size_t n = 0; n < length_ && n < sequence.size(); ++n)
      sequenceEnergy_[size_t(b)][n / binSamples_[size_t(b)]] +=
          double(sequence[n]) * sequence[n] * filters.share[size_t(b)];
  realised_ = std::move(realised);
  useRealised_ = true;
}

size_t BandEnvelope::binSamplesFor(int sampleRate, int b) {
  const size_t base = std::max<size_t>(1, size_t(std::lround(1e-3 * sampleRate)));
  const double want = 2.0 * sampleRate / bandCentreExactHz(b);  // two periods, samples
  size_t w = base;
  while (double(w) < want - 1e-9) w *= 2;
  return w;
}

void BandEnvelope::targets(const EnergyResponse& energy) {
  const double samplesPerBin = energy.binSeconds() * sampleRate_;
  for (int b = 0; b < kNumBands; ++b) {
    const size_t bi = size_t(b);
    auto& target = target_[bi];
    std::fill(target.begin(), target.end(), 0.0);
    const size_t nb = target.size();
    for (size_t k = 0; k < energy.binCount(); ++k) {
      const float e = energy.bins()[k][b];
      if (!(e > 0.f)) continue;  // energy is >= 0: a negative rounding residue counts as 0
      // Assign the energy bin to the synthesis bin holding its centre sample.
      const size_t n = size_t((double(k) + 0.5) * samplesPerBin);
      const size_t j = std::min(nb - 1, n / binSamples_[bi]);
      target[j] += e;
    }
    const auto& seqE = sequenceEnergy_[bi];
    size_t onset = nb;  // the band's first bin with energy
    if (!useRealised_) {
      // Expectation form (one sequence per direction, sparse early): the energy of a bin the
      // sequence leaves empty goes to the nearer bin that holds pulses, the earlier one only
      // from the band's first bin with energy on (never before the sound's onset), so that
      // the energy's centre in time stays put.
      for (size_t j = 0; j < nb; ++j)
        if (target[j] > 0.0) {
          onset = j;
          break;
        }
      size_t previous = nb;  // last bin at or after the onset holding pulses
      size_t next = onset;   // first bin after j holding pulses (nb: none), kept across j
      for (size_t j = onset; j < nb; ++j) {
        if (seqE[j] > 1e-12) {
          previous = j;
          continue;
        }
        if (target[j] == 0.0) continue;
        if (next <= j) {
          next = j + 1;
          while (next < nb && !(seqE[next] > 1e-12)) ++next;
        }
        const bool back = previous < nb && (next >= nb || j - previous <= next - j);
        if (!back && next >= nb) continue;  // no bin with pulses after it: as below
        target[back ? previous : next] += target[j];
        target[j] = 0.0;
      }
    }
    // Energy of a bin the sequence leaves empty moves on to the next bin; first-guess gains.
    double carry = 0.0;
    for (size_t j = 0; j < nb; ++j) {
      const double want = target[j] + carry;
      if (seqE[j] > 1e-12) {
        target[j] = want;
        gain_[bi][j] = float(std::sqrt(want / seqE[j]));
        carry = 0.0;
      } else {
        target[j] = 0.0;
        gain_[bi][j] = 0.f;
        carry = want;
      }
    }
    unplaced_[bi] += carry;  // after the last bin with pulses: nowhere to go
    if (!useRealised_) {
      // A bin without pulses still carries its neighbours' pulses as the band filter (and a
      // spatial synthesiser's ear filter, with its delay) spreads them; at gain 0 it would cut
      // that part of their energy, which the expected energy e_b[j] counts in the pulse's
      // bin. So from the onset on it takes the gain of the bin it handed its energy to (the
      // nearer bin with pulses, as above), and a sparse sequence's pulses sound whole.
      size_t previous = nb, next = onset;
      for (size_t j = onset; j < nb; ++j) {
        if (seqE[j] > 1e-12) {
          previous = j;
          continue;
        }
        if (next <= j) {
          next = j + 1;
          while (next < nb && !(seqE[next] > 1e-12)) ++next;
        }
        const bool back = previous < nb && (next >= nb || j - previous <= next - j);
        if (back || next < nb) gain_[bi][j] = gain_[bi][back ? previous : next];
      }
    }
  }
}

void BandEnvelope::compute(const EnergyResponse& energy) {
  unplaced_.fill(0.0);
  targets(energy);
  if (useRealised_)
    computeRealised();
  else
    computeExpected();
}

void BandEnvelope::computeRealised() {
  // Band b's measured energy in its bin j is a quadratic in g_b with the neighbours' gains
  // fixed: a g^2 + 2 h g + c, summed over the fine bins q of j, where the upper neighbour's
  // gain may change from one q to the next. Gauss-Seidel sweeps over the bands; the coupling
  // between bands is a few per cent, so four sweeps converge far below 0.1 %.
  constexpr int kSweeps = 4;
  constexpr double kGainRange = 3.0;
  for (int b = 0; b < kNumBands; ++b) first_[size_t(b)] = gain_[size_t(b)];
  for (int sweep = 0; sweep < kSweeps; ++sweep) {
    for (int b = 0; b < kNumBands; ++b) {
      const size_t bi = size_t(b);
      const auto& fine = realised_.fine[bi];
      const size_t w = binSamples_[bi];
      const size_t fw = b + 1 < kNumBands ? binSamples_[bi + 1] : w;
      const size_t perBin = w / fw;
      const bool last = sweep == kSweeps - 1;
      for (size_t j = 0; j < gain_[bi].size(); ++j) {
        const double want = target_[bi][j];
        if (want <= 0.0) continue;
        const double gLow = b > 0 ? double(gain_[bi - 1][(j * w) / binSamples_[bi - 1]]) : 0.0;
        double a = 0.0, h = 0.0, c = 0.0;
        const size_t qEnd = std::min(fine.size(), (j + 1) * perBin);
        for (size_t q = j * perBin; q < qEnd; ++q) {
          const double gHigh =
              b + 1 < kNumBands ? double(gain_[bi + 1][(q * fw) / binSamples_[bi + 1]]) : 0.0;
          const Correlations& r = fine[q];
          a += r[3];
          h += gLow * r[1] + gHigh * r[4];
          c += gLow * gLow * r[0] + 2.0 * gLow * gHigh * r[2] + gHigh * gHigh * r[5];
        }
        if (!(a > 0.0)) continue;  // keep the first guess
        const double disc = h * h - a * (c - want);
        double g = disc > 0.0 ? (-h + std::sqrt(disc)) / a : 0.0;
        // A bin whose pulses sit at its edges has little realised energy inside it; a large
        // gain there would spill into the neighbouring bins through the band filter. Keep
        // the gain within kGainRange of the expectation form's.
        const double guess = first_[bi][j];
        g = std::min(g, kGainRange * guess);
        if (g > 0.0) g = std::max(g, guess / kGainRange);
        if (g > 0.0) {
          gain_[bi][j] = float(g);
        } else {
          gain_[bi][j] = 0.f;
          if (last) unplaced_[bi] += want;
        }
      }
    }
  }
}

void BandEnvelope::computeExpected() {
  // Crossover correction: band b's measured energy in a bin is
  // sum_{i,k} g_{b+i} g_{b+k} coupling[b][i][k] times the white energy; scale g_b so that it
  // equals the uncorrected g_b^2 (what the energy response asks for). Gauss-Seidel steps.
  for (int b = 0; b < kNumBands; ++b) wanted_[size_t(b)] = gain_[size_t(b)];
  const BandCoupling& coupling = filters_->coupling;
  for (int iter = 0; iter < 3; ++iter) {
    for (int b = 0; b < kNumBands; ++b) {
      const size_t bi = size_t(b);
      const size_t w = binSamples_[bi];
      for (size_t j = 0; j < gain_[bi].size(); ++j) {
        const double target = wanted_[bi][j];
        if (target == 0.0) continue;
        const size_t centre = std::min(length_ - 1, j * w + w / 2);
        double g[3];
        for (int i = 0; i < 3; ++i) {
          const int nb = b + i - 1;
          g[i] = (nb < 0 || nb >= kNumBands)
                     ? 0.0
                     : double(gain_[size_t(nb)][centre / binSamples_[size_t(nb)]]);
        }
        double measured = 0.0;
        for (int i = 0; i < 3; ++i)
          for (int k = 0; k < 3; ++k) measured += g[i] * g[k] * coupling[bi][size_t(i)][size_t(k)];
        if (measured > 0.0) gain_[bi][j] = float(g[1] * std::sqrt(target * target / measured));
      }
    }
  }
}

void BandEnvelope::accumulateRange(const std::array<const float*, kNumBands>& bands, float* out,
                                   size_t begin, size_t end, float scale, int bandBegin,
                                   int bandEnd) const {
  end = std::min(end, length_);
  for (int b = bandBegin; b < bandEnd; ++b) {
    const size_t bi = size_t(b);
    const float* s = bands[bi];
    const size_t w = binSamples_[bi];
    for (size_t j = begin / w; j * w < end; ++j) {
      const float g = gain_[bi][j] * scale;
      if (g == 0.f) continue;
      const size_t lo = std::max(begin, j * w), hi = std::min(end, (j + 1) * w);
      for (size_t n = lo; n < hi; ++n) out[n] += g * s[n];
    }
  }
}

BandEnvelope::Realised measureRealised(int sampleRate, const std::vector<float>& sequence,
                                       size_t length, size_t nfft, const OctaveBandMasks& masks) {
  const size_t nbins = nfft / 2 + 1;
  FftwArray<float> time(nfft);
  FftwArray<fftwf_complex> spec(nbins), bandSpec(nbins);
  fftwf_plan fwd = fftwf_plan_dft_r2c_1d(int(nfft), time.p, spec.p, FFTW_ESTIMATE);
  fftwf_plan inv = fftwf_plan_dft_c2r_1d(int(nfft), bandSpec.p, time.p, FFTW_ESTIMATE);
  if (!fwd || !inv) throw std::runtime_error("measureRealised: FFTW plan failed");
  std::fill(time.p, time.p + nfft, 0.f);
  std::copy(sequence.begin(), sequence.begin() + long(std::min(length, sequence.size())), time.p);
  fftwf_execute(fwd);
  const float scale = 1.f / float(nfft);
  BandEnvelope::Realised out;
  std::array<std::vector<float>, 3> y;
  for (int b = 0; b < kNumBands; ++b) {
    for (int i = 0; i < 3; ++i) {
      const int nb = b + i - 1;
      y[size_t(i)].assign(length, 0.f);
      if (nb < 0 || nb >= kNumBands) continue;
      for (size_t k = 0; k < nbins; ++k) {
        const float g = masks.gain(b, k) * masks.gain(nb, k) * masks.gain(nb, k) * scale;
        bandSpec.p[k][0] = spec.p[k][0] * g;
        bandSpec.p[k][1] = spec.p[k][1] * g;
      }
      fftwf_execute(inv);
      y[size_t(i)].assign(time.p, time.p + length);
    }
    const size_t fw = BandEnvelope::binSamplesFor(sampleRate, std::min(b + 1, kNumBands - 1));
    auto& fine = out.fine[size_t(b)];
    fine.assign((length + fw - 1) / fw, BandEnvelope::Correlations{});
    for (size_t n = 0; n < length; ++n) {
      const double lo = y[0][n], mid = y[1][n], hi = y[2][n];
      BandEnvelope::Correlations& r = fine[n / fw];
      r[0] += lo * lo;
      r[1] += lo * mid;
      r[2] += lo * hi;
      r[3] += mid * mid;
      r[4] += mid * hi;
      r[5] += hi * hi;
    }
  }
  fftwf_destroy_plan(fwd);
  fftwf_destroy_plan(inv);
  return out;
}

double roomVolume(const Mesh& mesh) {
  if (mesh.vertices.empty()) return 1.0;
  glm::dvec3 lo(mesh.vertices[0]), hi(mesh.vertices[0]);
  for (const glm::vec3& v : mesh.vertices) {
    lo = glm::min(lo, glm::dvec3(v));
    hi = glm::max(hi, glm::dvec3(v));
  }
  const glm::dvec3 e = hi - lo;
  const double box = std::max(1.0, e.x * e.y * e.z);
  // Closed: every undirected edge is used by an even number of triangles (2 for a manifold).
  std::unordered_map<uint64_t, int> edges;
  edges.reserve(mesh.triangles.size() * 3);
  const std::vector<uint32_t> id = weldedVertexIds(mesh);  // corners written once per face
  double sixV = 0.0;
  for (const auto& t : mesh.triangles) {
    const glm::dvec3 a(mesh.vertices[t[0]]), b(mesh.vertices[t[1]]), c(mesh.vertices[t[2]]);
    sixV += glm::dot(a - lo, glm::cross(b - lo, c - lo));  // relative to lo: less rounding
    for (int i = 0; i < 3; ++i) {
      const uint64_t u = id[t[size_t(i)]], v = id[t[size_t((i + 1) % 3)]];
      ++edges[u < v ? (u << 32 | v) : (v << 32 | u)];
    }
  }
  for (const auto& [key, count] : edges)
    if (count % 2 != 0) return box;  // open mesh: no enclosed volume
  const double v = std::abs(sixV) / 6.0;
  return v >= 0.01 * box ? std::max(1.0, v) : box;
}

/// FFT buffers and plans of IrSynthesizer::cleanUp, made at construction.
IrSynthesizer::~IrSynthesizer() = default;
IrSynthesizer::IrSynthesizer(IrSynthesizer&&) noexcept = default;
IrSynthesizer& IrSynthesizer::operator=(IrSynthesizer&&) noexcept = default;

IrSynthesizer::IrSynthesizer(int sampleRate, double lengthSeconds, double roomVolume,
                             double speedOfSound, uint64_t seed)
    : sampleRate_(sampleRate) {
  if (sampleRate <= 0 || !(lengthSeconds > 0.0) || !(roomVolume > 0.0) || !(speedOfSound > 0.0) ||
      !std::isfinite(lengthSeconds) || !std::isfinite(roomVolume) || !std::isfinite(speedOfSound))
    throw std::invalid_argument("IrSynthesizer: rate, length, volume and c must be finite, > 0");
  length_ = size_t(std::ceil(lengthSeconds * sampleRate));
  const size_t margin = size_t(sampleRate / 4);  // room for the filters' tails
  const size_t nfft = nextPow2(length_ + margin);
  const size_t nbins = nfft / 2 + 1;
  const std::vector<float> seq =
      diracSequence(sampleRate, length_, roomVolume, speedOfSound, kMaxDensityPerSecond, seed);

  FftwArray<float> time(nfft);
  FftwArray<fftwf_complex> spec(nbins), bandSpec(nbins);
  fftwf_plan fwd = fftwf_plan_dft_r2c_1d(int(nfft), time.p, spec.p, FFTW_ESTIMATE);
  fftwf_plan inv = fftwf_plan_dft_c2r_1d(int(nfft), bandSpec.p, time.p, FFTW_ESTIMATE);
  if (!fwd || !inv) throw std::runtime_error("IrSynthesizer: FFTW plan failed");
  std::fill(time.p, time.p + nfft, 0.f);
  std::copy(seq.begin(), seq.end(), time.p);
  fftwf_execute(fwd);
  const OctaveBandMasks masks(sampleRate, nfft);
  filterData_ = BandFilterData::compute(masks, nfft);
  const float scale = 1.f / float(nfft);
  filterCentre_ = margin / 2;
  for (int b = 0; b < kNumBands; ++b) {
    const size_t bi = size_t(b);
    // s_b through the amplitude-complementary filter A_b = M_b^2 (sum_b A_b = 1, so equal
    // band gains give back the unfiltered, spectrally flat sequence: no coherent overlap).
    for (size_t k = 0; k < nbins; ++k) {
      const float g = masks.gain(b, k) * masks.gain(b, k) * scale;
      bandSpec.p[k][0] = spec.p[k][0] * g;
      bandSpec.p[k][1] = spec.p[k][1] * g;
    }
    fftwf_execute(inv);  // destroys bandSpec, which is rebuilt each time
    bandSequence_[bi].assign(time.p, time.p + length_);
    // Its upper half s_hi: A_b P, P the power fraction above fc (powerAbove), so that
    // s_b = s_lo + s_hi with s_lo = A_b (1 - P); the shares' energies for a white input.
    const double fc = bandCentreExactHz(b);
    std::array<double, 3> half{};
    for (size_t k = 0; k < nbins; ++k) {
      const double a = double(masks.gain(b, k)) * masks.gain(b, k);
      const double p = powerAbove(double(k) * sampleRate / double(nfft), fc);
      const float g = float(a * p) * scale;
      bandSpec.p[k][0] = spec.p[k][0] * g;
      bandSpec.p[k][1] = spec.p[k][1] * g;
      half[0] += a * (1.0 - p) * a * (1.0 - p);
      half[1] += a * (1.0 - p) * a * p;
      half[2] += a * p * a * p;
    }
    halfEnergy_[bi] = half;
    fftwf_execute(inv);
    bandSequenceHigh_[bi].assign(time.p, time.p + length_);
    tilted_[bi].assign(length_, 0.f);
    // Direct-sound filter: impulse response of A_b (zero phase), stored rotated so that
    // index filterCentre_ is time 0; its measured energy per unit amplitude is beta_b.
    for (size_t k = 0; k < nbins; ++k) {
      bandSpec.p[k][0] = masks.gain(b, k) * masks.gain(b, k) * scale;
      bandSpec.p[k][1] = 0.f;
    }
    fftwf_execute(inv);
    filter_[bi].assign(margin, 0.f);
    for (size_t i = 0; i < margin; ++i) filter_[bi][i] = time.p[(i + nfft - filterCentre_) % nfft];
  }
  fftwf_destroy_plan(fwd);
  fftwf_destroy_plan(inv);
  leveller_ = std::make_unique<BandLeveller>(
      sampleRate, length_, kFirstCleanedBand,
      BandLeveller::densityStart(sampleRate, roomVolume, speedOfSound, 10.0));
  envelope_ =
      std::make_unique<BandEnvelope>(sampleRate, seq, length_, filterData_,
                                     measureRealised(sampleRate, seq, length_, nfft, masks));
  // The analysis filters' responses to each synthesis bin of each band signal.
  size_t maxBins = 0;
  for (int b = 0; b < kNumBands; ++b) {
    const size_t bi = size_t(b);
    const double fc = bandCentreExactHz(b);
    analysed_[bi] = fc * std::numbers::sqrt2 < 0.5 * sampleRate;
    if (!analysed_[bi]) continue;
    analysis_[bi] = OctaveBandPass::design(fc, sampleRate);
    const size_t w = envelope_->binSamples(b);
    const size_t nb = (length_ + w - 1) / w;
    maxBins = std::max(maxBins, nb);
    binResponse_[bi].assign(length_, 0.f);
    binResponseEnergy_[bi].assign(nb, 0.0);
    binEndState_[bi].assign(nb, OctaveBandPass::State{});
    binResponseHigh_[bi].assign(length_, 0.f);
    binResponseCross_[bi].assign(nb, 0.0);
    binResponseHighEnergy_[bi].assign(nb, 0.0);
    binEndStateHigh_[bi].assign(nb, OctaveBandPass::State{});
    firstGain_[bi].assign(nb, 0.f);  // capacity for the per-frame copy (no allocation then)
    for (size_t j = 0; j < nb; ++j) {
      OctaveBandPass::State st{};
      double e = 0.0;
      for (size_t n = j * w; n < std::min(length_, (j + 1) * w); ++n) {
        const double y = analysis_[bi].step(bandSequence_[bi][n], st);
        binResponse_[bi][n] = float(y);
        e += y * y;
      }
      binResponseEnergy_[bi][j] = e;
      binEndState_[bi][j] = st;
      OctaveBandPass::State sh{};
      double cross = 0.0, high = 0.0;
      for (size_t n = j * w; n < std::min(length_, (j + 1) * w); ++n) {
        const double y = analysis_[bi].step(bandSequenceHigh_[bi][n], sh);
        binResponseHigh_[bi][n] = float(y);
        cross += double(binResponse_[bi][n]) * y;
        high += y * y;
      }
      binResponseCross_[bi][j] = cross;
      binResponseHighEnergy_[bi][j] = high;
      binEndStateHigh_[bi][j] = sh;
    }
  }
  // Tail energy form: the energy of the filter's zero-input response from state x is x^T Q x.
  for (int b = 0; b < kNumBands; ++b) {
    const size_t bi = size_t(b);
    if (!analysed_[bi]) continue;
    std::array<std::vector<double>, 6> resp;
    const size_t ring = size_t(sampleRate);  // 1 s: the 63 Hz filter has decayed by > 200 dB
    for (size_t i = 0; i < 6; ++i) {
      OctaveBandPass::State st{};
      st[i] = 1.0;
      resp[i].resize(ring);
      for (size_t n = 0; n < ring; ++n) {
        resp[i][n] = analysis_[bi].step(0.0, st);
        if (n % 64 == 63) OctaveBandPass::flushTiny(st);
      }
    }
    for (size_t i = 0; i < 6; ++i)
      for (size_t k = 0; k < 6; ++k) {
        double t = 0.0;
        for (size_t n = 0; n < ring; ++n) t += resp[i][n] * resp[k][n];
        tailForm_[bi][i][k] = t;
      }
  }
  // Zero-input responses over one bin from unit states, and the bin's state transition.
  for (int b = 0; b < kNumBands; ++b) {
    const size_t bi = size_t(b);
    if (!analysed_[bi]) continue;
    const size_t w = envelope_->binSamples(b);
    zeroInput_[bi].assign(6 * w, 0.0);
    for (size_t i = 0; i < 6; ++i) {
      OctaveBandPass::State st{};
      st[i] = 1.0;
      for (size_t m = 0; m < w; ++m) zeroInput_[bi][i * w + m] = analysis_[bi].step(0.0, st);
      transition_[bi][i] = st;
    }
  }
  filtered_.assign(size_t(kNumBands) / 2 * length_, 0.f);
  for (int b = 0; b < kNumBands; ++b) {
    const size_t nb = envelope_->gains(b).size();
    tiltLow_[size_t(b)].assign(nb, 1.f);
    tiltDelta_[size_t(b)].assign(nb, 0.f);
  }
  cumulativeWant_.assign(maxBins, 0.0);
}

namespace {

// The loops below are plain multiply-adds over independent lanes (common/wide_vectors.h).
constexpr size_t kHalfBands = size_t(kNumBands) / 2;
static_assert(kHalfBands == 4, "one Double4 lane per band of a parity");

/// The IR through the kHalfBands cascades (3 biquads each, transposed direct form II,
/// coefficients c[coef][section], one band per lane) side by side, sample by sample.
/// out[n * kHalfBands + lane], samples [0, end).
DPC_WIDE_VECTORS
void filterCascades(const Double4 (&c)[5][3], const float* ir, size_t end, float* out) {
  Double4 s1[3] = {}, s2[3] = {};
  const Double4 tiny = {1e-150, 1e-150, 1e-150, 1e-150}, zero = {};
  for (size_t n = 0; n < end; ++n) {
    const double in0 = double(ir[n]);
    Double4 x = {in0, in0, in0, in0};
    for (size_t k = 0; k < 3; ++k) {
      const Double4 y = c[0][k] * x + s1[k];
      s1[k] = c[1][k] * x - c[3][k] * y + s2[k];
      s2[k] = c[2][k] * x - c[4][k] * y;
      x = y;
    }
    for (size_t b = 0; b < kHalfBands; ++b) out[n * kHalfBands + b] = float(x[b]);
    if (n % 64 == 63)  // flush values far below float range (denormals would follow)
      for (size_t k = 0; k < 3; ++k) {
        s1[k] = (s1[k] < tiny && s1[k] > -tiny) ? zero : s1[k];
        s2[k] = (s2[k] < tiny && s2[k] > -tiny) ? zero : s2[k];
      }
  }
}

/// Over one synthesis bin of `count` samples, with u the filter's zero-state response to the
/// bin's tilted band signal, u = alpha uBand + gamma uHigh: v = y - gOld u + sum_i d_i basis_i
/// (the band's filter output without its own bin's old contribution, with the zero-input
/// response moved from the old state to the new, d = new - old state), accumulating
/// h += sum v u and c += sum v^2 (four interleaved partial sums). y has stride kHalfBands;
/// basis_i is basis[i * w + m].
DPC_WIDE_VECTORS
void binProducts(const float* y, const float* u, const float* uHigh, double alpha, double gamma,
                 const double* basis, size_t w, const double (&d)[6], double gOld, size_t count,
                 double& h, double& c) {
  Double4 h4 = {}, c4 = {};
  size_t m = 0;
  for (; m + 4 <= count; m += 4) {
    Double4 dr = {};
    for (size_t i = 0; i < 6; ++i) {
      const double* p = basis + i * w + m;
      const Double4 bi = {p[0], p[1], p[2], p[3]};
      dr += d[i] * bi;
    }
    const Double4 ub = {double(u[m]), double(u[m + 1]), double(u[m + 2]), double(u[m + 3])};
    const Double4 uh = {double(uHigh[m]), double(uHigh[m + 1]), double(uHigh[m + 2]),
                        double(uHigh[m + 3])};
    const Double4 uu = alpha * ub + gamma * uh;
    const Double4 yy = {double(y[m * kHalfBands]), double(y[(m + 1) * kHalfBands]),
                        double(y[(m + 2) * kHalfBands]), double(y[(m + 3) * kHalfBands])};
    const Double4 v = yy - gOld * uu + dr;
    h4 += v * uu;
    c4 += v * v;
  }
  double hh = (h4[0] + h4[1]) + (h4[2] + h4[3]), cc = (c4[0] + c4[1]) + (c4[2] + c4[3]);
  for (; m < count; ++m) {
    double dr = 0.0;
    for (size_t i = 0; i < 6; ++i) dr += d[i] * basis[i * w + m];
    const double uu = alpha * double(u[m]) + gamma * double(uHigh[m]);
    const double v = double(y[m * kHalfBands]) - gOld * uu + dr;
    hh += v * uu;
    cc += v * v;
  }
  h += hh;
  c += cc;
}

}  // namespace

void IrSynthesizer::filterBands(const float* ir, size_t end, int parity) {
  Double4 c[5][3];
  for (size_t lane = 0; lane < kHalfBands; ++lane)
    for (size_t k = 0; k < 3; ++k) {
      const Biquad& q = analysis_[2 * lane + size_t(parity)].sections[k];
      c[0][k][lane] = q.b0;
      c[1][k][lane] = q.b1;
      c[2][k][lane] = q.b2;
      c[3][k][lane] = q.a1;
      c[4][k][lane] = q.a2;
    }
  filterCascades(c, ir, end, filtered_.data());
}

void IrSynthesizer::refineOnAnalysisFilters(const EnergyResponse& energy, const DirectSound& direct,
                                            float* ir) {
  // A bin whose pulses sit at its start has little of its response inside it; cap the gain
  // at this multiple of the first guess so one bin cannot spill far into the next.
  constexpr double kGainRange = 4.0;
  missing_.fill(0.0);
  const double samplesPerBin = energy.binSeconds() * sampleRate_;
  const long directSample =
      direct.visible ? std::lround(double(direct.delaySeconds) * sampleRate_) : -1;
  // How far the refinement reaches: where every band's remaining target is negligible.
  {
    std::array<double, kNumBands> total{}, rest{};
    for (size_t k = 0; k < energy.binCount(); ++k)
      for (int b = 0; b < kNumBands; ++b) total[size_t(b)] += std::max(0.f, energy.bins()[k][b]);
    for (int b = 0; b < kNumBands; ++b)
      total[size_t(b)] += direct.visible ? direct.intensity[b] : 0.f;
    rest = total;
    refineEnd_ = 0;
    for (size_t k = 0; k < energy.binCount(); ++k) {
      bool any = false;
      for (int b = 0; b < kNumBands; ++b) {
        rest[size_t(b)] -= std::max(0.f, energy.bins()[k][b]);
        any = any || rest[size_t(b)] >= kNegligible * total[size_t(b)];
      }
      refineEnd_ = std::min(length_, size_t(double(k + 1) * samplesPerBin) + 1);
      if (!any) break;
    }
    // whole bins of the widest band, which the per-band loops may reach
    const size_t widest = envelope_->binSamples(0);
    refineEnd_ = std::min(length_, (refineEnd_ + widest - 1) / widest * widest + widest);
  }
  for (int b = 0; b < kNumBands; ++b)
    if (analysed_[size_t(b)])  // bands above Nyquist (8 kHz at 22.05 kHz) are not refined
      std::copy(envelope_->gains(b).begin(), envelope_->gains(b).end(),
                firstGain_[size_t(b)].begin());
  for (int pass = 0; pass < 2 * kRefineSweeps; ++pass) {
    const int sweep = pass / 2;
    // The filter output of the IR of every band this half-sweep updates, as it starts; each
    // band below subtracts its own part, so it sees its neighbours' leakage. Even bands, then
    // odd ones (red-black Gauss-Seidel: a band's nearest neighbours are updated between its
    // steps).
    filterBands(ir, refineEnd_, pass % 2);
    for (int b = pass % 2; b < kNumBands; b += 2) {
      const size_t bi = size_t(b);
      if (!analysed_[bi]) continue;
      std::vector<float>& gain = envelope_->gains(b);
      const size_t w = envelope_->binSamples(b);
      const size_t nb = gain.size();
      const float* s = tilted_[bi].data();
      const float* u = binResponse_[bi].data();
      const float* uHigh = binResponseHigh_[bi].data();
      const float* y = filtered_.data() + bi / 2;  // stride kHalfBands
      const double* basis = zeroInput_[bi].data();
      // Target per bin: the energy response's bins by their centre sample, plus the direct sound.
      double* want = cumulativeWant_.data();
      std::fill(want, want + nb, 0.0);
      for (size_t k = 0; k < energy.binCount(); ++k) {
        const size_t n = size_t((double(k) + 0.5) * samplesPerBin);
        want[std::min(nb - 1, n / w)] += std::max(0.f, energy.bins()[k][b]);
      }
      if (directSample >= 0 && size_t(directSample) < length_)
        want[size_t(directSample) / w] += direct.intensity[b];
      // Bins after the remaining target falls below kNegligible of the total keep their first
      // guess: what is left there moves the decay curve above it by < 0.01 dB.
      size_t stop = nb;
      {
        double total = 0.0;
        for (size_t j = 0; j < nb; ++j) total += want[j];
        double rest = total;
        for (size_t j = 0; j < nb; ++j) {
          rest -= want[j];
          if (rest < kNegligible * total) {
            stop = j + 1;
            break;
          }
        }
      }
      const auto& q = tailForm_[bi];
      auto tail = [&q](const OctaveBandPass::State& x, const OctaveBandPass::State& z) {
        double t = 0.0;
        for (size_t i = 0; i < 6; ++i)
          for (size_t k = 0; k < 6; ++k) t += x[i] * q[i][k] * z[k];
        return t;
      };
      const auto& tr = transition_[bi];
      auto advance = [&tr](const OctaveBandPass::State& x) {
        OctaveBandPass::State z{};
        for (size_t i = 0; i < 6; ++i)
          for (size_t k = 0; k < 6; ++k) z[k] += x[i] * tr[i][k];
        OctaveBandPass::flushTiny(z);
        return z;
      };
      // Forward through the bins, in state-space form: the filter's state after this band's
      // earlier bins, with the new gains (state) and with the gains the IR holds now (old);
      // within a bin the zero-input response is a sum of the 6 precomputed basis responses.
      // Each bin is charged with its whole output energy, in the bin and in the ringing that
      // follows (the tail energy of the state, x^T Q x), so a pulse at a bin's end counts in
      // full.
      OctaveBandPass::State state{}, old{};
      double wantSoFar = 0.0, gotSoFar = 0.0;  // gotSoFar: output up to bin j-1 + its tail
      for (size_t j = 0; j < stop; ++j) {
        const size_t lo = j * w, hi = std::min(length_, (j + 1) * w);
        const double gOld = gain[j];
        wantSoFar += want[j];
        gotSoFar -= tail(state, state);  // the tail is about to be measured in this bin
        double h = 0.0, c = 0.0;
        double d[6];
        for (size_t i = 0; i < 6; ++i) d[i] = state[i] - old[i];
        const double alpha = tiltLow_[bi][j], gamma = tiltDelta_[bi][j];
        binProducts(y + lo * kHalfBands, u + lo, uHigh + lo, alpha, gamma, basis, w, d, gOld,
                    hi - lo, h, c);
        OctaveBandPass::State z, zOld;
        if (hi - lo == w) {
          z = advance(state);
          zOld = advance(old);
        } else {  // a last, shorter bin
          z = state;
          zOld = old;
          for (size_t n = lo; n < hi; ++n) {
            analysis_[bi].step(0.0, z);
            analysis_[bi].step(0.0, zOld);
          }
        }
        // The bin's tilted signal: its zero-state response's energy and end state.
        OctaveBandPass::State end;
        for (size_t i = 0; i < 6; ++i)
          end[i] = alpha * binEndState_[bi][j][i] + gamma * binEndStateHigh_[bi][j][i];
        const double a = alpha * alpha * binResponseEnergy_[bi][j] +
                         2.0 * alpha * gamma * binResponseCross_[bi][j] +
                         gamma * gamma * binResponseHighEnergy_[bi][j] + tail(end, end);
        h += tail(z, end);
        c += tail(z, z) + gotSoFar;
        const double missing = wantSoFar - c;
        double g = 0.0;
        if (a > 0.0 && missing > 0.0) {
          g = (-h + std::sqrt(h * h + a * missing)) / a;
          g = std::min(g, kGainRange * double(firstGain_[bi][j]));
        }
        gotSoFar = a * g * g + 2.0 * h * g + c;
        for (size_t i = 0; i < 6; ++i) {
          state[i] = z[i] + g * end[i];
          old[i] = zOld[i] + gOld * end[i];
        }
        const float step = float(g) - gain[j];
        if (step != 0.f)
          for (size_t n = lo; n < hi; ++n) ir[n] += step * s[n];
        gain[j] = float(g);
      }
      if (sweep == kRefineSweeps - 1) missing_[bi] = std::max(0.0, wantSoFar - gotSoFar);
    }
  }
}

HalfBandDensity halfBandDensity(const EnergyResponse& energy, int band, double centreSeconds) {
  const size_t nk = energy.binCount();
  const double from = (centreSeconds - 0.5 * kTiltWindowSeconds) / energy.binSeconds();
  const double to = (centreSeconds + 0.5 * kTiltWindowSeconds) / energy.binSeconds();
  const size_t k0 = size_t(std::clamp(std::floor(from), 0.0, double(nk)));
  const size_t k1 = size_t(std::clamp(std::ceil(to), 0.0, double(nk)));
  double below = 0.0, own = 0.0, above = 0.0;
  for (size_t k = k0; k < k1; ++k) {
    const Bands& e = energy.bins()[k];
    own += std::max(0.f, e[band]);
    if (band > 0) below += std::max(0.f, e[band - 1]);
    if (band + 1 < kNumBands) above += std::max(0.f, e[band + 1]);
  }
  // Mean of exp(x L) over half an octave, x in [0, 1/2]: the log-linear density's average
  // over a half band, relative to its value at the band centre.
  auto halfMean = [](double l) {
    l = std::clamp(l, -kTiltMaxLog, kTiltMaxLog);
    return std::abs(l) < 1e-6 ? 1.0 : std::expm1(0.5 * l) / (0.5 * l);
  };
  HalfBandDensity r{1.0, 1.0};
  if (!(own > 0.0)) return r;
  // Spectral densities E / bandwidth, the neighbours' octaves being half and twice as wide.
  if (band > 0) r.low = halfMean(std::log(std::max(2.0 * below / own, 1e-300)));
  if (band + 1 < kNumBands) r.high = halfMean(std::log(std::max(0.5 * above / own, 1e-300)));
  return r;
}

void IrSynthesizer::tiltBands(const EnergyResponse& energy) {
  for (int b = 0; b < kNumBands; ++b) {
    const size_t bi = size_t(b);
    const size_t w = envelope_->binSamples(b);
    const size_t nb = tiltLow_[bi].size();
    const auto& [ll, lh, hh] = halfEnergy_[bi];
    for (size_t j = 0; j < nb; ++j) {
      const HalfBandDensity r =
          halfBandDensity(energy, b, (double(j) + 0.5) * double(w) / sampleRate_);
      const double pl = std::sqrt(r.low), ph = std::sqrt(r.high);
      // Same expected energy as the untilted s_b = s_lo + s_hi.
      const double norm =
          std::sqrt((ll + 2.0 * lh + hh) / (r.low * ll + 2.0 * pl * ph * lh + r.high * hh));
      const double alpha = pl * norm, gamma = ph * norm - alpha;
      tiltLow_[bi][j] = float(alpha);
      tiltDelta_[bi][j] = float(gamma);
      const float* s = bandSequence_[bi].data();
      const float* sh = bandSequenceHigh_[bi].data();
      float* t = tilted_[bi].data();
      const float a = float(alpha), g = float(gamma);
      for (size_t n = j * w; n < std::min(length_, (j + 1) * w); ++n) t[n] = a * s[n] + g * sh[n];
    }
  }
}

void IrSynthesizer::synthesize(const EnergyResponse& energy, const DirectSound& direct, float* ir) {
  std::fill(ir, ir + length_, 0.f);
  tiltBands(energy);
  envelope_->compute(energy);
  std::array<const float*, kNumBands> bands;
  for (int b = 0; b < kNumBands; ++b) bands[size_t(b)] = tilted_[size_t(b)].data();
  envelope_->accumulate(bands, ir);
  if (direct.visible) {
    const long n0 = std::lround(double(direct.delaySeconds) * sampleRate_);
    for (int b = 0; b < kNumBands; ++b) {
      const size_t bi = size_t(b);
      const float amp = float(std::sqrt(double(direct.intensity[b]) / filterData_.share[bi]));
      const auto& h = filter_[bi];
      for (size_t i = 0; i < h.size(); ++i) {
        const long n = n0 + long(i) - long(filterCentre_);
        if (n >= 0 && n < long(length_)) ir[n] += amp * h[i];
      }
    }
  }
  refineOnAnalysisFilters(energy, direct, ir);
  cleanUp(energy, direct, ir);
  for (int b = 0; b < kNumBands; ++b) missingBands_[b] = float(missing_[size_t(b)]);
}

void IrSynthesizer::cleanUp(const EnergyResponse& energy, const DirectSound& direct, float* ir) {
  leveller_->clearTargets();
  leveller_->addResponse(energy, Bands(1.f));
  if (direct.visible) leveller_->addDirect(direct.delaySeconds, direct.intensity);
  leveller_->apply(ir, kCleanMargin, 1.0);
}

std::array<std::vector<double>, kNumBands> expectedBandAnalysisEnergy(const EnergyResponse& energy,
                                                                      const DirectSound& direct,
                                                                      int sampleRate) {
  const double fs = double(sampleRate);
  const double w = energy.binSeconds() * fs;  // samples per response bin
  if (sampleRate <= 0 || !(w >= 1.0))
    throw std::invalid_argument("expectedBandAnalysisEnergy: rate <= 0 or bins below a sample");
  const size_t nbins = energy.binCount();
  const auto& bins = energy.bins();

  // Zero-phase impulse responses of the masks m_k and of the direct pulse, time -half..half-1
  // at index 0..2 half-1 (their crossovers span 1/3 octave, >= 20 Hz: negligible beyond 1/4 s).
  const size_t half = size_t(sampleRate / 4);
  const size_t nfft = nextPow2(2 * half);
  const size_t nspec = nfft / 2 + 1;
  const OctaveBandMasks masks(sampleRate, nfft);
  FftwArray<float> time(nfft);
  FftwArray<fftwf_complex> spec(nspec);
  fftwf_plan inv = fftwf_plan_dft_c2r_1d(int(nfft), spec.p, time.p, FFTW_ESTIMATE);
  if (!inv) throw std::runtime_error("expectedBandAnalysisEnergy: FFTW plan failed");
  std::array<double, kNumBands> density{};  // (fs/2) / B_k: band energy -> white-noise energy
  for (int k = 0; k < kNumBands; ++k)
    density[size_t(k)] = 0.5 * fs / (bandCentreExactHz(k) / std::numbers::sqrt2);
  auto impulse = [&](auto amplitudeAt) {
    for (size_t f = 0; f < nspec; ++f) {
      spec.p[f][0] = float(amplitudeAt(f) / double(nfft));
      spec.p[f][1] = 0.f;
    }
    fftwf_execute(inv);
    std::vector<double> h(2 * half);
    for (size_t i = 0; i < h.size(); ++i) h[i] = time.p[(i + nfft - half) % nfft];
    return h;
  };
  // Each band's noise in two half-octave processes (power split at fc by powerAbove), whose
  // energies follow the within-band tilt (halfBandDensity) per response bin.
  std::array<std::array<std::vector<double>, 2>, kNumBands> mask;
  std::array<std::array<double, 2>, kNumBands> halfWidth{};
  for (int k = 0; k < kNumBands; ++k)
    for (int h = 0; h < 2; ++h) {
      const double fc = bandCentreExactHz(k);
      auto share = [&](size_t f) {
        const double p = powerAbove(fs * double(f) / double(nfft), fc);
        return h == 0 ? 1.0 - p : p;
      };
      mask[size_t(k)][size_t(h)] =
          impulse([&](size_t f) { return double(masks.gain(k, f)) * std::sqrt(share(f)); });
      for (size_t f = 0; f < nspec; ++f)
        halfWidth[size_t(k)][size_t(h)] += double(masks.gain(k, f)) * masks.gain(k, f) * share(f);
    }
  std::array<std::array<std::vector<double>, 2>, kNumBands> weight;
  for (int k = 0; k < kNumBands; ++k) {
    const auto [wl, wh] = halfWidth[size_t(k)];
    for (auto& v : weight[size_t(k)]) v.assign(nbins, 1.0);
    for (size_t j = 0; j < nbins; ++j) {
      const HalfBandDensity r = halfBandDensity(energy, k, (double(j) + 0.5) * energy.binSeconds());
      const double norm = (wl + wh) / (r.low * wl + r.high * wh);
      weight[size_t(k)][0][j] = r.low * norm;
      weight[size_t(k)][1][j] = r.high * norm;
    }
  }
  std::vector<double> pulse;
  if (direct.visible)
    pulse = impulse([&](size_t f) {
      double s = 0.0;
      for (int k = 0; k < kNumBands; ++k) {
        const double m = masks.gain(k, f);
        s += m * m * std::max(0.0, double(direct.intensity[k])) * density[size_t(k)];
      }
      return std::sqrt(s);
    });
  fftwf_destroy_plan(inv);

  // The broadband onset: the band analysis integrates from the direct sound (or the first
  // arrival), so nothing before its bin counts.
  const long directSample = direct.visible ? std::lround(double(direct.delaySeconds) * fs) : -1;
  size_t onset = nbins;
  if (direct.visible) onset = std::min(nbins, size_t(std::floor(double(directSample) / w)));
  for (size_t j = 0; j < std::min(onset, nbins); ++j)
    for (int k = 0; k < kNumBands; ++k)
      if (bins[j][k] > 0.f) {
        onset = j;
        break;
      }

  // The filter's response rings on after the mask's span; 1/2 s takes the 63 Hz octave's
  // 6th-order Butterworth more than 100 dB down.
  const size_t ring = size_t(sampleRate / 2);
  const size_t span = 2 * half + ring;  // kernel samples, time -half .. half+ring-1
  const size_t wi = std::max<size_t>(1, size_t(std::lround(w)));
  // Bin offsets d = i - j at which a unit bin j feeds output bin i: from the kernel's first
  // sample (-half) to its last, one bin either side for the bin averaging.
  const long dMin = -long(half / wi) - 2, dMax = long((half + ring) / wi) + 2;
  std::vector<double> prefix(span + 1), cumulative(size_t(dMax - dMin + 2)),
      g(size_t(dMax - dMin + 1));
  std::vector<double> u(span);

  std::array<std::vector<double>, kNumBands> out;
  for (int b = 0; b < kNumBands; ++b) {
    const size_t bi = size_t(b);
    const double fc = bandCentreExactHz(b);
    if (!(fc * std::numbers::sqrt2 < 0.5 * fs)) {
      out[bi].assign(nbins, std::numeric_limits<double>::quiet_NaN());
      continue;
    }
    out[bi].assign(nbins, 0.0);
    const OctaveBandPass filter = OctaveBandPass::design(fc, fs);
    auto filtered = [&](const std::vector<double>& x) {
      OctaveBandPass::State st{};
      for (size_t n = 0; n < span; ++n) {
        u[n] = filter.step(n < x.size() ? x[n] : 0.0, st);
        if (n % 64 == 63) OctaveBandPass::flushTiny(st);
      }
    };
    for (int kh = 0; kh < 2 * kNumBands; ++kh) {
      const int k = kh / 2, part = kh % 2;
      const std::vector<double>& tilt = weight[size_t(k)][size_t(part)];
      filtered(mask[size_t(k)][size_t(part)]);
      // prefix[s]: kernel energy at times < s - half; the kernel K = density (h_b * m_k)^2.
      prefix[0] = 0.0;
      for (size_t n = 0; n < span; ++n)
        prefix[n + 1] = prefix[n] + density[size_t(k)] * u[n] * u[n];
      auto below = [&](long t) {  // kernel energy at times < t (t in samples)
        const long s = t + long(half);
        return prefix[size_t(std::clamp<long>(s, 0, long(span)))];
      };
      // cumulative[d - dMin]: output energy before the start of output bin j + d from a unit
      // energy spread evenly over bin j's wi samples; g: the part inside output bin j + d.
      for (long d = dMin; d <= dMax + 1; ++d) {
        double c = 0.0;
        for (size_t m = 0; m < wi; ++m) c += below(d * long(wi) - long(m));
        cumulative[size_t(d - dMin)] = c / double(wi);
      }
      for (long d = dMin; d <= dMax; ++d)
        g[size_t(d - dMin)] = cumulative[size_t(d + 1 - dMin)] - cumulative[size_t(d - dMin)];
      for (size_t j = 0; j < nbins; ++j) {
        const double e = bins[j][k] * tilt[j];
        if (!(e > 0.0)) continue;
        const long iLo = std::max<long>(long(onset), long(j) + dMin);
        const long iHi = std::min<long>(long(nbins) - 1, long(j) + dMax);
        for (long i = iLo; i <= iHi; ++i) out[bi][size_t(i)] += e * g[size_t(i - long(j) - dMin)];
      }
    }
    if (direct.visible) {
      filtered(pulse);
      for (size_t n = 0; n < span; ++n) {
        const long s = directSample + long(n) - long(half);
        if (s < 0) continue;
        const size_t i = size_t(std::floor(double(s) / w));
        if (i >= nbins) break;
        if (i >= onset) out[bi][i] += u[n] * u[n];
      }
    }
  }
  return out;
}

}  // namespace dpc
