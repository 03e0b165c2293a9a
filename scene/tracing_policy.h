// Which end of the source-listener pairs a frame traces rays from (PropagationSettings::tracing):
// one trace per emitter, so the fewer end is traced unless the scene asks for one.
//
// Threads: any thread. Allocation: none. Errors: none.
#pragma once

#include <cstddef>

#include "scene/scene.h"

namespace dpc {

/// Whether a frame with this many sources and listeners traces from the listeners: kAuto when
/// there are more sources than listeners, else as `tracing` says.
inline bool tracesFromListeners(Tracing tracing, size_t sources, size_t listeners) {
  if (tracing == Tracing::kAuto) return sources > listeners;
  return tracing == Tracing::kFromListeners;
}

}  // namespace dpc
