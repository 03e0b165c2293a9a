#include "runtime/callback_adapter.h"

#include "scene/limits.h"

namespace dpc {

int engineBlockForHostPeriod(int hostFrames) {
  const Limit& block = limitOf("audio.block_size");
  return int(std::clamp(double(hostFrames), block.min, block.max));
}

CallbackAdapter::CallbackAdapter(int blockSize, int sources, int channels) : blockSize_(blockSize) {
  assert(blockSize >= 1 && sources >= 0 && channels >= 1);
  in_.assign(size_t(sources), std::vector<float>(size_t(blockSize), 0.f));
  for (auto& ch : in_) inPtr_.push_back(ch.data());
  out_.assign(size_t(channels), std::vector<float>(size_t(blockSize), 0.f));
  for (auto& ch : out_) outPtr_.push_back(ch.data());
}

}  // namespace dpc
