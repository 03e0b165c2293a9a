// libFuzzer target: the bake file's reader and validator (bake/bake_file.h: BakeFile::open for
// reading, which checks the HDF5 signature and superblock version, the format, attributes,
// settings hashes and shapes, and every stored probe's CRC-32) on arbitrary bytes, then the
// reads a player makes of a file it accepted (with its wave band, when it holds one). Every
// refusal must be an InputError (one line naming the file); any other exception, crash or
// sanitizer report is a finding. HDF5's own parser is not instrumented: a finding inside it
// shows as a crash. Corpus: fuzz/corpus/bake (small valid bakes, valid-*, and damaged copies;
// fuzz/make_bake_seeds.sh makes them).
#include <cstdint>

#include "bake/bake_file.h"
#include "common/input_error.h"
#include "fuzz/fuzz_files.h"
#include "fuzz/fuzz_report.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = dpc::fuzz::put("bake.h5", data, size);
  try {
    const auto file = dpc::bake::BakeFile::open(path, dpc::bake::BakeFile::Access::kRead);
    const bool complete = file.complete();
    const size_t energy = file.readAll("energy").size();
    const size_t parameters = file.readAll("parameters").size();
    const size_t wave = file.header().wave.enabled ? file.readAll("wave/band").size() +
                                                         file.readBytes("wave/reached").size()
                                                   : 0;
    dpc::fuzz::accepted("format " + std::to_string(file.header().version) + ", " +
                        std::to_string(file.header().probes.positions.size()) + " probes, " +
                        (complete ? "complete, " : "incomplete, ") + std::to_string(energy) +
                        " energy, " + std::to_string(parameters) + " parameter and " +
                        std::to_string(wave) + " wave band values");
  } catch (const dpc::InputError& e) {
    dpc::fuzz::refused(e.what());
  }
  return 0;
}
