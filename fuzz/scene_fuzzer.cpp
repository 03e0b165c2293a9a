// libFuzzer target: the scene loader (engine/scene: JSON, then the OBJ it names) on arbitrary
// scene JSON. Every refusal must be an InputError (one line naming file and field); any other
// exception, crash, hang or sanitizer report is a finding. Corpus: fuzz/corpus/scene.
#include <cstdint>

#include "common/input_error.h"
#include "fuzz/fuzz_files.h"
#include "fuzz/fuzz_report.h"
#include "scene/scene.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = dpc::fuzz::put("scene.json", data, size);
  try {
    dpc::fuzz::acceptedScene(dpc::loadScene(path));
  } catch (const dpc::InputError& e) {
    dpc::fuzz::refused(e.what());
  }
  return 0;
}
