// Comparing partitioned IR sets in the runtime tests (audio/nonuniform_convolver.h).
#pragma once

#include <algorithm>
#include <cstddef>

#include "audio/nonuniform_convolver.h"

namespace dpc::test {

/// Whether two partitioned sets hold the same partitions of IR `item` (a source, or a late
/// bus): every level's active partitions, every channel, every float of their split spectra.
inline bool samePartitions(const audio::NonUniformIrSet& x, const audio::NonUniformIrSet& y,
                           int item) {
  for (int l = 0; l < x.layout().numLevels(); ++l) {
    if (x.activePartitions(item, l) != y.activePartitions(item, l)) return false;
    const size_t floats = 2 * (size_t(x.layout().level(l).partitionSize) + 1);
    for (int c = 0; c < x.numChannels(); ++c)
      for (int p = 0; p < x.activePartitions(item, l); ++p)
        if (!std::equal(x.spectrum(l, item, c, p), x.spectrum(l, item, c, p) + floats,
                        y.spectrum(l, item, c, p)))
          return false;
  }
  return true;
}

}  // namespace dpc::test
