// numpy arrays from the module's C++ results without copying them: the vector moves into a
// capsule that the array owns. Private to python/.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <algorithm>
#include <vector>

#include "common/bands.h"

namespace dpc::python {

namespace py = pybind11;

/// The vector as a C-ordered array of `shape` (whose product is v.size()), owning the data.
template <class T>
py::array vectorArray(std::vector<T>&& v, std::vector<size_t> shape) {
  auto* owned = new std::vector<T>(std::move(v));
  py::capsule free(owned, [](void* p) { delete static_cast<std::vector<T>*>(p); });
  return py::array_t<T>(shape, owned->data(), free);
}

/// Channels of equal length as one float32 array, channels x samples (one copy into the
/// row-major block: the channels are separate vectors).
inline py::array channelsArray(std::vector<std::vector<float>>&& channels) {
  const size_t n = channels.empty() ? 0 : channels.front().size();
  if (channels.size() == 1) return vectorArray(std::move(channels.front()), {1, n});
  std::vector<float> block(channels.size() * n, 0.f);
  for (size_t c = 0; c < channels.size(); ++c)
    std::copy_n(channels[c].begin(), std::min(n, channels[c].size()), block.begin() + c * n);
  return vectorArray(std::move(block), {channels.size(), n});
}

/// Bin-major band values ([bin][band], `bins` bins) as a float32 array, bands x bins.
inline py::array bandsByBins(const float* binMajor, size_t bins) {
  std::vector<float> out(size_t(kNumBands) * bins);
  for (size_t k = 0; k < bins; ++k)
    for (int b = 0; b < kNumBands; ++b) out[size_t(b) * bins + k] = binMajor[k * kNumBands + b];
  return vectorArray(std::move(out), {size_t(kNumBands), bins});
}

}  // namespace dpc::python
