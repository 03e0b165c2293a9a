// Construction work spread over threads of its own, for what must not wait for the tracing
// threads (they may not exist yet, or be fewer than the groups): building many synthesisers
// is a live session's time to first sound. FFTW planning inside f is serialised by
// fftwPlannerMutex (common/fftw_util.h).
#pragma once

#include <cstddef>
#include <functional>

namespace dpc {

/// Runs f(0) on the calling thread and f(1) .. f(n - 1) on threads of their own, returns when
/// all have returned and rethrows the first error (by index) after all have ended. Control or
/// propagation thread, between frames; allocates.
void onOwnThreads(size_t n, const std::function<void(size_t)>& f);

}  // namespace dpc
