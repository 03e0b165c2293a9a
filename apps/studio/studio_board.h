// StudioBoard: what dpc studio's control loop and its web server share (docs/studio.md).
// The control loop (dpc-demo's main thread) publishes a StudioFrame after each new propagation
// frame and takes the page's requests; the server thread reads frames and posts requests. One
// mutex, held only to swap a shared_ptr or copy a few numbers: neither side waits for the
// other's work, and the propagation and audio threads never see the board.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <glm/vec3.hpp>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "apps/studio/studio_audio.h"
#include "common/bands.h"
#include "common/impulse_response.h"
#include "engine/propagation.h"
#include "engine/specular_paths.h"

namespace dpc::studio {

/// The live status line's figures at the time of a frame (NaN: not known in this clock).
struct StudioFigures {
  double frameMs = 0.0, raysPerSecond = 0.0, irAgeMs = 0.0;
  int raysPerFrame = 0, raysPerFrameScene = 0;
  size_t cacheEntries = 0;
  double cacheMb = 0.0, cacheBudgetMb = 0.0;
  double latencyMedianMs = 0.0, latencyP95Ms = 0.0;
  double loadPercent = 0.0;  ///< callback load, median (live clock only)
  uint64_t xruns = 0;
  bool live = false;  ///< live clock (a device plays) or the offline clock (frames stepped)
};

/// One published view of the session: poses, the selected pair's responses, the figures.
struct StudioFrame {
  uint64_t frame = 0;  ///< propagation frames run when its responses were taken
  double sceneSeconds = 0.0;
  size_t played = 0;   ///< the played listener (scene.listeners index)
  size_t source = 0;   ///< the selected source (scene.sources index)
  std::vector<glm::vec3> listeners;  ///< every listener's position, m
  std::vector<float> listenerYaw;    ///< radians, dpc::Orientation's convention
  std::vector<glm::vec3> sources;    ///< every source's position, m
  double binSeconds = 0.0;
  std::vector<Bands> energy;  ///< the selected pair's energy response, direct sound included
  /// energy is the bake's response at the listener (the pair played from --bake this frame,
  /// not traced), else the traced one (ResponseSnapshot::Responses::fromBake).
  bool fromBake = false;
  DirectSound direct;         ///< its direct sound alone
  std::vector<SpecularPath> paths;  ///< its exact early specular paths
  /// The world the frame traced (WorldState): its scene time, each object's pose and each
  /// source's rotation (its directivity's forward axis is rotation * +x).
  double worldSeconds = 0.0;
  std::vector<Pose> objects;
  std::vector<glm::quat> sourceRotations;
  /// The diffracting edges (endpoints a, b, m) whose paths the pair's direct sound sums.
  std::vector<std::array<glm::vec3, 2>> edges;
  /// The selected pair's energy per surface averaged over the DPC's window (SurfaceHeat):
  /// the triangles holding some (the mesh's numbering, then each object's) and their energy
  /// (1/m^2, mean over the octave bands). Empty for a pair played from the bake.
  std::vector<uint32_t> surfaceTriangles;
  std::vector<float> surfaceEnergy;
  StudioFigures figures;
  double publishMicros = 0.0;  ///< what building this frame cost the control loop, us
};

/// The selected pair's pressure IR of a frame, as the audio thread convolves with it (early and
/// late parts summed: PropagationStage::wholeIrsInto), kept apart from its StudioFrame because
/// it is large (channels x ir_length x rate floats): only some frames have one, and only the
/// newest few are kept.
struct StudioIr {
  uint64_t frame = 0;
  size_t source = 0;
  ImpulseResponse ir;
  bool binaural = false;  ///< channels are (left, right) ears: IACC applies
  /// The frame's direct sound (its delay places the IR's onset), kept with the IR: the IR
  /// outlives its frame in the board's ring.
  DirectSound direct;
};

/// A listener pose asked for by the page.
struct ListenerRequest {
  glm::vec3 position{0.f};
  float yawRadians = 0.f;
};

/// What the page asked for since the control loop last looked.
struct StudioRequests {
  std::optional<ListenerRequest> listener;
  std::vector<std::pair<size_t, glm::vec3>> sources;  ///< (index, position), in order
};

class StudioBoard {
 public:
  /// Frames kept for /api/energy.csv?frame=N (about 4 s at 15 frames per second).
  static constexpr size_t kKeptFrames = 64;
  /// IRs kept for /api/ir?frame=N: one is taken per page request (every 2 s), so the last
  /// 16 s; a binaural 2 s IR at 48 kHz is 768 kB, 6 MB for all.
  static constexpr size_t kKeptIrs = 8;

  /// Control thread, once before the server starts: the scene's JSON (studio_json.h).
  void setScene(std::string json);
  std::shared_ptr<const std::string> scene() const;
  /// Control thread, once before the server starts: the bake's JSON (bakeJson), when dpc-demo
  /// plays from a bake; bake() is null otherwise.
  void setBake(std::string json);
  std::shared_ptr<const std::string> bake() const;
  /// Control thread, once before the server starts: the offline clock's sound for the page
  /// (studio_audio.h); audio() is null on the live clock (the device plays) and for outputs a
  /// page cannot play.
  void setAudio(std::shared_ptr<StudioAudio> audio);
  std::shared_ptr<StudioAudio> audio() const;

  /// Control thread: the newest frame (older ones kept up to kKeptFrames).
  void publish(std::shared_ptr<const StudioFrame> frame);
  /// Control thread: the newest frame's IR (older ones kept up to kKeptIrs).
  void publishIr(std::shared_ptr<const StudioIr> ir);
  /// Server thread: the page asked for the newest IR; the control loop takes the next frame's.
  void wantIr();
  /// Control thread: whether an IR was asked for since the last call (and clears it).
  bool takeIrWanted();
  /// Server thread: the newest frame, or null before the first.
  std::shared_ptr<const StudioFrame> latest() const;
  /// Server thread: a kept frame by number, or null.
  std::shared_ptr<const StudioFrame> find(uint64_t frame) const;
  /// Server thread: the newest IR, or a kept one by frame number; null when there is none.
  std::shared_ptr<const StudioIr> latestIr() const;
  std::shared_ptr<const StudioIr> findIr(uint64_t frame) const;

  /// Server thread: the page's requests (the newest listener pose wins).
  void requestListener(const ListenerRequest& r);
  void requestSource(size_t index, const glm::vec3& position);
  void select(size_t source);
  /// Control thread: takes (and clears) the requests.
  StudioRequests take();
  /// The selected source (0 until the page selects one).
  size_t selected() const;

 private:
  mutable std::mutex mutex_;
  std::shared_ptr<const std::string> scene_;
  std::shared_ptr<const std::string> bake_;
  std::shared_ptr<StudioAudio> audio_;
  std::deque<std::shared_ptr<const StudioFrame>> frames_;  ///< oldest first
  std::deque<std::shared_ptr<const StudioIr>> irs_;        ///< oldest first
  StudioRequests requests_;
  size_t selected_ = 0;
  bool irWanted_ = false;
};

}  // namespace dpc::studio
