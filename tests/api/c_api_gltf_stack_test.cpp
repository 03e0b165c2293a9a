// glTF levels loaded through the C API on a thread with a small stack, as a plugin host's
// worker thread runs dpc_engine_create_from_file (the LV2 plugin loads its scene there): a node
// tree 20,000 deep is refused in one line naming the level and its depth limit (the checks walk
// the tree without recursion, before assimp, which recurses once per level, reads it), and the
// door level (scenes/door_level.json) loads on the same stack.
#include <pthread.h>

#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>
#include <string>

#include "dpc/dpc.h"
#include "testing/temp_dir.h"

namespace {

#if defined(__SANITIZE_ADDRESS__)
constexpr size_t kFrameGrowth = 4;  // AddressSanitizer's redzones make stack frames larger
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
constexpr size_t kFrameGrowth = 4;
#else
constexpr size_t kFrameGrowth = 1;
#endif
#else
constexpr size_t kFrameGrowth = 1;
#endif

/// A host worker's stack: 256 KiB (glibc's default is 8 MiB; hosts and thread pools often
/// give their workers far less). A 20,000-deep recursion of even 100 bytes a level overflows it.
constexpr size_t kHostStackBytes = 256 * 1024 * kFrameGrowth;

struct Load {
  std::string scene;
  dpc_status status = DPC_OK;
  std::string error;
};

void* load(void* arg) {
  auto* l = static_cast<Load*>(arg);
  dpc_engine* e = nullptr;
  dpc_engine_options o;
  dpc_engine_options_init(&o);
  o.host_inputs_only = 1;  // as the plugin: the host feeds the sources
  l->status = dpc_engine_create_from_file(l->scene.c_str(), &o, &e);
  if (l->status != DPC_OK) l->error = dpc_last_error();
  if (e) dpc_engine_destroy(e);
  return nullptr;
}

Load loadOnSmallStack(const std::string& scene) {
  Load l;
  l.scene = scene;
  pthread_attr_t attr;
  REQUIRE(pthread_attr_init(&attr) == 0);
  REQUIRE(pthread_attr_setstacksize(&attr, kHostStackBytes) == 0);
  pthread_t thread;
  REQUIRE(pthread_create(&thread, &attr, load, &l) == 0);
  REQUIRE(pthread_join(thread, nullptr) == 0);
  pthread_attr_destroy(&attr);
  return l;
}

/// deep.gltf: `depth` nodes, each the only child of the one before; and scene.json naming it.
void writeChain(const std::filesystem::path& dir, int depth) {
  std::ofstream level(dir / "deep.gltf");
  level << R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [)";
  for (int k = 0; k + 1 < depth; ++k) level << R"({"children": [)" << k + 1 << "]},";
  level << "{}]}";
  std::ofstream(dir / "scene.json") << R"({"mesh": "deep.gltf",
    "materials": {"walls": {"absorption": 0.1}}, "sources": [{"name": "s", "position": [1, 1, 1]}],
    "listener": {"position": [2, 1, 1]}})";
}

}  // namespace

TEST_CASE("A node tree 20,000 deep is refused on a 256 KiB host thread", "[gltf]") {
  dpc::test::TempDir dir("dpc_gltf_stack");
  writeChain(dir.path(), 20000);
  const Load l = loadOnSmallStack((dir.path() / "scene.json").string());
  CHECK(l.status == DPC_ERR_INPUT);
  INFO(l.error);
  CHECK(l.error.find("deep.gltf: nodes[128]: lies more than 128 levels deep") != std::string::npos);
}

TEST_CASE("The door level loads on a 256 KiB host thread", "[gltf]") {
  const Load l = loadOnSmallStack(std::string(DPC_SOURCE_DIR) + "/scenes/door_level.json");
  INFO(l.error);
  CHECK(l.status == DPC_OK);
}
