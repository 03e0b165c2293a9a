#include "runtime/offline_renderer.h"

#include <algorithm>
#include <chrono>
#include <cmath>

namespace dpc {

double offlineDurationSeconds(const SceneDesc& scene, const PropagationSettings& settings,
                              const DrySignals& dry, const OfflineOptions& options) {
  if (options.durationSeconds >= 0.0) return options.durationSeconds;
  double content = double(dry.longestFrames()) / scene.audio.sampleRate;
  const bool all = options.allListeners && !scene.listeners.empty();
  for (const ListenerDesc& l : all ? scene.listeners : std::vector<ListenerDesc>{scene.listener})
    if (!l.loop && !l.trajectory.empty())
      content = std::max(content, l.trajectory.back().timeSeconds);
  for (const SourceDesc& s : scene.sources)
    if (!s.trajectoryLoop && !s.trajectory.empty())
      content = std::max(content, s.trajectory.back().timeSeconds);
  return content + settings.irLength;
}

OfflineResult renderOffline(const SceneDesc& scene, const PropagationSettings& settings,
                            const DrySignals& dry, const OfflineOptions& options) {
  const auto wall0 = std::chrono::steady_clock::now();
  const int fs = scene.audio.sampleRate;
  // The listeners rendered: every scene listener from one pass, or scene.listener alone.
  const bool all = options.allListeners && !scene.listeners.empty();
  const std::vector<ListenerDesc> listeners =
      all ? scene.listeners : std::vector<ListenerDesc>{scene.listener};
  const size_t L = listeners.size();
  // Each audio stage holds at most a current and a pending set; one more per listener is being
  // filled while the others wait.
  PropagationStage propagation(scene, settings, int(std::max<size_t>(4, 3 * L + 1)));
  const int numOutputs = propagation.numOutputs();
  std::vector<std::unique_ptr<AudioStage>> audioStages;
  for (size_t l = 0; l < L; ++l)
    audioStages.push_back(std::make_unique<AudioStage>(propagation.layout(), dry, numOutputs));
  const size_t B = size_t(scene.audio.blockSize);
  const double duration = offlineDurationSeconds(scene, settings, dry, options);
  const size_t totalFrames = size_t(std::ceil(duration * fs));
  const size_t blocks = (totalFrames + B - 1) / B;

  OfflineResult result;
  const bool streaming = bool(options.sink);
  result.listeners.resize(L);
  for (size_t l = 0; l < L; ++l) {
    result.listeners[l].name = listeners[l].name;
    result.listeners[l].output.sampleRate = fs;
    // Streaming: one block per channel, handed to the sink; otherwise the whole render is kept.
    result.listeners[l].output.channels.assign(size_t(numOutputs),
                                               std::vector<float>(streaming ? B : blocks * B));
  }
  std::vector<float*> out(static_cast<size_t>(numOutputs));
  std::vector<IrSet*> newest(L, nullptr);
  WorldState world;
  const double framePeriod = 1.0 / settings.frameRate;
  uint64_t nextFrame = 0;
  size_t lastReport = 0;
  for (size_t blk = 0; blk < blocks; ++blk) {
    const double t = double(blk * B) / fs;
    // Frames due by the start of this block (normally at most one).
    std::fill(newest.begin(), newest.end(), nullptr);
    while (double(nextFrame) * framePeriod <= t + 1e-12) {
      const double ft = double(nextFrame) * framePeriod;
      if (all) {
        evaluateWorld(scene, ft, world);
        propagation.traceWorld(world);
        for (size_t l = 0; l < L; ++l) {
          IrSet* set = propagation.prepare(l);
          if (newest[l]) propagation.recycle(newest[l]);  // superseded before it was heard
          newest[l] = set;
        }
      } else {
        IrSet* set = propagation.computeFrame(listenerPositionAt(scene.listener, ft),
                                              listenerOrientationAt(scene.listener, ft), ft);
        if (newest[0]) propagation.recycle(newest[0]);
        newest[0] = set;
      }
      ++nextFrame;
    }
    for (size_t l = 0; l < L; ++l) {
      if (newest[l]) audioStages[l]->offer(newest[l]);
      for (int c = 0; c < numOutputs; ++c)
        out[size_t(c)] =
            result.listeners[l].output.channels[size_t(c)].data() + (streaming ? 0 : blk * B);
      audioStages[l]->process(out.data());
      if (streaming) options.sink(l, out.data(), std::min(B, totalFrames - blk * B));
      while (IrSet* spent = audioStages[l]->takeSpent()) propagation.recycle(spent);
    }
    if (options.progress && (blk + 1 == blocks || (blk - lastReport) * 100 >= blocks)) {
      options.progress(double((blk + 1) * B) / fs, double(blocks * B) / fs);
      lastReport = blk;
    }
  }
  result.totals = propagation.totals();
  const Simulation& sim = propagation.simulation();
  for (size_t l = 0; l < L; ++l) {
    OfflineListenerResult& lr = result.listeners[l];
    if (streaming)
      lr.output.channels.clear();
    else
      for (auto& ch : lr.output.channels) ch.resize(totalFrames);
    lr.lastIrs = propagation.lastIrs(l);
    lr.irsApplied = audioStages[l]->irsApplied();
    for (size_t s = 0; s < sim.sourceCount(); ++s) {
      const Simulation::SourceResult& sr = sim.result(s, l);
      result.cacheEntries += sr.cacheEntries;
      result.cacheBytes += sr.cacheBytes;
      result.cacheCoarseEntries += sr.cacheCoarseEntries;
      result.cacheBudgetBytes += sr.cacheBudgetBytes;
      result.cacheMergedEntries += sr.cacheMergedEntries;
      result.cacheCoarseEnergyFraction =
          std::max(result.cacheCoarseEnergyFraction, sr.cacheCoarseEnergyFraction);
      lr.lastEnergy.push_back(sr.energy);
      lr.lastDirect.push_back(sr.direct);
    }
  }
  result.wallSeconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  return result;
}

}  // namespace dpc
