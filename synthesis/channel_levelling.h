// Window levelling of each channel of a spatial IR (Ambisonics, stereo, binaural, loudspeaker
// feeds): every channel's reverberant part is levelled to its own share of the directional
// energy response, band by band in short windows (synthesis/window_leveller.h, the mono
// synthesis's levelling), so that one IR's W, which a user reads as the omnidirectional IR,
// or one ear carries its response's octave parameters as one mono IR does, and every other
// channel its own share. The shares' weights are what a window's band view sees of each
// direction's filter (synthesis/filter_shape.h, viewWeights; an HRIR is not flat within an
// octave). A channel's factors are its own: W's factors whiten W's realisation, and a channel
// uncorrelated with W (a diffuse field's X, Y, Z ...) scaled by them would gain energy where W
// happened to be weak.
// In a window each channel is scaled as a whole, so the channels' correlations there (a
// direction's share in every channel) stay as synthesised.
//
// Construction: control/propagation thread (FFTW planning); allocates. level(): propagation
// thread; allocates only while a response has more bins than any before; no errors.
#pragma once

#include <cstddef>
#include <functional>
#include <memory>
#include <span>
#include <vector>

#include "common/bands.h"
#include "engine/energy_response.h"
#include "synthesis/window_leveller.h"

namespace dpc {

class ChannelLevelling {
 public:
  /// IRs of `length` samples at sampleRate Hz; channel c's bands firstBand..lastBand[c] (one
  /// entry per channel; level() leaves channels beyond them as they are).
  ChannelLevelling(int sampleRate, size_t length, int firstBand, std::vector<int> lastBand);
  ~ChannelLevelling();

  /// Runs `n` tasks f(0..n-1), possibly concurrently (SpatialIrSynthesizer::ParallelFor).
  using ParallelFor = std::function<void(size_t n, const std::function<void(size_t)>& f)>;
  /// From now on level() spreads the channels over `workers` (>= 1) through `parallel`, each
  /// worker with a leveller of its own: channel c is levelled alike by any worker, so the IR
  /// does not depend on their number. An empty `parallel`: one worker, on the calling thread.
  /// Control thread; allocates (FFTW planning).
  void setWorkers(size_t workers, ParallelFor parallel);

  /// Levels each channel c (its reverberant part, zero before `onset`) to its share of
  /// `energy`: per band b, the sum over the first `count` directions d of weight[d][c][b] E_d
  /// for the directional bands (b >= directionalFrom) and omniGain[c]^2 sum_d E_d below them;
  /// beside fixed[c] (length samples: the channel's direct sound and exact paths, aligned with
  /// it; empty: none), as WindowLeveller::level.
  void level(const DirectionalEnergyResponse& energy, size_t count,
             const std::vector<std::vector<Bands>>& weight, std::span<const float> omniGain,
             int directionalFrom, size_t onset, std::span<float* const> channels,
             std::span<const float* const> fixed = {});

 private:
  struct Worker {
    /// Per distinct last band (bands_, in its order): a leveller if one of the worker's
    /// channels ends there, else null.
    std::vector<std::unique_ptr<WindowLeveller>> levellers;
    EnergyResponse target;  ///< scratch: the channel's share of the response
  };
  /// The index into bands_ (and Worker::levellers) of channel c's last band.
  size_t levellerOf(size_t c) const;
  /// target <- channel c's share of energy.
  static void channelTarget(const DirectionalEnergyResponse& energy, size_t count,
                            const std::vector<std::vector<Bands>>& weight, float omniGain,
                            int directionalFrom, size_t c, EnergyResponse& target);

  int sampleRate_;
  size_t length_;
  int firstBand_;
  std::vector<int> lastBand_;    ///< per channel
  std::vector<int> bands_;       ///< the distinct entries of lastBand_
  std::vector<Worker> workers_;  ///< [0] always exists
  ParallelFor parallel_;         ///< empty: on the calling thread
};

}  // namespace dpc
