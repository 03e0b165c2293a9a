// IrSet: one propagation frame's impulse responses for one listener, partitioned and
// transformed for the audio stage's convolvers (audio/nonuniform_convolver.h), with the frame,
// listener and pose times they came from. Sets are made once, up front, by the
// PropagationStage (makeIrSet) and owned by an IrExchange (runtime/ir_exchange.h), which hands
// them between the propagation thread (fills one, publishes it) and the audio thread (takes
// the newest, releases it once no partition level uses it).
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "audio/nonuniform_convolver.h"

namespace dpc {

struct IrSet {
  /// scene sources x IR channels: the whole IRs, or in hybrid rendering the early parts
  std::unique_ptr<audio::NonUniformIrSet> irs;
  /// Hybrid rendering (runtime/hybrid_synthesis.h), else null: late buses x IR channels.
  std::unique_ptr<audio::NonUniformIrSet> lateIrs;
  /// Hybrid: per source, the amplitude gain of its dry signal into its bus, and the bus.
  std::vector<float> lateGain;
  std::vector<int> lateBus;
  /// Hybrid: per bus, the identity of the bus IR lateIrs holds the partitions of
  /// (HybridSynthesis::busIrId; 0: none yet): a kept bus IR is not partitioned again.
  std::vector<uint64_t> lateIrIds;
  /// Per source, the identity of the IR irs holds the partitions of
  /// (PropagationStage::sourceIrId; 0: none, or source IRs not kept).
  std::vector<uint64_t> irIds;
  size_t listener = 0;           ///< listener index (scene.listeners order) it was computed for
  uint64_t frame = 0;            ///< propagation frame index that produced it
  double poseTimeSeconds = 0.0;  ///< scene time of the listener pose it was computed for
  int64_t poseNs = 0;            ///< live: steady_clock ns when that pose was published (latency)
  int64_t readyNs = 0;           ///< live: steady_clock ns when the set was ready (IR age)
  /// Audio thread: how many convolvers (early, late) still hold the set; it is released to
  /// its exchange when this falls to 0 (AudioStage).
  int convolversHolding = 0;
};

}  // namespace dpc
