// The settings hash of a bake: FNV-1a (64 bit) over everything that changes what a probe
// stores, in groups, so that a bake is refused for a changed scene or setting with a line
// naming what changed. dpc-bake --resume compares every group (a resumed bake must be the bake
// it started as); baked playback (bake/bake_loader.h) compares the groups that say what the
// stored responses are of (`playback`), not those that only draw another Monte Carlo sample
// of them (rays, seed, probe radius) or place the probes.
//
// Left out on purpose, because they do not change a probe (a bake always traces plain path
// tracing, docs/bake.md): the estimator and the cache settings (cache_tau, cache memory,
// dpc_weighting), frame_rate, the audio settings (sample rate, block size,
// output format: a bake stores energy per 1 ms, synthesised at playback), sources' gains and
// signals, names, tracing threads. tests/bake/bake_cli_test.sh checks that changing each of
// them leaves the file byte-identical.
// Any thread; allocates nothing but the result; no errors.
#pragma once

#include <array>
#include <cstdint>
#include <glm/vec3.hpp>
#include <vector>

#include "bake/probe_bake.h"
#include "scene/scene.h"

namespace dpc::bake {

enum class SettingGroup : int {
  kGeometry,   ///< static mesh; moving objects' meshes and poses at t = 0
  kMaterials,  ///< absorption, scattering, transmission_loss_db of every material
  kSources,    ///< positions and orientations at t = 0, directivity
  kListener,   ///< the probe radius (the scene's first listener's radius)
  kPhysics,    ///< orders, air, speed of sound, diffraction, roulette
  kSampling,   ///< rays, frames, sub-streams, seed, patch size, tracing direction
  kResponse,   ///< response length and bin widths, SH order
  kProbes,     ///< probe positions
  kWave,       ///< the wave band: off, or its maximum frequency, crossover, spacing, rate
};
inline constexpr int kSettingGroups = 9;
/// Groups a file of format version 5 holds (kWave came with version 6).
inline constexpr int kSettingGroupsVersion5 = 8;

struct SettingGroupInfo {
  const char* attribute;  ///< root attribute of the bake file holding the group's hash
  const char* what;       ///< what it covers, for messages
  bool playback;          ///< compared by baked playback too
};
inline constexpr std::array<SettingGroupInfo, kSettingGroups> kSettingGroupInfo = {{
    {"hash_geometry", "geometry (the static mesh, the moving objects' meshes and first poses)",
     true},
    {"hash_materials", "materials (absorption, scattering, transmission_loss_db)", true},
    {"hash_sources", "sources (positions and orientations at t = 0, directivity)", true},
    {"hash_listener", "probe radius (the first listener's radius)", false},
    {"hash_physics",
     "propagation physics (max_order, exact_order, speed of sound, temperature, humidity, air "
     "absorption, diffraction, roulette)",
     true},
    {"hash_sampling", "sampling (rays, frames, seed, patch_size, tracing direction)", false},
    {"hash_response", "response length (ir_length)", true},
    {"hash_probes", "probe positions", false},
    // Compared by baked playback only when the scene plays the wave band (bake/bake_loader.h).
    {"hash_wave",
     "wave band settings (wave.enabled, max_frequency, crossover_hz, grid_spacing, and the "
     "sample rate it is stored at)",
     false},
}};

using SettingsHash = std::array<uint64_t, kSettingGroups>;

/// The groups' hashes of a bake of `scene` with `settings` (rays, frames, sub-streams and
/// irLength as baked; threads ignored) at `probes` (metres).
SettingsHash settingsHash(const SceneDesc& scene, const BakeSettings& settings,
                          const std::vector<glm::vec3>& probes);
/// The groups' hashes a scene gives for playback comparisons: the scene's own ir_length, its
/// sampling and probe groups meaningless (baked playback does not compare them).
SettingsHash playbackHash(const SceneDesc& scene);
/// The same with `settings` in place of the scene's propagation settings.
SettingsHash playbackHash(const SceneDesc& scene, const PropagationSettings& settings);
/// The wave group's hash of `scene` (off: the same for every scene with wave.enabled false,
/// and the value files of format version 5 are read with).
uint64_t waveHash(const SceneDesc& scene);
/// One hash of every group and the bake format's version: the file's `settings_hash`. A file
/// of version 5 hashed its 8 groups with its version.
uint64_t combinedHash(const SettingsHash& groups, int64_t version);
/// The first group whose hashes differ (only the playback groups when playbackOnly), or -1.
int firstDifference(const SettingsHash& a, const SettingsHash& b, bool playbackOnly);

}  // namespace dpc::bake
