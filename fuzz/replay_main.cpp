// Replays files through a fuzz target's LLVMFuzzerTestOneInput without libFuzzer, so that the
// seed corpus and every reproducer committed to fuzz/corpus/<target>/ run as an ordinary test
// in every build (ctest fuzz_replay:<target>; sanitized in scripts/asan.sh). An input that makes
// the target throw anything but the refusals it catches, or crash, fails the run; so does a
// seed named valid-* that the target does not accept (fuzz/fuzz_report.h: a stale seed).
// Usage: <target>_fuzz_replay FILE_OR_FOLDER...
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "fuzz/fuzz_report.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

namespace {

namespace fs = std::filesystem;

/// The files named, folders expanded to the files they hold; sorted.
std::vector<fs::path> inputFiles(int argc, char** argv) {
  std::vector<fs::path> inputs;
  for (int i = 1; i < argc; ++i) {
    if (fs::is_directory(argv[i])) {
      for (const auto& e : fs::directory_iterator(argv[i]))
        if (e.is_regular_file()) inputs.push_back(e.path());
    } else {
      inputs.push_back(argv[i]);
    }
  }
  std::sort(inputs.begin(), inputs.end());
  return inputs;
}

/// Runs the target on file `p`; false when it is a seed named valid-* that was not accepted.
bool replay(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  const std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(in)),
                                   std::istreambuf_iterator<char>());
  std::printf("%s (%zu bytes)\n", p.string().c_str(), bytes.size());
  std::fflush(stdout);
  dpc::fuzz::lastOutcome() = dpc::fuzz::Outcome::kNone;
  LLVMFuzzerTestOneInput(bytes.data(), bytes.size());
  if (p.filename().string().rfind("valid-", 0) != 0 ||
      dpc::fuzz::lastOutcome() == dpc::fuzz::Outcome::kAccepted)
    return true;
  std::fprintf(stderr, "fuzz replay: %s is a valid seed but was not accepted\n",
               p.string().c_str());
  return false;
}

}  // namespace

int main(int argc, char** argv) {
  const std::vector<fs::path> inputs = inputFiles(argc, argv);
  if (inputs.empty()) {
    std::fprintf(stderr, "fuzz replay: no input files\n");
    return 1;
  }
  size_t stale = 0;
  for (const fs::path& p : inputs) stale += replay(p) ? 0 : 1;
  if (stale) {
    std::printf("fuzz replay: %zu inputs, %zu valid seeds not accepted\n", inputs.size(), stale);
    return 1;
  }
  std::printf("fuzz replay: %zu inputs, no finding\n", inputs.size());
  return 0;
}
