// KeptIrs: which sources' own IRs (a source's whole IR, or its early part in hybrid
// rendering) still stand for this frame's inputs, so that a frame synthesises and partitions
// only the IRs whose inputs changed. Per listener and source it holds what the IR playing now
// was made from (an EarlySignature, runtime/early_signature.h) and an identity; per worker
// (a group of sources rendered whole, or a workspace slot of hybrid rendering's early jobs),
// the signature of the source at hand. A source's inputs are summarised in two halves:
// the exact arrivals (cheap, and what changes when anything moves) and the diffuse response,
// summarised only once the arrivals have held since the source's last synthesis. So a moving
// listener's frames cost the arrivals' comparison alone, and a source is kept from the second
// frame its arrivals hold.
//
// Threads: setTolerance, ensure and forget on the propagation thread between frames; kept()
// and made() for a source from the one thread that holds worker w while it synthesises that
// source (no two threads hold one worker at once, nor synthesise one source); drainCounts() and the accessors on the propagation thread after the
// groups. No allocation after the first frames (the signatures trade storage); no errors.
#pragma once

#include <atomic>
#include <cstdint>
#include <span>
#include <vector>

#include "engine/energy_response.h"
#include "engine/specular_paths.h"
#include "engine/trace_request.h"
#include "runtime/early_signature.h"

namespace dpc {

class KeptIrs {
 public:
  /// Cumulative counts of one listener's source IRs.
  struct Counts {
    uint64_t synthesized = 0;  ///< IRs synthesised
    uint64_t kept = 0;         ///< IRs kept from an earlier frame
  };

  /// toleranceDb > 0: IRs kept while their inputs match within it (EarlySignature::matches);
  /// 0: every IR every frame. No allocation.
  void setTolerance(double toleranceDb) { toleranceDb_ = toleranceDb; }
  bool on() const { return toleranceDb_ > 0.0; }
  /// Room for `listeners` x `sources` and `workers` worker groups (allocates when growing).
  void ensure(size_t listeners, size_t sources, size_t workers);
  /// Every IR made so far no longer stands (the synthesisers changed).
  void forget();

  /// Whether source s's IR of `listener` stands for this frame's inputs: the response r, the
  /// direct sound and the exact paths as they are synthesised; frame: the listener frame of
  /// spatial output, nullptr for mono. Counted; false when off.
  template <class Response>
  bool kept(const Response& r, const DirectSound& direct, std::span<const SpecularPath> paths,
            const ListenerFrame* frame, size_t listener, size_t s, size_t worker) {
    if (!on()) return false;
    Worker& x = workers_[worker];
    const Made& made = made_[listener][s];
    x.signature.assignArrivals(direct, paths, frame);
    x.listener = listener;
    x.source = s;
    // Arrivals that changed since the last synthesis: something moves; the diffuse part, the
    // costlier half, is summarised only once the arrivals hold.
    if (!made.current || !x.signature.sameArrivals(made.signature, toleranceDb_)) return false;
    x.signature.assignDiffuse(r);
    // A signature made while the arrivals still moved has no diffuse part: no match.
    if (!x.signature.sameDiffuse(made.signature, toleranceDb_)) return false;
    ++x.kept;
    return true;
  }
  /// After source s's IR was synthesised by `worker`: a new identity, counted, and what it was
  /// made from, the inputs kept() just summarised (without that kept() call for this source
  /// the IR is not kept later: its inputs are unknown).
  void made(size_t listener, size_t s, size_t worker);
  /// The identity of the IR source s of listener l holds since its last synthesis: unique
  /// over this object's syntheses; 0 while off or before the first. An IR set holding the
  /// partitions of that identity need not partition it again.
  uint64_t id(size_t listener, size_t s) const {
    return listener < made_.size() ? made_[listener][s].id : 0;
  }
  /// Adds the worker groups' counts of this frame to listener l's, and clears them.
  void drainCounts(size_t listener);
  Counts counts(size_t listener) const {
    return listener < counts_.size() ? counts_[listener] : Counts{};
  }

 private:
  /// What a source's IR was made from (current: the signature is the IR's; it has its diffuse
  /// part once made from arrivals that held since the synthesis before).
  struct Made {
    EarlySignature signature;
    bool current = false;
    uint64_t id = 0;
  };
  struct Worker {
    EarlySignature signature;  ///< this frame's inputs of the source at hand
    size_t listener = kNone, source = kNone;  ///< whose inputs signature holds
    uint64_t kept = 0, synthesized = 0;
  };
  static constexpr size_t kNone = ~size_t(0);
  double toleranceDb_ = 0.0;
  std::atomic<uint64_t> lastId_{0};
  std::vector<std::vector<Made>> made_;  ///< per listener, per source
  std::vector<Worker> workers_;
  std::vector<Counts> counts_;  ///< per listener
};

}  // namespace dpc
