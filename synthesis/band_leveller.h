// Per-band level correction of a finished impulse response, measured on the ISO 3382-1
// analysis filters (common/octave_filter.h, the filters the band analysis of an IR uses).
//
// Both IR synthesisers shape band-filtered noise with gains that step between synthesis bins.
// Every step splatters a little of its band over the whole spectrum (a step in an envelope is
// broadband), some 40-60 dB below the band; late in a large room's decay the 8 kHz band lies
// that far below the 2 kHz band, so the splatter, not the band's own signal, is what its
// analysis filter measures. The spatial synthesiser's per-direction gains are besides set in
// expectation (docs/design.md, "IR synthesis"), so a band's level in a time window follows its
// noise realisation. The leveller takes each band b >= firstBand out of the IR with its
// zero-phase amplitude-complementary filter A_b (sum_b A_b = 1), measures that part through
// b's analysis filter in kBinSeconds bins, and compares, over kWindowBins bins centred on
// each bin, with what white noise of the target band energy over A_b gives there
// (analysedPerOctave: the analysis filter's energy response to A_b, a response's band value
// being a spectral density). Where the
// ratio leaves [1 / tolerance, tolerance] the part is scaled to the nearer edge, the gain
// linear between bin centres (so the correction does not splatter itself); scaling down is
// unbounded (splatter can exceed a band by 30 dB), scaling up at most maxBoost (1: never).
// Bins before the direct sound's bin + 2 (the filter A_b spreads the direct pulse over bins
// whose target holds none of it) and before `startSample` (where the Dirac sequence holds too
// few pulses per bin for a bin's energy to stay in it) are left as they are.
//
// Construction: control/propagation thread (FFTW planning is not thread-safe); allocates
// O(nfft) with nfft = smoothFftSize(length + bandFilterTapsFrom(sampleRate, firstBand));
// throws std::invalid_argument on bad sizes. clearTargets / addResponse / addDirect / apply:
// propagation thread; no allocation; no errors.
#pragma once

#include <array>
#include <cstddef>
#include <memory>
#include <span>
#include <vector>

#include "common/bands.h"
#include "common/fftw_util.h"
#include "common/octave_filter.h"
#include "engine/energy_response.h"

namespace dpc {

class BandLeveller {
 public:
  /// Time resolution of the correction, seconds.
  static constexpr double kBinSeconds = 0.01;
  /// Bins per comparison window (centred): energy a synthesis moves between neighbouring bins
  /// (a bin without pulses passes its share on) is not taken for an error.
  static constexpr size_t kWindowBins = 5;
  /// Periods of its centre an analysis filter runs before the first bin compared (started at
  /// rest: its 3 biquads' poles, Q up to about 2.2, decay some 12 dB a period).
  static constexpr double kSettlePeriods = 16.0;

  /// sampleRate Hz; length samples of the IRs to level; bands firstBand..7 are levelled (those
  /// whose analysis filter fits below Nyquist); startSample as in the file comment.
  BandLeveller(int sampleRate, size_t length, int firstBand, size_t startSample);
  ~BandLeveller();
  BandLeveller(const BandLeveller&) = delete;
  BandLeveller& operator=(const BandLeveller&) = delete;

  /// The first sample at which a Dirac sequence of density 4 pi c^3 t^2 / V (Kuttruff eq. 4.6)
  /// holds `pulses` pulses per kBinSeconds bin by that law alone (the sequence's floor,
  /// kMinPulseDensity in synthesis/dirac_sequence.h, is not counted); roomVolume m^3,
  /// speedOfSound m/s. A room so large that this lies beyond 10^15 samples (or invalid
  /// arguments) gives 10^15: never.
  static size_t densityStart(int sampleRate, double roomVolume, double speedOfSound, double pulses);

  /// Empties the targets.
  void clearTargets();
  /// Adds weight[b] x the response's band energies (1/m^2) to the targets (any bin width; a
  /// negative bin counts as 0).
  void addResponse(const EnergyResponse& energy, const Bands& weight);
  /// The leveller's bins (kBinSeconds each) over the IR.
  size_t bins() const { return gain_.size(); }
  /// energy's band energies (1/m^2; negative counts as 0) summed into the leveller's bins:
  /// out[j] for j < bins() (resized). For addBinned: a response weighted differently for many
  /// IRs is binned once. No allocation once out has bins() elements.
  void binResponse(const EnergyResponse& energy, std::vector<Bands>& out) const;
  /// Adds weight[b] x binned[j][b] (from binResponse) to the targets; same as addResponse of
  /// the binned response.
  void addBinned(std::span<const Bands> binned, const Bands& weight);
  /// Adds one arrival's band energies (1/m^2; a negative one counts as 0) at delaySeconds to
  /// the targets (the direct sound or an exact early path). The earliest arrival marks where
  /// levelling may start (its bin and the next are not levelled). An arrival outside
  /// [0, length) is ignored.
  void addDirect(double delaySeconds, const Bands& energy);
  /// How one band is levelled: see the file comment for tolerance (>= 1, energy ratio) and
  /// maxBoost (>= 1, amplitude factor).
  struct Levelling {
    double tolerance = 1.0;
    double maxBoost = 1.0;
    bool levelled = true;  ///< false: the band is left as it is (and not analysed)
  };
  /// Levels ir (length samples) to the targets, every band alike.
  void apply(float* ir, double tolerance, double maxBoost);
  /// Levels ir (length samples) to the targets, band b as perBand[b] says (bands below
  /// firstBand are never levelled).
  void apply(float* ir, const std::array<Levelling, kNumBands>& perBand);

 private:
  /// The bands to level, and per band its first levelled bin (after the direct sound's or the
  /// first target's bin + 2, and after start_); returns their count.
  int levelledBands(std::array<int, kNumBands>& bands, std::array<size_t, kNumBands>& first) const;
  /// part_[b] = ir (whose spectrum fft_->spec holds) through A_b for the given bands.
  void splitBands(const std::array<int, kNumBands>& bands, int count);
  /// actual_[b] = what b's analysis filter measures of part_[b], per bin, from the bins a
  /// comparison window from first[b] on reads (0 before).
  void measureBands(const std::array<int, kNumBands>& bands,
                    const std::array<size_t, kNumBands>& first, int count);
  /// gain_ per bin for band b; whether any differs from 1.
  bool bandGains(size_t bi, size_t first, double tolerance, double maxBoost);
  /// ir += (g(n) - 1) part_[b], g linear between the bins' centres.
  void applyGains(size_t bi, float* ir) const;

  std::unique_ptr<FftwRealTransforms> fft_;
  int sampleRate_;
  size_t length_;
  int firstBand_;
  size_t start_;
  size_t binSamples_;
  long directSample_ = -1;
  std::array<bool, kNumBands> analysed_{};
  std::array<OctaveBandPass, kNumBands> analysis_{};
  std::array<double, kNumBands> analysedPerOctave_{};
  std::array<std::vector<float>, kNumBands> filter_;   ///< A_b / nfft on the FFT bins
  std::array<std::vector<double>, kNumBands> target_;  ///< per bin
  std::array<std::vector<double>, kNumBands> actual_;  ///< analysed energy per bin
  std::vector<float> gain_;                            ///< per bin, one band at a time
  std::vector<double> unusedEnergy_;                   ///< output of an unused filter lane
  std::array<std::vector<float>, kNumBands> part_;     ///< the IR through A_b
};

}  // namespace dpc
