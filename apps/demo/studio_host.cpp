#include "apps/demo/studio_host.h"

#include <chrono>
#include <cstdio>
#include <cstdlib>

#include "apps/studio/studio_access.h"
#include "apps/studio/studio_json.h"

namespace dpc::demo {

using studio::StudioFrame;

std::string studioWebFolder() {
  if (const char* env = std::getenv("DPC_STUDIO_WEB"); env && *env) return env;
  return DPC_STUDIO_WEB_DIR;  // the build's copy (studio/CMakeLists.txt)
}

StudioHost::StudioHost(const SceneDesc& scene, const Flags& fl)
    : scene_(scene), placedSources_(scene.sources.size()) {
  board_.setScene(studio::sceneJson(scene));
  studio::ServerOptions o;
  o.port = int(fl.port.value_or(0));
  o.webFolder = studioWebFolder();
  o.token = studio::newToken();
  o.sourceCount = scene.sources.size();
  server_ = std::make_unique<studio::StudioServer>(o, board_);
  std::printf("studio: %s\n", server_->url().c_str());
  std::fflush(stdout);
}

StudioHost::~StudioHost() {
  server_.reset();
  if (published_)
    std::printf("studio: %llu frames published, %.1f us each on the control thread (mean)\n",
                (unsigned long long)published_, publishMicrosTotal_ / double(published_));
}

void StudioHost::applyRequests(KeyboardMotion& motion, LiveSession& session) {
  studio::StudioRequests r = board_.take();
  if (r.listener) motion.place(r.listener->position, r.listener->yawRadians);
  for (const auto& [index, position] : r.sources) {
    session.setSourcePosition(index, position);
    session.teleportSource(index);  // a drag is a jump: the pair's cache starts over
    placedSources_[index] = position;
  }
}

void StudioHost::addSessionFigures(const LiveSession& session, studio::StudioFigures& f) {
  const LiveSession::Status st = session.status();
  f.frameMs = st.frameMs;
  f.raysPerSecond = st.raysPerSecond;
  f.raysPerFrame = st.raysPerFrame;
  f.raysPerFrameScene = st.raysPerFrameScene;
  f.cacheEntries = st.cacheEntries;
  f.cacheMb = double(st.cacheBytes) / 1e6;
  f.cacheBudgetMb = double(st.cacheBudgetBytes) / 1e6;
  f.irAgeMs = st.irAgeMs;
  f.latencyMedianMs = st.latencyMedianMs;
  f.latencyP95Ms = st.latencyP95Ms;
}

bool StudioHost::publish(LiveSession& session, const KeyboardMotion& motion,
                         studio::StudioFigures figures) {
  const auto start = std::chrono::steady_clock::now();
  auto f = std::make_shared<StudioFrame>();
  f->source = std::min(board_.selected(), scene_.sources.size() - 1);
  // Copied under the snapshot's lock: the propagation thread skips one copy rather than wait.
  bool newer = false;
  session.copyResponses(f->source, [&](const LiveSession::Responses& r) {
    if (r.frame == lastFrame_) return;
    newer = true;
    f->frame = r.frame;
    f->binSeconds = r.binSeconds;
    f->energy = *r.energy;
    f->direct = *r.direct;
    f->paths = *r.paths;
  });
  if (!newer) return false;
  lastFrame_ = f->frame;
  f->sceneSeconds = motion.sceneTime();
  f->played = motion.playedIndex();
  for (size_t i = 0; i < scene_.listeners.size(); ++i) {
    const bool played = i == motion.playedIndex();
    f->listeners.push_back(played ? motion.position()
                                  : listenerPositionAt(scene_.listeners[i], f->sceneSeconds));
    f->listenerYaw.push_back(played ? motion.yaw()
                                    : listenerOrientationAt(scene_.listeners[i], f->sceneSeconds)
                                          .yawRadians);
  }
  for (size_t i = 0; i < scene_.sources.size(); ++i)
    f->sources.push_back(placedSources_[i].value_or(
        sourcePositionAt(scene_.sources[i], f->sceneSeconds)));
  addSessionFigures(session, figures);
  f->figures = figures;
  f->publishMicros =
      std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - start).count();
  publishMicrosTotal_ += f->publishMicros;
  ++published_;
  board_.publish(std::move(f));
  return true;
}

}  // namespace dpc::demo
