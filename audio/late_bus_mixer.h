// The inputs of hybrid rendering's late buses (runtime/hybrid_synthesis.h): bus k's input is
// sum over its member sources of g_s x_s, with x_s a source's dry block and g_s its late gain.
//
// New gains and bus assignments (setTargets, when an IR set is applied) are reached by a linear
// ramp over the next block, so a gain change never steps. A source that moves to another bus
// fades out of the old one over that block while it fades into the new one (energy-wise the
// two ramps' sum dips by at most 3 dB mid-block for one block; the old bus keeps ringing with
// what it was given before, as the room would).
//
// Threads: construction on the control thread (allocates every buffer); setTargets, mix and
// the accessors on the audio thread: no allocation, locks or system calls. No errors (indices
// out of range are ignored: a bus < 0 or >= buses() silences the source's late part).
#pragma once

#include <cstddef>
#include <span>
#include <vector>

namespace dpc::audio {

class LateBusMixer {
 public:
  /// sources, buses >= 1; blockSize samples per mix().
  LateBusMixer(int sources, int buses, int blockSize);

  /// Gains (amplitude) and buses per source to reach over the next block.
  void setTargets(std::span<const int> bus, std::span<const float> gain);
  /// Mixes one block: in[s][0..blockSize) per source, into the bus inputs.
  void mix(const float* const* in);
  /// Bus k's input for the last mixed block: busInputs()[k][0..blockSize).
  const float* const* busInputs() const { return busPtrs_.data(); }
  int buses() const { return int(busPtrs_.size()); }

 private:
  struct Voice {
    int bus = -1;
    float gain = 0.f;    ///< at the start of the next block
    float target = 0.f;  ///< at its end
  };
  /// Adds x ramped from v.gain to v.target into v's bus, then v.gain = v.target.
  void addRamped(Voice& v, const float* x);

  int blockSize_;
  std::vector<Voice> current_, fading_;  ///< per source: its bus, and the bus it leaves
  std::vector<float> bus_;               ///< buses x blockSize
  std::vector<float*> busPtrs_;
};

}  // namespace dpc::audio
