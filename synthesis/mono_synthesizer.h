// The mono pressure impulse response from a band energy response: the band-filtered Dirac
// sequence method (D. Schröder, "Physically Based Real-Time Auralization of Interactive
// Virtual Environments", PhD thesis, RWTH Aachen 2011, section 5.3).
//
// A response's band value E_b is a spectral density relative to a unit impulse's (see
// synthesis/band_filters.h): an anechoic response of 1/(4 pi r^2) in every band gives a
// scaled Dirac, and the IR's power spectrum follows the band values across each band's mask.
//
// At construction a Dirac sequence s (synthesis/dirac_sequence.h; fixed per synthesiser, so
// successive frames' IRs differ only in their envelopes, never in fine structure) is split
// into octave bands s_b = a_b * s by the amplitude-complementary band filters A_b
// (synthesis/band_filters.h). Each frame, in stages:
//  1. the within-band tilt (synthesis/band_tilt.h): each band's spectrum is tilted within its
//     octave per synthesis bin toward its neighbours';
//  2. the envelope (synthesis/band_envelope.h): per band and bin the gain that gives the
//     tilted band signal the response's band energy in expectation (one realisation's
//     readings scatter around it until stage 4 levels them);
//     ir[n] = sum_b g_b[j] s_b[n], from the first arrival on (the bin that straddles it keeps
//     its energy in its part after it: nothing is rendered before the first arrival);
//  3. the direct sound and the exact early arrivals: the band filters' impulse responses at
//     each arrival's sample delay, with band amplitudes sqrt(E_b), so a flat arrival is a
//     Dirac; placed apart first, so that
//  4. the window levelling (synthesis/window_leveller.h) brings the 125 Hz - 1 kHz views of
//     one realisation, beside those arrivals, to what an exact IR of the response puts in
//     short windows; then the arrivals are added;
//  5. the clean-up of the 4 and 8 kHz parts where the gain steps of slower bands splatter into
//     them (synthesis/band_leveller.h).
// The 63 Hz band's mask reaches down to 0 Hz and the 8 kHz band's up to Nyquist, for the
// direct sound and the reverberant part alike. Units: the IR's squared samples sum to energy
// in 1/m^2 relative to source power (so 1/(4 pi r^2) for a direct sound at r metres).
//
// Construction: control/propagation thread (FFTW plan creation is not thread-safe);
// allocates; throws std::invalid_argument on bad sizes, std::runtime_error when FFTW cannot
// plan. synthesize(): propagation thread; no allocation after the first call; no errors.
// Build::kFirstIr builds what a first IR needs and leaves two per-realisation refinements, most
// of the construction's work, to complete(): a live session's first sound comes that much
// sooner, and its following IRs are the same bits as a complete build's.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "common/bands.h"
#include "engine/energy_response.h"
#include "engine/propagation.h"
#include "engine/specular_paths.h"
#include "synthesis/band_filters.h"

namespace dpc {

class ArrivalPlacer;
class BandEnvelope;
class BandLeveller;
class TiltedBands;
class WindowLeveller;

class IrSynthesizer {
 public:
  /// Bands the band leveller treats in the finished IR (see cleanUp): 2, 4 and 8 kHz, the bands
  /// above the window levelling. 2 and 4 kHz are levelled both ways to their targets over
  /// 50 ms (one IR's 2 kHz EDT scattered 2.8 % RMS, up to 9 %, around its response without);
  /// 8 kHz is only cleaned of the slower bands' splatter (kCleanMargin), because its share above
  /// 11.3 kHz must stay the direct sound's spectrum, which scaling its noise up moves.
  static constexpr int kFirstCleanedBand = 5, kLastTwoWayBand = 6;
  /// Bands whose octave views of the reverberant part are levelled per realisation in short
  /// windows (WindowLeveller): 125 Hz .. 1 kHz, after each band's sequence was levelled to its
  /// expectation per window (TiltedBands::levelSequence, from 125 Hz up); the 125 Hz windows
  /// (24 ms) hold the single IR's band near its response where the sequence's 80 ms windows
  /// leave one realisation's scatter (ir_synthesis_test: 0.54 dB rms over seeds without, 0.32
  /// with). The 63 Hz band is normalised by realised energy per synthesis bin
  /// (BandEnvelope::kRealisedBands). From 2 kHz up the windows (2 ms) hold too few pulses in
  /// a large room: levelling them there read G +0.4 dB and C80 +0.6 dB too high on average at
  /// 4 kHz (up to +1.4 / +2.0 dB in a 3000 m^3 hall, tests/apps/single_ir_fidelity_test.cpp),
  /// where the sequence's levelling alone reads within 0.2 dB RMS.
  static constexpr int kFirstLevelledBand = 1, kLastLevelledBand = 4;
  /// A band's part is cleaned only where its analysed energy exceeds the expected by this
  /// factor (1 dB): the synthesis's own realisation noise stays.
  static constexpr double kCleanMargin = 1.26;
  /// The most the two-way bands' levelling scales a 10 ms bin up (amplitude): a bin whose
  /// realisation holds few pulses is not made of one pulse scaled far up.
  static constexpr double kTwoWayBoost = 2.0;
  /// What construction builds. kComplete: everything. kFirstIr: all but the band sequences'
  /// levelling (TiltedBands::level) and the window leveller; until complete() the IRs are
  /// unlevelled realisations, their band energies set in expectation as ever (each band's
  /// reading then scatters as one noise realisation's does: about +-0.6 dB G and +-1 dB C80
  /// at 250 Hz in a 1 s decay, window_leveller.h) and cleaned up (BandLeveller) as ever.
  enum class Build { kComplete, kFirstIr };

  /// What a synthesis writes besides the synthesiser's own state: the arrival placement, the
  /// band and window levelling and the tilted band signals. It holds nothing between
  /// synthesize() calls, so synthesisers that share it (sharesWith) may take turns with it,
  /// never at once.
  struct Workspace {
    std::shared_ptr<ArrivalPlacer> placer;
    std::shared_ptr<BandLeveller> leveller;
    std::shared_ptr<WindowLeveller> windowLeveller;  ///< null until complete()
    std::shared_ptr<std::array<std::vector<float>, kNumBands>> tilted;
  };

  /// sampleRate in Hz; lengthSeconds of the IR; roomVolume in m^3 (density law: roomVolume()
  /// of the scene's mesh, engine/room_volume.h); speedOfSound m/s; seed for the Dirac sequence.
  /// shareWith: a synthesiser of the same rate, length, volume and c whose octave masks and
  /// direct-sound filters (read only), tilted-band buffers and clean-up workspace this one uses
  /// too (they hold nothing between frames; hybrid rendering's many early synthesisers share
  /// one set); both must then synthesise on one thread, one at a time. nullptr: its own.
  IrSynthesizer(int sampleRate, double lengthSeconds, double roomVolume, double speedOfSound,
                uint64_t seed, const IrSynthesizer* shareWith = nullptr,
                Build build = Build::kComplete);
  ~IrSynthesizer();
  IrSynthesizer(IrSynthesizer&&) noexcept;
  IrSynthesizer& operator=(IrSynthesizer&&) noexcept;

  /// Builds what Build::kFirstIr left out; from then on synthesize() writes what a complete
  /// build's would, bit for bit. shareWith: as at construction (completed before this one, so
  /// that its window leveller is shared). Nothing when complete. Same threads as construction,
  /// not during a synthesize() of this synthesiser or of one sharing its workspace; allocates;
  /// throws std::runtime_error when FFTW cannot plan.
  void complete(const IrSynthesizer* shareWith = nullptr);
  bool completed() const;

  size_t lengthSamples() const { return length_; }
  int sampleRate() const { return sampleRate_; }

  /// The workspace this synthesiser writes now.
  Workspace workspace() const;
  /// Writes w from the next synthesize() on: w from a synthesiser this one sharesWith, as
  /// complete as this one, and used by no other synthesize() meanwhile. The IRs are the same
  /// bits whichever workspace writes them. Propagation thread, between synthesize() calls of
  /// this synthesiser; no allocation; no errors.
  void useWorkspace(const Workspace& w);

  /// Writes lengthSamples() samples of pressure IR to ir. energy: the frame's energy
  /// response (any bin width; a bin below 0, which no energy is, counts as 0); direct: the
  /// analytic direct sound (ignored when not visible); early: the frame's exact specular paths
  /// (engine/specular_paths.h), placed like the direct sound at their delays (the energy
  /// response holds none of their energy, so nothing is counted twice).
  void synthesize(const EnergyResponse& energy, const DirectSound& direct, float* ir,
                  std::span<const SpecularPath> early = {});

  /// Arrivals (direct sound and exact paths) per frame that need no allocation.
  static constexpr size_t kReservedArrivals = 256;

  /// Fraction of a unit impulse's energy that a band measurement (mask M_b) puts in band b.
  double bandFilterEnergy(int b) const { return filterData_.share[size_t(b)]; }
  /// The band filters a_b that place the direct sound.
  const DirectSoundFilter& directSoundFilter() const { return *direct_; }
  /// Per band, the energy (1/m^2, the response's unit) of the last synthesize()'s energy
  /// response that no gain could place (a bin whose neighbours' crossover spill alone exceeds
  /// its target, or energy after the Dirac sequence's last pulse). Zero when all is placed.
  const Bands& missingEnergy() const { return missingBands_; }

 private:
  /// The first arrival's sample: the earliest of arrivals_, or the start of the response's
  /// first bin with energy when that is earlier (a response holding energy before the direct
  /// sound). The reverberant part starts there.
  size_t firstArrivalSample(const EnergyResponse& energy) const;
  /// Samples either side of an exact arrival's sample where the reverberant part is cleared
  /// before the arrival is added: a Dirac-sequence pulse on the same sample (a few per cent of
  /// the arrivals, late in a large room) would otherwise add to or cancel the arrival's
  /// amplitude; the energy removed is at most (2 k + 1) samples of reverberation per arrival.
  static constexpr long kClearSamples = 1;
  void clearAroundArrivals(float* ir) const;
  /// Levels the bands b >= kFirstCleanedBand of the finished IR (BandLeveller, from where the
  /// Dirac sequence holds 10 pulses per bin): up to kLastTwoWayBand to the target both ways
  /// (tolerance 1, boost at most 2 in amplitude), above it scale-down only, of the slower bands'
  /// gain-step splatter (kCleanMargin). Without the clean-up the 8 kHz T30 of a large hall's IR
  /// reads twice the response's.
  void cleanUp(const EnergyResponse& energy, float* ir);
  /// Whether other's workspaces fit this synthesiser (same rate and length).
  bool sharesWith(const IrSynthesizer* other) const {
    return other && other->sampleRate_ == sampleRate_ && other->length_ == length_;
  }
  /// windowLeveller_ <- shareWith's when it fits and has one, else a new one.
  void takeWindowLeveller(const IrSynthesizer* shareWith);
  /// The FFT size of the band signals (the IR plus the band filters' reach), 2^a 3^b 5^c
  /// (smoothFftSize): 20000 points for a 164 ms early part at 48 kHz where a power of two
  /// would take 32768.
  size_t bandFftSize() const;

  int sampleRate_;
  size_t length_;
  /// The octave masks on the band signals' FFT bins (shared like the filter data).
  std::shared_ptr<const OctaveBandMasks> masks_;
  BandFilterData filterData_;
  std::unique_ptr<TiltedBands> bands_;
  std::shared_ptr<const DirectSoundFilter> direct_;
  /// Places the arrivals with direct_'s filters (shared like the leveller: a workspace).
  std::shared_ptr<ArrivalPlacer> placer_;
  std::unique_ptr<BandEnvelope> envelope_;
  std::shared_ptr<BandLeveller> leveller_;
  /// Levels the reverberant part to the response in short windows (synthesis/window_leveller.h),
  /// beside the direct sound and the exact paths.
  std::shared_ptr<WindowLeveller> windowLeveller_;
  /// Build::kFirstIr until complete(): the Dirac sequence, which the levelling scales.
  std::vector<float> sequence_;
  std::vector<Arrival> arrivals_;  ///< this frame's direct sound and exact paths
  Bands missingBands_{};
};

}  // namespace dpc
