// ResponseSnapshot: the newest frame's responses of one listener, copied by the propagation
// thread after each frame for readers on other threads (the C API's copy functions, tests).
// The writer tries the lock first: a reader holding it makes that frame skip its copy, so a
// reader rarely delays propagation. A reader holding it at the next store too makes the
// writer wait for it (and later readers wait for the writer), so a reader that copies without
// pause cannot keep the snapshot at an old frame: at most every other frame is skipped, and
// the writer waits at most one reader's copy. The audio thread must not read it.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <mutex>
#include <thread>
#include <vector>

#include "common/bands.h"
#include "engine/specular_paths.h"
#include "runtime/propagation_stage.h"
#include "scene/trajectory.h"

namespace dpc {

class ResponseSnapshot {
 public:
  /// One source's responses: ir the pressure IR (its channels) at the scene's rate;
  /// energy[k][band] the energy response in bins of binSeconds (1/m^2 relative to source
  /// power, direct sound included); frame = propagation frames run when it was taken;
  /// direct the analytic direct sound alone (also in energy); paths the pair's exact early
  /// specular paths (empty while exact_order is 0), for viewers that draw them (dpc studio);
  /// world the world the frame traced (every pose, objects' too, and its scene time);
  /// edges the endpoints (m) of the diffracting edges whose paths the direct sound sums;
  /// fromBake: the pair was played from an attached bake this frame (not traced), so energy is
  /// the bake's response interpolated at the listener (BakedPlayback::interpolate), the one its
  /// IR was synthesised from, plus the live direct sound; else the traced estimator's.
  /// In both, energy also holds the exact early paths in their bins (as --er-out writes
  /// them): the whole response the IR is synthesised from.
  /// surfaces: the traced frame's energy per surface (Simulation::recordSurfaces; empty when
  /// not recorded and for a pair played from the bake).
  struct Responses {
    const ImpulseResponse* ir;
    const std::vector<Bands>* energy;
    double binSeconds;
    uint64_t frame;
    const DirectSound* direct;
    const std::vector<SpecularPath>* paths;
    const WorldState* world;
    const std::vector<std::array<glm::vec3, 2>>* edges;
    bool fromBake;
    const std::vector<SurfaceTally::Surface>* surfaces;
  };

  /// withIrs false: Responses::ir holds no channels (the session's
  /// Options::keepImpulseResponses). Control thread, before the first frame.
  explicit ResponseSnapshot(bool withIrs = true) : withIrs_(withIrs) {}

  /// Propagation thread, after stage.prepare(listener): copies listener's IRs (when kept) and
  /// energy responses (direct sound added into its bin; a pair played from the bake: the
  /// bake's interpolated response) and the frame's `world`. Skips the copy when a reader holds
  /// the lock, unless the previous store skipped too: then waits for that reader. Returns
  /// whether it copied. Allocates only while the copies grow: the buffers are reused,
  /// so a frame does not allocate and fault in its IRs' size of fresh memory again.
  bool tryStore(const PropagationStage& stage, const WorldState& world, size_t listener,
                uint64_t frame);

  /// Any thread but the audio thread: calls f(const Responses&) with the newest responses of
  /// `source` while holding the lock. Returns false, without calling f, before the first
  /// store or for a bad index. Allocates nothing itself (f is called directly).
  /// Yields while the writer waits for the lock, so that readers in turn cannot hold it off.
  template <class F>
  bool read(size_t source, F&& f) {
    while (writerWaiting_.load(std::memory_order_acquire)) std::this_thread::yield();
    std::lock_guard<std::mutex> lock(mutex_);
    if (!valid_ || source >= irs_.size()) return false;
    f(Responses{&irs_[source], &energy_[source].bins(), binSeconds_, frame_, &direct_[source],
                &paths_[source], &world_, &edges_[source], fromBake_[source] != 0,
                &surfaces_[source]});
    return true;
  }

 private:
  /// Source s's energy response for listener into energy_[s] and fromBake_[s]: the bake's
  /// interpolated one when the pair played from it this frame, else the traced one; with the
  /// direct sound and the exact early paths added.
  void storeEnergy(const PropagationStage& stage, size_t s, size_t listener);

  std::mutex mutex_;
  std::atomic<bool> writerWaiting_{false};  ///< the writer blocks on mutex_: readers hold off
  bool skippedLast_ = false;                ///< writer only: the previous store was skipped
  std::vector<ImpulseResponse> irs_;        ///< [source]
  std::vector<EnergyResponse> energy_;                ///< [source]
  std::vector<DirectSound> direct_;                   ///< [source]
  std::vector<std::vector<SpecularPath>> paths_;      ///< [source][path]
  WorldState world_;
  std::vector<std::vector<std::array<glm::vec3, 2>>> edges_;  ///< [source][edge]: a, b
  std::vector<uint8_t> fromBake_;  ///< [source]: Responses::fromBake
  std::vector<std::vector<SurfaceTally::Surface>> surfaces_;  ///< [source][surface]
  double binSeconds_ = 0.0;
  uint64_t frame_ = 0;
  bool valid_ = false;
  bool withIrs_ = true;
};

}  // namespace dpc
