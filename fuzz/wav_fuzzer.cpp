// libFuzzer target: the dry-signal reader (audio/wav_io readWav, libsndfile underneath) on
// arbitrary bytes. Every refusal must be an InputError; any other exception, crash or
// sanitizer report is a finding. Corpus: fuzz/corpus/wav.
#include <cstdint>

#include "audio/wav_io.h"
#include "common/input_error.h"
#include "fuzz/fuzz_files.h"
#include "fuzz/fuzz_report.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = dpc::fuzz::put("signal.wav", data, size);
  try {
    const dpc::audio::AudioData audio = dpc::audio::readWav(path);
    dpc::fuzz::accepted(std::to_string(audio.channels.size()) + " channels, " +
                        std::to_string(audio.frames()) + " frames at " +
                        std::to_string(audio.sampleRate) + " Hz");
  } catch (const dpc::InputError& e) {
    dpc::fuzz::refused(e.what());
  }
  return 0;
}
