#include "runtime/audio_stage.h"

#include <algorithm>
#include <cassert>

#include "audio/rt_check.h"

namespace dpc {

AudioStage::AudioStage(std::shared_ptr<const audio::NonUniformLayout> layout,
                       std::shared_ptr<const DrySignals> dry, int numOutputs)
    : layout_(std::move(layout)),
      dry_(std::move(dry)),
      numOutputs_(numOutputs),
      convolver_(*layout_, int(dry_->samples.size()), numOutputs) {
  assert(dry_->loop.size() == dry_->samples.size());
  tail_.assign(dry_->samples.size() * size_t(layout_->blockSize()), 0.f);
  in_.assign(dry_->samples.size(), nullptr);
}

void AudioStage::offer(IrSet* set) {
  if (pending_) spent_.tryPush(pending_);  // a full ring counts it (lostSets())
  pending_ = set;
}

void AudioStage::applyPending() {
  if (!pending_) return;
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

void AudioStage::readDry(size_t s, size_t B) {
  const std::vector<float>& x = dry_->samples[s];
  float* tail = tail_.data() + s * B;
  if (dry_->loop[s]) {
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

void AudioStage::collectRetired() {
  while (const audio::NonUniformIrSet* retired = convolver_.takeRetired()) {
    for (IrSet*& set : inFlight_) {
      if (set && set->irs.get() == retired) {
        spent_.tryPush(set);  // a full ring counts it (lostSets())
        set = nullptr;
        break;
      }
    }
  }
}

void AudioStage::process(float* const* out, const float* const* inputs) {
  DPC_ASSERT_AUDIO_THREAD();
  const size_t B = size_t(layout_->blockSize());
  applyPending();
  for (size_t s = 0; s < in_.size(); ++s) {
    if (inputs)
      in_[s] = inputs[s];
    else
      readDry(s, B);
  }
  convolver_.process(in_.data(), out);
  collectRetired();
  position_ += B;
  ++blocks_;
}

IrSet* AudioStage::takeSpent() {
  IrSet* s = nullptr;
  return spent_.tryPop(s) ? s : nullptr;
}

}  // namespace dpc
