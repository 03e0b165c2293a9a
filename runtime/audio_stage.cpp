#include "runtime/audio_stage.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <string>

#include "audio/rt_check.h"
#include "common/input_error.h"
#include "common/input_file.h"

namespace dpc {

namespace {

/// The head-tracked decoder the scene asks for. Throws InputError naming audio.hrtf when MagLS
/// at the scene's order needs more measured directions than its SOFA set has.
audio::BinauralDecoderOptions binauralDecoder(const SceneDesc& scene, const audio::Hrtf& hrtf) {
  audio::BinauralDecoderOptions decoder;
  if (scene.audio.binauralDecoder == BinauralDecoder::kSampling) {
    decoder.method = audio::BinauralDecoderMethod::kSampling;
    return decoder;
  }
  const int order = scene.audio.ambisonicOrder;
  if (hrtf.measurementCount() < size_t(ambisonicChannels(order)))
    throw InputError(scene.path, "audio.hrtf",
                     "the MagLS decoder of order " + std::to_string(order) + " needs at least " +
                         std::to_string(ambisonicChannels(order)) +
                         " measured directions; the SOFA file has " +
                         std::to_string(hrtf.measurementCount()));
  return decoder;
}

}  // namespace

AudioStage::AudioStage(std::shared_ptr<const audio::NonUniformLayout> layout,
                       std::shared_ptr<const DrySignals> dry, int numOutputs, IrExchange& exchange,
                       size_t channel, std::shared_ptr<const audio::NonUniformLayout> lateLayout,
                       int lateBuses)
    : layout_(std::move(layout)),
      dry_(std::move(dry)),
      numOutputs_(numOutputs),
      convolver_(*layout_, int(dry_->samples.size()), numOutputs),
      lateLayout_(std::move(lateLayout)),
      exchange_(exchange),
      channel_(channel) {
  assert(dry_->loop.size() == dry_->samples.size());
  tail_.assign(dry_->samples.size() * size_t(layout_->blockSize()), 0.f);
  in_.assign(dry_->samples.size(), nullptr);
  if (lateLayout_ && lateBuses > 0) {
    // Phase slot 1: its levels' inverse FFTs fall in other callbacks than the early parts'.
    lateConvolver_ =
        std::make_unique<audio::NonUniformConvolver>(*lateLayout_, lateBuses, numOutputs, 1);
    lateMixer_ = std::make_unique<audio::LateBusMixer>(int(dry_->samples.size()), lateBuses,
                                                       layout_->blockSize());
  }
}

AudioStage::AudioStage(const PropagationStage& propagation, std::shared_ptr<const DrySignals> dry,
                       IrExchange& exchange, size_t channel)
    : AudioStage(propagation.layout(), std::move(dry), propagation.numOutputs(), exchange, channel,
                 propagation.lateLayout(), propagation.lateBuses()) {
  const SceneDesc& scene = propagation.scene();
  if (scene.audio.output != OutputFormat::kAmbisonicBinaural) return;
  std::unique_ptr<audio::Hrtf> hrtf;
  try {
    hrtf = std::make_unique<audio::Hrtf>(
        audio::Hrtf::load(scene.audio.hrtfPath, scene.audio.sampleRate));
  } catch (const InputError& e) {
    throw InputError(scene.path, "audio.hrtf", e.what());
  }
  const size_t B = size_t(layout_->blockSize());
  head_ = std::make_unique<audio::HeadTrackedBinaural>(scene.audio.ambisonicOrder, *hrtf, int(B),
                                                       binauralDecoder(scene, *hrtf));
  ambisonic_.assign(size_t(numOutputs_) * B, 0.f);
  for (int c = 0; c < numOutputs_; ++c)
    ambisonicChannels_.push_back(ambisonic_.data() + size_t(c) * B);
}

AudioStage::~AudioStage() = default;

void AudioStage::setHeadOrientation(const Orientation& head) {
  DPC_ASSERT_AUDIO_THREAD();
  if (!head_ || (head.yawRadians == headOrientation_.yawRadians &&
                 head.pitchRadians == headOrientation_.pitchRadians &&
                 head.rollRadians == headOrientation_.rollRadians))
    return;
  headOrientation_ = head;
  const Orientation reference{};
  const glm::vec3 rf = reference.forward(), ru = reference.up(), f = head.forward(), u = head.up();
  const float refForward[3] = {rf.x, rf.y, rf.z}, refUp[3] = {ru.x, ru.y, ru.z},
              forward[3] = {f.x, f.y, f.z}, up[3] = {u.x, u.y, u.z};
  head_->setRotation(audio::headRotation(refForward, refUp, forward, up));
}

void AudioStage::applyNewest() {
  // A convolver without room keeps the newest set in the exchange's mailbox, where a newer
  // one may still replace it.
  if (!convolver_.canAccept(nullptr) || (lateConvolver_ && !lateConvolver_->canAccept(nullptr)))
    return;
  IrSet* set = exchange_.takeNewest(channel_);
  if (!set) return;
  convolver_.setNextIr(set->irs.get());
  set->convolversHolding = 1;
  if (lateConvolver_) {
    lateConvolver_->setNextIr(set->lateIrs.get());
    lateMixer_->setTargets(set->lateBus, set->lateGain);
    set->convolversHolding = 2;
  }
  current_ = set;
  ++applied_;
}

void AudioStage::readDry(size_t s, size_t B) {
  const std::vector<float>& x = dry_->samples[s];
  float* tail = tail_.data() + s * B;
  if (dry_->loop[s]) {
    // Looping signal: B samples from position mod length, read in place unless the block
    // wraps; then copied in runs, wrapping as often as a signal shorter than B needs.
    size_t p = position_ % x.size();
    if (p + B <= x.size()) {
      in_[s] = x.data() + p;
      return;
    }
    for (size_t i = 0; i < B;) {
      const size_t run = std::min(B - i, x.size() - p);
      std::copy(x.data() + p, x.data() + p + run, tail + i);
      i += run;
      p = 0;
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

void AudioStage::retire(const audio::NonUniformIrSet* part, bool late) {
  IrSet* set = exchange_.find(part, late);
  if (set && --set->convolversHolding == 0) exchange_.release(channel_, set);
}

void AudioStage::collectRetired() {
  while (const audio::NonUniformIrSet* retired = convolver_.takeRetired()) retire(retired, false);
  if (!lateConvolver_) return;
  while (const audio::NonUniformIrSet* retired = lateConvolver_->takeRetired())
    retire(retired, true);
}

void AudioStage::readHostInput(size_t s, size_t B, const float* x) {
  float* block = tail_.data() + s * B;
  const float gain = s < dry_->gain.size() ? dry_->gain[s] : 1.f;
  uint64_t replaced = 0;
  for (size_t i = 0; i < B; ++i) {
    // NaN fails the comparison too: one such sample would fill the convolution's history
    // and silence the output (the NaN guard) for the whole IR length.
    const bool usable = std::abs(x[i]) <= kMaxSignalMagnitude;
    block[i] = usable ? gain * x[i] : 0.f;
    replaced += usable ? 0 : 1;
  }
  replacedInputSamples_ += replaced;
  in_[s] = block;
}

void AudioStage::process(float* const* out, const float* const* inputs) {
  DPC_ASSERT_AUDIO_THREAD();
  const size_t B = size_t(layout_->blockSize());
  applyNewest();
  for (size_t s = 0; s < in_.size(); ++s) {
    if (inputs)
      readHostInput(s, B, inputs[s]);
    else
      readDry(s, B);
  }
  // Head-tracked binaural convolves into the Ambisonic block, then turns and decodes it.
  float* const* irOut = head_ ? ambisonicChannels_.data() : out;
  convolver_.process(in_.data(), irOut);
  if (lateConvolver_) {
    lateMixer_->mix(in_.data());
    lateConvolver_->process(lateMixer_->busInputs(), irOut, /*add=*/true);
  }
  if (head_) head_->process(ambisonicChannels_.data(), out[0], out[1]);
  collectRetired();
  position_ += B;
  ++blocks_;
}

void AudioStage::setIrSwapSpread(int blocks) {
  convolver_.setSwapSpread(blocks);
  if (lateConvolver_) lateConvolver_->setSwapSpread(blocks);
  swapSpreadBlocks_ = 1 + std::max(convolver_.swapDelayBlocks(),
                                   lateConvolver_ ? lateConvolver_->swapDelayBlocks() : 0);
}

void AudioStage::setSkipSilentLevels(bool skip) {
  convolver_.setSkipSilentLevels(skip);
  if (lateConvolver_) lateConvolver_->setSkipSilentLevels(skip);
}

uint64_t AudioStage::stalePartitions() const {
  return convolver_.stalePartitions() + (lateConvolver_ ? lateConvolver_->stalePartitions() : 0);
}

}  // namespace dpc
