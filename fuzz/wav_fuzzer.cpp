// libFuzzer target: the dry-signal reader (audio/wav_io readWav, libsndfile underneath) on
// arbitrary bytes. Every refusal must be an InputError; any other exception, crash or
// sanitizer report is a finding. Corpus: fuzz/corpus/wav.
#include <cstdint>

#include "audio/wav_io.h"
#include "common/input_error.h"
#include "fuzz/fuzz_files.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = dpc::fuzz::put("signal.wav", data, size);
  try {
    (void)dpc::audio::readWav(path);
  } catch (const dpc::InputError&) {
  }
  return 0;
}
