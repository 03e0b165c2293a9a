// BakedPlayback: the propagation stage's use of a bake (engine/baked_field.h). Each frame a
// source standing at its baked position (a static source) is played from the bake for every
// listener that sees a probe: its late response is interpolated between the probes the
// listener can see, its direct sound (and the direct sound's occlusion and diffraction) is the
// live simulation's, and its exact early paths stay live. Such a pair is not traced at all
// (bakedPairs() goes to FrameInputs::skippedPairs before the frame is traced), so a bake
// saves the static sources' tracing and cache updates. Moving sources, sources the bake lacks,
// and listeners that see no probe use the live response (the DPC); the fallbacks are counted
// (stats()).
// Cost per frame and listener: one partial sort of the probe distances and up to `candidates`
// visibility rays, then per baked source a weighted sum of maxProbes responses (B x 8 floats).
// Propagation thread (construction: control thread, allocates; beginFrame allocates only when
// more listeners than before appear; the rest does not allocate).
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "engine/baked_field.h"
#include "engine/simulation.h"

namespace dpc {

class BakedPlayback {
 public:
  struct Stats {
    uint64_t bakedResponses = 0;  ///< source responses taken from the bake
    uint64_t liveResponses = 0;   ///< source responses kept live (moving or not baked)
    uint64_t fallbacks = 0;       ///< listener positions with no visible probe (all live)
  };

  BakedPlayback(std::shared_ptr<const BakedField> field, const Simulation& simulation,
                BakeInterpolation settings = {});

  /// The frame's world before it is traced: which sources (positions in world order, metres)
  /// stand at their baked positions, and the probes each listener sees. Fills bakedPairs().
  void beginFrame(std::span<const glm::vec3> sources, std::span<const ListenerSphere> listeners);
  /// Per pair, index listener * sources + source: 1 when the pair is played from the bake this
  /// frame (its source is static and its listener sees a probe), for FrameInputs::skippedPairs.
  const std::vector<uint8_t>& bakedPairs() const { return pairs_; }
  /// Source s's energy response for listener l to synthesise: the interpolated one when the
  /// pair is baked this frame, else `live`. The reference is valid until the next call. Writes
  /// only its own response and the counts: one thread at a time, which may run beside
  /// interpolate() calls (hybrid rendering's buses' job beside the early jobs).
  const EnergyResponse& energy(size_t s, size_t listener, const EnergyResponse& live);
  /// The same for the spatial synthesiser (live's directions and listener frame).
  const DirectionalEnergyResponse& directional(size_t s, size_t listener,
                                               const DirectionalEnergyResponse& live);

  /// Whether pair (s, listener) is played from the bake this frame (counts nothing).
  bool plays(size_t s, size_t listener) const {
    const size_t pair = listener * baked_.size() + s;
    return s < baked_.size() && pair < pairs_.size() && pairs_[pair];
  }
  /// The interpolated late response of a pair that plays() into `out` (cleared first; as many
  /// bins as out holds). Writes only `out` and counts nothing: several threads may call it
  /// with outputs of their own (hybrid rendering's early parts).
  void interpolate(size_t s, size_t listener, EnergyResponse& out) const {
    interpolators_[listener]->response(s, out);
  }

  const Stats& stats() const { return stats_; }
  /// Listener l's interpolator (l < the listeners of the frames so far, or 0).
  const BakeInterpolator& interpolator(size_t listener = 0) const {
    return *interpolators_.at(listener);
  }

 private:
  bool useBake(size_t s, size_t listener);

  std::shared_ptr<const BakedField> field_;
  const Simulation& simulation_;
  BakeInterpolation settings_;
  std::vector<std::unique_ptr<BakeInterpolator>> interpolators_;  ///< per listener
  std::vector<uint8_t> baked_;     ///< per source: at its baked position this frame
  std::vector<uint8_t> located_;   ///< per listener: sees a probe this frame
  std::vector<uint8_t> pairs_;     ///< bakedPairs()
  EnergyResponse energy_;
  DirectionalEnergyResponse directional_;
  Stats stats_;
};

}  // namespace dpc
