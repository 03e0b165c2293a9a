#include "bake/bake_loader.h"

#include "bake/bake_file.h"
#include "common/input_error.h"
#include "engine/workload.h"

namespace dpc::bake {
namespace {

/// Checks the file's header against the scene; throws InputError naming the field.
void checkHeader(const BakeFile& file, const SceneDesc& scene) {
  const BakeHeader& h = file.header();
  if (h.meshHash != sceneHash(scene))
    throw InputError(file.path(), "mesh_hash",
                     "the bake is of another scene than " + scene.path +
                         " (or the scene changed since the bake)");
  bool complete = false;
  try {
    complete = file.complete();
  } catch (const std::runtime_error& e) {
    throw InputError(file.path(), "complete", e.what());
  }
  if (!complete)
    throw InputError(file.path(), "complete",
                     "the bake is incomplete (finish it with dpc-bake --resume)");
  if (h.sources.size() != scene.sources.size())
    throw InputError(file.path(), "sources/position",
                     std::to_string(h.sources.size()) + " sources, the scene has " +
                         std::to_string(scene.sources.size()));
}

/// Takes the stored exact early paths out of the late responses (each from the bin of its
/// delay, as the bake added it), as the direct sound.
void removeEarly(const BakeFile& file, BakedField& f) {
  const std::vector<float> count = file.readAll("early/count");
  const std::vector<float> paths = file.readAll("early/paths");
  for (size_t i = 0; i < count.size(); ++i)
    for (size_t j = 0; j < size_t(count[i]) && j < kEarlyPaths; ++j) {
      const float* p = paths.data() + (i * kEarlyPaths + j) * kEarlyPathFloats;
      removeDirect(f.late.data() + i * f.bins * kNumBands, f.bins, f.binSeconds, p[0], p + 1);
    }
}

/// Refuses a bake whose arrays would not fit the memory a render may plan for
/// (plannableMemoryBytes), before reading them.
void checkMemory(const BakeFile& file) {
  const BakeHeader& h = file.header();
  const double bytes = double(h.probes.positions.size()) *
                       double(h.shape.energyFloats() + h.shape.directionalFloats()) *
                       sizeof(float);
  const double available = plannableMemoryBytes();
  if (bytes > available)
    throw InputError(file.path(), "energy",
                     "baked playback needs " + std::to_string(int64_t(bytes / 1e6)) +
                         " MB in memory, more than the " +
                         std::to_string(int64_t(available / 1e6)) + " MB available");
}

}  // namespace

std::shared_ptr<const BakedField> loadBakedField(const std::string& path, const SceneDesc& scene) {
  const BakeFile file = BakeFile::open(path, false);
  checkHeader(file, scene);
  checkMemory(file);
  const BakeHeader& h = file.header();
  auto f = std::make_shared<BakedField>();
  f->path = path;
  f->probes = h.probes.positions;
  f->sources = h.sources;
  f->bins = h.shape.bins;
  f->binSeconds = 1e-3;
  f->directionalBinFactor = kDirectionalBinFactor;
  for (const auto& a : kDirectionAxes) f->axes.push_back({a[0], a[1], a[2]});
  f->late = file.readAll("energy");
  f->directional = file.readAll("directional_energy");
  const std::vector<float> delay = file.readAll("direct/delay_s");
  const std::vector<float> direct = file.readAll("direct/energy");
  const size_t rows = f->probes.size() * f->sources.size();
  for (size_t i = 0; i < rows; ++i)
    removeDirect(f->late.data() + i * f->bins * kNumBands, f->bins, f->binSeconds, delay[i],
                 direct.data() + i * kNumBands);
  // Playback synthesises the exact early paths live when the scene asks for them.
  if (scene.propagation.exactOrder > 0) removeEarly(file, *f);
  return f;
}

}  // namespace dpc::bake
