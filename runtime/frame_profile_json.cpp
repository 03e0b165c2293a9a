#include "runtime/frame_profile_json.h"

namespace dpc {

nlohmann::ordered_json frameProfileJson(const FrameProfile::Snapshot& profile) {
  using Json = nlohmann::ordered_json;
  Json j = Json::object();
  for (const FrameProfile::Snapshot::Row& r : profile.rows())
    j[r.name] = {{"frames", r.frames}, {"mean", r.meanMs},  {"median", r.medianMs},
                 {"p95", r.p95Ms},     {"max", r.maxMs}};
  j["pairs_cpu_s"] = {{"direct_and_diffraction", profile.directCpuSeconds},
                      {"exact_paths", profile.exactCpuSeconds},
                      {"estimator", profile.estimatorCpuSeconds}};
  return j;
}

}  // namespace dpc
