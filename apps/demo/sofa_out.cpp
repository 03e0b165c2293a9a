#include "apps/demo/sofa_out.h"

#include <algorithm>
#include <cctype>
#include <filesystem>

#include "audio/sofa_writer.h"

namespace dpc::demo {
namespace {

audio::Vec3d toSofa(const glm::vec3& v) {
  return {double(v.x), -double(v.z), double(v.y)};
}

/// What the receivers are, for the file's Comment.
std::string receiverText(const AudioSettings& a) {
  switch (a.output) {
    case OutputFormat::kMono: return "receiver 1: pressure (mono)";
    case OutputFormat::kStereo: return "receivers 1-2: stereo left, right (constant-power pan)";
    case OutputFormat::kBinaural: return "receivers 1-2: left, right ear (HRTF " + a.hrtfPath + ")";
    case OutputFormat::kLoudspeakers: {
      std::string names;
      for (const LoudspeakerDesc& sp : a.speakers) names += (names.empty() ? "" : " ") + sp.name;
      return "receivers: loudspeaker feeds of layout " + a.layoutName + " (" + names + ")";
    }
    case OutputFormat::kAmbisonicBinaural:
    case OutputFormat::kAmbisonics:
      return "receivers: AmbiX, ACN order, SN3D, Ambisonic order " +
             std::to_string(a.ambisonicOrder) +
             (a.maxRe && a.output == OutputFormat::kAmbisonics ? ", max-rE weighted" : "");
  }
  return "";
}

}  // namespace

bool isSofaPath(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext == ".sofa";
}

TempOutputFile stageIrSofa(const SceneDesc& scene, const OfflineListenerResult& r,
                           const std::string& path) {
  audio::SofaIrs s;
  s.sampleRate = scene.audio.sampleRate;
  s.irs = r.lastIrs;
  for (const glm::vec3& p : r.lastSourcePositions) s.sourcePositions.push_back(toSofa(p));
  const size_t receivers = r.lastIrs.empty() ? 0 : size_t(r.lastIrs[0].channels());
  s.receiverPositions.assign(receivers, audio::Vec3d{});
  if (scene.audio.output == OutputFormat::kBinaural && receivers == 2) {
    s.receiverPositions[0] = {0.0, 0.09, 0.0};  // left ear: the listener's +y
    s.receiverPositions[1] = {0.0, -0.09, 0.0};
  }
  s.listenerPosition = toSofa(r.lastListenerPosition);
  s.listenerView = toSofa(r.lastListenerOrientation.forward());
  s.listenerUp = toSofa(r.lastListenerOrientation.up());
  s.title = "dpc impulse responses: " + scene.path + ", listener " + r.name;
  s.comment = receiverText(scene.audio) + "; one measurement per source, last propagation frame";
  return audio::stageSofa(path, s);
}

}  // namespace dpc::demo
