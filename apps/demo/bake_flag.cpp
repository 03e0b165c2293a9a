#include "apps/demo/bake_flag.h"

#include <cstdio>

#include "common/input_error.h"
#ifdef DPC_HAVE_BAKE
#include "bake/bake_loader.h"
#endif

namespace dpc::demo {

std::shared_ptr<const BakedField> loadBakeFlag(const Flags& fl, const SceneDesc& scene,
                                               const PropagationSettings& settings) {
  if (fl.bake.empty()) return nullptr;
#ifdef DPC_HAVE_BAKE
  return bake::loadBakedField(fl.bake, scene, settings);
#else
  (void)scene;
  (void)settings;
  throw InputError("command line", "--bake",
                   "this dpc-demo was built without HDF5 (scripts/install-deps.sh installs "
                   "libhdf5-dev)");
#endif
}

void printBakeSummary(const BakedField& bake, const BakedPlayback::Stats& stats) {
  std::printf(
      "bake %s: %zu probes, %.1f MB  source responses from the bake %llu, live %llu  "
      "listener positions with no visible probe (played live) %llu\n",
      bake.path.c_str(), bake.probes.size(), double(bake.bytes()) / 1e6,
      (unsigned long long)stats.bakedResponses, (unsigned long long)stats.liveResponses,
      (unsigned long long)stats.fallbacks);
}

}  // namespace dpc::demo
