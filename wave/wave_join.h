// Joining the wave band to the ray-traced IR: the ray-traced channel high-passed and the wave
// band low-passed at the crossover by a 3rd-order Butterworth pair (common/butterworth.h):
// power complementary (|H_lp|^2 + |H_hp|^2 = 1), so the joined IR's energy per frequency is
// the wave band's below the crossover, the ray band's above and their power mean at it (-3 dB
// each) where the bands are incoherent (the late field), and in quadrature, so their sum is
// an allpass and what both bands hold alike (the direct sound) keeps its level across the
// crossover too (an even order would add 3 dB there). For that the two bands must also be in
// phase: the wave band carries its pulse's low-pass P (4th-order Butterworth at the maximum
// frequency, wave/wave_band.h), whose phase at the crossover is large (78 degrees at half the
// maximum frequency). So the wave band is low-passed by P once more and the ray-traced band
// passed through the allpass with P's poles (twice P's phase): both then carry twice P's
// phase, and the ray band's magnitude is untouched. The cost: the joined IR's content below
// about twice the maximum frequency is delayed alike in both bands (group delay 1.7 ms at
// 0 Hz for a 500 Hz maximum). Every filter is causal, so nothing moves before the direct
// sound.
//
// How the omnidirectional wave band enters each output channel (`waveBandGain`): mono, and
// each ear of binaural output, take it whole (below a few hundred hertz the head barely shades
// one ear); stereo and loudspeaker outputs share its power equally (1 / sqrt(channels)); AmbiX
// IRs (Ambisonic output, and head-tracked binaural, whose IRs are AmbiX) put it in W (ACN 0,
// SN3D: the pressure) and nowhere else.
//
// Control thread; joinWaveBand allocates a copy of the wave band; no errors (requires
// 0 < crossoverHz < fs / 2, checked by the scene's validation). WaveBandSet: built on the
// control thread (allocates); join() runs on the propagation thread, allocation-free.
#pragma once

#include <span>
#include <vector>

#include "common/butterworth.h"
#include "common/impulse_response.h"
#include "scene/scene.h"

namespace dpc::wave {

/// Order of each crossover filter: odd, so the pair is both power and allpass complementary;
/// 18 dB per octave.
inline constexpr int kCrossoverOrder = 3;

/// The wave band's gain in output channel `channel` of `format` with `channels` channels.
double waveBandGain(OutputFormat format, int channel, int channels);

/// Order of the wave band's pulse (wave/wave_band.h) and of the phase matching above.
inline constexpr int kPulseOrder = 4;

/// The octave bands (indices into kBandCentreHz) the wave band is simulated in, one
/// simulation each with that band's absorption: those with centres up to crossoverHz, at
/// least the lowest.
std::vector<int> simulatedBands(double crossoverHz);

/// The edges between consecutive simulated bands, Hz: geometric means of their centres.
std::vector<double> bandEdges(std::span<const int> bands);

/// Band k of a split at `edges` (edges.size() + 1 bands), in place at fs Hz: the crossover's
/// high-pass at every edge below it, its low-pass at the band's upper edge, and at every edge
/// above that the allpass LP + HP. Identical inputs to every band sum to the allpass of every
/// edge (odd order: each LP + HP is one), so the split keeps each band's level and phase.
void splitBand(std::span<float> x, size_t k, std::span<const double> edges, double fs);

/// rayChannel <- HP(AP(E(rayChannel))) + gain * LP(P(wave)), over rayChannel's length (fs:
/// both signals' rate, Hz; P and AP at maxFrequencyHz; E the allpasses of the band edges of
/// simulatedBands(crossoverHz), which wave/wave_band.h's wave band carries).
void joinWaveBand(std::span<float> rayChannel, std::span<const float> wave, double gain,
                  double crossoverHz, double maxFrequencyHz, double fs);

/// One band of a blend (WaveBandSet::join): a listener of the set (a bake's probe) and its
/// weight.
struct BandWeight {
  size_t listener = 0;
  float weight = 0.f;
};

/// The wave bands of a render, each low-passed once when it is set, joined to every IR the
/// renderer synthesises for its listener-source pair.
class WaveBandSet {
 public:
  /// For `listeners` x `sources` pairs of IRs of output `format` at `fs` Hz, crossing over
  /// at crossoverHz, of wave bands simulated up to maxFrequencyHz (and split at the edges of
  /// simulatedBands(crossoverHz), whose allpass the ray band gets too).
  WaveBandSet(size_t listeners, size_t sources, OutputFormat format, double crossoverHz,
              double maxFrequencyHz, double fs);
  /// The wave band of (listener, source) (scene indices), at fs.
  void set(size_t listener, size_t source, std::span<const float> band);
  bool has(size_t listener, size_t source) const;
  /// Every channel of `ir` (the pair's ray-traced IR at fs) phase-matched and high-passed,
  /// plus its share of the low-passed wave band. No allocation.
  void join(size_t listener, size_t source, ImpulseResponse& ir) const;
  /// The same with the weighted sum of listeners' bands, sum_k w_k LP(P(band_k)) (the
  /// low-pass is linear: the band of the weighted sum), for a listener between a bake's probes;
  /// the weights as given, listeners without a band (has() false) left out. One entry of
  /// weight 1 gives join(listener, ...)'s bits. No allocation.
  void join(std::span<const BandWeight> blend, size_t source, ImpulseResponse& ir) const;
  double crossoverHz() const { return crossoverHz_; }

 private:
  size_t sources_;
  OutputFormat format_;
  double crossoverHz_, maxFrequencyHz_, fs_;
  Butterworth highPass_, allPass_;
  std::vector<Butterworth> edgeAllPasses_;
  std::vector<std::vector<float>> lowPassed_;  ///< [listener * sources + source]
};

}  // namespace dpc::wave
