// The mono synthesiser's refinement of its envelope gains on the ISO 3382-1 analysis filters
// H_b (common/octave_filter.h, the filters the band analysis of an IR uses).
//
// The realised-form envelope (synthesis/band_envelope.h) is the first guess. Per band b,
// walking forward through its synthesis bins, g_b[j] is chosen so that H_b has put out, up to
// the end of bin j and counting the ringing its state still holds (x^T Q x), the energy
// response's cumulative energy plus the direct sound. The other bands' leakage through H_b's
// skirts and H_b's memory of earlier bins are measured on the realised signal, so the band
// analysis of the IR returns the response's decay (T30 within 1 % from 125 Hz up,
// docs/validation.md) and level. Red-black Gauss-Seidel over the bands (kSweeps sweeps: a
// band's gains change the leakage its neighbours see); bins after the remaining target falls
// below kNegligible keep the first guess.
//
// Construction: any thread; allocates O(kNumBands x length); no errors. refine(): propagation
// thread; no allocation; no errors.
#pragma once

#include <array>
#include <cstddef>
#include <span>
#include <vector>

#include "common/bands.h"
#include "common/octave_filter.h"
#include "engine/energy_response.h"
#include "engine/propagation.h"
#include "synthesis/band_envelope.h"
#include "synthesis/band_filters.h"
#include "synthesis/band_tilt.h"

namespace dpc {

class AnalysisFilterRefinement {
 public:
  /// Gauss-Seidel sweeps over the bands.
  static constexpr int kSweeps = 2;
  /// Relative remaining target energy below which a band's later bins are not refined.
  static constexpr double kNegligible = 1e-6;
  /// A bin whose pulses sit at its start has little of its response inside it; its gain is
  /// capped at this multiple of the first guess so one bin cannot spill far into the next.
  static constexpr double kGainRange = 4.0;

  /// sampleRate Hz; length samples of the IR; bands: the synthesiser's band signals (their
  /// bins' responses through H_b are measured here).
  AnalysisFilterRefinement(int sampleRate, size_t length, const TiltedBands& bands);

  /// Rewrites envelope's gains (from its last compute(), whose bands.tilted() the IR holds)
  /// and ir (length samples) for the energy response (any bin width) and the arrivals the IR
  /// holds (direct sound, exact early paths). Samples before `onset` (the first arrival) are
  /// left as they are: the reverberant part starts there. A band value is a spectral density
  /// (synthesis/band_filters.h): band b's target is it times the filter's unit-impulse energy.
  void refine(const EnergyResponse& energy, std::span<const Arrival> arrivals, size_t onset,
              BandEnvelope& envelope, const TiltedBands& bands, float* ir);
  /// Per band, the energy (1/m^2) of the last refine()'s target that the IR's analysis-filter
  /// output lacks at its end (no gain could place it). Zero when the refinement is exact.
  const std::array<double, kNumBands>& missing() const { return missing_; }

 private:
  using State = OctaveBandPass::State;
  /// The forward walk through one band's bins: the filter's state after this band's earlier
  /// bins with the new gains (state) and with the gains the IR holds (old); the cumulative
  /// target, and the output up to the previous bin plus its tail.
  struct Walk {
    State state{}, old{};
    double wantSoFar = 0.0, gotSoFar = 0.0;
  };
  /// The bins' responses through H_b of s_b and s_hi, their energies and end states.
  void measureBinResponses(int b, const TiltedBands& bands);
  /// Q with x^T Q x the energy of H_b's zero-input response from x.
  void measureTailForm(int b);
  /// H_b's zero-input response over one bin from each unit state, and the bin's transition.
  void measureZeroInput(int b);
  /// refineEnd_: where every band's remaining target is negligible, in whole widest bins.
  void findRefineEnd(const EnergyResponse& energy, std::span<const Arrival> arrivals, size_t widestBin);
  /// filtered_[n * kNumBands / 2 + b / 2] = ir through band b's analysis filter, samples
  /// [0, end), for the bands b of the given parity (0: even, 1: odd).
  void filterBands(const float* ir, size_t end, int parity);
  /// Target per bin of band b in cumulativeWant_ (response bins by their centre sample, plus
  /// the direct sound); returns the bin after which the rest is negligible.
  size_t bandTargets(const EnergyResponse& energy, std::span<const Arrival> arrivals, int b, size_t w,
                     size_t nb);
  void refineBand(const EnergyResponse& energy, std::span<const Arrival> arrivals, int b, bool lastSweep,
                  BandEnvelope& envelope, const TiltedBands& bands, float* ir);
  /// Chooses bin j's gain (rewriting gain[j] and ir) and advances the walk.
  void refineBin(int b, size_t j, size_t w, std::vector<float>& gain, const TiltedBands& bands,
                 Walk& walk, float* ir);
  /// z and zOld (the walk's states at bin start) advanced over `count` samples of zero input
  /// (w: a whole bin).
  void zeroInputStates(size_t b, size_t count, size_t w, State& z, State& zOld) const;
  /// The zero-state response of bin j's tilted signal alpha s_b + gamma s_hi: its end state in
  /// `end`; returns its energy in the bin and in the ringing after it.
  double tiltedBin(size_t b, size_t j, double alpha, double gamma, State& end) const;
  /// x^T Q_b z.
  double tail(size_t b, const State& x, const State& z) const;
  /// The state one whole bin of zero input after x.
  State advance(size_t b, const State& x) const;

  int sampleRate_;
  size_t length_;
  size_t refineEnd_ = 0;  ///< samples the refinement filters
  /// Analysis filter per band, and whether the band is representable (upper edge < Nyquist).
  std::array<OctaveBandPass, kNumBands> analysis_{};
  std::array<bool, kNumBands> analysed_{};
  std::array<double, kNumBands> unitEnergy_{};  ///< H_b's unit-impulse energy
  size_t onset_ = 0;  ///< refine()'s onset
  /// Per band and synthesis bin j: u = the analysis filter's zero-state response to the bin's
  /// part of s_b (over the bin), its energy and the filter state at the bin's end; the same for
  /// s_hi, and <u, u_hi> per bin.
  std::array<std::vector<float>, kNumBands> binResponse_, binResponseHigh_;
  std::array<std::vector<double>, kNumBands> binResponseEnergy_, binResponseHighEnergy_;
  std::array<std::vector<double>, kNumBands> binResponseCross_;
  std::array<std::vector<State>, kNumBands> binEndState_, binEndStateHigh_;
  std::array<std::array<std::array<double, 6>, 6>, kNumBands> tailForm_{};
  /// Per band, the zero-input response over one synthesis bin (w samples) from each unit
  /// state: zeroInput_[b][i * w + m], and the state after w steps: transition_.
  std::array<std::vector<double>, kNumBands> zeroInput_;
  std::array<std::array<State, 6>, kNumBands> transition_{};
  std::array<std::vector<float>, kNumBands> firstGain_;  ///< scratch: gains before refinement
  std::vector<float> filtered_;  ///< scratch: the IR through one parity's band filters, band-major
  std::vector<double> cumulativeWant_;  ///< scratch: target energy per bin
  std::array<double, kNumBands> missing_{};
};

}  // namespace dpc
