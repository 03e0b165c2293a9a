// dpc-demo's flags that override a scene key (scene/validate.h commandLineOrigin) fed every
// limit of scene/limits.h: each bound is accepted and one step beyond is refused with an error
// naming the flag. Table-driven: every table entry with a flag that dpc-demo offers is probed.
#include <sys/wait.h>
#include <unistd.h>

#include <catch2/catch.hpp>
#include <cstdio>
#include <filesystem>
#include <string>

#include "scene/limits.h"
#include "scene/validate.h"
#include "tests/limit_probes.h"

using namespace dpc;

namespace {

const std::string kDemo = std::string(DPC_BINARY_DIR) + "/apps/dpc-demo";
const std::string kScene = std::string(DPC_SOURCE_DIR) + "/scenes/shoebox.json";

/// Runs dpc-demo with `args`; returns its standard error (and output) text.
std::string runDemo(const std::string& args) {
  const std::string cmd = kDemo + " " + args + " 2>&1";
  FILE* pipe = ::popen(cmd.c_str(), "r");
  REQUIRE(pipe != nullptr);
  std::string out;
  char buf[4096];
  for (size_t n; (n = std::fread(buf, 1, sizeof buf, pipe)) > 0;) out.append(buf, n);
  ::pclose(pipe);
  return out;
}

}  // namespace

TEST_CASE("dpc-demo flags: every limit is accepted at its bounds and refused beyond", "[limits]") {
  const std::string help = runDemo("--help");
  const Origin flags = commandLineOrigin();
  int probed = 0;
  for (const Limit& l : limits()) {
    const std::string flag = flags.fieldName(std::string(l.field));
    if (flag.rfind("--", 0) != 0 || help.find(flag + " ") == std::string::npos) continue;
    for (const test::LimitProbe& p : test::probesFor(l)) {
      // Live mode with a refused --duration: every override is checked before it, so an
      // accepted value ends with the --duration error and no audio device is opened.
      // A flag for one kind of output only is refused with any other, as changing nothing.
      const std::string output = flag == "--ambisonic-order" ? " --output ambisonics" : "";
      const std::string out = runDemo(kScene + " " + flag + "=" + valueText(p.value) + output +
                                      " --duration=-1");
      INFO(flag << " " << p.what << " = " << valueText(p.value) << ": " << out);
      if (p.accepted) {
        CHECK(out.find("command line: --duration: ") != std::string::npos);
      } else {
        CHECK(out.find("command line: " + flag + ": ") != std::string::npos);
      }
      ++probed;
    }
  }
  CHECK(probed >= 5 * 4);  // --rays, --max-order, --tau, --cache-memory-mb, --block-size
}
