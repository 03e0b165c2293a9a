// Sample-rate conversion (libsamplerate).
//
// Control thread (or an offline render thread): allocates, may take time. Not for the audio
// thread.
#pragma once

#include "audio/wav_io.h"

namespace dpc::audio {

/// Returns `in` converted to `targetRate` Hz with libsamplerate's SRC_SINC_BEST_QUALITY
/// converter (documented: 97 dB SNR, 97 % bandwidth). Every channel is converted
/// independently; the output has round(frames * targetRate / in.sampleRate) frames per channel
/// and no added delay. Identity (a copy) when the rates already match.
/// Throws std::invalid_argument if either rate is not positive or the ratio is outside
/// libsamplerate's range [1/256, 256]; std::runtime_error if libsamplerate reports an error.
AudioData resample(const AudioData& in, int targetRate);

}  // namespace dpc::audio
