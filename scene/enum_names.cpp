#include "scene/enum_names.h"

#include <utility>

namespace dpc {

namespace {

constexpr std::pair<const char*, OutputFormat> kOutputFormats[] = {
    {"mono", OutputFormat::kMono},
    {"stereo", OutputFormat::kStereo},
    {"binaural", OutputFormat::kBinaural},
    {"ambisonics", OutputFormat::kAmbisonics},
    {"ambisonic_binaural", OutputFormat::kAmbisonicBinaural}};

}  // namespace

std::optional<OutputFormat> parseOutputFormat(const std::string& s) {
  for (const auto& [name, format] : kOutputFormats)
    if (s == name) return format;
  return std::nullopt;
}

const char* outputFormatName(OutputFormat format) {
  for (const auto& [name, f] : kOutputFormats)
    if (f == format) return name;
  return "a loudspeaker layout";
}

std::optional<BinauralDecoder> parseBinauralDecoder(const std::string& s) {
  if (s == "magls") return BinauralDecoder::kMagLs;
  if (s == "sampling") return BinauralDecoder::kSampling;
  return std::nullopt;
}

std::optional<Estimator> parseEstimator(const std::string& s) {
  if (s == "dpc") return Estimator::kDpc;
  if (s == "path_tracing") return Estimator::kPathTracing;
  return std::nullopt;
}

std::optional<Tracing> parseTracing(const std::string& s) {
  if (s == "auto") return Tracing::kAuto;
  if (s == "from_sources") return Tracing::kFromSources;
  if (s == "from_listeners") return Tracing::kFromListeners;
  return std::nullopt;
}

std::optional<Rendering> parseRendering(const std::string& s) {
  if (s == "auto") return Rendering::kAuto;
  if (s == "per_source") return Rendering::kPerSource;
  if (s == "hybrid") return Rendering::kHybrid;
  return std::nullopt;
}

std::optional<DpcWeighting> parseDpcWeighting(const std::string& s) {
  if (s == "ema") return DpcWeighting::kEma;
  if (s == "seed") return DpcWeighting::kSeed;
  if (s == "window") return DpcWeighting::kWindow;
  return std::nullopt;
}

}  // namespace dpc
