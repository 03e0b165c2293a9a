#include "runtime/hybrid_synthesis.h"

#include <algorithm>
#include <cmath>
#include <glm/geometric.hpp>

#include "common/random.h"
#include "runtime/baked_playback.h"
#include "runtime/output_format.h"
#include "runtime/own_threads.h"

namespace dpc {

bool rendersHybrid(const AudioSettings& audio, size_t sources) {
  if (audio.rendering == Rendering::kAuto) return sources > size_t(audio.lateBuses);
  return audio.rendering == Rendering::kHybrid;
}

/// Per-frame buffers, sized at construction or on a listener's first frame.
struct HybridSynthesis::Scratch {
  EnergyResponse early;                            ///< mono: one source's early part
  std::vector<EnergyResponse> late;                ///< mono: per bus
  std::vector<DirectionalEnergyResponse> earlyDirs;  ///< spatial: per source, its early part
  std::vector<DirectionalEnergyResponse> lateDir;  ///< spatial: per bus
  std::vector<SpecularPath> paths;                 ///< one source's early exact paths
  std::vector<double> lateEnergy;                  ///< per source, this frame
  std::vector<double> busEnergy;                   ///< per bus, this frame
  std::vector<float*> channels;                    ///< one IR's channel pointers
};

/// One worker workspace's buffers for the early parts.
struct HybridSynthesis::WorkerScratch {
  EnergyResponse early;  ///< mono
  std::vector<SpecularPath> paths;
  std::vector<float*> channels;  ///< spatial: one IR's channel pointers
};

HybridSynthesis::HybridSynthesis(const SceneDesc& scene, const PropagationSettings& settings,
                                 double roomVolume, SpatialIrSynthesizer* spatial,
                                 double earlySeconds, size_t listeners, int workers,
                                 SpatialIrSynthesizer::ParallelFor parallel,
                                 IrSynthesizer::Build build)
    : buses_(scene.audio.lateBuses),
      clusterAngle_(double(scene.audio.clusterAngleDegrees) * M_PI / 180.0),
      spatial_(spatial),
      scratch_(std::make_unique<Scratch>()) {
  split_.fadeSeconds = kHybridFadeSeconds;
  split_.splitSeconds = earlySeconds;
  const size_t S = scene.sources.size();
  if (spatial_) {
    buildSpatial(scene, settings, roomVolume, earlySeconds, workers, std::move(parallel));
  } else {
    buildMono(scene, settings, roomVolume, earlySeconds, workers, std::move(parallel), build);
  }
  scratch_->lateEnergy.assign(S, 0.0);
  for (WorkerScratch& w : workers_) {
    w.paths.reserve(256);
    w.channels.reserve(spatial_ ? spatial_->channelCount() : 1);
  }
  scratch_->busEnergy.assign(size_t(buses_), 0.0);
  scratch_->paths.reserve(256);
  for (size_t l = 0; l < listeners; ++l) ensureListener(l, S);
}

HybridSynthesis::~HybridSynthesis() = default;

size_t HybridSynthesis::groupCount(bool parallel, int workers, size_t sources) {
  if (!parallel) return 1;
  const size_t groups = size_t(std::max(workers, 2));
  return std::clamp<size_t>(groups, 1, std::max<size_t>(sources, 1));
}

void HybridSynthesis::buildSpatial(const SceneDesc& scene, const PropagationSettings& settings,
                                   double roomVolume, double earlySeconds, int workers,
                                   SpatialIrSynthesizer::ParallelFor parallel) {
  // One synthesiser renders every source's early part (each its own late field); the groups'
  // copies share its band signals and filters, each with workspaces of its own.
  const size_t W = groupCount(bool(parallel), workers, scene.sources.size());
  earlySpatial_.push_back(
      makeSpatialSynthesizer(scene, settings, roomVolume, earlySeconds, 0x2545f4914f6cdd1dULL));
  while (earlySpatial_.size() < W) earlySpatial_.push_back(earlySpatial_.front()->workspaceCopy());
  workers_.resize(W);
  slots_.reset(W);
  parallel_ = std::move(parallel);
  earlySamples_ = earlySpatial_.front()->lengthSamples();
}

void HybridSynthesis::buildMono(const SceneDesc& scene, const PropagationSettings& settings,
                                double roomVolume, double earlySeconds, int workers,
                                SpatialIrSynthesizer::ParallelFor parallel,
                                IrSynthesizer::Build build) {
  const int fs = scene.audio.sampleRate;
  const size_t S = scene.sources.size();
  // Per source its own Dirac sequence (sources playing one signal stay incoherent); the
  // read-only filters and the clean-up workspace are shared by the synthesisers of a length
  // that one worker runs (sources s = w, w + W, ...). At least two workers' workspaces, so
  // that two groups are built at once whatever the tracing threads (the IRs are the same for
  // any grouping).
  const size_t W = groupCount(bool(parallel), workers, S);
  workers_.resize(W);
  slots_.reset(W);
  parallel_ = std::move(parallel);
  earlyMono_.resize(S);
  lateMono_.resize(size_t(buses_));
  const auto group = [&](size_t w) {
    for (size_t s = w; s < S; s += W)
      earlyMono_[s] =
          std::make_unique<IrSynthesizer>(fs, earlySeconds, roomVolume, settings.speedOfSound,
                                          hashCombine(settings.seed, 0x5bd1e995ULL + s),
                                          s < W ? nullptr : earlyMono_[s % W].get(), build);
  };
  const auto late = [&] {
    for (size_t k = 0; k < lateMono_.size(); ++k)
      lateMono_[k] = std::make_unique<IrSynthesizer>(
          fs, settings.irLength, roomVolume, settings.speedOfSound,
          hashCombine(settings.seed, 0x9e3779b97f4a7c15ULL + uint64_t(k)),
          k == 0 ? nullptr : lateMono_.front().get(), build);
  };
  concurrently(late, group);
  earlySamples_ = earlyMono_.front()->lengthSamples();
  monoWorkspaces_.resize(W);
  for (size_t w = 0; w < W; ++w) monoWorkspaces_[w] = earlyMono_[w]->workspace();
}

void HybridSynthesis::concurrently(const std::function<void()>& late,
                                   const std::function<void(size_t)>& group) const {
  // The groups and the late buses share no workspace: they run concurrently (their
  // construction is the time to first sound of a live session with many sources).
  onOwnThreads(workers_.size() + 1, [&](size_t i) { i == 0 ? late() : group(i - 1); });
}

bool HybridSynthesis::completed() const {
  for (const auto& synth : earlyMono_)
    if (!synth->completed()) return false;
  for (const auto& synth : lateMono_)
    if (!synth->completed()) return false;
  return true;
}

void HybridSynthesis::complete() {
  if (completed()) return;
  forgetMade();
  const size_t S = earlyMono_.size(), W = workers_.size();
  // The order of construction: each group's first synthesiser before those sharing with it.
  const auto group = [&](size_t w) {
    for (size_t s = w; s < S; s += W)
      earlyMono_[s]->complete(s < W ? nullptr : earlyMono_[s % W].get());
  };
  const auto late = [&] {
    for (size_t k = 0; k < lateMono_.size(); ++k)
      lateMono_[k]->complete(k == 0 ? nullptr : lateMono_.front().get());
  };
  concurrently(late, group);
  // Each group's first synthesiser made its group's window leveller.
  for (size_t w = 0; w < monoWorkspaces_.size(); ++w)
    monoWorkspaces_[w].windowLeveller = earlyMono_[w]->workspace().windowLeveller;
}

size_t HybridSynthesis::lateSamples() const {
  return spatial_ ? spatial_->lengthSamples() : lateMono_.front()->lengthSamples();
}

void HybridSynthesis::ensureListener(size_t listener, size_t sources) {
  while (clusters_.size() <= listener) {
    clusters_.push_back(std::make_unique<SourceClusters>(sources, buses_, clusterAngle_));
    counts_.emplace_back();
    made_.emplace_back(size_t(buses_));
  }
  early_.ensure(listener + 1, sources, workers_.size());
}

void HybridSynthesis::forgetMade() {
  for (auto& buses : made_)
    for (BusMade& m : buses) m.valid = false;
  early_.forget();
}

namespace {
/// out's bins = in's first out.binCount() bins (same bin width); no allocation.
void copyPrefix(const EnergyResponse& in, EnergyResponse& out) {
  const size_t n = std::min(in.binCount(), out.binCount());
  std::copy_n(in.bins().begin(), n, out.bins().begin());
  std::fill(out.bins().begin() + std::ptrdiff_t(n), out.bins().end(), Bands(0.f));
}
}  // namespace

void HybridSynthesis::prepareBuses(const Simulation& sim, size_t listener) {
  Scratch& x = *scratch_;
  const size_t B = size_t(buses_);
  // The early scratch: the response's bins up to the early part's end (allocated once).
  const EnergyResponse& any = sim.result(0, listener).energy;
  if (x.early.binCount() == 0) {
    const double early = split_.splitSeconds + any.binSeconds();
    x.early = EnergyResponse(early, any.binSeconds());
    for (WorkerScratch& w : workers_) w.early = x.early;
    if (spatial_)
      x.earlyDirs.assign(x.lateEnergy.size(), sim.directional(0, listener).truncated(early));
  }
  if (spatial_) {
    x.lateDir.resize(B);
    for (DirectionalEnergyResponse& r : x.lateDir) {
      r = sim.directional(0, listener);  // the listener's frame, bins and directions
      r.clear();
    }
  } else {
    x.late.resize(B);
    for (EnergyResponse& r : x.late) {
      r = sim.result(0, listener).energy;
      r.clear();
    }
  }
}

double HybridSynthesis::splitSpatial(const Simulation& sim, size_t s, size_t listener, int k,
                                     BakedPlayback* baked) {
  Scratch& x = *scratch_;
  const DirectionalEnergyResponse& live = sim.directional(s, listener);
  const DirectionalEnergyResponse& in = baked ? baked->directional(s, listener, live) : live;
  const LateShare share = addLate(in, sim.result(s, listener).direct,
                                  sim.specularPaths(s, listener), split_, x.lateDir[size_t(k)]);
  DirectionalEnergyResponse& early = x.earlyDirs[s];
  early.copyFrame(in);
  for (size_t d = 0; d < in.directionCount(); ++d) copyPrefix(in.response(d), early.response(d));
  keepEarly(early, split_);
  HybridCounts& n = counts_[listener];
  n.lateDirect += share.directIsLate ? 1 : 0;
  n.lateArrivals += uint64_t(share.lateArrivals);
  return share.energy;
}

void HybridSynthesis::synthesizeSpatialEarly(const Simulation& sim, size_t s, size_t listener,
                                             size_t w, ImpulseResponse& early) {
  WorkerScratch& x = workers_[w];
  earlyPaths(sim.specularPaths(s, listener), split_, x.paths);
  DirectSound direct = sim.result(s, listener).direct;
  if (split_.directIsLate(direct)) direct.visible = false;  // in its bus
  const DirectionalEnergyResponse& response = scratch_->earlyDirs[s];
  if (early_.kept(response, direct, x.paths, &response.frame(), listener, s, w)) return;
  x.channels.resize(size_t(early.channels()));
  for (int c = 0; c < early.channels(); ++c) x.channels[size_t(c)] = early.channel(c);
  earlySpatial_[w]->synthesize(response, direct, x.channels, x.paths, s);
  early_.made(listener, s, w);
}

double HybridSynthesis::addMonoLate(const Simulation& sim, size_t s, size_t listener, int k,
                                    BakedPlayback* baked) {
  Scratch& x = *scratch_;
  const Simulation::SourceResult& r = sim.result(s, listener);
  const EnergyResponse& in = baked ? baked->energy(s, listener, r.energy) : r.energy;
  const LateShare share =
      addLate(in, r.direct, sim.specularPaths(s, listener), split_, x.late[size_t(k)]);
  HybridCounts& n = counts_[listener];
  n.lateDirect += share.directIsLate ? 1 : 0;
  n.lateArrivals += uint64_t(share.lateArrivals);
  return share.energy;
}

void HybridSynthesis::synthesizeMonoEarly(const Simulation& sim, size_t s, size_t listener,
                                          size_t w, BakedPlayback* baked,
                                          ImpulseResponse& early) {
  WorkerScratch& x = workers_[w];
  const Simulation::SourceResult& r = sim.result(s, listener);
  earlyPaths(sim.specularPaths(s, listener), split_, x.paths);
  DirectSound direct = r.direct;
  if (split_.directIsLate(direct)) direct.visible = false;  // in its bus
  // Worker threads run this concurrently: the bake is read into the worker's own scratch.
  if (baked && baked->plays(s, listener))
    baked->interpolate(s, listener, x.early);
  else
    copyPrefix(r.energy, x.early);
  keepEarly(x.early, split_);
  if (early_.kept(x.early, direct, x.paths, nullptr, listener, s, w)) return;
  earlyMono_[s]->useWorkspace(monoWorkspaces_[w]);
  earlyMono_[s]->synthesize(x.early, direct, early.channel(0), x.paths);
  early_.made(listener, s, w);
}

void HybridSynthesis::splitSources(const Simulation& sim, size_t listener, BakedPlayback* baked,
                                   std::span<const int> bus) {
  Scratch& x = *scratch_;
  std::fill(x.busEnergy.begin(), x.busEnergy.end(), 0.0);
  for (size_t s = 0; s < sim.sourceCount(); ++s) {
    const int k = bus[s];
    x.lateEnergy[s] = spatial_ ? splitSpatial(sim, s, listener, k, baked)
                               : addMonoLate(sim, s, listener, k, baked);
    x.busEnergy[size_t(k)] += x.lateEnergy[s];
  }
}

void HybridSynthesis::synthesizeAll(const Simulation& sim, size_t listener, BakedPlayback* baked,
                                    std::span<const int> bus, std::vector<ImpulseResponse>& early,
                                    std::vector<ImpulseResponse>& late) {
  // Job 0: the buses (mono output: the sources' late shares first; spatial output split them
  // before, as its early jobs read the early responses that splitting makes); job 1 + s:
  // source s's early part, in a worker workspace no other job holds meanwhile. Jobs of one
  // source each let the threads share the frame evenly, whatever the buses take.
  const size_t S = sim.sourceCount();
  const auto job = [&](size_t j) {
    if (j == 0) {
      if (!spatial_) splitSources(sim, listener, baked, bus);
      return updateBuses(listener, late);
    }
    const size_t s = j - 1;
    const WorkspaceSlots::Held held(slots_);
    spatial_ ? synthesizeSpatialEarly(sim, s, listener, held.slot(), early[s])
             : synthesizeMonoEarly(sim, s, listener, held.slot(), baked, early[s]);
  };
  if (parallel_) {
    parallel_(S + 1, std::ref(job));  // by reference: no std::function allocation per frame
  } else {
    for (size_t j = 0; j <= S; ++j) job(j);
  }
  early_.drainCounts(listener);
}

void HybridSynthesis::synthesizeBus(int k, ImpulseResponse& late) {
  Scratch& x = *scratch_;
  x.channels.resize(size_t(late.channels()));
  for (int c = 0; c < late.channels(); ++c) x.channels[size_t(c)] = late.channel(c);
  const DirectSound none;
  if (spatial_)
    spatial_->synthesize(x.lateDir[size_t(k)], none, x.channels, {}, size_t(k));
  else
    lateMono_[size_t(k)]->synthesize(x.late[size_t(k)], none, x.channels[0]);
}

void HybridSynthesis::updateBuses(size_t listener, std::vector<ImpulseResponse>& late) {
  Scratch& x = *scratch_;
  HybridCounts& n = counts_[listener];
  for (int k = 0; k < buses_; ++k) {
    const LateShape shape = spatial_ ? LateShape::of(x.lateDir[size_t(k)], split_.splitSeconds)
                                     : LateShape::of(x.late[size_t(k)], split_.splitSeconds);
    BusMade& made = made_[listener][size_t(k)];
    if (keepToleranceDb_ > 0.0 && made.valid && shape.maxExcessDb(made.shape) <= keepToleranceDb_) {
      ++n.busesKept;
      continue;
    }
    synthesizeBus(k, late[size_t(k)]);
    made = BusMade{shape, x.busEnergy[size_t(k)], true, ++lastBusIrId_};
    ++n.busesSynthesized;
  }
}

void HybridSynthesis::prepare(const Simulation& sim, size_t listener,
                              const glm::vec3& listenerPosition, std::span<const glm::vec3> sources,
                              BakedPlayback* baked,
                              std::vector<ImpulseResponse>& early,
                              std::vector<ImpulseResponse>& late,
                              std::span<float> gain, std::span<int> bus) {
  Scratch& x = *scratch_;
  const size_t S = sim.sourceCount();
  ensureListener(listener, S);
  prepareBuses(sim, listener);
  SourceClusters& clusters = *clusters_[listener];
  const Tracer& tracer = sim.tracer();
  clusters.update(listenerPosition, sources, [&tracer](const glm::vec3& a, const glm::vec3& b) {
    return lineOfSight(tracer, a, b);
  });
  for (size_t s = 0; s < S; ++s) bus[s] = clusters.cluster(s);
  if (spatial_) splitSources(sim, listener, baked, bus);
  synthesizeAll(sim, listener, baked, bus, early, late);
  for (size_t s = 0; s < S; ++s) {
    // The energy the bus's playing IR holds: each source gets exactly its own late energy.
    const double e = made_[listener][size_t(bus[s])].energy;
    gain[s] = e > 0.0 ? float(std::sqrt(x.lateEnergy[s] / e)) : 0.f;
  }
  HybridCounts& n = counts_[listener];
  ++n.frames;
  n.occupiedBuses = clusters.occupied();
  n.maxAngularRadiusDegrees = clusters.maxAngularRadius() * 180.0 / M_PI;
  n.switches = clusters.switches();
  n.forcedJoins = clusters.forcedJoins();
}

HybridReport HybridSynthesis::report(size_t listener) const {
  HybridReport r;
  r.on = true;
  r.earlySeconds = split_.splitSeconds;
  r.buses = buses_;
  if (listener < counts_.size()) r.counts = counts_[listener];
  return r;
}

}  // namespace dpc
