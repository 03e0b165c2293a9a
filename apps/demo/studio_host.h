// dpc studio inside a dpc-demo run (--studio; docs/studio.md): the board, the web server on its
// own thread, and the control loop's side of it: the page's requests into the session through
// the same calls as the keyboard and the C API's pose setters, and a StudioFrame published
// after each new propagation frame. Control thread only; the propagation thread is read only
// through LiveSession::copyResponses (a lock it only tries), the audio thread never.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "apps/demo/flags.h"
#include "apps/demo/keyboard_motion.h"
#include "apps/studio/studio_board.h"
#include "apps/studio/surface_heat.h"
#include "apps/studio/studio_server.h"
#include "runtime/live_session.h"

namespace dpc::demo {

class StudioHost {
 public:

  /// Starts the server for `scene` (its JSON published once, and with --bake the bake's maps:
  /// /api/bake) and prints its URL on stdout. Throws InputError naming --port when the port
  /// cannot be bound, naming the bake when it does not open. `scene` must outlive it.
  /// audio: the offline clock's sound for the page (GET /api/audio), or null (the live clock,
  /// or an output a page cannot play); on the board before the URL is printed.
  StudioHost(const SceneDesc& scene, const Flags& fl,
             std::shared_ptr<studio::StudioAudio> audio = nullptr);
  /// http://127.0.0.1:PORT/?token=TOKEN, as printed.
  std::string url() const { return server_->url(); }
  /// Stops the server; prints what publishing cost (studio: N frames, mean us per frame).
  ~StudioHost();

  /// The page's requests since the last call: the listener pose into `motion` (which
  /// publishPoses hands to LiveSession::setPose, as a key would), each source position to
  /// LiveSession::setSourcePosition (a jump: teleportSource), the selection kept for publish().
  void applyRequests(KeyboardMotion& motion, LiveSession& session);

  /// Publishes a StudioFrame if the session has a frame newer than the last one published:
  /// poses, the selected pair's responses (its IR when the page asked for one), the status figures (`figures` brings the device's
  /// load and xruns; the session's are filled in here). Returns whether it published.
  bool publish(LiveSession& session, const KeyboardMotion& motion,
               studio::StudioFigures figures);

 private:
  /// The session's figures into `f` (LiveSession::status()).
  static void addSessionFigures(const LiveSession& session, studio::StudioFigures& f);
  /// An IR buffer no one else holds any more (the board dropped it and no request reads it),
  /// or a new one: copying into a buffer of the right size neither allocates nor faults in
  /// fresh pages (an allocation per frame cost 0.2 ms more per frame here).
  std::shared_ptr<studio::StudioIr> freeIr();

  const SceneDesc& scene_;
  studio::StudioBoard board_;
  studio::SurfaceHeat heat_;
  size_t heatSource_ = 0;  ///< the pair heat_ averages (a new selection resets it)
  /// The newest frame's per-surface energies, copied under the snapshot's lock (capacity kept).
  std::vector<SurfaceTally::Surface> surfaces_;
  std::unique_ptr<studio::StudioServer> server_;
  std::vector<std::optional<glm::vec3>> placedSources_;  ///< by the page, else the trajectory
  std::vector<std::shared_ptr<studio::StudioIr>> irs_;  ///< every IR buffer made (freeIr)
  uint64_t lastFrame_ = 0;
  uint64_t published_ = 0;
  double publishMicrosTotal_ = 0.0;
};

/// The folder of the page's files: $DPC_STUDIO_WEB if set, else the build's studio/web.
std::string studioWebFolder();

}  // namespace dpc::demo
