#include "audio/head_tracked_binaural.h"

#include <algorithm>
#include <stdexcept>
#include <string>

#include "audio/rt_check.h"

namespace dpc::audio {

HeadTrackedBinaural::HeadTrackedBinaural(int order, const Hrtf& hrtf, int blockSize,
                                         const BinauralDecoderOptions& decoderOptions)
    : order_(order), blockSize_(blockSize) {
  if (order < 1 || order > kMaxAmbisonicOrder || blockSize <= 0)
    throw std::invalid_argument("HeadTrackedBinaural: order must be 1.." +
                                std::to_string(kMaxAmbisonicOrder) + " and the block size > 0");
  const AmbisonicBinauralDecoder decoder(order, hrtf, decoderOptions);
  filterLength_ = decoder.filterLength();
  layout_ = std::make_unique<ConvolverLayout>(blockSize, filterLength_);
  const size_t C = size_t(channels()), B = size_t(blockSize);
  for (size_t c = 0; c < C; ++c) {
    filters_.push_back(std::make_unique<IrSpectra>(*layout_, 2));
    const float* ears[2] = {decoder.filter(c, 0).data(), decoder.filter(c, 1).data()};
    filters_.back()->prepare(ears, filterLength_);
    convolvers_.push_back(std::make_unique<PartitionedConvolver>(*layout_, 2));
    convolvers_.back()->setNextIr(filters_.back().get());
  }
  equaliserLayout_ = std::make_unique<ConvolverLayout>(blockSize, decoder.equaliser().size());
  equaliser_ = std::make_unique<IrSpectra>(*equaliserLayout_, 1);
  const float* eq[1] = {decoder.equaliser().data()};
  equaliser_->prepare(eq, decoder.equaliser().size());
  for (auto& e : equalisers_) {
    e = std::make_unique<PartitionedConvolver>(*equaliserLayout_, 1);
    e->setNextIr(equaliser_.get());
  }
  ears_.assign(2 * B, 0.f);
  matrix_.assign(C * C, 0.f);
  for (size_t c = 0; c < C; ++c) matrix_[c * C + c] = 1.f;
  previous_ = matrix_;
  scratch_.assign(C * B, 0.f);
  for (size_t c = 0; c < C; ++c) scratchChannels_.push_back(scratch_.data() + c * B);
  // Run one silent block so every convolver has taken its filters (the set-up crossfade from
  // silence happens here, not on the first block heard).
  std::vector<float> silence(C * B, 0.f), out(2 * B, 0.f);
  std::vector<float*> in(C);
  for (size_t c = 0; c < C; ++c) in[c] = silence.data() + c * B;
  processBlock(in.data(), out.data(), out.data() + B);
}

HeadTrackedBinaural::~HeadTrackedBinaural() = default;

void HeadTrackedBinaural::setRotation(const Rotation3& r) {
  DPC_ASSERT_AUDIO_THREAD();
  previous_.swap(matrix_);
  ambisonicRotation(order_, r, matrix_);
  changed_ = true;
}

void HeadTrackedBinaural::rotate(float* const* x) {
  const size_t C = size_t(channels()), B = size_t(blockSize_);
  if (!changed_) {
    rotateAmbisonic(order_, matrix_, x, B);
    return;
  }
  for (size_t c = 0; c < C; ++c) std::copy(x[c], x[c] + B, scratchChannels_[c]);
  rotateAmbisonic(order_, previous_, scratchChannels_.data(), B);
  rotateAmbisonic(order_, matrix_, x, B);
  const float step = 1.f / float(B);
  for (size_t c = 0; c < C; ++c)
    for (size_t n = 0; n < B; ++n) {
      const float w = float(n + 1) * step;
      x[c][n] = (1.f - w) * scratchChannels_[c][n] + w * x[c][n];
    }
  previous_ = matrix_;  // sizes equal: no allocation
  changed_ = false;
}

void HeadTrackedBinaural::process(float* const* ambisonic, float* left, float* right) {
  DPC_ASSERT_AUDIO_THREAD();
  processBlock(ambisonic, left, right);
}

void HeadTrackedBinaural::processBlock(float* const* ambisonic, float* left, float* right) {
  const size_t B = size_t(blockSize_);
  rotate(ambisonic);
  std::fill(ears_.begin(), ears_.end(), 0.f);
  float* ears[2] = {ears_.data(), ears_.data() + B};
  for (size_t c = 0; c < convolvers_.size(); ++c) convolvers_[c]->processAdd(ambisonic[c], ears);
  float* out[2] = {left, right};
  for (int e = 0; e < 2; ++e) equalisers_[e]->process(ears[e], &out[e]);
}

Rotation3 headRotation(const float refForward[3], const float refUp[3], const float forward[3],
                       const float up[3]) {
  const auto cross = [](const float* a, const float* b, float* out) {
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
  };
  float refLeft[3], left[3];
  cross(refUp, refForward, refLeft);
  cross(up, forward, left);
  const float* now[3] = {forward, left, up};
  const float* ref[3] = {refForward, refLeft, refUp};
  Rotation3 r{};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      r[size_t(3 * i + j)] = now[i][0] * ref[j][0] + now[i][1] * ref[j][1] + now[i][2] * ref[j][2];
  return r;
}

}  // namespace dpc::audio
