// Output file names per listener for dpc-demo --offline.
#include "apps/demo/output_paths.h"

namespace dpc::demo {

std::string withListener(const std::string& path, const std::string& name) {
  if (path.empty()) return path;
  const size_t slash = path.find_last_of('/');
  const size_t dot = path.rfind('.');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash))
    return path + "-" + name;
  return path.substr(0, dot) + "-" + name + path.substr(dot);
}

std::vector<OutputPaths> offlineOutputs(const SceneDesc& scene, const Flags& fl) {
  if (!fl.listener.empty() || scene.listeners.size() <= 1)
    return {{fl.offline, fl.irOut, fl.erOut}};
  std::vector<OutputPaths> v;
  for (const ListenerDesc& l : scene.listeners)
    v.push_back({withListener(fl.offline, l.name), withListener(fl.irOut, l.name),
                 withListener(fl.erOut, l.name)});
  return v;
}

}  // namespace dpc::demo
