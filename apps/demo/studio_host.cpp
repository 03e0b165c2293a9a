#include "apps/demo/studio_host.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>

#include "apps/demo/overrides.h"
#include "apps/demo/studio_bake.h"
#include "apps/studio/studio_access.h"
#include "apps/studio/studio_json.h"

namespace dpc::demo {

using studio::StudioFrame;

std::string studioWebFolder() {
  if (const char* env = std::getenv("DPC_STUDIO_WEB"); env && *env) return env;
  return DPC_STUDIO_WEB_DIR;  // the build's copy (studio/CMakeLists.txt)
}

namespace {

/// Triangles of the scene's geometry: the mesh's, then every object's.
size_t triangleCount(const SceneDesc& scene) {
  size_t n = scene.mesh.triangles.size();
  for (const ObjectDesc& o : scene.objects) n += o.mesh.triangles.size();
  return n;
}

/// Frames the DPC's window covers (SurfaceHeat's K): tau times the frame rate, 1 without reuse.
double windowFrames(const SceneDesc& scene, const Flags& fl) {
  const PropagationSettings s = applyOverrides(scene, fl);
  if (s.estimator != Estimator::kDpc) return 1.0;
  return std::max(1.0, double(s.cacheTau) * double(s.frameRate));
}

}  // namespace

StudioHost::StudioHost(const SceneDesc& scene, const Flags& fl,
                       std::shared_ptr<studio::StudioAudio> audio)
    : scene_(scene),
      heat_(triangleCount(scene), windowFrames(scene, fl)),
      placedSources_(scene.sources.size()) {
  // The bake does not change while dpc-demo runs: its maps are read and put in JSON once.
  if (!fl.bake.empty()) board_.setBake(studio::bakeJson(readStudioBake(fl.bake)));
  board_.setScene(studio::sceneJson(scene, fl.bake));
  board_.setAudio(std::move(audio));
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

std::shared_ptr<studio::StudioIr> StudioHost::freeIr() {
  // use_count() 1: only this list holds it, and nothing else can take it from here. The
  // fence orders the server's last reads of it (before its release of the count) before the
  // copy into it.
  for (const auto& ir : irs_)
    if (ir.use_count() == 1) {
      std::atomic_thread_fence(std::memory_order_acquire);
      return ir;
    }
  irs_.push_back(std::make_shared<studio::StudioIr>());
  return irs_.back();
}

bool StudioHost::publish(LiveSession& session, const KeyboardMotion& motion,
                         studio::StudioFigures figures) {
  const auto start = std::chrono::steady_clock::now();
  auto f = std::make_shared<StudioFrame>();
  f->source = std::min(board_.selected(), scene_.sources.size() - 1);
  // Copied under the snapshot's lock: the propagation thread skips one copy rather than wait.
  bool newer = false;
  // The IR (768 kB binaural at 2 s) only when the page asked for one since (and with the
  // first frame): a copy of it cost 0.2-0.4 ms here, and the page shows a new one every 2 s.
  const bool wantIr = board_.takeIrWanted() || published_ == 0;
  const std::shared_ptr<studio::StudioIr> ir = wantIr ? freeIr() : nullptr;
  session.copyResponses(f->source, [&](const LiveSession::Responses& r) {
    if (r.frame == lastFrame_) return;
    newer = true;
    f->frame = r.frame;
    f->binSeconds = r.binSeconds;
    f->energy = *r.energy;
    f->fromBake = r.fromBake;
    f->direct = *r.direct;
    f->paths = *r.paths;
    f->worldSeconds = r.world->timeSeconds;
    f->objects = r.world->objectPoses;
    f->sourceRotations = r.world->sourceRotations;
    f->edges = *r.edges;
    surfaces_ = *r.surfaces;  // averaged below, outside the snapshot's lock
    if (ir) ir->ir.assignFrom(*r.ir);
  });
  if (!newer) {
    if (wantIr) board_.wantIr();  // still wanted: the next new frame brings it
    return false;
  }
  if (ir) {
    ir->frame = f->frame;
    ir->source = f->source;
    ir->binaural = scene_.audio.output == OutputFormat::kBinaural;
    ir->direct = f->direct;
  }
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
  if (f->source != heatSource_) heat_.reset();
  heatSource_ = f->source;
  if (!f->fromBake) {
    heat_.add(surfaces_);
    heat_.nonzero(f->surfaceTriangles, f->surfaceEnergy);
  }
  addSessionFigures(session, figures);
  f->figures = figures;
  f->publishMicros =
      std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - start).count();
  publishMicrosTotal_ += f->publishMicros;
  ++published_;
  if (ir) board_.publishIr(ir);
  board_.publish(std::move(f));
  return true;
}

}  // namespace dpc::demo
