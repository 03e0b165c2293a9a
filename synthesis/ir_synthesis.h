// Pressure impulse response from a band energy response: the band-filtered Dirac sequence
// method (D. Schröder, "Physically Based Real-Time Auralization of Interactive Virtual
// Environments", PhD thesis, RWTH Aachen 2011, section 5.3; reflection density after
// H. Kuttruff, "Room Acoustics", 5th ed., eq. 4.6: dN/dt = 4 pi c^3 t^2 / V).
//
// At construction a Dirac sequence s (Poisson arrivals of rate 4 pi c^3 t^2 / V, held within
// [kMinPulseDensity, kMaxDensityPerSecond], random signs; fixed per synthesiser, so successive frames' IRs differ
// only in their envelopes, never in fine structure) is split into octave bands
// s_b = a_b * s by zero-phase, amplitude-complementary band filters A_b = M_b^2, where M_b
// are power-complementary masks (sum_b M_b^2 = 1, raised-cosine crossovers 1/3 octave wide
// at the band edges fc * 2^(1/2)); sum_b A_b = 1, so neighbouring bands never add up
// coherently to more than the sequence itself.
// Each frame: ir[n] = sum_b g_b[j] s_b[n] with per-band, per-bin gains g_b[j]. The mono
// synthesiser normalises to the sequence's *realised* energy: at construction it measures, for
// every band b and time bin, the correlations of y_{b,i} = M_b A_{b+i} s (i = -1, 0, 1: what a
// band measurement with M_b sees of its own and its neighbours' band signals); each frame it
// solves, bin by bin, sum_{i,k} g_{b+i} g_{b+k} <y_{b,i}, y_{b,k}>_bin = E_b[bin] for g_b
// (Gauss-Seidel over the bands, a quadratic per bin), so the synthesised IR's band energy in
// every bin equals the energy response's exactly up to the smearing of the gain steps between
// bins by the band filters (no random-sign fluctuation, no crossover error). Energy of bins
// that hold no pulse moves to the next bin. That solve is the first guess of the refinement
// on the analysis filters: per band b, walking forward through its bins, g_b[j] is chosen so
// that the ISO 3382-1 octave filter H_b (common/octave_filter.h, the filter the band analysis
// uses) has put out, up to the end of bin j and counting the ringing its state still holds
// (x^T Q x), the energy response's cumulative energy plus the direct sound. The other bands'
// leakage through H_b's skirts and H_b's memory of earlier bins are measured on the realised
// signal, so the band analysis of the IR returns the response's decay (T30 within 1 % from
// 125 Hz up, docs/validation.md) and level; the extreme bands' shares outside the analysed
// octaves (below 44 Hz, above 11.3 kHz) carry their band's spectral density. Red-black
// Gauss-Seidel over the bands (kRefineSweeps sweeps); bins after the remaining target falls
// below kNegligible keep the first guess. Two steps serve rooms whose bands decay at very
// different rates (air absorption in large rooms): each band's spectrum is tilted within
// its octave per synthesis bin toward its neighbours' (halfBandDensity: the density
// log-linear in log frequency between band centres), and the finished IR's 4 and 8 kHz parts
// are scaled down where the gain steps of slower bands splatter into them (cleanUp). The
// spatial synthesiser, whose band signals pass through HRIRs, uses the older expectation
// form per direction and levels each ear afterwards (BandLeveller): g_b[j] =
// sqrt(E_b[j] / e_b[j]), e_b = beta_b x
// the pulses' energy in the bin (beta_b: the share of a unit impulse's energy that a band
// measurement with M_b sees), realised energy at 63/125 Hz, and a crossover correction with
// white-spectrum coupling coefficients.
// Synthesis bins are 1 ms x 2^p wide, the smallest such width holding 2 periods of the band
// centre (32 ms at 63 Hz ... 1 ms from 2 kHz up); a band's bin is a whole number of the next
// band's bins, so neighbours' gains are constant or change only at bin boundaries. The direct sound
// is added as the band filters' impulse responses at its exact sample delay, with band energies
// equal to DirectSound::intensity. Units: the IR's squared samples sum to energy in 1/m^2 relative
// to source power (so 1/(4 pi r^2) for a direct sound at r metres).
//
// Construction: control/propagation thread (FFTW plan creation is not thread-safe);
// allocates; throws std::invalid_argument on bad sizes. synthesize(): propagation thread;
// no allocation; no errors.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "common/bands.h"
#include "engine/energy_response.h"
#include "common/octave_filter.h"
#include "engine/propagation.h"
#include "scene/scene.h"

namespace dpc {

class BandLeveller;

/// Fraction of power above `edge` Hz at f Hz: a raised cosine in log2 frequency over +-1/6
/// octave around the edge (a 1/3-octave crossover); with its complement (1 - it) it splits
/// power without loss (sin^2 + cos^2 = 1). Any thread; no allocation; no errors.
double powerAbove(double f, double edge);

/// Within-band spectral tilt, shared by IrSynthesizer and expectedBandAnalysisEnergy: the
/// spectral density (band energy / octave width) taken log-linear in log frequency between
/// octave-band centres, as air absorption and most materials change smoothly with frequency.
/// From the response's energies of the octaves below, at and above `band` over
/// kTiltWindowSeconds centred on centreSeconds: the mean density of the octave's lower and
/// upper halves relative to the density at its centre, mean over x in [0, 1/2] of
/// (D_{band-1} / D_band)^x and (D_{band+1} / D_band)^x (log ratio clamped to +-kTiltMaxLog).
/// 1 for a missing neighbour (63 Hz below, 8 kHz above) or an octave without energy there.
/// Any thread; no allocation; no errors.
struct HalfBandDensity {
  double low, high;
};
inline constexpr double kTiltWindowSeconds = 0.02;
inline constexpr double kTiltMaxLog = 10.0;  ///< a density ratio of e^10 (43 dB)
HalfBandDensity halfBandDensity(const EnergyResponse& energy, int band, double centreSeconds);

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

/// Lowest Dirac-sequence density, pulses per second. The law 4 pi c^3 t^2 / V alone leaves an
/// open scene (V its bounding box, 10^8 m^3 for a 2 km square) without a pulse for the first
/// second, so every early reflection's energy would wait for a pulse up to a second later and
/// be heard as an echo; at 100 pulses/s the next pulse is 10 ms away on average, well inside
/// the echo threshold (about 50 ms). The floor changes the law only before
/// t = sqrt(100 V / (4 pi c^3)): 6 ms in 200 m^3, 54 ms in 15,000 m^3. Bins without energy
/// leave their pulses silent, so a denser carrier adds no sound of its own.
inline constexpr double kMinPulseDensity = 100.0;

/// A Dirac sequence (Poisson arrivals of rate 4 pi c^3 t^2 / V per second held within
/// [kMinPulseDensity, maxDensity], random signs), `length` samples. Any thread; allocates.
std::vector<float> diracSequence(int sampleRate, size_t length, double roomVolume,
                                 double speedOfSound, double maxDensity, uint64_t seed);

/// Gains g_b[j] per band and synthesis bin that give the band-filtered parts of one Dirac
/// sequence the band energies of an energy response (in expectation over the sequence's
/// signs): g_b[j] = sqrt(E_b[j] / e_b[j]), e_b[j] = beta_b x the pulses' energy in bin j, then
/// the crossover correction. Synthesis bins are max(1 ms, 2 periods of the band centre). The
/// energy of a bin without pulses goes to the next bin with pulses (realised form) or to the
/// nearer one, the earlier one only from the band's first bin with energy on (expectation
/// form: the spatial synthesiser's sparse per-direction sequences, where the next pulse can
/// lie tens of milliseconds on early in a large room).
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
  /// Correlations per fine bin of band b (width: the next band's bin, or b's own for the top
  /// band): {<y-,y->, <y-,y0>, <y-,y+>, <y0,y0>, <y0,y+>, <y+,y+>} with y_i = M_b A_{b+i} s.
  using Correlations = std::array<double, 6>;
  struct Realised {
    std::array<std::vector<Correlations>, kNumBands> fine;
  };
  /// Realised normalisation (mono synthesis): `realised` from measureRealised().
  BandEnvelope(int sampleRate, const std::vector<float>& sequence, size_t length,
               const BandFilterData& filters, Realised realised);
  /// Synthesis bin width of band b in samples at sampleRate (see the file comment).
  static size_t binSamplesFor(int sampleRate, int b);

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
  /// Band b's gains g_b[j] of the last compute(), one per synthesis bin (the synthesiser's
  /// refinement on the analysis filters rewrites them).
  std::vector<float>& gains(int b) { return gain_[size_t(b)]; }
  /// Energy of the last compute() that no gain could place (a bin whose neighbours' crossover
  /// spill alone exceeds its target, or energy after the sequence's last pulse), summed over
  /// bins, per band, in the response's unit.
  const std::array<double, kNumBands>& unplacedEnergy() const { return unplaced_; }

 private:
  void targets(const EnergyResponse& energy);
  void computeExpected();
  void computeRealised();
  int sampleRate_;
  size_t length_;
  const BandFilterData* filters_;  ///< owned by the synthesiser, outlives the envelope
  std::array<size_t, kNumBands> binSamples_{};
  std::array<std::vector<double>, kNumBands> sequenceEnergy_;  ///< e_b[j]
  std::array<std::vector<double>, kNumBands> target_;          ///< scratch: E_b[j]
  std::array<std::vector<float>, kNumBands> gain_;             ///< g_b[j]
  std::array<std::vector<float>, kNumBands> wanted_;           ///< scratch: uncorrected g_b[j]
  std::array<std::vector<float>, kNumBands> first_;            ///< scratch: first-guess g_b[j]
  Realised realised_;                                          ///< empty: expectation form
  bool useRealised_ = false;
  std::array<double, kNumBands> unplaced_{};
};

/// The realised correlations of `sequence` (length samples) for BandEnvelope: 3 band
/// measurements per band by FFT (nfft >= length + filter margin). Allocates; any thread that
/// may plan FFTW (not thread-safe: control/propagation thread).
BandEnvelope::Realised measureRealised(int sampleRate, const std::vector<float>& sequence,
                                       size_t length, size_t nfft, const OctaveBandMasks& masks);

/// Volume for the reflection-density law, m^3: the enclosed volume of a closed mesh by the
/// divergence theorem, V = |sum_triangles v0 . (v1 x v2)| / 6 (exact for any closed,
/// consistently oriented triangle mesh; edges matched by vertex position, weldedVertexIds);
/// for a mesh with boundary edges (an open scene) or a volume below 1 % of the bounding box,
/// the bounding-box volume. At least 1 m^3. Any thread;
/// allocates a temporary edge table; no errors.
double roomVolume(const Mesh& mesh);

class IrSynthesizer {
 public:
  /// Dirac sequence density cap, pulses per second (Schröder 2011 uses about this order).
  static constexpr double kMaxDensityPerSecond = 10000.0;
  /// Gauss-Seidel sweeps over the bands of the refinement on the analysis filters (a band's
  /// gains change the leakage its neighbours see).
  static constexpr int kRefineSweeps = 2;

  /// sampleRate in Hz; lengthSeconds of the IR; roomVolume in m^3 (density law: roomVolume()
  /// of the scene's mesh); speedOfSound m/s; seed for the Dirac sequence.
  IrSynthesizer(int sampleRate, double lengthSeconds, double roomVolume, double speedOfSound,
                uint64_t seed);
  ~IrSynthesizer();
  IrSynthesizer(IrSynthesizer&&) noexcept;
  IrSynthesizer& operator=(IrSynthesizer&&) noexcept;

  /// Bands whose synthesised part is cleaned of the other bands' splatter (see cleanUp):
  /// the two highest, 4 and 8 kHz, where air absorption makes the decay much faster than the
  /// band below's.
  static constexpr int kFirstCleanedBand = 6;
  /// A band's part is cleaned only where its analysed energy exceeds the expected by this
  /// factor (1 dB): below it, the refinement's own adjustments for the analysis filters stand.
  static constexpr double kCleanMargin = 1.26;

  size_t lengthSamples() const { return length_; }
  int sampleRate() const { return sampleRate_; }

  /// Writes lengthSamples() samples of pressure IR to ir. energy: the frame's energy
  /// response (any bin width; a bin below 0, which no energy is, counts as 0); direct: the
  /// analytic direct sound (ignored when not visible).
  void synthesize(const EnergyResponse& energy, const DirectSound& direct, float* ir);

  /// Fraction of a unit impulse's energy that a band measurement (mask M_b) puts in band b.
  double bandFilterEnergy(int b) const { return filterData_.share[size_t(b)]; }
  /// Impulse response of the amplitude-complementary band filter A_b (zero phase), with time
  /// 0 at index filterCentre().
  const std::vector<float>& bandFilter(int b) const { return filter_[size_t(b)]; }
  size_t filterCentre() const { return filterCentre_; }
  /// Per band, the energy (1/m^2, the response's unit) of the last synthesize()'s energy
  /// response plus direct sound that the IR's analysis-filter output lacks at its end: energy
  /// no gain could place (a bin whose earlier bins' ringing and the neighbours' leakage
  /// already exceed the target, or the gain cap). Zero when the synthesis is exact.
  const Bands& missingEnergy() const { return missingBands_; }

 private:
  /// Per band, walking forward through its synthesis bins, chooses the bin's gain so that the
  /// ISO 3382-1 analysis filter's output (octave_filter.h) holds, up to the bin's end, the
  /// energy response's cumulative energy: the filter's causal memory of earlier bins and the
  /// other bands' leakage through its skirts are measured, not estimated. Rewrites the
  /// envelope's gains and ir.
  void refineOnAnalysisFilters(const EnergyResponse& energy, const DirectSound& direct, float* ir);
  /// filtered_[n * kNumBands / 2 + b / 2] = ir through band b's analysis filter, samples
  /// [0, end), for the bands b of the given parity (0: even, 1: odd).
  void filterBands(const float* ir, size_t end, int parity);
  /// Shapes each band's spectrum within the octave, per synthesis bin, after the energy
  /// response's neighbouring bands: the spectral density (band energy / octave width) is
  /// taken log-linear in log frequency between band centres (air absorption and most
  /// materials change smoothly with frequency), so the band's upper half carries
  /// mean_{x in [0, 1/2]} (D_{b+1} / D_b)^x and its lower half likewise toward D_{b-1},
  /// scaled to keep the band's expected energy. Without it, a band decaying much slower than
  /// the band above (4 kHz under 8 kHz in a large hall: air absorption) keeps its slow decay
  /// up to its upper edge, where the octave above's analysis filter passes it. The band
  /// energies over kTiltWindowSeconds around each bin set the ratios (halfBandDensity).
  /// Fills tiltLow_, tiltDelta_ and tilted_.
  void tiltBands(const EnergyResponse& energy);
  /// Cleans the bands b >= kFirstCleanedBand of the finished IR of the slower bands' gain-step
  /// splatter (BandLeveller, synthesis/band_leveller.h: scale-down only, kCleanMargin tolerance,
  /// from where the Dirac sequence holds 10 pulses per bin). Without it the 8 kHz T30 of a
  /// large hall's IR reads twice the response's.
  void cleanUp(const EnergyResponse& energy, const DirectSound& direct, float* ir);
  std::unique_ptr<BandLeveller> leveller_;  ///< does cleanUp's work
  /// Relative remaining target energy below which a band's later bins are not refined.
  static constexpr double kNegligible = 1e-6;
  size_t refineEnd_ = 0;
  std::array<std::vector<float>, kNumBands>
      firstGain_;  ///< scratch: gains before refinement  ///< samples the refinement filters

  int sampleRate_;
  size_t length_;
  BandFilterData filterData_;
  /// Analysis filter per band, and whether the band is representable (upper edge < Nyquist).
  std::array<OctaveBandPass, kNumBands> analysis_{};
  std::array<bool, kNumBands> analysed_{};
  /// Per band and synthesis bin j: u = the analysis filter's zero-state response to the bin's
  /// part of s_b (over the bin), its energy and the filter state at the bin's end.
  std::array<std::vector<float>, kNumBands> binResponse_;
  std::array<std::vector<double>, kNumBands> binResponseEnergy_;
  std::array<std::vector<OctaveBandPass::State>, kNumBands> binEndState_;
  /// Per band: Q with x^T Q x the energy of the analysis filter's zero-input response from x.
  std::array<std::array<std::array<double, 6>, 6>, kNumBands> tailForm_{};
  std::array<double, kNumBands> missing_{};
  Bands missingBands_{};
  /// Per band, the analysis filter's zero-input response over one synthesis bin (w samples)
  /// from each unit state: zeroInput_[b][i * w + m], and the state after w steps: transition_.
  std::array<std::vector<double>, kNumBands> zeroInput_;
  std::array<std::array<OctaveBandPass::State, 6>, kNumBands> transition_{};
  std::vector<float> filtered_;  ///< scratch: the IR through one parity's band filters, band-major
  std::vector<double> cumulativeWant_;  ///< scratch: target energy per bin
  std::unique_ptr<BandEnvelope> envelope_;
  std::array<std::vector<float>, kNumBands> bandSequence_;  ///< s_b, length_ samples
  /// Within-band tilt (see tiltBands): s_hi, the upper half of s_b; per band and synthesis
  /// bin the filter's zero-state response to it, its products with u and itself, its end
  /// state; <s_lo,s_lo>, <s_lo,s_hi>, <s_hi,s_hi> for a white input; the bins' weights alpha
  /// (s_b) and gamma (s_hi); and the tilted band signals alpha s_b + gamma s_hi.
  std::array<std::vector<float>, kNumBands> bandSequenceHigh_;
  std::array<std::vector<float>, kNumBands> binResponseHigh_;
  std::array<std::vector<double>, kNumBands> binResponseCross_, binResponseHighEnergy_;
  std::array<std::vector<OctaveBandPass::State>, kNumBands> binEndStateHigh_;
  std::array<std::array<double, 3>, kNumBands> halfEnergy_{};
  std::array<std::vector<float>, kNumBands> tiltLow_, tiltDelta_;
  std::array<std::vector<float>, kNumBands> tilted_;
  std::array<std::vector<float>, kNumBands> filter_;  ///< a_b, centred at filterCentre_
  size_t filterCentre_ = 0;
};

}  // namespace dpc

namespace dpc {

/// What the ISO 3382-1 band analysis (the OctaveBandPass filters of analyzeImpulseResponse in
/// analysis/room_parameters.h) reads, in expectation, from an impulse response that carries the
/// energy response exactly: per octave b, the expected energy of the IR through b's analysis
/// filter in each of the response's time bins. Use it to compare a simulated energy response
/// with parameters measured from real IRs, and to separate what the analysis filters do to any
/// IR (their delay of 16 ms at 63 Hz halving per octave, their skirts passing neighbouring
/// octaves, their noise bandwidth 4.7 % above the octave) from what a synthesis adds.
///
/// The model IR: the direct sound is one zero-phase pulse at the sample nearest its delay,
/// with amplitude spectrum sqrt(sum_k M_k^2(f) E_k (fs/2) / B_k); every other bin j of band k
/// is noise of energy E_k[j] within octave k, split into two independent half-octave
/// processes x_kh = sqrt((fs/2) / B_k) m_kh * (v_kh w), w unit white noise,
/// v_kh^2 = E_k[j] t_kh[j] / (samples per bin), m_kh = M_k sqrt(1 - P) and M_k sqrt(P) (M_k
/// the zero-phase power-complementary band mask of OctaveBandMasks, P = powerAbove(f, fc_k)),
/// t_kh the within-band tilt (halfBandDensity, scaled so that the band keeps its energy),
/// B_k = fc_k / sqrt(2) the octave's width in Hz (the 63 Hz band's density continues down to
/// 0 Hz and the 8 kHz band's up to Nyquist). Its expected analysed energy is then exact: the
/// direct pulse through the filter, squared, plus sum_kh E_k t_kh (*) (fs/2)/B_k (h_b * m_kh)^2,
/// convolved at the response's bin resolution.
///
/// energy: bins of any width (>= 1 sample at sampleRate); direct: added when visible. Returns
/// out[b][j], same bins and unit as `energy` (1/m^2 relative to source power); bins before the
/// onset (the direct sound's bin, else the response's first non-zero bin) are 0, since the
/// band analysis integrates from the broadband onset; bands whose analysis filter reaches
/// Nyquist (fc sqrt(2) >= fs/2) are all NaN. Any thread that may plan FFTW (not thread-safe:
/// not beside another thread creating plans); allocates O(bins + fs); not for the audio
/// thread. Throws std::invalid_argument when sampleRate <= 0 or the bins are shorter than a
/// sample.
std::array<std::vector<double>, kNumBands> expectedBandAnalysisEnergy(const EnergyResponse& energy,
                                                                      const DirectSound& direct,
                                                                      int sampleRate);

}  // namespace dpc
