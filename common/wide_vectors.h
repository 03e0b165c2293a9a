// Four-lane double vectors for loops over independent lanes (bands), compiled twice, for AVX2
// and for the baseline, and picked at load time (GCC function multiversioning). No FMA is
// enabled, so both versions round identically and as the scalar code does. Internal to the
// engine's IR synthesis; any thread; no allocation.
#pragma once

namespace dpc {

#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && \
    !defined(__SANITIZE_ADDRESS__) && !defined(__SANITIZE_THREAD__)
#define DPC_WIDE_VECTORS __attribute__((target_clones("avx2", "default")))
#else
#define DPC_WIDE_VECTORS
#endif

/// Four doubles (GCC/Clang vector extension): one AVX2 register, two SSE2 ones in the
/// baseline; the same IEEE operations per lane either way.
typedef double Double4 __attribute__((vector_size(32)));

}  // namespace dpc
