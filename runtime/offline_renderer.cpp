#include "runtime/offline_renderer.h"

#include <algorithm>
#include <chrono>
#include <cmath>

namespace dpc {

double offlineDurationSeconds(const SceneDesc& scene, const PropagationSettings& settings,
                              const DrySignals& dry, const OfflineOptions& options) {
  if (options.durationSeconds >= 0.0) return options.durationSeconds;
  double content = double(dry.longestFrames()) / scene.audio.sampleRate;
  if (!scene.listener.loop && !scene.listener.trajectory.empty())
    content = std::max(content, scene.listener.trajectory.back().timeSeconds);
  for (const SourceDesc& s : scene.sources)
    if (!s.trajectoryLoop && !s.trajectory.empty())
      content = std::max(content, s.trajectory.back().timeSeconds);
  return content + settings.irLength;
}

OfflineResult renderOffline(const SceneDesc& scene, const PropagationSettings& settings,
                            const DrySignals& dry, const OfflineOptions& options) {
  const auto wall0 = std::chrono::steady_clock::now();
  const int fs = scene.audio.sampleRate;
  PropagationStage propagation(scene, settings);
  const int numOutputs = propagation.numOutputs();
  AudioStage audioStage(propagation.layout(), dry, numOutputs);
  const size_t B = size_t(scene.audio.blockSize);
  const double duration = offlineDurationSeconds(scene, settings, dry, options);
  const size_t totalFrames = size_t(std::ceil(duration * fs));
  const size_t blocks = (totalFrames + B - 1) / B;

  OfflineResult result;
  result.output.sampleRate = fs;
  const bool streaming = bool(options.sink);
  // Streaming: one block per channel, handed to the sink; otherwise the whole render is kept.
  result.output.channels.assign(size_t(numOutputs), std::vector<float>(streaming ? B : blocks * B));
  std::vector<float*> out(static_cast<size_t>(numOutputs));
  const double framePeriod = 1.0 / settings.frameRate;
  uint64_t nextFrame = 0;
  size_t lastReport = 0;
  for (size_t blk = 0; blk < blocks; ++blk) {
    const double t = double(blk * B) / fs;
    // Frames due by the start of this block (normally at most one).
    IrSet* newest = nullptr;
    while (double(nextFrame) * framePeriod <= t + 1e-12) {
      const double ft = double(nextFrame) * framePeriod;
      IrSet* set = propagation.computeFrame(listenerPositionAt(scene.listener, ft),
                                            listenerOrientationAt(scene.listener, ft), ft);
      if (newest) propagation.recycle(newest);  // superseded before the audio side saw it
      newest = set;
      ++nextFrame;
    }
    if (newest) audioStage.offer(newest);
    for (int c = 0; c < numOutputs; ++c)
      out[size_t(c)] = result.output.channels[size_t(c)].data() + (streaming ? 0 : blk * B);
    audioStage.process(out.data());
    if (streaming) options.sink(out.data(), std::min(B, totalFrames - blk * B));
    while (IrSet* spent = audioStage.takeSpent()) propagation.recycle(spent);
    if (options.progress && (blk + 1 == blocks || (blk - lastReport) * 100 >= blocks)) {
      options.progress(double((blk + 1) * B) / fs, double(blocks * B) / fs);
      lastReport = blk;
    }
  }
  if (streaming)
    result.output.channels.clear();
  else
    for (auto& ch : result.output.channels) ch.resize(totalFrames);
  result.lastIrs = propagation.lastIrs();
  result.totals = propagation.totals();
  for (size_t s = 0; s < propagation.simulation().sourceCount(); ++s) {
    result.cacheEntries += propagation.simulation().result(s).cacheEntries;
    const Simulation::SourceResult& sr = propagation.simulation().result(s);
    result.cacheBytes += sr.cacheBytes;
    result.cacheCoarseEntries += sr.cacheCoarseEntries;
    result.cacheBudgetBytes += sr.cacheBudgetBytes;
    result.cacheMergedEntries += sr.cacheMergedEntries;
    result.cacheCoarseEnergyFraction =
        std::max(result.cacheCoarseEnergyFraction, sr.cacheCoarseEnergyFraction);
    result.lastEnergy.push_back(sr.energy);
    result.lastDirect.push_back(sr.direct);
  }
  result.irsApplied = audioStage.irsApplied();
  result.wallSeconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  return result;
}

}  // namespace dpc
