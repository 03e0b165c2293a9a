#include "apps/bake/bake_run.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>

#include "apps/bake/progress.h"
#include "apps/bake/watchdog.h"
#include "bake/bake_file.h"
#include "bake/parameter_map.h"
#include "common/input_error.h"
#include "common/output_file.h"
#include "common/stop_signals.h"
#include "scene/trajectory.h"

namespace dpc::bake {
namespace {

/// The exit status of a run that did not finish: 128 + the number of the stop signal that
/// ended it (common/stop_signals.h), else 1 (bad input, already reported).
int unfinishedStatus() {
  const int s = stopSignal();
  return s != 0 ? 128 + s : 1;
}

/// What this run bakes: the scene, the file's header and the probes not yet done.
struct Plan {
  SceneDesc scene;
  BakeHeader header;
  std::vector<size_t> todo;
  size_t alreadyDone = 0;
};

Plan planFresh(const Options& o) {
  Plan plan;
  plan.scene = loadScene(o.scene);
  BakeHeader& h = plan.header;
  h.scenePath = std::filesystem::absolute(o.scene).string();
  h.meshHash = sceneHash(plan.scene);
  h.seed = plan.scene.propagation.seed;
  h.settings = o.settings;
  if (!o.raysGiven) h.settings.rays = plan.scene.propagation.raysPerFrame;
  h.settings.irLength = plan.scene.propagation.irLength;
  h.grid = o.grid;
  h.grid.radiusM = plan.scene.listeners[0].radius;
  if (o.probes.empty()) {
    h.probes = makeProbeGrid(plan.scene, h.grid, o.scene);
  } else {
    h.grid.spacingM = h.grid.heightM = 0.0;  // a list: no grid
    h.probes =
        placeProbes(plan.scene, readProbeList(o.probes), h.grid.radiusM, o.probes, "--probes");
  }
  for (const SourceDesc& s : plan.scene.sources) h.sources.push_back(sourcePositionAt(s, 0.0));
  h.shape = probeShape(plan.scene, h.settings);
  for (size_t p = 0; p < h.probes.positions.size(); ++p) plan.todo.push_back(p);
  return plan;
}

Plan planResume(const Options& o) {
  Plan plan;
  std::vector<uint8_t> done;
  {
    const BakeFile file = BakeFile::open(o.resume, false);
    plan.header = file.header();
    done = file.done();
  }
  const std::string scenePath = o.scene.empty() ? plan.header.scenePath : o.scene;
  plan.scene = loadScene(scenePath);
  if (sceneHash(plan.scene) != plan.header.meshHash)
    throw InputError(o.resume, "mesh_hash",
                     "the bake is of another scene than " + scenePath + " (or the scene changed)");
  plan.header.settings.threads = o.settings.threads;
  for (size_t p = 0; p < done.size(); ++p)
    if (!done[p]) plan.todo.push_back(p);
  plan.alreadyDone = done.size() - plan.todo.size();
  return plan;
}

/// Rank 0's file: a fresh one built in a temporary next to --out and renamed into place once
/// its layout is written (so --out is only ever replaced by a valid bake), or the resumed one.
BakeFile openOutput(const Options& o, const Plan& plan) {
  if (!o.resume.empty()) return BakeFile::open(o.resume, true);
  TempOutputFile tmp(o.out);
  BakeFile file = BakeFile::create(tmp.tempPath(), o.out, plan.header);
  tmp.commit();
  return file;
}

void printEstimate(const Plan& plan, const Cluster& cluster) {
  const BakeHeader& h = plan.header;
  const double rays = double(plan.todo.size()) * double(h.shape.sources) *
                      double(h.settings.frames) * double(h.settings.rays);
  const double mb = double(plan.todo.size()) * double(h.shape.packedFloats()) * 4.0 / 1e6;
  std::fprintf(stderr,
               "dpc-bake: %zu probes to bake of %zu (%zu candidates: %zu outside, %zu inside "
               "geometry, %zu near a surface) x %zu sources x %d frames x %d rays = %.3g rays, "
               "%.1f MB of data, %d process%s\n",
               plan.todo.size(), h.probes.positions.size(), h.probes.candidates, h.probes.outside,
               h.probes.insideGeometry, h.probes.nearSurface, h.shape.sources, h.settings.frames,
               h.settings.rays, rays, mb, cluster.size(), cluster.size() > 1 ? "es" : "");
}

/// This rank's probes: every size-th of the todo list, from its rank.
std::vector<size_t> share(const std::vector<size_t>& todo, const Cluster& cluster) {
  std::vector<size_t> mine;
  for (size_t j = size_t(cluster.rank()); j < todo.size(); j += size_t(cluster.size()))
    mine.push_back(todo[j]);
  return mine;
}

/// Rank 0's file, committed under the watchdog's lock when there is one (several ranks).
struct Writer {
  BakeFile& file;
  Progress& progress;
  Watchdog* watchdog = nullptr;
  size_t committed = 0;
  void commit(size_t probe, const ProbeResult& r) {
    std::unique_lock<std::mutex> between;
    if (watchdog) between = watchdog->lock();
    file.commit(probe, r);
    if (watchdog) watchdog->committed();
    ++committed;
    progress.step();
  }
};

/// Rank 0: bakes its share and commits every probe (its own and the others') as it comes.
/// False when interrupted.
bool bakeAsWriter(const Plan& plan, Cluster& cluster, Writer& out) {
  const BakeHeader& h = plan.header;
  size_t& committed = out.committed;
  auto drain = [&] {
    bool any = false;
    while (auto m = cluster.receive(h.shape.packedFloats())) {
      out.commit(m->probe, unpack(m->data, h.shape));
      any = true;
    }
    return any;
  };
  ProbeBaker baker(plan.scene, h.settings);
  for (const size_t p : share(plan.todo, cluster)) {
    if (stopSignal() != 0) return false;
    out.commit(p, baker.bake(p, h.probes.positions[p]));
    drain();
  }
  while (committed < plan.todo.size()) {
    if (stopSignal() != 0) return false;
    if (!drain()) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return true;
}

void bakeAsWorker(const Plan& plan, Cluster& cluster) {
  const BakeHeader& h = plan.header;
  ProbeBaker baker(plan.scene, h.settings);
  for (const size_t p : share(plan.todo, cluster)) {
    if (stopSignal() != 0) return;
    cluster.send(p, pack(baker.bake(p, h.probes.positions[p])));
  }
  cluster.finishSends();
}

void printJson(const Plan& plan, const Cluster& cluster, const BakeFile& file,
               const Progress& progress) {
  const double n = double(std::max<size_t>(plan.todo.size(), 1));
  std::printf(
      "{\"probes\": %zu, \"seconds\": %.6g, \"probes_per_second\": %.6g, "
      "\"processes\": %d, \"bytes_per_probe\": %zu, \"commit_seconds_per_probe\": "
      "%.6g}\n",
      plan.todo.size(), progress.elapsedSeconds(), progress.rate(), cluster.size(),
      plan.header.shape.packedFloats() * sizeof(float), file.commitSeconds() / n);
}

/// Rank 0's watchdog over the other ranks (apps/bake/watchdog.h), when there are any.
std::unique_ptr<Watchdog> watch(const Plan& plan, const Cluster& cluster, const BakeFile& file) {
  if (cluster.size() < 2) return nullptr;
  std::vector<Watchdog::Peer> peers;
  for (const Cluster::Peer& p : cluster.peers()) peers.push_back({p.rank, p.pid});
  return std::make_unique<Watchdog>(std::move(peers), cluster.size(), file.path(),
                                    plan.header.probes.positions.size(), plan.alreadyDone);
}

int finishAsWriter(const Options& o, const Plan& plan, Cluster& cluster, BakeFile& file) {
  Progress progress(plan.todo.size(), plan.alreadyDone, o.quiet);
  std::unique_ptr<Watchdog> watchdog = watch(plan, cluster, file);
  Writer writer{file, progress, watchdog.get()};
  const bool finished = bakeAsWriter(plan, cluster, writer);
  watchdog.reset();  // every probe is in (or the single process was interrupted)
  progress.finish();
  if (!finished) {
    // Under mpirun a rank that dies makes mpirun stop the others with a signal: rank 0 cannot
    // tell that from a user's signal, so the line names both.
    std::fprintf(stderr,
                 "dpc-bake: %s: %s%s with %zu of %zu probes done; dpc-bake --resume %s "
                 "finishes it\n",
                 file.path().c_str(), Interrupted(stopSignal()).what(),
                 cluster.size() > 1 ? " (the user's, or mpirun's after a rank died)" : "",
                 plan.alreadyDone + progress.done(), plan.header.probes.positions.size(),
                 file.path().c_str());
    return unfinishedStatus();
  }
  file.markComplete();
  if (!o.map.empty()) writeParameterMap(file, o.map);
  if (o.json) printJson(plan, cluster, file, progress);
  std::fprintf(stderr,
               "dpc-bake: %s: %zu probes complete; this run baked %zu in %.1f s (%.3g "
               "probes/s, %d process%s)\n",
               file.path().c_str(), plan.header.probes.positions.size(), plan.todo.size(),
               progress.elapsedSeconds(), progress.rate(), cluster.size(),
               cluster.size() > 1 ? "es" : "");
  return 0;
}

/// The bake and the map, checked before any work as dpc-demo checks its outputs: each a
/// regular file or absent, naming no input of the scene (nor each other), in an existing
/// folder. A fresh bake's --out is checked too; a resumed one is the file being finished.
void checkBakeOutputs(const Options& o, const Plan& plan) {
  auto inputs = sceneInputFiles(plan.scene, o.scene.empty() ? plan.header.scenePath : o.scene);
  if (o.resume.empty()) checkOutputPath(o.out, "--out", inputs);
  if (o.map.empty()) return;
  const std::string bake = o.resume.empty() ? o.out : o.resume;
  inputs.push_back({bake, "the bake"});
  checkOutputPath(o.map, "--map", inputs);
  if (std::filesystem::weakly_canonical(std::filesystem::absolute(o.map)) ==
      std::filesystem::weakly_canonical(std::filesystem::absolute(bake)))
    throw InputError("command line", "--map",
                     "'" + o.map + "' is the bake; refusing to overwrite it");
}

}  // namespace

int runBake(const Options& o, Cluster& cluster) {
  catchStopSignals();
  Plan plan;
  if (!together(cluster, [&] {
        plan = o.resume.empty() ? planFresh(o) : planResume(o);
        checkBakeOutputs(o, plan);
        throwIfStopped();  // a signal while planning: no file opened or created
        return 0;
      }))
    return unfinishedStatus();
  std::optional<BakeFile> file;
  if (!together(cluster, [&] {
        if (cluster.rank() == 0) file.emplace(openOutput(o, plan));
        return 0;
      }))
    return unfinishedStatus();
  if (cluster.rank() != 0) {
    bakeAsWorker(plan, cluster);
    return stopSignal() != 0 ? unfinishedStatus() : 0;
  }
  if (!o.quiet) printEstimate(plan, cluster);
  return finishAsWriter(o, plan, cluster, *file);
}

}  // namespace dpc::bake
