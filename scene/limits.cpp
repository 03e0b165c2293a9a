#include "scene/limits.h"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "common/input_file.h"
#include "common/text_buffer.h"
#include "scene/scene.h"

namespace dpc {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// clang-format off
constexpr std::array kLimits = {
  // Top level: entity counts (docs/scene-format.md "Limits" says why these values).
  Limit{"sources", 1, double(kMaxSources), false, true, "",
        "each source traces its own rays and has its own IRs and convolutions"},
  Limit{"listeners", 1, double(kMaxListeners), false, true, "",
        "each listener multiplies the IRs and convolutions (sources x listeners)"},
  Limit{"objects", 0, double(kMaxObjects), false, true, "",
        "each object keeps its own mesh, BVH and top-level instance"},
  Limit{"position", -kMaxCoordinateM, kMaxCoordinateM, false, false, "m",
        "keeps Embree's rays and hit distances valid in float"},
  Limit{"materials.*.absorption", 0, 1, false, false, "",
        "a fraction of the incident energy (ISO 354)"},
  Limit{"materials.*.scattering", 0, 1, false, false, "",
        "a fraction of the reflected energy (ISO 17497-1)"},
  Limit{"materials.*.transmission_loss_db", 0, 200, false, false, "dB",
        "R >= 0 transmits at most the incident energy (ISO 10140-2); above 200 dB tau = "
        "10^(-R/10) is below any audible level: omit the field for an opaque material"},
  Limit{"sources[].gain_db", -200, 200, false, false, "dB",
        "beyond, a float signal under- or overflows"},
  Limit{"sources[].directivity.a", 0, 1, false, false, "",
        "first-order coefficient: 0 omni, 1 figure of eight; beyond, the pattern's lobes "
        "are no longer first-order (Eargle, The Microphone Book, ch. 5)"},
  Limit{"listener.radius", 0, kMaxCoordinateM, true, false, "m",
        "the receiver sphere needs an area to be hit; a sphere wider than the coordinate "
        "limit encloses any scene and hears nothing (and its area overflows a float)"},
  Limit{"listener.yaw", -3600, 3600, false, false, "degrees",
        "ten turns either way: enough for any keyframed spin, finite for interpolation"},
  Limit{"listener.pitch", -90, 90, false, false, "degrees",
        "beyond the poles the head would be upside down"},
  Limit{"listener.roll", -180, 180, false, false, "degrees",
        "a head tilt: every tilt once, finite for interpolation"},
  Limit{"propagation.rays_per_frame", 1, 1e8, false, true, "",
        "at least one ray; more cannot finish a frame on any machine"},
  Limit{"propagation.max_order", 0, 10000, false, true, "",
        "0 is the direct sound; beyond, the path bookkeeping grows without audible effect"},
  Limit{"propagation.exact_order", 0, double(kMaxExactOrder), false, true, "",
        "0 disables exact specular paths; image-source candidates grow as the order's power"},
  Limit{"propagation.patch_size", 0, kInf, true, false, "m",
        "patches need an extent to be told apart"},
  Limit{"propagation.cache_tau", 0, 3600, false, false, "s",
        "0 is plain path tracing; an hour exceeds any render, and the window length "
        "(tau times the frame rate) must fit the cache's frame counter"},
  Limit{"propagation.cache_memory_mb", 0, 16384, true, false, "MB",
        "per source-listener pair; beyond, several pairs exhaust any machine"},
  Limit{"propagation.cache_pool_mb", 0, 65536, true, false, "MB",
        "the whole engine's caches together; 64 GB is beyond this class of machine"},
  Limit{"propagation.frame_rate", 1, 120, false, false, "Hz",
        "slower than 1 Hz is no longer interactive; faster than audio blocks is wasted"},
  Limit{"propagation.ir_length", 0, 60, true, false, "s",
        "no room rings for a minute; longer IRs only cost memory and convolution"},
  Limit{"propagation.speed_of_sound", 1, 10000, false, false, "m/s",
        "covers every gas, liquid and most solids"},
  Limit{"wave.max_frequency", 20, 4000, false, false, "Hz",
        "below 20 Hz nothing is heard; above 4 kHz the grid's memory grows beyond any room "
        "(nodes grow as the frequency cubed) and rays are accurate"},
  Limit{"wave.crossover_hz", 0, 2000, false, false, "Hz",
        "0 takes half the maximum frequency; a crossover must lie below the maximum "
        "frequency (checked with it), so at most half the largest one"},
  Limit{"wave.grid_spacing", 0, 1, false, false, "m",
        "0 derives it from the maximum frequency; a metre resolves nothing above 34 Hz"},
  Limit{"propagation.temperature", -50, 60, false, false, "degrees C",
        "the range of ISO 9613-1 air absorption"},
  Limit{"propagation.humidity", 0, 100, false, false, "%", "relative humidity"},
  Limit{"propagation.roulette_threshold_db", -300, 0, false, false, "dB",
        "0 dB ends every ray at once; below -300 dB the threshold underflows a float"},
  Limit{"audio.sample_rate", 16000, 192000, false, true, "Hz",
        "below 16 kHz the 8 kHz octave band lies beyond Nyquist (NaN IRs)"},
  Limit{"audio.block_size", 16, 8192, false, true, "samples",
        "the partitioned convolver's smallest and largest partition"},
  Limit{"audio.ambisonic_order", 1, double(kMaxAmbisonicOrder), false, true, "",
        "order 0 is mono; above 7, 64+ channels that AmbiX tools do not read"},
  Limit{"audio.late_buses", 1, 64, false, true, "",
        "each bus costs a full-length IR and convolution; 64 gives every listener direction "
        "of a 30-degree grid its own"},
  Limit{"audio.cluster_angle", 0, 180, true, false, "degrees",
        "a cluster needs some angular size; 180 degrees lets any two sources share"},
};
// clang-format on

// The text of a value ("48000", "1.7", "inf", "nan") into [first, last); returns its end.
// No allocation.
char* writeValue(double value, char* first, char* last) {
  if (!std::isfinite(value)) {
    const std::string_view t = std::isnan(value) ? "nan" : (value > 0 ? "inf" : "-inf");
    const size_t n = std::min(t.size(), size_t(last - first));
    return std::copy_n(t.data(), n, first);
  }
  if (value == std::floor(value) && std::abs(value) < 1e15)
    return std::to_chars(first, last, static_cast<long long>(value)).ptr;
  // A float field reads back as the float it holds ("1.7", not "1.7000000476837158").
  const float f = static_cast<float>(value);
  return double(f) == value ? std::to_chars(first, last, f).ptr
                            : std::to_chars(first, last, value).ptr;
}

// A value in the error messages' form (valueText) appended to `out`.
TextBuffer& operator<<(TextBuffer& out, double value) {
  char digits[64];
  return out << std::string_view(digits, size_t(writeValue(value, digits, digits + 64) - digits));
}

// The range as docs/scene-format.md writes it; see rangeText.
void writeRange(const Limit& limit, TextBuffer& out) {
  if (std::isinf(limit.max)) {
    out << (limit.minExclusive ? "> " : ">= ") << limit.min;
    return;
  }
  out << (limit.minExclusive ? "(" : "[") << limit.min << ", " << limit.max << "]";
}

}  // namespace

std::span<const Limit> limits() {
  return kLimits;
}

const Limit& limitOf(std::string_view field) {
  for (const Limit& l : kLimits)
    if (l.field == field) return l;
  throw std::logic_error("no limit for field " + std::string(field));
}

bool withinLimit(const Limit& limit, double value) {
  // Infinity is no value of any field, also of those without an upper bound ("> 0").
  if (!std::isfinite(value)) return false;
  if (limit.integer && value != std::floor(value)) return false;
  const bool aboveMin = limit.minExclusive ? value > limit.min : value >= limit.min;
  return aboveMin && value <= limit.max;
}

std::string rangeText(const Limit& limit) {
  char text[96];
  TextBuffer out(text, sizeof text);
  writeRange(limit, out);
  return text;
}

std::string valueText(double value) {
  char text[64];
  return std::string(text, writeValue(value, text, text + sizeof text));
}

void writeLimitProblem(const Limit& limit, double value, char* text, size_t size) {
  TextBuffer out(text, size);
  if (withinLimit(limit, value)) return;
  out << value;
  if (limit.integer && std::isfinite(value) && value != std::floor(value)) {
    out << " is not an integer";
    return;
  }
  out << (std::isinf(limit.max) ? " must be " : " is outside ");
  writeRange(limit, out);
  if (!limit.unit.empty()) out << " " << limit.unit;
}

bool positionWithinLimit(float x, float y, float z) {
  const Limit& l = limitOf("position");
  return withinLimit(l, x) && withinLimit(l, y) && withinLimit(l, z);
}

}  // namespace dpc
