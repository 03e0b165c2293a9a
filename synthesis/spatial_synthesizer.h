// N-channel impulse responses (stereo or binaural for N = 2) from a directional energy
// response.
//
// K fixed directions in the listener's frame each own a Dirac sequence (independent per
// direction, so the directions add up incoherently, as a diffuse field does) that is split
// into octave bands by the amplitude-complementary filters A_b and convolved, once at
// construction, with that direction's N per-channel filters (HRIR pairs, or panning gains). A
// frame then only weights those pre-convolved band signals by per-bin envelope gains
// (BandEnvelope, expectation form, synthesis/band_envelope.h), so per frame the cost is
// K x 8 bands x N channels multiply-adds per sample, with no FFT. The direct sound is placed
// with the filters for its exact direction (FFT convolution of the band-shaped impulse, made
// of the direct-sound filters a_b that the mono synthesiser uses, with each channel's filter).
// Below kDirectionalFromBand (63 and 125 Hz) the reverberant part is rendered once from the
// omnidirectional response and fed to every channel: a diffuse field is almost fully coherent
// between the ears there (sin(kd)/kd = 0.97 at 125 Hz for d = 18 cm), the HRTFs carry no
// directional cue, and K independent low-band noises would interfere with too few degrees of
// freedom to keep their band energy. All filters are diffuse-field equalised per band (divided
// by the band energy of the K directions' filters averaged over all channels), so that the
// channels' average band energy follows the mono energy response for a diffuse field (taken
// over the analysed octave: the 63 Hz and 8 kHz bands carry their octave's spectral density on
// below 44 Hz and above 11.3 kHz, as an exact IR does). Each channel's reverberant part is
// then levelled in short windows (ChannelLevelling, synthesis/channel_levelling.h: 125 Hz -
// 4 kHz for stereo, binaural and an Ambisonic IR's W, 125 Hz - 1 kHz for the other channels of
// more than two) and above on the ISO
// 3382-1 analysis filters (BandLeveller, synthesis/band_leveller.h) to its own target: sum_d E_d,b x the direction's
// weight, channelWeight(d, c)[b] as the levellers' band views see the filter (viewWeights,
// synthesis/filter_shape.h: an HRIR is not flat within an octave), plus (BandLeveller) the
// direct sound x directWeight(c)[b]; this removes the slower bands' gain-step splatter from the
// faster ones and the expectation form's realisation noise. HRIRs delay what they filter: the
// field is delayed by their mean energy centroid (fieldDelay), as the direct sound is.
// Method: the band-filtered Dirac sequence (Schröder 2011, section 5.3) per direction,
// rendered through HRTFs as virtual loudspeakers (e.g. Noisternig et al., "3D binaural sound
// reproduction using a virtual ambisonic approach", VECIMS 2003, for the virtual-loudspeaker
// idea).
//
// Binaural late fields get the HRTF set's diffuse-field interaural coherence per band: the
// two ears' band signals are mixed per frame (synthesis/coherence_match.h; 2 x length floats
// of scratch and one more pass over each directional band).
// One synthesiser serves every source: its sequences are shared, and each source reads their
// late part through its own circular shift (synthesis/late_rotation.h), so different sources'
// late fields are uncorrelated at no cost in memory or time. Construction: control/propagation thread (FFTW planning); allocates
// K x N x 8 x length floats (K x 8 x length when every filter is one tap, a gain: panning,
// Ambisonic encoding); throws std::invalid_argument on inconsistent input,
// std::runtime_error when FFTW cannot plan. synthesize(): propagation thread; does not
// allocate after the first call; no errors.
#pragma once

#include <complex>
#include <functional>
#include <glm/vec3.hpp>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "common/fftw_util.h"
#include "common/octave_band_masks.h"
#include "engine/energy_response.h"
#include "engine/propagation.h"
#include "engine/specular_paths.h"
#include "synthesis/band_envelope.h"
#include "synthesis/band_filters.h"
#include "synthesis/coherence_match.h"
#include "synthesis/mono_synthesizer.h"
#include "synthesis/spatial_directions.h"
#include "synthesis/channel_levelling.h"

namespace dpc {

class BandLeveller;

/// One direction's filter: one FIR per output channel at the synthesis rate. Panning gains
/// (one tap per channel) and HRIR pairs (left, right) are the N = 2 cases.
struct DirectionFilter {
  std::vector<std::vector<float>> channels;
};

class SpatialIrSynthesizer {
 public:
  /// Bands from this one up are rendered per direction; lower ones omnidirectionally.
  static constexpr int kDirectionalFromBand = dpc::kDirectionalFromBand;
  /// Bands whose channels are levelled in short windows (ChannelLevelling): from
  /// IrSynthesizer::kFirstLevelledBand (125 Hz) to lastWindowLevelledBand(channels). Outputs of
  /// at most kFewChannels channels (stereo, binaural) are window-levelled up to 4 kHz, two
  /// octaves more than the mono synthesis: a channel sums K directions' sequences, so its 2 and
  /// 4 kHz windows hold enough pulses, and levelled on the analysis filters over 50 ms instead,
  /// one stereo channel's 2 kHz EDT read up to 10 % off its share's (1.9 % in windows;
  /// tests/apps/single_ir_fidelity_test.cpp). Ambisonic and loudspeaker-layout outputs stop
  /// at 1 kHz as the mono synthesis does: their 2-4 kHz windows over 16 channels (AmbiX order
  /// 3) cost a quarter more synthesis, and one order-5 IR's decoded late coherence at 4 kHz
  /// read 0.16 against the HRTF set's 0.00 (tests/apps/late_coherence_test.cpp, bound 0.15).
  /// The exception: an Ambisonic IR's W (Reference::kFirstChannelPressure's channel 0), which
  /// a user reads as the omnidirectional IR, is window-levelled up to 4 kHz too (one channel of
  /// 16 at order 3); on the analysis filters its 2 and 4 kHz C80 read up to 0.53 and 0.78 dB off
  /// the response's (scripts/single_ir_fidelity.py --output ambisonics --channels 1).
  static constexpr size_t kFewChannels = 2;
  static constexpr int kLastFewChannelsWindowBand = 6;  ///< 4 kHz
  static constexpr int lastWindowLevelledBand(size_t channels) {
    return channels <= kFewChannels ? kLastFewChannelsWindowBand : IrSynthesizer::kLastLevelledBand;
  }
  /// Channel c's last window-levelled band: lastWindowLevelledBand(channelCount()), or
  /// kLastFewChannelsWindowBand for an Ambisonic IR's W. Any thread.
  int lastWindowLevelledBandOf(size_t c) const;
  /// Per-channel levelling of the bands above (BandLeveller): each band's analysed
  /// energy over 50 ms windows is brought to within this energy ratio of the channel's
  /// target, scaled up by at most kLevelMaxBoost (amplitude), from where each direction's Dirac
  /// sequence holds kLevelFromPulses pulses per 10 ms.
  static constexpr double kLevelTolerance = 1.0;
  static constexpr double kLevelMaxBoost = 2.0;
  static constexpr double kLevelFromPulses = 1.0;

  /// Fills `out` (as many channels as the constructor's filters) for an exact listener-frame
  /// direction (x forward, y left, z up); called on the thread that calls synthesize().
  using ExactFilter = std::function<void(const glm::vec3& listenerDirection, DirectionFilter& out)>;

  /// What the diffuse-field equalisation keeps at the mono energy response.
  enum class Reference {
    /// The channels' average band energy (loudspeaker pairs, ears); the omnidirectional low
    /// bands feed every channel.
    kChannelAverage,
    /// Channel 0 alone, which carries the pressure (Ambisonics' W = Y_0^0 = 1 in SN3D): it
    /// follows the mono response, the other channels keep their filters' gains relative to
    /// it, and only it receives the omnidirectional low bands (a diffuse field's first-order
    /// and higher components are incoherent with W; the K directions cannot resolve them there).
    kFirstChannelPressure,
    /// The channels' summed band energy (loudspeaker feeds with constant-power gains, sum
    /// g^2 = 1): the layout as a whole radiates the mono response. The omnidirectional low
    /// bands feed every channel some direction uses, at 1 / sqrt(their count) each.
    kChannelSum,
  };

  /// directions: K listener-frame unit vectors; filters: one DirectionFilter per direction,
  /// all with the same N >= 1 channels of 1 .. sampleRate / 4 - 1 taps; exact: the filter for
  /// any direction (direct sound). roomVolume m^3 and speedOfSound m/s set the reflection
  /// density; seed the directions' Dirac sequences.
  SpatialIrSynthesizer(int sampleRate, double lengthSeconds, double roomVolume, double speedOfSound,
                       uint64_t seed, std::vector<glm::vec3> directions,
                       const std::vector<DirectionFilter>& filters, ExactFilter exact,
                       Reference reference = Reference::kChannelAverage);
  ~SpatialIrSynthesizer();

  size_t lengthSamples() const { return length_; }
  /// N: the channels synthesize() writes.
  size_t channelCount() const { return channels_; }
  const std::vector<glm::vec3>& directions() const { return directions_; }
  /// Diffuse-field equalisation gain applied in band b (energy factor).
  double diffuseFieldGain(int b) const { return 1.0 / kappa_[size_t(b)]; }

  /// Direction d's filter's band energy for channel c (M_b^2-weighted, as a band measurement
  /// sees it) over the diffuse-field average kappa_b: what channel c's IR carries of direction
  /// d's band energy. directWeight: the same for the last visible direct sound's exact filter.
  /// omniGain: channel c's pressure gain on the omni noise below kDirectionalFromBand.
  const Bands& channelWeight(size_t d, size_t c) const { return channelWeight_[d][c]; }
  const Bands& directWeight(size_t c) const { return directWeight_[c]; }
  float omniGain(size_t c) const { return omniGains_[c]; }
  /// Binaural (two channels of HRIRs, Reference::kChannelAverage): the late field's interaural
  /// coherence match (synthesis/coherence_match.h), applied to every frame's directional
  /// bands; nullptr for other outputs.
  const CoherenceMatch* coherence() const { return coherence_.get(); }

  /// Writes lengthSamples() samples to each of the channelCount() buffers of `channels`.
  /// energy must use this synthesiser's directions (same order); direct.direction is a world
  /// vector, rotated by energy's frame. early: the frame's exact specular paths
  /// (engine/specular_paths.h), each placed like the direct sound through the exact filter of
  /// its arrival direction (the energy response holds none of their energy). Nothing is
  /// rendered before the first arrival. Allocates only when a frame has more than
  /// kReservedArrivals arrivals for the first time.
  /// lateField: which late field to render (synthesis/late_rotation.h): the index of the
  /// source (or late bus) the IR is for, so that different sources' late parts are
  /// uncorrelated; 0 is the unshifted field. The same field gives the same noise every frame.
  void synthesize(const DirectionalEnergyResponse& energy, const DirectSound& direct,
                  std::span<float* const> channels, std::span<const SpecularPath> early = {},
                  size_t lateField = 0);
  /// Runs f(0) .. f(n - 1), possibly concurrently, returning when all have returned.
  using ParallelFor = std::function<void(size_t n, const std::function<void(size_t)>& f)>;
  /// Levels the channels (the larger part of a many-channel synthesis: one FFT split and
  /// analysis per channel) in min(workers, N) groups through `parallel`, each group with a
  /// BandLeveller of its own, so the IRs are the same for any workers. Control/propagation
  /// thread, between synthesize() calls; allocates a leveller per worker beyond the first
  /// (about 11 x length floats, FFTW planning); `parallel` must stay callable while the
  /// synthesiser is used. Without it (default) every channel is levelled on the calling thread.
  void setParallelLevelling(int workers, ParallelFor parallel);
  /// Arrivals (direct sound and exact paths) per frame that need no allocation.
  static constexpr size_t kReservedArrivals = 256;
  /// A synthesiser whose synthesize() writes this one's bits, sharing its read-only band
  /// signals, filters and coherence match (K x N x 8 x length floats; K x 8 x length with gains
  /// only), with workspaces of its own (envelopes, direct-sound FFT, one leveller: about
  /// (14 + 2 N) x length floats) so the two synthesise concurrently (hybrid rendering's early
  /// parts), levelling on its calling thread. Control/propagation thread (FFTW planning), not
  /// during a synthesize() of this one; allocates; throws std::runtime_error if FFTW cannot plan.
  std::unique_ptr<SpatialIrSynthesizer> workspaceCopy() const;

 private:
  SpatialIrSynthesizer(const SpatialIrSynthesizer&);  ///< all; workspaceCopy() renews some
  using Spectrum = std::vector<std::complex<float>>;  // layout-compatible with fftwf_complex
  /// The spectrum of taps on big_'s bins.
  void spectrumOf(FftwRealTransforms& fft, const std::vector<float>& taps, Spectrum& out) const;
  /// kappa_ and channelWeight_ from every direction's filters.
  void equaliseDiffuseField(const std::vector<DirectionFilter>& filters,
                            const OctaveBandMasks& masks, FftwRealTransforms& fft);
  /// omniGains_ from reference_ and the channels the filters use.
  void setOmniGains();
  /// Direction d's sequence through A_b and its channels' filters, and its envelope.
  void directionBands(size_t d, const std::vector<float>& sequence, const DirectionFilter& filter,
                      const OctaveBandMasks& masks, FftwRealTransforms& fft);
  /// The omnidirectional low bands' sequence through A_b, and its envelope.
  void omniBands(const std::vector<float>& sequence, const OctaveBandMasks& masks,
                 FftwRealTransforms& fft, double lengthSeconds);
  /// The direct sound's FFT and the analysed-octave masks on its bins.
  void prepareDirect(size_t margin, size_t longestFilter);
  /// The omnidirectional response: the directions' low bands summed.
  void sumOmniEnergy(const DirectionalEnergyResponse& energy, size_t count);
  /// fixed_ <- the direct sound and the exact paths, each through its exact filter (addArrival;
  /// these and the direct-sound set-up are in synthesis/spatial_arrivals.cpp).
  void placeArrivals(const DirectionalEnergyResponse& energy, const DirectSound& direct,
                     std::span<const SpecularPath> early);
  /// Adds one arrival through the exact filter of its listener-frame direction, and records
  /// its per-channel band energies for the levelling.
  void addArrival(const DirectSound& arrival, const glm::vec3& listenerDirection,
                  std::span<float* const> channels);
  /// Every channel of f is one tap (a gain).
  static bool oneTap(const DirectionFilter& f);
  /// addArrival for one-tap exact filters: the band-shaped impulse in fft_->time, starting at
  /// sample n0, scaled per channel (no FFT).
  void addGainArrival(const DirectSound& direct, long n0, std::span<float* const> channels);
  /// The first arrival's sample: the direct sound's or an exact path's, or the start of the
  /// first bin with energy when that is earlier (length_ when there is nothing).
  size_t firstArrivalSample(const DirectionalEnergyResponse& energy, const DirectSound& direct,
                            std::span<const SpecularPath> early) const;
  /// Direction d's band signals for channel c (before gains_[d][c]).
  std::array<const float*, kNumBands> bandSignals(size_t d, size_t c) const;
  /// directWeight_[c] from the channel's exact-filter spectrum in fft_->band.
  void directBandWeights(size_t c);
  /// Adds every direction's enveloped band signals over [begin, end) to the channels.
  void accumulateDirections(size_t count, std::span<float* const> channels, size_t begin,
                            size_t end);
  /// The same with the coherence match: per band, both ears into earScratch_, then mixed by
  /// earMix_ into the channels.
  void accumulateMixed(size_t count, std::span<float* const> channels, size_t begin, size_t end);
  /// Where the coherence match's late part starts, after the first arrival (ISO 3382-1).
  static constexpr double kLateAfterSeconds = 0.08;
  /// earMix_ for this frame's direction energies before and from kLateAfterSeconds after
  /// the onset (sample).
  void setEarMix(const DirectionalEnergyResponse& energy, size_t count, size_t onset);
  /// Levels each channel to its target (see the file comment).
  void level(const DirectionalEnergyResponse& energy, size_t count,
             std::span<float* const> channels);

  int sampleRate_;
  Reference reference_;
  std::shared_ptr<const CoherenceMatch> coherence_;  ///< binaural only; read-only
  /// Each channel's reverberant part levelled in short windows (125 Hz - 1 kHz).
  std::shared_ptr<ChannelLevelling> channelLevelling_;
  /// This frame's mixes per band, [0] before mixSplit_ (a sample), [1] from it on.
  std::array<std::array<EarMix, kNumBands>, 2> earMix_{};
  size_t mixSplit_ = 0;
  std::array<std::vector<float>, 2> earScratch_;
  /// This frame's band energy per direction, before and from mixSplit_.
  std::vector<std::array<Bands, 2>> directionTotals_;
  std::vector<double> bandEnergy_;      ///< one band's directionTotals_
  std::vector<float> omniGains_;  ///< per channel: the omnidirectional low bands' gain
  size_t length_ = 0;
  size_t channels_ = 0;
  std::vector<glm::vec3> directions_;
  ExactFilter exact_;
  BandFilterData filterData_;
  std::array<double, kNumBands> kappa_{};
  std::vector<BandEnvelope> envelopes_;                  ///< one per direction
  std::optional<BandEnvelope> omniEnvelope_;             ///< low bands, every channel
  /// The omni sequence through A_b (read-only after construction, shared by copies).
  std::shared_ptr<std::array<std::vector<float>, kNumBands>> omniBands_;
  EnergyResponse omniEnergy_;                             ///< scratch: sum over directions
  /// bands_[d][c][b]: direction d's sequence through A_b and its channel c filter, length_
  /// samples; with gainsOnly_ (every filter one tap) one unit-filter c = 0 per direction, and
  /// gains_[d][c] the channel's tap (otherwise 1). Read-only after construction, shared.
  std::shared_ptr<std::vector<std::vector<std::array<std::vector<float>, kNumBands>>>> bands_;
  std::vector<std::vector<float>> gains_;
  bool gainsOnly_ = false;
  /// HRIRs: fieldDelay() (samples; 0 otherwise). The band signals are stored advanced by it (the
  /// gains meet the pulses they were set for) and the rendered field delayed by it again.
  size_t reverbDelay_ = 0;
  /// With gainsOnly_: one direction's enveloped signal over the current block (length_
  /// samples, the block's range used), mixed into every channel by its gain.
  std::vector<float> directionScratch_;
  std::shared_ptr<const DirectSoundFilter> direct_;
  std::shared_ptr<FftwRealTransforms> fft_;  ///< the exact arrivals' FFT convolution
  DirectionFilter exactScratch_;
  /// channelWeight_[d][c][b]: direction d's channel c filter's band energy / kappa_b;
  /// directWeight_: the same for the last direct sound's exact filter.
  std::vector<std::vector<Bands>> channelWeight_;
  /// levelWeight_[d][c][b]: the levellers' weights (viewWeights of channelWeight_).
  std::vector<std::vector<Bands>> levelWeight_;
  std::vector<Bands> directWeight_;
  /// Per channel: this frame's arrivals (length + reverbDelay_ samples), placed apart so that
  /// the window levelling sees them beside the reverberant part; pointers into them (scratch).
  std::vector<std::vector<float>> fixed_;
  std::vector<float*> fixedTo_;
  std::vector<const float*> fixedFrom_;
  std::vector<double> arrivalDelays_;  ///< this frame's arrivals, seconds
  std::vector<Bands> arrivalEnergy_;   ///< per arrival and channel: band energy as levelled
  std::vector<Bands> directMask2_;     ///< M_b^2 on the direct-sound FFT's bins
  /// Per band: [first, end) of the bins where directMask2_ is not 0 (the rest add exactly 0).
  std::array<std::pair<size_t, size_t>, kNumBands> directBins_{};
  std::array<double, kNumBands> directNorm_{};
  /// One per levelling worker (setParallelLevelling); [0] always exists.
  std::vector<std::shared_ptr<BandLeveller>> levellers_;
  size_t levelStart_ = 0;                   ///< BandLeveller's start sample
  int levelledFrom_ = kDirectionalFromBand;  ///< BandLeveller's first band
  /// lastWindowLevelledBandOf(c) for every channel: ChannelLevelling's bands.
  std::vector<int> windowBands() const;
  size_t rotationFrom_ = 0;                 ///< where late fields start to differ, samples
  ParallelFor parallel_;                    ///< empty: level on the calling thread
  std::vector<std::vector<Bands>> binned_;  ///< per direction: its response in leveller bins
};

}  // namespace dpc
