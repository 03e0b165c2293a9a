#include "bake/settings_hash.h"

#include "bake/bake_layout.h"
#include "scene/tracing_policy.h"
#include "scene/trajectory.h"

namespace dpc::bake {
namespace {

/// FNV-1a, 64 bit.
class Fnv {
 public:
  void bytes(const void* data, size_t n) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (size_t i = 0; i < n; ++i) h_ = (h_ ^ p[i]) * 0x100000001b3ULL;
  }
  template <typename T>
  void value(const T& v) {
    bytes(&v, sizeof v);
  }
  template <typename T>
  void values(const std::vector<T>& v) {
    value(uint64_t(v.size()));
    bytes(v.data(), v.size() * sizeof(T));
  }
  uint64_t get() const { return h_; }

 private:
  uint64_t h_ = 0xcbf29ce484222325ULL;
};

void mesh(Fnv& h, const Mesh& m) {
  h.values(m.vertices);
  h.values(m.triangles);
  h.values(m.materialIndex);
}

uint64_t geometry(const SceneDesc& scene) {
  Fnv h;
  mesh(h, scene.mesh);
  h.value(uint64_t(scene.objects.size()));
  for (const ObjectDesc& o : scene.objects) {
    mesh(h, o.mesh);
    const Pose p = objectPoseAt(o, 0.0);
    h.value(p.position);
    h.value(p.rotation);
  }
  return h.get();
}

uint64_t materials(const SceneDesc& scene) {
  Fnv h;
  h.value(uint64_t(scene.materials.size()));
  for (const Material& m : scene.materials) {
    h.value(m.absorption);
    h.value(m.scattering);
    h.value(m.transmissionLossDb);
  }
  return h.get();
}

uint64_t sources(const SceneDesc& scene) {
  Fnv h;
  h.value(uint64_t(scene.sources.size()));
  for (const SourceDesc& s : scene.sources) {
    h.value(sourcePositionAt(s, 0.0));
    h.value(sourceRotationAt(s, 0.0));
    h.value(s.directivity.a);
  }
  return h.get();
}

uint64_t physics(const PropagationSettings& p) {
  Fnv h;
  for (const int v : {p.maxOrder, p.exactOrder, int(p.airAbsorption), int(p.diffraction),
                      int(p.reflectionScattering)})
    h.value(v);
  for (const float v : {p.speedOfSound, p.temperatureC, p.humidityPercent, p.rouletteThreshold})
    h.value(v);
  return h.get();
}

uint64_t sampling(const SceneDesc& scene, const BakeSettings& s) {
  Fnv h;
  for (const int v : {s.rays, s.frames, s.subStreams}) h.value(v);
  h.value(scene.propagation.seed);
  // The patches path identifiers are made of: they group a frame's hits into the arrivals
  // whose directions sh_energy sums (energy only to float rounding).
  h.value(scene.propagation.patchSize);
  // The direction the rays leave from, as a probe's frame traces it (one listener).
  h.value(uint8_t(tracesFromListeners(scene.propagation.tracing, scene.sources.size(), 1)));
  return h.get();
}

uint64_t response(const BakeSettings& s) {
  Fnv h;
  h.value(uint64_t(responseBins(s.irLength)));
  h.value(s.irLength);
  h.value(uint64_t(kDirectionalBinFactor));
  h.value(kShOrder);
  return h.get();
}

}  // namespace

uint64_t waveHash(const SceneDesc& scene) {
  Fnv h;
  const WaveSettings& w = scene.wave;
  h.value(uint8_t(w.enabled));
  if (!w.enabled) return h.get();
  for (const float v : {w.maxFrequencyHz, w.crossover(), w.gridSpacingM}) h.value(v);
  h.value(scene.audio.sampleRate);
  return h.get();
}

SettingsHash settingsHash(const SceneDesc& scene, const BakeSettings& settings,
                          const std::vector<glm::vec3>& probes) {
  SettingsHash g{};
  g[size_t(SettingGroup::kGeometry)] = geometry(scene);
  g[size_t(SettingGroup::kMaterials)] = materials(scene);
  g[size_t(SettingGroup::kSources)] = sources(scene);
  Fnv radius;
  radius.value(scene.listeners.empty() ? 0.f : scene.listeners[0].radius);
  g[size_t(SettingGroup::kListener)] = radius.get();
  g[size_t(SettingGroup::kPhysics)] = physics(scene.propagation);
  g[size_t(SettingGroup::kSampling)] = sampling(scene, settings);
  g[size_t(SettingGroup::kResponse)] = response(settings);
  Fnv positions;
  positions.values(probes);
  g[size_t(SettingGroup::kProbes)] = positions.get();
  g[size_t(SettingGroup::kWave)] = waveHash(scene);
  return g;
}

SettingsHash playbackHash(const SceneDesc& scene) {
  return playbackHash(scene, scene.propagation);
}

SettingsHash playbackHash(const SceneDesc& scene, const PropagationSettings& settings) {
  BakeSettings bake;
  bake.irLength = settings.irLength;
  SettingsHash g = settingsHash(scene, bake, {});
  g[size_t(SettingGroup::kPhysics)] = physics(settings);
  return g;
}

uint64_t combinedHash(const SettingsHash& groups, int64_t version) {
  Fnv h;
  h.value(version);
  const int n = version < 6 ? kSettingGroupsVersion5 : kSettingGroups;
  for (int g = 0; g < n; ++g) h.value(groups[size_t(g)]);
  return h.get();
}

int firstDifference(const SettingsHash& a, const SettingsHash& b, bool playbackOnly) {
  for (int i = 0; i < kSettingGroups; ++i)
    if ((!playbackOnly || kSettingGroupInfo[size_t(i)].playback) && a[size_t(i)] != b[size_t(i)])
      return i;
  return -1;
}

}  // namespace dpc::bake
