#include "runtime/kept_irs.h"

#include <utility>

namespace dpc {

namespace {
/// Exact paths a worker's signature holds without allocation (a frame's early paths per pair
/// rarely exceed it).
constexpr size_t kReservedArrivals = 256;
}  // namespace

void KeptIrs::ensure(size_t listeners, size_t sources, size_t workers) {
  if (made_.size() < listeners) made_.resize(listeners);
  for (auto& perSource : made_)
    if (perSource.size() < sources) perSource.resize(sources);
  if (counts_.size() < listeners) counts_.resize(listeners);
  while (workers_.size() < workers) {
    workers_.emplace_back();
    workers_.back().signature.reserve(kReservedArrivals);
  }
}

void KeptIrs::forget() {
  for (auto& perSource : made_)
    for (Made& m : perSource) m.current = false;
}

void KeptIrs::made(size_t listener, size_t s, size_t worker) {
  Worker& x = workers_[worker];
  Made& m = made_[listener][s];
  ++x.synthesized;
  const bool known = x.listener == listener && x.source == s;
  x.listener = x.source = kNone;
  m.id = on() ? ++lastId_ : 0;
  m.current = on() && known;
  if (m.current) std::swap(m.signature, x.signature);  // no allocation: they trade storage
}

void KeptIrs::drainCounts(size_t listener) {
  Counts& n = counts_[listener];
  for (Worker& x : workers_) {
    n.kept += std::exchange(x.kept, 0);
    n.synthesized += std::exchange(x.synthesized, 0);
  }
}

}  // namespace dpc
