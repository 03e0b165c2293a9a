// dpc-demo's overrides of the scene's settings from the command line, and the checks of its
// output paths against the inputs and each other.
#include "apps/demo/overrides.h"

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <filesystem>
#include <initializer_list>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "apps/demo/output_paths.h"
#include "apps/demo/sofa_out.h"
#include "common/input_error.h"
#include "common/input_file.h"
#include "common/output_file.h"
#include "scene/enum_names.h"
#include "scene/validate.h"

namespace dpc::demo {

namespace {

/// A flag for a float field, checked as the field will hold it (single precision; see
/// checkFloatField): --cluster-angle 1e-300 is refused naming the flag, not held as 0.
float floatFlag(std::string_view field, double given) {
  return checkFloatField(field, given, commandLineOrigin());
}

}  // namespace

PropagationSettings applyOverrides(const SceneDesc& scene, const Flags& fl) {
  PropagationSettings s = scene.propagation;
  auto bad = [&](const char* flag, const std::string& why) {
    throw InputError("command line", flag, why);
  };
  if (fl.seed) {
    s.seed = *fl.seed;
  }
  // Ranges: the scene keys' (scene/limits.h), checked before narrowing to the stored type.
  const Origin flags = commandLineOrigin();
  if (fl.rays) {
    checkField("propagation.rays_per_frame", double(*fl.rays), flags);
    s.raysPerFrame = int(*fl.rays);
  }
  if (fl.maxOrder) {
    checkField("propagation.max_order", double(*fl.maxOrder), flags);
    s.maxOrder = int(*fl.maxOrder);
  }
  if (fl.tau) {
    s.cacheTau = floatFlag("propagation.cache_tau", *fl.tau);
  }
  if (fl.cachePoolMb) {
    s.cachePoolMb = floatFlag("propagation.cache_pool_mb", *fl.cachePoolMb);
  }
  if (fl.cacheMb) {
    s.cacheMemoryMb = floatFlag("propagation.cache_memory_mb", *fl.cacheMb);
  }
  if (fl.threads) {
    if (*fl.threads < 0 || *fl.threads > kMaxTracingThreads)
      bad("--threads", "must be in 0.." + std::to_string(kMaxTracingThreads));
    s.threads = int(*fl.threads);
  }
  if (!fl.estimator.empty()) {
    auto e = parseEstimator(fl.estimator);
    if (!e) bad("--estimator", "'" + fl.estimator + "' is not dpc or path_tracing");
    s.estimator = *e;
  }
  if (!fl.tracing.empty()) {
    auto t = parseTracing(fl.tracing);
    if (!t) bad("--tracing", "'" + fl.tracing + "' is not auto, from_sources or from_listeners");
    s.tracing = *t;
  }
  if (!fl.weighting.empty()) {
    auto w = parseDpcWeighting(fl.weighting);
    if (!w) bad("--dpc-weighting", "'" + fl.weighting + "' is not ema, seed or window");
    s.dpcWeighting = *w;
  }
  return s;
}

void applyAudioOverrides(SceneDesc& scene, const Flags& fl) {
  if (fl.output.rfind("layout:", 0) == 0) {
    scene.audio.layoutName = fl.output.substr(7);
    scene.audio.speakers = loudspeakerLayout(scene.audio.layoutName, "--output");
    scene.audio.output = OutputFormat::kLoudspeakers;
  } else if (!fl.output.empty()) {
    auto o = parseOutputFormat(fl.output);
    if (!o)
      throw InputError("command line", "--output",
                       "'" + fl.output +
                           "' is not mono, stereo, binaural, ambisonics, ambisonic_binaural or "
                           "layout:NAME");
    scene.audio.output = *o;
  }
  if (fl.ambisonicOrder) {
    checkField("audio.ambisonic_order", double(*fl.ambisonicOrder), commandLineOrigin());
    scene.audio.ambisonicOrder = int(*fl.ambisonicOrder);
  }
  if (fl.maxRe) scene.audio.maxRe = true;  // both range-checked, used by Ambisonic output only
  if (!fl.binauralDecoder.empty()) {
    auto d = parseBinauralDecoder(fl.binauralDecoder);
    if (!d)
      throw InputError("command line", "--binaural-decoder",
                       "'" + fl.binauralDecoder + "' is not magls or sampling");
    scene.audio.binauralDecoder = *d;
  }
  if (!fl.hrtf.empty()) {
    checkInputFile(fl.hrtf, kMaxSofaBytes, "command line", "--hrtf", "SOFA file");
    scene.audio.hrtfPath = fl.hrtf;
    // Without --output, an output that does not use an HRTF becomes binaural; one that does
    // (ambisonic_binaural) is kept.
    if (fl.output.empty() && scene.audio.output != OutputFormat::kAmbisonicBinaural)
      scene.audio.output = OutputFormat::kBinaural;
  }
  if (!fl.listener.empty()) listenerIndex(scene, fl.listener, "--listener");  // known name?
  applyRenderingOverrides(scene.audio, fl);
  refuseUnusedAudioFlags(scene.audio, fl);
}

void refuseUnusedAudioFlags(const AudioSettings& audio, const Flags& fl) {
  const OutputFormat out = audio.output;
  const bool ambisonic = out == OutputFormat::kAmbisonics || out == OutputFormat::kAmbisonicBinaural;
  auto unused = [&](const char* flag, const char* forWhat) {
    throw InputError("command line", flag,
                     std::string("is for ") + forWhat + " (this run's output is " +
                         outputFormatName(out) + "); it would change nothing");
  };
  auto perSource = [](const char* flag) {
    throw InputError("command line", flag,
                     "is for hybrid rendering; with this run's per-source rendering it would "
                     "change nothing");
  };
  if (!fl.hrtf.empty() && out != OutputFormat::kBinaural && out != OutputFormat::kAmbisonicBinaural)
    unused("--hrtf", "binaural and ambisonic_binaural output");
  if (fl.ambisonicOrder && !ambisonic)
    unused("--ambisonic-order", "ambisonics and ambisonic_binaural output");
  if (fl.maxRe && out != OutputFormat::kAmbisonics) unused("--max-re", "ambisonics output");
  if (!fl.binauralDecoder.empty() && out != OutputFormat::kAmbisonicBinaural)
    unused("--binaural-decoder", "ambisonic_binaural output");
  if (audio.rendering == Rendering::kPerSource) {
    if (fl.lateBuses) perSource("--late-buses");
    if (fl.clusterAngle) perSource("--cluster-angle");
  }
}

void applyRenderingOverrides(AudioSettings& audio, const Flags& fl) {
  if (!fl.rendering.empty()) {
    auto r = parseRendering(fl.rendering);
    if (!r)
      throw InputError("command line", "--rendering",
                       "'" + fl.rendering + "' is not auto, per_source or hybrid");
    audio.rendering = *r;
  }
  if (fl.lateBuses) {
    checkField("audio.late_buses", double(*fl.lateBuses), commandLineOrigin());
    audio.lateBuses = int(*fl.lateBuses);
  }
  if (fl.clusterAngle) {
    audio.clusterAngleDegrees = floatFlag("audio.cluster_angle", *fl.clusterAngle);
  }
  // The engine block of live runs and offline renders alike (offline, the renderer's block).
  if (fl.blockSize) {
    checkField("audio.block_size", double(*fl.blockSize), commandLineOrigin());
    audio.blockSize = int(*fl.blockSize);
  }
}

size_t selectedListener(const SceneDesc& scene, const Flags& fl) {
  return fl.listener.empty() ? 0 : listenerIndex(scene, fl.listener, "--listener");
}

namespace {

/// Throws naming `flag` if `out` is also written for another of the run's outputs.
void checkDistinct(const std::vector<std::pair<const char*, std::string>>& outputs, size_t i) {
  const auto& [flag, out] = outputs[i];
  for (size_t j = 0; j < outputs.size(); ++j) {
    const auto& [flag2, out2] = outputs[j];
    if (j != i && !out2.empty() &&
        (sameFile(out, out2) ||
         std::filesystem::weakly_canonical(std::filesystem::absolute(out)) ==
             std::filesystem::weakly_canonical(std::filesystem::absolute(out2))))
      throw InputError("command line", flag, "'" + out + "' is also written for " + flag2);
  }
}

/// Several listeners: each one's name is part of its output files' names (OUT-NAME.wav), so a
/// name too long for a file name is the scene's field, not the flag's.
void checkListenerFileNames(const SceneDesc& scene, const Flags& fl) {
  const std::vector<OutputPaths> paths = offlineOutputs(scene, fl);
  if (paths.size() < 2) return;  // the names as given, checked with their flags
  for (size_t i = 0; i < paths.size(); ++i)
    for (const auto& [flag, out] :
         {std::pair<const char*, std::string>{"--offline", paths[i].audio},
          {"--ir-out", paths[i].ir},
          {"--er-out", paths[i].energy}}) {
      const std::string why = out.empty() ? "" : outputNameProblem(out);
      if (!why.empty())
        throw InputError(fl.scene, "listeners[" + std::to_string(i) + "].name",
                         std::string("too long for the listener's ") + flag + " file: " + why);
    }
}

}  // namespace

void checkOutputs(const SceneDesc& scene, const Flags& fl) {
  std::vector<std::pair<const char*, std::string>> outputs = {{"--record", fl.record},
                                                              {"--stats", fl.stats}};
  if (!fl.offline.empty()) {
    checkListenerFileNames(scene, fl);
    for (const OutputPaths& o : offlineOutputs(scene, fl)) {
      outputs.push_back({"--offline", o.audio});
      outputs.push_back({"--ir-out", o.ir});
      outputs.push_back({"--er-out", o.energy});
    }
  }
  if (isSofaPath(fl.offline) || isSofaPath(fl.record))
    throw InputError("command line", isSofaPath(fl.offline) ? "--offline" : "--record",
                     "SOFA holds impulse responses, not audio: use --ir-out FILE.sofa");
  auto inputs = sceneInputFiles(scene, fl.scene);
  if (!fl.bake.empty()) inputs.push_back({fl.bake, "the bake"});
  // Every path on its own first (a name too long breaks the comparisons), then against the others.
  for (const auto& [flag, out] : outputs)
    if (!out.empty()) checkOutputPath(out, flag, inputs);
  for (size_t i = 0; i < outputs.size(); ++i)
    if (!outputs[i].second.empty()) checkDistinct(outputs, i);
  // After the inputs' checks: an output named as the mesh is refused as the mesh.
  checkOutputFormat("--offline", fl.offline, {"WAV"});
  checkOutputFormat("--record", fl.record, {"WAV"});
  checkOutputFormat("--ir-out", fl.irOut, {"WAV", "SOFA"});
  checkOutputFormat("--er-out", fl.erOut, {"CSV"});
  checkOutputFormat("--stats", fl.stats, {"JSON"});
}

}  // namespace dpc::demo
