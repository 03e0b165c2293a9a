// Levels one realisation of a synthesised IR's reverberant part to its energy response, band by
// band in short windows, so that a single IR carries the response's octave parameters rather
// than scattering around them as a noise realisation does (one noise IR of a 1 s decay reads
// C80 about +-1 dB and G +-0.6 dB at 250 Hz; ISO 3382-1's just noticeable differences are 1 dB).
//
// The IR is split into power-complementary views y_b = M_b * r (the octave masks of
// common/octave_band_masks.h, sum_b M_b^2 = 1: the views' energies add up to the IR's, so
// levelling them keeps the broadband level and leaves nothing unseen whose level a noisy
// factor could inflate). Per band b in firstBand..lastBand and window, the view's energy is
// compared with what an exact IR of the response puts in that view: sum_k E_k sum_h t_kh c_bkh,
// E_k the response's band values (spectral densities, synthesis/band_filters.h), t_kh the
// within-band tilt of band k's half h (halfBandDensity, synthesis/band_tilt.h, as
// analysis/expected_band_analysis.h models it) and c_bkh = sum_f M_b^2 M_k^2 P_kh (the share of
// that half-band's white noise the view sees; P_kh = powerAbove or its complement at the band
// centre). A factor g per window, held inside it and blended into the next window's over
// kBlend of a window at each boundary, scales the view, and the correction
// sum_b M_b * ((g - 1) y_b) is added to the IR from `onset` on (nothing lands before the first
// arrival); kIterations passes (the masks smooth each correction and the views overlap, so one
// pass leaves a window short of its target).
//
// Windows. About kWindowPeriods periods of the band centre (at least kMinWindowSeconds),
// from the first arrival less the ISO 3382-1 analysis filter's delay at that band (its energy
// centroid, about one period: common/octave_filter.h), so many that 80 ms is a whole number of
// them: the analysis's C80 split then falls on a window boundary, and no window's energy is
// shared between the early and the late part by the chance of where its noise lies. Every
// window from the first arrival on is levelled, also where the Dirac sequence is still sparse.
// What a window cannot hold (too few pulses, or the fixed part's cross term, below) is carried
// into the windows after it (kCarryShare).
// Only the span up to where the response's remaining energy falls below kSpanEnergy of its
// total is levelled (beyond it the factor is 1; its last window takes the span's remainder, as
// a few samples alone estimate no energy), on the smallest of a few FFT sizes that holds it.
//
// The fixed part. The direct sound and the exact paths (placed by the caller, not levelled)
// add to a window's energy in pressure: |f + g y|^2 = F + g^2 Y + 2 g X, F and Y their views'
// energies and X their product summed over the window. X is zero in expectation but not in one
// realisation (it moved one IR's 500 Hz G by up to 0.5 dB). g solves g^2 Y + 2 g X = T, the
// window's target, so the whole IR's view holds F + T; but g stays between sqrt(T / Y) /
// kCrossLower and sqrt(T / Y) x kCrossRaise, around the factor without the fixed part. A
// positive X may lower the factor: less noise, less cross term, in any filter. A negative X
// raises it less far: the noise a larger g adds is seen by every filter (the neighbouring
// bands' views, the analysis filters, whose shapes differ), its cancellation by X in this view
// only. Raised up to 2 sqrt(T / Y), one mono IR of a small room read 250 Hz G +0.54 dB and C80
// +0.82 dB (its 500 Hz window at the direct sound held 4x its target's noise); not raised at
// all, a box's 250 Hz C80 read -0.57 dB (the cancellation there is the analysis filter's too).
// What a window then lacks in the view is carried on (kCarryShare).
//
// Construction: control/propagation thread (FFTW planning); allocates O(length) (FFT buffers
// and masks for four sizes); throws std::invalid_argument on bad sizes, std::runtime_error
// when FFTW cannot plan. level(): propagation thread; allocates only when a response has more
// bins than any before (its per-bin targets); no errors.
#pragma once

#include <array>
#include <cstddef>
#include <memory>
#include <vector>

#include "common/bands.h"
#include "common/fftw_util.h"
#include "engine/energy_response.h"
#include "synthesis/band_tilt.h"

namespace dpc {

class WindowLeveller {
 public:
  /// Window length per band: this many periods of its centre frequency (about 2 x 0.7 x 3 = 4
  /// degrees of freedom of the band's noise), but at least kMinWindowSeconds.
  static constexpr double kWindowPeriods = 3.0;
  static constexpr double kMinWindowSeconds = 0.002;
  /// Windows start at the first arrival less the analysis filter's delay, and this span (C80's
  /// split, ISO 3382-1) is a whole number of them, so no window straddles the split.
  static constexpr double kAlignedSeconds = 0.080;
  static constexpr int kIterations = 2;
  /// The share of a window over which its factor blends into the next one's.
  static constexpr double kBlend = 0.25;
  /// How far the fixed part's cross term may lower a window's factor below sqrt(target / view
  /// energy), and how far it may raise it above (see the fixed part, above).
  static constexpr double kCrossLower = 2.0;
  static constexpr double kCrossRaise = 1.5;
  /// Largest amplitude factor (either way) one pass applies to a window.
  static constexpr double kMaxFactor = 8.0;
  /// The levelled span ends where the response's remaining energy is this fraction of its
  /// total (-40 dB: what lies beyond moves no octave parameter by 0.01 dB).
  static constexpr double kSpanEnergy = 1e-4;
  /// The share of the energy pending from windows that could not hold their targets that
  /// the next window takes on (windowFactors): all in one window put one stereo IR's 250 Hz
  /// EDT 8.5 % off its share's, half per window 6.4 % (tests/apps/single_ir_fidelity_test).
  static constexpr double kCarryShare = 0.5;

  /// sampleRate Hz; IRs of `length` samples; bands firstBand..lastBand (0..7) are levelled.
  WindowLeveller(int sampleRate, size_t length, int firstBand, int lastBand);
  /// Band b's window length in samples (fractional): near kWindowPeriods periods of its
  /// centre, at least kMinWindowSeconds, kAlignedSeconds a whole number of them. Any thread.
  double windowLength(int b) const;
  /// Where band b's windows start (fractional sample) for an IR whose first arrival is at
  /// sample `onset`: that less the analysis filter's energy centroid. Any thread.
  double windowOrigin(int b, size_t onset) const {
    return double(onset) - analysisDelay_[size_t(b)];
  }
  ~WindowLeveller();
  WindowLeveller(const WindowLeveller&) = delete;
  WindowLeveller& operator=(const WindowLeveller&) = delete;

  /// Levels the reverberant part `ir` (length samples, zero before `onset`) to `energy` (any
  /// bin width; negative bins count as 0) beside `fixed` (length samples: the direct sound and
  /// exact paths that will be added to it, pressure on the IR's scale; null: none).
  void level(const EnergyResponse& energy, size_t onset, float* ir, const float* fixed = nullptr);
  /// A scratch buffer of `length` samples for the caller's fixed part: the thread that levels;
  /// allocates on the first call.
  float* fixedScratch() {
    fixedScratch_.resize(length_);
    return fixedScratch_.data();
  }

 private:
  struct View;  ///< one band's view at a reduced rate: its transforms
  struct Size;  ///< one FFT size: its transforms, masks, views and view couplings
  /// The view of a band whose mask on an n-point FFT's bins is `mask`.
  static View reducedView(const std::vector<float>& mask, size_t n);
  /// The index of the smallest size whose span covers `span` samples.
  size_t sizeFor(size_t span) const;
  /// targetDensity_[b][j]: what view b of an exact IR of `energy` holds per response bin j.
  void viewTargets(const EnergyResponse& energy, const Size& s);
  /// The span to level: up to where energy's remaining total falls below kSpanEnergy.
  size_t spanOf(const EnergyResponse& energy) const;
  /// One pass: views of the IR whose spectrum `current` holds, their factors, and the
  /// correction's spectrum added to `correction` and `current`.
  void pass(const EnergyResponse& energy, Size& s, size_t origin, size_t span);
  /// v.fft->time <- band b's view of `spectrum` (s.n / 2 + 1 bins).
  void viewOf(Size& s, int b, const fftwf_complex* spectrum);
  /// Each levelled band's view of `fixed` (length samples) into its View::fixed; none if null.
  void loadFixed(Size& s, const float* fixed);
  /// The analysis filters' delays and the per-window scratch, sized for the shortest window.
  void prepareWindows();
  /// The view (scaled) back to the spectrum: added to correction_ and current_.
  void addViewCorrection(Size& s, int b);
  /// current_ <- ir's spectrum (its first s.n samples), correction_ <- 0.
  void loadSpectrum(Size& s, const float* ir);
  /// ir += the correction's time signal, from onset on.
  void applyCorrection(Size& s, size_t onset, float* ir);
  /// Windows of `length` full-rate samples (fractional) from `origin`, `count` of them, the
  /// last up to `end` (the levelled span's end).
  struct Windows {
    double origin, length;
    size_t count;
    double end;
  };
  /// A window's factor: its noise view's energy e, the view's product with the fixed part's x,
  /// its target; between sqrt(target / e) / kCrossLower and sqrt(target / e) x kCrossRaise,
  /// within kMaxFactor of 1. e, target > 0.
  static double windowFactor(double e, double x, double target);

  /// Band b's view (v.fft->time) <- (g - 1) x the view: window factors g over [0, span) from
  /// the view's energies, its cross term with the fixed part and the targets, held per window
  /// and blended at the boundaries; windows laid from windowOrigin(b, origin).
  void windowFactors(int b, const EnergyResponse& energy, const View& v, size_t origin,
                     size_t span);
  /// windowEnergy_[i], windowCross_[i]: the view's energy and its product with the fixed
  /// part's view in window i.
  void windowEnergies(const View& v, const Windows& win, size_t span);
  /// The view <- (g - 1) x the view, g the factor_ of the windows, blended over kBlend of a
  /// window at each boundary and into 1 at the span's end (windowFactors).
  void scaleByFactors(const View& v, const Windows& win) const;

  int sampleRate_;
  size_t length_;
  int firstBand_, lastBand_;
  std::vector<std::unique_ptr<Size>> sizes_;
  std::array<std::vector<double>, kNumBands> targetDensity_;  ///< per response bin
  TiltWindowSums tilt_;  ///< viewTargets()' scratch
  std::vector<double> windowEnergy_;                          ///< per window (scratch)
  std::vector<double> windowCross_;  ///< per window: the view times the fixed part's (scratch)
  bool hasFixed_ = false;            ///< level() was given a fixed part
  std::vector<float> fixedScratch_;  ///< length samples, for the caller
  /// Per band: the ISO 3382-1 analysis filter's energy centroid (full-rate samples).
  std::array<double, kNumBands> analysisDelay_{};
  std::vector<float> factor_;                                 ///< per window (scratch)
  FftwArray<fftwf_complex> current_, correction_;             ///< spectra (largest size)
};

}  // namespace dpc
