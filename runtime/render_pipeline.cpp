#include "runtime/render_pipeline.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <stdexcept>

#include "audio/hrtf.h"
#include "audio/panning.h"
#include "audio/resample.h"
#include "common/input_error.h"
#include "common/input_file.h"

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
    if (src.signalPath.empty()) {  // host input only: silence when played on its own
      d.samples.emplace_back();
      d.loop.push_back(0);
      d.notes.push_back("sources[" + std::to_string(i) + "]: no signal (silent without host input)");
      continue;
    }
    audio::AudioData a;
    try {
      a = audio::readWav(src.signalPath);
    } catch (const InputError& e) {
      throw InputError(scene.path, field, e.what());
    }
    if (a.frames() == 0) throw InputError(scene.path, field, src.signalPath + ": no samples");
    if (a.sampleRate < kMinSignalRateHz || a.sampleRate > kMaxSignalRateHz)
      throw InputError(scene.path, field,
                       src.signalPath + ": sample rate " + std::to_string(a.sampleRate) +
                           " Hz is outside [" + std::to_string(kMinSignalRateHz) + ", " +
                           std::to_string(kMaxSignalRateHz) + "] Hz");
    for (size_t c = 0; c < a.channels.size(); ++c)
      for (size_t n = 0; n < a.frames(); ++n)
        if (!std::isfinite(a.channels[c][n]))
          throw InputError(scene.path, field,
                           src.signalPath + ": sample " + std::to_string(n) + " of channel " +
                               std::to_string(c) + " is not finite (NaN or infinity)");
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

int outputChannels(OutputFormat format) {
  return format == OutputFormat::kMono ? 1 : 2;
}

namespace {

/// Two-channel filters for the spatial synthesiser: HRIR pairs (binaural, with the SOFA
/// file's onset delays as leading zeros) or constant-power panning gains (stereo).
struct SpatialFilters {
  std::shared_ptr<audio::Hrtf> hrtf;
  void fill(const glm::vec3& d, EarFilter& out) const {
    const float dir[3] = {d.x, d.y, d.z};
    if (!hrtf) {
      float l = 0.f, r = 0.f;
      audio::stereoGains(dir, &l, &r);
      out.left.assign(1, l);
      out.right.assign(1, r);
      return;
    }
    const size_t n = size_t(hrtf->filterLength());
    float delayL = 0.f, delayR = 0.f;
    out.left.resize(n);
    out.right.resize(n);
    hrtf->hrir(dir, out.left.data(), out.right.data(), &delayL, &delayR);
    auto delay = [](std::vector<float>& h, float samples) {
      const size_t k = size_t(std::max(0.f, std::round(samples)));
      if (k) h.insert(h.begin(), k, 0.f);
    };
    delay(out.left, delayL);
    delay(out.right, delayR);
  }
};

}  // namespace

std::unique_ptr<SpatialIrSynthesizer> makeSpatialSynthesizer(const SceneDesc& scene,
                                                             const PropagationSettings& settings,
                                                             double roomVolume) {
  const int fs = scene.audio.sampleRate;
  auto filters = std::make_shared<SpatialFilters>();
  if (scene.audio.output == OutputFormat::kBinaural) {
    try {
      filters->hrtf = std::make_shared<audio::Hrtf>(audio::Hrtf::load(scene.audio.hrtfPath, fs));
    } catch (const InputError& e) {
      throw InputError(scene.path, "audio.hrtf", e.what());
    }
  }
  const std::vector<glm::vec3> directions = defaultSpatialDirections();
  std::vector<EarFilter> ear(directions.size());
  for (size_t d = 0; d < directions.size(); ++d) filters->fill(directions[d], ear[d]);
  return std::make_unique<SpatialIrSynthesizer>(
      fs, settings.irLength, roomVolume, settings.speedOfSound,
      hashCombine(settings.seed, 0x5bd1e995ULL), directions, ear,
      [filters](const glm::vec3& d, EarFilter& out) { filters->fill(d, out); });
}

PropagationStage::PropagationStage(const SceneDesc& scene, const PropagationSettings& settings,
                                   int poolSize)
    : scene_(scene), numOutputs_(outputChannels(scene.audio.output)) {
  simulation_ = std::make_unique<Simulation>(scene, settings);
  sourcePositions_.resize(scene.sources.size());
  objectPoses_.resize(scene.objects.size());
  sourceOverridden_.assign(scene.sources.size(), 0);
  objectOverridden_.assign(scene.objects.size(), 0);
  const int fs = scene.audio.sampleRate;
  if (scene.audio.output == OutputFormat::kMono) {
    for (size_t s = 0; s < scene.sources.size(); ++s)
      synthesizers_.push_back(std::make_unique<IrSynthesizer>(
          fs, settings.irLength, roomVolume(scene.mesh), settings.speedOfSound,
          hashCombine(settings.seed, 0x5bd1e995ULL + s)));
    irSamples_ = synthesizers_.front()->lengthSamples();
  } else {
    spatial_ = makeSpatialSynthesizer(scene, settings, roomVolume(scene.mesh));
    const std::vector<glm::vec3>& directions = spatial_->directions();
    simulation_->enableDirectional(directions);
    irSamples_ = spatial_->lengthSamples();
  }
  layout_ = std::make_unique<audio::NonUniformLayout>(scene.audio.blockSize, irSamples_);
  const int sets = poolSize + 2 * (layout_->numLevels() - 1);
  for (int i = 0; i < sets; ++i) {
    auto set = std::make_unique<IrSet>();
    set->irs =
        std::make_unique<audio::NonUniformIrSet>(*layout_, int(scene.sources.size()), numOutputs_);
    free_.push_back(set.get());
    pool_.push_back(std::move(set));
  }
  irs_.assign(
      1, std::vector<std::vector<std::vector<float>>>(
             scene.sources.size(),
             std::vector<std::vector<float>>(size_t(numOutputs_), std::vector<float>(irSamples_))));
}

void PropagationStage::overrideSource(size_t index, const glm::vec3& position) {
  if (index >= sourcePositions_.size()) return;
  sourcePositions_[index] = position;
  sourceOverridden_[index] = 1;
}

void PropagationStage::overrideObject(size_t index, const Pose& pose) {
  if (index >= objectPoses_.size()) return;
  objectPoses_[index] = pose;
  objectOverridden_[index] = 1;
}

IrSet* PropagationStage::computeFrame(const glm::vec3& listener, const Orientation& orientation,
                                      double t) {
  // Sources and objects follow their trajectories at scene time t unless a host took over.
  for (size_t s = 0; s < scene_.sources.size(); ++s)
    if (!sourceOverridden_[s]) sourcePositions_[s] = sourcePositionAt(scene_.sources[s], t);
  for (size_t k = 0; k < scene_.objects.size(); ++k)
    if (!objectOverridden_[k]) objectPoses_[k] = objectPoseAt(scene_.objects[k], t);
  return runPrepared(listener, orientation, t);
}

IrSet* PropagationStage::computeFrame(const WorldState& world, size_t listener) {
  for (size_t s = 0; s < sourcePositions_.size() && s < world.sourcePositions.size(); ++s)
    sourcePositions_[s] = world.sourcePositions[s];
  for (size_t k = 0; k < objectPoses_.size() && k < world.objectPoses.size(); ++k)
    objectPoses_[k] = world.objectPoses[k];
  return runPrepared(world.listenerPositions.at(listener), world.listenerOrientations.at(listener),
                     world.timeSeconds);
}

IrSet* PropagationStage::runPrepared(const glm::vec3& listener, const Orientation& orientation,
                                     double t) {
  if (free_.empty()) return nullptr;
  simulation_->setListenerOrientation(orientation);
  const ListenerSphere sphere{listener, scene_.listener.radius};
  trace(std::span(&sphere, 1), t);
  return prepare(0);
}

void PropagationStage::traceWorld(const WorldState& world) {
  for (size_t s = 0; s < sourcePositions_.size() && s < world.sourcePositions.size(); ++s)
    if (!sourceOverridden_[s]) sourcePositions_[s] = world.sourcePositions[s];
  for (size_t k = 0; k < objectPoses_.size() && k < world.objectPoses.size(); ++k)
    if (!objectOverridden_[k]) objectPoses_[k] = world.objectPoses[k];
  const size_t L = world.listenerPositions.size();
  spheres_.resize(L);
  for (size_t l = 0; l < L; ++l) {
    const float radius =
        l < scene_.listeners.size() ? scene_.listeners[l].radius : scene_.listener.radius;
    spheres_[l] = ListenerSphere{world.listenerPositions[l], radius};
    if (l < world.listenerOrientations.size())
      simulation_->setListenerOrientation(l, world.listenerOrientations[l]);
  }
  trace(spheres_, world.timeSeconds);
}

void PropagationStage::trace(std::span<const ListenerSphere> listeners, double t) {
  const auto t0 = std::chrono::steady_clock::now();
  if (!objectPoses_.empty()) simulation_->setObjectPoses(objectPoses_);
  simulation_->runFrame(listeners, sourcePositions_);
  totals_.traceSeconds += secondsSince(t0);
  for (size_t s = 0; s < simulation_->sourceCount(); ++s) {
    totals_.rays += simulation_->result(s).trace.rays;
    totals_.segments += simulation_->result(s).trace.segments;
  }
  while (irs_.size() < listeners.size()) irs_.push_back(irs_.front());
  lastTime_ = t;
  ++totals_.frames;
}

IrSet* PropagationStage::prepare(size_t listener) {
  if (listener >= simulation_->listenerCount())
    throw std::out_of_range("PropagationStage::prepare: listener index out of range");
  if (free_.empty()) return nullptr;
  IrSet* set = free_.back();
  free_.pop_back();
  auto& irs = irs_[listener];
  for (size_t s = 0; s < simulation_->sourceCount(); ++s) {
    const Simulation::SourceResult& r = simulation_->result(s, listener);
    auto t0 = std::chrono::steady_clock::now();
    if (spatial_)
      spatial_->synthesize(simulation_->directional(s, listener), r.direct, irs[s][0].data(),
                           irs[s][1].data());
    else
      synthesizers_[s]->synthesize(r.energy, r.direct, irs[s][0].data());
    totals_.synthesisSeconds += secondsSince(t0);
    t0 = std::chrono::steady_clock::now();
    std::array<const float*, 2> channels{};
    for (int c = 0; c < numOutputs_; ++c) channels[size_t(c)] = irs[s][size_t(c)].data();
    set->irs->prepare(int(s), channels.data(), irSamples_);
    totals_.prepareSeconds += secondsSince(t0);
  }
  set->listener = listener;
  set->frame = simulation_->framesRun() - 1;
  set->poseTimeSeconds = lastTime_;
  return set;
}

void PropagationStage::recycle(IrSet* set) {
  if (set) free_.push_back(set);
}

AudioStage::AudioStage(const audio::NonUniformLayout& layout, const DrySignals& dry, int numOutputs)
    : layout_(layout),
      dry_(dry),
      numOutputs_(numOutputs),
      convolver_(layout, int(dry.samples.size()), numOutputs) {
  tail_.assign(dry.samples.size() * size_t(layout.blockSize()), 0.f);
  in_.assign(dry.samples.size(), nullptr);
}

void AudioStage::offer(IrSet* set) {
  if (pending_) spent_.tryPush(pending_);  // a full ring counts it (lostSets())
  pending_ = set;
}

void AudioStage::process(float* const* out, const float* const* inputs) {
  const size_t B = size_t(layout_.blockSize());
  if (pending_) {
    int slot = 0;
    while (slot < kInFlightCapacity && inFlight_[slot]) ++slot;
    // A full table or retired list (spent sets not drained) keeps the set pending.
    if (slot < kInFlightCapacity && convolver_.setNextIr(pending_->irs.get())) {
      inFlight_[slot] = pending_;
      current_ = pending_;
      pending_ = nullptr;
      ++applied_;
    }
  }
  for (size_t s = 0; s < in_.size(); ++s) {
    const std::vector<float>& x = dry_.samples[s];
    float* tail = tail_.data() + s * B;
    if (inputs) {
      in_[s] = inputs[s];
    } else if (dry_.loop[s]) {
      // Looping signal: read B samples from position mod length, wrapping as often as needed.
      size_t p = position_ % x.size();
      for (size_t i = 0; i < B; ++i) {
        tail[i] = x[p];
        if (++p == x.size()) p = 0;
      }
      in_[s] = tail;
    } else if (position_ + B <= x.size()) {
      in_[s] = x.data() + position_;
    } else {
      // The signal's last partial block, or silence past its end (the IR tail rings on).
      const size_t left = position_ < x.size() ? x.size() - position_ : 0;
      std::fill(tail, tail + B, 0.f);
      if (left) std::copy(x.data() + position_, x.data() + position_ + left, tail);
      in_[s] = tail;
    }
  }
  convolver_.process(in_.data(), out);
  while (const audio::NonUniformIrSet* retired = convolver_.takeRetired()) {
    for (IrSet*& set : inFlight_) {
      if (set && set->irs.get() == retired) {
        spent_.tryPush(set);
        set = nullptr;
        break;
      }
    }
  }
  position_ += B;
  ++blocks_;
}

IrSet* AudioStage::takeSpent() {
  IrSet* s = nullptr;
  return spent_.tryPop(s) ? s : nullptr;
}

}  // namespace dpc
