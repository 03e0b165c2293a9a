#include "apps/pipeline/render_pipeline.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "audio/resample.h"
#include "engine/input_error.h"

namespace dpc {

namespace {
double secondsSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}
}  // namespace

size_t DrySignals::longestFrames() const {
  size_t once = 0, any = 0;
  for (size_t i = 0; i < samples.size(); ++i) {
    any = std::max(any, samples[i].size());
    if (!loop[i]) once = std::max(once, samples[i].size());
  }
  return once > 0 ? once : any;
}

DrySignals loadDrySignals(const SceneDesc& scene) {
  DrySignals d;
  for (size_t i = 0; i < scene.sources.size(); ++i) {
    const SourceDesc& src = scene.sources[i];
    const std::string field = "sources[" + std::to_string(i) + "].signal";
    audio::AudioData a;
    try {
      a = audio::readWav(src.signalPath);
    } catch (const InputError& e) {
      throw InputError(scene.path, field, e.what());
    }
    if (a.frames() == 0) throw InputError(scene.path, field, src.signalPath + ": no samples");
    if (a.channels.size() > 1) {
      std::vector<float> mono(a.frames(), 0.f);
      for (const auto& ch : a.channels)
        for (size_t n = 0; n < mono.size(); ++n) mono[n] += ch[n] / float(a.channels.size());
      d.notes.push_back(src.signalPath + ": " + std::to_string(a.channels.size()) +
                        " channels mixed to mono");
      a.channels = {std::move(mono)};
    }
    if (a.sampleRate != scene.audio.sampleRate) {
      d.notes.push_back(src.signalPath + ": resampled " + std::to_string(a.sampleRate) + " -> " +
                        std::to_string(scene.audio.sampleRate) + " Hz");
      a = audio::resample(a, scene.audio.sampleRate);
    }
    const float gain = float(std::pow(10.0, src.gainDb / 20.0));
    for (float& x : a.channels[0]) x *= gain;
    d.samples.push_back(std::move(a.channels[0]));
    d.loop.push_back(src.loop ? 1 : 0);
  }
  return d;
}

PropagationStage::PropagationStage(const SceneDesc& scene, const PropagationSettings& settings,
                                   int numOutputs, int poolSize)
    : scene_(scene), numOutputs_(numOutputs) {
  simulation_ = std::make_unique<Simulation>(scene, settings);
  const int fs = scene.audio.sampleRate;
  for (size_t s = 0; s < scene.sources.size(); ++s)
    synthesizers_.push_back(std::make_unique<IrSynthesizer>(
        fs, settings.irLength, simulation_->boundingVolume(), settings.speedOfSound,
        hashCombine(settings.seed, 0x5bd1e995ULL + s)));
  irSamples_ = synthesizers_.front()->lengthSamples();
  layout_ = std::make_unique<audio::ConvolverLayout>(scene.audio.blockSize, irSamples_);
  for (int i = 0; i < poolSize; ++i) {
    auto set = std::make_unique<IrSet>();
    for (size_t s = 0; s < scene.sources.size(); ++s)
      set->sources.push_back(std::make_unique<audio::IrSpectra>(*layout_, numOutputs));
    free_.push_back(set.get());
    pool_.push_back(std::move(set));
  }
  irs_.assign(scene.sources.size(),
              std::vector<std::vector<float>>(size_t(numOutputs), std::vector<float>(irSamples_)));
}

IrSet* PropagationStage::computeFrame(const glm::vec3& listener, double t) {
  if (free_.empty()) return nullptr;
  IrSet* set = free_.back();
  free_.pop_back();
  auto t0 = std::chrono::steady_clock::now();
  simulation_->runFrame(listener);
  totals_.traceSeconds += secondsSince(t0);
  for (size_t s = 0; s < synthesizers_.size(); ++s) {
    const Simulation::SourceResult& r = simulation_->result(s);
    totals_.rays += r.trace.rays;
    totals_.segments += r.trace.segments;
    t0 = std::chrono::steady_clock::now();
    synthesizers_[s]->synthesize(r.energy, r.direct, irs_[s][0].data());
    for (int c = 1; c < numOutputs_; ++c) irs_[s][size_t(c)] = irs_[s][0];
    totals_.synthesisSeconds += secondsSince(t0);
    t0 = std::chrono::steady_clock::now();
    std::vector<const float*> channels;
    for (int c = 0; c < numOutputs_; ++c) channels.push_back(irs_[s][size_t(c)].data());
    set->sources[s]->prepare(channels.data(), irSamples_);
    totals_.prepareSeconds += secondsSince(t0);
  }
  set->frame = simulation_->framesRun() - 1;
  set->poseTimeSeconds = t;
  ++totals_.frames;
  return set;
}

void PropagationStage::recycle(IrSet* set) {
  if (set) free_.push_back(set);
}

AudioStage::AudioStage(const audio::ConvolverLayout& layout, const DrySignals& dry,
                       int numOutputs)
    : layout_(layout), dry_(dry), numOutputs_(numOutputs) {
  for (size_t s = 0; s < dry.samples.size(); ++s)
    convolvers_.push_back(std::make_unique<audio::PartitionedConvolver>(layout, numOutputs));
  tail_.assign(size_t(layout.blockSize()), 0.f);
}

void AudioStage::offer(IrSet* set) {
  if (pending_ && spentCount_ < kSpentCapacity) spent_[spentCount_++] = pending_;
  pending_ = set;
}

void AudioStage::process(float* const* out) {
  const size_t B = size_t(layout_.blockSize());
  IrSet* swapped = nullptr;
  if (pending_) {
    bool ok = true;
    for (size_t s = 0; s < convolvers_.size(); ++s)
      ok = convolvers_[s]->setNextIr(pending_->sources[s].get()) && ok;
    if (ok) {
      swapped = current_;
      current_ = pending_;
      pending_ = nullptr;
      ++applied_;
    }
  }
  for (int c = 0; c < numOutputs_; ++c) std::fill(out[c], out[c] + B, 0.f);
  for (size_t s = 0; s < convolvers_.size(); ++s) {
    const std::vector<float>& x = dry_.samples[s];
    if (dry_.loop[s]) {
      // Looping signal: read B samples from position mod length, wrapping as often as needed.
      size_t p = position_ % x.size();
      for (size_t i = 0; i < B; ++i) {
        tail_[i] = x[p];
        if (++p == x.size()) p = 0;
      }
      convolvers_[s]->processAdd(tail_.data(), out);
    } else if (position_ + B <= x.size()) {
      convolvers_[s]->processAdd(x.data() + position_, out);
    } else {
      // The signal's last partial block, or silence past its end (the IR tail rings on).
      const size_t left = position_ < x.size() ? x.size() - position_ : 0;
      std::fill(tail_.begin(), tail_.end(), 0.f);
      if (left) std::copy(x.data() + position_, x.data() + position_ + left, tail_.begin());
      convolvers_[s]->processAdd(tail_.data(), out);
    }
    while (convolvers_[s]->takeRetired()) {
    }
  }
  if (swapped && spentCount_ < kSpentCapacity) spent_[spentCount_++] = swapped;
  position_ += B;
  ++blocks_;
}

IrSet* AudioStage::takeSpent() {
  if (spentCount_ == 0) return nullptr;
  IrSet* s = spent_[0];
  for (int i = 1; i < spentCount_; ++i) spent_[i - 1] = spent_[i];
  --spentCount_;
  return s;
}

}  // namespace dpc
