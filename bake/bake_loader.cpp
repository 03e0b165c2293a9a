#include "bake/bake_loader.h"

#include <algorithm>

#include "bake/bake_file.h"
#include "common/input_error.h"
#include "engine/workload.h"
#include "scene/limits.h"

namespace dpc::bake {
namespace {

/// Refuses a bake whose playback settings hashes differ from the scene's (bake/settings_hash.h),
/// naming the group: InputError(file, attribute, ...).
void checkSettings(const BakeFile& file, const SceneDesc& scene,
                   const PropagationSettings& settings) {
  const BakeHeader& h = file.header();
  const int g = firstDifference(h.hashes, playbackHash(scene, settings), true);
  if (g < 0) return;
  if (g == int(SettingGroup::kResponse))
    throw InputError(file.path(), "ir_length_s",
                     "the bake's responses are " + valueText(h.settings.irLength) +
                         " s long, " + scene.path + "'s ir_length is " +
                         valueText(settings.irLength) + " s: bake again");
  const SettingGroupInfo& info = kSettingGroupInfo[size_t(g)];
  throw InputError(file.path(), info.attribute,
                   std::string("the bake's ") + info.what + " differ from " + scene.path +
                       "'s (another scene's bake, or the scene changed since): bake again");
}

/// Checks the file's header against the scene; throws InputError naming the field.
void checkHeader(const BakeFile& file, const SceneDesc& scene,
                 const PropagationSettings& settings) {
  const BakeHeader& h = file.header();
  checkSettings(file, scene, settings);
  if (h.sources.size() != scene.sources.size())  // hash_sources differs first, but for a collision
    throw InputError(file.path(), "sources/position",
                     std::to_string(h.sources.size()) + " sources, the scene has " +
                         std::to_string(scene.sources.size()));
  if (!file.complete())
    throw InputError(file.path(), "complete",
                     "the bake is incomplete (finish it with dpc-bake --resume)");
}

/// Takes one arrival out of row i ([probe][source]) of the late responses and of their SH
/// energy, from the bins the bake added it to.
void removeArrival(BakedField& f, size_t i, float delay, const float* intensity,
                   const glm::vec3& direction) {
  removeDirect(f.late.data() + i * f.bins * kNumBands, f.bins, f.binSeconds, delay, intensity);
  const size_t D = f.directionalBins();
  removeArrivalSh(f.sh.data() + i * D * f.shChannels() * kNumBands, D, f.shOrder,
                  f.binSeconds * double(f.directionalBinFactor), delay, intensity, direction);
}

/// Takes the direct sounds out of the late responses, as playback synthesises them live.
void removeDirectSounds(const BakeFile& file, BakedField& f) {
  const std::vector<float> delay = file.readAll("direct/delay_s");
  const std::vector<float> direct = file.readAll("direct/energy");
  const std::vector<float> direction = file.readAll("direct/direction");
  for (size_t i = 0; i < delay.size(); ++i)
    removeArrival(f, i, delay[i], direct.data() + i * kNumBands,
                  {direction[3 * i], direction[3 * i + 1], direction[3 * i + 2]});
}

/// Subtracts `part` from `whole` element by element, clamping at 0 where `clamp` says (the
/// energies; the SH channels beyond 0 are signed).
template <class Clamp>
void subtract(std::vector<float>& whole, const std::vector<float>& part, Clamp clamp) {
  for (size_t i = 0; i < whole.size() && i < part.size(); ++i)
    whole[i] = clamp(i) ? std::max(0.f, whole[i] - part[i]) : whole[i] - part[i];
}

/// Takes every exact early path out of the late responses and their SH energy: the bake's
/// `early/energy` and `early/sh_energy`, the paths' part of `energy` and `sh_energy` bin by
/// bin (all the paths the probe found, not only the 32 of `early/paths`), as playback adds
/// the paths it finds live.
void removeEarly(const BakeFile& file, BakedField& f) {
  subtract(f.late, file.readAll("early/energy"), [](size_t) { return true; });
  const size_t channels = f.shChannels();
  subtract(f.sh, file.readAll("early/sh_energy"),
           [channels](size_t i) { return (i / kNumBands) % channels == 0; });
}

/// Refuses a bake whose arrays would not fit the memory a render may plan for
/// (plannableMemoryBytes), before reading them: the late responses and their SH energy, and
/// while they are loaded one exact-path dataset (`early/energy`, the larger).
void checkMemory(const BakeFile& file, bool wave) {
  const BakeHeader& h = file.header();
  const double waveFloats =
      wave && h.wave.enabled ? double(h.sources.size()) * double(h.wave.samples) : 0.0;
  const double bytes = double(h.probes.positions.size()) *
                       (double(2 * h.shape.energyFloats() + h.shape.shFloats()) + waveFloats) *
                       sizeof(float);
  const double available = plannableMemoryBytes();
  if (bytes > available)
    throw InputError(file.path(), "energy",
                     "baked playback needs " + std::to_string(int64_t(bytes / 1e6)) +
                         " MB in memory, more than the " +
                         std::to_string(int64_t(available / 1e6)) + " MB available");
}

/// The bake's wave band into `f` when the scene plays it (wave.enabled) and the bake holds it,
/// refused (InputError naming `hash_wave`) when the bake's wave settings differ from the
/// scene's: another maximum frequency, crossover, grid spacing or sample rate.
void loadWave(const BakeFile& file, const SceneDesc& scene, BakedField& f) {
  const BakeHeader& h = file.header();
  if (!scene.wave.enabled || !h.wave.enabled) return;
  if (h.hashes[size_t(SettingGroup::kWave)] != waveHash(scene))
    throw InputError(file.path(), "hash_wave",
                     "the bake's wave band (max_frequency " +
                         valueText(h.wave.maxFrequencyHz) + " Hz, crossover " +
                         valueText(h.wave.crossoverHz) + " Hz, " +
                         std::to_string(h.wave.sampleRate) + " Hz sample rate) is not the one " +
                         scene.path + " asks for: bake again");
  f.wave = file.readAll(kWaveBand);
  f.waveReached = file.readBytes(kWaveReached);
  f.waveSamples = h.wave.samples;
  f.waveSampleRate = h.wave.sampleRate;
  f.waveMaxFrequencyHz = h.wave.maxFrequencyHz;
  f.waveCrossoverHz = h.wave.crossoverHz;
}

}  // namespace

std::shared_ptr<const BakedField> loadBakedField(const std::string& path, const SceneDesc& scene) {
  return loadBakedField(path, scene, scene.propagation);
}

std::shared_ptr<const BakedField> loadBakedField(const std::string& path, const SceneDesc& scene,
                                                 const PropagationSettings& settings) {
  const BakeFile file = BakeFile::open(path, BakeFile::Access::kRead);
  checkHeader(file, scene, settings);
  checkMemory(file, scene.wave.enabled);
  const BakeHeader& h = file.header();
  auto f = std::make_shared<BakedField>();
  f->path = path;
  f->probes = h.probes.positions;
  f->sources = h.sources;
  f->bins = h.shape.bins;
  f->binSeconds = 1e-3;
  f->directionalBinFactor = kDirectionalBinFactor;
  f->shOrder = kShOrder;
  f->late = file.readAll("energy");
  f->sh = file.readAll("sh_energy");
  removeDirectSounds(file, *f);
  // Playback synthesises the exact early paths live when the scene asks for them.
  if (settings.exactOrder > 0) removeEarly(file, *f);
  loadWave(file, scene, *f);
  return f;
}

}  // namespace dpc::bake
