// BakedPlayback: the propagation stage's use of a bake (engine/baked_field.h). Each frame a
// source standing at its baked position (a static source) is played from the bake: its late
// response is interpolated between the probes the listener can see, its direct sound (and the
// direct sound's occlusion and diffraction) is the live simulation's, and its exact early paths
// stay live. Moving sources, sources the bake lacks, and frames where the listener sees no
// probe use the live response (the DPC); the fallbacks are counted (stats()).
// Cost per frame and listener: one partial sort of the probe distances and up to `candidates`
// visibility rays, then per baked source a weighted sum of maxProbes responses (B x 8 floats).
// Propagation thread (construction: control thread, allocates; the rest does not allocate).
#pragma once

#include <cstdint>
#include <memory>
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

  /// The frame's source positions (world order, metres): which sources are static.
  void setSources(const std::vector<glm::vec3>& positions);
  /// Chooses the probes for a listener at `position`, metres, before its sources' responses.
  void locate(const glm::vec3& position);
  /// Source s's energy response to synthesise: the interpolated one when s is baked and the
  /// listener located, else `live`. The reference is valid until the next call.
  const EnergyResponse& energy(size_t s, const EnergyResponse& live);
  /// The same for the spatial synthesiser (live's directions and listener frame).
  const DirectionalEnergyResponse& directional(size_t s, const DirectionalEnergyResponse& live);

  const Stats& stats() const { return stats_; }
  const BakeInterpolator& interpolator() const { return interpolator_; }

 private:
  bool useBake(size_t s);

  BakeInterpolator interpolator_;
  std::vector<uint8_t> baked_;  ///< per source: at its baked position this frame
  bool located_ = false;
  EnergyResponse energy_;
  DirectionalEnergyResponse directional_;
  Stats stats_;
};

}  // namespace dpc
