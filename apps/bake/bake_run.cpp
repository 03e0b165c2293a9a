#include "apps/bake/bake_run.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "apps/bake/bake_plan.h"
#include "apps/bake/bake_wave.h"
#include "apps/bake/progress.h"
#include "apps/bake/watchdog.h"
#include "bake/bake_file.h"
#include "bake/bake_lock.h"
#include "bake/parameter_map.h"
#include "common/input_error.h"
#include "common/output_file.h"
#include "common/stop_signals.h"
#include "runtime/max_order_warning.h"
#include "scene/trajectory.h"

namespace dpc::bake {
namespace {

/// The exit status of a run that did not finish: 128 + the number of the stop signal that
/// ended it (common/stop_signals.h), else 1 (bad input, already reported).
int unfinishedStatus() {
  const int s = stopSignal();
  return s != 0 ? 128 + s : 1;
}

/// What a fresh bake's file adds to --out's name while a file is already there.
constexpr char kPartialSuffix[] = ".partial";

/// Where a fresh bake is written: --out itself when nothing is there yet, else beside the file
/// it would replace (where --out's links lead: the rename stays on one file system), with
/// kPartialSuffix, so that a bake already there stays whole until the new one is complete.
std::string freshPath(const std::string& out) {
  std::error_code ec;
  const std::string target = outputTarget(out);
  return std::filesystem::exists(target, ec) ? target + kPartialSuffix : out;
}

/// The file a complete bake at `path` replaces: X for X.partial, else "" (none).
std::string replacedBy(const std::string& path) {
  const std::string suffix = kPartialSuffix;
  if (path.size() <= suffix.size() || !path.ends_with(suffix)) return "";
  return path.substr(0, path.size() - suffix.size());
}

/// Rank 0's file: a fresh one built in a temporary next to its path (freshPath) and renamed
/// into place once its layout is written and flushed (so a disk too small fails here), or the
/// resumed one (marked incomplete again when probes it held were damaged and are baked anew).
BakeFile openOutput(const Options& o, const Plan& plan) {
  if (!o.resume.empty()) {
    BakeFile file = BakeFile::open(o.resume, BakeFile::Access::kWrite);
    if (plan.wasComplete && !(plan.todo.empty() && plan.waveTodo.empty())) file.markIncomplete();
    return file;
  }
  checkFreeSpace(o.out, plan.estimate.bytes, o.force);
  const std::string path = freshPath(o.out);
  TempOutputFile tmp(path);
  BakeFile file = BakeFile::create(tmp.tempPath(), path, plan.header);
  tmp.commit();
  file.renamedTo(path);
  return file;
}

/// A complete X.partial renamed onto X, the bake it was made to replace.
void replaceWithComplete(BakeFile& file) {
  const std::string to = replacedBy(file.path());
  if (to.empty()) return;
  checkReplaceable(to, outputTarget(to));
  std::error_code ec;
  std::filesystem::rename(file.path(), outputTarget(to), ec);
  if (ec) throw InputError(to, "", "cannot replace it with '" + file.path() + "': " + ec.message());
  file.renamedTo(to);
}

void printEstimate(const Plan& plan) {
  const BakeHeader& h = plan.header;
  const double rays = double(plan.todo.size()) * double(h.shape.sources) *
                      double(h.settings.frames) * double(h.settings.rays);
  std::fprintf(stderr,
               "dpc-bake: %zu probes to bake of %zu (%zu candidates: %zu outside, %zu inside "
               "geometry, %zu near a surface) x %zu sources x %d frames x %d rays = %.3g rays; "
               "estimate: %s\n",
               plan.todo.size(), h.probes.positions.size(), h.probes.candidates, h.probes.outside,
               h.probes.insideGeometry, h.probes.nearSurface, h.shape.sources, h.settings.frames,
               h.settings.rays, rays, describe(plan.estimate).c_str());
  if (!plan.waveTodo.empty())
    std::fprintf(stderr, "dpc-bake: the wave band first: %s\n", describe(plan.wave).c_str());
}

/// The energy the reflection order bound cuts off, measured in the frame timed for the
/// estimate, above kMaxOrderWarnFraction: one warning line (also with --quiet), as dpc-demo's.
void warnMaxOrder(const Options& o, const Plan& plan) {
  const double share = plan.baker ? plan.baker->maxOrderShare() : 0.0;
  if (!(share > kMaxOrderWarnFraction)) return;
  std::fprintf(stderr, "dpc-bake: warning: %s: %s (measured in the frame timed for the estimate)\n",
               (o.scene.empty() ? plan.header.scenePath : o.scene).c_str(),
               maxOrderWarning(plan.scene.propagation.maxOrder, share).c_str());
}

/// With --quiet, the probes of a --probes list that were skipped (outside the room, inside a
/// solid, too near a surface) still get one line: the user named each of them.
void warnSkippedProbes(const Options& o, const Plan& plan) {
  const BakeHeader& h = plan.header;
  const size_t skipped = h.probes.outside + h.probes.insideGeometry + h.probes.nearSurface;
  if (o.probes.empty() || skipped == 0) return;
  std::fprintf(stderr,
               "dpc-bake: %s: %zu of %zu listed probes skipped (%zu outside, %zu inside "
               "geometry, %zu near a surface)\n",
               o.probes.c_str(), skipped, h.probes.candidates, h.probes.outside,
               h.probes.insideGeometry, h.probes.nearSurface);
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
bool bakeAsWriter(Plan& plan, Cluster& cluster, Writer& out) {
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
  for (const size_t p : share(plan.todo, cluster)) {
    if (stopSignal() != 0) return false;
    out.commit(p, plan.baker->bake(p, h.probes.positions[p]));
    drain();
  }
  while (committed < plan.todo.size()) {
    if (stopSignal() != 0) return false;
    if (!drain()) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return true;
}

void bakeAsWorker(Plan& plan, Cluster& cluster) {
  const BakeHeader& h = plan.header;
  for (const size_t p : share(plan.todo, cluster)) {
    if (stopSignal() != 0) return;
    cluster.send(p, pack(plan.baker->bake(p, h.probes.positions[p])));
  }
  cluster.finishSends();
}

void printJson(const Plan& plan, const Cluster& cluster, const BakeFile& file,
               const Progress& progress, const WaveBakeStats& wave) {
  const double n = double(std::max<size_t>(plan.todo.size(), 1));
  std::printf(
      "{\"probes\": %zu, \"probes_skipped\": %zu, \"seconds\": %.6g, \"probes_per_second\": %.6g, "
      "\"processes\": %d, \"bytes_per_probe\": %zu, \"commit_seconds_per_probe\": "
      "%.6g, \"wave_sources\": %zu, \"wave_seconds\": %.6g, \"wave_unreached\": %zu}\n",
      plan.todo.size(),
      plan.header.probes.outside + plan.header.probes.insideGeometry + plan.header.probes.nearSurface,
      progress.elapsedSeconds(), progress.rate(), cluster.size(),
      plan.header.shape.packedFloats() * sizeof(float), file.commitSeconds() / n, wave.sources,
      wave.seconds, wave.unreached);
}

/// Rank 0's watchdog over the other ranks (apps/bake/watchdog.h), when there are any.
std::unique_ptr<Watchdog> watch(const Plan& plan, const Cluster& cluster, const BakeFile& file) {
  if (cluster.size() < 2) return nullptr;
  std::vector<Watchdog::Peer> peers;
  for (const Cluster::Peer& p : cluster.peers()) peers.push_back({p.rank, p.pid});
  return std::make_unique<Watchdog>(std::move(peers), cluster.size(), file.path(),
                                    plan.header.probes.positions.size(), plan.alreadyDone);
}

/// ", and the wave band of 2 sources in 3.1 s" when this run simulated any.
std::string waveSummary(const WaveBakeStats& wave) {
  if (wave.sources == 0) return "";
  char text[96];
  std::snprintf(text, sizeof text, ", and the wave band of %zu source%s in %.1f s",
                wave.sources, wave.sources > 1 ? "s" : "", wave.seconds);
  return text;
}

/// The map of the complete bake `file`. A map that cannot be written (a full disk) leaves the
/// bake complete, which the error says, with how to write the map again without baking.
void writeMapOf(const BakeFile& file, const std::string& map) {
  try {
    writeParameterMap(file, map);
  } catch (const InputError& e) {
    throw InputError(e.file(), e.field(),
                     e.problem() + "; the bake " + file.path() +
                         " is complete: dpc-bake --resume " + file.path() + " --map " + map +
                         " writes the map again");
  }
}

int finishAsWriter(const Options& o, Plan& plan, Cluster& cluster, BakeFile& file) {
  std::unique_ptr<Watchdog> watchdog = watch(plan, cluster, file);
  // The wave band first (the other ranks bake their probes meanwhile): its one simulation per
  // source serves every probe.
  WaveBakeStats wave;
  const bool waved = bakeWaveBands(plan, file, o.quiet, watchdog.get(), wave);
  Progress progress(plan.todo.size(), plan.alreadyDone, o.quiet);
  Writer writer{file, progress, watchdog.get()};
  const bool finished = waved && bakeAsWriter(plan, cluster, writer);
  watchdog.reset();  // every probe is in (or the single process was interrupted)
  progress.finish();
  if (!finished) {
    // Under mpirun a rank that dies makes mpirun stop the others with a signal: rank 0 cannot
    // tell that from a user's signal, so the line names both.
    const std::string replaces = replacedBy(file.path());
    std::fprintf(stderr,
                 "dpc-bake: %s: %s%s with %zu of %zu probes done; dpc-bake --resume %s "
                 "finishes it%s%s%s\n",
                 file.path().c_str(), Interrupted(stopSignal()).what(),
                 cluster.size() > 1 ? " (the user's, or mpirun's after a rank died)" : "",
                 plan.alreadyDone + progress.done(), plan.header.probes.positions.size(),
                 file.path().c_str(), replaces.empty() ? "" : " and then replaces ",
                 replaces.c_str(), replaces.empty() ? "" : ", untouched until then");
    return unfinishedStatus();
  }
  file.markComplete();
  replaceWithComplete(file);
  if (!o.map.empty()) writeMapOf(file, o.map);
  if (o.json) printJson(plan, cluster, file, progress, wave);
  std::fprintf(stderr,
               "dpc-bake: %s: %zu probes complete; this run baked %zu in %.1f s (%.3g "
               "probes/s, %d process%s)%s\n",
               file.path().c_str(), plan.header.probes.positions.size(), plan.todo.size(),
               progress.elapsedSeconds(), progress.rate(), cluster.size(),
               cluster.size() > 1 ? "es" : "", waveSummary(wave).c_str());
  return 0;
}

/// The bake this run writes (resuming X.partial, the X it replaces: one lock for both), its
/// path checked as an output (fresh bakes) before its lock is taken: a folder that does not
/// exist is named as such, not as a lock file that cannot be made.
std::string lockedOutput(const Options& o) {
  if (!o.resume.empty()) {
    const std::string replaces = replacedBy(o.resume);
    return replaces.empty() ? o.resume : replaces;
  }
  checkOutputPath(o.out, "--out", {});
  // The suffix is the partial bake's: completed, X.partial replaces X.
  if (!replacedBy(o.out).empty())
    throw InputError("command line", "--out",
                     "'" + o.out + "' ends in " + kPartialSuffix +
                         ", the name of a bake built beside the one it will replace; choose "
                         "another name");
  return o.out;
}

/// The bake and the map, checked before any work as dpc-demo checks its outputs: each a
/// regular file or absent, naming no input of the scene or the --probes list (nor each other,
/// nor the bake a resumed X.partial will replace), in an existing folder; the writer (rank 0)
/// makes and removes a temporary beside the map. A fresh bake's --out is checked too; a
/// resumed one is the file being finished.
void checkBakeOutputs(const Options& o, const Plan& plan, bool writer) {
  auto inputs = sceneInputFiles(plan.scene, o.scene.empty() ? plan.header.scenePath : o.scene);
  if (!o.probes.empty()) inputs.push_back({o.probes, "the probe list"});
  if (o.resume.empty()) {
    checkOutputPath(o.out, "--out", inputs);
    checkOutputFormat("--out", o.out, {"HDF5"});
  }
  if (o.map.empty()) return;
  std::vector<std::string> bakes{o.resume.empty() ? o.out : o.resume};
  if (!o.resume.empty() && !replacedBy(o.resume).empty()) bakes.push_back(replacedBy(o.resume));
  for (const std::string& bake : bakes) inputs.push_back({bake, "the bake"});
  if (writer)
    checkOutputCreatable(o.map, "--map", inputs);
  else
    checkOutputPath(o.map, "--map", inputs);
  for (const std::string& bake : bakes)
    if (std::filesystem::weakly_canonical(std::filesystem::absolute(o.map)) ==
        std::filesystem::weakly_canonical(std::filesystem::absolute(bake)))
      throw InputError("command line", "--map",
                       "'" + o.map + "' is the bake; refusing to overwrite it");
  checkOutputFormat("--map", o.map, {"CSV"});
}

}  // namespace

int runBake(const Options& o, Cluster& cluster) {
  catchStopSignals();
  const bool writer = cluster.rank() == 0;
  std::optional<BakeLock> lock;  // rank 0, the one writer, holds it until the file is done
  Plan plan;
  if (!together(cluster, "dpc-bake", [&] {
        if (writer) lock.emplace(lockedOutput(o));
        if (o.resume.empty())
          planFresh(o, cluster.size(), writer, plan);
        else
          planResume(o, cluster.size(), writer, plan);
        checkBakeOutputs(o, plan, writer);
        throwIfStopped();  // a signal while planning: no file opened or created
        return 0;
      }))
    return unfinishedStatus();
  std::optional<BakeFile> file;
  if (!together(cluster, "dpc-bake", [&] {
        if (writer) file.emplace(openOutput(o, plan));
        return 0;
      }))
    return unfinishedStatus();
  if (!writer) {
    bakeAsWorker(plan, cluster);
    return stopSignal() != 0 ? unfinishedStatus() : 0;
  }
  if (!o.quiet) printEstimate(plan);
  if (o.quiet) warnSkippedProbes(o, plan);
  if (o.spacingGiven) warnWaveProbeSpacing(plan.scene, o.grid.spacingM);
  warnMaxOrder(o, plan);
  if (cluster.size() == 1) return finishAsWriter(o, plan, cluster, *file);
  // With other ranks, an error here (a write the disk refused) must end the job: the others
  // would wait for rank 0 to receive their probes. Every probe committed so far is flushed.
  const int status = runReportingErrors("dpc-bake", [&] {
    return finishAsWriter(o, plan, cluster, *file);
  });
  if (status == 1) {
    lock.reset();
    std::fflush(stderr);
    std::_Exit(1);
  }
  return status;
}

}  // namespace dpc::bake
