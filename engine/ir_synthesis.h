// Pressure impulse response from a band energy response: the band-filtered Dirac sequence
// method (D. Schröder, "Physically Based Real-Time Auralization of Interactive Virtual
// Environments", PhD thesis, RWTH Aachen 2011, section 5.3; reflection density after
// H. Kuttruff, "Room Acoustics", 5th ed., eq. 4.6: dN/dt = 4 pi c^3 t^2 / V).
//
// At construction a Dirac sequence s (Poisson arrivals of rate min(4 pi c^3 t^2 / V,
// kMaxDensityPerSecond), random signs; fixed per synthesiser, so successive frames' IRs differ
// only in their envelopes, never in fine structure) is split into octave bands
// s_b = a_b * s by zero-phase, amplitude-complementary band filters A_b = M_b^2, where M_b
// are power-complementary masks (sum_b M_b^2 = 1, raised-cosine crossovers 1/3 octave wide
// at the band edges fc * 2^(1/2)); sum_b A_b = 1, so neighbouring bands never add up
// coherently to more than the sequence itself.
// Each frame: ir[n] = sum_b g_b[j] s_b[n], with g_b[j] = sqrt(E_b[j] / e_b[j]) per synthesis
// bin j (E_b from the energy response, e_b = beta_b x the pulses' energy in that bin, beta_b
// the share of a unit impulse's energy that a band measurement with M_b sees), so every
// band's energy follows the energy response in expectation over the sequence's random signs
// (energy of bins without any pulse moves to the next bin). Where neighbouring bands' gains differ,
// the crossovers would mix them; a per-bin correction (three fixed-point steps with the crossovers'
// coupling coefficients for a white spectrum) keeps each band's measured energy on target.
// Synthesis bins are max(1 ms, 2 periods of the band centre) wide. The direct sound is added as the
// band filters' impulse responses at its exact sample delay, with band energies equal to
// DirectSound::intensity. Units: the IR's squared samples sum to energy in 1/m^2 relative to source
// power (so 1/(4 pi r^2) for a direct sound at r metres).
//
// Construction: control/propagation thread (FFTW plan creation is not thread-safe);
// allocates; throws std::invalid_argument on bad sizes. synthesize(): propagation thread;
// no allocation; no errors.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "engine/bands.h"
#include "engine/energy_response.h"
#include "engine/propagation.h"

namespace dpc {

/// Zero-phase power-complementary octave-band masks on the bins 0..fftSize/2 of a real FFT.
class OctaveBandMasks {
 public:
  OctaveBandMasks(int sampleRate, size_t fftSize);
  /// |H_b| at FFT bin k (0 <= k <= fftSize/2).
  float gain(int band, size_t k) const { return gains_[size_t(band)][k]; }
  size_t binCount() const { return gains_[0].size(); }

 private:
  std::array<std::vector<float>, kNumBands> gains_;
};

/// Crossover coupling of the band masks for a white spectrum:
/// coupling[b][i][k] = sum_f M_b^2 A_{b+i-1} A_{b+k-1} / sum_f M_b^2, the share of band b's
/// measured energy that the product of the gains of bands b+i-1 and b+k-1 contributes.
using BandCoupling = std::array<std::array<std::array<double, 3>, 3>, kNumBands>;

/// The band filters' fixed data for one sample rate: coupling and each band's energy share
/// beta_b (the fraction of a unit impulse's energy that a band measurement with M_b sees).
struct BandFilterData {
  BandCoupling coupling{};
  std::array<double, kNumBands> share{};
  static BandFilterData compute(const OctaveBandMasks& masks, size_t fftSize);
};

/// A Dirac sequence (Poisson arrivals of rate min(4 pi c^3 t^2 / V, maxDensity) per second,
/// random signs), `length` samples. Any thread; allocates.
std::vector<float> diracSequence(int sampleRate, size_t length, double roomVolume,
                                 double speedOfSound, double maxDensity, uint64_t seed);

/// Gains g_b[j] per band and synthesis bin that give the band-filtered parts of one Dirac
/// sequence the band energies of an energy response (in expectation over the sequence's
/// signs): g_b[j] = sqrt(E_b[j] / e_b[j]), e_b[j] = beta_b x the pulses' energy in bin j, then
/// the crossover correction. Synthesis bins are max(1 ms, 2 periods of the band centre).
/// Construction allocates; compute() and accumulate() do not. Propagation thread.
class BandEnvelope {
 public:
  /// Bands normalised by realised rather than expected energy (63 and 125 Hz: a noise
  /// realisation there has too few degrees of freedom, e.g. 60 Hz x 0.3 s, to be near its
  /// expectation).
  static constexpr int kRealisedBands = 2;

  /// measured: for b < kRealisedBands, the sequence through M_b^3 (what a band measurement
  /// with M_b sees of the A_b-filtered sequence), length samples; e_b[j] is its energy in bin
  /// j. Other bands use the expected energy (beta_b x the pulses' energy).
  BandEnvelope(int sampleRate, const std::vector<float>& sequence, size_t length,
               const BandFilterData& filters,
               const std::array<std::vector<float>, kRealisedBands>& measured);
  /// Gains for an energy response (any bin width).
  void compute(const EnergyResponse& energy);
  /// out[n] += scale * sum_b g_b[j(n)] x_b[n] for the band signals x_b (length samples each).
  void accumulate(const std::array<const float*, kNumBands>& bands, float* out,
                  float scale = 1.f) const {
    accumulateRange(bands, out, 0, length_, scale);
  }
  /// The same for samples [begin, end) and bands [bandBegin, bandEnd) only (cache-blocked
  /// accumulation of many signals; band subsets).
  void accumulateRange(const std::array<const float*, kNumBands>& bands, float* out, size_t begin,
                       size_t end, float scale = 1.f, int bandBegin = 0,
                       int bandEnd = kNumBands) const;
  size_t binSamples(int b) const { return binSamples_[size_t(b)]; }

 private:
  int sampleRate_;
  size_t length_;
  const BandFilterData* filters_;  ///< owned by the synthesiser, outlives the envelope
  std::array<size_t, kNumBands> binSamples_{};
  std::array<std::vector<double>, kNumBands> sequenceEnergy_;  ///< e_b[j]
  std::array<std::vector<double>, kNumBands> target_;          ///< scratch: E_b[j]
  std::array<std::vector<float>, kNumBands> gain_;             ///< g_b[j]
  std::array<std::vector<float>, kNumBands> wanted_;           ///< scratch: uncorrected g_b[j]
};

class IrSynthesizer {
 public:
  /// Dirac sequence density cap, pulses per second (Schröder 2011 uses about this order).
  static constexpr double kMaxDensityPerSecond = 10000.0;

  /// sampleRate in Hz; lengthSeconds of the IR; roomVolume in m^3 (density law; the bounding
  /// box volume is an adequate estimate); speedOfSound m/s; seed for the Dirac sequence.
  IrSynthesizer(int sampleRate, double lengthSeconds, double roomVolume, double speedOfSound,
                uint64_t seed);

  size_t lengthSamples() const { return length_; }
  int sampleRate() const { return sampleRate_; }

  /// Writes lengthSamples() samples of pressure IR to ir. energy: the frame's energy
  /// response (any bin width); direct: the analytic direct sound (ignored when not visible).
  void synthesize(const EnergyResponse& energy, const DirectSound& direct, float* ir);

  /// Fraction of a unit impulse's energy that a band measurement (mask M_b) puts in band b.
  double bandFilterEnergy(int b) const { return filterData_.share[size_t(b)]; }
  /// Impulse response of the amplitude-complementary band filter A_b (zero phase), with time
  /// 0 at index filterCentre().
  const std::vector<float>& bandFilter(int b) const { return filter_[size_t(b)]; }
  size_t filterCentre() const { return filterCentre_; }

 private:
  int sampleRate_;
  size_t length_;
  BandFilterData filterData_;
  std::unique_ptr<BandEnvelope> envelope_;
  std::array<std::vector<float>, kNumBands> bandSequence_;  ///< s_b, length_ samples
  std::array<std::vector<float>, kNumBands> filter_;        ///< a_b, centred at filterCentre_
  size_t filterCentre_ = 0;
};

}  // namespace dpc
