#include "runtime/ir_exchange.h"

#include <cassert>
#include <stdexcept>

#include "audio/rt_check.h"

namespace dpc {

IrExchange::IrExchange(size_t channels, size_t sets,
                       const std::function<std::unique_ptr<IrSet>()>& makeSet) {
  if (channels == 0 || sets == 0)
    throw std::invalid_argument("IrExchange: needs at least one channel and one set");
  free_.reserve(sets);
  for (size_t i = 0; i < sets; ++i) {
    pool_.push_back(makeSet());
    free_.push_back(pool_.back().get());
  }
  for (size_t c = 0; c < channels; ++c) {
    channels_.push_back(std::make_unique<Channel>());
    // Room for every set: a push never fails.
    channels_.back()->returned = std::make_unique<FixedRing<IrSet*>>(sets);
  }
}

IrExchange::~IrExchange() = default;

IrSet* IrExchange::acquire() {
  for (const auto& ch : channels_) {
    IrSet* back = nullptr;
    while (ch->returned->tryPop(back)) free_.push_back(back);  // capacity: the pool's size
  }
  if (free_.empty()) return nullptr;
  IrSet* set = free_.back();
  free_.pop_back();
  return set;
}

void IrExchange::publish(size_t channel, IrSet* set) {
  IrSet* old = channels_[channel]->mailbox.exchange(set, std::memory_order_acq_rel);
  if (!old) return;
  free_.push_back(old);
  superseded_.fetch_add(1, std::memory_order_relaxed);
}

void IrExchange::discard(IrSet* set) {
  assert(set);
  free_.push_back(set);
}

IrSet* IrExchange::takeNewest(size_t channel) noexcept {
  DPC_ASSERT_AUDIO_THREAD();
  return channels_[channel]->mailbox.exchange(nullptr, std::memory_order_acq_rel);
}

void IrExchange::release(size_t channel, IrSet* set) noexcept {
  DPC_ASSERT_AUDIO_THREAD();
  const bool room = channels_[channel]->returned->tryPush(set);
  assert(room);
  (void)room;
}

IrSet* IrExchange::find(const audio::NonUniformIrSet* part, bool late) const noexcept {
  for (const auto& set : pool_)
    if ((late ? set->lateIrs.get() : set->irs.get()) == part) return set.get();
  return nullptr;
}

}  // namespace dpc
