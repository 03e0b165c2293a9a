#include "runtime/output_format.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>

#include "audio/hrtf.h"
#include "audio/panning.h"
#include "audio/vbap.h"
#include "common/input_error.h"
#include "common/random.h"
#include "common/spherical_harmonics.h"

namespace dpc {

std::vector<glm::vec3> spatialDirections(const AudioSettings& audio) {
  if (audio.output != OutputFormat::kAmbisonics && audio.output != OutputFormat::kAmbisonicBinaural)
    return defaultSpatialDirections();
  return uniformSpatialDirections(kTurnedFieldDirectionsPerChannel *
                                  ambisonicChannels(audio.ambisonicOrder));
}

int renderedChannels(const AudioSettings& audio) {
  return audio.output == OutputFormat::kAmbisonicBinaural ? 2 : irChannels(audio);
}

std::vector<std::string> renderedChannelNames(const AudioSettings& audio) {
  std::vector<std::string> names;
  switch (audio.output) {
    case OutputFormat::kMono:
      return {"mono"};
    case OutputFormat::kAmbisonics:
      for (int c = 0; c < irChannels(audio); ++c) names.push_back("ACN" + std::to_string(c));
      return names;
    case OutputFormat::kLoudspeakers:
      for (const LoudspeakerDesc& s : audio.speakers) names.push_back(s.name);
      return names;
    default:
      return {"left", "right"};
  }
}

int irChannels(const AudioSettings& audio) {
  switch (audio.output) {
    case OutputFormat::kMono:
      return 1;
    case OutputFormat::kAmbisonics:
    case OutputFormat::kAmbisonicBinaural:
      return ambisonicChannels(audio.ambisonicOrder);
    case OutputFormat::kLoudspeakers:
      return int(audio.speakers.size());
    default:
      return 2;
  }
}

namespace {

/// Filters for the spatial synthesiser: HRIR pairs (binaural, with the SOFA file's onset
/// delays as leading zeros), constant-power panning gains (stereo), or one-tap ACN/SN3D
/// spherical-harmonic gains times the per-order weights (Ambisonics, ambisonicOrder > 0).
struct SpatialFilters {
  std::shared_ptr<audio::Hrtf> hrtf;
  int ambisonicOrder = 0;
  std::array<float, kMaxAmbisonicOrder + 1> orderWeights{};
  std::shared_ptr<audio::Vbap> vbap;  ///< loudspeakers: over the non-LFE ones
  std::vector<size_t> vbapChannel;    ///< the output channel of each VBAP loudspeaker
  size_t speakerChannels = 0;         ///< every loudspeaker, LFE included
  /// Per output channel: the layout's distance compensation (delay, gain).
  std::vector<DistanceCompensation> compensation;
  void fill(const glm::vec3& d, DirectionFilter& out) const {
    const float dir[3] = {d.x, d.y, d.z};
    if (ambisonicOrder > 0) return fillAmbisonic(dir, out);
    if (vbap) return fillLoudspeakers(dir, out);
    out.channels.resize(2);
    std::vector<float>& left = out.channels[0];
    std::vector<float>& right = out.channels[1];
    if (!hrtf) {
      float l = 0.f, r = 0.f;
      audio::stereoGains(dir, &l, &r);
      left.assign(1, l);
      right.assign(1, r);
      return;
    }
    const size_t n = size_t(hrtf->filterLength());
    float delayL = 0.f, delayR = 0.f;
    left.resize(n);
    right.resize(n);
    hrtf->hrir(dir, left.data(), right.data(), &delayL, &delayR);
    auto delay = [](std::vector<float>& h, float samples) {
      const size_t k = size_t(std::max(0.f, std::round(samples)));
      if (k) h.insert(h.begin(), k, 0.f);
    };
    delay(left, delayL);
    delay(right, delayR);
  }
  void fillLoudspeakers(const float dir[3], DirectionFilter& out) const {
    std::array<float, kMaxLoudspeakers> g{};
    vbap->gains(dir, g);
    out.channels.resize(speakerChannels);
    for (auto& c : out.channels) c.assign(1, 0.f);  // LFE: silent
    for (size_t k = 0; k < vbapChannel.size(); ++k) {
      const DistanceCompensation& dc = compensation[vbapChannel[k]];
      std::vector<float>& h = out.channels[vbapChannel[k]];
      h.assign(dc.delaySamples + 1, 0.f);  // a delayed gain (a gain when not compensated)
      h.back() = g[k] * float(dc.gain);
    }
  }
  void fillAmbisonic(const float dir[3], DirectionFilter& out) const {
    std::array<float, ambisonicChannels(kMaxAmbisonicOrder)> y{};
    sphericalHarmonicsSn3d(ambisonicOrder, dir, y);
    out.channels.resize(size_t(ambisonicChannels(ambisonicOrder)));
    for (int n = 0; n <= ambisonicOrder; ++n)
      for (int c = n * n; c < (n + 1) * (n + 1); ++c)
        out.channels[size_t(c)].assign(1, y[size_t(c)] * orderWeights[size_t(n)]);
  }
};

/// Loudspeaker output: VBAP over the layout's loudspeakers that are not LFE, and the layout's
/// distance compensation. Throws InputError naming the layout for one VBAP cannot pan over.
void setLoudspeakers(const SceneDesc& scene, double speedOfSound, SpatialFilters& filters) {
  std::vector<std::array<double, 2>> angles;
  for (size_t c = 0; c < scene.audio.speakers.size(); ++c) {
    const LoudspeakerDesc& s = scene.audio.speakers[c];
    if (s.lfe) continue;
    angles.push_back({s.azimuthDegrees, s.elevationDegrees});
    filters.vbapChannel.push_back(c);
  }
  try {
    filters.vbap = std::make_shared<audio::Vbap>(angles);
  } catch (const std::invalid_argument& e) {
    throw InputError(scene.audio.layoutName, "speakers", e.what());
  }
  filters.speakerChannels = scene.audio.speakers.size();
  filters.compensation =
      distanceCompensation(scene.audio.speakers, speedOfSound, scene.audio.sampleRate);
}

}  // namespace

std::unique_ptr<SpatialIrSynthesizer> makeSpatialSynthesizer(const SceneDesc& scene,
                                                             const PropagationSettings& settings,
                                                             double roomVolume) {
  return makeSpatialSynthesizer(scene, settings, roomVolume, settings.irLength, 0);
}

std::unique_ptr<SpatialIrSynthesizer> makeSpatialSynthesizer(const SceneDesc& scene,
                                                             const PropagationSettings& settings,
                                                             double roomVolume,
                                                             double lengthSeconds,
                                                             uint64_t seedSalt) {
  const int fs = scene.audio.sampleRate;
  auto filters = std::make_shared<SpatialFilters>();
  if (scene.audio.output == OutputFormat::kBinaural) {
    try {
      filters->hrtf = std::make_shared<audio::Hrtf>(audio::Hrtf::load(scene.audio.hrtfPath, fs));
    } catch (const InputError& e) {
      throw InputError(scene.path, "audio.hrtf", e.what());
    }
  }
  using Reference = SpatialIrSynthesizer::Reference;
  Reference reference = Reference::kChannelAverage;
  if (scene.audio.output == OutputFormat::kAmbisonics ||
      scene.audio.output == OutputFormat::kAmbisonicBinaural) {
    filters->ambisonicOrder = scene.audio.ambisonicOrder;
    filters->orderWeights.fill(1.f);
    // The binaural decoders are fitted to the plain SN3D encoding: max-rE's order weights
    // would skew them (at order 3 MagLS's 4 kHz ILD at 90 degrees 4.9 dB too high).
    if (scene.audio.maxRe && scene.audio.output == OutputFormat::kAmbisonics)
      maxReWeights(filters->ambisonicOrder, filters->orderWeights);
    reference = Reference::kFirstChannelPressure;
  }
  if (scene.audio.output == OutputFormat::kLoudspeakers) {
    setLoudspeakers(scene, settings.speedOfSound, *filters);
    reference = Reference::kChannelSum;
  }
  const std::vector<glm::vec3> directions = spatialDirections(scene.audio);
  std::vector<DirectionFilter> perDirection(directions.size());
  for (size_t d = 0; d < directions.size(); ++d) filters->fill(directions[d], perDirection[d]);
  const uint64_t seed = hashCombine(settings.seed, 0x5bd1e995ULL);
  return std::make_unique<SpatialIrSynthesizer>(
      fs, lengthSeconds, roomVolume, settings.speedOfSound,
      seedSalt ? hashCombine(seed, seedSalt) : seed, directions, perDirection,
      [filters](const glm::vec3& d, DirectionFilter& out) { filters->fill(d, out); }, reference);
}

}  // namespace dpc
