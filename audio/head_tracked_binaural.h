// HeadTrackedBinaural: binaural playback of an AmbiX (ACN, SN3D) signal whose sound field is
// turned by the listener's head orientation on every audio block, without waiting for a new
// impulse response: the output mode "ambisonic_binaural" (docs/spatial.md).
//
// Per block of B samples: the order-N sound field x (C = (N + 1)^2 channels, in the reference
// head frame the impulse responses were synthesised in) is rotated into the current head
// frame, y = M(R) x with M from ambisonicRotation() (common/spherical_harmonics.h), and
// decoded to two ears by the binaural decoder (audio/ambisonic_binaural.h: MagLS, or the
// virtual-loudspeaker sampling decoder) as C x 2 uniformly partitioned convolutions of block B
// and its diffuse-field equaliser as two more (one per ear; no latency beyond the block). When
// the rotation changes, the block crossfades linearly from the previous matrix to the new one,
//   y[n] = (1 - w[n]) M_old x[n] + w[n] M_new x[n],  w[n] = (n + 1) / B,
// so a head turn is heard from the first block after the pose arrives, without clicks.
//
// Rotation R (row-major 3 x 3, listener frame x forward, y left, z up) maps a direction as
// seen in the reference frame to the same world direction as seen by the current head:
// headRotation() builds it from the two orientations.
//
// Threads: construction on the control thread (allocates, loads nothing: the HRTF is given).
// setRotation() and process() on the audio thread: no allocation, locks, logging, exceptions
// or waits.
#pragma once

#include <memory>
#include <vector>

#include "audio/ambisonic_binaural.h"
#include "audio/convolver.h"
#include "audio/hrtf.h"
#include "common/spherical_harmonics.h"

namespace dpc::audio {

class HeadTrackedBinaural {
 public:
  /// order 1 .. kMaxAmbisonicOrder; blockSize B > 0 samples; the decoder (MagLS by default).
  /// Throws std::invalid_argument on an order outside that range or a non-positive block size.
  HeadTrackedBinaural(int order, const Hrtf& hrtf, int blockSize,
                      const BinauralDecoderOptions& decoder = {});
  ~HeadTrackedBinaural();
  HeadTrackedBinaural(const HeadTrackedBinaural&) = delete;
  HeadTrackedBinaural& operator=(const HeadTrackedBinaural&) = delete;

  int order() const { return order_; }
  int channels() const { return ambisonicChannels(order_); }
  /// The decoder's filter taps per channel and ear (HRIR plus onset delays).
  size_t filterLength() const { return filterLength_; }

  /// The rotation from the next block on (identity until first set). Audio thread.
  void setRotation(const Rotation3& r);
  /// Rotates the channels() planar channels ambisonic[c][0..B) in place and writes the two
  /// decoded ears to left[0..B) and right[0..B). Audio thread.
  void process(float* const* ambisonic, float* left, float* right);

 private:
  /// Rotates the block in place: one matrix, or the crossfade from the previous one.
  void rotate(float* const* x);
  /// process() without the audio-thread check (the constructor's priming block).
  void processBlock(float* const* ambisonic, float* left, float* right);

  int order_;
  int blockSize_;
  size_t filterLength_ = 0;
  std::unique_ptr<ConvolverLayout> layout_;
  std::vector<std::unique_ptr<IrSpectra>> filters_;  ///< per channel: its two ear filters
  std::vector<std::unique_ptr<PartitionedConvolver>> convolvers_;  ///< per channel, 2 ears
  std::unique_ptr<ConvolverLayout> equaliserLayout_;
  std::unique_ptr<IrSpectra> equaliser_;                 ///< the decoder's equaliser
  std::unique_ptr<PartitionedConvolver> equalisers_[2];  ///< per ear
  std::vector<float> ears_;                              ///< 2 x B: the ears before the equaliser
  std::vector<float> matrix_, previous_;                 ///< C x C, row-major
  bool changed_ = false;                                 ///< previous_ != matrix_ for this block
  std::vector<float> scratch_;                           ///< C x B: the block under the old matrix
  std::vector<float*> scratchChannels_;
};

/// Rotation3 taking the reference head frame (the orientation the impulse responses were
/// synthesised for) to the current head frame: R = L(now) L(ref)^T, where L's rows are the
/// head's forward, left (up x forward) and up vectors in world coordinates. Any thread,
/// including the audio thread; no allocation.
Rotation3 headRotation(const float refForward[3], const float refUp[3], const float forward[3],
                       const float up[3]);

}  // namespace dpc::audio
