#include "audio/resample.h"

#include <samplerate.h>

#include <cmath>
#include <stdexcept>
#include <string>

namespace dpc::audio {

AudioData resample(const AudioData& in, int targetRate) {
  if (in.sampleRate <= 0 || targetRate <= 0)
    throw std::invalid_argument("resample: sample rates must be positive (got " +
                                std::to_string(in.sampleRate) + " -> " +
                                std::to_string(targetRate) + ")");
  if (in.sampleRate == targetRate) return in;
  const double ratio = double(targetRate) / double(in.sampleRate);
  if (!src_is_valid_ratio(ratio))
    throw std::invalid_argument("resample: ratio " + std::to_string(ratio) +
                                " is outside libsamplerate's range [1/256, 256]");

  const size_t inFrames = in.frames();
  const size_t outFrames = size_t(std::llround(double(inFrames) * ratio));
  AudioData out;
  out.sampleRate = targetRate;
  out.channels.reserve(in.channels.size());
  for (const auto& channel : in.channels) {
    // Room for the converter's rounding; trimmed or zero-padded to outFrames below.
    std::vector<float> converted(outFrames + 16, 0.f);
    SRC_DATA data{};
    data.data_in = channel.data();
    data.input_frames = long(inFrames);
    data.data_out = converted.data();
    data.output_frames = long(converted.size());
    data.src_ratio = ratio;
    data.end_of_input = 1;
    const int err = src_simple(&data, SRC_SINC_BEST_QUALITY, 1);
    if (err != 0) throw std::runtime_error(std::string("resample: ") + src_strerror(err));
    converted.resize(outFrames);  // frames past output_frames_gen are already zero
    out.channels.push_back(std::move(converted));
  }
  return out;
}

}  // namespace dpc::audio
