// IrExchange: the one owner of IR sets (runtime/ir_set.h) and the one place of the
// newest-wins rule between the propagation side and its audio stages.
//
//   propagation thread                       audio thread (one per channel)
//   acquire() -> fill -> publish(ch, set) -> mailbox[ch] -> takeNewest(ch) -> convolvers
//   free list <- reclaimed at acquire() <---- returned[ch] <-- release(ch, set)
//
// Newest wins: each channel's mailbox holds at most one set. Publishing while the mailbox
// still holds an untaken set swaps it out; the superseded set goes straight back to the free
// list (counted, superseded()). So the propagation side never waits for, and never depends
// on, an audio side that does not run: a stepped engine whose audio is never pulled keeps
// producing frames.
//
// Channels are the audio stages fed by one propagation stage (one per listener rendered
// offline; one live). The pool holds enough sets for every channel's convolvers, mailbox and
// the set being filled (PropagationStage::poolSizeFor); acquire() returns nullptr only if the
// audio side holds more sets than that (counted as a frame without a set by the caller).
//
// Threads: construction and the accessors on the control thread before the exchange is
// shared; acquire/publish/discard on one propagation thread; takeNewest/release/find on the
// audio thread of the channel: wait-free (one atomic exchange, or a FixedRing push), no
// allocation, locks or system calls. Every set is in exactly one place at a time (free, being
// filled, in a mailbox, or held by an audio stage), so no ring can overflow.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "common/fixed_ring.h"
#include "runtime/ir_set.h"

namespace dpc {

class IrExchange {
 public:
  /// `sets` sets made by makeSet, for `channels` >= 1 audio stages. Control thread; allocates.
  /// Throws std::invalid_argument for no channel or no set.
  IrExchange(size_t channels, size_t sets, const std::function<std::unique_ptr<IrSet>()>& makeSet);
  ~IrExchange();
  IrExchange(const IrExchange&) = delete;
  IrExchange& operator=(const IrExchange&) = delete;

  // Propagation thread.
  /// A free set to fill (released sets are reclaimed first), or nullptr when every set is held
  /// by the audio side.
  IrSet* acquire();
  /// Makes `set` channel `channel`'s newest; an untaken older one goes back to the free list.
  void publish(size_t channel, IrSet* set);
  /// Gives an acquired set back unpublished.
  void discard(IrSet* set);
  /// Sets published and then superseded before their audio stage took them.
  uint64_t superseded() const { return superseded_.load(std::memory_order_relaxed); }

  // Audio thread of `channel`; wait-free.
  /// The newest published set (the caller now holds it), or nullptr when none is new.
  IrSet* takeNewest(size_t channel) noexcept;
  /// Hands back a set the audio stage no longer uses.
  void release(size_t channel, IrSet* set) noexcept;
  /// The set whose early (late: late) partitioned IRs are `part`, or nullptr.
  IrSet* find(const audio::NonUniformIrSet* part, bool late) const noexcept;

  size_t channels() const { return channels_.size(); }
  size_t size() const { return pool_.size(); }

 private:
  struct Channel {
    std::atomic<IrSet*> mailbox{nullptr};
    std::unique_ptr<FixedRing<IrSet*>> returned;
  };
  std::vector<std::unique_ptr<IrSet>> pool_;
  std::vector<IrSet*> free_;  ///< propagation thread only
  std::vector<std::unique_ptr<Channel>> channels_;
  std::atomic<uint64_t> superseded_{0};
};

}  // namespace dpc
