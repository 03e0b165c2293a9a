// The names of the scene's enumerations as scene files and command lines spell them
// ("binaural", "path_tracing", "from_listeners", "window", ...), parsed into the enumerations of
// scene/scene.h. The callers turn an unknown name into their own error (naming the file and
// field, or the flag).
//
// Threads: any thread. Allocation: none. Errors: none (nullopt for an unknown name).
#pragma once

#include <optional>
#include <string>

#include "scene/scene.h"

namespace dpc {

/// Parses "mono" / "stereo" / "binaural" / "ambisonics" / "ambisonic_binaural"; nullopt for
/// anything else (loudspeaker layouts are named "layout:..." and read by the scene reader).
std::optional<OutputFormat> parseOutputFormat(const std::string& s);
/// The name parseOutputFormat reads, "a loudspeaker layout" for kLoudspeakers.
const char* outputFormatName(OutputFormat format);
/// Parses "magls" / "sampling"; nullopt for anything else.
std::optional<BinauralDecoder> parseBinauralDecoder(const std::string& s);
/// Parses "auto" / "per_source" / "hybrid"; nullopt for anything else.
std::optional<Rendering> parseRendering(const std::string& s);
/// Parses "dpc" / "path_tracing"; nullopt for anything else.
std::optional<Estimator> parseEstimator(const std::string& s);
/// Parses "auto" / "from_sources" / "from_listeners"; nullopt for anything else.
std::optional<Tracing> parseTracing(const std::string& s);
/// Parses "ema" / "seed" / "window"; nullopt for anything else.
std::optional<DpcWeighting> parseDpcWeighting(const std::string& s);

}  // namespace dpc
